r"""Pictures of a free-rigid-body :class:`~eulerpoisson.trajectory.Trajectory`.

One function per kind of picture, each drawing into a given matplotlib axes
(or figure) or a new :class:`matplotlib.figure.Figure` and returning the
figure, and :func:`plot`, which dispatches on the kind and saves the figure
atomically when given a file name:

============== ==============================================================
kind           picture
============== ==============================================================
``omega``      body angular velocity :math:`\boldsymbol\Omega(t)` (the flips
               of the tennis racket are visible)
``invariants`` relative drift of :math:`E`, :math:`|\mathbf m|` and the
               components of :math:`\mathbf m` on a log scale
``polhode``    body angular momentum :math:`\mathbf M(t)` on the momentum
               sphere, with the energy-ellipsoid intersection (polhodes) and
               the separatrices through the intermediate axis
``gibbs``      the path of the paper's Gibbs vector :math:`\mathbf n(t)` in
               local charts (geodesics of :math:`G(\mathbf n)` through the
               origin)
``attitude``   the principal axes of the body traced on the unit sphere, with
               the fixed direction of :math:`\mathbf m`
``apex``       the locus of the symmetry axis of a top (through the centre of
               mass) on the unit sphere, seen from above: precession,
               nutation loops and cusps
============== ==============================================================

Conventions of the pictures
---------------------------
* **Units.** The package uses the units of its inputs (any consistent
  system). Axis labels use the SI names, as the NetCDF attributes of
  :meth:`~eulerpoisson.trajectory.Trajectory.to_xarray` do: time in ``s``,
  angular velocity in ``rad/s``, angular momentum in ``kg m²/s``;
  dimensionless quantities (relative drifts, the Gibbs vector, unit vectors)
  say ``dimensionless``. A trajectory with an attribute ``time_unit`` (or an
  option ``"time_unit"``) gets that time unit instead of ``s``.
* **Titles** name the body (its ``name`` and principal moments) and the
  method that produced the trajectory.
* **Style.** All figures are drawn inside ``matplotlib.rc_context(STYLE)``;
  the three body axes always have the colours :data:`AXIS_COLORS` (also used
  by :mod:`eulerpoisson.viz.animate`).
* **Batches.** For a batched trajectory the functions draw one body,
  ``index=0`` by default (an int is a flat index into the batch, a tuple a
  multi-index).
* **Backend.** Figures are created as :class:`matplotlib.figure.Figure`
  objects, never through ``pyplot``: no window is opened and no global
  backend is changed; saving uses the Agg (png) / svg / pdf renderers.

Long runs and Zarr stores
-------------------------
Every function takes a :class:`~eulerpoisson.trajectory.Trajectory` or a
:class:`~eulerpoisson.io.read.LazyTrajectory` (a ``.zarr`` store written by
``simulate --out run.zarr``, opened by :meth:`Trajectory.open
<eulerpoisson.trajectory.Trajectory.open>`). A time series of more than
:data:`DECIMATE_ABOVE` samples (``omega``, ``invariants``) is drawn as the
minimum and maximum of the samples in each of 2000 columns
(:class:`~eulerpoisson.viz.decimate.MinMaxEnvelope`), computed piece by piece
(a store is read chunk by chunk, only the variables needed): the drawn
envelope contains every sample, and memory does not grow with the run. The
3-D pictures draw evenly strided samples (20 000, 40 000 for ``apex``); a
store longer than :data:`MAX_READ_3D` samples is read in whole chunks evenly
spread over the run, so that a picture of :math:`10^8` samples costs what one
of :math:`10^7` does. ``gibbs`` splits at most a million samples into charts
(in linear time) and draws at most :data:`MAX_CHARTS` of them, evenly chosen.
Names (of the body, of the method) and the time unit are drawn as text, never
as mathtext (:func:`plain_text`): a ``$`` in them is a dollar sign.

The Gibbs-vector picture and chart restarts
-------------------------------------------
The global Gibbs vector :math:`\mathbf n = \mathbf k\tan(\alpha/2)` (paper
eq. 1.8) is infinite at :math:`\alpha = \pi`, which a tumbling body reaches
again and again. ``plot_gibbs`` therefore draws *local* Gibbs vectors with
chart restarts (:func:`chart_segments`): the first chart is centred on the
first attitude :math:`q(t_0)`, the local vector is
:math:`\mathbf n_\mathrm{loc}(t)` with
:math:`R(t) = R(q_\mathrm{ref})R(\mathbf n_\mathrm{loc})`, and when
:math:`|\mathbf n_\mathrm{loc}|` exceeds ``chart_radius`` (default 1, a
relative rotation of 90°) the chart is restarted at the current attitude.
The free body is left-invariant, so its equations — the geodesic equations
of the paper's metric :math:`G(\mathbf n)` (eq. 1.13-1.14) — are the same in
every chart, and every chart segment is a geodesic arc that starts at the
origin. The picture is a bouquet of such arcs, one colour per chart (by its
start time), with the restart points marked.

Modules
-------
This module dispatches on the kind (:func:`plot`, :func:`plot_all`,
:func:`save_figure`) and re-exports the pictures, which live in
:mod:`eulerpoisson.viz.time_series_plots` (``omega``, ``invariants``),
:mod:`eulerpoisson.viz.polhode`, :mod:`eulerpoisson.viz.gibbs_charts`
(``gibbs`` and the chart split) and :mod:`eulerpoisson.viz.axis_plots`
(``attitude``, ``apex``), on top of :mod:`eulerpoisson.viz.plot_common`
(style, body, axes) and :mod:`eulerpoisson.viz.long_runs` (envelopes and
thinning of long runs and stores).

References
----------
Paper eq. 1.8-1.9 (Gibbs vector), 1.13-1.14 (the metric and its geodesics).
L. D. Landau and E. M. Lifshitz, *Mechanics*, §37 (polhodes, separatrices).
J. E. Marsden and T. S. Ratiu, *Introduction to Mechanics and Symmetry*,
§15.10 (the momentum sphere and the energy ellipsoid).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from ..io.atomic import atomic_path
from .axis_plots import apex_axis as apex_axis
from .axis_plots import plot_apex as plot_apex
from .axis_plots import plot_attitude as plot_attitude
from .gibbs_charts import CHART_KERNEL as CHART_KERNEL
from .gibbs_charts import chart_bounds as chart_bounds
from .gibbs_charts import chart_bounds_numpy as _chart_bounds_numpy  # noqa: F401 (tests use the old name)
from .gibbs_charts import chart_segments as chart_segments
from .gibbs_charts import plot_gibbs as plot_gibbs
from .long_runs import DECIMATE_ABOVE as DECIMATE_ABOVE
from .long_runs import MAX_CHARTS as MAX_CHARTS
from .long_runs import MAX_READ_3D as MAX_READ_3D
from .long_runs import PIECE as _PIECE  # noqa: F401 (the old name)
from .long_runs import window as window
from .plot_common import AXIS_COLORS as AXIS_COLORS
from .plot_common import STYLE as STYLE
from .plot_common import import_matplotlib as import_matplotlib
from .plot_common import plain_text as plain_text
from .plot_common import select_body as select_body
from .polhode import plot_polhode as plot_polhode
from .polhode import sphere_conic as sphere_conic
from .time_series_plots import invariant_drift as invariant_drift
from .time_series_plots import plot_invariants as plot_invariants
from .time_series_plots import plot_omega as plot_omega

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = [
    "KINDS",
    "STYLE",
    "AXIS_COLORS",
    "plot",
    "plot_all",
    "plot_omega",
    "plot_invariants",
    "plot_polhode",
    "plot_gibbs",
    "plot_attitude",
    "plot_apex",
    "apex_axis",
    "chart_segments",
    "sphere_conic",
    "plain_text",
    "DECIMATE_ABOVE",
    "MAX_CHARTS",
]

#: picture kinds accepted by :func:`plot`
KINDS = ("omega", "invariants", "polhode", "gibbs", "attitude", "apex")

#: file formats accepted by :func:`plot` (by the extension of ``out``)
FORMATS = ("png", "svg", "pdf")


# ---------------------------------------------------------------------------
# dispatch
# ---------------------------------------------------------------------------
_PLOTTERS = {
    "omega": plot_omega,
    "invariants": plot_invariants,
    "polhode": plot_polhode,
    "gibbs": plot_gibbs,
    "attitude": plot_attitude,
    "apex": plot_apex,
}


def _check_out(out) -> tuple[Path, str]:
    if not isinstance(out, (str, os.PathLike)):
        raise TypeError(f"out must be a file name (str or path), got {type(out).__name__}")
    p = Path(out)
    ext = p.suffix.lower().lstrip(".")
    if ext not in FORMATS:
        raise InvalidInputError(
            f"out={str(out)!r}: unsupported file extension {p.suffix!r}; use one of "
            + ", ".join("." + f for f in FORMATS)
        )
    return p, ext


def save_figure(fig, out, *, dpi=None) -> Path:
    """Save ``fig`` to ``out`` (png/svg/pdf by extension) atomically: temporary file, then rename.

    Raises
    ------
    InvalidInputError
        Unsupported extension.
    """
    p, ext = _check_out(out)
    with atomic_path(p, suffix="." + ext) as tmp:
        fig.savefig(tmp, format=ext, dpi=dpi or STYLE["savefig.dpi"])
    return p


def plot(
    traj: Trajectory | LazyTrajectory,
    kind: str,
    out: str | os.PathLike[str] | None = None,
    *,
    index: int | tuple[int, ...] = 0,
    dpi: float | None = None,
    t_start: float | None = None,
    t_end: float | None = None,
    **kwargs: Any,
) -> Figure:
    """Draw one kind of picture, and save it when ``out`` is given.

    Parameters
    ----------
    traj : Trajectory
    kind : str
        One of :data:`KINDS`: ``"omega"``, ``"invariants"``, ``"polhode"``,
        ``"gibbs"``, ``"attitude"``, ``"apex"``.
    out : str or path, optional
        File to write; the format is given by the extension (``.png``,
        ``.svg``, ``.pdf``). Written atomically.
    index : int or tuple
        Body of a batched trajectory.
    dpi : float, optional
        Resolution of raster output (default ``STYLE["savefig.dpi"]``).
    t_start, t_end : float, optional
        Draw only the samples with ``t_start <= t <= t_end`` (a window of a
        long run; either end open when None), in the run's time unit. A store
        stays on disk: the window's ends are found by a binary search on its
        times and only the window is read (:func:`~eulerpoisson.viz.long_runs.window`).
        The drift of ``invariants`` stays relative to the first sample of the
        whole run.
    **kwargs
        Passed to the ``plot_<kind>`` function (``ax``, ``fig``, style...).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InvalidInputError
        Unknown ``kind``, unsupported extension of ``out``, bad ``index``,
        a window (``t_start``, ``t_end``) that is not two finite ordered times
        or holds fewer than two samples.
    TypeError
        ``traj`` is not a Trajectory, ``out`` not a path.
    MissingDependencyError
        matplotlib is not installed (extra ``plot``).

    Examples
    --------
    A flat "tennis racket" (moments 3, 5, 8) spun almost about its intermediate axis:

    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([3, 5, 8], np.linspace(0, 150, 301), omega0=[0, 0.4, 0.01 / 8])
    >>> fig = ep.plots.plot(tr, "polhode", out="polhode.png")
    >>> from pathlib import Path
    >>> Path("polhode.png").stat().st_size > 0
    True
    """
    if not isinstance(kind, str) or kind not in _PLOTTERS:
        raise InvalidInputError(f"unknown plot kind {kind!r}; available kinds: {', '.join(KINDS)}")
    if out is not None:
        _check_out(out)  # fail before drawing
    if t_start is not None or t_end is not None:
        whole = traj
        traj = window(traj, t_start, t_end)
        if kind == "invariants":
            kwargs.setdefault("reference", whole)  # the drift from the run's first sample, not the window's
    fig = _PLOTTERS[kind](traj, index=index, **kwargs)
    if out is not None:
        save_figure(fig, out, dpi=dpi)
    return fig


def plot_all(
    traj: Trajectory | LazyTrajectory,
    out_dir: str | os.PathLike[str],
    *,
    fmt: str = "png",
    index: int | tuple[int, ...] = 0,
    dpi: float | None = None,
    prefix: str = "",
) -> dict[str, Path]:
    """Write every kind of picture to ``out_dir/<prefix><kind>.<fmt>``.

    Returns
    -------
    dict
        Kind -> path written.

    Raises
    ------
    InvalidInputError
        Unsupported ``fmt``; others as for :func:`plot`.
    """
    if fmt not in FORMATS:
        raise InvalidInputError(f"fmt={fmt!r} is not supported; use one of {', '.join(FORMATS)}")
    d = Path(out_dir)
    paths = {}
    for kind in KINDS:
        p = d / f"{prefix}{kind}.{fmt}"
        plot(traj, kind, out=p, index=index, dpi=dpi)
        paths[kind] = p
    return paths
