r"""Animations of a tumbling body: a self-contained HTML page, a GIF or an MP4.

:func:`animate` shows the body as a uniform box with the proportions of its
inertia ellipsoid (:func:`box_dimensions`), turning according to the
trajectory, together with its spatial angular momentum :math:`\mathbf m`,
which is fixed in space for the free body.

* ``.html`` — one self-contained page (inline JavaScript, no network, no
  library): the sampled attitude quaternions are embedded as JSON and
  interpolated by spherical linear interpolation (slerp); the box is painted
  on a ``<canvas>`` with a small hand-written perspective projection
  (back-face culling, painter's algorithm, Lambert-shaded faces). The page
  has a play/pause button, a time slider, and drag-to-rotate for the view.
* ``.gif`` — rendered by matplotlib and streamed to the file frame by frame
  (:class:`GifStreamWriter`, with Pillow, a dependency of matplotlib): memory
  is bounded by two frames whatever their number. The fixed orthographic view
  of matplotlib's 3-D axes is applied as an affine map and the frames are
  blitted on a 2-D axes: only what moves is drawn again.
* ``.mp4`` — the same frames, piped to the ``ffmpeg`` program (H.264), as
  matplotlib's ``FFMpegWriter`` does; needs ``ffmpeg``.

The face colours are those of :data:`eulerpoisson.viz.plots.AXIS_COLORS`: the
two faces normal to principal axis :math:`i` have the colour of axis
:math:`i` (the face on the negative side lighter), so a flip of the
intermediate axis — the tennis racket — is easy to see.

Files are written atomically (temporary file, then rename).

References
----------
K. Shoemake, "Animating rotation with quaternion curves", SIGGRAPH 1985
(slerp). L. D. Landau and E. M. Lifshitz, *Mechanics*, §32 (moments of
inertia of a box).
"""

from __future__ import annotations

import contextlib
import html as _html
import json
import os
import re
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError, MissingDependencyError
from ..io.atomic import atomic_path
from ..io.outputs import mark_text
from ..util.validate import as_float_array
from .plots import AXIS_COLORS, import_matplotlib, plain_text, select_body

if TYPE_CHECKING:
    from ..io.read import LazyTrajectory
    from ..trajectory import Trajectory

__all__ = ["animate", "box_dimensions", "slerp_series", "FORMATS", "GifStreamWriter"]

#: output formats of :func:`animate`, by file extension
FORMATS = ("html", "gif", "mp4")

#: thinnest side of the box relative to the longest (a planar body, I1 + I2 = I3, has zero thickness)
MIN_THICKNESS = 0.04

#: most attitude samples embedded in an HTML page (longer trajectories are subsampled)
MAX_HTML_SAMPLES = 20000

_ELEVATION = 22.0  # camera elevation, degrees
_M_AZIMUTH = 70.0  # m is shown this far (degrees) in azimuth from the viewing direction


def _view(mdir) -> tuple[float, float]:
    """Camera (azimuth, elevation) in degrees: m seen from the side, pointing right and a little towards the viewer."""
    if mdir is None or np.hypot(mdir[0], mdir[1]) < 1e-3:
        return (-55.0, _ELEVATION)
    return (float(np.degrees(np.arctan2(mdir[1], mdir[0])) - _M_AZIMUTH), _ELEVATION)


def _camera(view) -> np.ndarray:
    """Rows: screen right, screen up, towards the viewer (space frame), for (azimuth, elevation) in degrees."""
    az, el = np.radians(view[0]), np.radians(view[1])
    ca, sa, ce, se = np.cos(az), np.sin(az), np.cos(el), np.sin(el)
    return np.array([[-sa, ca, 0.0], [-se * ca, -se * sa, ce], [ce * ca, ce * sa, se]])


def hidden_by_box(points, R, half, axes, eye, *, orthographic=False) -> np.ndarray:
    r"""Which points are inside the box or behind it as seen from ``eye``.

    The box has half sides ``half`` along the principal axes (columns of
    ``axes``, body frame) and attitude ``R`` (space = R body). A point
    :math:`\mathbf p` is hidden when the segment from the eye to it meets the
    box (slab test). With ``orthographic=True``, ``eye`` is the direction
    towards the viewer and the segment runs from :math:`\mathbf p` to
    infinity along it.

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        Space frame.
    R : ndarray, shape (3, 3)
    half : ndarray, shape (3,)
    axes : ndarray, shape (3, 3)
    eye : ndarray, shape (3,)

    Returns
    -------
    ndarray of bool, shape (N,)
    """
    B = R @ np.asarray(axes)  # principal axes in space
    p = np.asarray(points, float) @ B  # principal box coordinates
    e = np.asarray(eye, float) @ B
    if orthographic:
        a, d = p, np.broadcast_to(e, p.shape)  # ray p + s d, s in [0, inf)
        lo_s, hi_s = 0.0, np.inf
    else:
        a, d = np.broadcast_to(e, p.shape), p - e  # eye + s (p - eye), s in [0, 1]
        lo_s, hi_s = 0.0, 1.0
    h = np.asarray(half, float) * (1.0 - 1e-9)
    t0 = np.full(p.shape[0], lo_s)
    t1 = np.full(p.shape[0], hi_s)
    with np.errstate(divide="ignore", invalid="ignore"):
        for i in range(3):
            par = np.abs(d[:, i]) < 1e-300
            u = (-h[i] - a[:, i]) / d[:, i]
            v = (h[i] - a[:, i]) / d[:, i]
            lo = np.where(par, np.where(np.abs(a[:, i]) <= h[i], -np.inf, np.inf), np.minimum(u, v))
            hi = np.where(par, np.where(np.abs(a[:, i]) <= h[i], np.inf, -np.inf), np.maximum(u, v))
            t0 = np.maximum(t0, lo)
            t1 = np.minimum(t1, hi)
    return t0 <= t1


