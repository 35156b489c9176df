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

References
----------
Paper eq. 1.8-1.9 (Gibbs vector), 1.13-1.14 (the metric and its geodesics).
L. D. Landau and E. M. Lifshitz, *Mechanics*, §37 (polhodes, separatrices).
J. E. Marsden and T. S. Ratiu, *Introduction to Mechanics and Symmetry*,
§15.10 (the momentum sphere and the energy ellipsoid).
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion
from ..errors import InvalidInputError, require
from ..io.atomic import atomic_path
from ..numerics.quaternion import qmul, qmul_components

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D
    from numpy.typing import ArrayLike

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

#: colours of body axes 1, 2, 3 (and of x, y, z components)
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")

#: matplotlib rc parameters used for every figure of this module
STYLE = {
    "font.size": 10,
    "axes.titlesize": 10.5,
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "legend.framealpha": 0.85,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "lines.linewidth": 1.4,
    "figure.dpi": 100,
    "savefig.dpi": 150,
    "figure.constrained_layout.use": True,
}

_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
_MAX_3D_POINTS = 20000  # longer series are strided for the 3-D pictures


# ---------------------------------------------------------------------------
# selection of one body, labels
# ---------------------------------------------------------------------------
@dataclass
class _One:
    """One body of a (possibly batched) trajectory, sorted by time."""

    t: np.ndarray  # (T,)
    q: np.ndarray  # (T, 4)
    omega: np.ndarray  # (T, 3)
    inertia: np.ndarray  # (3, 3)
    moments: np.ndarray  # (3,)
    axes: np.ndarray  # (3, 3) columns
    first: int  # position of the first given sample (t[0] of the trajectory) after sorting
    name: str | None
    method: str
    time_unit: str
    label: str  # "name (I = a, b, c)"

    @property
    def unit(self) -> str:
        """The time unit as matplotlib draws it literally (:func:`plain_text`: a ``$`` is no mathtext)."""
        return plain_text(self.time_unit)

    @property
    def R(self):
        return matrix_from_unit_quaternion(self.q)

    @property
    def M(self):
        return self.omega @ self.inertia.T

    @property
    def m(self):
        return np.einsum("tij,tj->ti", self.R, self.M)

    @property
    def energy(self):
        return 0.5 * np.sum(self.omega * self.M, -1)


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def _body_label(name, moments) -> str:
    mom = "I = (" + ", ".join(_fmt(v) for v in moments) + ")"
    return f"{name}, {mom}" if name else mom


def _time_unit(traj) -> str:
    unit = getattr(traj, "time_unit", None) or getattr(traj, "options", {}).get("time_unit")
    return str(unit) if unit else "s"


