r"""NetCDF files of trajectories: the layout (:func:`dataset_content`), :func:`write_netcdf`, :func:`read_netcdf`.

One module per file format (as xarray keeps one backend per format): this one writes and reads NetCDF-4
(through h5netcdf, without importing xarray), :mod:`.stream` writes Zarr stores from the same layout, and
:mod:`.read` opens any of them by content. :class:`~eulerpoisson.trajectory.Trajectory` reaches this module
through its lazy accessors ``to_netcdf``, ``from_netcdf`` and ``to_xarray``.

Examples
--------
>>> import eulerpoisson as ep
>>> from eulerpoisson.io.netcdf import read_netcdf, write_netcdf
>>> tr = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
>>> write_netcdf(tr, "run.nc")                                   # doctest: +SKIP
>>> bool((read_netcdf("run.nc").quaternion == tr.quaternion).all())   # doctest: +SKIP
True
"""

from __future__ import annotations

import json
import os
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import numpy as np

from ..errors import EulerPoissonError, InvalidInputError, require
from ..model.body import RigidBody
from ..trajectory import CONVENTIONS, FORMAT_VERSION, Trajectory
from ..version import package_version
from .atomic import atomic_path, write_error

if TYPE_CHECKING:
    import xarray

__all__ = [
    "dataset_content",
    "to_xarray",
    "write_netcdf",
    "read_netcdf",
    "torque_records",
    "read_torques",
    "format_version",
    "json_attr",
]


def to_xarray(traj: Trajectory) -> xarray.Dataset:
    """The trajectory as an :class:`xarray.Dataset` with CF-style attributes.

    Batches are flattened to a ``body`` dimension (the batch shape is kept
    in the ``batch_shape`` attribute).

    Raises
    ------
    MissingDependencyError
        If xarray is not installed (extra ``io``).
    """
    xr = require("xarray", "io")
    data, coords, attrs = dataset_content(traj)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def dataset_content(traj: Trajectory) -> tuple[dict, dict, dict]:
    """The variables ``{name: (dims, values, attrs)}``, coordinates and global attributes of a trajectory's file.

    The one description of the layout: NetCDF files and Zarr stores (:mod:`eulerpoisson.io.stream`) are
    written from it.
    """
    version = package_version()

    bshape = traj.batch_shape
    nb = int(np.prod(bshape)) if bshape else 0
    T = len(traj.t)

    def flat(a, tail):
        return a.reshape((nb,) + a.shape[len(bshape) :]) if bshape else a

    bdim = ("body",) if bshape else ()
    inertia = np.broadcast_to(traj.body.inertia, bshape + (3, 3))
    data = {
        "quaternion": (
            bdim + ("time", "quat"),
            flat(traj.quaternion, 2),
            {"long_name": "attitude quaternion, scalar first (w, x, y, z); x_space = R(q) x_body", "units": "1"},
        ),
        "omega": (
            bdim + ("time", "axis"),
            flat(traj.omega, 2),
            {"long_name": "body angular velocity Omega (body frame)", "units": "rad s-1"},
        ),
        "M": (
            bdim + ("time", "axis"),
            flat(traj.M, 2),
            {"long_name": "body angular momentum M = I Omega (body frame)", "units": "kg m2 s-1"},
        ),
        "m": (
            bdim + ("time", "axis"),
            flat(traj.m, 2),
            {"long_name": "spatial angular momentum m = R I Omega (space frame)", "units": "kg m2 s-1"},
        ),
        "energy": (
            bdim + ("time",),
            flat(traj.energy, 1),
            {
                "long_name": (
                    "kinetic energy E = Omega.I Omega/2"
                    if traj.model.is_free
                    else "energy E = Omega.I Omega/2 + U (kinetic plus the potential of the torques)"
                ),
                "units": "J",
            },
        ),
        "gibbs": (
            bdim + ("time", "axis"),
            flat(traj.gibbs, 2),
            {
                "long_name": "Gibbs rotation vector n = k tan(alpha/2) (paper eq. 1.8); NaN at alpha = pi",
                "units": "1",
            },
        ),
        "inertia": (
            bdim + ("axis", "axis2"),
            flat(inertia, 2),
            {"long_name": "inertia tensor in the body frame", "units": "kg m2"},
        ),
    }
    if traj.body.positions is not None and not bshape:
        data["particle_masses"] = (("particle",), traj.body.masses, {"long_name": "point masses", "units": "kg"})
        data["particle_positions"] = (
            ("particle", "axis"),
            traj.body.positions,
            {"long_name": "particle positions relative to the centre of mass at t = 0 (body frame)", "units": "m"},
        )
        data["center_of_mass"] = (
            ("axis",),
            traj.body.center_of_mass,
            {"long_name": "centre of mass", "units": "m"},
        )
    coords = {
        "time": ("time", traj.t, {"long_name": "time", "units": "s", "standard_name": "time"}),
        "quat": ("quat", np.array(["w", "x", "y", "z"])),
        "axis": ("axis", np.array(["x", "y", "z"])),
        "axis2": ("axis2", np.array(["x", "y", "z"])),
    }
    attrs = {
        "title": (
            f"free rigid body trajectory ({traj.method})"
            if traj.model.is_free
            else f"rigid body under torque: {traj.model.describe()} ({traj.method})"
        ),
        "torque": json.dumps(torque_records(traj.model.torques)),
        "Conventions": "CF-1.10",
        "eulerpoisson_conventions": CONVENTIONS,
        "eulerpoisson_format_version": FORMAT_VERSION,
        "eulerpoisson_version": version,
        "method": traj.method,
        "method_options": json.dumps(traj.options, default=float, sort_keys=True),
        "stats": json.dumps(traj.stats, default=float, sort_keys=True),
        "batch_shape": json.dumps(list(bshape)),
        "body_name": traj.body.name or "",
        "T": T,
        "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} written by eulerpoisson {version}",
        "references": "A. A. Deriglazov, Geodesic motion on the symplectic leaf of SO(3) ... (the paper)",
    }
    return data, coords, attrs


