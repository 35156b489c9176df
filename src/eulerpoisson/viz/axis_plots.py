r"""The pictures on the unit sphere of the body's axes: ``attitude`` and ``apex``.

:func:`plot_attitude` traces the principal axes of the body with the fixed
direction of :math:`\mathbf m`; :func:`plot_apex` the locus of the symmetry
axis of a top (:func:`apex_axis`) seen from above: precession, nutation
loops and cusps. Part of :mod:`eulerpoisson.viz.plots`, which re-exports
every name.

Examples
--------
>>> import eulerpoisson as ep
>>> apex_axis(ep.Model([1.0, 1.0, 0.5]))[1]
'e = symmetry axis 3'
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion
from ..errors import InvalidInputError
from .long_runs import thin as _thin
from .plot_common import AXIS_COLORS, STYLE, import_matplotlib, select_body
from .plot_common import MAX_3D_POINTS as _MAX_3D_POINTS
from .plot_common import SUBSCRIPTS as _SUB
from .plot_common import draw_unit_sphere as _unit_sphere
from .plot_common import fmt_number as _fmt
from .plot_common import new_axes as _new_axes
from .plot_common import setup_3d as _setup_3d
from .plot_common import stride as _stride
from .plot_common import title_of as _title

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D
    from numpy.typing import ArrayLike

    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = [
    "plot_attitude",
    "plot_apex",
    "apex_axis",
]


# ---------------------------------------------------------------------------
# attitude
# ---------------------------------------------------------------------------
def plot_attitude(
    traj: Trajectory | LazyTrajectory,
    ax: Axes3D | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    **style: Any,
) -> Figure:
    r"""The body's principal axes traced on the unit sphere (space frame).

    Curves :math:`R(t)P\mathbf e_i` (:math:`P` the principal axes in the body
    frame; :math:`R(t)\mathbf e_i` for a body given by its principal
    moments), with start (●) and end (■) marked, and the fixed direction
    :math:`\mathbf m/|\mathbf m|` of the spatial angular momentum (★ and an
    arrow). The body axes wander around the fixed :math:`\mathbf m` (for the
    tennis racket the intermediate axis turns over between :math:`\pm\mathbf m`).

    Parameters
    ----------
    traj, ax, fig, index
        As for :func:`plot_omega`; ``ax`` must be 3-D.
    **style
        Passed to ``Axes.plot`` for the three curves.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError, InvalidInputError, MissingDependencyError
        As for :func:`plot_omega`.
    """
    traj = _thin(traj, _MAX_3D_POINTS)  # a long run (or a store): evenly strided, read piece by piece
    one = select_body(traj, index)
    mpl = import_matplotlib()
    sl = _stride(len(one.t))
    R = one.R[sl]
    A = np.einsum("tij,jk->tki", R, one.axes)  # (T, 3 axes, 3 comps)
    m0 = one.m[one.first]
    mn = float(np.linalg.norm(m0))
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, True, (6.2, 6.0))
        _setup_3d(ax, 1.15, [f"{c} [dimensionless]" for c in "xyz"])
        _unit_sphere(ax, 1.0, alpha=0.15)
        kw = {"lw": 1.2, **style}
        for i in range(3):
            ax.plot(
                *A[:, i].T,
                color=AXIS_COLORS[i],
                label=f"axis {i + 1} (I{str(i + 1).translate(_SUB)} = {_fmt(one.moments[i])})",
                **kw,
            )
            ax.scatter(*A[0, i], color=AXIS_COLORS[i], marker="o", s=22, depthshade=False)
            ax.scatter(*A[-1, i], color=AXIS_COLORS[i], marker="s", s=22, depthshade=False)
        if mn > 0:
            u = m0 / mn
            ax.quiver(0, 0, 0, *(1.1 * u), color="k", lw=1.8, arrow_length_ratio=0.1)
            ax.scatter(*u, color="k", marker="*", s=90, depthshade=False, label="m/|m| (fixed)")
        ax.legend(loc="upper left", fontsize=8)
        ax.set_title(_title(one, "Principal axes R(t)·eᵢ in the space frame (● start, ■ end)"))
    return fig


# ---------------------------------------------------------------------------
# apex (tops)
# ---------------------------------------------------------------------------
_MAX_APEX_POINTS = 40000  # longer series are strided (cusps stay sharp at this density)


def _model_of(traj, index):
    """The model (body and torques) of the body drawn by ``select_body(traj, index)``."""
    model = traj.model
    bshape = traj.batch_shape
    if not bshape or not model.batch_shape:
        return model
    if isinstance(index, tuple):
        idx = tuple(int(i) % n for i, n in zip(index, bshape))
    else:
        idx = np.unravel_index(int(index) % int(np.prod(bshape)), bshape)
    return model.element(tuple(int(i) for i in idx))


def apex_axis(model, one=None) -> tuple[np.ndarray, str]:
    r"""The body axis whose locus ``apex`` draws, and its name: ``(unit vector, label)``.

    The direction of the centre of mass from the fixed point for a heavy top
    (the first :class:`~eulerpoisson.torques.Gravity` with a centre of mass
    off the origin); otherwise the symmetry axis of a symmetric body (the
    principal axis of the moment that differs from the other two); otherwise
    the principal axis 3.
    """
    from ..model.torques import Gravity

    for tq in model.torques:
        if isinstance(tq, Gravity):
            c = np.asarray(tq.center_of_mass, dtype=float).reshape(-1, 3)[0]
            n = float(np.linalg.norm(c))
            if n > 0:
                return c / n, "e = c/|c| (centre of mass)"
    moments = one.moments if one is not None else np.asarray(model.body.principal_moments).reshape(-1, 3)[0]
    axes = one.axes if one is not None else np.asarray(model.body.principal_axes).reshape(-1, 3, 3)[0]
    scale = max(float(np.max(np.abs(moments))), 1e-300)
    for i in range(3):
        j, l = [a for a in range(3) if a != i]
        if abs(moments[j] - moments[l]) <= 1e-9 * scale and abs(moments[i] - moments[j]) > 1e-9 * scale:
            return axes[:, i], f"e = symmetry axis {i + 1}"
    return axes[:, 2], "e = principal axis 3"


def _view_up(model, one) -> tuple[np.ndarray, str]:
    """The space direction seen from above: against gravity, else along m (free body), else z."""
    from ..model.torques import Gravity

    for tq in model.torques:
        if isinstance(tq, Gravity):
            g = np.asarray(tq.g, dtype=float).reshape(-1, 3)[0]
            n = float(np.linalg.norm(g))
            if n > 0:
                return -g / n, "vertical −g/|g|"
    if model.is_free:
        m0 = one.m[one.first]
        n = float(np.linalg.norm(m0))
        if n > 0:
            return m0 / n, "m/|m|"
    return np.array([0.0, 0.0, 1.0]), "space z"


def plot_apex(
    traj: Trajectory | LazyTrajectory,
    ax: Axes | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    axis: ArrayLike | None = None,
    cmap: str = "viridis",
    **style: Any,
) -> Figure:
    r"""The locus of a top's symmetry axis on the unit sphere, seen from above.

    The unit vector :math:`\mathbf a(t) = R(t)\mathbf e` of the body axis
    :math:`\mathbf e` through the centre of mass (:func:`apex_axis`; for a
    free symmetric body its symmetry axis) is drawn in the orthographic
    projection of the sphere seen from the top: along :math:`-\mathbf g` for
    a heavy top, along the fixed :math:`\mathbf m` for a free body, along the
    space :math:`z` axis otherwise. The curve is coloured by time, with start
    (●) and end (■) marked; circles of constant polar angle (every 15°) and
    the horizon (90°) are drawn, and a part of the curve below the horizon is
    dashed. A fast top precesses slowly around the vertical while it nutates
    between two circles: cusps when it is released without transverse spin,
    loops or waves otherwise. Long runs are strided to at most 40 000 points.

    Parameters
    ----------
    traj, ax, fig, index
        As for :func:`plot_omega`; ``ax`` must be 2-D.
    axis : array_like, shape (3,), optional
        The body axis to follow instead of :func:`apex_axis`.
    cmap : str
        Colour map of the time.
    **style
        Passed to the line collection (``linewidth``, ...).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError, InvalidInputError, MissingDependencyError
        As for :func:`plot_omega`; a zero or non-finite ``axis``.
    """
    traj = _thin(traj, _MAX_APEX_POINTS)  # a long run (or a store): evenly strided, read piece by piece
    one = select_body(traj, index)
    model = _model_of(traj, index)
    if axis is None:
        e, what = apex_axis(model, one)
    else:
        e = np.asarray(axis, dtype=float).reshape(-1)
        if e.shape != (3,) or not np.all(np.isfinite(e)) or not np.linalg.norm(e) > 0:
            raise InvalidInputError(f"axis must be three finite numbers, not all zero; got {axis!r}")
        e = e / np.linalg.norm(e)
        what = "e = (" + ", ".join(_fmt(v) for v in e) + ")"
    up, up_name = _view_up(model, one)
    # an orthonormal frame (u, v, up) of the view
    helper = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = helper - up * np.dot(helper, up)
    u /= np.linalg.norm(u)
    v = np.cross(up, u)
    sl = slice(None, None, max(1, -(-len(one.t) // _MAX_APEX_POINTS)))
    t = one.t[sl]
    a = np.einsum("tij,j->ti", matrix_from_unit_quaternion(one.q[sl]), e)
    x, y, h = a @ u, a @ v, a @ up
    theta = np.degrees(np.arccos(np.clip(h, -1.0, 1.0)))
    mpl = import_matplotlib()
    from matplotlib.collections import LineCollection

    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, False, (6.4, 5.8))
        rmax = 1.0 if np.any(h < 0) else float(np.max(np.hypot(x, y)))
        lim = min(1.06, max(1.15 * rmax, 0.05))
        ang = np.linspace(0.0, 2 * np.pi, 361)
        for deg in range(15, 91, 15):
            r = np.sin(np.radians(deg))
            if r > 1.3 * lim:
                break
            ax.plot(
                r * np.cos(ang),
                r * np.sin(ang),
                color="0.55" if deg == 90 else "0.8",
                lw=1.0 if deg == 90 else 0.6,
                zorder=1,
            )
            if deg % 30 == 0:
                ax.annotate(
                    f"{deg}°",
                    (r * np.cos(np.pi / 4), r * np.sin(np.pi / 4)),
                    color="0.45",
                    fontsize=7.5,
                    ha="left",
                    va="bottom",
                    zorder=1,
                )
        pts = np.stack([x, y], -1)
        segs: Any = np.stack([pts[:-1], pts[1:]], 1)  # (N, 2, 2): LineCollection takes it (its stubs say a list)
        below = (h[:-1] < 0) & (h[1:] < 0)
        kw = {"linewidth": 1.1, **style}
        lc = LineCollection(segs, cmap=cmap, linestyles=[(0, (3, 2)) if b else "solid" for b in below], **kw)
        lc.set_array(0.5 * (t[:-1] + t[1:]) if t.size > 1 else t)
        ax.add_collection(lc)
        ax.scatter([x[0]], [y[0]], color="k", marker="o", s=26, zorder=3, label="start")
        ax.scatter([x[-1]], [y[-1]], color="k", marker="s", s=22, zorder=3, label="end")
        ax.scatter([0.0], [0.0], color="0.3", marker="+", s=60, zorder=2, label=f"up: {up_name}")
        cb = fig.colorbar(lc, ax=ax, shrink=0.8, pad=0.02)
        cb.set_label(f"time t [{one.unit}]")
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xlabel("horizontal component 1 [dimensionless]")
        ax.set_ylabel("horizontal component 2 [dimensionless]")
        ax.legend(loc="lower left", fontsize=8)
        ax.text(
            0.99,
            0.01,
            f"polar angle {np.min(theta):.1f}° to {np.max(theta):.1f}°",
            transform=ax.transAxes,
            ha="right",
            va="bottom",
            fontsize=8,
            color="0.3",
        )
        ax.grid(False)
        ax.set_title(_title(one, f"Axis R(t)·e on the unit sphere seen from above, {what}"))
    return fig