# ---------------------------------------------------------------------------
# geometry
# ---------------------------------------------------------------------------
def box_dimensions(moments: ArrayLike, *, min_thickness: float = MIN_THICKNESS) -> np.ndarray:
    r"""Side lengths of the uniform box with the given principal moments, scaled to a longest side of 1.

    A uniform box of mass :math:`m` and sides :math:`a_1, a_2, a_3` has
    :math:`I_1 = m(a_2^2+a_3^2)/12` and cyclic, so
    :math:`a_1^2+a_2^2+a_3^2 = 6(I_1+I_2+I_3)/m` and

    .. math:: a_i^2 = \frac{6}{m}\,(I_j + I_k - I_i),

    real by the triangle inequality of a physical body.

    Parameters
    ----------
    moments : array_like, shape (3,)
        Principal moments :math:`I_i > 0`.
    min_thickness : float
        Sides shorter than this fraction of the longest are raised to it (a
        planar body would otherwise be invisible edge-on).

    Returns
    -------
    ndarray, shape (3,)
        :math:`a_i/\max_j a_j`.

    Raises
    ------
    InvalidInputError
        Wrong shape, non-positive or non-finite moments, or moments violating
        the triangle inequality :math:`I_i \le I_j + I_k`.
    """
    I = as_float_array(moments, "moments")
    if I.shape != (3,):
        raise InvalidInputError(f"moments must have shape (3,), got {I.shape}")
    if np.any(I <= 0):
        raise InvalidInputError(f"moments must be > 0, got {I.tolist()}")
    sq = I.sum() - 2.0 * I  # I_j + I_k - I_i
    tol = 1e-12 * I.sum()
    if np.any(sq < -tol):
        raise InvalidInputError(
            f"moments {I.tolist()} violate the triangle inequality I_i <= I_j + I_k; no box has them"
        )
    a = np.sqrt(np.clip(sq, 0.0, None))
    a = a / a.max()
    return np.maximum(a, float(min_thickness))


def _box_mesh(moments, axes):
    """Vertices (8, 3) in the body frame and faces (vertex indices, body normal, axis, sign)."""
    sides = box_dimensions(moments)
    half = 0.5 * sides
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    verts = (corners * half) @ np.asarray(axes).T  # principal -> body frame
    faces = []
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        for s in (1, -1):
            cyc = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
            if s < 0:
                cyc = cyc[::-1]
            idx = []
            for uj, uk in cyc:
                c = np.zeros(3)
                c[i], c[j], c[k] = s, uj, uk
                idx.append(int(np.flatnonzero(np.all(corners == c, axis=1))[0]))
            normal = s * np.asarray(axes)[:, i]
            faces.append((idx, normal, i, s))
    return sides, verts, faces


def _face_rgb(axis: int, sign: int) -> list[int]:
    h = AXIS_COLORS[axis].lstrip("#")
    rgb = np.array([int(h[p : p + 2], 16) for p in (0, 2, 4)], float)
    if sign < 0:  # the face on the negative side: lighter
        rgb = rgb + 0.45 * (255.0 - rgb)
    return [int(round(c)) for c in rgb]


def slerp_series(t: ArrayLike, q: ArrayLike, tf: ArrayLike) -> np.ndarray:
    r"""Attitudes at times ``tf`` by spherical linear interpolation of the samples ``(t, q)``.

    .. math:: q(s) = \frac{\sin((1-s)\theta)}{\sin\theta}q_i + \frac{\sin(s\theta)}{\sin\theta}q_{i+1},
              \qquad \cos\theta = |q_i\cdot q_{i+1}|,

    with the sign of :math:`q_{i+1}` chosen so that :math:`q_i\cdot q_{i+1}\ge 0`
    (the shorter arc). Exact for a rotation with constant angular velocity
    between samples. Times outside ``[t[0], t[-1]]`` are clamped.

    Parameters
    ----------
    t : array_like, shape (T,)
        Sample times, non-decreasing, T >= 1.
    q : array_like, shape (T, 4)
        Unit quaternions.
    tf : array_like, shape (F,)
        Requested times.

    Returns
    -------
    ndarray, shape (F, 4)

    Raises
    ------
    InvalidInputError
        Wrong shapes, non-finite values, decreasing ``t``.
    """
    t = as_float_array(t, "t")
    q = as_float_array(q, "q", (4,))
    tf = np.atleast_1d(as_float_array(tf, "tf"))
    if t.ndim != 1 or q.shape != (t.size, 4) or t.size < 1:
        raise InvalidInputError(f"t must have shape (T,) and q (T, 4) with T >= 1; got {t.shape} and {q.shape}")
    if np.any(np.diff(t) < 0):
        raise InvalidInputError("t must be non-decreasing")
    if t.size == 1:
        return np.broadcast_to(q[0] / np.linalg.norm(q[0]), tf.shape + (4,)).copy()
    tc = np.clip(tf, t[0], t[-1])
    i = np.clip(np.searchsorted(t, tc, side="right") - 1, 0, t.size - 2)
    dt = t[i + 1] - t[i]
    s = np.where(dt > 0, (tc - t[i]) / np.where(dt > 0, dt, 1.0), 0.0)
    a, b = q[i], q[i + 1]
    d = np.sum(a * b, -1)
    b = np.where(d[:, None] < 0, -b, b)
    d = np.abs(d)
    th = np.arccos(np.clip(d, -1.0, 1.0))
    st = np.sin(th)
    small = st < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        k0 = np.where(small, 1.0 - s, np.sin((1.0 - s) * th) / np.where(small, 1.0, st))
        k1 = np.where(small, s, np.sin(s * th) / np.where(small, 1.0, st))
    r = k0[:, None] * a + k1[:, None] * b
    return r / np.linalg.norm(r, axis=-1, keepdims=True)


# ---------------------------------------------------------------------------
# argument checks
# ---------------------------------------------------------------------------
def _check_args(out, fps, duration, size):
    if not isinstance(out, (str, os.PathLike)):
        raise TypeError(f"out must be a file name (str or path), got {type(out).__name__}")
    p = Path(out)
    ext = p.suffix.lower().lstrip(".")
    if ext == "htm":
        ext = "html"
    if ext not in FORMATS:
        raise InvalidInputError(
            f"out={str(out)!r}: unsupported file extension {p.suffix!r}; use .html (self-contained page), .gif or .mp4"
        )
    if (
        isinstance(fps, bool)
        or not isinstance(fps, (int, float, np.integer, np.floating))
        or not (np.isfinite(fps) and fps > 0)
    ):
        raise InvalidInputError(f"fps must be a positive number of frames per second, got {fps!r}")
    if duration is not None and (
        isinstance(duration, bool)
        or not isinstance(duration, (int, float, np.integer, np.floating))
        or not (np.isfinite(duration) and duration > 0)
    ):
        raise InvalidInputError(f"duration must be None or a positive number of seconds, got {duration!r}")
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise InvalidInputError(f"size must be (width, height) in pixels, got {size!r}") from None
    if not (16 <= w <= 4096 and 16 <= h <= 4096):
        raise InvalidInputError(f"size must be (width, height) between 16 and 4096 pixels, got {size!r}")
    return p, ext, (w, h)


def default_duration(span: float) -> float:
    return float(np.clip(span, 2.0, 20.0))


