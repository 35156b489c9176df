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

from .long_runs import body_model
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
    "outside_legend",
    "layered_styles",
    "INTEGRAL_LABELS",
    "ref_time",
]

#: the legend of a time series: outside the axes, to the right of the data (it never covers a curve)
LEGEND_OUTSIDE = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}


def outside_legend(ax, handles=None, labels=None, **kw):
    """Put the legend of ``ax`` outside the axes, at the right of its top edge (it covers no data)."""
    if handles is None:
        return ax.legend(**{**LEGEND_OUTSIDE, **kw})
    return ax.legend(handles, labels, **{**LEGEND_OUTSIDE, **kw})


def layered_styles(peaks) -> list[dict]:
    """Line widths and z-orders that keep every curve visible where curves coincide.

    The curves are stacked by decreasing ``peaks`` (their largest values):
    the largest is drawn widest and lowest, each next one thinner and above
    it, so that where two curves coincide the lower one still shows as a
    coloured fringe on both sides of the upper one.

    Examples
    --------
    >>> [(d["lw"], d["zorder"]) for d in layered_styles([1.0, 3.0, 2.0])]
    [(0.9, 4), (2.6, 2), (1.75, 3)]
    """
    peaks = np.asarray(peaks, dtype=float)
    order = np.argsort(-np.nan_to_num(peaks, nan=-np.inf), kind="stable")
    n = len(peaks)
    widths = np.linspace(2.6, 0.9, n) if n > 1 else np.array([1.4])
    out: list[dict] = [{} for _ in range(n)]
    for rank, i in enumerate(order):
        out[int(i)] = {"lw": round(float(widths[rank]), 2), "zorder": 2 + rank}
    return out


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
    component flips sign periodically. A long run (more than
    :data:`~eulerpoisson.viz.long_runs.DECIMATE_ABOVE` samples, or a store) is
    drawn per pixel column: the min/max envelope of each component as a
    translucent band underneath (a line labelled ``Ω₁``... with ``alpha``
    0.3), so that no band hides another, and the mean of the column's samples
    as a line on top (a :class:`~matplotlib.collections.LineCollection`). The
    legend stands outside the axes.

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
    long = _is_long(traj)
    if long:  # min/max and mean per pixel column, computed piece by piece
        one, env = _envelope(traj, index, 3, lambda piece, one: piece["omega"], names=("time", "omega"), means=True)
        x, y = env.points()
        xm, ym = env.means()
    else:
        one = select_body(traj, index)
        x, y = one.t, one.omega
    mpl = import_matplotlib()
    from matplotlib.collections import LineCollection

    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, False, (7.6, 3.8))
        handles: list[Any] = []
        for i in range(3):
            label = f"Ω{str(i + 1).translate(_SUB)}"
            if long:
                # the envelope translucent and underneath (no band hides another), the mean per column on top
                ax.plot(
                    x, y[:, i], color=AXIS_COLORS[i], label=label, **{"lw": 0.8, "alpha": 0.3, "zorder": 1.5, **style}
                )
                # (a collection, not a Line2D: the sums behind the means may differ in the last bit with the
                # size of the pieces a run is read in, while the envelope lines are bit for bit the same)
                lw = style.get("linewidth", style.get("lw", 1.1))
                mean = LineCollection(
                    [np.column_stack([xm, ym[:, i]])], colors=AXIS_COLORS[i], linewidths=lw, zorder=3, label=label
                )
                ax.add_collection(mean, autolim=False)
                handles.append(mean)
            else:
                handles.append(ax.plot(x, y[:, i], color=AXIS_COLORS[i], label=label, **style)[0])
        if long:
            _decimated_note(ax, env.samples, "band: min/max, line: mean")
        ax.axhline(0.0, color="0.3", lw=0.6, zorder=1)
        ax.set_xlabel(f"time t [{one.unit}]")
        ax.set_ylabel(f"body angular velocity Ω [rad/{one.unit}]")
        ax.set_xlim(one.t[0], one.t[-1])
        outside_legend(ax, handles, [h.get_label() for h in handles])
        ax.set_title(_title(one, "Body angular velocity Ω(t)"))
    return fig


