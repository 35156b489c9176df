r"""The time-series pictures: the angular velocity (``omega``) and the drift of the invariants (``invariants``).

Part of :mod:`eulerpoisson.viz.plots`, which re-exports every name and
dispatches on the kind (:func:`~eulerpoisson.viz.plots.plot`).

Examples
--------
>>> import numpy as np, eulerpoisson as ep
>>> traj = ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 1.0, 11), omega0=[1.0, 0.1, 0.5])
>>> list(invariant_drift(select_body(traj)))
['E', '|m|', 'm₁', 'm₂', 'm₃']
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import numpy as np

from .long_runs import decimated_note as _decimated_note
from .long_runs import envelope as _envelope
from .long_runs import is_lazy as _is_lazy
from .long_runs import is_long as _is_long
from .plot_common import AXIS_COLORS, STYLE, import_matplotlib, select_body
from .plot_common import SUBSCRIPTS as _SUB
from .plot_common import OneBody as _One
from .plot_common import new_axes as _new_axes
from .plot_common import title_of as _title

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = [
    "plot_omega",
    "plot_invariants",
    "invariant_drift",
]


# ---------------------------------------------------------------------------
# omega
# ---------------------------------------------------------------------------
def plot_omega(
    traj: Trajectory | LazyTrajectory,
    ax: Axes | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    **style: Any,
) -> Figure:
    r"""Body angular velocity :math:`\boldsymbol\Omega(t)`, one curve per component.

    For a body near its intermediate axis (the tennis racket) the middle
    component flips sign periodically.

    Parameters
    ----------
    traj : Trajectory
    ax : matplotlib Axes, optional
        Draw into this (2-D) axes.
    fig : matplotlib Figure, optional
        Add a subplot to this figure (ignored when ``ax`` is given).
    index : int or tuple, optional
        Body of a batched trajectory.
    **style
        Passed to ``Axes.plot`` for the three curves (e.g. ``linewidth``).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError
        ``traj`` is not a Trajectory.
    InvalidInputError
        Bad ``index``, ``ax`` or ``fig``; fewer than two distinct times.
    MissingDependencyError
        matplotlib is not installed (extra ``plot``).
    """
    if _is_long(traj):  # min/max per pixel column, computed piece by piece
        one, env = _envelope(traj, index, 3, lambda piece, one: piece["omega"], names=("time", "omega"))
        x, y = env.points()
    else:
        one = select_body(traj, index)
        x, y = one.t, one.omega
    mpl = import_matplotlib()
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, False, (7.0, 3.8))
        for i in range(3):
            ax.plot(x, y[:, i], color=AXIS_COLORS[i], label=f"Ω{str(i + 1).translate(_SUB)}", **style)
        if _is_long(traj):
            _decimated_note(ax, env.samples)
        ax.axhline(0.0, color="0.3", lw=0.6)
        ax.set_xlabel(f"time t [{one.unit}]")
        ax.set_ylabel(f"body angular velocity Ω [rad/{one.unit}]")
        ax.set_xlim(one.t[0], one.t[-1])
        ax.legend(loc="upper right", ncols=3)
        ax.set_title(_title(one, "Body angular velocity Ω(t)"))
    return fig


# ---------------------------------------------------------------------------
# invariants
# ---------------------------------------------------------------------------
def invariant_drift(one: _One) -> dict[str, np.ndarray]:
    r"""Relative drift curves of the integrals (private helper of :func:`plot_invariants`).

    :math:`|E(t)-E_0|/|E_0|`, :math:`||\mathbf m(t)|-|\mathbf m_0||/|\mathbf m_0|`
    and :math:`|m_i(t)-m_i(t_0)|/|\mathbf m_0|`, with the values at the first
    given output time as reference (as :meth:`Trajectory.drift`); zero scales
    give absolute values. Not floored.
    """
    E = one.energy
    m = one.m
    mn = np.linalg.norm(m, axis=-1)
    k = one.first

    def rel(x, ref, scale):
        return np.abs(x - ref) / (scale if scale > 0 else 1.0)

    out = {"E": rel(E, E[k], abs(E[k])), "|m|": rel(mn, mn[k], mn[k])}
    for i in range(3):
        out[f"m{str(i + 1).translate(_SUB)}"] = rel(m[:, i], m[k, i], mn[k])
    return out


def _drift_values(traj, index):
    """``(values, names, scales)`` of the five drift curves of :func:`invariant_drift`, for :func:`_envelope`.

    ``values(piece, one)`` gives the columns :math:`|x - x_0|` (E, the norm of m,
    m1, m2, m3), not yet divided by their ``scales``: a positive division is
    monotonic, so the extremes per column divided afterwards are those of the
    drift, bit for bit, at a fraction of the cost.
    """
    from ..trajectory import Trajectory

    first = (
        traj[0]
        if _is_lazy(traj)
        else Trajectory(traj.t[:1], traj.quaternion[..., :1, :], traj.omega[..., :1, :], traj.body)
    )
    ref = select_body(
        Trajectory(
            np.array([0.0, 1.0]),
            np.repeat(first.quaternion, 2, axis=-2),
            np.repeat(first.omega, 2, axis=-2),
            first.body,
        ),
        index,
    )
    E0 = float(ref.energy[0])
    m0 = ref.m[0]
    mn0 = float(np.linalg.norm(m0))

    # a store keeps m (and, for the free body, the energy): read those instead of computing them
    stored = set(getattr(traj, "variables", ()))
    use_m = _is_lazy(traj) and "m" in stored
    use_E = use_m and "energy" in stored and traj.model.is_free
    names = ("time",) + (("m",) if use_m else ("quaternion",)) + (("energy",) if use_E else ("omega",))

    def values(piece, one):
        n = piece["time"].shape[0]
        cols = _thread_columns(5, n)  # this thread's arrays, reused piece after piece (no fresh pages)

        def dist(x, r, out):
            np.subtract(x, r, out=out)
            return np.abs(out, out=out)

        if use_m:
            m = piece["m"]
        else:
            q, w = piece["quaternion"], piece["omega"]
            m = _rotate(q, w @ one.inertia.T)
        if use_E:
            E = piece["energy"]
        else:
            w = piece["omega"]
            M = w @ one.inertia.T
            E = 0.5 * (w[:, 0] * M[:, 0] + w[:, 1] * M[:, 1] + w[:, 2] * M[:, 2])
        m1, m2, m3 = m[:, 0], m[:, 1], m[:, 2]
        mn, sq = cols[1], cols[2]
        np.square(m1, out=mn)
        mn += np.square(m2, out=sq)
        mn += np.square(m3, out=sq)
        np.sqrt(mn, out=mn)  # (a reduction over a short last axis is slow)
        return [
            dist(E, E0, cols[0]),
            dist(mn, mn0, mn),
            dist(m1, m0[0], cols[2]),
            dist(m2, m0[1], cols[3]),
            dist(m3, m0[2], cols[4]),
        ]

    scales = np.array([abs(E0), mn0, mn0, mn0, mn0])
    return values, names, np.where(scales > 0, scales, 1.0)


_LOCAL = threading.local()


def _thread_columns(k: int, n: int) -> list[np.ndarray]:
    """``k`` float64 arrays of length ``n``, this thread's own, reused from call to call.

    For work on the pieces of a long run in worker threads: fresh memory
    costs a page fault per 4 kB, more than the arithmetic done on it.
    """
    have = getattr(_LOCAL, "columns", [])
    if len(have) < k or have[0].size < n:
        size = max(n, have[0].size if have else 0)
        have = _LOCAL.columns = [np.empty(size) for _ in range(max(k, len(have)))]
    return [c[:n] for c in have[:k]]


def _rotate(q, v):
    """``R(q) v`` for unit quaternions (n, 4) and vectors (n, 3), without forming the matrices."""
    w, u = q[:, :1], q[:, 1:]
    tt = 2.0 * np.cross(u, v)
    return v + w * tt + np.cross(u, tt)


def plot_invariants(
    traj: Trajectory | LazyTrajectory,
    ax: Axes | None = None,
    fig: Figure | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    **style: Any,
) -> Figure:
    r"""Relative drift of the integrals of motion on a log scale.

    Curves :math:`|E(t)-E_0|/|E_0|`,
    :math:`\bigl||\mathbf m(t)|-|\mathbf m_0|\bigr|/|\mathbf m_0|` and
    :math:`|m_i(t)-m_i(t_0)|/|\mathbf m_0|` (the spatial angular momentum is
    constant for the free body), floored at the machine epsilon so that the
    log scale can show exact conservation: an exact solution gives
    round-off-level curves. The reference is the first given output time, as
    in :meth:`~eulerpoisson.trajectory.Trajectory.drift`.

    Parameters
    ----------
    traj, ax, fig, index, **style
        As for :func:`plot_omega`.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError, InvalidInputError, MissingDependencyError
        As for :func:`plot_omega`.
    """
    long = _is_long(traj)
    if long:
        values, names, scales = _drift_values(traj, index)
        one, env = _envelope(traj, index, 5, values, names=names)
        env.lo /= scales  # the extremes of |x - x0|, divided: those of the drift
        env.hi /= scales
        x, y = env.points()
        curves = {key: y[:, i] for i, key in enumerate(("E", "|m|", "m₁", "m₂", "m₃"))}
    else:
        one = select_body(traj, index)
        x = one.t
        curves = invariant_drift(one)
    mpl = import_matplotlib()
    eps = np.finfo(float).eps
    colors = {"E": "k", "|m|": "#9467bd"}
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, False, (7.0, 3.8))
        # the components of m thin and underneath, E and |m| on top
        for i, (key, y) in enumerate(curves.items()):
            color = colors.get(key, AXIS_COLORS[(i - 2) % 3])
            base = {"lw": 1.4, "zorder": 3} if i < 2 else {"lw": 0.8, "alpha": 0.8, "zorder": 2}
            ax.semilogy(x, np.maximum(y, eps), color=color, label=key, **{**base, **style})
        if long:
            _decimated_note(ax, env.samples)
        ax.axhline(eps, color="0.5", lw=0.8, ls=":")
        ax.annotate(
            "machine ε",
            (1.0, eps),
            xycoords=("axes fraction", "data"),
            xytext=(-4, -3),
            textcoords="offset points",
            ha="right",
            va="top",
            fontsize=8,
            color="0.4",
        )
        top = max(float(np.nanmax([np.nanmax(y) for y in curves.values()])), 1e3 * eps)
        ax.set_ylim(eps / 4, top * 60)  # room for the legend above the curves
        ax.set_xlim(one.t[0], one.t[-1])
        ax.set_xlabel(f"time t [{one.unit}]")
        ax.set_ylabel("relative drift [dimensionless]")
        ax.legend(loc="upper left", ncols=5, fontsize=8)
        ax.set_title(_title(one, "Drift of the integrals: |x(t) − x(t₀)| / scale"))
    return fig
