r"""Stream very long solutions to disk, chunk by chunk (Zarr).

:func:`solve_to_file` computes the motion at :math:`10^8` output times (or
more) without ever holding them in memory: the output times are produced
and solved one chunk at a time, and every finished chunk is written to a
`Zarr <https://zarr.dev>`_ store at once. The peak memory is set by the
chunk length (about 1 kB per sample of the chunk, i.e. ~100 MB for the
default ``chunk=100_000``), not by the length of the run.

The store has the variables, dimensions and attributes of
:meth:`Trajectory.to_xarray <eulerpoisson.trajectory.Trajectory.to_xarray>`
(``quaternion``, ``omega``, ``M``, ``m``, ``energy``, ``gibbs`` over
``time``; ``inertia``; the coordinates ``time``, ``quat``, ``axis``,
``axis2``; a ``body`` dimension for a batch of bodies), so that
``xarray.open_zarr(path)`` reads it lazily (with dask) as it would read the
dataset of a small run. The attribute ``T`` is the total number of samples
and ``stream_chunk`` the chunk length, which is also the Zarr chunk along
``time``.

Output times
------------
``t`` is one of

* a ``tuple`` ``(t0, t1, n)``: ``n`` equally spaced times from ``t0`` to
  ``t1`` inclusive, generated lazily chunk by chunk (a :class:`TimeGrid`; its
  values are bit-for-bit those of ``numpy.linspace(t0, t1, n)``);
* a :class:`TimeGrid` (the same thing, built explicitly);
* any 1-D array-like that supports ``len`` and slicing and returns numbers
  (a NumPy array, a ``numpy.memmap``, a Zarr or HDF5 array): it is read one
  chunk at a time, so it may itself live on disk. Only a *tuple* of three
  numbers is read as ``(t0, t1, n)``; a list or an array is a list of times.

Closed-form and stepping methods
--------------------------------
For a closed-form method (a registered method whose ``order`` is ``None``,
i.e. ``"exact"``) every chunk is solved independently from the initial
state at :math:`t=0`, so the output is *identical* to a single
:func:`~eulerpoisson.solve` call on all the times (the closed form
costs O(1) per time and has no state to carry).

For a stepping method (``"rk"``, ``"taylor"``, ``"symplectic"``, ...) the
times must be strictly monotonic and chunk :math:`k>0` is solved from the
last state of chunk :math:`k-1`: with :math:`\tau_k` that last time and
:math:`(q, \boldsymbol\Omega)` the state there,
``solve(body, t_chunk - tau_k, attitude0=q, omega0=Omega)`` (the free body,
and a body under time-independent torques, is autonomous, so shifting time
is exact; a time-dependent torque is shifted with it, see
:func:`solve_from`). The result is *consistent* —
the same integrator at the same settings, restarted at the chunk
boundaries — but not bitwise equal to one long integration: an adaptive
step-size controller restarts at each boundary and a fixed-step method
re-aligns its steps there. The difference is of the order of the method's
own error.

Atomic output, interruption and resuming
----------------------------------------
Everything is written into a work folder ``.NAME.partial`` next to
``path`` (the store itself is ``.NAME.partial/store.zarr``); only when all
chunks are done is the store renamed to ``path``. A finished chunk is
recorded by a marker file (``.NAME.partial/done/CHUNK``) written *after*
its data, so on Ctrl-C (or a crash, or a kill) nothing finished is lost:

* the completed chunks are readable in the partial store, e.g.
  ``xarray.open_zarr(partial_store(path))`` (samples of unfinished chunks
  read as NaN);
* rerunning the same call with ``resume=True`` checks that the arguments
  are the same (a fingerprint of body, initial state, times, method,
  options, chunk and variables is kept in ``.NAME.partial/state.json``) and
  computes only the missing chunks; a stepping method continues from the
  last stored state. Without ``resume=True`` a leftover partial store is an
  error (pass ``overwrite=True`` to discard it and start again);
  ``resume=True`` with no partial store simply starts the run. A work
  folder whose ``state.json`` is missing (interrupted while the empty store
  was being created, before any chunk) is discarded.

Reading a store with :math:`10^8` samples: ``xarray.open_zarr`` loads the
``time`` coordinate into memory to index it (800 MB for :math:`10^8`
samples); pass ``drop_variables=["time"]`` or read the arrays with
``zarr.open_group`` to avoid it.

Examples
--------
>>> from eulerpoisson.io.stream import solve_to_file
>>> solve_to_file([1, 2, 3], (0.0, 1e4, 10**8), "long.zarr",
...               omega0=[1.0, 0.1, 0.5], chunk=10**5)          # doctest: +SKIP
PosixPath('long.zarr')

References
----------
Zarr storage specification version 3, https://zarr-specs.readthedocs.io.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import numbers
import os
import shutil
import sys
import time as _time
import warnings
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import EulerPoissonError, InvalidInputError, require

if TYPE_CHECKING:
    from ..attitude.core import AttitudeLike
    from ..model.body import RigidBody
    from ..model.equations import Model
    from ..model.torques import TorqueLike
    from ..trajectory import Trajectory

__all__ = ["TimeGrid", "solve_to_file", "solve_from", "partial_store", "TIME_VARIABLES"]

#: the time-dependent variables of :meth:`Trajectory.to_xarray`, all written by default
TIME_VARIABLES = ("quaternion", "omega", "M", "m", "energy", "gibbs")

_STATE_VERSION = 1


# ---------------------------------------------------------------------------
# output times
# ---------------------------------------------------------------------------
class TimeGrid:
    r"""``n`` equally spaced times from ``t0`` to ``t1`` (inclusive), generated on demand.

    Behaves as a read-only 1-D float64 sequence: ``len(grid)`` and
    ``grid[a:b]`` (an ndarray computed on the fly, equal bit for bit to
    ``numpy.linspace(t0, t1, n)[a:b]``). Nothing of size ``n`` is ever
    allocated.

    Parameters
    ----------
    t0, t1 : float
        First and last time (finite; ``t1 < t0`` runs backwards).
    n : int
        Number of times, >= 1.

    Raises
    ------
    InvalidInputError
        Non-finite ``t0``/``t1`` or ``n < 1``.
    TypeError
        Non-numeric arguments or a non-integer ``n``.

    Examples
    --------
    >>> g = TimeGrid(0.0, 1.0, 5)
    >>> len(g), g[1:3].tolist()
    (5, [0.25, 0.5])
    """

    def __init__(self, t0, t1, n) -> None:  # float, float, int: anything else is refused below
        for name, v in (("t0", t0), ("t1", t1)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise TypeError(f"t: {name} must be a real number, got {type(v).__name__} {v!r}")
            if not np.isfinite(v):  # type: ignore[call-overload]  # mypy types no numbers.Real as a float
                raise InvalidInputError(f"t: {name} must be finite, got {v!r}")
        if isinstance(n, bool) or not isinstance(n, numbers.Integral):
            if isinstance(n, numbers.Real) and float(n) == int(n):  # type: ignore[call-overload]
                n = int(n)  # type: ignore[call-overload]
            else:
                raise TypeError(f"t: the number of samples n must be an integer, got {n!r}")
        if n < 1:
            raise InvalidInputError(f"t: the number of samples n must be >= 1, got {n}")
        self.t0, self.t1, self.n = float(t0), float(t1), int(n)
        div = self.n - 1
        self._delta = self.t1 - self.t0
        self._step = self._delta / div if div > 0 else np.nan

    def __len__(self) -> int:
        return self.n

    @property
    def shape(self) -> tuple[int]:
        return (self.n,)

    @overload
    def __getitem__(self, idx: slice) -> NDArray[np.float64]: ...
    @overload
    def __getitem__(self, idx: int | np.integer) -> float: ...
    @overload
    def __getitem__(self, idx: ArrayLike) -> float | NDArray[np.float64]: ...
    def __getitem__(self, idx: int | slice | ArrayLike) -> float | NDArray[np.float64]:
        if isinstance(idx, slice):
            a, b, s = idx.indices(self.n)
            i = np.arange(a, b, s, dtype=np.float64)
        else:
            i = np.asarray(idx)
            if not np.issubdtype(i.dtype, np.integer):
                raise TypeError(f"TimeGrid indices must be integers or slices, got {idx!r}")
            i = np.where(i < 0, i + self.n, i)
            if np.any((i < 0) | (i >= self.n)):
                raise IndexError(f"TimeGrid index out of range for n = {self.n}")
            i = i.astype(np.float64)
        if self.n == 1:
            y = i * self._delta
        elif self._step == 0:  # denormal step, as numpy.linspace
            y = i / (self.n - 1) * self._delta
        else:
            y = i * self._step
        y = y + self.t0
        if self.n > 1:
            y = np.where(i == self.n - 1, self.t1, y)
        return y if y.ndim else float(y)

    def __repr__(self) -> str:
        return f"TimeGrid({self.t0!r}, {self.t1!r}, {self.n})"


def _as_time_source(t):
    if isinstance(t, TimeGrid):
        return t
    if isinstance(t, tuple):
        if len(t) != 3:
            raise InvalidInputError(
                f"t: a tuple is read as (t0, t1, n), got a tuple of length {len(t)}; "
                "pass a list or an array for explicit times"
            )
        return TimeGrid(*t)
    if isinstance(t, (str, bytes)):
        raise TypeError(f"t must be (t0, t1, n), a TimeGrid or a 1-D array of times, got the string {t!r}")
    if isinstance(t, (list, numbers.Real)) or not hasattr(t, "__getitem__"):
        t = np.atleast_1d(np.asarray(t))
    shape = getattr(t, "shape", None)
    if shape is None:
        shape = (len(t),)
    if len(shape) != 1:
        raise InvalidInputError(f"t must be a 1-D array of output times, got shape {tuple(shape)}")
    if shape[0] < 1:
        raise InvalidInputError("t is empty: give at least one output time")
    return t


def _read_times(src, a: int, b: int) -> np.ndarray:
    from ..util.validate import as_float_array

    return as_float_array(np.asarray(src[a:b]), f"t[{a}:{b}]").reshape(-1)


def _times_fingerprint(src, chunk: int) -> dict:
    if isinstance(src, TimeGrid):
        return {"grid": [src.t0, src.t1, src.n]}
    h = hashlib.sha256()
    n = len(src)
    for a in range(0, n, chunk):
        h.update(_read_times(src, a, min(n, a + chunk)).tobytes())
    return {"array": n, "sha256": h.hexdigest()}


# ---------------------------------------------------------------------------
# progress display (shared with eulerpoisson.sweep)
# ---------------------------------------------------------------------------
class ProgressDisplay:
    """A rich progress bar on a terminal, a user callback, or nothing.

    ``progress`` is None (a bar when stderr is a terminal and rich is
    installed, else quiet), True (a bar if rich is installed), False (quiet)
    or a callable ``progress(done, total)``.
    """

    def __init__(self, progress, total: int, description: str):
        self.total = total
        self.callback = None
        self._bar = None
        if callable(progress):
            self.callback = progress
            return
        if progress is None:
            progress = sys.stderr.isatty()
        if progress is False:
            return
        if progress is not True:
            raise TypeError(f"progress must be None, True, False or a callable(done, total), got {progress!r}")
        try:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
        except ImportError:  # pragma: no cover - rich is optional
            return
        self._bar = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=False,
        )
        self._task = self._bar.add_task(description, total=total)

    def __enter__(self):
        if self._bar is not None:
            self._bar.start()
        return self

    def update(self, done: int) -> None:
        if self._bar is not None:
            self._bar.update(self._task, completed=done)
        if self.callback is not None:
            self.callback(done, self.total)

    def __exit__(self, *exc):
        if self._bar is not None:
            self._bar.stop()
        return False


# ---------------------------------------------------------------------------
# work folder
# ---------------------------------------------------------------------------
def work_dir(path: Path) -> Path:
    return path.with_name(f".{path.name}.partial")


def _finished_run(path: Path):
    """The arguments recorded in a finished store (None if there are none or it is not a store of ours)."""
    try:
        zarr = require("zarr", "dask")
        with quiet_zarr():
            g = zarr.open_group(str(path), mode="r")
            raw = g.attrs.get("eulerpoisson_run")
        return json.loads(raw) if isinstance(raw, str) else None
    except Exception:  # noqa: BLE001 - anything unreadable is "not a finished run of ours"
        return None


def partial_store(path: str | os.PathLike[str]) -> Path:
    """The Zarr store where :func:`solve_to_file` keeps the chunks of an unfinished run to ``path``.

    Readable while the run is going on or after it was interrupted
    (``xarray.open_zarr(partial_store(path))``); unfinished samples read as NaN.
    """
    return work_dir(Path(path)) / "store.zarr"


def write_json_atomic(path: Path, obj) -> None:
    from .atomic import atomic_write_text

    atomic_write_text(path, json.dumps(obj, sort_keys=True, indent=1))


def mark_done(work: Path, k: int, info: dict) -> None:
    write_json_atomic(work / "done" / f"{k:09d}", info)


def done_chunks(work: Path) -> set[int]:
    d = work / "done"
    if not d.is_dir():
        return set()
    return {int(p.name) for p in d.iterdir() if p.name.isdigit()}


def _is_zarr_store(path: Path) -> bool:
    """True for a folder holding a Zarr group or array (format 2 or 3 metadata at its top)."""
    return any((path / name).is_file() for name in ("zarr.json", ".zgroup", ".zarray"))


def check_replaceable(dest: Path) -> None:
    """FileExistsError when ``dest`` is a folder that is not a Zarr store (``overwrite`` must not delete it)."""
    if dest.is_dir() and not dest.is_symlink() and not _is_zarr_store(dest):
        raise FileExistsError(
            f"refusing to replace {dest}: it is a folder but not a Zarr store (overwrite only replaces "
            f"earlier results); remove it yourself or choose another path"
        )


def replace_dir(src: Path, dest: Path, overwrite: bool) -> None:
    """Move folder ``src`` to ``dest``; an existing ``dest`` is replaced only with ``overwrite``."""
    if dest.exists() or dest.is_symlink():
        if not overwrite:
            raise FileExistsError(f"{dest} exists; pass overwrite=True to replace it")
        check_replaceable(dest)
        trash = dest.with_name(f".{dest.name}.old-{os.getpid()}")
        os.replace(dest, trash)
        os.replace(src, dest)
        if trash.is_dir() and not trash.is_symlink():
            shutil.rmtree(trash, ignore_errors=True)
        else:
            trash.unlink(missing_ok=True)
    else:
        os.replace(src, dest)


@contextlib.contextmanager
def quiet_zarr():
    """Silence zarr's warnings about v3 extensions (fixed-width strings, consolidated metadata)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*Zarr format 3 specification.*")
        warnings.filterwarnings("ignore", message=".*does not have a Zarr V3 specification.*")
        warnings.filterwarnings("ignore", message=".*Consolidated metadata.*")
        yield