# ---------------------------------------------------------------------------
# invariants
# ---------------------------------------------------------------------------
def invariant_drift(one: _One, reference: _One | None = None) -> dict[str, np.ndarray]:
    r"""Relative drift curves of the integrals of the free body (helper of :func:`plot_invariants`).

    :math:`|E(t)-E_0|/|E_0|`, :math:`||\mathbf m(t)|-|\mathbf m_0||/|\mathbf m_0|`
    and :math:`|m_i(t)-m_i(t_0)|/|\mathbf m_0|`, with the values at the first
    given output time as reference (as :meth:`Trajectory.drift`), or at the
    first sample of ``reference`` when given (the start of the run for a
    window of it); zero scales give absolute values. Not floored.
    """
    E = one.energy
    m = one.m
    mn = np.linalg.norm(m, axis=-1)
    if reference is None:
        k = one.first
        E0, m0, mn0 = E[k], m[k], mn[k]
    else:
        E0, m0 = reference.energy[reference.first], reference.m[reference.first]
        mn0 = np.linalg.norm(m0)

    def rel(x, ref, scale):
        return np.abs(x - ref) / (scale if scale > 0 else 1.0)

    out = {"E": rel(E, E0, abs(E0)), "|m|": rel(mn, mn0, mn0)}
    for i in range(3):
        out[f"m{str(i + 1).translate(_SUB)}"] = rel(m[:, i], m0[i], mn0)
    return out


#: how the integrals of :meth:`eulerpoisson.Model.integrals` are named in the picture
INTEGRAL_LABELS = {
    "energy": "E",
    "jacobi": "J (Jacobi)",
    "m_vertical": "m·ĝ",
    "m_field": "m·B̂",
    "M3": "M₃ (symmetry axis)",
    "m_x": "m₁",
    "m_y": "m₂",
    "m_z": "m₃",
    "m_norm": "|m|",
}


def _first_state(traj, index) -> _One:
    """The body ``index`` at the first given sample of ``traj`` (twice, so that it is a valid picture body)."""
    from ..trajectory import Trajectory

    first = (
        traj[0]
        if _is_lazy(traj)
        else Trajectory(traj.t[:1], traj.quaternion[..., :1, :], traj.omega[..., :1, :], traj.body)
    )
    return select_body(
        Trajectory(
            np.array([0.0, 1.0]),
            np.repeat(first.quaternion, 2, axis=-2),
            np.repeat(first.omega, 2, axis=-2),
            first.body,
        ),
        index,
    )


def _model_drift(model, ref: _One):
    r"""``(keys, values, scales)`` of the drift of the integrals of a model under torque, for one body.

    ``values(t, q, omega)`` gives the columns :math:`|x - x_0|` of the
    integrals ``keys`` (:meth:`eulerpoisson.Model.integrals`); the scales are
    those of :meth:`~eulerpoisson.Trajectory.drift` (energy-like: kinetic
    energy plus :math:`|U|` at the reference, angular momenta: :math:`|\mathbf m_0|`,
    others: their own magnitude).
    """
    t0 = np.array([0.0])
    x0 = model.integrals(t0, ref.q[:1], ref.omega[:1])
    keys = [k for k in x0 if np.ndim(x0[k]) == 1 and np.all(np.isfinite(x0[k]))]
    kin0 = float(ref.energy[0])
    mn0 = float(np.linalg.norm(ref.m[0]))
    scales = []
    for k in keys:
        v0 = float(x0[k][0])
        if k in ("energy", "jacobi"):
            sc = kin0 + abs(v0 - kin0)
        elif k.startswith("m_") or k == "M3":
            sc = mn0
        else:
            sc = abs(v0)
        scales.append(sc if sc > 0 else 1.0)

    def values(t, q, omega):
        x = model.integrals(np.asarray(t, dtype=float), q, omega)
        return [np.abs(x[k] - x0[k][0]) for k in keys]

    return keys, values, np.array(scales)


