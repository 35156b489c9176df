r"""Runs of other simulators: reading them (CSV, NetCDF, JSON) and putting them in eulerpoisson's conventions.

A *run* is a sampled attitude and angular velocity of one free body: times
:math:`t_i`, quaternions and angular velocities, written by a physics engine
or an attitude simulator in its own conventions. :func:`read_run` reads the
numbers as they are written (:class:`RawRun`); :func:`normalize_run` turns
them, under stated :class:`Conventions`, into eulerpoisson's: scalar-first
unit quaternions ``(w, x, y, z)`` of the rotation body -> space
(:math:`\mathbf x_\mathrm{space} = R\mathbf x_\mathrm{body}`) and the body
angular velocity :math:`\boldsymbol\Omega`.

The conventions that differ between simulators:

- quaternion order: scalar first ``wxyz`` (eulerpoisson, MuJoCo, Eigen's
  constructor) or scalar last ``xyzw`` (scipy, ROS, Unity, PyBullet);
- attitude: body-to-space (``x_space = R x_body``) or space-to-body (the
  conjugate quaternion, e.g. some aerospace "navigation to body" outputs);
- angular velocity frame: body (:math:`\boldsymbol\Omega`) or space
  (:math:`\boldsymbol\omega = R\boldsymbol\Omega`).

References
----------
M. D. Shuster, "A survey of attitude representations", J. Astronaut. Sci. 41
(1993) 439-517 (the conventions and their traps).
"""

from __future__ import annotations

import csv
import itertools
import json
import os
from dataclasses import dataclass, replace
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import matrix_from_unit_quaternion
from ..errors import InvalidInputError

# the readings of a run's numbers, one list with the observations that ``fit`` reads: quaternion component orders
# accepted by the flags (the column names may give any permutation), and what the quaternion rotates (body to
# space, x_space = R x_body, eulerpoisson's; or space to body)
from ..io.observations import ATTITUDE_CONVENTIONS, QUATERNION_ORDERS

__all__ = [
    "Conventions",
    "RawRun",
    "read_run",
    "run_from_arrays",
    "normalize_run",
    "QUATERNION_ORDERS",
    "OMEGA_FRAMES",
    "ATTITUDE_CONVENTIONS",
    "NORM_TOLERANCE",
    "CSV_HEADER",
]

#: frames of the angular velocity
OMEGA_FRAMES = ("body", "space")
#: a quaternion whose norm differs from 1 by more than this is refused (a run's quaternions are rotations)
NORM_TOLERANCE = 1e-3
#: the header of a run in eulerpoisson's conventions
CSV_HEADER = ("t", "qw", "qx", "qy", "qz", "wx", "wy", "wz")

_TIME_NAMES = ("t", "time")
_Q_LETTER = {f"q{c}": c for c in "wxyz"} | {f"quat_{c}": c for c in "wxyz"}
_Q_POSITIONAL = ("q0", "q1", "q2", "q3")
_W_NAMES = {}
for _c in "xyz":
    for _pre in ("w", "omega_", "omega", "w_"):
        _W_NAMES[f"{_pre}{_c}"] = _c


@dataclass(frozen=True)
class Conventions:
    """The conventions a run is read in.

    Parameters
    ----------
    quaternion_order : str or None
        ``"wxyz"`` (scalar first) or ``"xyzw"`` (scalar last) for the four
        quaternion columns in the order they appear in the file; None: as the
        column names say (``qw,qx,qy,qz`` in any order; ``q0..q3`` are scalar
        first).
    omega_frame : str
        ``"body"`` or ``"space"``.
    attitude_convention : str
        ``"body-to-space"`` or ``"space-to-body"``.

    Raises
    ------
    InvalidInputError
        A value outside the lists above.

    Examples
    --------
    >>> from eulerpoisson.oracle import Conventions
    >>> Conventions(quaternion_order="xyzw", omega_frame="space")
    Conventions(quaternion_order='xyzw', omega_frame='space', attitude_convention='body-to-space')
    >>> try:
    ...     Conventions(omega_frame="inertial")
    ... except ValueError as err:
    ...     print(err)
    omega_frame must be one of 'body', 'space', got 'inertial'
    """

    quaternion_order: str | None = None
    omega_frame: str = "body"
    attitude_convention: str = "body-to-space"

    def __post_init__(self):
        for name, value, allowed in (
            ("quaternion_order", self.quaternion_order, QUATERNION_ORDERS + (None,)),
            ("omega_frame", self.omega_frame, OMEGA_FRAMES),
            ("attitude_convention", self.attitude_convention, ATTITUDE_CONVENTIONS),
        ):
            if value not in allowed:
                shown = ", ".join(repr(a) for a in allowed if a is not None)
                raise InvalidInputError(f"{name} must be one of {shown}, got {value!r}")

    def to_dict(self) -> dict:
        """The three conventions as a JSON-able dict."""
        return {
            "quaternion_order": self.quaternion_order,
            "omega_frame": self.omega_frame,
            "attitude_convention": self.attitude_convention,
        }


