"""GIF/MP4 frames of ``animate``: the blitted 2-D renderer draws what matplotlib's 3-D axes drew.

The frames were drawn on an orthographic ``Axes3D`` (every artist redrawn
each frame); they are now drawn on a 2-D axes through the same fixed
projection, with a background blitted once. The reference here is the 3-D drawing itself (the renderer as it was), frame by
frame; the GIF writer compares frames as 32-bit words; the MP4 path pipes
the same canvas buffer to ``ffmpeg`` (a stand-in program records what it is
given).
"""

import json
import os
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

matplotlib = pytest.importorskip("matplotlib")
pytest.importorskip("PIL")

from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.errors import InvalidInputError  # noqa: E402
from eulerpoisson.viz import animate as an  # noqa: E402
from eulerpoisson.viz.plots import plain_text, select_body  # noqa: E402


# ---------------------------------------------------------------------------
# the reference: the box drawn by matplotlib's 3-D axes, every artist redrawn each frame
# ---------------------------------------------------------------------------
def _reference_frames(tr, fps, duration, size):
    """The RGB frames as the former renderer drew them (Axes3D, Poly3DCollection, Line3D, scatter, Text3D)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from eulerpoisson.attitude.core import matrix_from_unit_quaternion

    one = select_body(tr, 0)
    sides, verts, faces = an._box_mesh(one.moments, one.axes)
    m0 = one.m[one.first]
    mdir = m0 / np.linalg.norm(m0) if np.linalg.norm(m0) > 0 else None
    n = max(2, int(round(fps * duration)))
    tf = np.linspace(one.t[0], one.t[-1], n)
    Rf = matrix_from_unit_quaternion(an.slerp_series(one.t, one.q, tf))
    w, h = size
    R0 = float(np.max(np.linalg.norm(verts, axis=1)))
    arrow, lim = 1.6 * R0, 0.9 * max(1.6 * R0, 1.2 * R0)
    light = np.array([0.25, 0.6, 0.75]) / np.linalg.norm([0.25, 0.6, 0.75])
    base = np.array([an._face_rgb(a, s) for _, _, a, s in faces], float) / 255.0
    normals = np.array([nrm for _, nrm, _, _ in faces])
    view = an._view(mdir)
    cam = an._camera(view)
    pieces = np.linspace(0.0, 1.0, 121)
    mid = 0.5 * (pieces[1:] + pieces[:-1])
    lines = [(-np.eye(3)[i] * lim, np.eye(3)[i] * lim, "#c3c7cd", 0.8) for i in range(3)]
    if mdir is not None:
        lines.append((np.zeros(3), arrow * mdir, "#111111", 2.2))
    out = []
    with matplotlib.rc_context({"font.size": 10}):
        fig = Figure(figsize=(w / 100, h / 100), dpi=100, layout="none")
        FigureCanvasAgg(fig)
        fig.patch.set_facecolor("white")
        ax = fig.add_axes([0.0, 0.0, 1.0, 0.9], projection="3d")
        ax.set_axis_off()
        ax.set_proj_type("ortho")
        ax.computed_zorder = False
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_zlim(-lim, lim)
        ax.set_box_aspect((1, 1, 1), zoom=1.35)
        ax.view_init(elev=view[1], azim=view[0])
        for i in range(3):
            ax.text(*(1.05 * np.eye(3)[i] * lim), "xyz"[i], color="#888888", ha="center", va="center", zorder=0)
        coll = Poly3DCollection([verts[idx] for idx, *_ in faces], zorder=1, linewidths=0.6)
        ax.add_collection3d(coll)
        arts = [ax.plot([], [], [], color=c, lw=lw, zorder=2, solid_capstyle="butt")[0] for _, _, c, lw in lines]
        tip = None
        if mdir is not None:
            tip = ax.scatter(*(arrow * mdir[:, None]), color="#111111", marker="o", s=16, zorder=3, depthshade=False)
            mpos = 1.04 * arrow * mdir + 0.1 * lim * cam[1]
            ax.text(*mpos, "m", color="#111111", zorder=3, ha="center", va="center", fontsize=11)
        fig.text(0.5, 0.965, plain_text(one.label + " — " + one.method), ha="center", va="center", fontsize=10)
        ttext = fig.text(0.5, 0.925, "", ha="center", va="center", fontsize=9, color="#444444")
        for k in range(n):
            R = Rf[k]
            V = verts @ R.T
            fc = np.clip(base * (0.5 + 0.5 * np.clip((normals @ R.T @ cam.T) @ light, 0, None))[:, None], 0, 1)
            coll.set_verts([V[idx] for idx, *_ in faces])
            coll.set_facecolor(fc)
            coll.set_edgecolor(fc * 0.55)
            for (a, b, _, _), ln in zip(lines, arts):
                P = a + pieces[:, None] * (b - a)
                hid = an.hidden_by_box(a + mid[:, None] * (b - a), R, 0.5 * sides, one.axes, cam[2], orthographic=True)
                keep = np.zeros(len(P), bool)
                keep[:-1] |= ~hid
                keep[1:] |= ~hid
                Pn = np.where(keep[:, None], P, np.nan)
                ln.set_data_3d(Pn[:, 0], Pn[:, 1], Pn[:, 2])
            if tip is not None:
                hid = an.hidden_by_box((arrow * mdir)[None], R, 0.5 * sides, one.axes, cam[2], orthographic=True)
                tip.set_visible(not hid[0])
            ttext.set_text(plain_text(f"t = {tf[k]:.2f} {one.time_unit}"))
            fig.canvas.draw()
            out.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
    return out


def _new_frames(tr, folder, **kw):
    """The frames ``animate`` hands to the GIF writer (RGBA canvas buffers), as RGB copies."""
    got = []
    add = an.GifStreamWriter.add_frame

    def capture(self, rgb):
        got.append(np.array(np.asarray(rgb)[..., :3]))
        return add(self, rgb)

    an.GifStreamWriter.add_frame = capture
    try:
        an.animate(tr, Path(folder) / "f.gif", **kw)
    finally:
        an.GifStreamWriter.add_frame = add
    return got


def _assert_same_pictures(new, ref):
    assert len(new) == len(ref)
    for k, (a, b) in enumerate(zip(new, ref)):
        assert a.shape == b.shape
        d = np.abs(a.astype(int) - b.astype(int)).max(axis=2)
        # the same float operations: identical pixels; a rounding of a coordinate may move one antialiased
        # pixel by a level or two, a missing or misplaced artist changes many by far more
        assert np.count_nonzero(d > 2) == 0, f"frame {k}: {np.count_nonzero(d > 2)} pixels differ, by up to {d.max()}"
        assert d.mean() < 0.01, f"frame {k}: mean difference {d.mean()}"


LONG_NAME = "gjpqy" * 20  # the descenders of the title reach into the axes and over the z axis
CASES = {
    "racket": ([3.0, 5.0, 7.0], [0.0, 0.4, 0.01 / 7], 150.0, "", (160, 120)),
    "m vertical": ([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], 50.0, "", (200, 150)),
    "m = 0": ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0], 5.0, "", (120, 90)),
    "low, a title over the axes": ([1.0, 2.0, 2.5], [0.3, 2.0, 0.1], 30.0, LONG_NAME, (100, 30)),
    "wide": ([3.0, 5.0, 7.0], [1.0, 0.1, 0.5], 60.0, "", (300, 80)),
    "tiny": ([1.0, 2.0, 2.5], [0.3, 2.0, 0.1], 30.0, "", (48, 40)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_frames_are_those_of_the_3d_axes(case, tmp_path):
    moments, omega0, span, name, size = CASES[case]
    body = ep.RigidBody(moments, name=name) if name else moments
    tr = ep.solve(body, np.linspace(0.0, span, 301), omega0=omega0)
    new = _new_frames(tr, tmp_path, fps=4, duration=1.5, size=size)
    _assert_same_pictures(new, _reference_frames(tr, 4, 1.5, size))


@settings(max_examples=6, deadline=None)
@given(
    moments=st.tuples(*[st.floats(1.0, 3.0)] * 3).filter(lambda I: max(I) <= sum(I) - max(I)),
    omega0=st.tuples(*[st.floats(-1.0, 1.0)] * 3),
    size=st.tuples(st.integers(48, 260), st.integers(40, 200)),
)
def test_frames_are_those_of_the_3d_axes_for_any_body(moments, omega0, size):
    tr = ep.solve(list(moments), np.linspace(0.0, 20.0, 101), omega0=list(omega0))
    with tempfile.TemporaryDirectory() as tmp:
        new = _new_frames(tr, tmp, fps=2, duration=1.0, size=size)
    _assert_same_pictures(new, _reference_frames(tr, 2, 1.0, size))


def test_the_comparison_sees_a_box_two_percent_too_wide(monkeypatch, tmp_path):
    """The comparison can fail: a projection that widens the picture by 2 % is seen."""
    tr = ep.solve([3.0, 5.0, 7.0], np.linspace(0.0, 30.0, 301), omega0=[0.0, 0.4, 0.01 / 7])
    project = an._project
    monkeypatch.setattr(an, "_project", lambda M, X: project(M, X) * [1.02, 1.0, 1.0])
    new = _new_frames(tr, tmp_path, fps=2, duration=1.0, size=(160, 120))
    with pytest.raises(AssertionError, match="pixels differ"):
        _assert_same_pictures(new, _reference_frames(tr, 2, 1.0, (160, 120)))


# ---------------------------------------------------------------------------
# the GIF writer: frames compared as words, RGB or RGBA
# ---------------------------------------------------------------------------
def _gif_frames(path):
    im = Image.open(path)
    out = []
    for k in range(im.n_frames):
        im.seek(k)
        out.append((im.tile[0][1], im.info["duration"], np.asarray(im.convert("RGB"))))
    return out


def test_gif_writer_sees_a_change_of_any_channel_and_ignores_alpha(tmp_path):
    f0 = np.full((30, 40, 4), 255, np.uint8)
    f0[5:9, 6:12, :3] = (31, 119, 180)
    frames = [f0]
    for ch, (y, x) in zip(range(3), [(2, 3), (20, 30), (29, 39)]):  # one level of one channel of one pixel
        f = frames[-1].copy()
        f[y, x, ch] -= 1
        frames.append(f)
    alpha = frames[-1].copy()
    alpha[..., 3] = 7  # only alpha differs: the same picture
    frames.append(alpha)
    wr = an.GifStreamWriter(fps=10)
    fig = Figure(figsize=(0.4, 0.3))
    with wr.saving(fig, tmp_path / "c.gif", 100):
        for f in frames:
            wr.add_frame(f)
    got = _gif_frames(tmp_path / "c.gif")
    assert [g[0] for g in got] == [(0, 0, 40, 30), (3, 2, 4, 3), (30, 20, 31, 21), (39, 29, 40, 30)]
    assert [g[1] for g in got] == [100, 100, 100, 200]
    np.testing.assert_array_equal(got[-1][2], frames[-1][..., :3])  # few colours: exact


def test_gif_writer_rgb_and_rgba_give_the_same_file(tmp_path):
    rng = np.random.default_rng(3)
    frames = []
    for k in range(5):
        f = np.full((24, 32, 3), 255, np.uint8)
        f[4 + k : 12 + k, 3:20] = rng.integers(0, 256, 3)
        frames.append(f)
    frames.insert(2, frames[1].copy())
    fig = Figure(figsize=(0.32, 0.24))
    for name, conv in (("rgb", lambda f: f), ("rgba", lambda f: np.dstack([f, np.full(f.shape[:2], 255, np.uint8)]))):
        wr = an.GifStreamWriter(fps=20)
        with wr.saving(fig, tmp_path / f"{name}.gif", 100):
            for f in frames:
                wr.add_frame(conv(f))
        assert wr.frames == 5
    assert (tmp_path / "rgb.gif").read_bytes() == (tmp_path / "rgba.gif").read_bytes()
    got = _gif_frames(tmp_path / "rgb.gif")
    for (_, _, g), f in zip(got, [frames[0], frames[1], *frames[3:]]):
        np.testing.assert_array_equal(g, f)


def test_gif_writer_refuses_a_frame_that_is_not_an_image(tmp_path):
    wr = an.GifStreamWriter(fps=20)
    fig = Figure(figsize=(0.32, 0.24))
    with wr.saving(fig, tmp_path / "e.gif", 100):
        for bad in (np.zeros((24, 32)), np.zeros((24, 32, 2), np.uint8)):
            with pytest.raises(InvalidInputError, match=r"rgb must be an \(h, w, 3\) RGB or \(h, w, 4\) RGBA array"):
                wr.add_frame(bad)
        wr.add_frame(np.zeros((24, 32, 3), np.uint8))
        with pytest.raises(InvalidInputError, match=r"GIF frames must all have the size \(32, 24\), got \(31, 24\)"):
            wr.add_frame(np.zeros((24, 31, 4), np.uint8))


# ---------------------------------------------------------------------------
# MP4: the canvas buffers piped to ffmpeg (a stand-in program records them)
# ---------------------------------------------------------------------------
FAKE_FFMPEG = """#!{python}
import json, sys
args = sys.argv[1:]
if {fail!r}:
    sys.stderr.write("fake ffmpeg: cannot encode\\n")
    sys.exit(3)
