r"""The ``gibbs`` picture: the paper's Gibbs vector in local charts, and the split into charts.

:func:`chart_segments` splits an attitude series into local Gibbs-vector
charts (in linear time; :func:`chart_bounds` finds the charts, compiled by
numba for long series); :func:`plot_gibbs` draws the bouquet of geodesic
arcs. See the module docstring of :mod:`eulerpoisson.viz.plots` (which
re-exports every name) for the chart restarts.

Examples
--------
>>> import numpy as np
>>> q = np.array([[np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)] for a in np.linspace(0.0, 3.0, 31)])
>>> [len(idx) for idx, n_loc, q_ref in chart_segments(q)]
[17, 15]
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError
from ..numerics.quaternion import qmul, qmul_components
from .long_runs import MAX_CHARTS
from .long_runs import MAX_GIBBS_SAMPLES as _MAX_GIBBS_SAMPLES
from .long_runs import thin as _thin
from .plot_common import AXIS_COLORS, STYLE, import_matplotlib, select_body
from .plot_common import SUBSCRIPTS as _SUB
from .plot_common import draw_unit_sphere as _unit_sphere
from .plot_common import fmt_number as _fmt
from .plot_common import new_axes as _new_axes
from .plot_common import setup_3d as _setup_3d
from .plot_common import stride as _stride
from .plot_common import title_of as _title

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = [
    "plot_gibbs",
    "chart_segments",
    "chart_bounds",
    "chart_bounds_numpy",
    "CHART_KERNEL",
]


# ---------------------------------------------------------------------------
# gibbs
# ---------------------------------------------------------------------------
def chart_segments(q, chart_radius=1.0, *, jump_limit=4.0):
    r"""Split an attitude series into local Gibbs-vector charts.

    The first chart is centred on ``q[0]``. Along the series the local Gibbs
    vector :math:`\mathbf n_\mathrm{loc} = \mathrm{gibbs}(q_\mathrm{ref}^{-1}\otimes q)`
    (:math:`R(q) = R(q_\mathrm{ref})R(\mathbf n_\mathrm{loc})`) is kept while
    :math:`|\mathbf n_\mathrm{loc}| \le` ``chart_radius``; the first sample
    beyond it ends the segment (it is included, unless it has jumped past
    ``jump_limit * chart_radius`` — a too coarse sampling) and becomes the
    centre of the next chart, where its local vector is 0.

    Parameters
    ----------
    q : array_like, shape (T, 4)
        Attitudes in time order (unit quaternions).
    chart_radius : float
        Restart threshold on :math:`|\mathbf n_\mathrm{loc}| = \tan(\alpha_\mathrm{rel}/2)`;
        the default 1 restarts at a relative rotation of 90°.
    jump_limit : float
        See above.

    Returns
    -------
    list of (indices, n_loc, q_ref)
        ``indices`` (k,) into ``q``, ``n_loc`` (k, 3) the local Gibbs vectors,
        ``q_ref`` (4,) the chart centre. Consecutive segments share their
        boundary sample (when it is included).

    Raises
    ------
    InvalidInputError
        ``q`` not of shape (T, 4) or non-finite; ``chart_radius`` not positive
        and finite.

    References
    ----------
    Paper eq. 1.8 (the Gibbs vector) and 1.13 (the metric, the same in every chart).
    """
    from ..util.validate import as_float_array

    q = as_float_array(q, "q", (4,))
    if q.ndim != 2:
        raise InvalidInputError(f"q must have shape (T, 4), got {q.shape}")
    r = float(chart_radius)
    if not (np.isfinite(r) and r > 0):
        raise InvalidInputError(f"chart_radius must be positive and finite, got {chart_radius!r}")
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    conj = np.array([1.0, -1.0, -1.0, -1.0])
    bounds = chart_bounds(q, r, float(jump_limit))
    if not bounds:
        return []
    # the local vectors of all charts at once: q_ref^-1 q for every sample of every chart
    starts = np.array([a for a, _ in bounds])
    lens = np.array([b - a for a, b in bounds])
    idx_all = np.concatenate([np.arange(a, b) for a, b in bounds])
    rel = qmul(np.repeat(q[starts] * conj, lens, axis=0), q[idx_all])
    first = np.concatenate([[0], np.cumsum(lens)[:-1]])
    rel[first] = (1.0, 0.0, 0.0, 0.0)  # the chart centres, exactly (q_ref^-1 q_ref rounds to it)
    n_all = rel[:, 1:] / rel[:, :1]
    cut = np.cumsum(lens)[:-1]
    return list(zip(np.split(idx_all, cut), np.split(n_all, cut), q[starts]))


def chart_bounds_numpy(q, r: float, jump_limit: float) -> list[tuple[int, int]]:
    """``(start, end)`` of every chart of :func:`chart_segments` (numpy, in windows that double)."""
    conj = np.array([1.0, -1.0, -1.0, -1.0])
    T = q.shape[0]
    out = []
    start = 0
    window = 64
    while start < T:
        ref = q[start] * conj
        # the chart's samples are examined in windows that double until the chart is left: the work
        # is proportional to the samples of the chart (not to all the samples after it, which made the
        # split quadratic in the length of the run)
        stop = start
        h = -1
        while stop < T:
            lo, stop = stop, min(T, stop + window)
            seg = q[lo:stop]
            w, x, y, z = qmul_components(ref[0], ref[1], ref[2], ref[3], seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3])
            # |n| > r  <=>  |v| > r |w|  (no division: w may be 0); the centre itself is never out
            out_ = np.sqrt(x * x + y * y + z * z) > r * np.abs(w)
            if lo == start:
                out_[0] = False
            hit = np.flatnonzero(out_)
            if hit.size:
                k = int(hit[0])
                h = lo - start + k
                big = np.sqrt(x[k] ** 2 + y[k] ** 2 + z[k] ** 2) > jump_limit * r * abs(w[k])
                break
            window *= 2
        if h < 0:
            out.append((start, T))
            break
        window = max(64, 2 * (h + 1))
        out.append((start, start + (h if big else h + 1)))
        start += h
    return out


def _chart_bounds_compiled():
    from numba import njit

    from ..util.jit import activate

    activate()  # the jitable helpers (qmul_components) are registered with numba before the kernel is typed

    @njit(cache=True)
    def bounds(q, r, jump_limit):  # pragma: no cover - compiled
        T = q.shape[0]
        starts = np.empty(T, np.int64)
        ends = np.empty(T, np.int64)
        n = 0
        start = 0
        while start < T:
            rw, rx, ry, rz = q[start, 0], -q[start, 1], -q[start, 2], -q[start, 3]
            h = -1
            big = False
            for i in range(start + 1, T):
                w, x, y, z = qmul_components(rw, rx, ry, rz, q[i, 0], q[i, 1], q[i, 2], q[i, 3])
                nv = np.sqrt(x * x + y * y + z * z)
                if nv > r * abs(w):
                    h = i - start
                    big = nv > jump_limit * r * abs(w)
                    break
            starts[n] = start
            if h < 0:
                ends[n] = T
                n += 1
                break
            ends[n] = start + h if big else start + h + 1
            n += 1
            start += h
        return starts[:n], ends[:n]

    return bounds


CHART_KERNEL: list = []


def chart_bounds(q, r: float, jump_limit: float) -> list[tuple[int, int]]:
    """The charts' ``(start, end)``: a numba kernel when numba is used, else :func:`chart_bounds_numpy`."""
    from ..util.jit import USE_NUMBA

    if USE_NUMBA and q.shape[0] > 20_000:  # (short series: not worth the compilation)
        if not CHART_KERNEL:
            CHART_KERNEL.append(_chart_bounds_compiled())
        a, b = CHART_KERNEL[0](np.ascontiguousarray(q), float(r), float(jump_limit))
        return list(zip(a.tolist(), b.tolist()))
    return chart_bounds_numpy(q, r, jump_limit)


