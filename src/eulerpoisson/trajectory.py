r"""The result of :func:`~eulerpoisson.solve`: a :class:`Trajectory`.

A trajectory holds the output times, the attitude (unit quaternions with a
continuous sign) and the body angular velocity of one body or a batch of
bodies; everything else — rotation matrices, Gibbs vectors, body and spatial
angular momenta, energy, the drift of the integrals, the motion of the
particles of a point-mass body (paper eq. 1.2) — is derived from them.
Trajectories are written to and read from NetCDF with CF-style attributes.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .attitude.core import matrix_from_unit_quaternion, quaternion_make_continuous
from .errors import EulerPoissonError, InvalidInputError, require
from .io.atomic import atomic_path
from .model.body import RigidBody
from .model.equations import Model
from .util.validate import as_float_array

if TYPE_CHECKING:
    import xarray
    from matplotlib.figure import Figure

    from .io.read import LazyTrajectory
    from .model.torques import TorqueLike

__all__ = ["Trajectory", "FORMAT_VERSION"]

#: version of the NetCDF layout written by :meth:`Trajectory.to_netcdf`
FORMAT_VERSION = 1

CONVENTIONS = (
    "x_space = R x_body; dR/dt = R [Omega]x with Omega the body angular velocity; "
    "quaternion scalar first (w, x, y, z), Hamilton product; Gibbs vector n = (x, y, z)/w = k tan(alpha/2); "
    "M = I Omega (body frame), m = R I Omega (space frame), E = Omega.I Omega/2. "
    "Units are those of the inputs (any consistent system; SI names are given for orientation)."
)


def _unit_continuous(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Quaternions (..., T, 4) as a trajectory stores them: normalized, with signs continuous in time.

    Body by body along the time axis (``t``, any order): any split of a batch gives the same bits.

    Raises
    ------
    InvalidInputError
        A zero quaternion.
    """
    # a fixed summation order (an einsum or a reduction may sum in an order that depends on the
    # memory layout, and then two equal arrays could be normalized differently)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    nrm = np.sqrt(w * w + x * x + y * y + z * z)[..., None]
    if np.any(nrm == 0):
        raise InvalidInputError("quaternion contains a zero quaternion, which is not a rotation")
    # normalize, but leave already-unit quaternions bit for bit (files round-trip exactly)
    off = np.abs(nrm - 1.0) > 4 * np.finfo(float).eps
    if np.any(off):
        q = np.where(off, q / nrm, q)
    if t.size < 2 or np.all(t[1:] >= t[:-1]):  # the usual case: no reordering needed
        return quaternion_make_continuous(q, axis=-2) if q.ndim > 1 else q
    order = np.argsort(t, kind="stable")
    qs = quaternion_make_continuous(np.take(q, order, axis=-2), axis=-2)
    inv = np.empty_like(order)
    inv[order] = np.arange(order.size)
    return np.take(qs, inv, axis=-2)


def stored_attitudes(t: np.ndarray, quaternion, omega) -> np.ndarray:
    """What :class:`Trajectory` does to a solver's output, for part of a batch (the solve driver runs it in the
    thread that solved the part): ``quaternion`` and ``omega`` checked (finite, shapes), the quaternions
    returned as the trajectory stores them (:func:`_unit_continuous`).

    Raises
    ------
    InvalidInputError
        As :class:`Trajectory` (the driver then builds the trajectory of the whole batch again, so that the
        message is about the whole batch).
    """
    q = as_float_array(quaternion, "quaternion", (4,))
    as_float_array(omega, "omega", (3,))
    return _unit_continuous(t, q)


