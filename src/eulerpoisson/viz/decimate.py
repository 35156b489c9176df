r"""Decimation of long time series for pictures: min/max per pixel column, computed chunk by chunk.

A picture is some 1000 pixels wide; a run may have :math:`10^8` samples.
:class:`MinMaxEnvelope` splits the time range into ``nbins`` columns (more
than the pixels of the axes) and keeps, for every column and every series,
the smallest and the largest value of the samples that fall in it. The
samples arrive in pieces (:meth:`MinMaxEnvelope.add`), so memory is bounded
by the number of columns, not by the length of the run. :meth:`points`
gives a line through the two extremes of every column — alternately
min → max and max → min, so that consecutive columns join — whose vertical
extent over each column is exactly the range of the samples in it: the
drawn envelope contains every sample's value, and nothing more than the
samples reach.

A piece is reduced on its own (:meth:`MinMaxEnvelope.reduce`: for monotonic
times, a search for the column boundaries and one ``minimum`` and one
``maximum`` pass per series, nothing copied) and merged afterwards
(:meth:`MinMaxEnvelope.merge`, in any order): the pieces of a long run are
reduced in several threads at once.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["MinMaxEnvelope", "Piece", "DEFAULT_BINS"]

#: columns of a decimated time series (a 7-inch figure at 150 dpi is about 1000 pixels wide)
DEFAULT_BINS = 2000


class Piece(NamedTuple):
    """The extremes of one piece of samples per column reached (:meth:`MinMaxEnvelope.reduce`)."""

    cols: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    count: np.ndarray  # type: ignore[assignment]  # the field hides tuple.count, which nobody calls on a Piece
    n: int
    tmin: float
    tmax: float
    total: np.ndarray | None = None  # (m, k) sums of the finite samples, with means=True
    finite: np.ndarray | None = None  # (m, k) numbers of finite samples, with means=True


class MinMaxEnvelope:
    """Per-column minimum and maximum of ``k`` series over the time range ``[t0, t1]``.

    Parameters
    ----------
    t0, t1 : float
        Time range (``t0 < t1``); samples outside are put in the first/last column.
    k : int
        Number of series.
    nbins : int
        Number of columns.
    means : bool
        Also keep the sum of the (finite) samples of every column, for
        :meth:`means` (one more pass over the samples).

    Examples
    --------
    >>> env = MinMaxEnvelope(0.0, 1.0, 1, nbins=2, means=True)
    >>> env.add(np.array([0.0, 0.2, 0.6, 0.9]), np.array([1.0, 3.0, -1.0, 5.0]))
    >>> env.means()
    (array([0.25, 0.75]), array([[2.],
           [2.]]))
    """

    def __init__(self, t0: float, t1: float, k: int, nbins: int = DEFAULT_BINS, *, means: bool = False):
        self.t0, self.t1 = float(t0), float(t1)
        self.nbins = int(nbins)
        self.k = int(k)
        self.lo = np.full((self.nbins, self.k), np.inf)
        self.hi = np.full((self.nbins, self.k), -np.inf)
        self.count = np.zeros(self.nbins, dtype=np.int64)
        self.samples = 0
        self.keep_means = bool(means)
        self.total = np.zeros((self.nbins, self.k)) if means else None
        self.finite = np.zeros((self.nbins, self.k), dtype=np.int64) if means else None

    def bins_of(self, t) -> np.ndarray:
        """Column of every time."""
        t = np.asarray(t, dtype=float)
        span = self.t1 - self.t0
        with np.errstate(invalid="ignore"):
            b = np.floor((t - self.t0) / span * self.nbins) if span > 0 else np.zeros_like(t)
        return np.clip(np.nan_to_num(b, nan=0.0), 0, self.nbins - 1).astype(np.int64)

    def add(self, t, y) -> None:
        """Add samples: times ``t`` (n,) and values ``y`` (n, k) (or (n,) for one series, or a list of k columns)."""
        self.merge(self.reduce(t, y))

    def reduce(self, t, y):
        """The extremes of one piece of samples, for :meth:`merge`; reads nothing but ``t0``, ``t1``, ``nbins``.

        Pieces can be reduced in several threads at once and merged in any
        order. ``y`` is an array (n, k) or (n,) or a list of ``k`` arrays
        (n,) (columns: any strides, nothing is copied). Times that are
        monotonic (the usual case) cost a search for the column boundaries
        (:meth:`_starts`) and one ``minimum``/``maximum`` pass per series;
        times in any order are binned one by one.

        Returns
        -------
        Piece
            ``cols`` (m,) the columns reached, ``lo``/``hi`` (m, k) their
            extremes (NaN samples ignored; NaN where a series has none),
            ``count`` (m,), ``n`` samples, ``tmin``/``tmax``.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        n = t.size
        if isinstance(y, (list, tuple)):
            cols = [np.asarray(c, dtype=float).reshape(n) for c in y]
        else:
            y = np.asarray(y, dtype=float).reshape(n, self.k)
            cols = [y[:, j] for j in range(self.k)]
        if len(cols) != self.k:
            raise ValueError(f"expected {self.k} series, got {len(cols)}")
        if n == 0:
            e = np.empty((0, self.k))
            return Piece(np.empty(0, np.int64), e, e, np.empty(0, np.int64), 0, np.inf, -np.inf)
        if n == 1 or bool(np.all(t[1:] >= t[:-1])):
            return self._reduce_sorted(t, cols, float(t[0]), float(t[-1]))
        if bool(np.all(t[1:] <= t[:-1])):  # decreasing times: reversed (views), it is the monotonic case
            return self._reduce_sorted(t[::-1], [c[::-1] for c in cols], float(t[-1]), float(t[0]))
        b = self.bins_of(t)  # any order
        lo = np.full((self.nbins, self.k), np.inf)
        hi = np.full((self.nbins, self.k), -np.inf)
        for j, yj in enumerate(cols):
            ok = ~np.isnan(yj)
            np.fmin.at(lo[:, j], b[ok], yj[ok])
            np.fmax.at(hi[:, j], b[ok], yj[ok])
        count = np.bincount(b, minlength=self.nbins)
        used = np.flatnonzero(count)
        total = finite = None
        if self.keep_means:
            total = np.zeros((used.size, self.k))
            finite = np.zeros((used.size, self.k), dtype=np.int64)
            for j, yj in enumerate(cols):
                ok = ~np.isnan(yj)
                total[:, j] = np.bincount(b[ok], weights=yj[ok], minlength=self.nbins)[used]
                finite[:, j] = np.bincount(b[ok], minlength=self.nbins)[used]
        empty = ~(lo[used] <= hi[used])
        with np.errstate(invalid="ignore"):
            return Piece(
                used,
                np.where(empty, np.nan, lo[used]),
                np.where(empty, np.nan, hi[used]),
                count[used],
                n,
                float(np.min(t)),
                float(np.max(t)),
                total,
                finite,
            )

    def _starts(self, t) -> np.ndarray:
        """First sample of every column reached by increasing times ``t``: where :meth:`bins_of` changes.

        The column edges located by ``searchsorted`` are corrected sample by
        sample against :meth:`bins_of` itself (rounding may put a sample next
        to an edge into the neighbouring column), so that the columns are
        exactly those of :meth:`bins_of`; a binary search if that does not settle.
        """
        n = t.size
        b0, b1 = (int(v) for v in self.bins_of(t[[0, -1]]))
        if b1 == b0:
            return np.zeros(1, np.int64)
        js = np.arange(b0 + 1, b1 + 1)
        span = self.t1 - self.t0
        pos = np.searchsorted(t, self.t0 + js * (span / self.nbins)) if span > 0 else np.full(js.size, n - 1)
        pos = np.clip(pos, 1, n - 1)  # first index with bins_of >= j: t[0] is in b0 < j, t[-1] in b1 >= j
        for _ in range(8):
            up = self.bins_of(t[pos]) < js  # too early: move right
            down = ~up & (self.bins_of(t[pos - 1]) >= js)  # too late: move left
            if not (up.any() or down.any()):
                break
            pos = np.clip(pos + up - down, 1, n - 1)
        else:
            pos = self._starts_bisect(t, js)
        return np.unique(np.concatenate([[0], pos]))  # columns without samples share their next one's start

    def _starts_bisect(self, t, js) -> np.ndarray:
        lo = np.zeros(js.size, np.int64)  # bins_of(t[lo]) < j <= bins_of(t[hi])  (bins_of is monotonic in t)
        hi = np.full(js.size, t.size - 1, np.int64)
        while True:
            open_ = hi - lo > 1
            if not open_.any():
                return hi
            mid = (lo + hi) // 2
            ge = self.bins_of(t[mid]) >= js
            hi = np.where(open_ & ge, mid, hi)
            lo = np.where(open_ & ~ge, mid, lo)

    def _reduce_sorted(self, t, cols, tmin, tmax):
        n = t.size
        starts = self._starts(t)
        bins = self.bins_of(t[starts])
        ends = np.append(starts[1:], n)
        lo = np.empty((starts.size, self.k))
        hi = np.empty((starts.size, self.k))
        for j, yj in enumerate(cols):
            lo[:, j] = np.minimum.reduceat(yj, starts)
            hi[:, j] = np.maximum.reduceat(yj, starts)
        total = finite = None
        if self.keep_means:
            total = np.empty((starts.size, self.k))
            for j, yj in enumerate(cols):
                total[:, j] = np.add.reduceat(yj, starts)
            finite = np.repeat((ends - starts)[:, None], self.k, axis=1)
        bad = np.isnan(lo) | np.isnan(hi)
        if bad.any():  # a column with NaN samples: their extremes without them (NaN when all are NaN)
            with np.errstate(invalid="ignore"):
                for c, j in zip(*np.nonzero(bad)):
                    seg = cols[j][starts[c] : ends[c]]
                    lo[c, j] = np.fmin.reduce(seg)
                    hi[c, j] = np.fmax.reduce(seg)
                    if total is not None and finite is not None:
                        ok = ~np.isnan(seg)
                        total[c, j] = np.sum(seg[ok])
                        finite[c, j] = int(np.count_nonzero(ok))
        return Piece(bins, lo, hi, ends - starts, n, tmin, tmax, total, finite)

    def merge(self, piece) -> None:
        """Add the extremes of a piece reduced by :meth:`reduce` (of this envelope, or one with the same columns)."""
        c = piece.cols
        if c.size:
            self.lo[c] = np.fmin(self.lo[c], piece.lo)
            self.hi[c] = np.fmax(self.hi[c], piece.hi)
            self.count[c] += piece.count
            if self.total is not None and self.finite is not None and piece.total is not None:
                self.total[c] += piece.total
                self.finite[c] += piece.finite
        self.samples += piece.n

    def bands(self):
        """``(x, lo, hi)``: the centre of every non-empty column (m,) and the extremes there (m, k), NaN where none."""
        used = np.flatnonzero(self.count > 0)
        xc = self.t0 + (used + 0.5) * ((self.t1 - self.t0) / self.nbins)
        lo, hi = self.lo[used], self.hi[used]
        empty = ~(lo <= hi)
        return xc, np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)

    def means(self):
        """``(x, mean)``: the centre of every non-empty column (m,) and the mean of its finite samples (m, k).

        Raises
        ------
        ValueError
            The envelope was made without ``means=True``.
        """
        if self.total is None or self.finite is None:
            raise ValueError("this envelope keeps no sums: make it with MinMaxEnvelope(..., means=True)")
        used = np.flatnonzero(self.count > 0)
        xc = self.t0 + (used + 0.5) * ((self.t1 - self.t0) / self.nbins)
        f = self.finite[used]
        with np.errstate(invalid="ignore", divide="ignore"):
            return xc, np.where(f > 0, self.total[used] / np.maximum(f, 1), np.nan)

    def points(self):
        """``(x, y)``: two points per non-empty column at its centre, ``x`` (2m,), ``y`` (2m, k).

        A column where a series has no finite value gives NaN there (a gap).
        """
        used = np.flatnonzero(self.count > 0)
        w = (self.t1 - self.t0) / self.nbins
        xc = self.t0 + (used + 0.5) * w
        lo = self.lo[used]
        hi = self.hi[used]
        empty = ~(lo <= hi)
        lo = np.where(empty, np.nan, lo)
        hi = np.where(empty, np.nan, hi)
        flip = (np.arange(used.size) % 2 == 1)[:, None]
        first = np.where(flip, hi, lo)
        second = np.where(flip, lo, hi)
        x = np.repeat(xc, 2)
        y = np.empty((2 * used.size, self.k))
        y[0::2] = first
        y[1::2] = second
        return x, y
