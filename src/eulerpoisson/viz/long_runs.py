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

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError
from ..io.read import LazyTrajectory
from .plot_common import OneBody as _One
from .plot_common import select_body

if TYPE_CHECKING:
    from ..trajectory import Trajectory

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
    "batch_index",
    "body_model",
    "window",
    "StoreWindow",
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


def batch_index(bshape, index) -> tuple:
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


def envelope(traj, index, k: int, values, nbins=None, names=("time", "quaternion", "omega"), *, means: bool = False):
    """Min/max envelope of ``values(piece, one)`` (an array (n, k) or ``k`` columns) over the run, piece by piece.

    Every piece is read and reduced in a worker thread
    (:meth:`MinMaxEnvelope.reduce <eulerpoisson.viz.decimate.MinMaxEnvelope.reduce>`);
    this thread merges the extremes (and with ``means=True`` the sums, for
    :meth:`~eulerpoisson.viz.decimate.MinMaxEnvelope.means`). Returns ``(one, env)``: the body at the
    ends (:func:`_ends`) and the :class:`~eulerpoisson.viz.decimate.MinMaxEnvelope`.
    """
    from .decimate import DEFAULT_BINS, MinMaxEnvelope

    one = _ends(traj, index)
    idx = batch_index(traj.batch_shape, index)
    t0, t1 = float(np.min(one.t)), float(np.max(one.t))
    for _ in range(2):  # a store whose times are not monotonic: a second pass over the true range
        env = MinMaxEnvelope(t0, t1, k, nbins or DEFAULT_BINS, means=means)
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


def decimated_note(ax, n: int, what: str = "min/max") -> None:
    """Say in a corner of ``ax`` that its ``n`` samples are drawn as ``what`` per pixel column."""
    ax.text(
        0.005,
        0.005,
        f"{n:,} samples: {what} per pixel column",
        transform=ax.transAxes,
        ha="left",
        va="bottom",
        fontsize=7,
        color="0.45",
    )


def body_model(traj, index) -> Any:
    """The :class:`~eulerpoisson.model.equations.Model` of the body ``index`` of ``traj`` (one element of a batch)."""
    model = traj.model
    bshape = tuple(traj.batch_shape)
    if not bshape:
        return model
    return model.element(batch_index(bshape, index))