class Trajectory:
    r"""Motion of one body or a batch of bodies at a set of output times.

    Parameters
    ----------
    t : array_like, shape (T,)
        Output times, a 1-D array (``T = 0`` is allowed: an empty
        trajectory, whose :meth:`drift` raises).
    quaternion : array_like, shape ``(*batch, T, 4)``
        Attitudes (made unit and sign-continuous in time here).
    omega : array_like, shape ``(*batch, T, 3)``
        Body angular velocities.
    body : RigidBody
        One body, or a batch whose shape broadcasts to ``batch``.
    torque : Torque, list of Torque, or None
        The torques of the motion (:mod:`eulerpoisson.torques`); None for the
        free body. They define :attr:`energy` (with the potential),
        :meth:`integrals` and :meth:`drift`. Keyword only.
    method : str
        Name of the method that produced it.
    options : dict, optional
        The method's options.
    stats : dict, optional
        Counters (wall time, steps, ...).

    Raises
    ------
    InvalidInputError
        ``t`` not 1-D, inconsistent shapes, NaN or infinite values, a zero
        quaternion, or a body batch that does not broadcast to the batch of
        the states.
    TypeError
        ``body`` not a :class:`RigidBody`, ``method`` not a string,
        ``options``/``stats`` not mappings.

    Attributes
    ----------
    t, quaternion, omega, body, model, method, options, stats

    Notes
    -----
    Derived quantities are properties computed on access: :attr:`matrix`,
    :attr:`gibbs` (NaN where the rotation angle is :math:`\pi`, flagged by
    :attr:`gibbs_singular`), :attr:`M`, :attr:`m`, :attr:`energy`.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 10.0, 101), omega0=[1.0, 0.1, 0.5])
    >>> tr
    Trajectory(method='exact', T=101, t=[0, 10])
    >>> tr.quaternion.shape, tr.omega.shape, tr.matrix.shape
    ((101, 4), (101, 3), (101, 3, 3))
    >>> print(np.round(tr.omega[-1], 6))
    [ 0.856743 -0.639521  0.192891]
    >>> {k: bool(v < 1e-12) for k, v in tr.drift().items()}          # the integrals are conserved
    {'energy': True, 'm_norm': True, 'm_x': True, 'm_y': True, 'm_z': True}
    >>> print(tr[::50].t)                                            # index the samples
    [ 0.  5. 10.]
    """

    def __init__(
        self,
        t: ArrayLike,
        quaternion: ArrayLike,
        omega: ArrayLike,
        body: RigidBody,
        method: str = "",
        options: dict[str, Any] | None = None,
        stats: dict[str, Any] | None = None,
        *,
        torque: TorqueLike = None,
        _prepared: bool = False,
    ) -> None:
        # _prepared (private, for the solve driver): ``quaternion`` and ``omega`` are float64 arrays already
        # checked and stored by :func:`stored_attitudes` (chunk by chunk, in the threads that solved them)
        self.t = as_float_array(t, "t")
        if self.t.ndim != 1:
            raise InvalidInputError(f"t must be a 1-D array of output times, shape (T,); got shape {self.t.shape}")
        if not isinstance(body, RigidBody):
            raise TypeError(f"body must be a RigidBody, got {type(body).__name__} {body!r}")
        if not isinstance(method, str):
            raise TypeError(f"method must be a string, got {type(method).__name__} {method!r}")
        for nm, val in (("options", options), ("stats", stats)):
            if val is not None and not isinstance(val, Mapping):
                raise TypeError(f"{nm} must be a dict (or None), got {type(val).__name__} {val!r}")
        if _prepared:
            q = np.asarray(quaternion, dtype=np.float64)
            self.omega = np.asarray(omega, dtype=np.float64)
        else:
            q = as_float_array(quaternion, "quaternion", (4,))
            self.omega = as_float_array(omega, "omega", (3,))
        if q.shape[-2:-1] != self.t.shape or self.omega.shape[:-1] != q.shape[:-1]:
            raise InvalidInputError(
                f"inconsistent trajectory shapes: t {self.t.shape}, quaternion {q.shape}, omega {self.omega.shape}"
            )
        bshape = q.shape[:-2]
        try:
            ok = np.broadcast_shapes(body.batch_shape, bshape) == bshape
        except ValueError:
            ok = False
        if not ok:
            raise InvalidInputError(
                f"the body's batch shape {body.batch_shape} does not broadcast to the trajectory's batch "
                f"shape {bshape} (quaternion {q.shape}, omega {self.omega.shape})"
            )
        self.quaternion = q if _prepared else _unit_continuous(self.t, q)
        self.body = body
        self.model = Model(body, torque)
        if self.model.batch_shape != () and np.broadcast_shapes(self.model.batch_shape, bshape) != bshape:
            raise InvalidInputError(
                f"the torque parameters' batch shape {self.model.batch_shape} does not broadcast to the "
                f"trajectory's batch shape {bshape}"
            )
        self.method = method
        self.options = dict(options or {})
        self.stats = dict(stats or {})

    # ------------------------------------------------------------------
    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of bodies (``()`` for one body)."""
        return self.quaternion.shape[:-2]

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def _inertia(self) -> np.ndarray:
        return self.body.inertia[..., None, :, :]

    @property
    def matrix(self) -> NDArray[np.float64]:
        """Rotation matrices R(t), ``(*batch, T, 3, 3)``."""
        return matrix_from_unit_quaternion(self.quaternion)

    @property
    def gibbs_singular(self) -> NDArray[np.bool_]:
        r"""Boolean mask ``(*batch, T)``: rotation angle exactly :math:`\pi`, where the global Gibbs vector is infinite."""
        return self.quaternion[..., 0] == 0

    @property
    def gibbs(self) -> NDArray[np.float64]:
        """Global Gibbs vectors n(t) = (x, y, z)/w, ``(*batch, T, 3)``; NaN where :attr:`gibbs_singular`."""
        w = self.quaternion[..., :1]
        with np.errstate(divide="ignore", invalid="ignore"):
            n = self.quaternion[..., 1:] / w
        return np.where(w == 0, np.nan, n)

    @property
    def M(self) -> NDArray[np.float64]:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega`, ``(*batch, T, 3)``."""
        return np.einsum("...ij,...j->...i", self._inertia, self.omega)

    @property
    def m(self) -> NDArray[np.float64]:
        r"""Spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`, ``(*batch, T, 3)``; constant for the free body."""
        return np.einsum("...ij,...j->...i", self.matrix, self.M)

    @property
    def kinetic_energy(self) -> NDArray[np.float64]:
        r"""Kinetic energy :math:`\tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega`, ``(*batch, T)``."""
        return 0.5 * np.sum(self.omega * self.M, -1)

    @property
    def potential_energy(self) -> NDArray[np.float64]:
        r"""Potential energy :math:`U(t, R)` of the conservative torques, ``(*batch, T)``; 0 for the free body."""
        if self.model.is_free:
            return np.zeros(self.omega.shape[:-1])
        T = self.t.shape[0]
        Rt = np.moveaxis(self.matrix, -3, 0)  # time first: the torques' parameters broadcast over the batch
        tt = self.t.reshape((T,) + (1,) * len(self.batch_shape))
        U = np.zeros((T,) + self.batch_shape)
        for tq in self.model.torques:
            if tq.conservative:
                U = U + tq.potential(tt, Rt, self.body.inertia)
        return np.moveaxis(U, 0, -1)

    @property
    def energy(self) -> NDArray[np.float64]:
        r"""Energy :math:`E = \tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega + U`, ``(*batch, T)``.

        The kinetic energy plus the potential of the conservative torques
        (:attr:`kinetic_energy`, :attr:`potential_energy`); the kinetic energy
        alone for the free body.
        """
        if self.model.is_free:
            return self.kinetic_energy
        return self.kinetic_energy + self.potential_energy

    def integrals(self) -> dict[str, NDArray[np.float64]]:
        """The conserved quantities of the trajectory's model at every output time, each ``(*batch, T)``.

        See :meth:`eulerpoisson.Model.integrals` for which ones (energy and
        spatial angular momentum for the free body; energy, vertical angular
        momentum, and the Lagrange, Kovalevskaya or Goryachev–Chaplygin
        integral for heavy tops; the Jacobi integral for the gravity gradient).
        """
        return self.model.integrals(self.t, self.quaternion, self.omega)

    def drift(self) -> dict[str, NDArray[np.float64]]:
        r"""Relative drift of every integral of motion of the model over the trajectory.

        Relative to the value at the first output time ``t[0]`` (the
        initial state when ``t[0] = 0``). Free body: for the energy
        :math:`\max_t|E(t)-E_0|/|E_0|`, for :math:`|\mathbf m|` the same, and
        for each component :math:`\max_t|m_i(t)-m_i(t_0)|/|\mathbf m(t_0)|`.
        Under torque: each integral of :meth:`integrals`, the energy-like
        ones (``energy``, ``jacobi``) relative to the sum of the magnitudes
        of their terms at ``t[0]`` (kinetic plus :math:`|U|`, so a zero total
        energy does not divide by zero), the angular momenta relative to
        :math:`|\mathbf m(t_0)|`, the others to their own magnitude. Zero
        scales (a body at rest) give absolute values.

        Returns
        -------
        dict
            One entry per integral (free body: ``"energy"``, ``"m_norm"``,
            ``"m_x"``, ``"m_y"``, ``"m_z"``), each an array of the batch shape
            (a float for one body). Empty for a model with no known integral.

        Raises
        ------
        InvalidInputError
            For an empty trajectory (no output times, ``T = 0``): the drift is
            measured from the values at ``t[0]``, which it does not have. (An
            empty result would be read as "no drift"; the error is explicit.)
        """
        if self.t.size == 0:
            raise InvalidInputError(
                "drift() is measured from the integrals at the first output time t[0], and this trajectory "
                "has no output times (T = 0)"
            )

        from .model.drift import DriftAccumulator

        acc = DriftAccumulator(self.model)  # the same computation as for long runs seen in pieces
        acc.update(self.t, self.quaternion, self.omega)
        return acc.result()

    def particles(
        self, center0: ArrayLike = (0.0, 0.0, 0.0), velocity0: ArrayLike = (0.0, 0.0, 0.0)
    ) -> NDArray[np.float64]:
        r"""Positions of the body's point masses, :math:`\mathbf y_N(t) = \mathbf C_0 + \mathbf V_0 t + R(t)\mathbf x_N(0)` (paper eq. 1.2).

        Parameters
        ----------
        center0 : array_like, shape (3,)
            Centre of mass at t = 0 (defaults to the body's own centre of mass
            if it was built with :meth:`RigidBody.from_particles` and
            ``center0`` is not given).
        velocity0 : array_like, shape (3,)
            Velocity of the centre of mass.

        Returns
        -------
        ndarray, shape ``(*batch, T, N, 3)``

        Raises
        ------
        InvalidInputError
            If the body was not built from particles.
        """
        if self.body.positions is None:
            raise InvalidInputError(
                "this trajectory's body has no particles; build it with RigidBody.from_particles(masses, positions)"
            )
        C0 = as_float_array(center0, "center0", (3,))
        V0 = as_float_array(velocity0, "velocity0", (3,))
        x0 = self.body.positions  # relative to the centre of mass, body frame = space frame at q = 1
        y = np.einsum("...tij,nj->...tni", self.matrix, x0)
        return y + C0 + V0 * self.t[:, None, None]

    # ------------------------------------------------------------------
    def to_xarray(self) -> xarray.Dataset:
        """The trajectory as an :class:`xarray.Dataset` with CF-style attributes.

        Batches are flattened to a ``body`` dimension (the batch shape is kept
        in the ``batch_shape`` attribute).

        Raises
        ------
        MissingDependencyError
            If xarray is not installed (extra ``io``).
        """
        xr = require("xarray", "io")
        data, coords, attrs = self._netcdf_content()
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def _netcdf_content(self):
        """The variables ``{name: (dims, values, attrs)}``, coordinates and global attributes of the file."""
        from . import __version__

        bshape = self.batch_shape
        nb = int(np.prod(bshape)) if bshape else 0
        T = len(self.t)

        def flat(a, tail):
            return a.reshape((nb,) + a.shape[len(bshape) :]) if bshape else a

        bdim = ("body",) if bshape else ()
        inertia = np.broadcast_to(self.body.inertia, bshape + (3, 3))
        data = {
            "quaternion": (
                bdim + ("time", "quat"),
                flat(self.quaternion, 2),
                {"long_name": "attitude quaternion, scalar first (w, x, y, z); x_space = R(q) x_body", "units": "1"},
            ),
            "omega": (
                bdim + ("time", "axis"),
                flat(self.omega, 2),
                {"long_name": "body angular velocity Omega (body frame)", "units": "rad s-1"},
            ),
            "M": (
                bdim + ("time", "axis"),
                flat(self.M, 2),
                {"long_name": "body angular momentum M = I Omega (body frame)", "units": "kg m2 s-1"},
            ),
            "m": (
                bdim + ("time", "axis"),
                flat(self.m, 2),
                {"long_name": "spatial angular momentum m = R I Omega (space frame)", "units": "kg m2 s-1"},
            ),
            "energy": (
                bdim + ("time",),
                flat(self.energy, 1),
                {
                    "long_name": (
                        "kinetic energy E = Omega.I Omega/2"
                        if self.model.is_free
                        else "energy E = Omega.I Omega/2 + U (kinetic plus the potential of the torques)"
                    ),
                    "units": "J",
                },
            ),
            "gibbs": (
                bdim + ("time", "axis"),
                flat(self.gibbs, 2),
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
        if self.body.positions is not None and not bshape:
            data["particle_masses"] = (("particle",), self.body.masses, {"long_name": "point masses", "units": "kg"})
            data["particle_positions"] = (
                ("particle", "axis"),
                self.body.positions,
                {"long_name": "particle positions relative to the centre of mass at t = 0 (body frame)", "units": "m"},
            )
            data["center_of_mass"] = (
                ("axis",),
                self.body.center_of_mass,
                {"long_name": "centre of mass", "units": "m"},
            )
        coords = {
            "time": ("time", self.t, {"long_name": "time", "units": "s", "standard_name": "time"}),
            "quat": ("quat", np.array(["w", "x", "y", "z"])),
            "axis": ("axis", np.array(["x", "y", "z"])),
            "axis2": ("axis2", np.array(["x", "y", "z"])),
        }
        attrs = {
            "title": (
                f"free rigid body trajectory ({self.method})"
                if self.model.is_free
                else f"rigid body under torque: {self.model.describe()} ({self.method})"
            ),
            "torque": json.dumps(_torque_records(self.model.torques)),
            "Conventions": "CF-1.10",
            "eulerpoisson_conventions": CONVENTIONS,
            "eulerpoisson_format_version": FORMAT_VERSION,
            "eulerpoisson_version": __version__,
            "method": self.method,
            "method_options": json.dumps(self.options, default=float, sort_keys=True),
            "stats": json.dumps(self.stats, default=float, sort_keys=True),
            "batch_shape": json.dumps(list(bshape)),
            "body_name": self.body.name or "",
            "T": T,
            "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} written by eulerpoisson {__version__}",
            "references": "A. A. Deriglazov, Geodesic motion on the symplectic leaf of SO(3) ... (the paper)",
        }
        return data, coords, attrs

    def to_netcdf(self, path: str | os.PathLike[str]) -> None:
        """Write the trajectory to a NetCDF-4 file, atomically (temporary file, then rename).

        Raises
        ------
        MissingDependencyError
            If xarray or h5netcdf is missing (extra ``io``).
        """
        import io

        h5netcdf = require("h5netcdf", "io")
        content, coords, attrs = self._netcdf_content()
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
        from .io.atomic import write_error

        with atomic_path(path) as tmp:
            try:
                with open(tmp, "wb") as fh:
                    fh.write(data)
            except OSError as exc:
                raise write_error(path, exc) from None

    @classmethod
    def from_netcdf(cls, path: str | os.PathLike[str]) -> Trajectory:
        """Read a trajectory written by :meth:`to_netcdf`.

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
            are not the JSON written by :meth:`to_netcdf`, variables whose
            shapes do not match ``batch_shape`` and the number of times, or
            values the constructors reject (NaN, a non-physical inertia
            tensor: :class:`InvalidInertiaError`), or a stored ``M`` that
            disagrees with ``inertia @ omega`` (an edited file).
        MissingDependencyError
            If xarray or h5netcdf is missing (extra ``io``).
        """
        import os

        if not isinstance(path, (str, bytes, os.PathLike)):
            raise TypeError(f"path must be a file name (str or os.PathLike), got {type(path).__name__} {path!r}")
        if isinstance(path, bytes):
            path = os.fsdecode(path)  # named as text in the messages below, not b'...'
        xr = require("xarray", "io")
        if not os.path.exists(path):
            raise FileNotFoundError(f"no such file: {path}")
        try:
            from .io.read import netcdf_engine  # NetCDF-3 (classic) files through scipy, NetCDF-4 through h5netcdf

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
        from .attitude.core import UNIT_QUATERNION_TOLERANCE

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
            traj = cls(
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

    @classmethod
    def open(cls, path: str | os.PathLike[str]) -> Trajectory | LazyTrajectory:
        """Open a trajectory file of any format eulerpoisson writes, by its content.

        NetCDF-4 (:meth:`to_netcdf`) and NetCDF-3 classic files are read into
        memory (:meth:`from_netcdf`); a Zarr store written by
        ``simulate --out run.zarr`` (:func:`eulerpoisson.io.stream.solve_to_file`)
        gives a :class:`eulerpoisson.io.read.LazyTrajectory`, which reads
        the metadata and the first and last samples now and the others on
        demand (``lazy[a:b]``,
        ``lazy.iter_chunks()``, ``lazy.load()``; plots draw it chunk by chunk).

        Raises
        ------
        TypeError, FileNotFoundError, EulerPoissonError, InvalidInputError, MissingDependencyError
            As :func:`eulerpoisson.io.read.open_trajectory`.
        """
        from .io.read import open_trajectory

        return open_trajectory(path)

    # ------------------------------------------------------------------
    # selecting and evaluating
    # ------------------------------------------------------------------
    def __getitem__(self, index: Any) -> Trajectory:
        """The samples ``index`` (an int, a slice, an integer or boolean array) of the time axis.

        ``len(tr)`` is the number of output times and ``tr[i]`` the trajectory
        reduced to sample ``i`` (for every body of a batch); ``tr[::10]``
        thins it. Select a time by value with :meth:`sel`, evaluate at any
        time with ``tr(t)``.

        Raises
        ------
        TypeError
            A float or a tuple index.
        IndexError
            Out of range.
        """
        if isinstance(index, (tuple, float, np.floating, str)) or isinstance(index, (bool, np.bool_)):
            raise TypeError(
                f"a trajectory is indexed by sample (int, slice or integer array), got {index!r}; "
                f"select by time with tr.sel(t=...) or evaluate with tr(t)"
            )
        idx = np.arange(self.t.shape[0])[index]
        idx = np.atleast_1d(idx)
        return Trajectory(
            self.t[idx],
            self.quaternion[..., idx, :],
            self.omega[..., idx, :],
            self.body,
            self.method,
            self.options,
            self.stats,
            torque=list(self.model.torques),
        )

    def sel(self, t: ArrayLike, method: str | None = None) -> Trajectory:
        """The samples at the output times ``t`` (exact match, or ``method="nearest"``).

        Parameters
        ----------
        t : float or array_like
            Times to select.
        method : {None, "nearest"}
            None: every time must be one of the output times.

        Raises
        ------
        KeyError
            A time that is not an output time (with ``method=None``).
        ValueError
            An unknown ``method``; an empty trajectory.
        """
        want = np.atleast_1d(as_float_array(t, "t"))
        if self.t.size == 0:
            raise ValueError("sel() on a trajectory with no output times")
        if method not in (None, "nearest"):
            raise ValueError(f"sel(method=...) must be None or 'nearest', got {method!r}")
        order = np.argsort(self.t, kind="stable")
        ts = self.t[order]
        pos = np.clip(np.searchsorted(ts, want), 0, ts.size - 1)
        left = np.clip(pos - 1, 0, ts.size - 1)
        pick = np.where(np.abs(ts[left] - want) < np.abs(ts[pos] - want), left, pos)
        if method is None and np.any(ts[pick] != want):
            bad = float(want[ts[pick] != want][0])
            raise KeyError(
                f"t = {bad!r} is not an output time of this trajectory; use sel(t, method='nearest') "
                f"or evaluate it with tr({bad!r})"
            )
        return self[order[pick]]

    def __call__(self, t: ArrayLike, **options: Any) -> Trajectory:
        r"""The motion at any times ``t``: recomputed from the first sample by the trajectory's method.

        The closed form (``exact``) evaluates the same solution at the new
        times; an integrator integrates again from ``t[0]`` with the same
        options (its error is of the same size as the trajectory's own).
        Time-dependent torques are continued at the right phase. ``options``
        override the method's options.

        Parameters
        ----------
        t : float or array_like, shape (T,)
            Any times (before ``t[0]`` too).

        Returns
        -------
        Trajectory

        Raises
        ------
        InvalidInputError
            An empty trajectory, or a method that is not known.
        """
        from .io.stream import solve_from
        from .solvers import available_methods

        if self.t.size == 0:
            raise InvalidInputError("a trajectory with no output times cannot be evaluated: it has no state")
        i0 = int(np.argmin(self.t))
        method = self.method if self.method in available_methods() else ("exact" if self.model.is_free else "taylor")
        opts = {**({} if method != self.method else self.options), **options}
        times = np.atleast_1d(as_float_array(t, "t"))
        return solve_from(
            self.model,
            times,
            float(self.t[i0]),
            self.quaternion[..., i0, :],
            self.omega[..., i0, :],
            method=method,
            **opts,
        )

    def plot(self, kind: str = "omega", **kwargs: Any) -> Figure:
        """A picture of the trajectory: :func:`eulerpoisson.viz.plots.plot` (``kind``: omega, invariants,
        polhode, gibbs, attitude, apex); returns the matplotlib figure (or writes ``out=`` when given)."""
        from .viz import plots

        return plots.plot(self, kind, **kwargs)

    def __repr__(self) -> str:
        b = f", batch_shape={self.batch_shape}" if self.batch_shape else ""
        span = f"[{self.t.min():.6g}, {self.t.max():.6g}]" if self.t.size else "[]"
        return f"Trajectory(method={self.method!r}, T={len(self.t)}, t={span}{b})"

    def _repr_html_(self) -> str:
        """A compact HTML table and a small inline SVG picture of Ω(t) and of the energy, for notebooks.

        See :func:`eulerpoisson.util.htmlrepr.trajectory_html` (no matplotlib; decimated, a few kB at any length).
        """
        from .util.htmlrepr import trajectory_html

        return trajectory_html(self)


def _torque_records(torques) -> list[dict]:
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
    from .model.torques import Torque, UnrecordedTorque, torque_from_dict

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