data = sys.stdin.buffer.read()
with open(args[-1], "wb") as fh:
    fh.write(json.dumps(args).encode() + b"\\n" + data)
"""


def _fake_ffmpeg(tmp_path, monkeypatch, fail=False):
    path = tmp_path / ("ffmpeg-fails" if fail else "ffmpeg-fake")
    path.write_text(FAKE_FFMPEG.format(python=sys.executable, fail=fail))
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setitem(matplotlib.rcParams, "animation.ffmpeg_path", str(path))
    return path


def test_mp4_pipes_the_frames_of_the_gif_to_ffmpeg(tmp_path, monkeypatch):
    tr = ep.solve([3.0, 5.0, 7.0], np.linspace(0.0, 30.0, 301), omega0=[0.0, 0.4, 0.01 / 7])
    gif_frames = _new_frames(tr, tmp_path, fps=5, duration=1.2, size=(162, 120))
    fake = _fake_ffmpeg(tmp_path, monkeypatch)
    out = an.animate(tr, tmp_path / "a.mp4", fps=5, duration=1.2, size=(161, 119))  # odd: made even
    head, _, data = out.read_bytes().partition(b"\n")
    args = json.loads(head)
    assert args[-2:] == ["-y", args[-1]] and args[-1].endswith(".mp4") and os.path.basename(args[-1]) != "a.mp4"
    want = ["-f", "rawvideo", "-vcodec", "rawvideo", "-s", "162x120", "-pix_fmt", "rgba", "-framerate", "5.0"]
    assert args[: len(want)] == want
    assert args[args.index("-i") + 1] == "pipe:"
    assert args[args.index("-i") + 2 :][:4] == ["-vcodec", "libx264", "-pix_fmt", "yuv420p"]
    frames = np.frombuffer(data, np.uint8).reshape(-1, 120, 162, 4)
    assert len(frames) == len(gif_frames) == 6 and (frames[..., 3] == 255).all()
    for got, want_rgb in zip(frames, gif_frames):
        np.testing.assert_array_equal(got[..., :3], want_rgb)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["a.mp4", "f.gif", fake.name])


def test_mp4_reports_a_failing_ffmpeg_and_leaves_no_file(tmp_path, monkeypatch):
    tr = ep.solve([3.0, 5.0, 7.0], np.linspace(0.0, 30.0, 301), omega0=[0.0, 0.4, 0.01 / 7])
    fake = _fake_ffmpeg(tmp_path, monkeypatch, fail=True)
    with pytest.raises(subprocess.CalledProcessError) as err:
        an.animate(tr, tmp_path / "a.mp4", fps=5, duration=4, size=(160, 120))
    assert err.value.returncode == 3 and "cannot encode" in err.value.stderr
    assert [p.name for p in tmp_path.iterdir()] == [fake.name]


def test_gif_writer_grab_frame_draws_the_figure(tmp_path):
    """``grab_frame`` (the matplotlib movie-writer interface) draws the figure and adds its buffer."""
    fig = Figure(figsize=(0.64, 0.48), dpi=100)
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_axis_off()
    (ln,) = ax.plot([0, 1], [0, 1], color="#d62728", lw=3)
    wr = an.GifStreamWriter(fps=10)
    with wr.saving(fig, tmp_path / "g.gif", 100):
        wr.grab_frame()
        ln.set_ydata([1, 0])
        wr.grab_frame()
        drawn = np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()
    got = _gif_frames(tmp_path / "g.gif")
    assert len(got) == 2 and got[0][2].shape == (48, 64, 3)
    assert np.mean(np.abs(got[1][2].astype(int) - drawn.astype(int))) < 2.0  # quantized to 256 colours
    assert np.mean(np.abs(got[0][2].astype(int) - got[1][2].astype(int))) > 5.0