@dataclass(frozen=True, eq=False)
class RawRun:
    """A run's numbers as written, before any convention is applied.

    Attributes
    ----------
    t : ndarray, shape (T,)
        Times, strictly increasing.
    quaternion : ndarray, shape (T, 4)
        The four quaternion columns in the order of the file.
    omega : ndarray, shape (T, 3)
        Angular velocity (x, y, z), in the frame the run uses.
    label_order : str
        The component order the file's names say (``"wxyz"`` when they do not say).
    source : str
        File name or ``"arrays"``.
    inertia : ndarray or None
        The inertia the file states (an eulerpoisson NetCDF file), else None.
    quaternion_columns : tuple of str
        The names of the quaternion columns.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.oracle import run_from_arrays
    >>> raw = run_from_arrays([0.0, 1.0], [[1.0, 0.0, 0.0, 0.0], [0.9, 0.1, 0.0, 0.0]], [[0.2, 0.0, 0.0]] * 2)
    >>> type(raw).__name__, raw.t.shape, raw.quaternion.shape, raw.label_order, raw.source
    ('RawRun', (2,), (2, 4), 'wxyz', 'arrays')
    """

    t: np.ndarray
    quaternion: np.ndarray
    omega: np.ndarray
    label_order: str = "wxyz"
    source: str = "arrays"
    inertia: np.ndarray | None = None
    quaternion_columns: tuple = ("qw", "qx", "qy", "qz")

    def __len__(self) -> int:
        return self.t.shape[0]

    def head(self, n: int) -> RawRun:
        """The first ``n`` samples."""
        return replace(self, t=self.t[:n], quaternion=self.quaternion[:n], omega=self.omega[:n])