def plot_gibbs(
    traj: Trajectory | LazyTrajectory,
    ax: Axes3D | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    chart_radius: float = 1.0,
    **style: Any,
) -> Figure:
    r"""Path of the paper's Gibbs vector :math:`\mathbf n(t)`, in local charts.

    The global :math:`\mathbf n` is infinite at the rotation angle
    :math:`\pi`; the path is drawn in local charts with restarts
    (:func:`chart_segments`): each segment is the local Gibbs vector
    relative to the attitude at its start, so each is a geodesic of the
    paper's metric :math:`G(\mathbf n)` (eq. 1.13) through the origin, and
    ends on the sphere :math:`|\mathbf n| =` ``chart_radius`` (drawn), where
    the next chart starts (marked ×). Segments are coloured by their start
    time.

    Parameters
    ----------
    traj, ax, fig, index
        As for :func:`plot_omega`; ``ax`` must be 3-D.
    chart_radius : float
        Restart threshold on :math:`|\mathbf n_\mathrm{loc}|` (1: 90°).
    **style
        Passed to ``Axes.plot`` for the segments.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError, InvalidInputError, MissingDependencyError
        As for :func:`plot_omega`; ``chart_radius`` not positive.
    """
    traj, starts = _thin(traj, _MAX_GIBBS_SAMPLES, blocks=True)  # a long run (or a store): evenly strided
    one = select_body(traj, index)
    mpl = import_matplotlib()
    segs = []
    bounds = list(starts) + [len(traj.t)]
    for a, b in zip(bounds[:-1], bounds[1:]):  # a gap in time (a store read in parts) starts a new chart
        segs += [(idx + a, n, ref) for idx, n, ref in chart_segments(one.q[a:b], chart_radius)]
    r = float(chart_radius)
    lim = 1.15 * r
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, True, (6.6, 6.0))
        _setup_3d(ax, lim, [f"n{str(i + 1).translate(_SUB)} [dimensionless]" for i in range(3)])
        _unit_sphere(ax, r, alpha=0.15)
        cmap = mpl.colormaps["viridis"]
        t0, t1 = one.t[0], one.t[-1]
        norm = mpl.colors.Normalize(vmin=t0, vmax=t1)
        kw = {"lw": 1.5, **style}
        ends = [n[-1] for _, n, _ in segs]
        # a long run has thousands of charts: draw at most MAX_CHARTS of them, evenly chosen in time
        drawn = (
            range(len(segs))
            if len(segs) <= MAX_CHARTS
            else np.unique(np.round(np.linspace(0, len(segs) - 1, MAX_CHARTS)).astype(int))
        )
        for j in drawn:
            idx, n, _ = segs[j]
            sl = _stride(len(idx), 4000)
            pts = np.concatenate([n[sl], n[-1:]]) if len(n) > 1 else n
            ax.plot(*pts.T, color=cmap(norm(one.t[idx[0]])), **kw)
        if len(segs) > MAX_CHARTS:
            ax.text2D(
                0.99,
                0.01,
                f"{len(drawn)} of {len(segs)} charts drawn",
                transform=ax.transAxes,
                ha="right",
                va="bottom",
                fontsize=7.5,
                color="0.4",
            )
        ax.scatter([0], [0], [0], color="k", s=18, depthshade=False, label="chart centre n = 0")
        if len(segs) > 1:
            # the restarts that end the drawn charts (all of them when every chart is drawn)
            E = np.array([ends[j] for j in drawn if j < len(segs) - 1])
            ax.scatter(
                *E.T,
                marker="x",
                color="#d62728",
                s=30 if len(segs) <= MAX_CHARTS else 12,
                depthshade=False,
                label=f"chart restart ({len(segs) - 1}×)",
            )
        for i in range(3):
            e = np.eye(3)[i] * lim
            ax.plot(*np.stack([-e, e]).T, color=AXIS_COLORS[i], lw=0.7, alpha=0.6)
        sm = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
        cb = fig.colorbar(sm, ax=ax, shrink=0.6, pad=0.08)
        cb.set_label(f"chart start time [{one.unit}]")
        ax.legend(loc="upper left", fontsize=8)
        ax.set_title(_title(one, f"Gibbs vector n(t) = k tan(α/2) in local charts (restart at |n| = {_fmt(r)})"))
    return fig