def _drift_values(traj, index, ref: _One | None = None):
    """``(values, names, scales)`` of the five drift curves of :func:`invariant_drift`, for :func:`_envelope`.

    ``values(piece, one)`` gives the columns :math:`|x - x_0|` (E, the norm of m,
    m1, m2, m3), not yet divided by their ``scales``: a positive division is
    monotonic, so the extremes per column divided afterwards are those of the
    drift, bit for bit, at a fraction of the cost.
    """
    ref = _first_state(traj, index) if ref is None else ref
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
    reference: Trajectory | LazyTrajectory | None = None,
    **style: Any,
) -> Figure:
    r"""Relative drift of the integrals of motion on a log scale.

    Free body: curves :math:`|E(t)-E_0|/|E_0|`,
    :math:`\bigl||\mathbf m(t)|-|\mathbf m_0|\bigr|/|\mathbf m_0|` and
    :math:`|m_i(t)-m_i(t_0)|/|\mathbf m_0|` (the spatial angular momentum is
    constant for the free body). Under torque: the integrals that the model
    has (:meth:`eulerpoisson.Model.integrals`: the total energy and
    :math:`\mathbf m\cdot\hat{\mathbf g}` of a heavy top, :math:`M_3` of a
    Lagrange top, the Jacobi integral...), with the scales of
    :meth:`~eulerpoisson.Trajectory.drift`; a model with none gets a note and
    no curve. Values are floored at the machine epsilon so that the log
    scale can show exact conservation. The reference is the first given
    output time, as in :meth:`~eulerpoisson.trajectory.Trajectory.drift`, or
    the first sample of ``reference`` (:func:`~eulerpoisson.viz.plots.plot`
    passes the whole run for a window of it).

    Every curve stays visible: they are stacked by decreasing size, the
    largest widest and lowest (:func:`layered_styles`), and the legend,
    outside the axes, gives the largest value of each.

    Parameters
    ----------
    traj, ax, fig, index, **style
        As for :func:`plot_omega`.
    reference : Trajectory or LazyTrajectory, optional
        The values at its first sample are the reference :math:`x(t_0)`.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError, InvalidInputError, MissingDependencyError
        As for :func:`plot_omega`.
    """
    long = _is_long(traj)
    model = body_model(traj, index)
    ref = None if reference is None else _first_state(reference, index)
    if model.is_free:
        if long:
            values, names, scales = _drift_values(traj, index, ref)
            one, env = _envelope(traj, index, 5, values, names=names)
            env.lo /= scales  # the extremes of |x - x0|, divided: those of the drift
            env.hi /= scales
            x, y = env.points()
            curves = {key: y[:, i] for i, key in enumerate(("E", "|m|", "m₁", "m₂", "m₃"))}
        else:
            one = select_body(traj, index)
            x = one.t
            curves = invariant_drift(one, ref)
        what = "Drift of the integrals: |x(t) − x(t₀)| / scale"
    else:
        if ref is None:
            ref = _first_state(traj, index)
        keys, fn, scales = _model_drift(model, ref)
        if long and keys:
            one, env = _envelope(
                traj, index, len(keys), lambda piece, one: fn(piece["time"], piece["quaternion"], piece["omega"])
            )
            env.lo /= scales
            env.hi /= scales
            x, y = env.points()
            curves = {INTEGRAL_LABELS.get(k, k): y[:, i] for i, k in enumerate(keys)}
        else:
            one = select_body(traj, index)
            x = one.t
            curves = {INTEGRAL_LABELS.get(k, k): v / sc for k, v, sc in zip(keys, fn(one.t, one.q, one.omega), scales)}
        torques = ", ".join(dict.fromkeys(type(tq).__name__ for tq in model.torques))
        what = f"Drift of the integrals of the model (torque: {torques}): |x(t) − x(t₀)| / scale"
    mpl = import_matplotlib()
    eps = np.finfo(float).eps
    colors = {
        "E": "k",
        "|m|": "#9467bd",
        "J (Jacobi)": "k",
        "m·ĝ": "#9467bd",
        "m·B̂": "#9467bd",
        "M₃ (symmetry axis)": "#ff7f0e",
    }
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, False, (7.8, 3.8))
        peaks = [float(np.nanmax(y)) if np.any(np.isfinite(y)) else np.nan for y in curves.values()]
        layers = layered_styles(peaks)
        handles, labels = [], []
        for i, ((key, y), lay, peak) in enumerate(zip(curves.items(), layers, peaks)):
            color = colors.get(key, AXIS_COLORS[(i - 2) % 3] if model.is_free else f"C{i}")
            (ln,) = ax.semilogy(x, np.maximum(y, eps), color=color, label=key, **{**lay, **style})
            handles.append(ln)
            labels.append(f"{key}  (max {peak:.2g})" if np.isfinite(peak) and peak > eps else f"{key}  (≤ ε)")
        if long:
            _decimated_note(ax, env.samples)
        ax.axhline(eps, color="0.5", lw=0.8, ls=":", zorder=1)
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
        finite = [p for p in peaks if np.isfinite(p)]
        top = max(max(finite, default=0.0), 1e3 * eps)
        ax.set_ylim(eps / 4, top * 4)
        ax.set_xlim(one.t[0], one.t[-1])
        ax.set_xlabel(f"time t [{one.unit}]")
        ax.set_ylabel("relative drift [dimensionless]")
        if curves:
            outside_legend(ax, handles, labels, fontsize=8)
        else:
            ax.text(
                0.5,
                0.5,
                "no integral of motion is known for this model: nothing to draw",
                transform=ax.transAxes,
                ha="center",
                va="center",
                fontsize=9,
                color="0.3",
            )
        if reference is not None:
            what += f"\nreference x(t₀): the first sample of the run, t₀ = {float(ref_time(reference)):g} {one.unit}"
        ax.set_title(_title(one, what))
    return fig


def ref_time(traj) -> float:
    """The first given time of ``traj`` (one sample read from a store)."""
    return float(traj[0].t[0]) if _is_lazy(traj) else float(np.asarray(traj.t)[0])
