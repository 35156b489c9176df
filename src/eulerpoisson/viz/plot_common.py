r"""What every picture of :mod:`eulerpoisson.viz.plots` shares: the style, the chosen body, labels, axes.

:data:`STYLE` and :data:`AXIS_COLORS` (also used by
:mod:`eulerpoisson.viz.animate`), :func:`select_body` (one body of a batch,
sorted by time, with its labels), :func:`plain_text` (names drawn as text,
never mathtext), :func:`import_matplotlib` and the helpers that make the
axes of a figure. Re-exported by :mod:`eulerpoisson.viz.plots`.

Examples
--------
>>> plain_text("cost in $")
'cost in \\$'
>>> fmt_number(1.0 / 3.0)
'0.3333'
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion
from ..errors import InvalidInputError, require

__all__ = [
    "AXIS_COLORS",
    "STYLE",
    "SUBSCRIPTS",
    "MAX_3D_POINTS",
    "OneBody",
    "select_body",
    "plain_text",
    "import_matplotlib",
    "fmt_number",
    "title_of",
    "new_axes",
    "stride",
    "draw_unit_sphere",
    "setup_3d",
]

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

#: subscript digits, for component labels (Ω₁)
SUBSCRIPTS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
#: longer series are strided for the 3-D pictures
MAX_3D_POINTS = 20000


# ---------------------------------------------------------------------------
# selection of one body, labels
# ---------------------------------------------------------------------------
@dataclass
class OneBody:
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


def fmt_number(x: float) -> str:
    """``x`` with 4 significant digits."""
    return f"{x:.4g}"


def _body_label(name, moments) -> str:
    mom = "I = (" + ", ".join(fmt_number(v) for v in moments) + ")"
    return f"{name}, {mom}" if name else mom


def _time_unit(traj) -> str:
    unit = getattr(traj, "time_unit", None) or getattr(traj, "options", {}).get("time_unit")
    return str(unit) if unit else "s"


def select_body(traj, index=0) -> OneBody:
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
    return OneBody(
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


def title_of(one: OneBody, what: str) -> str:
    """The title of a picture of ``what`` for the body ``one`` (its label and method)."""
    return f"{what}\n{plain_text(one.label)} — method: {plain_text(one.method)}"


def import_matplotlib():
    """Import matplotlib (extra ``plot``)."""
    mpl = require("matplotlib", "plot")
    require("matplotlib.figure", "plot")
    return mpl


def new_axes(ax, fig, three_d: bool, figsize):
    """``(fig, ax)``: the given axes (or a new one in ``fig``, or a new figure), 3-D if asked."""
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


def stride(n: int, limit: int = MAX_3D_POINTS) -> slice:
    """A slice that keeps at most about ``limit`` of ``n`` samples, evenly strided."""
    return slice(None, None, max(1, -(-n // limit)))


def draw_unit_sphere(ax, radius=1.0, color="0.6", alpha=0.25, n=(25, 13)):
    """Draw a wire sphere of ``radius`` about the origin into the 3-D axes ``ax``."""
    u = np.linspace(0, 2 * np.pi, n[0])
    v = np.linspace(0, np.pi, n[1])
    x = radius * np.outer(np.cos(u), np.sin(v))
    y = radius * np.outer(np.sin(u), np.sin(v))
    z = radius * np.outer(np.ones_like(u), np.cos(v))
    ax.plot_wireframe(x, y, z, color=color, alpha=alpha, linewidth=0.4)


def setup_3d(ax, lim, labels, elev=22, azim=38):
    """Equal 3-D limits ``[-lim, lim]``, the axis labels and the view angles of ``ax``."""
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