def write_netcdf(traj: Trajectory, path: str | os.PathLike[str]) -> None:
    """Write the trajectory to a NetCDF-4 file, atomically (temporary file, then rename).

    An existing NetCDF file or empty file at ``path`` is replaced; any other file (recognized by its content,
    not its name: a configuration, data, a figure), a folder or a store is not.

    Raises
    ------
    OutputError
        ``path`` holds something that is not a NetCDF file.
    InvalidInputError
        A name that cannot be meant (empty, a control character, only a suffix such as ``.nc``).
    MissingDependencyError
        If xarray or h5netcdf is missing (extra ``io``).
    """
    import io

    from .outputs import check_output

    check_output(path, "netcdf", overwrite=True, flag="to_netcdf", option="path", replace_empty=True)
    h5netcdf = require("h5netcdf", "io")
    content, coords, attrs = dataset_content(traj)
    # HDF5 writes into memory first; the file itself is written by plain Python I/O, so a full disk is
    # an OSError naming the file (HDF5 left with a half-written file on a full disk crashed the
    # interpreter at exit), and nothing is left behind. h5netcdf directly, not through xarray: the
    # same file (xarray reads back the dataset of to_xarray(), a test checks) without importing
    # xarray and dask on every run of the command line.
    variables = {name: (v if len(v) == 3 else (*v, {})) for name, v in {**coords, **content}.items()}
    dims: dict[str, int] = {}
    for dnames, values, _ in variables.values():
        dnames = (dnames,) if isinstance(dnames, str) else tuple(dnames)
        for d, n in zip(dnames, np.shape(values)):
            dims.setdefault(d, n)
    buf = io.BytesIO()
    with h5netcdf.File(buf, "w") as f:
        f.dimensions = dims
        for name, (dnames, values, vattrs) in variables.items():
            dnames = (dnames,) if isinstance(dnames, str) else tuple(dnames)
            values = np.asarray(values)
            if values.dtype.kind == "U":
                import h5py

                var = f.create_variable(name, dnames, dtype=h5py.string_dtype())
                var[...] = values.astype(object)
            else:
                var = f.create_variable(
                    name,
                    dnames,
                    dtype=values.dtype,
                    data=values,
                    fillvalue=np.nan if values.dtype.kind == "f" else None,
                )
            for k, val in vattrs.items():
                var.attrs[k] = val
        for k, val in attrs.items():
            f.attrs[k] = val
    data = buf.getbuffer()

    with atomic_path(path) as tmp:
        try:
            with open(tmp, "wb") as fh:
                fh.write(data)
        except OSError as exc:
            raise write_error(path, exc) from None