def _check_arrays(t, q, w, source: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    try:
        t = np.asarray(t, dtype=float)
        q = np.asarray(q, dtype=float)
        w = np.asarray(w, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{source}: the samples must be numbers ({exc})") from None
    if t.ndim != 1 or q.shape != t.shape + (4,) or w.shape != t.shape + (3,):
        raise InvalidInputError(
            f"{source}: expected times (T,), quaternions (T, 4) and angular velocities (T, 3); "
            f"got shapes {t.shape}, {q.shape}, {w.shape}"
        )
    if t.size < 2:
        raise InvalidInputError(f"{source}: a run needs at least 2 samples, got {t.size}")
    for name, a in (("t", t), ("quaternion", q), ("angular velocity", w)):
        bad = ~np.isfinite(a.reshape(t.size, -1)).all(axis=1)
        if bad.any():
            i = int(np.argmax(bad))
            raise InvalidInputError(f"{source}: {name} of sample {i} (t = {float(t[i])!r}) is not finite (NaN or inf)")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise InvalidInputError(
            f"{source}: times must increase strictly; sample {i} has t = {float(t[i])!r} after "
            f"t = {float(t[i - 1])!r} (sort the run, or drop repeated samples)"
        )
    return t, q, w


def run_from_arrays(
    t: ArrayLike, quaternion: ArrayLike, omega: ArrayLike, *, quaternion_order: str = "wxyz", source: str = "arrays"
) -> RawRun:
    """A :class:`RawRun` from arrays.

    Parameters
    ----------
    t : array_like, shape (T,)
        Strictly increasing times, T >= 2.
    quaternion : array_like, shape (T, 4)
        Quaternions in ``quaternion_order``.
    omega : array_like, shape (T, 3)
        Angular velocities.
    quaternion_order : str
        The order of the quaternion components (``"wxyz"`` or ``"xyzw"``).
    source : str
        Name used in messages.

    Returns
    -------
    RawRun

    Raises
    ------
    InvalidInputError
        Wrong shapes, fewer than 2 samples, NaN or inf, times that do not increase strictly.

    Examples
    --------
    >>> from eulerpoisson.oracle import run_from_arrays
    >>> raw = run_from_arrays([0.0, 1.0], [[0.0, 0.0, 0.0, 1.0]] * 2, [[0.0, 0.0, 0.0]] * 2, quaternion_order="xyzw")
    >>> raw.quaternion[0], raw.label_order
    (array([0., 0., 0., 1.]), 'xyzw')
    >>> try:
    ...     run_from_arrays([1.0, 0.0], [[1.0, 0.0, 0.0, 0.0]] * 2, [[0.0, 0.0, 0.0]] * 2)
    ... except ValueError as err:
    ...     print(err)
    arrays: times must increase strictly; sample 1 has t = 0.0 after t = 1.0 (sort the run, or drop repeated samples)
    """
    if quaternion_order not in QUATERNION_ORDERS:
        raise InvalidInputError(
            f"quaternion_order must be one of {', '.join(QUATERNION_ORDERS)}, got {quaternion_order!r}"
        )
    t, q, w = _check_arrays(t, quaternion, omega, source)
    return RawRun(
        t,
        q,
        w,
        label_order=quaternion_order,
        source=source,
        quaternion_columns=tuple(f"q{c}" for c in quaternion_order),
    )


def _columns(names: list[str], source: str) -> tuple[int, list[int], str, list[int]]:
    """Indices of the time, quaternion (file order) and angular velocity (x, y, z) columns, and the label order."""
    low = [n.strip().lower() for n in names]
    missing = []
    it = next((i for i, n in enumerate(low) if n in _TIME_NAMES), None)
    if it is None:
        missing.append("t")
    qi = [i for i, n in enumerate(low) if n in _Q_LETTER]
    if len(qi) == 4 and {_Q_LETTER[low[i]] for i in qi} == set("wxyz"):
        order = "".join(_Q_LETTER[low[i]] for i in qi)
    else:
        qi = [low.index(n) for n in _Q_POSITIONAL if n in low]
        order = "wxyz"
        if len(qi) != 4:
            have = {_Q_LETTER[n] for n in low if n in _Q_LETTER}
            missing += [f"q{c}" for c in "wxyz" if c not in have]
    wi = []
    for c in "xyz":
        j = next((i for i, n in enumerate(low) if _W_NAMES.get(n) == c), None)
        if j is None:
            missing.append(f"w{c}")
        wi.append(j)
    if missing:
        raise InvalidInputError(
            f"{source}: missing column(s) {', '.join(missing)} (expected a header like "
            f"{','.join(CSV_HEADER)}; got {','.join(names)})"
        )
    return cast(int, it), qi, order, cast("list[int]", wi)  # none missing: all found


def _read_csv(path: str) -> RawRun:
    with open(path, newline="", encoding="utf-8-sig") as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.lstrip().startswith("#")) if r]
    if not rows:
        raise InvalidInputError(f"{path}: empty file (expected a header {','.join(CSV_HEADER)} and samples)")
    header, data = rows[0], rows[1:]
    it, qi, order, wi = _columns(header, path)
    try:  # the fast path: a clean numeric table
        vals = np.array(data, dtype=float).reshape(len(data), len(header))
    except ValueError:  # find the row and column to name
        vals = _slow_table(path, header, data)
    t, q, w = _check_arrays(vals[:, it], vals[:, qi], vals[:, wi], path)
    return RawRun(t, q, w, label_order=order, source=path, quaternion_columns=tuple(header[i].strip() for i in qi))