# ---------------------------------------------------------------------------
# public entry point
# ---------------------------------------------------------------------------
def animate(
    traj: Trajectory | LazyTrajectory,
    out: str | os.PathLike[str],
    *,
    fps: float = 30,
    duration: float | None = None,
    index: int | tuple[int, ...] = 0,
    size: tuple[int, int] = (640, 480),
    max_samples: int = MAX_HTML_SAMPLES,
) -> Path:
    r"""Write an animation of the tumbling body: ``.html``, ``.gif`` or ``.mp4`` by the extension of ``out``.

    Parameters
    ----------
    traj : Trajectory or LazyTrajectory
        The motion (for a batch, the body ``index`` is shown). A Zarr store
        (:class:`~eulerpoisson.io.read.LazyTrajectory`) is read at
        ``max(max_samples, 80000)`` evenly spread samples, each chunk once.
    out : str or path
        Output file; ``.html`` (a self-contained page), ``.gif`` or ``.mp4``.
    fps : float
        Frames per second of a GIF/MP4 (the HTML page animates at the
        browser's frame rate).
    duration : float, optional
        Playing time of the whole trajectory in seconds (the HTML page
        loops). Default: the trajectory's time span, clipped to [2, 20] s.
        A GIF/MP4 has ``round(fps * duration)`` frames (at least 2).
    index : int or tuple
        Body of a batched trajectory.
    size : (int, int)
        Width and height in pixels of the canvas / video frames.
    max_samples : int
        Most attitude samples embedded in an HTML page; longer trajectories
        are subsampled evenly (keeping both ends).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    InvalidInputError
        Unsupported extension, non-positive ``fps`` or ``duration``, bad
        ``size`` or ``index``, fewer than two distinct times.
    TypeError
        ``traj`` is not a Trajectory, ``out`` not a path.
    MissingDependencyError
        matplotlib is missing (GIF/MP4, extra ``plot``), or ``ffmpeg`` is not
        installed (MP4).

    Examples
    --------
    >>> tr = ep.solve([3, 5, 7], np.linspace(0, 150, 3001), omega0=[0, 0.4, 0.01 / 7])  # doctest: +SKIP
    >>> animate(tr, "racket.html")                                                   # doctest: +SKIP
    """
    from ..io.read import LazyTrajectory

    if isinstance(traj, LazyTrajectory):  # a store: evenly spread samples, each Zarr chunk read once
        n = len(traj)
        keep = max(int(max_samples), 4 * MAX_HTML_SAMPLES)
        traj = traj.gather(np.unique(np.round(np.linspace(0, n - 1, min(n, keep))).astype(np.int64)))
    one = select_body(traj, index)
    p, ext, px = _check_args(out, fps, duration, size)
    span = float(one.t[-1] - one.t[0])
    dur = default_duration(span) if duration is None else float(duration)
    sides, verts, faces = _box_mesh(one.moments, one.axes)
    m0 = one.m[one.first]
    mn = float(np.linalg.norm(m0))
    mdir = m0 / mn if mn > 0 else None
    if ext == "html":
        # marked as ours (io.outputs.content_kind: a command's --overwrite may replace it, never another page)
        text = mark_text(_html_page(one, sides, verts, faces, mdir, dur, px, int(max_samples)), "animation", "html")
        with atomic_path(p, suffix=".html") as tmp:
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
        return p
    nframes = max(2, int(round(float(fps) * dur)))
    tf = np.linspace(one.t[0], one.t[-1], nframes)
    qf = slerp_series(one.t, one.q, tf)
    _render_video(one, sides, verts, faces, mdir, tf, qf, p, ext, float(fps), px)
    return p


# ---------------------------------------------------------------------------
# HTML
# ---------------------------------------------------------------------------
def _html_page(one, sides, verts, faces, mdir, duration, px, max_samples) -> str:
    T = len(one.t)
    if max_samples < 2:
        raise InvalidInputError(f"max_samples must be >= 2, got {max_samples}")
    if T > max_samples:
        sel = np.unique(np.round(np.linspace(0, T - 1, max_samples)).astype(int))
    else:
        sel = np.arange(T)
    t = one.t[sel]
    q = one.q[sel]
    title = f"{one.label} — method: {one.method}"
    data = {
        "title": title,
        "unit": one.time_unit,
        "t": [float(f"{v:.10g}") for v in t],
        "q": np.round(q, 7).tolist(),
        "verts": np.round(verts, 6).tolist(),
        "faces": [
            {"v": idx, "normal": np.round(nrm, 9).tolist(), "color": _face_rgb(ax, s), "axis": ax + 1}
            for idx, nrm, ax, s in faces
        ],
        "m": None if mdir is None else np.round(mdir, 9).tolist(),
        "moments": [float(v) for v in one.moments],
        "duration": float(duration),
        "view": list(_view(mdir)),
        "half": np.round(0.5 * sides, 9).tolist(),
        "axes": np.round(np.asarray(one.axes).T, 12).tolist(),
        "axisColors": list(AXIS_COLORS),
    }
    blob = json.dumps(data, separators=(",", ":"), ensure_ascii=True)
    blob = blob.replace("&", "\\u0026").replace("<", "\\u003c").replace(">", "\\u003e")
    w, h = px
    moms = ", ".join(f"I{i + 1} = {v:.4g}" for i, v in enumerate(one.moments))
    values = {
        "TITLE": _html.escape(title),
        "MOMENTS": _html.escape(moms),
        "W": str(w),
        "H": str(h),
        "DATA": blob,
    }
    # one pass over the template: the substituted text (a body name may contain "__DATA__") is never
    # searched for placeholders again
    return _PLACEHOLDER.sub(lambda mt: values[mt.group(1)], _TEMPLATE)


_PLACEHOLDER = re.compile(r"__(TITLE|MOMENTS|W|H|DATA)__")