def select_body(traj, index=0) -> _One:
    """Validate ``traj`` and ``index`` and return the chosen body, sorted by time.

    Raises
    ------
    TypeError
        ``traj`` is not a Trajectory.
    InvalidInputError
        ``index`` out of range or of the wrong type; fewer than two distinct times.
    """
    from ..trajectory import Trajectory

    if not isinstance(traj, Trajectory):
        raise TypeError(f"traj must be an eulerpoisson Trajectory, got {type(traj).__name__}")
    bshape = traj.batch_shape
    if bshape:
        nb = int(np.prod(bshape))
        if isinstance(index, (int, np.integer)) and not isinstance(index, bool):
            if not -nb <= int(index) < nb:
                raise InvalidInputError(
                    f"index={index!r} is out of range for a batch of {nb} bodies (batch shape {bshape})"
                )
            idx: tuple = np.unravel_index(int(index) % nb, bshape)
        elif (
            isinstance(index, tuple)
            and len(index) == len(bshape)
            and all(isinstance(i, (int, np.integer)) and not isinstance(i, bool) for i in index)
        ):
            if not all(-n <= int(i) < n for i, n in zip(index, bshape)):
                raise InvalidInputError(f"index={index!r} is out of range for batch shape {bshape}")
            idx = tuple(int(i) % n for i, n in zip(index, bshape))
        else:
            raise InvalidInputError(
                f"index must be an int (flat index) or a tuple of {len(bshape)} ints for batch shape "
                f"{bshape}, got {index!r}"
            )
    else:
        if index not in (0, -1, (), None) or isinstance(index, bool):
            raise InvalidInputError(f"index={index!r} given for a trajectory of one body; use index=0")
        idx = ()
    t = np.asarray(traj.t, float)
    if t.size < 2 or not np.ptp(t) > 0:
        raise InvalidInputError(
            f"a picture needs a trajectory with at least two distinct times, got t of shape {t.shape}"
        )
    order = np.argsort(t, kind="stable")
    q = traj.quaternion[idx][order]
    omega = traj.omega[idx][order]
    body = traj.body
    inertia = np.broadcast_to(body.inertia, bshape + (3, 3))[idx]
    moments = np.broadcast_to(body.principal_moments, bshape + (3,))[idx]
    axes = np.broadcast_to(body.principal_axes, bshape + (3, 3))[idx]
    first = int(np.flatnonzero(order == 0)[0])
    name = body.name
    return _One(
        t=t[order],
        q=q,
        omega=omega,
        inertia=np.array(inertia),
        moments=np.array(moments),
        axes=np.array(axes),
        first=first,
        name=name,
        method=str(traj.method or "?"),
        time_unit=_time_unit(traj),
        label=_body_label(name, moments),
    )


def plain_text(text: str) -> str:
    r"""``text`` as matplotlib draws it literally: every ``$`` escaped (``\$``), so no mathtext.

    A body name (or a method name read from a file) is text: ``"$x^2$ rod"``
    must be drawn as typed, not parsed as mathematics (which fails on names
    that are not valid TeX, and changes those that are).
    """
    return str(text).replace("$", r"\$")


def _title(one: _One, what: str) -> str:
    return f"{what}\n{plain_text(one.label)} — method: {plain_text(one.method)}"


def import_matplotlib():
    """Import matplotlib (extra ``plot``)."""
    mpl = require("matplotlib", "plot")
    require("matplotlib.figure", "plot")
    return mpl


def _new_axes(ax, fig, three_d: bool, figsize):
    """An axes to draw into: ``ax`` itself, a new subplot of ``fig``, or a new Figure."""
    import_matplotlib()
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    if ax is not None:
        if not isinstance(ax, Axes):
            raise InvalidInputError(f"ax must be a matplotlib Axes, got {type(ax).__name__}")
        if three_d and getattr(ax, "name", "") != "3d":
            raise InvalidInputError(
                "this picture is 3-D: ax must be created with projection='3d' "
                f"(got a {getattr(ax, 'name', type(ax).__name__)!r} axes)"
            )
        if not three_d and getattr(ax, "name", "") == "3d":
            raise InvalidInputError("this picture is 2-D: ax must not be a 3-D axes")
        return ax.figure, ax
    if fig is None:
        fig = Figure(figsize=figsize)
    elif not isinstance(fig, (Figure, SubFigure)):
        raise InvalidInputError(f"fig must be a matplotlib Figure, got {type(fig).__name__}")
    ax = fig.add_subplot(projection="3d") if three_d else fig.add_subplot()
    return fig, ax