def _slow_table(path: str, header: list, data: list) -> np.ndarray:
    vals = np.empty((len(data), len(header)))
    for r, row in enumerate(data):
        if len(row) != len(header):
            raise InvalidInputError(f"{path}: row {r + 2} has {len(row)} values, the header {len(header)}")
        for c, text in enumerate(row):
            try:
                vals[r, c] = float(text)
            except ValueError:
                raise InvalidInputError(
                    f"{path}: row {r + 2}, column {header[c].strip()}: {text!r} is not a number"
                ) from None
    return vals


def _read_json(path: str) -> RawRun:
    with open(path, encoding="utf-8") as fh:
        try:
            recs = json.load(fh)
        except json.JSONDecodeError as exc:
            raise InvalidInputError(f"{path}: invalid JSON: {exc}") from None
    if not isinstance(recs, list) or not all(isinstance(r, dict) for r in recs) or not recs:
        raise InvalidInputError(
            f"{path}: expected a JSON list of records like "
            '{"t": 0.0, "qw": 1.0, "qx": 0.0, "qy": 0.0, "qz": 0.0, "wx": 0.1, "wy": 0.2, "wz": 0.3}'
        )
    keys = list(recs[0])
    if "quaternion" in keys and "omega" in keys and any(k in keys for k in _TIME_NAMES):
        tk = next(k for k in keys if k in _TIME_NAMES)
        try:
            tl = [r[tk] for r in recs]
            ql = [r["quaternion"] for r in recs]
            wl = [r["omega"] for r in recs]
        except KeyError as exc:
            raise InvalidInputError(f"{path}: a record has no key {exc.args[0]!r}") from None
        t, q, w = _check_arrays(tl, ql, wl, path)
        return RawRun(t, q, w, label_order="wxyz", source=path, quaternion_columns=("quaternion",) * 4)
    it, qi, order, wi = _columns(keys, path)
    try:
        cols = [[r[keys[i]] for r in recs] for i in [it, *qi, *wi]]
    except KeyError as exc:
        raise InvalidInputError(f"{path}: a record has no key {exc.args[0]!r}") from None
    for name, col in zip([keys[i] for i in [it, *qi, *wi]], cols):
        for r, v in enumerate(col):
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise InvalidInputError(f"{path}: record {r}, key {name}: {v!r} is not a number")
    t, q, w = _check_arrays(cols[0], np.array(cols[1:5]).T, np.array(cols[5:8]).T, path)
    return RawRun(t, q, w, label_order=order, source=path, quaternion_columns=tuple(keys[i] for i in qi))


def _read_netcdf(path: str) -> RawRun:
    from ..trajectory import Trajectory

    tr = Trajectory.from_netcdf(path)
    if tr.batch_shape:
        raise InvalidInputError(f"{path}: a batch of {tr.batch_shape} bodies; a run is one body")
    t, q, w = _check_arrays(tr.t, tr.quaternion, tr.omega, path)
    return RawRun(t, q, w, label_order="wxyz", source=path, inertia=np.array(tr.body.inertia))