_TEMPLATE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="eulerpoisson.viz.animate">
<title>Tumbling body: __TITLE__</title>
<style>
  body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
         margin: 0; padding: 10px 0; background: #eef0f3; color: #222; }
  main { width: __W__px; margin: 0 auto; }
  h1 { font-size: 15px; font-weight: 600; margin: 0 0 6px 0; white-space: nowrap;
       overflow: hidden; text-overflow: ellipsis; }
  #ep-canvas { display: block; background: #ffffff; border: 1px solid #c8ccd2; border-radius: 4px;
               cursor: grab; touch-action: none; }
  .ctl { display: flex; align-items: center; gap: 10px; margin-top: 6px; font-size: 13px; }
  #ep-slider { flex: 1; }
  #ep-time { font-variant-numeric: tabular-nums; min-width: 150px; text-align: right; }
  button { font-size: 13px; padding: 2px 12px; min-width: 64px; }
  .legend { font-size: 12px; color: #555; margin-top: 4px; }
  .sw { display: inline-block; width: 10px; height: 10px; margin: 0 3px 0 8px; vertical-align: -1px; }
</style>
</head>
<body>
<main>
<h1>__TITLE__</h1>
<noscript><p><strong>This animation needs JavaScript.</strong> It shows a box with the
proportions of the body's inertia ellipsoid (__MOMENTS__) tumbling freely, with its angular
momentum m fixed in space. Enable JavaScript, or write a GIF with
<code>eulerpoisson.viz.animate.animate(traj, "out.gif")</code>.</p></noscript>
<canvas id="ep-canvas" width="__W__" height="__H__" aria-label="tumbling rigid body"></canvas>
<div class="ctl">
  <button id="ep-play" type="button">Pause</button>
  <input id="ep-slider" type="range" min="0" max="1000" step="1" value="0" aria-label="time">
  <span id="ep-time"></span>
</div>
<div class="legend">Box with the proportions of the inertia ellipsoid (__MOMENTS__); faces coloured by principal
axis<span class="sw" style="background:#d62728"></span>1<span class="sw" style="background:#2ca02c"></span>2<span
class="sw" style="background:#1f77b4"></span>3 (lighter: negative side). Black arrow: angular momentum m, fixed in
space. Drag to turn the view.</div>
</main>
<script type="application/json" id="ep-data">__DATA__</script>
<script>
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("ep-data").textContent);
  var cv = document.getElementById("ep-canvas");
  var ctx = cv.getContext("2d");
  var W = cv.width, H = cv.height;
  var dpr = window.devicePixelRatio || 1;
  cv.style.width = W + "px"; cv.style.height = H + "px";
  cv.width = Math.round(W * dpr); cv.height = Math.round(H * dpr);
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);

  var T = D.t, Q = D.q, n = T.length, t0 = T[0], t1 = T[n - 1];
  var span = t1 - t0, speed = span / D.duration;
  var az = D.view[0] * Math.PI / 180, el = D.view[1] * Math.PI / 180;
  var playing = true, tcur = t0, last = null;

  // scene size: box half-diagonal and the arrow
  var R0 = 0;
  D.verts.forEach(function (v) { R0 = Math.max(R0, Math.hypot(v[0], v[1], v[2])); });
  var ARROW = 1.6 * R0, RS = Math.max(ARROW, 1.2 * R0);
  var DIST = 5 * RS, SCALE = 0.40 * Math.min(W, H) / RS;
  var LIGHT = norm([0.25, 0.6, 0.75]);

  function norm(v) { var s = Math.hypot(v[0], v[1], v[2]); return [v[0] / s, v[1] / s, v[2] / s]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

  // rotate v by the unit quaternion q = (w, x, y, z): v + w t + u x t with t = 2 u x v
  function qrot(q, v) {
    var w = q[0], x = q[1], y = q[2], z = q[3];
    var tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
    return [v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)];
  }

  // spherical linear interpolation between unit quaternions (shorter arc)
  function slerp(a, b, s) {
    var d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], sg = 1;
    if (d < 0) { d = -d; sg = -1; }
    var k0, k1;
    if (d > 0.9999995) { k0 = 1 - s; k1 = s; }
    else { var th = Math.acos(d), st = Math.sin(th); k0 = Math.sin((1 - s) * th) / st; k1 = Math.sin(s * th) / st; }
    k1 *= sg;
    var r = [k0 * a[0] + k1 * b[0], k0 * a[1] + k1 * b[1], k0 * a[2] + k1 * b[2], k0 * a[3] + k1 * b[3]];
    var s2 = Math.hypot(r[0], r[1], r[2], r[3]);
    return [r[0] / s2, r[1] / s2, r[2] / s2, r[3] / s2];
  }

  function attitude(tt) {
    if (n === 1 || tt <= t0) return Q[0];
    if (tt >= t1) return Q[n - 1];
    var lo = 0, hi = n - 1;
    while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (T[mid] <= tt) lo = mid; else hi = mid; }
    var dt = T[hi] - T[lo];
    return slerp(Q[lo], Q[hi], dt > 0 ? (tt - T[lo]) / dt : 0);
  }

  // camera: space (x, y, z) -> (right, up, towards the viewer)
  function cam(p) {
    var ca = Math.cos(az), sa = Math.sin(az), ce = Math.cos(el), se = Math.sin(el);
    return [-sa * p[0] + ca * p[1],
            -se * ca * p[0] - se * sa * p[1] + ce * p[2],
             ce * ca * p[0] + ce * sa * p[1] + se * p[2]];
  }
  function proj(c) { var f = DIST / (DIST - c[2]); return [W / 2 + SCALE * c[0] * f, H / 2 - SCALE * c[1] * f]; }

  function rgb(c, k) {
    return "rgb(" + Math.round(c[0] * k) + "," + Math.round(c[1] * k) + "," + Math.round(c[2] * k) + ")";
  }

  // space point -> coordinates along the box's principal axes
  function toBox(q, p) {
    var b = qrot([q[0], -q[1], -q[2], -q[3]], p);
    return [dot(D.axes[0], b), dot(D.axes[1], b), dot(D.axes[2], b)];
  }
  // is p inside the box or behind it, seen from the eye? (slab test on the segment eye -> p)
  function hidden(q, p, eye) {
    var a = toBox(q, eye), b = toBox(q, p), lo = 0, hi = 1;
    for (var i = 0; i < 3; i++) {
      var d = b[i] - a[i], h = D.half[i] * (1 - 1e-9);
      if (Math.abs(d) < 1e-300) { if (Math.abs(a[i]) > h) return false; continue; }
      var u = (-h - a[i]) / d, v = (h - a[i]) / d;
      lo = Math.max(lo, Math.min(u, v)); hi = Math.min(hi, Math.max(u, v));
      if (lo > hi) return false;
    }
    return true;
  }
  // a straight line cut into pieces; the pieces hidden by the (convex, opaque) box are dropped,
  // the others are drawn after the faces
  function lineItems(items, q, eye, a, b, color, width, pieces) {
    for (var i = 0; i < pieces; i++) {
      var s0 = i / pieces, s1 = (i + 1) / pieces, sm = 0.5 * (s0 + s1);
      var p = [a[0] + (b[0] - a[0]) * s0, a[1] + (b[1] - a[1]) * s0, a[2] + (b[2] - a[2]) * s0];
      var r = [a[0] + (b[0] - a[0]) * s1, a[1] + (b[1] - a[1]) * s1, a[2] + (b[2] - a[2]) * s1];
      var mid = [a[0] + (b[0] - a[0]) * sm, a[1] + (b[1] - a[1]) * sm, a[2] + (b[2] - a[2]) * sm];
      if (hidden(q, mid, eye)) continue;
      var cp = cam(p), cr = cam(r);
      items.push({ z: Infinity, kind: 0, a: proj(cp), b: proj(cr), color: color, width: width });
    }
  }

  function draw() {
    var q = attitude(tcur);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, W, H);
    var items = [], i, k;
    var ce = Math.cos(el), eye = [DIST * ce * Math.cos(az), DIST * ce * Math.sin(az), DIST * Math.sin(el)];
    // space axes (faint), through the centre of mass
    var AX = 1.15 * RS, names = ["x", "y", "z"];
    for (i = 0; i < 3; i++) {
      var e = [0, 0, 0]; e[i] = AX;
      lineItems(items, q, eye, [-e[0], -e[1], -e[2]], e, "#c3c7cd", 1, 60);
    }
    // box faces: back-face culling, Lambert shading
    var V = D.verts.map(function (v) { return cam(qrot(q, v)); });
    D.faces.forEach(function (f) {
      var nn = cam(qrot(q, f.normal));
      var c = [0, 0, 0];
      f.v.forEach(function (j) { c[0] += V[j][0] / 4; c[1] += V[j][1] / 4; c[2] += V[j][2] / 4; });
      var view = [-c[0], -c[1], DIST - c[2]];
      if (dot(nn, view) <= 0) return;
      var shade = 0.5 + 0.5 * Math.max(0, dot(nn, LIGHT));
      items.push({ z: c[2], kind: 1, pts: f.v.map(function (j) { return proj(V[j]); }),
                   fill: rgb(f.color, shade), edge: rgb(f.color, 0.55 * shade) });
    });
    // angular momentum, fixed in space
    var tip = null;
    if (D.m) {
      var mtip = [ARROW * D.m[0], ARROW * D.m[1], ARROW * D.m[2]];
      lineItems(items, q, eye, [0, 0, 0], mtip, "#111111", 3, 60);
      if (!hidden(q, mtip, eye)) tip = cam(mtip);
    }
    // painter's algorithm: far first (visible line pieces last)
    items.sort(function (a, b) { return a.z - b.z; });
    ctx.lineJoin = "round"; ctx.lineCap = "round";
    for (k = 0; k < items.length; k++) {
      var it = items[k];
      if (it.kind === 0) {
        ctx.strokeStyle = it.color; ctx.lineWidth = it.width;
        ctx.beginPath(); ctx.moveTo(it.a[0], it.a[1]); ctx.lineTo(it.b[0], it.b[1]); ctx.stroke();
      } else {
        ctx.beginPath(); ctx.moveTo(it.pts[0][0], it.pts[0][1]);
        for (i = 1; i < it.pts.length; i++) ctx.lineTo(it.pts[i][0], it.pts[i][1]);
        ctx.closePath(); ctx.fillStyle = it.fill; ctx.fill();
        ctx.strokeStyle = it.edge; ctx.lineWidth = 1; ctx.stroke();
      }
    }
    // arrow head and labels on top
    ctx.font = "13px system-ui, sans-serif"; ctx.textAlign = "center"; ctx.textBaseline = "middle";
    if (tip) {
      var base = cam([0.86 * ARROW * D.m[0], 0.86 * ARROW * D.m[1], 0.86 * ARROW * D.m[2]]);
      var P = proj(tip), B = proj(base), dx = P[0] - B[0], dy = P[1] - B[1], L = Math.hypot(dx, dy) || 1;
      var ux = dx / L, uy = dy / L, hw = 6;
      ctx.fillStyle = "#111111"; ctx.beginPath(); ctx.moveTo(P[0] + 4 * ux, P[1] + 4 * uy);
      ctx.lineTo(P[0] - 10 * ux - hw * uy, P[1] - 10 * uy + hw * ux);
      ctx.lineTo(P[0] - 10 * ux + hw * uy, P[1] - 10 * uy - hw * ux); ctx.closePath(); ctx.fill();
      ctx.fillText("m", P[0] + 16 * ux - 8 * uy, P[1] + 16 * uy + 8 * ux);
    }
    ctx.fillStyle = "#888888";
    for (i = 0; i < 3; i++) {
      var e2 = [0, 0, 0]; e2[i] = 1.2 * RS; var pp = proj(cam(e2));
      ctx.fillText(names[i], pp[0], pp[1]);
    }
    document.getElementById("ep-time").textContent =
      "t = " + tcur.toFixed(2) + " " + D.unit + "  (" + speed.toPrecision(3) + "\u00d7)";
  }

  var slider = document.getElementById("ep-slider"), btn = document.getElementById("ep-play");
  btn.addEventListener("click", function () {
    playing = !playing; btn.textContent = playing ? "Pause" : "Play"; last = null;
  });
  slider.addEventListener("input", function () {
    tcur = t0 + span * slider.value / 1000; draw();
  });
  var drag = null;
  cv.addEventListener("pointerdown", function (ev) { drag = [ev.clientX, ev.clientY]; cv.setPointerCapture(ev.pointerId); });
  cv.addEventListener("pointerup", function () { drag = null; });
  cv.addEventListener("pointermove", function (ev) {
    if (!drag) return;
    az -= 0.01 * (ev.clientX - drag[0]);
    el = Math.max(-1.5, Math.min(1.5, el + 0.01 * (ev.clientY - drag[1])));
    drag = [ev.clientX, ev.clientY]; if (!playing) draw();
  });
  function frame(ts) {
    if (playing) {
      if (last !== null && span > 0) {
        tcur += (ts - last) / 1000 * speed;
        if (tcur > t1) tcur = t0 + ((tcur - t0) % span);
        slider.value = Math.round(1000 * (tcur - t0) / span);
      }
      last = ts;
      draw();
    }
    window.requestAnimationFrame(frame);
  }
  draw();
  window.requestAnimationFrame(frame);
})();
</script>
</body>
</html>
"""


# ---------------------------------------------------------------------------
# GIF / MP4
# ---------------------------------------------------------------------------
class GifStreamWriter:
    """Write a GIF frame by frame as the frames are drawn: memory bounded by one frame, whatever their number.

    matplotlib's ``PillowWriter`` keeps every frame (as RGBA) until the end
    and hands them to Pillow at once: 600 frames of 640×480 took 1 GB. Here
    every frame is quantized to its own palette of at most 256 colours
    (Pillow's fast octree; no dithering) and written at once, cropped to the
    rectangle where it differs from the previous frame; a frame identical to
    the previous one lengthens the previous one's display time instead. The
    file is a GIF89a that loops forever, with a local colour table per frame.
    Only the previous frame (as one 32-bit word per pixel, to compare the
    next one quickly) and the one waiting to be written are kept.

    The interface is that of a matplotlib movie writer: ``with
    writer.saving(fig, path, dpi): ... writer.grab_frame()``; a frame already
    drawn (a canvas buffer, RGB or RGBA) is given to :meth:`add_frame`.
    """

    def __init__(self, fps):
        self.fps = float(fps)
        self._fh: BinaryIO | None = None  # the open file, from setup() to finish()

    @contextlib.contextmanager
    def saving(self, fig, outfile, dpi):
        self.setup(fig, outfile, dpi)
        try:
            yield self
        finally:
            self.finish()

    def setup(self, fig, outfile, dpi):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.fig = fig
        if not isinstance(fig.canvas, FigureCanvasAgg):
            FigureCanvasAgg(fig)
        fig.set_dpi(dpi)
        self._fh = open(outfile, "wb")
        self._prev: np.ndarray | None = None  # the previous frame, one uint32 per pixel (see _key)
        # (P image, offset, duration in ms): written when the next frame differs
        self._pending: tuple[Any, tuple[int, int], float] | None = None
        self._size: tuple[int, int] | None = None
        self.frames = 0

    def _header(self, w, h) -> bytes:
        import struct

        # logical screen without a global colour table (every frame has its own), then the loop extension
        return (
            b"GIF89a"
            + struct.pack("<HHBBB", w, h, 0, 0, 0)
            + b"!\xff\x0bNETSCAPE2.0\x03\x01"
            + struct.pack("<H", 0)
            + b"\x00"
        )

    def grab_frame(self, **savefig_kwargs):
        self.fig.canvas.draw()
        self.add_frame(np.asarray(self.fig.canvas.buffer_rgba()))

    @staticmethod
    def _key(a) -> np.ndarray:
        """One uint32 per pixel holding its red, green and blue bytes (alpha left out), to compare frames."""
        if a.shape[2] == 4:  # RGBA (a canvas buffer): the pixels as little-endian words, alpha masked
            return np.ascontiguousarray(a).view("<u4")[..., 0] & np.uint32(0xFFFFFF)
        r, g, b = (a[..., i].astype(np.uint32) for i in range(3))
        return r | (g << np.uint32(8)) | (b << np.uint32(16))

    def add_frame(self, rgb) -> None:
        """Add one frame, an (h, w, 3) RGB or (h, w, 4) RGBA uint8 array (alpha is ignored).

        Raises
        ------
        InvalidInputError
            ``rgb`` is not of shape (h, w, 3) or (h, w, 4), or its size differs
            from the first frame's.
        """
        from PIL import Image

        a = np.asarray(rgb)
        if a.ndim != 3 or a.shape[2] not in (3, 4):
            raise InvalidInputError(f"rgb must be an (h, w, 3) RGB or (h, w, 4) RGBA array, got shape {a.shape}")
        if a.dtype != np.uint8:
            a = a.astype(np.uint8)
        h, w = a.shape[:2]
        duration = 1000.0 / self.fps
        assert self._fh is not None, "add_frame() after setup()"
        key = self._key(a)
        if self._size is None:
            self._size = (w, h)
            self._fh.write(self._header(w, h))
            box = (0, 0, w, h)
        else:
            if (w, h) != self._size:
                raise InvalidInputError(f"GIF frames must all have the size {self._size}, got {(w, h)}")
            diff = key != self._prev
            rows = np.flatnonzero(diff.any(axis=1))
            if rows.size == 0:  # the same picture: show the previous frame longer
                assert self._pending is not None  # a frame was added before
                im, off, d = self._pending
                self._pending = (im, off, d + duration)
                return
            cols = np.flatnonzero(diff[rows[0] : rows[-1] + 1].any(axis=0))
            box = (int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1)
        self._flush()
        # only the changed rectangle is copied, quantized and encoded
        part = Image.fromarray(np.ascontiguousarray(a[box[1] : box[3], box[0] : box[2], :3]), "RGB")
        pim = part.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        self._pending = (pim, box[:2], duration)
        self._prev = key  # a new array, not a view of the caller's buffer
        self.frames += 1

    def _flush(self) -> None:
        from PIL import GifImagePlugin

        if self._pending is None:
            return
        assert self._fh is not None  # frames pending: the file is open
        im, off, d = self._pending
        for part in GifImagePlugin.getdata(im, offset=off, duration=int(round(d)), include_color_table=True):
            self._fh.write(part)
        self._pending = None

    def finish(self):
        if self._fh is None:
            return
        try:
            self._flush()
            self._fh.write(b";")
        finally:
            self._fh.close()
            self._fh = None


class _FfmpegStreamWriter:
    """Pipe raw RGBA frames to the ``ffmpeg`` program (H.264, yuv420p), as matplotlib's ``FFMpegWriter`` does.

    The frames come from a canvas buffer the caller has already drawn
    (:meth:`add_frame`), so no figure is redrawn or saved per frame. The
    program is the one matplotlib uses (``rcParams["animation.ffmpeg_path"]``).
    """

    def __init__(self, fps, binary):
        self.fps = float(fps)
        self.binary = str(binary)
        self._proc: Any = None
        self._err: Any = None
        self._size: tuple[int, int] | None = None
        self.frames = 0

    def args(self, outfile, w, h) -> list[str]:
        """The ffmpeg command line (that of matplotlib's writer) for ``w`` x ``h`` frames written to ``outfile``."""
        frames_in = ["-f", "rawvideo", "-vcodec", "rawvideo", "-s", f"{w}x{h}", "-pix_fmt", "rgba"]
        video_out = ["-vcodec", "libx264", "-pix_fmt", "yuv420p", "-y", str(outfile)]
        return [self.binary, *frames_in, "-framerate", str(self.fps), "-loglevel", "error", "-i", "pipe:", *video_out]

    @contextlib.contextmanager
    def saving(self, fig, outfile, dpi):
        self.setup(fig, outfile, dpi)
        ok = False
        try:
            yield self
            ok = True
        finally:
            self.finish(check=ok)

    def setup(self, fig, outfile, dpi):
        import subprocess
        import tempfile

        fig.set_dpi(dpi)
        w, h = (int(round(v)) for v in fig.get_size_inches() * dpi)
        self._size = (w, h)
        self._err = tempfile.TemporaryFile()  # a file, not a pipe: ffmpeg never blocks on a full stderr pipe
        self._proc = subprocess.Popen(
            self.args(outfile, w, h), stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=self._err
        )
        self.frames = 0

    def add_frame(self, rgba) -> None:
        """Add one frame, an (h, w, 4) uint8 RGBA array."""
        a = np.ascontiguousarray(rgba, dtype=np.uint8)
        assert self._proc is not None and self._size is not None, "add_frame() after setup()"
        want = (self._size[1], self._size[0], 4)
        if a.shape != want:
            raise InvalidInputError(f"rgba must be an RGBA frame of shape (h, w, 4) = {want}, got shape {a.shape}")
        try:
            self._proc.stdin.write(a.data)
        except BrokenPipeError:  # ffmpeg stopped: finish() reports why
            self.finish(check=True)
            raise
        self.frames += 1

    def finish(self, check=True):
        import subprocess

        if self._proc is None:
            return
        proc, self._proc = self._proc, None
        with contextlib.suppress(BrokenPipeError):
            proc.stdin.close()
        rc = proc.wait()
        self._err.seek(0)
        err = self._err.read().decode("utf-8", "replace")
        self._err.close()
        if check and rc:
            raise subprocess.CalledProcessError(rc, proc.args, None, err)


def _writer(ext, fps):
    if ext == "gif":
        return GifStreamWriter(fps=fps)
    import matplotlib
    from matplotlib import animation

    if not animation.FFMpegWriter.isAvailable():
        path = matplotlib.rcParams["animation.ffmpeg_path"]
        found = shutil.which(path)
        raise MissingDependencyError(
            f"writing .mp4 needs the ffmpeg program, which was not found (matplotlib looks for {path!r}"
            f"{'' if found is None else ' at ' + found}); install ffmpeg (e.g. 'apt-get install ffmpeg' or "
            "'conda install ffmpeg') or write .html or .gif instead"
        )
    return _FfmpegStreamWriter(fps, animation.FFMpegWriter.bin_path())


def _ortho_projection(fig, rect, lim, view):
    """Where matplotlib's orthographic 3-D axes in ``rect`` puts space points: a fixed affine map.

    The axes has the cube ``[-lim, lim]^3`` with equal box aspect (zoom 1.35)
    seen from ``view`` = (azimuth, elevation). Returns ``(position, xlim, ylim,
    M)``: the axes' active position (a square in pixels), the limits of its 2-D
    data coordinates, and its projection matrix ``M`` (4, 4), whose last row is
    (0, 0, 0, w): see :func:`_project`. The 3-D axes is removed afterwards.
    """
    ax3 = fig.add_axes(rect, projection="3d")
    try:
        ax3.set_proj_type("ortho")
        ax3.set_xlim(-lim, lim)
        ax3.set_ylim(-lim, lim)
        ax3.set_zlim(-lim, lim)
        try:
            ax3.set_box_aspect((1, 1, 1), zoom=1.35)
        except TypeError:  # pragma: no cover - matplotlib < 3.7
            ax3.set_box_aspect((1, 1, 1))
        ax3.view_init(elev=view[1], azim=view[0])
        ax3.apply_aspect()
        M = np.asarray(ax3.get_proj(), float)
        position = ax3.get_position(original=False).frozen()
        xlim, ylim = tuple(ax3.viewLim.intervalx), tuple(ax3.viewLim.intervaly)
    finally:
        ax3.remove()
    assert np.allclose(M[3, :3], 0.0, atol=1e-12 * abs(M[3, 3])), "an orthographic projection is affine"
    return position, xlim, ylim, M


def _project(M, X) -> np.ndarray:
    """(x2, y2, depth) of the space points ``X`` (..., 3), computed as matplotlib's 3-D axes does; depth grows away."""
    X = np.asarray(X, float)
    vec = np.vstack([X.reshape(-1, 3).T, np.ones(X[..., 0].size)])
    product = np.dot(M, vec)
    return (product[:3] / product[3]).T.reshape(X.shape)


def _render_video(one, sides, verts, faces, mdir, tf, qf, out, ext, fps, px):
    """Render the frames of a GIF/MP4 and stream them to the writer.

    The view is fixed and orthographic, so matplotlib's 3-D projection is a
    fixed affine map (:func:`_ortho_projection`): the box is drawn on a plain
    2-D axes as polygons in painter's order (far faces first), the space axes
    and m as polylines whose pieces hidden by the box are gaps, exactly where
    the 3-D axes drew them. What never changes (white, axis letters, title) is
    drawn once and blitted; each frame draws the faces, the lines, the tip, the
    'm' label and the time text, and hands the canvas buffer to the writer.
    The tip and the 'm' label, when they lie outside the region the box can
    cover, look the same in every frame: their pixels are copied from the
    first frame instead of drawn again.
    """
    mpl = import_matplotlib()
    writer = _writer(ext, fps)  # fail early when ffmpeg is missing
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.figure import Figure
    from matplotlib.transforms import Bbox

    from ..attitude.core import matrix_from_unit_quaternion

    w, h = px
    if ext == "mp4":  # yuv420p needs even sizes
        w, h = w + w % 2, h + h % 2
    dpi = 100
    R0 = float(np.max(np.linalg.norm(verts, axis=1)))
    arrow = 1.6 * R0
    lim = 0.9 * max(arrow, 1.2 * R0)
    light = np.array([0.25, 0.6, 0.75])
    light /= np.linalg.norm(light)
    base = np.array([_face_rgb(a, s) for _, _, a, s in faces], float) / 255.0
    normals = np.array([nrm for _, nrm, _, _ in faces])
    fidx = np.array([idx for idx, *_ in faces])  # (6, 4) vertex indices
    view = _view(mdir)
    cam = _camera(view)
    towards_viewer = cam[2]
    half = 0.5 * sides
    pieces = np.linspace(0.0, 1.0, 121)
    mid = 0.5 * (pieces[1:] + pieces[:-1])
    # straight lines drawn in pieces; pieces hidden by the box become NaN (gaps)
    lines = [(-np.eye(3)[i] * lim, np.eye(3)[i] * lim, "#c3c7cd", 0.8) for i in range(3)]
    if mdir is not None:
        lines.append((np.zeros(3), arrow * mdir, "#111111", 2.2))
    # the midpoints of all pieces (and the tip last): one occlusion test per frame
    probe = np.concatenate([a + mid[:, None] * (b - a) for a, b, _, _ in lines] + [np.zeros((0, 3))])
    if mdir is not None:
        probe = np.concatenate([probe, (arrow * mdir)[None]])
    with mpl.rc_context({"font.size": 10}):
        fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi, layout="none")  # type: ignore[arg-type]  # "none" is documented
        canvas = FigureCanvasAgg(fig)
        fig.patch.set_facecolor("white")
        position, xlim, ylim, M = _ortho_projection(fig, [0.0, 0.0, 1.0, 0.9], lim, view)
        ax = fig.add_axes(position)
        ax.set_axis_off()
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        for i in range(3):
            x2, y2, _ = _project(M, 1.05 * np.eye(3)[i] * lim)
            ax.text(x2, y2, "xyz"[i], color="#888888", ha="center", va="center", zorder=0)
        coll = PolyCollection([], zorder=1, linewidths=0.6, animated=True)
        ax.add_collection(coll, autolim=False)
        artists, line_xy = [], []
        for a, b, color, lw in lines:
            (ln,) = ax.plot([], [], color=color, lw=lw, zorder=2, solid_capstyle="butt", animated=True)
            artists.append(ln)
            line_xy.append(_project(M, a + pieces[:, None] * (b - a))[:, :2])
        on_top = []  # drawn after the faces and lines
        if mdir is not None:
            tx, ty, _ = _project(M, arrow * mdir)
            tip = ax.scatter([tx], [ty], color="#111111", marker="o", s=16, zorder=3, animated=True)
            lx, ly, _ = _project(M, 1.04 * arrow * mdir + 0.1 * lim * cam[1])
            mlabel = ax.text(
                lx, ly, "m", color="#111111", zorder=3, ha="center", va="center", fontsize=11, animated=True
            )
            on_top = [tip, mlabel]
        # names are text: no mathtext ($...$ in a body name is drawn as typed)
        title = fig.text(0.5, 0.965, plain_text(one.label + " — " + one.method), ha="center", va="center", fontsize=10)
        ttext = fig.text(0.5, 0.925, "", ha="center", va="center", fontsize=9, color="#444444", animated=True)
        last = [ttext]  # drawn after everything else
        Rf = matrix_from_unit_quaternion(qf)
        with atomic_path(out, suffix="." + ext) as tmp:
            with writer.saving(fig, tmp, dpi):
                renderer = canvas.get_renderer()
                # the title is drawn after the axes: where it may overlap what moves (clipped to the axes) or
                # the 'm' label, it is drawn again in every frame
                tb = title.get_window_extent(renderer).padded(2)
                if tb.overlaps(ax.bbox) or (on_top and tb.overlaps(mlabel.get_window_extent(renderer))):
                    title.set_animated(True)
                    last.insert(0, title)
                canvas.draw()  # the background: what does not move (animated artists are left out)
                background = canvas.copy_from_bbox(fig.bbox)
                renderer = canvas.get_renderer()
                # the pixels the box can reach in some frame, with its gaps in the lines: the disc of the sphere
                # of radius R0 around the centre, widened by a line width, a piece's length and antialiasing
                J = ax.transData.get_affine().get_matrix()[:2, :2] @ (M[:2, :3] / M[3, 3])  # space -> pixels
                centre = ax.transData.transform(_project(M, np.zeros(3))[:2])
                piece = max(np.linalg.norm(J @ (b - a)) for a, b, _, _ in lines) / (len(pieces) - 1)
                reach = R0 * np.linalg.norm(J, 2) + 3.0 + 2.2 * dpi / 72.0 + piece
                ttext.set_text(plain_text(f"t = {tf[0]:.2f} {one.time_unit}"))
                band = ttext.get_window_extent(renderer)  # the time text's width changes: its whole row
                busy = [Bbox.from_extents(0, band.y0 - 3, w, band.y1 + 3)]
                busy += [a.get_window_extent(renderer).padded(3) for a in last[:-1]]
                frozen = {}  # artist -> its bbox, for those whose pixels are those of the first frame
                for artist in on_top:
                    if artist is tip:  # a marker of area s (points^2) with its edge, around its centre
                        mx, my = ax.transData.transform((tx, ty))
                        edge = float(np.atleast_1d(tip.get_linewidth())[0])
                        r = (0.5 * np.sqrt(tip.get_sizes()[0]) + 0.5 * edge) * dpi / 72.0
                        ext = Bbox.from_extents(mx - r, my - r, mx + r, my + r)
                    else:
                        ext = artist.get_window_extent(renderer)
                    bb = Bbox.intersection(ext.padded(3), fig.bbox)
                    if bb is None:
                        continue
                    near = np.clip(centre, bb.min, bb.max)  # the point of bb nearest to the centre
                    if np.hypot(*(near - centre)) > reach and not any(bb.overlaps(b) for b in busy):
                        frozen[artist] = bb
                snapshots = []
                for k in range(len(tf)):
                    Rk = Rf[k]
                    V = verts @ Rk.T
                    N = normals @ Rk.T
                    lam = np.clip((N @ cam.T) @ light, 0.0, None)
                    shade = (0.5 + 0.5 * lam)[:, None]
                    fc = np.clip(base * shade, 0, 1)
                    pv = _project(M, V)  # (8, 3): x2, y2, depth (growing away from the viewer)
                    order = np.argsort(pv[fidx, 2].mean(axis=1))[::-1]  # painter's order: far faces first
                    coll.set_verts(pv[fidx[order], :2])  # type: ignore[arg-type]  # a (6, 4, 2) array, as mplot3d
                    coll.set_facecolor(fc[order])
                    coll.set_edgecolor(fc[order] * 0.55)
                    hid = hidden_by_box(probe, Rk, half, one.axes, towards_viewer, orthographic=True)
                    for i, (xy, ln) in enumerate(zip(line_xy, artists)):
                        h_i = hid[i * len(mid) : (i + 1) * len(mid)]
                        # a point is kept when one of its two pieces is visible
                        keep = np.zeros(len(xy), bool)
                        keep[:-1] |= ~h_i
                        keep[1:] |= ~h_i
                        xyn = np.where(keep[:, None], xy, np.nan)
                        ln.set_data(xyn[:, 0], xyn[:, 1])
                    if on_top:
                        tip.set_visible(not hid[-1])
                    ttext.set_text(plain_text(f"t = {tf[k]:.2f} {one.time_unit}"))
                    canvas.restore_region(background)
                    coll.draw(renderer)
                    for ln in artists:
                        ln.draw(renderer)
                    for artist in on_top:
                        if k == 0 or artist not in frozen:
                            artist.draw(renderer)
                    if k == 0:
                        snapshots = [canvas.copy_from_bbox(bb) for bb in frozen.values()]
                    for region in snapshots:
                        canvas.restore_region(region)
                    for artist in last:
                        artist.draw(renderer)
                    writer.add_frame(np.asarray(canvas.buffer_rgba()))
    return out
