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
"""

from __future__ import annotations

import numpy as np

__all__ = ["MinMaxEnvelope", "DEFAULT_BINS"]

#: columns of a decimated time series (a 7-inch figure at 150 dpi is about 1000 pixels wide)
DEFAULT_BINS = 2000


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
    """

    def __init__(self, t0: float, t1: float, k: int, nbins: int = DEFAULT_BINS):
        self.t0, self.t1 = float(t0), float(t1)
        self.nbins = int(nbins)
        self.k = int(k)
        self.lo = np.full((self.nbins, self.k), np.inf)
        self.hi = np.full((self.nbins, self.k), -np.inf)
        self.count = np.zeros(self.nbins, dtype=np.int64)
        self.samples = 0

    def bins_of(self, t) -> np.ndarray:
        """Column of every time."""
        t = np.asarray(t, dtype=float)
        span = self.t1 - self.t0
        with np.errstate(invalid="ignore"):
            b = np.floor((t - self.t0) / span * self.nbins) if span > 0 else np.zeros_like(t)
        return np.clip(np.nan_to_num(b, nan=0.0), 0, self.nbins - 1).astype(np.int64)

    def add(self, t, y) -> None:
        """Add samples: times ``t`` (n,) and values ``y`` (n, k) (or (n,) for one series)."""
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float).reshape(t.shape[0], self.k)
        if t.size == 0:
            return
        b = self.bins_of(t)
        d = np.diff(b)
        if np.all(d <= 0) and not np.all(d == 0):  # decreasing times: reverse, then it is the monotonic case
            b, y, d = b[::-1], y[::-1], -d[::-1]
        if np.all(d >= 0):  # monotonic: every column is one contiguous run
            starts = np.concatenate([[0], np.flatnonzero(d) + 1])
            cols = b[starts]
            with np.errstate(invalid="ignore"):
                mn = np.fmin.reduceat(y, starts, axis=0)
                mx = np.fmax.reduceat(y, starts, axis=0)
            self.lo[cols] = np.fmin(self.lo[cols], mn)
            self.hi[cols] = np.fmax(self.hi[cols], mx)
            self.count[cols] += np.diff(np.concatenate([starts, [b.size]]))
        else:  # any order
            for j in range(self.k):
                yj = y[:, j]
                ok = ~np.isnan(yj)
                np.fmin.at(self.lo[:, j], b[ok], yj[ok])
                np.fmax.at(self.hi[:, j], b[ok], yj[ok])
            np.add.at(self.count, b, 1)
        self.samples += t.size

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
