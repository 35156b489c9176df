r"""Long runs and Zarr stores in the pictures of :mod:`eulerpoisson.viz.plots`.

A time series of more than :data:`DECIMATE_ABOVE` samples is drawn as its
min/max envelope per pixel column (:func:`envelope`, computed piece by piece
of :data:`PIECE` samples, a store read chunk by chunk); the 3-D pictures
draw evenly strided samples (:func:`thin`), a store longer than
:data:`MAX_READ_3D` samples read in whole chunks evenly spread over the run.
Re-exported by :mod:`eulerpoisson.viz.plots`.

Examples
--------
>>> DECIMATE_ABOVE, MAX_CHARTS
(20000, 200)
"""

from __future__ import annotations

import numpy as np

from .plot_common import OneBody as _One
from .plot_common import select_body

__all__ = [
    "DECIMATE_ABOVE",
    "PIECE",
    "MAX_GIBBS_SAMPLES",
    "MAX_CHARTS",
    "MAX_READ_3D",
    "is_lazy",
    "is_long",
    "envelope",
    "thin",
    "decimated_note",
]

#: time series with more samples than this are drawn as min/max envelopes per pixel column
DECIMATE_ABOVE = 20_000
#: samples per piece when a long run is walked through (in memory or in a Zarr store)
PIECE = 200_000
#: most samples a long run is thinned to before the Gibbs vector is split into charts
MAX_GIBBS_SAMPLES = 1_000_000
#: most chart segments drawn by plot_gibbs (evenly chosen among all of them)
MAX_CHARTS = 200


def is_lazy(traj) -> bool:
    """True for a :class:`~eulerpoisson.io.read.LazyTrajectory` (a store read on demand)."""
    """A trajectory read on demand (:class:`eulerpoisson.io.read.LazyTrajectory`)."""
    from ..io.read import LazyTrajectory

    return isinstance(traj, LazyTrajectory)


def is_long(traj) -> bool:
    """True when ``traj`` has more than :data:`DECIMATE_ABOVE` samples (drawn as an envelope)."""
    _check_traj(traj)
    return is_lazy(traj) or len(traj.t) > DECIMATE_ABOVE


def _check_traj(traj) -> None:
    from ..trajectory import Trajectory

    if not (isinstance(traj, Trajectory) or is_lazy(traj)):
        raise TypeError(f"traj must be an eulerpoisson Trajectory, got {type(traj).__name__}")


def _batch_index(bshape, index) -> tuple:
    """The batch index of the body ``index`` (validated by :func:`select_body`)."""
    if not bshape:
        return ()
    if isinstance(index, tuple):
        return tuple(int(i) % n for i, n in zip(index, bshape))
    return tuple(int(i) for i in np.unravel_index(int(index) % int(np.prod(bshape)), bshape))


def _ends(traj, index) -> _One:
    """The body ``index`` at the first and last samples of a long run (labels, inertia, time range)."""
    from ..trajectory import Trajectory

    _check_traj(traj)
    T = len(traj.t) if not is_lazy(traj) else len(traj)
    if T < 2:
        return select_body(traj if not is_lazy(traj) else traj.load(), index)
    if is_lazy(traj):
        ends = traj[[0, T - 1]]
    else:  # (indexing would build an index array of the run's length)
        ends = Trajectory(
            traj.t[[0, T - 1]],
            traj.quaternion[..., [0, T - 1], :],
            traj.omega[..., [0, T - 1], :],
            traj.body,
            traj.method,
            traj.options,
            traj.stats,
            torque=list(traj.model.torques),
        )
    one = select_body(ends, index)
    if not is_lazy(traj):  # in memory: the true time range (the times may be in any order)
        one.t = np.array([float(np.min(traj.t)), float(np.max(traj.t))])
    one.first = 0 if ends.t[0] <= ends.t[-1] or is_lazy(traj) else 1
    return one


def _map_pieces(traj, idx, fn, names=("time", "quaternion", "omega"), size: int | None = None):
    """``fn(piece)`` for the run of body ``idx``, piece by piece, in order; the pieces are computed in threads.

    A piece is a dict of the arrays ``names`` of that body (a store reads
    those only, its chunks decoded in parallel; a run in memory gives views).
    Memory is bounded by a few pieces (:func:`~eulerpoisson.io.read.ordered_map`).
    """
    from ..io.read import ordered_map

    size = PIECE if size is None else size
    if is_lazy(traj):

        def one(piece):
            return fn({k: (v if k == "time" or not idx else v[idx]) for k, v in piece.items()})

        yield from traj.map_arrays(names, one, size, reuse=True)  # fn reduces the piece: its memory is reused
        return
    q, w = traj.quaternion[idx], traj.omega[idx]

    def view(a):  # in memory: views, and the state only
        return fn({"time": traj.t[a : a + size], "quaternion": q[a : a + size], "omega": w[a : a + size]})

    yield from ordered_map(view, range(0, len(traj.t), size))


