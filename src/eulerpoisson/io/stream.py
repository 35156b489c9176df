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

The same bits as :func:`~eulerpoisson.solve`
---------------------------------------------
The run is solved by the one engine (:mod:`eulerpoisson.solvers.engine`),
segment by segment, exactly as :func:`~eulerpoisson.solve`, ``simulate``
and the sweeps solve it: the store holds the same bits as ``solve`` on the
same times, whatever its storage ``chunk`` (tested for every method,
``tests/test_routes.py``). A closed-form method (``"exact"``) evaluates
every time from the initial state at :math:`t=0`. A stepping method
(``"rk"``, ``"taylor"``, ``"symplectic"``, ...) needs strictly monotonic
times; the engine cuts a long run into segments (of at most
:data:`~eulerpoisson.solvers.engine.SEGMENT` output times, a function of
the run alone) and continues each segment from the last state of the
previous one (the free body, and a body under time-independent torques, is
autonomous, so shifting time is exact; a time-dependent torque is shifted
with it, :meth:`~eulerpoisson.Model.shifted`). The storage chunks only
decide what is written and marked at a time.

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
  stored state that ends the segment before them (the segment is computed
  again from its start, so the bits are those of an uninterrupted run). Without ``resume=True`` a leftover partial store is an
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

import hashlib
import json
import numbers
import os
import sys
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError, require
from ..solvers.engine import TimeGrid, as_time_source, read_times
from ..version import package_version
from .resumable import PartialRun, partial_store
from .zarr import create_trajectory_store, quiet_zarr

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
def _as_time_source(t):
    return as_time_source(t)


def _read_times(src, a: int, b: int) -> np.ndarray:
    return read_times(src, a, b)


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