# ---------------------------------------------------------------------------
# a window of a run: t_start <= t <= t_end
# ---------------------------------------------------------------------------
def _time_bound(value, name: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidInputError(f"{name} must be a number (a time of the run) or None, got {value!r}")
    v = float(value)
    if not np.isfinite(v):
        raise InvalidInputError(f"{name} must be a finite time, got {value!r}")
    return v


class _WindowTimes:
    """The ``time`` of a :class:`StoreWindow`: samples ``a0 : a0 + n`` of the store's, read on demand."""

    def __init__(self, win: StoreWindow) -> None:
        self._win = win
        self.shape = (win.T,)
        self.ndim = 1
        self.dtype = np.dtype(float)

    def __len__(self) -> int:
        return self.shape[0]

    def read(self, a: int, b: int, step: int = 1, out=None) -> np.ndarray:
        return self._win.read_arrays(("time",), a, b, step)["time"]

    def __getitem__(self, index):
        return np.asarray(self)[index]

    def __array__(self, dtype=None, copy=None):
        x = self.read(0, self.shape[0])
        return x if dtype is None else x.astype(dtype)


class StoreWindow(LazyTrajectory):
    """The samples ``a:b`` of a :class:`~eulerpoisson.io.read.LazyTrajectory`, itself read on demand.

    Every reading method of the store works on the window (sample 0 is the
    store's sample ``a``); the chunks are those of the store, so a window is
    read chunk by chunk as the store is. Made by :func:`window`.
    """

    store: LazyTrajectory
    offset: int

    def __init__(self, store: LazyTrajectory, a: int, b: int) -> None:  # noqa: D107 (no LazyTrajectory.__init__: nothing is reopened)
        self.__dict__.update({k: v for k, v in store.__dict__.items() if k != "_stored"})
        if isinstance(store, StoreWindow):
            a, b, store = a + store.offset, b + store.offset, store.store
        self.store = store
        self.offset = int(a)
        self.T = max(0, int(b) - int(a))
        self.t = _WindowTimes(self)  # type: ignore[assignment]

    def read(self, a: int = 0, b: int | None = None, step: int = 1) -> Trajectory:
        a, b, step = slice(a, b, step).indices(self.T)
        if step < 0:
            return self.gather(np.arange(self.T)[slice(a, b, step)]) if len(range(a, b, step)) else self.read(0, 0)
        b = max(a, b)
        return self.store.read(self.offset + a, self.offset + b, step)

    def read_arrays(self, names, a: int = 0, b: int | None = None, step: int = 1, *, scratch=None):
        a, b, step = slice(a, b, step).indices(self.T)
        if step < 0:
            raise InvalidInputError("a window of a store is read forwards (step > 0)")
        b = max(a, b)
        return self.store.read_arrays(names, self.offset + a, self.offset + b, step, scratch=scratch)

    def chunk_bounds(self, size: int | None = None) -> list[tuple[int, int]]:
        """``(a, b)`` ranges of the window, each within whole chunks of the store (``size``: as for the store)."""
        size = int(size or self.chunk)
        size = max(1, -(-size // self.chunk) * self.chunk)
        lo, hi = self.offset, self.offset + self.T
        out = []
        for c in range((lo // size) * size, hi, size):
            a, b = max(lo, c), min(hi, c + size)
            if a < b:
                out.append((a - lo, b - lo))
        return out

    def __repr__(self) -> str:
        return f"StoreWindow({self.store!r}, samples {self.offset}:{self.offset + self.T})"


def _first_true(pred, n: int) -> int:
    """The first ``i`` in ``[0, n)`` with ``pred(i)`` (``pred`` False then True along the samples), else ``n``."""
    lo, hi = 0, n
    while lo < hi:
        mid = (lo + hi) // 2
        if pred(mid):
            hi = mid
        else:
            lo = mid + 1
    return lo


def window(traj, t_start=None, t_end=None):
    """The samples of ``traj`` with ``t_start <= t <= t_end`` (either end open when None).

    A trajectory in memory gives a Trajectory (a slice found by a binary
    search when its times are sorted, else a mask); a store (a
    :class:`~eulerpoisson.io.read.LazyTrajectory`, whose times are monotonic)
    gives a :class:`StoreWindow` read on demand, its ends found by a binary
    search on the stored times (a few samples read). ``traj`` itself when
    both ends are None.

    Raises
    ------
    InvalidInputError
        An end that is not a finite number, ``t_start > t_end``, or a window
        with fewer than two samples (the message gives the run's time range).
    TypeError
        ``traj`` is not a trajectory.
    """
    _check_traj(traj)
    lo = _time_bound(t_start, "t_start")
    hi = _time_bound(t_end, "t_end")
    if lo is None and hi is None:
        return traj
    if lo is not None and hi is not None and lo > hi:
        raise InvalidInputError(f"t_start={t_start!r} is after t_end={t_end!r}; give t_start <= t_end")
    lo_ = -np.inf if lo is None else lo
    hi_ = np.inf if hi is None else hi
    if is_lazy(traj):
        T = len(traj)

        def time(i: int) -> float:
            return float(traj.read_arrays(("time",), i, i + 1)["time"][0])

        if T == 0:
            a = b = 0
            span = "no samples"
        else:
            first, last = time(0), time(T - 1)
            span = f"times from {first:g} to {last:g}"
            if last >= first:  # increasing times
                a = _first_true(lambda i: time(i) >= lo_, T)
                b = _first_true(lambda i: time(i) > hi_, T)
            else:  # decreasing times (a run backwards in time)
                a = _first_true(lambda i: time(i) <= hi_, T)
                b = _first_true(lambda i: time(i) < lo_, T)
        n = max(0, b - a)
        out: Any = StoreWindow(traj, a, a + n)
    else:
        t = np.asarray(traj.t, dtype=float)
        span = f"times from {np.min(t):g} to {np.max(t):g}" if t.size else "no samples"
        if t.size < 2 or bool(np.all(t[1:] >= t[:-1])):
            a, b = int(np.searchsorted(t, lo_, "left")), int(np.searchsorted(t, hi_, "right"))
            n = max(0, b - a)
            out = traj[a : a + n] if n else None
        else:
            sel = np.flatnonzero((t >= lo_) & (t <= hi_))
            n = sel.size
            out = traj[sel] if n else None
    if n < 2:
        raise InvalidInputError(
            f"the window t_start={t_start!r}, t_end={t_end!r} holds {n} sample(s) of the run ({span}); "
            "a picture needs at least two: widen the window"
        )
    return out