def envelope(traj, index, k: int, values, nbins=None, names=("time", "quaternion", "omega")):
    """Min/max envelope of ``values(piece, one)`` (an array (n, k) or ``k`` columns) over the run, piece by piece.

    Every piece is read and reduced in a worker thread
    (:meth:`MinMaxEnvelope.reduce <eulerpoisson.viz.decimate.MinMaxEnvelope.reduce>`);
    this thread merges the extremes. Returns ``(one, env)``: the body at the
    ends (:func:`_ends`) and the :class:`~eulerpoisson.viz.decimate.MinMaxEnvelope`.
    """
    from .decimate import DEFAULT_BINS, MinMaxEnvelope

    one = _ends(traj, index)
    idx = _batch_index(traj.batch_shape, index)
    t0, t1 = float(np.min(one.t)), float(np.max(one.t))
    for _ in range(2):  # a store whose times are not monotonic: a second pass over the true range
        env = MinMaxEnvelope(t0, t1, k, nbins or DEFAULT_BINS)
        lo, hi = t0, t1

        def reduce(piece, env=env):
            return env.reduce(piece["time"], values(piece, one))

        for part in _map_pieces(traj, idx, reduce, names):
            lo, hi = min(lo, part.tmin), max(hi, part.tmax)
            env.merge(part)
        if lo >= t0 and hi <= t1:
            break
        t0, t1 = lo, hi
    one.t = np.array([t0, t1])
    return one, env


#: most samples read from a store for a 3-D picture (whole Zarr chunks, evenly spread over the run)
MAX_READ_3D = 10_000_000


def thin(traj, limit: int, *, blocks: bool = False):
    """At most about ``limit`` evenly strided samples (the first one kept), as an in-memory Trajectory.

    A store is read piece by piece; one longer than :data:`MAX_READ_3D`
    samples is read in whole Zarr chunks evenly spread over the run (the
    3-D pictures are point samples of a path: the time for a picture stays
    bounded at any length). With ``blocks=True`` also the start positions,
    in the result, of its contiguous runs of samples (the joins are gaps in time).
    """
    from ..trajectory import Trajectory

    _check_traj(traj)
    if not is_lazy(traj):
        T = len(traj.t)
        if T > limit:
            step = -(-T // limit)
            traj = Trajectory(
                traj.t[::step],
                traj.quaternion[..., ::step, :],
                traj.omega[..., ::step, :],
                traj.body,
                traj.method,
                traj.options,
                traj.stats,
                torque=list(traj.model.torques),
            )
        return (traj, [0]) if blocks else traj
    T = len(traj)
    chunks = traj.chunk_bounds()
    if T > MAX_READ_3D and len(chunks) > 1:
        keep = max(1, MAX_READ_3D // traj.chunk)
        chunks = [chunks[i] for i in np.unique(np.round(np.linspace(0, len(chunks) - 1, keep)).astype(int))]
    total = sum(b - a for a, b in chunks)
    step = max(1, -(-total // limit))
    # contiguous runs of the chosen chunks, read in pieces of at most PIECE samples
    runs: list[list[int]] = []
    for a, b in chunks:
        if runs and runs[-1][1] == a:
            runs[-1][1] = b
        else:
            runs.append([a, b])
    ranges, starts, pos = [], [], 0
    for a, b in runs:
        starts.append(pos)
        for c in range(a, b, PIECE):
            d = min(b, c + PIECE)
            c0 = a + -(-(c - a) // step) * step  # the stride continues across pieces of a run
            if c0 < d:
                ranges.append((c0, d, step))
                pos += len(range(c0, d, step))
    parts = list(traj.map_arrays(("time", "quaternion", "omega"), ranges=ranges))  # read in parallel threads
    if not parts:
        return (traj.load(), [0]) if blocks else traj.load()
    out = Trajectory(
        np.concatenate([p["time"] for p in parts]),
        np.concatenate([p["quaternion"] for p in parts], axis=-2),
        np.concatenate([p["omega"] for p in parts], axis=-2),
        traj.body,
        traj.method,
        traj.options,
        traj.stats,
        torque=list(traj.model.torques),
    )
    return (out, starts) if blocks else out


def decimated_note(ax, n: int) -> None:
    """Say in a corner of ``ax`` that its ``n`` samples are drawn as min/max per pixel column."""
    ax.text(
        0.005,
        0.005,
        f"{n:,} samples: min/max per pixel column",
        transform=ax.transAxes,
        ha="left",
        va="bottom",
        fontsize=7,
        color="0.45",
    )