# ---------------------------------------------------------------------------
# continuing a solution from a later state (chunks)
# ---------------------------------------------------------------------------
def _rotation_z(phi) -> np.ndarray:
    """Quaternions (..., 4) of the rotations by ``phi`` about the space z axis."""
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.cos(phi / 2), np.zeros_like(phi), np.zeros_like(phi), np.sin(phi / 2)], -1)


def _rotate_z(v, phi) -> np.ndarray:
    """Space vectors ``v`` (..., 3) rotated by ``phi`` (...) about z."""
    v = np.asarray(v, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack(
        [
            c * v[..., 0] - s * v[..., 1],
            s * v[..., 0] + c * v[..., 1],
            np.broadcast_to(v[..., 2], np.broadcast_shapes(v[..., 2].shape, np.shape(c))),
        ],
        -1,
    )


def _shifted_torques(torques, t_start: float):
    r"""The torques seen from time ``t_start`` on: ``(torques', phi)``.

    With :math:`s = t - t_\mathrm{start}`, the motion under ``torques'``
    from the state at ``t_start`` rotated by :math:`R_z(-\varphi)` is the
    original motion, rotated by :math:`R_z(-\varphi)` in space. A gravity
    gradient of mean motion :math:`\nu` is the same torque in the space frame
    turned by :math:`\varphi = \nu t_\mathrm{start}` (its orbit direction is
    :math:`\hat{\mathbf r}(t_\mathrm{start} + s) = R_z(\varphi)\hat{\mathbf r}(s)`),
    so space-fixed vectors of the other torques (gravity, a space-frame torque)
    are turned by :math:`-\varphi`; a Python function is called at the shifted
    time with the attitude turned back. Body-frame torques are unchanged.

    Raises
    ------
    InvalidInputError
        A time-dependent torque of a class that cannot be shifted.
    """
    from ..model.torques import BodyTorque, CallableTorque, Gravity, GravityGradient, SpaceTorque, Torque
    from ..numerics.quaternion import qmul

    grads = [tq for tq in torques if isinstance(tq, GravityGradient)]
    phi = np.zeros(())
    for tq in grads:
        if np.any(tq.mean_motion != 0):
            phi = np.asarray(tq.mean_motion, dtype=float) * t_start
            break
    turn = bool(np.any(phi != 0))
    out: list[Torque] = []
    for tq in torques:
        if isinstance(tq, (GravityGradient, BodyTorque)):
            out.append(tq)
        elif isinstance(tq, Gravity):
            out.append(Gravity(tq.mass, tq.center_of_mass, _rotate_z(tq.g, -phi)) if turn else tq)
        elif isinstance(tq, SpaceTorque):
            out.append(SpaceTorque(_rotate_z(tq.tau, -phi)) if turn else tq)
        elif isinstance(tq, CallableTorque):
            func, rz = tq.func, _rotation_z(phi)

            def shifted(s, q, omega, _f=func, _rz=rz, _turn=turn):
                return _f(np.asarray(s) + t_start, qmul(_rz, q) if _turn else q, omega)

            shifted.__name__ = getattr(func, "__name__", "torque")
            out.append(CallableTorque(shifted))
        elif tq.time_dependent or turn:
            raise InvalidInputError(
                f"the torque {tq!r} depends on time (or on the space frame with a gravity gradient) and "
                "cannot be continued from a later state; solve the run in one piece"
            )
        else:
            out.append(tq)
    return out, phi


def solve_from(
    model: Model | RigidBody | ArrayLike,
    t: ArrayLike,
    t_start: float,
    q_start: ArrayLike,
    omega_start: ArrayLike,
    *,
    method: str,
    workers: int | None = None,
    **options: Any,
) -> Trajectory:
    r"""Continue a motion from its state at ``t_start`` to the (absolute) output times ``t``.

    The building block of long runs solved chunk by chunk: the model is
    autonomous unless a torque depends on time, so
    ``solve(model, t - t_start, attitude0=q_start, omega0=omega_start)``
    continues the motion; time-dependent torques (a gravity gradient, a
    Python function) are shifted by ``t_start`` so that the result is the same
    motion (see :func:`_shifted_torques`).

    Parameters
    ----------
    model : Model, RigidBody or array_like
        The equations of motion (a body alone: the free body).
    t : array_like, shape (T,)
        Absolute output times.
    t_start : float
        Time of the state ``(q_start, omega_start)``.
    q_start, omega_start : array_like, shapes (..., 4) and (..., 3)
    method : str
    workers : int or None
        Threads for a batch, as for :func:`~eulerpoisson.solve`.
    **options
        Method options.

    Returns
    -------
    Trajectory
        At the absolute times ``t``, with the original model (so that the
        energy, the integrals and the drift are those of the motion).
    """
    from ..model.equations import Model, as_model
    from ..numerics.quaternion import qmul
    from ..solvers import solve
    from ..trajectory import Trajectory

    model = as_model(model)
    t = np.asarray(t, dtype=float)
    t_start = float(t_start)
    if model.is_autonomous or t_start == 0.0:
        tr = solve(model, t - t_start, omega0=omega_start, attitude0=q_start, method=method, workers=workers, **options)
        tr.t = t
        return tr
    torques, phi = _shifted_torques(model.torques, t_start)
    q_start = np.asarray(q_start, dtype=float)
    turned = bool(np.any(phi != 0))
    if turned:
        rz = _rotation_z(phi)
        q_start = qmul(rz * np.array([1.0, -1.0, -1.0, -1.0]), q_start)
    tr = solve(
        Model(model.body, torques),
        t - t_start,
        omega0=omega_start,
        attitude0=q_start,
        method=method,
        workers=workers,
        **options,
    )
    q = tr.quaternion
    if turned:
        q = qmul(_rotation_z(phi)[..., None, :], q)
    return Trajectory(t, q, tr.omega, model.body, tr.method, tr.options, tr.stats, torque=list(model.torques))


def torque_fingerprint(model) -> list:
    out = []
    for tq in model.torques:
        try:
            out.append(tq.to_dict())
        except NotImplementedError:
            out.append({"kind": "unrecorded", "description": repr(tq)})
    return json.loads(json.dumps(out, default=float, sort_keys=True))


# ---------------------------------------------------------------------------
# the streaming solver
# ---------------------------------------------------------------------------
def _chunk_arrays(traj, variables) -> dict[str, np.ndarray]:
    out = {"quaternion": traj.quaternion, "omega": traj.omega}
    for name in variables:
        if name not in out:
            out[name] = getattr(traj, name)
    return out


def _flatten_batch(a: np.ndarray, bshape: tuple) -> np.ndarray:
    if not bshape:
        return a
    return a.reshape((int(np.prod(bshape)),) + a.shape[len(bshape) :])


def solve_to_file(
    body: RigidBody | Model | ArrayLike,
    t: TimeGrid | tuple[float, float, int] | ArrayLike,
    path: str | os.PathLike[str],
    *,
    omega0: ArrayLike | None = None,
    m0: ArrayLike | None = None,
    attitude0: AttitudeLike | None = None,
    torque: TorqueLike = None,
    method: str = "exact",
    chunk: int = 100_000,
    progress: bool | Callable[[int, int], Any] | None = None,
    resume: bool = False,
    overwrite: bool = False,
    variables: Sequence[str] | None = None,
    workers: int | None = None,
    **options: Any,
) -> Path:
    r"""Solve the motion at very many output times and stream it to a Zarr store.

    Parameters
    ----------
    body : RigidBody, Model or array_like
        The body or a batch of bodies (or a :class:`~eulerpoisson.Model`
        with its torques), as for :func:`~eulerpoisson.solve`.
    t : tuple (t0, t1, n), TimeGrid or array_like, shape (T,)
        Output times: ``(t0, t1, n)`` generates ``numpy.linspace(t0, t1, n)``
        lazily, chunk by chunk; an array(-like) is read chunk by chunk (see
        the module notes). Stepping methods need strictly monotonic times.
    path : str or Path
        Destination Zarr store (a folder), written atomically.
    omega0, m0, attitude0
        Initial state at :math:`t = 0`, as for :func:`~eulerpoisson.solve`.
    torque : Torque, callable, list of them, or None
        Torques, as for :func:`~eulerpoisson.solve`; recorded in the
        store's ``torque`` attribute (JSON records, as in a NetCDF file) and
        in the resume fingerprint. A time-dependent torque is shifted to each
        chunk's start (:func:`solve_from`).
    method : str
        A registered method; closed-form ones (``"exact"``) are evaluated
        chunk by chunk independently, stepping ones continue from the last
        state of the previous chunk.
    chunk : int
        Output samples per chunk (also the Zarr chunk along ``time``); the
        peak memory grows linearly with it (~1 kB per sample).
    progress : None, bool or callable
        ``None``: a progress bar on a terminal (rich), quiet otherwise;
        ``True``/``False``: always/never a bar; a callable is called as
        ``progress(done_samples, total_samples)`` after each chunk (and
        once at the start, with the samples already done on resume).
    resume : bool
        Continue an interrupted run with the same arguments from its
        partial store (see the module notes); without a partial store the
        run starts from the beginning.
    overwrite : bool
        Replace an existing ``path`` and discard a leftover partial run.
    variables : sequence of str, optional
        Time-dependent variables to write, a subset of :data:`TIME_VARIABLES`
        (default: all); ``quaternion`` and ``omega`` (the state) are always
        written.
    workers : int or None
        Threads that solve a batch of bodies, as for :func:`~eulerpoisson.solve`
        (None: ``EULERPOISSON_WORKERS`` or every core); the results do not
        depend on it, so a run may be resumed with another value.
    **options
        Method options (``tol``, ``dt``, ...).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    TypeError
        Bad initial-state combination, an unknown method option, a bad
        ``progress`` or non-integer ``chunk``.
    UnsupportedModelError
        The method cannot run the model (before anything is written).
    InvalidInputError
        Bad body, state or times; an unknown variable; ``chunk < 1``;
        non-monotonic times with a stepping method; ``resume=True`` with
        different arguments than the interrupted run.
    FileExistsError
        ``path`` exists and ``overwrite`` is False.
    EulerPoissonError
        A leftover partial run exists and neither ``resume`` nor
        ``overwrite`` was given.
    MissingDependencyError
        zarr or xarray is not installed (extras ``dask`` and ``io``).
    KeyboardInterrupt
        Propagated; the finished chunks stay in the partial store and the
        exception carries a note saying how to resume.

    Notes
    -----
    For the closed form the values equal those of one
    :func:`~eulerpoisson.solve` call at the same times, sample by
    sample; quaternion signs are made continuous across chunk boundaries
    (as :class:`~eulerpoisson.trajectory.Trajectory` does within one).
    """
    from ..solvers import get_method, make_problem, solve
    from ..solvers.parallel import check_workers
    from ..solvers.registry import check_supported
    from ..trajectory import Trajectory
    from ..util.validate import as_scalar

    zarr = require("zarr", "dask")
    require("xarray", "io")

    path = Path(path)
    chunk = int(as_scalar(chunk, "chunk", positive=True, integer=True))
    if variables is None:
        variables = list(TIME_VARIABLES)
    else:
        if isinstance(variables, str):
            variables = [variables]
        variables = list(variables)
        bad = [v for v in variables if v not in TIME_VARIABLES]
        if bad:
            raise InvalidInputError(
                f"variables: unknown variable(s) {', '.join(map(repr, bad))}; choose from {', '.join(TIME_VARIABLES)}"
            )
        variables = [v for v in TIME_VARIABLES if v in set(variables) | {"quaternion", "omega"}]
    if progress is not None and not isinstance(progress, bool) and not callable(progress):
        raise TypeError(f"progress must be None, True, False or a callable(done, total), got {progress!r}")

    cls = get_method(method)
    meth = cls(**options)  # validates the options
    check_workers(workers)
    closed_form = cls.order is None
    src = _as_time_source(t)
    n = len(src)
    t_first = _read_times(src, 0, 1)
    problem = make_problem(body, t_first, omega0=omega0, m0=m0, attitude0=attitude0, torque=torque)
    check_supported(method, problem.model)
    model = problem.model
    if not cls.negative_times and np.any(t_first < 0):
        raise InvalidInputError(f"method {method!r} cannot run backwards in time; got negative times in t")
    bshape = problem.batch_shape
    nchunks = -(-n // chunk)

    fingerprint = {
        "version": _STATE_VERSION,
        "method": method,
        "options": json.loads(json.dumps(meth.config, default=float, sort_keys=True)),
        "inertia": np.asarray(problem.body.inertia).tolist(),
        "positions": None if problem.body.positions is None else problem.body.positions.tolist(),
        "q0": problem.q0.tolist(),
        "omega0": problem.omega0.tolist(),
        "times": _times_fingerprint(src, chunk),
        "chunk": chunk,
        "n": n,
        "variables": variables,
    }
    if not model.is_free:  # (free runs keep the fingerprint of earlier versions: their partial runs resume)
        fingerprint["torque"] = torque_fingerprint(model)

    if overwrite:
        check_replaceable(path)  # before any work, not after
    if path.exists() and not overwrite:
        if resume and _finished_run(path) == fingerprint:
            return path  # the same run finished before: nothing to do
        raise FileExistsError(f"{path} exists; pass overwrite=True to replace it")
    work = work_dir(path)
    store = work / "store.zarr"
    done: set[int] = set()
    if work.exists():
        try:
            with open(work / "state.json", encoding="utf-8") as fh:
                old = json.load(fh)
        except (OSError, ValueError):
            old = None  # interrupted while the store was being created: nothing was computed
        if old is None or overwrite:
            shutil.rmtree(work)
        elif not resume:
            raise EulerPoissonError(
                f"an interrupted run to {path} left its finished chunks in {work}; pass resume=True "
                "to continue it or overwrite=True to discard it"
            )
        elif old != fingerprint:
            raise InvalidInputError(
                f"resume=True: the partial run in {work} was started with different arguments "
                "(body, initial state, times, method, options, chunk or variables); "
                "pass overwrite=True to discard it"
            )
        else:
            done = done_chunks(work)

    # metadata template: a one-sample trajectory at the initial state
    template = Trajectory(
        t=[0.0],
        quaternion=problem.q0[..., None, :],
        omega=problem.omega0[..., None, :],
        body=problem.body,
        method=method,
        options=dict(meth.config),
        torque=list(model.torques),
    ).to_xarray()

    if not work.exists():
        (work / "done").mkdir(parents=True)
        with quiet_zarr():
            g = zarr.open_group(str(store), mode="w")
            attrs = dict(template.attrs)
            attrs.update({"T": n, "stream_chunk": chunk, "stats": "{}"})
            g.attrs.update(attrs)
            for name in list(template.coords) + list(template.data_vars):
                v = template[name]
                if "time" in v.dims and name != "time" and name not in variables:
                    continue
                dims = list(v.dims)
                shape = list(v.shape)
                chunks = list(v.shape)
                if "time" in dims:
                    i = dims.index("time")
                    shape[i] = n
                    chunks[i] = min(chunk, n)
                kind = v.dtype.kind
                fill = np.nan if kind == "f" else ("" if kind == "U" else 0)
                arr = g.create_array(
                    name,
                    shape=tuple(shape),
                    chunks=tuple(chunks),
                    dtype=v.dtype,
                    fill_value=fill,
                    dimension_names=dims,
                )
                arr.attrs.update(dict(v.attrs))
                if "time" not in dims:
                    arr[...] = v.values
            zarr.consolidate_metadata(str(store))  # the partial store reads like the final one
        write_json_atomic(work / "state.json", fingerprint)  # last: marks the store as complete and resumable

    with quiet_zarr():
        g = zarr.open_group(str(store), mode="r+")
    arrays = {name: g[name] for name in variables}
    tarr = g["time"]
    body_dim = bool(bshape)

    def tslice(a, b):
        return (slice(None), slice(a, b)) if body_dim else (slice(a, b),)

    # carried state for stepping methods / quaternion sign continuity
    prev_q = None  # (*batch, 4) last quaternion of the previous chunk
    prev_w = None
    prev_t = None
    direction = [0]  # sign of the time steps, fixed by the first chunk (stepping methods)

    n_done = sum(min(chunk, n - k * chunk) for k in done)
    try:
        from ..util.jit import whole_run

        # one choice of compiled kernels or NumPy for the whole run, not per chunk
        with ProgressDisplay(progress, n, f"solving {method} to {path.name}") as bar, whole_run(n_times=n):
            bar.update(n_done)
            for k in range(nchunks):
                a, b = k * chunk, min(n, (k + 1) * chunk)
                if k in done:
                    prev_q = None
                    continue
                if prev_q is None and a > 0:  # resumed after finished chunks: the state they end in
                    with quiet_zarr():
                        prev_q = np.asarray(g["quaternion"][tslice(a - 1, a)]).reshape(bshape + (4,))
                        prev_w = np.asarray(g["omega"][tslice(a - 1, a)]).reshape(bshape + (3,))
                        prev_t = float(tarr[a - 1])
                tc = _read_times(src, a, b)
                if not closed_form:
                    _check_monotonic(tc, prev_t, a, direction)
                start = _time.perf_counter()
                if closed_form or prev_q is None:
                    tr = solve(
                        model,
                        tc,
                        omega0=problem.omega0,
                        attitude0=problem.q0,
                        method=method,
                        workers=workers,
                        **options,
                    )
                else:
                    assert prev_t is not None and prev_w is not None  # set with prev_q
                    tr = solve_from(model, tc, prev_t, prev_q, prev_w, method=method, workers=workers, **options)
                q = tr.quaternion
                if prev_q is not None:
                    # keep the quaternion sign continuous across the chunk boundary
                    sgn = np.where(np.sum(prev_q * q[..., 0, :], -1) < 0, -1.0, 1.0)
                    q = q * sgn[..., None, None]
                    tr.quaternion = q
                data = _chunk_arrays(tr, variables)
                wall = _time.perf_counter() - start
                with quiet_zarr():
                    for name, arr in arrays.items():
                        arr[tslice(a, b)] = _flatten_batch(data[name], bshape)
                    tarr[a:b] = tc
                counters = {
                    key: val
                    for key, val in tr.stats.items()
                    if isinstance(val, numbers.Number)
                    and not isinstance(val, bool)
                    and key not in ("wall_time", "threads")
                }
                mark_done(work, k, {"wall_time": wall, "stats": counters, "written": datetime.now(UTC).isoformat()})
                prev_q = q[..., -1, :]
                prev_w = tr.omega[..., -1, :]
                prev_t = float(tc[-1])
                n_done += b - a
                bar.update(n_done)
    except KeyboardInterrupt as exc:
        exc.add_note(
            f"eulerpoisson: the finished chunks of {path} are kept in {store}; rerun with resume=True to continue"
        )
        raise

    # finalize: totals over all chunks (also those of earlier, interrupted sessions) in the attributes,
    # consolidated metadata, atomic rename
    totals: dict = {"chunks": nchunks, "wall_time": 0.0}
    for k in range(nchunks):
        try:
            with open(work / "done" / f"{k:09d}", encoding="utf-8") as fh:
                info = json.load(fh)
        except (OSError, ValueError):
            continue
        totals["wall_time"] += float(info.get("wall_time", 0.0))
        for key, val in info.get("stats", {}).items():
            totals[key] = totals.get(key, 0) + val
    with quiet_zarr():
        g.attrs.update(
            {
                "stats": json.dumps(totals, default=float, sort_keys=True),
                "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} streamed by "
                f"eulerpoisson {template.attrs['eulerpoisson_version']} in {nchunks} chunks of {chunk}",
                # the arguments of the run: a later resume=True with the same ones finds it complete
                "eulerpoisson_run": json.dumps(fingerprint, sort_keys=True, default=float),
            }
        )
        zarr.consolidate_metadata(str(store))
    replace_dir(store, path, overwrite)
    shutil.rmtree(work, ignore_errors=True)
    return path


def _check_monotonic(tc: np.ndarray, prev_t, offset: int, direction: list) -> None:
    full = tc if prev_t is None else np.concatenate([[prev_t], tc])
    if full.size < 2:
        return
    d = np.diff(full)
    if not direction[0]:
        direction[0] = 1 if d[0] > 0 else -1
    if not np.all(d * direction[0] > 0):
        raise InvalidInputError(
            f"t must be strictly monotonic for a stepping method (checked near index {offset}); "
            "sort the times or use method='exact'"
        )