def read_run(path: str | os.PathLike[str]) -> RawRun:
    """Read a run: a CSV file, an eulerpoisson NetCDF trajectory or a JSON list of records.

    Parameters
    ----------
    path : str or os.PathLike
        ``.csv`` (a header ``t,qw,qx,qy,qz,wx,wy,wz``, any column order,
        extra columns ignored, ``#`` comment lines skipped; ``time``,
        ``q0..q3``, ``omega_x..`` are accepted names), ``.nc`` (written by
        ``eulerpoisson simulate --out`` or :meth:`Trajectory.to_netcdf`, its
        inertia is read too) or ``.json`` (a list of records with the CSV's
        keys, or ``t``, ``quaternion`` and ``omega`` lists).

    Returns
    -------
    RawRun

    Raises
    ------
    InvalidInputError
        No such file, an unknown extension, missing columns, a value that is
        not a number, fewer than 2 samples, non-finite values, times that do
        not increase strictly.

    Examples
    --------
    >>> from eulerpoisson.oracle import read_run
    >>> with open("run.csv", "w") as fh:
    ...     print("t,qw,qx,qy,qz,wx,wy,wz", file=fh)
    ...     print("0.0,1.0,0.0,0.0,0.0,0.0,0.0,1.0", file=fh)
    ...     print("1.0,0.8775825619,0.0,0.0,0.4794255386,0.0,0.0,1.0", file=fh)
    >>> raw = read_run("run.csv")
    >>> print(raw.t, raw.quaternion_columns, raw.omega[-1])
    [0. 1.] ('qw', 'qx', 'qy', 'qz') [0. 0. 1.]
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise InvalidInputError(f"{path}: no such file")
    if os.path.isdir(path):
        raise InvalidInputError(f"{path} is a directory, not a run (CSV, NetCDF or JSON)")
    ext = os.path.splitext(path)[1].lower()
    try:
        if ext in (".csv", ".txt"):
            return _read_csv(path)
        if ext == ".json":
            return _read_json(path)
    except UnicodeDecodeError as exc:
        raise InvalidInputError(
            f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start}); a run's {ext[1:].upper()} file must be "
            f"UTF-8: save it as UTF-8 (e.g. iconv -f latin1 -t utf-8 {path} > utf8{ext})"
        ) from None
    if ext in (".nc", ".nc4", ".netcdf"):
        return _read_netcdf(path)
    raise InvalidInputError(
        f"{path}: unknown file type {ext or '(none)'!r}; a run is a .csv, .nc (NetCDF) or .json file"
    )


def _permutation(order: str) -> list[int]:
    """Column indices (in file order) of w, x, y, z for a file whose quaternion columns are ``order``."""
    return [order.index(c) for c in "wxyz"]


def normalize_run(
    raw: RawRun, conventions: Conventions | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""The run in eulerpoisson's conventions.

    Parameters
    ----------
    raw : RawRun
        The numbers as written.
    conventions : Conventions, optional
        How to read them (default: the names' quaternion order, body-frame
        rates, body-to-space attitude).

    Returns
    -------
    t : ndarray, shape (T,)
    quaternion : ndarray, shape (T, 4)
        Unit, scalar first, body to space.
    omega : ndarray, shape (T, 3)
        Body angular velocity :math:`\boldsymbol\Omega = R^\mathsf{T}\boldsymbol\omega` for space-frame rates.

    Raises
    ------
    InvalidInputError
        A quaternion whose norm differs from 1 by more than :data:`NORM_TOLERANCE`.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.oracle import Conventions, normalize_run, run_from_arrays
    >>> raw = run_from_arrays([0.0, 1.0], [[0.0, 0.0, 0.0, 1.0]] * 2, [[0.0, 0.0, 0.5]] * 2, quaternion_order="xyzw")
    >>> t, q, w = normalize_run(raw, Conventions(quaternion_order="xyzw"))
    >>> print(q[0], w[0])                                              # scalar first, body rates
    [1. 0. 0. 0.] [0.  0.  0.5]
    """
    conv = conventions or Conventions()
    order = conv.quaternion_order or raw.label_order
    q = raw.quaternion[:, _permutation(order)]
    nrm = np.sqrt(np.sum(q * q, axis=1))
    off = np.abs(nrm - 1.0)
    if np.any(off > NORM_TOLERANCE):
        i = int(np.argmax(off > NORM_TOLERANCE))
        raise InvalidInputError(
            f"{raw.source}: the quaternion of sample {i} (t = {raw.t[i]:.6g}) has norm {nrm[i]:.9g}, far from 1 "
            f"(tolerance {NORM_TOLERANCE:g}): not a rotation; are these columns a quaternion?"
        )
    q = q / nrm[:, None]
    if conv.attitude_convention == "space-to-body":
        q = q * np.array([1.0, -1.0, -1.0, -1.0])
    w = raw.omega
    if conv.omega_frame == "space":
        R = matrix_from_unit_quaternion(q)
        w = np.einsum("tji,tj->ti", R, w)
    return raw.t, q, np.array(w, dtype=float)


def all_conventions(raw: RawRun) -> list[Conventions]:
    """Every explicit reading of a run (2 orders x 2 frames x 2 attitude conventions), the label order first."""
    other = "xyzw" if raw.label_order == "wxyz" else "wxyz"
    orders = [raw.label_order if raw.label_order in QUATERNION_ORDERS else "wxyz", other]
    return [Conventions(o, f, a) for o, f, a in itertools.product(orders, OMEGA_FRAMES, ATTITUDE_CONVENTIONS)]
