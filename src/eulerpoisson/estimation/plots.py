"""Figures of a fit: residuals over time, fitted against observed attitude and rate, the fitted polhode.

matplotlib is imported inside the functions (the ``plot`` extra).

Units: the axes name the units of the run. The time unit is that of a
``time_unit`` (or ``units``) attribute of the result or of its observations
when they carry one, else ``s``, as the trajectory files say
(:mod:`eulerpoisson.io.netcdf`); angles are in ``rad`` and rates in
``rad/<time unit>`` (the fit works in radians whatever the input unit).
The legends stand outside the axes, at their right: they never cover data.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

    from .result import FitResult

__all__ = ["plot_residuals", "plot_fit", "plot_polhode", "save_plots", "time_unit", "residual_unit"]

_LABELS = {"attitude": "attitude residual", "omega": "rate residual", "axis": "direction residual"}
#: the legend of every panel: outside the axes, at the right of its top edge
_LEGEND = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0, "fontsize": 7}


def time_unit(result) -> str:
    """The time unit of a fit: a ``time_unit`` or ``units`` attribute of ``result`` or its observations, else ``"s"``.

    Examples
    --------
    >>> class R: time_unit = "min"
    >>> time_unit(R()), time_unit(object())
    ('min', 's')
    """
    for obj in (result, getattr(result, "observations", None)):
        for name in ("time_unit", "units"):
            unit = getattr(obj, name, None)
            if isinstance(unit, str) and unit.strip():
                return unit.strip()
    return "s"


def residual_unit(kind: str, unit: str) -> str:
    """The unit of a residual of ``kind`` (``"attitude"``, ``"omega"``, ``"axis"``) for the time unit ``unit``."""
    return f"rad/{unit}" if kind == "omega" else "rad"


def _plt():
    from ..errors import require

    require("matplotlib", extra="plot")
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        try:
            matplotlib.use("Agg", force=False)
        except Exception:  # pragma: no cover - a backend already in use
            pass
    import matplotlib.pyplot as plt

    return plt


def _kinds(result):
    return [k for k in ("attitude", "omega", "axis") if k in result.residuals]


def plot_residuals(result: FitResult, ax: Axes | None = None) -> Figure:
    """Residuals of each kind over time, divided by nothing (their units), with the sigma band."""
    plt = _plt()
    kinds = _kinds(result)
    unit = time_unit(result)
    if ax is None:
        fig, axes = plt.subplots(
            len(kinds), 1, figsize=(7.8, 2.3 * len(kinds) + 0.6), sharex=True, squeeze=False, layout="constrained"
        )
        axes = axes[:, 0]
    else:
        fig, axes = ax.figure, [ax] * len(kinds)
    for a, kind in zip(axes, kinds):
        r = np.asarray(result.residuals[kind])
        t = result.residuals[kind + "_t"]
        names = "xyz" if r.shape[1] == 3 else ("across 1", "across 2")
        for j in range(r.shape[1]):
            a.plot(t, r[:, j], ".", ms=3, label=names[j])
        s = result.sigma.get(kind)
        if s is not None:
            a.axhspan(-s, s, color="0.85", zorder=0, label="±σ")
        a.set_ylabel(f"{_LABELS[kind]} [{residual_unit(kind, unit)}]")
        a.legend(**_LEGEND)
    axes[-1].set_xlabel(f"time t [{unit}]")
    fig.suptitle(f"residuals: chi2/dof = {result.reduced_chi2:.3g}")
    return fig


def plot_fit(result: FitResult, samples: int = 800) -> Figure:
    """The fitted motion (lines, closed form) against the observations (dots): attitude quaternion and rate."""
    plt = _plt()
    obs = result.observations
    t0, t1 = obs.t[0], obs.t[-1]
    tt = np.linspace(t0, t1, samples)
    tr = result.predict(tt)
    panels = []
    if len(obs.att_idx):
        panels.append("attitude")
    if len(obs.om_idx):
        panels.append("omega")
    if len(obs.ax_idx):
        panels.append("axis")
    unit = time_unit(result)
    fig, axes = plt.subplots(
        len(panels), 1, figsize=(7.8, 2.5 * len(panels) + 0.6), sharex=True, squeeze=False, layout="constrained"
    )
    axes = axes[:, 0]
    colors = ["C0", "C1", "C2", "C3"]
    for a, kind in zip(axes, panels):
        if kind == "attitude":
            q = tr.quaternion
            qo = obs.att_q.copy()
            # the sign of each observed quaternion that matches the fitted one
            qm = q[np.clip(np.searchsorted(tt, obs.t[obs.att_idx]), 0, samples - 1)]
            qo *= np.where(np.sum(qo * qm, axis=1) < 0, -1.0, 1.0)[:, None]
            for j, nm in enumerate("wxyz"):
                a.plot(tt, q[:, j], color=colors[j], lw=1, label=f"q{nm}")
                a.plot(obs.t[obs.att_idx], qo[:, j], ".", color=colors[j], ms=3)
            a.set_ylabel("attitude quaternion [1]")
        elif kind == "omega":
            w = tr.omega
            if obs.omega_frame == "space":
                w = np.einsum("kab,kb->ka", tr.matrix, w)
            for j, nm in enumerate("xyz"):
                a.plot(tt, w[:, j], color=colors[j], lw=1, label=f"ω{nm}")
                a.plot(obs.t[obs.om_idx], obs.om_value[:, j], ".", color=colors[j], ms=3)
            a.set_ylabel(f"angular velocity ({obs.omega_frame}) [rad/{unit}]")
        else:
            from ..attitude.core import matrix_from_unit_quaternion

            d = matrix_from_unit_quaternion(tr.quaternion) @ obs.axis
            for j, nm in enumerate("xyz"):
                a.plot(tt, d[:, j], color=colors[j], lw=1, label=f"d{nm}")
                a.plot(obs.t[obs.ax_idx], obs.ax_dir[:, j], ".", color=colors[j], ms=3)
            a.set_ylabel("axis direction (space) [1]")
        a.legend(**_LEGEND)
    axes[-1].set_xlabel(f"time t [{unit}]")
    fig.suptitle("fitted (lines) and observed (dots)")
    return fig


def plot_polhode(result: FitResult, ax: Axes3D | None = None, samples: int = 2000) -> Figure:
    """The body angular momentum of the fitted motion over one period of the polhode, in the principal frame."""
    plt = _plt()
    from ..analysis import momentum_period

    V = result.principal_axes
    ev = result.principal_moments
    M0 = V.T @ (result.inertia @ result.omega0)
    try:
        period = float(momentum_period(ev, M0))
    except Exception:  # a symmetric body or a rotation about an axis: no finite polhode period
        period = None
    span = period if period is not None and np.isfinite(period) else (result.observations.t[-1] - result.epoch)
    tt = result.epoch + np.linspace(0.0, span, samples)
    tr = result.predict(tt)
    M = (tr.omega @ result.inertia.T) @ V  # principal-frame components
    L = np.linalg.norm(M0)
    if ax is None:
        fig = plt.figure(figsize=(6.0, 6.0))
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    u, v = np.mgrid[0 : 2 * np.pi : 40j, 0 : np.pi : 20j]
    ax.plot_wireframe(L * np.cos(u) * np.sin(v), L * np.sin(u) * np.sin(v), L * np.cos(v), color="0.85", lw=0.4)
    ax.plot(M[:, 0], M[:, 1], M[:, 2], color="C3", lw=1.5, label="fitted polhode", zorder=3)
    obs = result.observations
    if len(obs.om_idx) and obs.omega_frame == "body":
        Mo = (obs.om_value @ result.inertia.T) @ V
        ax.plot(
            Mo[:, 0], Mo[:, 1], Mo[:, 2], ".", color="k", ms=1.5, alpha=0.6, label="observed rates (as I Ω)", zorder=2
        )
    ax.legend(loc="upper left", fontsize=7)
    unit = time_unit(result)
    for axis, i in ((ax.xaxis, "₁"), (ax.yaxis, "₂"), (ax.zaxis, "₃")):  # the fitted inertia has trace 1
        axis.set_label_text(f"M{i} [rad/{unit}]")
    try:  # keep the axis labels inside the figure (zoom needs matplotlib >= 3.7)
        ax.set_box_aspect((1, 1, 1), zoom=0.85)
    except TypeError:  # pragma: no cover
        pass
    ax.set_title(
        f"polhode ({result.mode}), moments "
        + ", ".join(f"{x:.3f}" for x in ev)
        + "\nM = I Ω with the inertia of trace 1"
    )
    return fig


def save_plots(result: FitResult, directory: str | os.PathLike[str]) -> list[Path]:
    """Write the three figures as PNG files (atomically) into ``directory``; returns the paths."""
    from ..io.atomic import atomic_path

    plt = _plt()
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    out = []
    for name, make in (("residuals.png", plot_residuals), ("fit.png", plot_fit), ("polhode.png", plot_polhode)):
        fig = make(result)
        path = d / name
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        plt.close(fig)
        out.append(path)
    return out
