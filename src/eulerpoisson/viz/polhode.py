r"""The ``polhode`` picture: the body angular momentum on the momentum sphere.

:math:`\mathbf M(t)` drawn with the intersections of the sphere with the
energy ellipsoids (polhodes, :func:`sphere_conic`) and the separatrices
through the intermediate axis. Part of :mod:`eulerpoisson.viz.plots`, which
re-exports every name.

Examples
--------
>>> [c.shape for c in sphere_conic([1.0, 2.0, 3.0], 0.9, 1.0)]  # two closed curves about the axis of I1
[(1200, 3), (1200, 3)]
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .long_runs import body_model
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
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = [
    "plot_polhode",
    "sphere_conic",
    "TORQUE_NOTE",
]


# ---------------------------------------------------------------------------
# polhode
# ---------------------------------------------------------------------------
def sphere_conic(moments, level, radius, n=1200):
    r"""Intersection of the momentum sphere with a level set of the energy.

    Curves of :math:`\mathbf M` in the principal frame with

    .. math:: |\mathbf M|^2 = L^2, \qquad \sum_i M_i^2/I_i = L^2 D,

    i.e. :math:`D = 2E/L^2`. For :math:`D = 1/I_2` (the intermediate moment)
    these are the separatrices: two great circles through :math:`\pm L\mathbf e_2`.

    Parameters
    ----------
    moments : array_like, shape (3,)
        Principal moments :math:`I_i`.
    level : float
        :math:`D`, between :math:`1/\max I` and :math:`1/\min I`.
    radius : float
        :math:`L = |\mathbf M|`.
    n : int
        Points per curve.

    Returns
    -------
    list of ndarray, each of shape (k, 3)
        Closed curves (first point repeated at the end); a single point
        :math:`\pm L\mathbf e_j` for a permanent rotation; empty when the
        level is outside the range (or the body is a sphere).

    Notes
    -----
    With :math:`c_i = 1/I_i - D`, the curve is :math:`\sum c_i M_i^2 = 0` on
    the sphere. Away from the separatrix exactly one :math:`c_j` has a sign
    different from the others; with :math:`p_i = -c_i/c_j > 0` the curve is
    :math:`M_i = \rho\cos\varphi/\sqrt{p_i}`, :math:`M_k = \rho\sin\varphi/\sqrt{p_k}`,
    :math:`M_j = \pm\rho` with :math:`\rho` fixed by the sphere. When one
    :math:`c_i` vanishes the quadric is a pair of planes through
    :math:`\mathbf e_i` and the curves are great circles.
    """
    I = np.asarray(moments, float)
    a = 1.0 / I
    c = a - float(level)
    L = float(radius)
    tol = 1e-9 * np.max(np.abs(a))
    zero = np.abs(c) <= tol
    th = np.linspace(0.0, 2 * np.pi, n)
    E = np.eye(3)

    def circle(e1, e2):
        return L * (np.cos(th)[:, None] * e1 + np.sin(th)[:, None] * e2)

    if zero.all():
        return []
    if zero.sum() == 2:
        i, k = map(int, np.flatnonzero(zero))
        return [circle(E[i], E[k])]
    if zero.sum() == 1:
        i = int(np.flatnonzero(zero)[0])
        j, k = [x for x in range(3) if x != i]
        if c[j] * c[k] > 0:
            return [L * E[i][None, :], -L * E[i][None, :]]
        s = np.sqrt(-c[k] / c[j])
        out = []
        for sign in (1.0, -1.0):
            u = E[k] + sign * s * E[j]
            out.append(circle(E[i], u / np.linalg.norm(u)))
        return out
    pos = c > 0
    if pos.all() or (~pos).all():
        return []
    j = int(np.flatnonzero(pos)[0]) if pos.sum() == 1 else int(np.flatnonzero(~pos)[0])
    i, k = [x for x in range(3) if x != j]
    pi, pk = -c[i] / c[j], -c[k] / c[j]
    # dense parametrization, then resampling by arc length (the parametrization
    # crowds near the saddles when the level is close to the separatrix)
    phi = np.linspace(0.0, 2 * np.pi, 8 * n)
    rho = L / np.sqrt(1.0 + np.cos(phi) ** 2 / pi + np.sin(phi) ** 2 / pk)
    out = []
    for sign in (1.0, -1.0):
        P = np.zeros((phi.size, 3))
        P[:, i] = rho * np.cos(phi) / np.sqrt(pi)
        P[:, k] = rho * np.sin(phi) / np.sqrt(pk)
        P[:, j] = sign * rho
        seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        si = np.linspace(0.0, s[-1], n)
        phs = np.interp(si, s, phi)
        r = L / np.sqrt(1.0 + np.cos(phs) ** 2 / pi + np.sin(phs) ** 2 / pk)
        Q = np.zeros((n, 3))
        Q[:, i] = r * np.cos(phs) / np.sqrt(pi)
        Q[:, k] = r * np.sin(phs) / np.sqrt(pk)
        Q[:, j] = sign * r
        out.append(Q)
    return out


def plot_polhode(
    traj: Trajectory | LazyTrajectory,
    ax: Axes3D | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    family: int = 4,
    **style: Any,
) -> Figure:
    r"""The body angular momentum on the momentum sphere (polhode picture).

    Draws, in the principal frame of the body: the computed path
    :math:`\mathbf M(t)` (thick), the exact intersection of the sphere
    :math:`|\mathbf M| = L` with the energy ellipsoid
    :math:`\mathbf M\cdot I^{-1}\mathbf M = 2E` (dashed, it should lie under
    the path), the separatrices :math:`\mathbf M\cdot I^{-1}\mathbf M = L^2/I_2`
    through the intermediate axis (black), ``family`` further polhodes on each
    side (light), a wireframe sphere and the principal axes.

    Under torque :math:`|\mathbf M|` and the kinetic energy change, so the
    sphere and the polhodes of the free body do not hold: only the path
    :math:`\mathbf M(t)` and the principal axes are drawn, with what the
    model conserves in this space — for a Lagrange top (symmetric body, centre
    of mass on its axis, under gravity) the plane
    :math:`\mathbf M\cdot\mathbf e_3 = M_3(t_0)` of the constant component
    along the symmetry axis — and a note on the figure says so.

    Parameters
    ----------
    traj, ax, fig, index
        As for :func:`plot_omega`; ``ax`` must be 3-D.
    family : int
        Number of extra polhodes per side of the separatrix (0 for none).
    **style
        Passed to ``Axes.plot`` for the path.

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
    model = body_model(traj, index)
    mpl = import_matplotlib()
    Mp = one.M @ one.axes  # principal components P^T M, (T, 3)
    k = one.first
    L = float(np.linalg.norm(Mp[k]))
    I = one.moments
    free = model.is_free
    if free:
        lim = 1.2 * (L if L > 0 else 1.0)
    else:
        big = float(np.max(np.linalg.norm(Mp, axis=-1)))
        lim = 1.2 * (big if big > 0 else 1.0)
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, True, (6.2, 6.0))
        unit = f"kg m²/{one.unit}"
        _setup_3d(ax, lim, [f"M{str(i + 1).translate(_SUB)} [{unit}]" for i in range(3)])
        if free and L > 0:
            _unit_sphere(ax, L, alpha=0.12)
            a = 1.0 / I
            order = np.argsort(a)
            lo, mid, hi = a[order]
            spherical = np.isclose(lo, hi, rtol=1e-9, atol=0)
            fam = int(family)
            first_family = True
            if not spherical and fam > 0:
                fr = np.arange(1, fam + 1) / (fam + 1)
                for D in np.concatenate([lo + fr * (mid - lo), mid + fr * (hi - mid)]):
                    if np.isclose(D, mid):
                        continue
                    for cur in sphere_conic(I, D, L, n=300):
                        ax.plot(
                            *cur.T, color="#8fa8c8", lw=0.6, alpha=0.8, label="other polhodes" if first_family else None
                        )
                        first_family = False
            if not spherical:
                for ic, cur in enumerate(sphere_conic(I, mid, L, n=600)):
                    ax.plot(*cur.T, color="k", lw=1.1, label="separatrices" if ic == 0 else None)
            D0 = 2.0 * float(one.energy[k]) / L**2
            for ic, cur in enumerate(sphere_conic(I, D0, L, n=600)):
                ax.plot(
                    *cur.T, color="#ff7f0e", lw=1.2, ls="--", label="|M| = L ∩ energy ellipsoid" if ic == 0 else None
                )
        note = None
        if not free:
            note = _conserved_under_torque(ax, model, one, Mp)
        # principal axes
        for i in range(3):
            e = np.eye(3)[i] * lim
            ax.plot(*np.stack([-e, e]).T, color=AXIS_COLORS[i], lw=0.9, alpha=0.9)
            ax.text(
                *(1.08 * e),
                f"I{str(i + 1).translate(_SUB)}={_fmt(I[i])}",
                color=AXIS_COLORS[i],
                fontsize=8.5,
                ha="center",
            )
        sl = _stride(len(Mp))
        kw = {"color": "#8c1d8c", "lw": 2.2 if free else 1.4, **style}
        ax.plot(*Mp[sl].T, label="M(t) computed", **kw)
        ax.scatter(*Mp[k], color="#8c1d8c", s=25, depthshade=False, label="M(t₀)")
        ax.legend(loc="upper left", fontsize=8)
        if free:
            ax.set_title(_title(one, "Polhode: body angular momentum M(t) on |M| = L"))
        else:
            torques = ", ".join(dict.fromkeys(type(tq).__name__ for tq in model.torques))
            ax.set_title(_title(one, f"Body angular momentum M(t) under torque ({torques})"))
            ax.text2D(
                0.5,
                0.0,
                note,
                transform=ax.transAxes,
                ha="center",
                va="bottom",
                fontsize=8,
                color="0.25",
                wrap=True,
            )
    return fig