# ---------------------------------------------------------------------------
# continuing a solution from a later state (chunks)
# ---------------------------------------------------------------------------
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
    motion (see :meth:`~eulerpoisson.Model.shifted`).

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
    from ..model.equations import as_model
    from ..solvers.engine import continue_from, prepare_run

    model = as_model(model)
    t = np.atleast_1d(np.asarray(t, dtype=float))
    run = prepare_run(
        model, t, omega0=omega_start, attitude0=q_start, method=method, workers=workers, in_memory=True, **options
    )
    return continue_from(run, t, float(t_start), run.problem.q0, run.problem.omega0)


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
#: the variables with a trailing component axis (the others are scalars at each time)
_VECTORS = ("quaternion", "omega", "M", "m", "gibbs")


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
    from ..solvers.engine import prepare_run
    from ..trajectory import Trajectory
    from ..util.validate import as_scalar

    zarr = require("zarr", "dask")

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

    src = as_time_source(t)
    # the one engine (solvers.engine): checks, the method planned for the whole run, its segments
    run = prepare_run(
        body,
        src,
        omega0=omega0,
        m0=m0,
        attitude0=attitude0,
        torque=torque,
        method=method,
        workers=workers,
        caller="solve_to_file",
        **options,
    )
    method = run.method_name
    problem, model = run.problem, run.model
    n = run.n
    bshape = problem.batch_shape
    nchunks = -(-n // chunk)

    fingerprint = {
        "version": _STATE_VERSION,
        "method": method,
        "options": json.loads(json.dumps(run.options, default=float, sort_keys=True)),
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

    partial = PartialRun(
        path,
        fingerprint,
        resume=resume,
        overwrite=overwrite,
        finished=lambda p: _finished_run(p) == fingerprint,
    )
    if not partial.open():
        return path  # the same run finished before: nothing to do
    store, done = partial.store, partial.done

    # the layout of the run's file, from a one-sample trajectory at the initial state (its body, model, method)
    template = Trajectory(
        t=[0.0],
        quaternion=problem.q0[..., None, :],
        omega=problem.omega0[..., None, :],
        body=problem.body,
        method=method,
        options=run.options,
        torque=list(model.torques),
    )
    version = package_version()

    def make_store(store: Path) -> None:
        create_trajectory_store(
            store, template, n=n, chunk=chunk, variables=variables, attrs={"T": n, "stream_chunk": chunk, "stats": "{}"}
        )

    partial.create(make_store)

    with quiet_zarr():
        g = zarr.open_group(str(store), mode="r+")
    arrays = {name: g[name] for name in variables}
    tarr = g["time"]
    body_dim = bool(bshape)

    def tslice(a, b):
        return (slice(None), slice(a, b)) if body_dim else (slice(a, b),)

    def chunk_digest(k: int, parts: dict[str, np.ndarray] | None = None) -> str:
        """sha256 of chunk ``k`` as written (``parts``) or as stored now (read back from the store)."""
        c0, c1 = k * chunk, min(n, (k + 1) * chunk)
        h = hashlib.sha256()
        for name in (*variables, "time"):
            if parts is not None:
                a = parts[name]
            else:
                with quiet_zarr():
                    a = np.asarray(
                        (tarr if name == "time" else arrays[name])[
                            (slice(c0, c1),) if name == "time" else tslice(c0, c1)
                        ]
                    )
            h.update(np.ascontiguousarray(a).tobytes())
        return h.hexdigest()

    # resume: every finished chunk is verified before it is trusted (its checksum recorded when it was written,
    # and its data decoded); a chunk that fails is computed again (a damaged store is never published)
    infos = partial.infos() if done else {}
    for k in sorted(done):
        want = infos.get(k, {}).get("sha256")
        try:
            ok = want is None or chunk_digest(k) == want  # (markers of older versions have no checksum)
            if want is None:
                chunk_digest(k)  # at least readable
        except Exception:  # noqa: BLE001 - undecodable or missing chunk data: computed again
            ok = False
        if not ok:
            partial.forget(k)
    # the storage chunks done form a prefix; the engine restarts at the segment that holds the first
    # sample not done, from the stored state just before it (what it continued from the first time)
    finished = 0
    while finished < nchunks and finished in done:
        finished += 1
    first_todo = min(n, finished * chunk)
    state = None
    seg0 = run.segment_index(first_todo) if first_todo < n else len(run.bounds)
    if seg0 < len(run.bounds) and run.bounds[seg0][0] > 0:
        s = run.bounds[seg0][0]
        with quiet_zarr():
            q_prev = np.asarray(g["quaternion"][tslice(s - 1, s)]).reshape(bshape + (4,))
            w_prev = np.asarray(g["omega"][tslice(s - 1, s)]).reshape(bshape + (3,))
            state = (float(read_times(src, s - 1, s)[0]), q_prev, w_prev)
    n_done = sum(min(chunk, n - k * chunk) for k in done)
    pending: dict[int, dict] = {}  # counters of storage chunks not complete yet
    try:
        with ProgressDisplay(progress, n, f"solving {method} to {path.name}") as bar:
            bar.update(n_done)
            for seg in run.segments(seg0, state) if seg0 < len(run.bounds) else ():
                tr = seg.trajectory
                a, b = seg.start, seg.stop
                data = _chunk_arrays(tr, variables)
                counters = {
                    key: val
                    for key, val in tr.stats.items()
                    if isinstance(val, numbers.Number)
                    and not isinstance(val, bool)
                    and key not in ("wall_time", "threads")
                }
                # written storage chunk by storage chunk: each one complete is marked at once (after its data),
                # so an interruption keeps every finished chunk; the segment's counters and time are shared out
                # over its chunks by their samples (the totals of a resumed run are those of one run)
                for k in range(a // chunk, -(-b // chunk)):
                    c0, c1 = max(a, k * chunk), min(b, (k + 1) * chunk)
                    written = pending.setdefault(k, {"wall_time": 0.0, "stats": {}, "parts": {}})["parts"]
                    with quiet_zarr():
                        for name, arr in arrays.items():
                            part = (
                                data[name][..., c0 - a : c1 - a, :]
                                if name in _VECTORS
                                else data[name][..., c0 - a : c1 - a]
                            )
                            flat = _flatten_batch(part, bshape)
                            arr[tslice(c0, c1)] = flat
                            written.setdefault(name, []).append(flat)
                        tarr[c0:c1] = tr.t[c0 - a : c1 - a]
                        written.setdefault("time", []).append(tr.t[c0 - a : c1 - a])
                    share = (c1 - c0) / (b - a)
                    acc = pending[k]
                    acc["wall_time"] += seg.wall_time * share
                    for key, val in counters.items():
                        acc["stats"][key] = acc["stats"].get(key, 0.0) + float(val) * share  # type: ignore[arg-type]
                    if c1 == min(n, (k + 1) * chunk) and k not in done:
                        info = pending.pop(k)
                        axis = 1 if body_dim else 0
                        parts = {
                            name: np.concatenate(v, axis=0 if name == "time" else axis)
                            for name, v in info.pop("parts").items()
                        }
                        info["sha256"] = chunk_digest(k, parts)
                        partial.mark(k, {**info, "written": datetime.now(UTC).isoformat()})
                        n_done += min(chunk, n - k * chunk)
                        bar.update(n_done)
                    elif k in done:
                        pending.pop(k, None)
    except KeyboardInterrupt as exc:
        exc.add_note(
            f"eulerpoisson: the finished chunks of {path} are kept in {store}; rerun with resume=True to continue"
        )
        raise

    # finalize: totals over all chunks (also those of earlier, interrupted sessions) in the attributes,
    # consolidated metadata, atomic rename
    totals: dict = {"chunks": nchunks, "wall_time": 0.0}
    for info in partial.infos().values():
        totals["wall_time"] += float(info.get("wall_time", 0.0))
        for key, val in info.get("stats", {}).items():
            totals[key] = totals.get(key, 0) + val
    for key, val in totals.items():  # counts shared out over chunks add up to whole numbers again
        if key != "wall_time" and isinstance(val, float) and abs(val - round(val)) < 1e-6 * max(1.0, abs(val)):
            totals[key] = int(round(val))
    with quiet_zarr():
        g.attrs.update(
            {
                "stats": json.dumps(totals, default=float, sort_keys=True),
                "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} streamed by "
                f"eulerpoisson {version} in {nchunks} chunks of {chunk}",
                # the arguments of the run: a later resume=True with the same ones finds it complete
                "eulerpoisson_run": json.dumps(fingerprint, sort_keys=True, default=float),
            }
        )
        zarr.consolidate_metadata(str(store))
    partial.publish()
    return path