def _stride(n: int, limit: int = _MAX_3D_POINTS) -> slice:
    return slice(None, None, max(1, -(-n // limit)))


def _unit_sphere(ax, radius=1.0, color="0.6", alpha=0.25, n=(25, 13)):
    u = np.linspace(0, 2 * np.pi, n[0])
    v = np.linspace(0, np.pi, n[1])
    x = radius * np.outer(np.cos(u), np.sin(v))
    y = radius * np.outer(np.sin(u), np.sin(v))
    z = radius * np.outer(np.ones_like(u), np.cos(v))
    ax.plot_wireframe(x, y, z, color=color, alpha=alpha, linewidth=0.4)


def _setup_3d(ax, lim, labels, elev=22, azim=38):
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_zlim(-lim, lim)
    ax.set_xlabel(labels[0], labelpad=2)
    ax.set_ylabel(labels[1], labelpad=2)
    ax.set_zlabel(labels[2], labelpad=2)
    ax.view_init(elev=elev, azim=azim)
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(nbins=3, steps=[1, 2, 2.5, 5, 10], symmetric=True))
        axis.set_pane_color((0.97, 0.97, 0.97, 1.0))
    try:  # keep the axis labels inside the figure (zoom needs matplotlib >= 3.7)
        ax.set_box_aspect((1, 1, 1), zoom=0.86)
    except TypeError:  # pragma: no cover
        pass


# ---------------------------------------------------------------------------
# long runs: decimated time series, thinned paths, stores read chunk by chunk
# ---------------------------------------------------------------------------
#: time series with more samples than this are drawn as min/max envelopes per pixel column
DECIMATE_ABOVE = 20_000
#: samples per piece when a long run is walked through (in memory or in a Zarr store)
_PIECE = 200_000
#: most samples a long run is thinned to before the Gibbs vector is split into charts
_MAX_GIBBS_SAMPLES = 1_000_000
#: most chart segments drawn by plot_gibbs (evenly chosen among all of them)
MAX_CHARTS = 200


def _is_lazy(traj) -> bool:
    """A trajectory read on demand (:class:`eulerpoisson.io.read.LazyTrajectory`)."""
    from ..io.read import LazyTrajectory

    return isinstance(traj, LazyTrajectory)


def _is_long(traj) -> bool:
    _check_traj(traj)
    return _is_lazy(traj) or len(traj.t) > DECIMATE_ABOVE


def _check_traj(traj) -> None:
    from ..trajectory import Trajectory

    if not (isinstance(traj, Trajectory) or _is_lazy(traj)):
        raise TypeError(f"traj must be an eulerpoisson Trajectory, got {type(traj).__name__}")


def _batch_index(bshape, index) -> tuple:
    """The batch index of the body ``index`` (validated by :func:`select_body`)."""
    if not bshape:
        return ()
    if isinstance(index, tuple):
        return tuple(int(i) % n for i, n in zip(index, bshape))
    return tuple(int(i) for i in np.unravel_index(int(index) % int(np.prod(bshape)), bshape))


def _ends(traj, index) -> _One:
    """The body ``index`` at the first and last samples of a long run (labels, inertia, time range)."""
    from ..trajectory import Trajectory

    _check_traj(traj)
    T = len(traj.t) if not _is_lazy(traj) else len(traj)
    if T < 2:
        return select_body(traj if not _is_lazy(traj) else traj.load(), index)
    if _is_lazy(traj):
        ends = traj[[0, T - 1]]
    else:  # (indexing would build an index array of the run's length)
        ends = Trajectory(
            traj.t[[0, T - 1]],
            traj.quaternion[..., [0, T - 1], :],
            traj.omega[..., [0, T - 1], :],
            traj.body,
            traj.method,
            traj.options,
            traj.stats,
            torque=list(traj.model.torques),
        )
    one = select_body(ends, index)
    if not _is_lazy(traj):  # in memory: the true time range (the times may be in any order)
        one.t = np.array([float(np.min(traj.t)), float(np.max(traj.t))])
    one.first = 0 if ends.t[0] <= ends.t[-1] or _is_lazy(traj) else 1
    return one


def _map_pieces(traj, idx, fn, names=("time", "quaternion", "omega"), size: int | None = None):
    """``fn(piece)`` for the run of body ``idx``, piece by piece, in order; the pieces are computed in threads.

    A piece is a dict of the arrays ``names`` of that body (a store reads
    those only, its chunks decoded in parallel; a run in memory gives views).
    Memory is bounded by a few pieces (:func:`~eulerpoisson.io.read.ordered_map`).
    """
    from ..io.read import ordered_map

    size = _PIECE if size is None else size
    if _is_lazy(traj):

        def one(piece):
            return fn({k: (v if k == "time" or not idx else v[idx]) for k, v in piece.items()})

        yield from traj.map_arrays(names, one, size, reuse=True)  # fn reduces the piece: its memory is reused
        return
    q, w = traj.quaternion[idx], traj.omega[idx]

    def view(a):  # in memory: views, and the state only
        return fn({"time": traj.t[a : a + size], "quaternion": q[a : a + size], "omega": w[a : a + size]})

    yield from ordered_map(view, range(0, len(traj.t), size))


def _envelope(traj, index, k: int, values, nbins=None, names=("time", "quaternion", "omega")):
    """Min/max envelope of ``values(piece, one)`` (an array (n, k) or ``k`` columns) over the run, piece by piece.

    Every piece is read and reduced in a worker thread
    (:meth:`MinMaxEnvelope.reduce <eulerpoisson.viz.decimate.MinMaxEnvelope.reduce>`);
    this thread merges the extremes. Returns ``(one, env)``: the body at the
    ends (:func:`_ends`) and the :class:`~eulerpoisson.viz.decimate.MinMaxEnvelope`.
    """
    from .decimate import DEFAULT_BINS, MinMaxEnvelope

    one = _ends(traj, index)
    idx = _batch_index(traj.batch_shape, index)
    t0, t1 = float(np.min(one.t)), float(np.max(one.t))
    for _ in range(2):  # a store whose times are not monotonic: a second pass over the true range
        env = MinMaxEnvelope(t0, t1, k, nbins or DEFAULT_BINS)
        lo, hi = t0, t1

        def reduce(piece, env=env):
            return env.reduce(piece["time"], values(piece, one))

        for part in _map_pieces(traj, idx, reduce, names):
            lo, hi = min(lo, part.tmin), max(hi, part.tmax)
            env.merge(part)
        if lo >= t0 and hi <= t1:
            break
        t0, t1 = lo, hi
    one.t = np.array([t0, t1])
    return one, env


#: most samples read from a store for a 3-D picture (whole Zarr chunks, evenly spread over the run)
MAX_READ_3D = 10_000_000


def _thin(traj, limit: int, *, blocks: bool = False):
    """At most about ``limit`` evenly strided samples (the first one kept), as an in-memory Trajectory.

    A store is read piece by piece; one longer than :data:`MAX_READ_3D`
    samples is read in whole Zarr chunks evenly spread over the run (the
    3-D pictures are point samples of a path: the time for a picture stays
    bounded at any length). With ``blocks=True`` also the start positions,
    in the result, of its contiguous runs of samples (the joins are gaps in time).
    """
    from ..trajectory import Trajectory

    _check_traj(traj)
    if not _is_lazy(traj):
        T = len(traj.t)
        if T > limit:
            step = -(-T // limit)
            traj = Trajectory(
                traj.t[::step],
                traj.quaternion[..., ::step, :],
                traj.omega[..., ::step, :],
                traj.body,
                traj.method,
                traj.options,
                traj.stats,
                torque=list(traj.model.torques),
            )
        return (traj, [0]) if blocks else traj
    T = len(traj)
    chunks = traj.chunk_bounds()
    if T > MAX_READ_3D and len(chunks) > 1:
        keep = max(1, MAX_READ_3D // traj.chunk)
        chunks = [chunks[i] for i in np.unique(np.round(np.linspace(0, len(chunks) - 1, keep)).astype(int))]
    total = sum(b - a for a, b in chunks)
    step = max(1, -(-total // limit))
    # contiguous runs of the chosen chunks, read in pieces of at most _PIECE samples
    runs: list[list[int]] = []
    for a, b in chunks:
        if runs and runs[-1][1] == a:
            runs[-1][1] = b
        else:
            runs.append([a, b])
    ranges, starts, pos = [], [], 0
    for a, b in runs:
        starts.append(pos)
        for c in range(a, b, _PIECE):
            d = min(b, c + _PIECE)
            c0 = a + -(-(c - a) // step) * step  # the stride continues across pieces of a run
            if c0 < d:
                ranges.append((c0, d, step))
                pos += len(range(c0, d, step))
    parts = list(traj.map_arrays(("time", "quaternion", "omega"), ranges=ranges))  # read in parallel threads
    if not parts:
        return (traj.load(), [0]) if blocks else traj.load()
    out = Trajectory(
        np.concatenate([p["time"] for p in parts]),
        np.concatenate([p["quaternion"] for p in parts], axis=-2),
        np.concatenate([p["omega"] for p in parts], axis=-2),
        traj.body,
        traj.method,
        traj.options,
        traj.stats,
        torque=list(traj.model.torques),
    )
    return (out, starts) if blocks else out


def _decimated_note(ax, n: int) -> None:
    ax.text(
        0.005,
        0.005,
        f"{n:,} samples: min/max per pixel column",
        transform=ax.transAxes,
        ha="left",
        va="bottom",
        fontsize=7,
        color="0.45",
    )


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
    mpl = import_matplotlib()
    Mp = one.M @ one.axes  # principal components P^T M, (T, 3)
    k = one.first
    L = float(np.linalg.norm(Mp[k]))
    I = one.moments
    lim = 1.2 * (L if L > 0 else 1.0)
    with mpl.rc_context(STYLE):
        fig, ax = _new_axes(ax, fig, True, (6.2, 6.0))
        unit = f"kg m²/{one.unit}"
        _setup_3d(ax, lim, [f"M{str(i + 1).translate(_SUB)} [{unit}]" for i in range(3)])
        if L > 0:
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
        kw = {"color": "#8c1d8c", "lw": 2.2, **style}
        ax.plot(*Mp[sl].T, label="M(t) computed", **kw)
        ax.scatter(*Mp[k], color="#8c1d8c", s=25, depthshade=False, label="M(t₀)")
        ax.legend(loc="upper left", fontsize=8)
        ax.set_title(_title(one, "Polhode: body angular momentum M(t) on |M| = L"))
    return fig


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


def _chart_bounds_numpy(q, r: float, jump_limit: float) -> list[tuple[int, int]]:
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
    """The charts' ``(start, end)``: a numba kernel when numba is used, else :func:`_chart_bounds_numpy`."""
    from ..util.jit import USE_NUMBA

    if USE_NUMBA and q.shape[0] > 20_000:  # (short series: not worth the compilation)
        if not CHART_KERNEL:
            CHART_KERNEL.append(_chart_bounds_compiled())
        a, b = CHART_KERNEL[0](np.ascontiguousarray(q), float(r), float(jump_limit))
        return list(zip(a.tolist(), b.tolist()))
    return _chart_bounds_numpy(q, r, jump_limit)


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
    **kwargs
        Passed to the ``plot_<kind>`` function (``ax``, ``fig``, style...).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InvalidInputError
        Unknown ``kind``, unsupported extension of ``out``, bad ``index``.
    TypeError
        ``traj`` is not a Trajectory, ``out`` not a path.
    MissingDependencyError
        matplotlib is not installed (extra ``plot``).

    Examples
    --------
    >>> import eulerpoisson as ep                             # doctest: +SKIP
    >>> tr = ep.solve([3, 5, 9], np.linspace(0, 150, 3001),
    ...               omega0=[0, 0.4, 0.01 / 9])               # doctest: +SKIP
    >>> ep.plots.plot(tr, "polhode", out="polhode.png")        # doctest: +SKIP
    """
    if not isinstance(kind, str) or kind not in _PLOTTERS:
        raise InvalidInputError(f"unknown plot kind {kind!r}; available kinds: {', '.join(KINDS)}")
    if out is not None:
        _check_out(out)  # fail before drawing
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
