"""The tennis-racket atlas: heat maps of a sweep read by :func:`~eulerpoisson.sweep.load_sweep`
(matplotlib is imported only when a figure is drawn).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

from ..errors import InvalidInputError, require

__all__ = ["plot_atlas"]


def _middle_gap(I: np.ndarray, M: np.ndarray) -> np.ndarray:
    r""":math:`2EI_\mathrm{mid} - L^2` (zero on the separatrix), elementwise over (..., 3)."""
    mid = np.median(I, axis=-1)[..., None]
    return np.sum(M**2 * (mid / I - 1.0), -1)


def plot_atlas(
    ds: xr.Dataset,
    out: str | os.PathLike[str],
    *,
    variables: Sequence[str] = ("half_period", "sensitivity"),
    dpi: int = 150,
) -> Path:
    """Heat maps of a sweep: the flip half-period (and sensitivity) with the separatrix drawn.

    A grid sweep with two axes of length > 1 is drawn as a heat map over
    them — over the momentum sphere in (azimuth, polar), or over an
    inertia plane (e.g. ``I2``, ``I3``) — with a logarithmic colour scale;
    the separatrix :math:`2EI_2 = L^2` is drawn as a black line (infinite
    half-periods on it are grey) and non-physical or symmetric points are
    left blank. A random sweep with one body is drawn as a scatter plot in
    (azimuth, polar).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`load_sweep`.
    out : str or Path
        Figure file (.png, .pdf, .svg).
    variables : sequence of str
        Panels to draw (data variables of ``ds``).
    dpi : int

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    InvalidInputError
        Not a sweep dataset, an unknown variable, a grid with other than
        two non-trivial axes (select a plane first, e.g. ``ds.isel(I2=0)``),
        or nothing to draw: no panel has a finite positive value (a sweep of
        bodies that are not physical). A panel without values (the
        half-period of a symmetric body) is drawn empty, with a note.
    MissingDependencyError
        matplotlib missing (extra ``plot``).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, plot_atlas, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0},
    ...        "momentum": {"polar": [30.0, 60.0, 90.0], "azimuth": [0.0, 45.0]},
    ...        "output": {"path": "sphere.zarr"}, "compute": {"T": 5.0, "scheduler": "serial"}}
    >>> plot_atlas(load_sweep(run_sweep(cfg, progress=False)), "atlas.png", dpi=40).name
    'atlas.png'
    """
    if not hasattr(ds, "data_vars") or "half_period" not in ds:
        raise InvalidInputError("plot_atlas needs a sweep dataset from load_sweep(path)")
    variables = [variables] if isinstance(variables, str) else list(variables)
    for v in variables:
        if v not in ds.data_vars:
            raise InvalidInputError(
                f"variables: {v!r} is not in the sweep; choose from {', '.join(map(str, ds.data_vars))}"
            )
    drawable = {v: _has_values(ds[v]) for v in variables}
    if not any(drawable.values()):
        raise InvalidInputError(_nothing_to_draw(ds, variables))
    mpl = require("matplotlib", "plot")
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure

    ds = ds.squeeze()
    deg = ds["polar"].attrs.get("units", "degree") == "degree"
    alabel = "deg" if deg else "rad"
    names = {"half_period": "flip half-period", "sensitivity": "attitude sensitivity", "k2": "k^2"}
    fig = Figure(figsize=(5.5 * len(variables), 4.2))
    axes = fig.subplots(1, len(variables), squeeze=False)
    ref = ds["half_period"]
    I = np.stack([ds[k].broadcast_like(ref).transpose(*ref.dims).values for k in ("I1", "I2", "I3")], -1)
    M = ds["M0"].broadcast_like(ref).transpose(*ref.dims, "axis").values
    gap = np.where(ds["status"].broadcast_like(ref).transpose(*ref.dims).values == 3, np.nan, _middle_gap(I, M))
    if "point" in ds.dims:
        if not (np.ptp(I, axis=0) == 0).all():
            raise InvalidInputError("plot_atlas draws a random sweep only for one body (constant inertia)")
        x, y = ds["azimuth"].values, ds["polar"].values
        for ax, v in zip(axes[0], variables):
            z = ds[v].values.astype(float)
            if not drawable[v]:
                _empty_panel(ax, ds, v, names.get(v, v))
                continue
            good = np.isfinite(z) & (z > 0)
            sc = ax.scatter(x[good], y[good], c=z[good], s=6, norm=LogNorm(), cmap="viridis")
            ax.scatter(x[~good], y[~good], c="0.5", s=6)
            fig.colorbar(sc, ax=ax, label=names.get(v, v))
            ax.set_xlabel(f"azimuth of M0 ({alabel})")
            ax.set_ylabel(f"polar angle of M0 ({alabel})")
            ax.invert_yaxis()
            ax.set_title(names.get(v, v))
    else:
        dims = [str(d) for d in ds["half_period"].dims]
        if len(dims) != 2:
            raise InvalidInputError(
                f"plot_atlas draws a grid with exactly two axes of length > 1, this one has {dims}; "
                "select a plane first, e.g. ds.isel(I2=0)"
            )
        if set(dims) == {"polar", "azimuth"}:
            xd, yd = "azimuth", "polar"
        else:
            yd, xd = dims
        for ax, v in zip(axes[0], variables):
            z = ds[v].transpose(yd, xd).values.astype(float)
            if not drawable[v]:
                _empty_panel(ax, ds, v, names.get(v, v))
                continue
            zm = np.ma.masked_invalid(np.where(z > 0, z, np.nan))
            cmap = mpl.colormaps["viridis"].with_extremes(bad="white")
            xv, yv = ds[xd].values, ds[yd].values
            pc = ax.pcolormesh(xv, yv, zm, norm=LogNorm(), cmap=cmap, shading="nearest")
            inf = np.isinf(z)
            if inf.any():
                ax.pcolormesh(
                    xv, yv, np.ma.masked_where(~inf, np.ones_like(z)), cmap="Greys", vmin=0, vmax=2, shading="nearest"
                )
            gz = _as_plane(ds, gap, yd, xd)
            crosses = bool(np.nanmin(gz) < 0 < np.nanmax(gz)) if np.isfinite(gz).any() else False
            if crosses:
                ax.contour(xv, yv, np.ma.masked_invalid(gz), levels=[0.0], colors="k", linewidths=1.0)
            fig.colorbar(pc, ax=ax, label=names.get(v, v))
            ax.set_xlabel(f"{xd} ({alabel})" if xd in ("polar", "azimuth") else xd)
            ax.set_ylabel(f"{yd} ({alabel})" if yd in ("polar", "azimuth") else yd)
            if yd == "polar":
                ax.invert_yaxis()
            ax.set_title(names.get(v, v) + ("  (black: separatrix)" if crosses else ""))
    fig.suptitle(f"tennis-racket atlas, T = {ds.attrs.get('T', float('nan')):g}")
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    from ..io.atomic import atomic_path

    with atomic_path(out, suffix=out.suffix) as tmp:
        fig.savefig(tmp, dpi=dpi, format=out.suffix.lstrip(".") or "png")
    return out


def _has_values(var) -> bool:
    """Whether a variable has a value a logarithmic colour scale can show (finite and > 0)."""
    z = np.asarray(var.values, dtype=float)
    return bool(np.any(np.isfinite(z) & (z > 0)))


def _status_words(ds) -> str:
    """'35 not a physical body, 2 symmetric body' for the points of ``ds``."""
    from .points import STATUS

    codes = np.asarray(ds["status"].values).ravel() if "status" in ds else np.array([], dtype=int)
    parts = [f"{int(np.count_nonzero(codes == c))} {name}" for c, name in STATUS.items() if np.any(codes == c)]
    if np.any(codes < 0):
        parts.append(f"{int(np.count_nonzero(codes < 0))} not computed yet")
    return ", ".join(parts)


def _nothing_to_draw(ds, variables) -> str:
    src = ds.encoding.get("source")
    where = f"{src}: " if src else ""
    statuses = _status_words(ds)
    why = f" (its points: {statuses})" if statuses else ""
    hint = ""
    if "status" in ds and np.all(np.asarray(ds["status"].values) == 3):
        hint = "; every body of the sweep violates the triangle inequality: sweep physical moments of inertia"
    return f"{where}nothing to draw: {', '.join(variables)} {'has' if len(variables) == 1 else 'have'} no finite value{why}{hint}"


def _empty_panel(ax, ds, v: str, title: str) -> None:
    """A panel without values: its axes and a note instead of a colour map."""
    statuses = _status_words(ds)
    ax.text(
        0.5,
        0.5,
        f"no finite values of {v}" + (f"\n({statuses})" if statuses else ""),
        ha="center",
        va="center",
        transform=ax.transAxes,
    )
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title)


def _as_plane(ds, values: np.ndarray, yd: str, xd: str) -> np.ndarray:
    """Values laid out like ``ds['half_period']`` (dims order) as a (yd, xd) array."""
    dims = list(ds["half_period"].dims)
    arr = np.asarray(values).reshape(ds["half_period"].shape)
    return np.transpose(arr, (dims.index(yd), dims.index(xd)))