def read_netcdf(path: str | os.PathLike[str]) -> Trajectory:
    """Read a trajectory written by :func:`write_netcdf`.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    Trajectory
        Bit for bit the one written (times, attitudes, angular velocities).

    Raises
    ------
    TypeError
        ``path`` is not a file name (``str``, ``bytes`` or ``os.PathLike``).
    FileNotFoundError
        If the file does not exist.
    EulerPoissonError
        If the file is not a readable NetCDF file or not an eulerpoisson
        trajectory, or was written by a newer, unknown format version.
    InvalidInputError
        A malformed trajectory file; the message names the file and the
        attribute or variable: a missing variable (``time``, ``inertia``,
        particle data), a format version that is not a positive integer,
        attributes (``batch_shape``, ``method_options``, ``stats``) that
        are not the JSON written by :func:`write_netcdf`, variables whose
        shapes do not match ``batch_shape`` and the number of times, or
        values the constructors reject (NaN, a non-physical inertia
        tensor: :class:`InvalidInertiaError`), or a stored ``M`` that
        disagrees with ``inertia @ omega`` (an edited file).
    MissingDependencyError
        If xarray or h5netcdf is missing (extra ``io``).
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path must be a file name (str or os.PathLike), got {type(path).__name__} {path!r}")
    if isinstance(path, bytes):
        path = os.fsdecode(path)  # named as text in the messages below, not b'...'
    xr = require("xarray", "io")
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such file: {path}")
    try:
        from .formats import netcdf_engine  # NetCDF-3 (classic) files through scipy, NetCDF-4 through h5netcdf

        ds = xr.load_dataset(path, engine=netcdf_engine(path))
    except Exception as exc:
        raise EulerPoissonError(f"{path} is not a readable NetCDF file: {exc}") from exc
    ver = ds.attrs.get("eulerpoisson_format_version")
    if ver is None or "quaternion" not in ds or "omega" not in ds:
        raise EulerPoissonError(f"{path} is not an eulerpoisson trajectory file")
    ver = format_version(path, ver)
    if ver > FORMAT_VERSION:
        raise EulerPoissonError(
            f"{path} has format version {ver}, newer than this eulerpoisson ({FORMAT_VERSION}); upgrade the package"
        )
    need = ["time", "inertia"]
    if "particle_masses" in ds:
        need += ["particle_positions", "center_of_mass"]
    missing = [v for v in need if v not in ds]
    if missing:
        raise InvalidInputError(
            f"{path}: malformed eulerpoisson trajectory file, variable(s) {missing} missing "
            f"(expected {need} besides quaternion and omega)"
        )
    bshape = json_attr(path, ds, "batch_shape", "[]", list)
    if not all(isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in bshape):
        raise InvalidInputError(
            f"{path}: attribute batch_shape must be a JSON list of non-negative integers, got {bshape!r}"
        )
    bshape = tuple(bshape)
    options = json_attr(path, ds, "method_options", "{}", dict)
    stats = json_attr(path, ds, "stats", "{}", dict)
    t = ds["time"].values
    q = ds["quaternion"].values
    w = ds["omega"].values
    inertia = ds["inertia"].values
    if t.ndim != 1:
        raise InvalidInputError(f"{path}: variable time must be 1-D, got shape {t.shape}")
    lead = (int(np.prod(bshape)),) if bshape else ()
    for nm, a, tail in (
        ("quaternion", q, (t.shape[0], 4)),
        ("omega", w, (t.shape[0], 3)),
        ("inertia", inertia, (3, 3)),
    ):
        if a.shape != lead + tail:
            raise InvalidInputError(
                f"{path}: variable {nm} has shape {a.shape}, expected {lead + tail} "
                f"(batch_shape {list(bshape)}, {t.shape[0]} times)"
            )
    if t.size > 1 and np.all(t == t[0]):
        raise InvalidInputError(
            f"{path}: the time variable holds the same value {float(t[0])!r} for all "
            f"{t.size} samples: the file was modified or is not ours"
        )
    from ..attitude.core import UNIT_QUATERNION_TOLERANCE

    with np.errstate(invalid="ignore", over="ignore"):
        norms = np.sqrt(np.sum(np.asarray(q, dtype=float) ** 2, axis=-1))
    norms = norms[np.isfinite(norms)]  # NaN and inf are named by the checks below
    if norms.size and not np.all(np.abs(norms - 1.0) <= UNIT_QUATERNION_TOLERANCE):
        worst = float(norms[np.argmax(np.abs(norms - 1.0))])
        raise InvalidInputError(
            f"{path}: the quaternion variable is not made of unit quaternions (a norm of {worst:.9g}; "
            f"we write norm 1 within {UNIT_QUATERNION_TOLERANCE:g}): the file was modified or is not ours"
        )
    if bshape:
        q = q.reshape(bshape + q.shape[1:])
        w = w.reshape(bshape + w.shape[1:])
        inertia = inertia.reshape(bshape + (3, 3))
    name = ds.attrs.get("body_name") or None
    try:
        if "particle_masses" in ds:
            body = RigidBody.from_particles(
                ds["particle_masses"].values,
                ds["particle_positions"].values + ds["center_of_mass"].values,
                name=name if name is None else str(name),
            )
        else:
            body = RigidBody(inertia, name=name if name is None else str(name), allow_unphysical=True)
        traj = Trajectory(
            t=t,
            quaternion=q,
            omega=w,
            body=body,
            method=str(ds.attrs.get("method", "")),
            options=options,
            stats=stats,
            torque=read_torques(path, ds),
        )
    except (InvalidInputError, TypeError) as exc:  # name the file (the type is kept)
        raise type(exc)(f"{path}: {exc}") from exc
    # the stored M = I Omega must agree with the inertia and omega read back (an edited inertia
    # or omega would otherwise give a silently different motion)
    Mf = ds["M"].values if "M" in ds else None
    if (
        Mf is not None
        and t.size
        and np.issubdtype(Mf.dtype, np.floating)
        and Mf.shape == lead + (t.shape[0], 3)
        and np.all(np.isfinite(Mf))
    ):
        Mf = Mf.reshape(traj.M.shape)
        scale = np.max(np.abs(Mf), axis=(-1, -2), keepdims=True)
        err = np.max(np.abs(traj.M - Mf) / np.where(scale > 0, scale, 1.0))
        if not err <= 1e-9:
            raise InvalidInputError(
                f"{path}: inconsistent file: the stored body angular momentum M differs from "
                f"inertia @ omega by {err:.3g} (relative); the inertia or omega variable was modified"
            )
    return traj


def torque_records(torques) -> list[dict]:
    """JSON-able records of the torques; a callable is recorded by name (it cannot be read back as code)."""
    out = []
    for tq in torques:
        try:
            out.append(tq.to_dict())
        except NotImplementedError:
            out.append({"kind": "unrecorded", "description": repr(tq)})
    return out


def read_torques(path, ds):
    """The torques of a file's ``torque`` attribute (absent: the free body)."""
    from ..model.torques import Torque, UnrecordedTorque, torque_from_dict

    raw = ds.attrs.get("torque")
    if raw is None or raw == "":
        return None
    try:
        records = json.loads(str(raw))
    except ValueError:
        raise InvalidInputError(f"{path}: the torque attribute is not valid JSON: {str(raw)[:80]!r}") from None
    if not isinstance(records, list):
        raise InvalidInputError(f"{path}: the torque attribute must be a JSON list of records, got {str(raw)[:80]!r}")
    out: list[Torque] = []
    for rec in records:
        if isinstance(rec, dict) and rec.get("kind") == "unrecorded":
            out.append(UnrecordedTorque(str(rec.get("description", ""))))
        else:
            try:
                out.append(torque_from_dict(rec))
            except (InvalidInputError, TypeError) as exc:
                raise InvalidInputError(f"{path}: torque attribute: {exc}") from None
    return out


def format_version(path, ver) -> int:
    """The ``eulerpoisson_format_version`` attribute as a positive int, or InvalidInputError."""
    v = ver.item() if isinstance(ver, np.ndarray) and ver.size == 1 else ver
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < 1:
        raise InvalidInputError(
            f"{path}: attribute eulerpoisson_format_version must be a positive integer, got {ver!r}"
        )
    return int(v)


def json_attr(path, ds, key: str, default: str, kind: type):
    """Decode the JSON attribute ``key`` (a ``kind``: list or dict), or InvalidInputError naming the file."""
    raw = ds.attrs.get(key, default)
    try:
        val = json.loads(raw)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{path}: attribute {key} is not valid JSON ({exc}): {str(raw)[:80]!r}") from exc
    if not isinstance(val, kind):
        raise InvalidInputError(
            f"{path}: attribute {key} must be a JSON {'list' if kind is list else 'object'}, got {raw!r}"
        )
    return val