#: the note of a polhode picture under torque (no sphere, no polhodes)
TORQUE_NOTE = "under torque |M| and the kinetic energy change: no momentum sphere, no polhodes drawn"


def _conserved_under_torque(ax, model, one, Mp) -> str:
    """Draw what the torque model conserves in the space of M (a Lagrange top: the plane M·e₃ = const); the note."""
    lt = model.lagrange_top()
    if lt is None:
        return TORQUE_NOTE + "; this model conserves nothing in this space"
    c = np.asarray(lt.frame, dtype=float)[..., :, 2]  # the symmetry axis (through the centre of mass), body frame
    u = one.axes.T @ c  # ... in the principal frame of the picture
    u = u / np.linalg.norm(u)
    M3 = float(Mp[one.first] @ u)
    across = Mp - np.outer(Mp @ u, u)
    r = 1.15 * max(float(np.max(np.linalg.norm(across, axis=-1))), 1e-3 * float(np.max(np.abs(Mp))) or 1.0)
    e1 = np.cross(u, np.eye(3)[int(np.argmin(np.abs(u)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    th = np.linspace(0.0, 2.0 * np.pi, 181)
    ring = M3 * u + r * (np.cos(th)[:, None] * e1 + np.sin(th)[:, None] * e2)
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax.add_collection3d(Poly3DCollection([ring], facecolor="#ff7f0e", alpha=0.12, edgecolor="none"))
    ax.plot(*ring.T, color="#ff7f0e", lw=1.2, ls="--", label="M·e₃ = M₃(t₀): conserved (Lagrange top)")
    return TORQUE_NOTE + "; a Lagrange top keeps M₃ = M·e₃ (symmetry axis): the path stays in that plane"
