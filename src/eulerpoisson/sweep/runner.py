r"""Parameter sweeps: the stability atlas of the tennis-racket effect, with Dask.

A sweep evaluates, at every point of a grid (or of a random sample) of
inertia tensors and directions of the initial body angular momentum,

* the **flip half-period** :math:`T_{1/2} = 2K(k)/\lambda`, the time between
  consecutive flips of the momentum components that change sign
  (:func:`~eulerpoisson.analysis.tennis_racket_half_period`); it is infinite
  on the separatrix :math:`L^2 = 2EI_2` and undefined (NaN) for a symmetric
  body. For a momentum exactly along the smallest or largest axis (a
  permanent rotation) it is the limit value :math:`\pi/\lambda`;
* the Jacobi parameter :math:`k^2` of the polhode
  (:func:`~eulerpoisson.analysis.elliptic_parameters`);
* an **attitude sensitivity**: with :math:`\mathbf u` the unit direction of
  the initial body momentum :math:`\mathbf M_0 = L\mathbf u` (attitude the
  identity) and :math:`\mathbf e_\theta,\mathbf e_\varphi` the polar and
  azimuthal unit tangents of the sphere at :math:`\mathbf u`, the initial
  states :math:`L(\cos\delta\,\mathbf u + \sin\delta\,\mathbf e)` differ
  from :math:`\mathbf M_0` by the angle :math:`\delta`; the sensitivity is

  .. math:: S = \max_{\mathbf e\in\{\mathbf e_\theta, \mathbf e_\varphi\}}
            \frac{\angle\big(R(T;\mathbf M_0),\, R(T;\mathbf M_0^{\mathbf e})\big)}{\delta},

  the rotation angle between the two attitudes at time :math:`T` over
  :math:`\delta` (a finite-difference estimate of the growth of attitude
  errors; it grows linearly in :math:`T` away from the separatrix and
  peaks on it).

The work is split into chunks of ``chunk`` points; each chunk is one task.
Tasks run on a Dask cluster — an embedded :class:`distributed.LocalCluster`
by default, an existing scheduler given by its address
``"tcp://HOST:PORT"``, or ``"serial"`` (plain loop, no Dask: the
reference). The client writes every finished chunk to a Zarr store and then
records it as done, so an interrupted sweep (Ctrl-C, a crash, a kill)
restarts where it stopped: rerunning the same sweep computes only the
missing chunks. Results do not depend on the scheduler: each point is
computed by the same code on the same chunk of inputs, so serial and
distributed sweeps agree bit for bit.

Store layout
------------
Work happens in ``.NAME.partial/`` next to the output path (the store is
``.NAME.partial/store.zarr``; marker files ``.NAME.partial/done/CHUNK``);
when every chunk is done the store is renamed to the output path. The store
holds, along a ``point`` dimension, the parameters ``I1, I2, I3`` (principal
moments), ``polar, azimuth`` (degrees or radians, as configured), ``M0``
(``point, axis``), the results ``half_period, k2, sensitivity`` and
``status`` (0 regular, 1 on the separatrix, 2 symmetric body, 3 not a
physical body: triangle inequality violated), and along a ``chunk``
dimension the bookkeeping ``chunk_count`` (how many times the chunk was
computed and written: 1 after any number of interruptions and resumes),
``chunk_time`` (UNIX time of the write) and ``chunk_seconds`` (compute time).
The attribute ``sweep_config`` is the normalized configuration (JSON);
``sweep_grid`` the grid axes. :func:`load_sweep` reshapes a grid sweep to
its axes.

TOML schema
-----------
The schema of a sweep file (or dict) is in :mod:`eulerpoisson.sweep.config`
(:func:`load_config`).

References
----------
L. D. Landau and E. M. Lifshitz, *Mechanics*, §37 (the periods). M. S.
Ashbaugh, C. C. Chicone and R. H. Cushman, "The twisting tennis racket",
J. Dyn. Diff. Eq. 3 (1991) 67-85.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shutil
import time as _time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

from ..errors import EulerPoissonError, InvalidInputError, require
from ..io.resumable import PartialRun, work_dir
from ..io.stream import ProgressDisplay, quiet_zarr
from .atlas import plot_atlas
from .config import (
    FORMAT_VERSION,
    SweepConfig,
    check_physical,
    check_scheduler,
    direction,
    grid_points,
    integer,
    is_remote,
    load_config,
    moments_from_axes,
    random_points,
)
from .points import STATUS, compute_chunk, compute_points

__all__ = [
    "SweepConfig",
    "load_config",
    "compute_points",
    "run_sweep",
    "load_sweep",
    "plot_atlas",
    "STATUS",
    "sweep_summary",
]

# The task of a sweep, looked up here by run_sweep at call time (so that it can be replaced on this
# module, e.g. to inject a failure in a test).
_compute_chunk = compute_chunk


# ---------------------------------------------------------------------------
# running a sweep
# ---------------------------------------------------------------------------
_RESULTS: dict[str, tuple[str, dict[str, Any]]] = {
    "half_period": (
        "f8",
        {"long_name": "flip half-period 2K(k)/lambda (time between flips); inf on the separatrix", "units": "s"},
    ),
    "k2": ("f8", {"long_name": "Jacobi parameter k^2 of the polhode", "units": "1"}),
    "sensitivity": (
        "f8",
        {
            "long_name": "attitude sensitivity: rotation angle between the attitudes at T of "
            "initial momenta differing by delta, divided by delta",
            "units": "1",
        },
    ),
    "status": (
        "i1",
        {
            "long_name": "0 regular, 1 separatrix, 2 symmetric body, 3 not a physical body",
            "units": "1",
            "flag_values": [0, 1, 2, 3],
            "flag_meanings": "regular separatrix symmetric_body not_physical",
        },
    ),
}


def _create_store(zarr, store: Path, cfg: SweepConfig) -> None:
    n, chunk = cfg.n_points, cfg.chunk
    nchunks = -(-n // chunk)
    ang_units = "degree" if cfg.degrees else "rad"
    from ..version import package_version

    __version__ = package_version()

    g = zarr.open_group(str(store), mode="w")
    g.attrs.update(
        {
            "title": f"eulerpoisson sweep: tennis-racket stability atlas ({cfg.kind})",
            "Conventions": "CF-1.10",
            "eulerpoisson_version": __version__,
            "sweep_format_version": FORMAT_VERSION,
            "sweep_config": json.dumps(cfg.fingerprint(), sort_keys=True),
            "sweep_kind": cfg.kind,
            "sweep_grid": json.dumps({k: v.tolist() for k, v in cfg.grid_axes.items()}) if cfg.kind == "grid" else "{}",
            "sweep_axes": json.dumps(cfg.axis_names),
            "n_points": n,
            "chunk": chunk,
            "T": cfg.T,
            "delta": cfg.delta,
            "method": cfg.method,
            "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} started by eulerpoisson {__version__}",
        }
    )

    def arr(name, dims, shape, chunks, dtype, attrs, fill):
        a = g.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill, dimension_names=dims)
        a.attrs.update(attrs)
        return a

    c = min(chunk, n)
    params = {
        "I1": {"long_name": "principal moment of inertia I1", "units": "kg m2"},
        "I2": {"long_name": "principal moment of inertia I2", "units": "kg m2"},
        "I3": {"long_name": "principal moment of inertia I3", "units": "kg m2"},
        "polar": {"long_name": "polar angle of M0 from principal axis 3", "units": ang_units},
        "azimuth": {"long_name": "azimuth of M0 from axis 1 towards axis 2", "units": ang_units},
    }
    for name, attrs in params.items():
        arr(name, ["point"], (n,), (c,), "f8", attrs, np.nan)
    arr(
        "M0",
        ["point", "axis"],
        (n, 3),
        (c, 3),
        "f8",
        {"long_name": "initial body angular momentum (principal frame)", "units": "kg m2 s-1"},
        np.nan,
    )
    ax = arr("axis", ["axis"], (3,), (3,), "<U1", {}, "")
    ax[...] = np.array(["x", "y", "z"])
    for name, (dtype, attrs) in _RESULTS.items():
        arr(name, ["point"], (n,), (c,), dtype, attrs, np.nan if dtype == "f8" else -1)
    arr("chunk_count", ["chunk"], (nchunks,), (1,), "i4", {"long_name": "times this chunk was computed and written"}, 0)
    arr(
        "chunk_time",
        ["chunk"],
        (nchunks,),
        (1,),
        "f8",
        {"long_name": "time the chunk was written", "units": "seconds since 1970-01-01 00:00:00 UTC"},
        np.nan,
    )
    arr(
        "chunk_seconds",
        ["chunk"],
        (nchunks,),
        (1,),
        "f8",
        {"long_name": "compute time of the chunk", "units": "s"},
        np.nan,
    )

    # the parameters of every point, written once, in slabs of whole chunks (<= ~2.6e5 points)
    if cfg.kind == "random":
        vals = random_points(cfg)
    slab = chunk * max(1, 262_144 // chunk)
    for a in range(0, n, slab):
        b = min(n, a + slab)
        v = grid_points(cfg, a, b) if cfg.kind == "grid" else {key: x[a:b] for key, x in vals.items()}
        I = moments_from_axes(cfg, v)
        for i, name in enumerate(("I1", "I2", "I3")):
            g[name][a:b] = I[:, i]
        g["polar"][a:b] = v["polar"]
        g["azimuth"][a:b] = v["azimuth"]
        g["M0"][a:b] = cfg.magnitude * direction(v["polar"], v["azimuth"], cfg.degrees)


#: bytes of memory per point of a random sweep while its points are drawn (its five axes, M0, temporaries)
_RANDOM_BYTES_PER_POINT = 8 * 12


def _memory_available() -> float | None:
    """Available memory in bytes (None where the system does not say)."""
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return None


def _local_cluster(workers):
    distributed = require("distributed", "dask")
    n = workers or os.cpu_count() or 1
    # everything on the loopback interface: no scheduler or dashboard port open to the network
    return distributed.LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        silence_logs=logging.ERROR,
    )


def run_sweep(
    config: SweepConfig | str | os.PathLike[str] | dict[str, Any],
    *,
    path: str | os.PathLike[str] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: bool | Callable[[int, int], object] | None = None,
    overwrite: bool = False,
    allow_unphysical: bool | None = None,
) -> Path:
    """Run (or resume) a sweep and write its Zarr store.

    Parameters
    ----------
    config : SweepConfig, str, Path or dict
        The sweep (a TOML file is read with :func:`load_config`).
    path : str or Path, optional
        Output store; default ``[output] path``.
    scheduler : str, optional
        ``"local"`` (an embedded :class:`distributed.LocalCluster`),
        ``"serial"`` (no Dask) or ``"tcp://HOST:PORT"`` (an existing
        cluster); default ``[compute] scheduler``.
    workers : int, optional
        Worker processes of the local cluster (each solves with one
        thread), or threads of the ``"serial"`` scheduler (``solve(...,
        workers=)``); default ``[compute] workers``, else the CPU count. The
        results do not depend on it.
    client : distributed.Client, optional
        Use this client (overrides ``scheduler``).
    progress : None, bool or callable
        ``None``: a progress bar on a terminal, quiet otherwise;
        ``True``/``False``; or ``progress(done_points, total_points)``.
    overwrite : bool
        Discard an existing result or a partial sweep made with a different
        configuration.
    allow_unphysical : bool, optional
        Run a sweep in which no body is physical (status 3, NaN results)
        instead of refusing it; default ``[inertia] allow_unphysical``
        (false). See :func:`~eulerpoisson.sweep.config.check_physical`.

    Returns
    -------
    Path
        The finished store (also when it was already complete: nothing is
        recomputed then).

    Raises
    ------
    InvalidInputError
        Invalid configuration or scheduler; a random sweep whose points do
        not fit in the available memory.
    InvalidInertiaError
        No body of the sweep is physical and ``allow_unphysical`` is not
        true.
    FileExistsError
        ``path`` holds a different sweep (or something else) and
        ``overwrite`` is False.
    EulerPoissonError
        A partial sweep with a different configuration is in the way.
    MissingDependencyError
        zarr (or dask/distributed for a cluster) is not installed (extra ``dask``).
    EulerPoissonError
        The scheduler cannot be reached (checked before anything is written).
    KeyboardInterrupt
        Propagated after the finished chunks are recorded; rerun to resume.

    Notes
    -----
    Finished chunks are written by the client (so remote workers need no
    shared file system) and then recorded by a marker; a rerun skips them.
    A sweep that fails (other than by an interruption) before its first
    chunk is finished leaves nothing behind: its work folder is removed.
    Workers of a remote cluster need eulerpoisson installed (the task is
    :func:`compute_points`, shipped by reference).

    The local cluster starts worker *processes* (spawned): a script that
    calls ``run_sweep(..., scheduler="local")`` must do so under
    ``if __name__ == "__main__":``, as for any :mod:`multiprocessing` code
    (the ``eulerpoisson`` command needs nothing).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, plot_atlas, run_sweep
    >>> if __name__ == "__main__":                                  # doctest: +SKIP
    ...     path = run_sweep("examples/sweep.toml", scheduler="local", workers=4)
    ...     plot_atlas(load_sweep(path), "atlas.png")

    >>> import numpy as np
    >>> from eulerpoisson.sweep import load_sweep, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0},
    ...        "momentum": {"polar": [30.0, 60.0], "azimuth": [0.0, 45.0]},
    ...        "output": {"path": "demo.zarr", "chunk": 2}, "compute": {"T": 10.0, "scheduler": "serial"}}
    >>> path = run_sweep(cfg, progress=False)
    >>> path.name
    'demo.zarr'
    >>> print(np.round(load_sweep(path)["half_period"].values, 6))
    [[132.062275  12.438453]
     [  6.469547   8.917193]]
    """
    zarr = require("zarr", "dask")
    if isinstance(config, SweepConfig):
        cfg = config if allow_unphysical is None else config.replace(allow_unphysical=bool(allow_unphysical))
        check_physical(cfg)
    else:
        cfg = load_config(config, path=path, allow_unphysical=allow_unphysical)
    if scheduler is None and client is None and is_remote(cfg.scheduler):
        raise InvalidInputError(
            f"the sweep file names the scheduler {cfg.scheduler!r}; a file never connects to a cluster on its own: "
            f"give it explicitly (run_sweep(..., scheduler={cfg.scheduler!r}) or --scheduler {cfg.scheduler})"
        )
    scheduler = check_scheduler(scheduler if scheduler is not None else cfg.scheduler, "scheduler")
    if workers is not None:
        workers = integer(workers, "workers", 1)
    else:
        workers = cfg.workers
    path = Path(path if path is not None else cfg.path)
    if cfg.kind == "random" and not work_dir(path).exists():
        # its points are drawn at once when the store is made: check that they fit before anything is written
        need = float(cfg.n_points) * _RANDOM_BYTES_PER_POINT
        free = _memory_available()
        if free is not None and need > free:
            raise InvalidInputError(
                f"{cfg.source}: [sweep] samples = {cfg.n_points} needs about {need / 2**30:.3g} GiB in memory to "
                f"draw its points, more than the {free / 2**30:.3g} GiB available; sweep fewer points"
            )
    fp = cfg.fingerprint()
    fp_text = json.dumps(fp, sort_keys=True)

    def finished(p: Path) -> bool:
        try:
            with quiet_zarr():
                return zarr.open_group(str(p), mode="r").attrs.get("sweep_config") == fp_text
        except Exception:  # noqa: BLE001 - not a zarr store
            return False

    # the resumable store shared with long runs (io.resumable): a sweep resumes whenever its configuration is the same
    partial = PartialRun(path, fp, resume="always", overwrite=overwrite, finished=finished, kind="sweep")
    if not partial.open():
        return path
    store, done = partial.store, partial.done

    def make_store(store: Path) -> None:
        with quiet_zarr():
            _create_store(zarr, store, cfg)
            zarr.consolidate_metadata(str(store))  # the partial store reads like the final one

    n, chunk = cfg.n_points, cfg.chunk
    nchunks = -(-n // chunk)
    todo = [k for k in range(nchunks) if k not in done]
    fresh = not partial.work.exists()
    with contextlib.ExitStack() as stack:
        if todo and client is None and scheduler != "serial":
            # reach the cluster first: a scheduler that cannot be reached leaves nothing behind
            client = _connect(stack, scheduler, workers)
        try:
            partial.create(make_store)
            _compute(zarr, cfg, store, partial, todo, client, workers, progress, path)
        except BaseException as exc:
            if fresh and not partial.done and not isinstance(exc, KeyboardInterrupt):
                shutil.rmtree(partial.work, ignore_errors=True)  # a failure before any chunk finished: nothing to keep
            if isinstance(exc, KeyboardInterrupt):
                exc.add_note(
                    f"eulerpoisson: the finished chunks of the sweep are kept in {store}; rerun the sweep to resume "
                    "(run_sweep with the same configuration and path: only the missing chunks are computed)"
                )
            raise

    with quiet_zarr():
        g = zarr.open_group(str(store), mode="r+")
        g.attrs["history"] = f"{g.attrs.get('history', '')}; finished {datetime.now(UTC).isoformat(timespec='seconds')}"
        zarr.consolidate_metadata(str(store))
    partial.publish()
    return path


def _connect(stack: contextlib.ExitStack, scheduler: str, workers):
    """A client of the embedded cluster (``"local"``) or of the scheduler at an address, closed by ``stack``."""
    distributed = require("distributed", "dask")
    if scheduler == "local":
        cluster = stack.enter_context(_local_cluster(workers))
        return stack.enter_context(distributed.Client(cluster, set_as_default=False))
    try:
        return stack.enter_context(distributed.Client(scheduler, set_as_default=False))
    except OSError as exc:
        raise EulerPoissonError(f"cannot connect to the Dask scheduler {scheduler}: {exc}") from exc


def _compute(zarr, cfg, store, partial, todo, client, workers, progress, path) -> None:
    """Compute the chunks ``todo`` of the sweep, writing each to ``store`` and marking it done."""
    with quiet_zarr():
        g = zarr.open_group(str(store), mode="r+")
        arrs = {
            name: g[name] for name in ("I1", "I2", "I3", "M0", *_RESULTS, "chunk_count", "chunk_seconds", "chunk_time")
        }
    n, chunk = cfg.n_points, cfg.chunk
    done = partial.done

    def bounds(k):
        return k * chunk, min(n, (k + 1) * chunk)

    def inputs(k):
        a, b = bounds(k)
        with quiet_zarr():
            I = np.stack([np.asarray(arrs[name][a:b]) for name in ("I1", "I2", "I3")], -1)
            M = np.asarray(arrs["M0"][a:b])
        return I, M

    def write(k, res):
        a, b = bounds(k)
        with quiet_zarr():
            for name in _RESULTS:
                arrs[name][a:b] = res[name]
            arrs["chunk_count"][k] = int(arrs["chunk_count"][k]) + 1
            arrs["chunk_seconds"][k] = float(res["seconds"])
            arrs["chunk_time"][k] = _time.time()
        partial.mark(k, {"seconds": float(res["seconds"])})

    n_done = sum(bounds(k)[1] - bounds(k)[0] for k in done)
    args = (cfg.T, cfg.delta, cfg.method, n)
    with ProgressDisplay(progress, n, f"sweep {path.name}") as bar:
        bar.update(n_done)
        if todo and client is None:  # serial
            for k in todo:
                I, M = inputs(k)
                write(k, _compute_chunk(I, M, *args, workers))
                n_done += bounds(k)[1] - bounds(k)[0]
                bar.update(n_done)
        elif todo:
            _run_distributed(client, todo, inputs, write, args, bounds, bar, n_done)


def _run_distributed(client, todo, inputs, write, args, bounds, bar, n_done):
    distributed = require("distributed", "dask")
    nthreads = max(1, sum(client.nthreads().values()))
    window = 4 * nthreads  # tasks in flight: bounded, so huge sweeps need no huge graphs
    pending = iter(todo)
    keys = {}

    def submit_next():
        k = next(pending, None)
        if k is None:
            return None
        I, M = inputs(k)
        fut = client.submit(_compute_chunk, I, M, *args, 1, pure=False)
        keys[fut.key] = k
        return fut

    first = [f for f in (submit_next() for _ in range(window)) if f is not None]
    ac = distributed.as_completed(first, loop=client.loop, with_results=True)
    try:
        for fut, res in ac:
            k = keys.pop(fut.key)
            write(k, res)
            n_done += bounds(k)[1] - bounds(k)[0]
            bar.update(n_done)
            fut = submit_next()
            if fut is not None:
                ac.add(fut)
    except BaseException:
        for f in list(ac.futures):
            f.cancel()
        raise
    return n_done


# ---------------------------------------------------------------------------
# reading a sweep
# ---------------------------------------------------------------------------
def sweep_summary(path: str | os.PathLike[str]) -> dict[str, int]:
    """How many points of a sweep store have each status (read chunk by chunk: memory stays bounded).

    Parameters
    ----------
    path : str or Path
        A sweep store (finished, or the partial store of an unfinished sweep).

    Returns
    -------
    dict of int
        ``points`` (all of them), one count per name of :data:`STATUS`
        (``regular``, ``separatrix``, ``symmetric body``, ``not a physical
        body``) and ``unfinished`` (points not computed yet).

    Raises
    ------
    EulerPoissonError
        Not a sweep store.
    MissingDependencyError
        zarr missing.

    Examples
    --------
    >>> from eulerpoisson.sweep import run_sweep
    >>> from eulerpoisson.sweep.runner import sweep_summary
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": [3.0, 2.0]}, "momentum": {"polar": [0.0, 45.0], "azimuth": 0.0},
    ...        "output": {"path": "summary.zarr"}, "compute": {"T": 1.0, "scheduler": "serial"}}
    >>> sweep_summary(run_sweep(cfg, progress=False))
    {'points': 4, 'regular': 2, 'separatrix': 0, 'symmetric body': 2, 'not a physical body': 0, 'unfinished': 0}
    """
    zarr = require("zarr", "dask")
    p = Path(path)
    try:
        with quiet_zarr():
            g = zarr.open_group(str(p), mode="r")
            status = g["status"]
            chunk = int(g.attrs.get("chunk", 0)) or int(status.chunks[0])
    except Exception as exc:
        raise EulerPoissonError(f"{p} is not an eulerpoisson sweep store ({exc})") from exc
    n = int(status.shape[0])
    counts = np.zeros(len(STATUS) + 1, dtype=np.int64)  # -1 (unfinished), then the status codes
    step = chunk * max(1, 2**22 // chunk)
    for a in range(0, n, step):
        with quiet_zarr():
            s = np.asarray(status[a : min(n, a + step)]).astype(np.int64)
        counts += np.bincount(np.clip(s, -1, len(STATUS) - 1) + 1, minlength=len(STATUS) + 1)
    out = {"points": n}
    out.update({name: int(counts[code + 1]) for code, name in STATUS.items()})
    out["unfinished"] = int(counts[0])
    return out


def load_sweep(path: str | os.PathLike[str], *, squeeze: bool = True) -> xr.Dataset:
    """Read a sweep store as an :class:`xarray.Dataset`.

    A grid sweep is reshaped to its axes (``I1, I2, I3`` or ``I1, ratio21,
    ratio31``, ``polar``, ``azimuth``) with the axis values as coordinates;
    with ``squeeze`` the axes of length 1 become scalar coordinates. A
    random sweep keeps the ``point`` dimension. The bookkeeping variables
    (``chunk_*``) keep their ``chunk`` dimension.

    Parameters
    ----------
    path : str or Path
        A finished store, or a partial one (``.NAME.partial/store.zarr``;
        unfinished points are NaN).
    squeeze : bool

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    FileNotFoundError
        No store there (the message says when a partial sweep exists).
    EulerPoissonError
        Not a sweep store.
    MissingDependencyError
        xarray or zarr missing.

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": [1.5, 2.0], "I3": 3.0}, "momentum": {"polar": 40.0, "azimuth": 20.0},
    ...        "output": {"path": "inertia_line.zarr"}, "compute": {"T": 5.0, "scheduler": "serial"}}
    >>> ds = load_sweep(run_sweep(cfg, progress=False))
    >>> dict(ds.sizes), sorted(ds.data_vars)[:4]
    ({'chunk': 1, 'I2': 2, 'axis': 3}, ['M0', 'chunk_count', 'chunk_seconds', 'chunk_time'])
    """
    xr = require("xarray", "io")
    require("zarr", "dask")
    p = Path(path)
    if not p.exists():
        work = work_dir(p)
        hint = (
            f"; an unfinished sweep is in {work / 'store.zarr'} (rerun the sweep to finish it)" if work.exists() else ""
        )
        raise FileNotFoundError(f"no sweep store at {p}{hint}")
    try:
        with quiet_zarr():
            ds = xr.open_zarr(str(p), consolidated=None).load()
    except Exception as exc:
        raise EulerPoissonError(f"{p} is not a readable Zarr store: {exc}") from exc
    if "sweep_config" not in ds.attrs or "half_period" not in ds:
        raise EulerPoissonError(f"{p} is not an eulerpoisson sweep store")
    ds.encoding["source"] = str(p)  # named by plot_atlas's messages
    if ds.attrs.get("sweep_kind") != "grid":
        return ds
    grid = json.loads(ds.attrs["sweep_grid"])
    names = list(grid)
    shape = tuple(len(v) for v in grid.values())
    coords: dict[str, tuple] = {name: (name, np.asarray(v, float)) for name, v in grid.items()}
    for name in ("polar", "azimuth"):
        coords[name] = (name, coords[name][1], dict(ds[name].attrs))
    data = {}
    for name, var in ds.data_vars.items():
        if "point" in var.dims:
            if name in coords:  # a grid axis: its coordinate says it all
                continue
            tail = var.dims[1:]
            data[name] = (tuple(names) + tail, var.values.reshape(shape + var.shape[1:]), dict(var.attrs))
        else:
            data[name] = var
    out = xr.Dataset(data, coords={**coords, "axis": ds["axis"].values}, attrs=dict(ds.attrs))
    if squeeze:
        out = out.squeeze([d for d, s in zip(names, shape) if s == 1])
    out.encoding["source"] = str(p)
    return out
