"""The figure of a validation: attitude error and invariant drift over time, log scale, exact flips marked.

The time axis names the run's unit: a ``time_unit`` (or ``units``) attribute
of the report or of its run when they carry one, else ``s`` as the
trajectory files say (:mod:`eulerpoisson.io.netcdf`); the legends stand
outside the axes, at their right, so that they cover no data.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .compare import ValidationReport

__all__ = ["plot_report", "report_time_unit"]

#: values below this are drawn at this level on the log axes (exact zeros have no logarithm)
FLOOR = 1e-17


def report_time_unit(report) -> str:
    """The time unit of a validation report: its (or its run's) ``time_unit`` or ``units`` attribute, else ``"s"``."""
    for obj in (report, getattr(report, "run", None)):
        for name in ("time_unit", "units"):
            unit = getattr(obj, name, None)
            if isinstance(unit, str) and unit.strip():
                return unit.strip()
    return "s"


def plot_report(
    report: ValidationReport | list[tuple[str, ValidationReport]] | tuple[tuple[str, ValidationReport], ...],
    out: str | os.PathLike[str] | None = None,
    *,
    title: str | None = None,
) -> Figure:
    """Draw a :class:`~eulerpoisson.oracle.ValidationReport`.

    Parameters
    ----------
    report : ValidationReport or sequence of (label, ValidationReport)
        One report, or several (e.g. two integrators of one engine) drawn on the same axes.
    out : str or os.PathLike, optional
        Write the figure here (.png, .svg, .pdf).
    title : str, optional
        Drawn as typed, as the labels and the run's source (a file name): a
        ``$`` is a dollar sign, never mathtext.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    MissingDependencyError
        Without matplotlib (extra ``plot``).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.oracle import plot_report, run_from_arrays, validate
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 5.0, 51), omega0=[1.0, 0.1, 0.5])
    >>> rep = validate(run_from_arrays(tr.t, tr.quaternion, tr.omega), [1.0, 2.0, 2.5])
    >>> fig = plot_report(rep, "report.png", title="exact vs exact")
    >>> import os
    >>> os.path.exists("report.png"), len(fig.axes) > 0
    (True, True)
    """
    from ..errors import require
    from ..viz.plots import plain_text  # text, never mathtext

    require("matplotlib", "plot")
    from matplotlib import rcParams
    from matplotlib.figure import Figure  # no pyplot: no window, no global backend change

    items: list[tuple[str, ValidationReport]] = (
        [("run", report)] if not isinstance(report, (list, tuple)) else list(report)
    )
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    colors = rcParams["axes.prop_cycle"].by_key()["color"]
    for n, (label, r) in enumerate(items):
        c = colors[n % len(colors)]
        label = plain_text(label)
        ax1.semilogy(
            r.t, np.maximum(r.attitude_error, FLOOR), color=c, label=f"{label} (max {r.max_attitude_error:.2g} rad)"
        )
        ax2.semilogy(r.t, np.maximum(r.energy_error, FLOOR), color=c, label=f"{label}: energy")
        ax2.semilogy(r.t, np.maximum(r.momentum_error, FLOOR), color=c, ls="--", label=f"{label}: |m - m0|/|m0|")
        if r.tolerance is not None and n == 0:
            ax1.axhline(r.tolerance, color="k", lw=0.8, ls=":", label=f"tolerance {r.tolerance:g} rad")
    flips = items[0][1].flip_times or ()
    for k, tf in enumerate(flips):
        for ax in (ax1, ax2):
            ax.axvline(tf, color="0.6", lw=0.8, ls="-.", label="exact flips" if (k == 0 and ax is ax1) else None)
    unit = plain_text(report_time_unit(items[0][1]))
    ax1.set_ylabel("attitude error [rad]")
    ax2.set_ylabel("relative drift of the run [1]")
    ax2.set_xlabel(f"time t [{unit}]")
    outside = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0, "fontsize": 8}
    ax1.legend(**outside)
    ax2.legend(**outside)
    ax1.set_title(plain_text(title or f"{items[0][1].source} against the exact motion"))
    if out is not None:
        fig.savefig(out, dpi=110)
    return fig
