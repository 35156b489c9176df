"""Tests of eulerpoisson.viz.animate: box geometry, slerp, occlusion, the HTML page (also in headless Chromium), GIF/MP4."""

import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")

from _reference import reference_motion  # noqa: E402
from eulerpoisson.errors import InvalidInputError, MissingDependencyError  # noqa: E402
from eulerpoisson.model.body import RigidBody  # noqa: E402
from eulerpoisson.trajectory import Trajectory  # noqa: E402
from eulerpoisson.viz import animate as an  # noqa: E402

RACKET_I = np.array([3.0, 5.0, 7.0])


@pytest.fixture(scope="module")
def racket():
    """The tennis racket (M0 = (0, 2, 0.01)) by an independent DOP853 integration."""
    t = np.linspace(0.0, 150.0, 751)
    q, w = reference_motion(RACKET_I, [0.0, 0.4, 0.01 / 7.0], np.array([1.0, 0, 0, 0]), t, rtol=1e-10, atol=1e-12)
    return Trajectory(t, q, w, RigidBody(RACKET_I, name="tennis racket"), method="dop853-reference")


def _page_data(text):
    m = re.search(r'<script type="application/json" id="ep-data">(.*?)</script>', text, re.S)
    assert m, "no embedded data"
    return json.loads(m.group(1))


def _face_pixel_fraction(img, region=None):
    """Fraction of pixels whose colour is a shaded face colour k * base, k in [0.45, 1.05]."""
    rgb = np.asarray(img, float)[..., :3]
    if rgb.max() <= 1.0:
        rgb = rgb * 255.0
    if region is not None:
        rgb = rgb[region]
    px = rgb.reshape(-1, 3)
    hit = np.zeros(len(px), bool)
    for axis in range(3):
        for sign in (1, -1):
            b = np.array(an._face_rgb(axis, sign), float)
            k = px @ b / (b @ b)
            res = np.linalg.norm(px - k[:, None] * b, axis=1)
            hit |= (res < 12.0) & (k > 0.45) & (k < 1.05)
    return hit.mean()


# ---------------------------------------------------------------------------
# geometry
# ---------------------------------------------------------------------------
def test_box_dimensions_inverts_box_moments(rng):
    for _ in range(20):
        sides = rng.uniform(0.2, 3.0, 3)
        a, b, c = sides
        mass = rng.uniform(0.5, 4.0)
        I = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])  # uniform box
        np.testing.assert_allclose(an.box_dimensions(I, min_thickness=0), sides / sides.max(), rtol=1e-12)
    # a planar body (I1 + I2 = I3) has zero thickness: raised to the minimum
    # a_i^2 proportional to I_j + I_k - I_i = (4, 2, 0)
    np.testing.assert_allclose(an.box_dimensions([1.0, 2.0, 3.0]), [1, 1 / np.sqrt(2), an.MIN_THICKNESS], rtol=1e-12)
    np.testing.assert_allclose(an.box_dimensions([2.0, 2.0, 2.0]), [1, 1, 1])


def test_box_dimensions_errors():
    with pytest.raises(InvalidInputError, match=r"moments must have shape \(3,\)"):
        an.box_dimensions([1.0, 2.0])
    with pytest.raises(InvalidInputError, match="moments must be > 0"):
        an.box_dimensions([1.0, 0.0, 1.0])
    with pytest.raises(InvalidInputError, match="violate the triangle inequality"):
        an.box_dimensions([3.0, 5.0, 9.0])
    with pytest.raises(InvalidInputError, match="NaN or infinite"):
        an.box_dimensions([1.0, np.nan, 1.0])


def test_box_mesh_faces_are_outward_and_planar():
    rng = np.random.default_rng(5)
    P, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    P[:, 2] *= np.sign(np.linalg.det(P))
    sides, verts, faces = an._box_mesh([1.0, 1.5, 2.0], P)
    assert len(faces) == 6
    for idx, normal, axis, sign in faces:
        c = verts[idx].mean(0)
        np.testing.assert_allclose(c, sign * 0.5 * sides[axis] * P[:, axis], atol=1e-14)
        np.testing.assert_allclose((verts[idx] - c) @ normal, 0, atol=1e-14)
        assert c @ normal > 0


def test_slerp_series_exact_for_uniform_rotation():
    w, axis = 1.3, np.array([1.0, 2.0, -2.0]) / 3.0
    ts = np.linspace(0, 10, 9)  # 1.6 rad between samples
    qs = np.concatenate([np.cos(w * ts / 2)[:, None], np.sin(w * ts / 2)[:, None] * axis], 1)
    qs[1::2] *= -1  # the sign of a quaternion does not matter
    tf = np.linspace(-1.0, 11.0, 97)
    got = an.slerp_series(ts, qs, tf)
    tc = np.clip(tf, 0, 10)
    want = np.concatenate([np.cos(w * tc / 2)[:, None], np.sin(w * tc / 2)[:, None] * axis], 1)
    np.testing.assert_allclose(np.abs(np.sum(got * want, 1)), 1.0, atol=1e-14)
    assert an.slerp_series([2.0], [[0.0, 0, 0, 2.0]], [0.0, 5.0]).tolist() == [[0, 0, 0, 1.0]] * 2
    with pytest.raises(InvalidInputError, match="non-decreasing"):
        an.slerp_series([1.0, 0.0], qs[:2], [0.5])
    with pytest.raises(InvalidInputError, match=r"t must have shape \(T,\) and q \(T, 4\)"):
        an.slerp_series(ts, qs[:3], [0.5])


def test_hidden_by_box_orthographic_and_perspective():
    half = np.array([0.5, 0.3, 0.2])
    eye_dir = np.array([0.0, 0.0, 1.0])
    pts = np.array([[0, 0, -1.0], [0, 0, 1.0], [0, 0, 0], [1.0, 0, -1], [0.7, 0, -10]])
    hid = an.hidden_by_box(pts, np.eye(3), half, np.eye(3), eye_dir, orthographic=True)
    assert hid.tolist() == [True, False, True, False, False]
    # a finite eye at z = 5 sees (0.7, 0, -10) through the box top
    hid = an.hidden_by_box(pts, np.eye(3), half, np.eye(3), 5 * eye_dir)
    assert hid.tolist() == [True, False, True, False, True]
    # the box turned by 90 degrees about z: long axis along y
    Rz = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    hid = an.hidden_by_box(np.array([[0.4, 0, -1], [0, 0.4, -1]]), Rz, half, np.eye(3), eye_dir, orthographic=True)
    assert hid.tolist() == [False, True]


# ---------------------------------------------------------------------------
# HTML
# ---------------------------------------------------------------------------
def test_html_structure_and_data(racket, tmp_path):
    out = tmp_path / "racket.html"
    assert an.animate(racket, out, duration=12) == out
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert '<canvas id="ep-canvas"' in text and "<noscript>" in text
    assert 'id="ep-play"' in text and 'type="range"' in text
    assert "http://" not in text and "https://" not in text and "src=" not in text and "<link" not in text
    assert "tennis racket" in text
    d = _page_data(text)
    np.testing.assert_allclose(d["t"], racket.t, rtol=1e-9)
    np.testing.assert_allclose(np.abs(np.sum(np.array(d["q"]) * racket.quaternion, 1)), 1, atol=1e-6)
    assert d["duration"] == 12 and d["unit"] == "s" and len(d["faces"]) == 6 and len(d["verts"]) == 8
    m = racket.m[0]
    np.testing.assert_allclose(d["m"], m / np.linalg.norm(m), atol=1e-9)
    np.testing.assert_allclose(2 * np.array(d["half"]), an.box_dimensions(RACKET_I), atol=1e-9)
    assert os.listdir(tmp_path) == ["racket.html"] and (out.stat().st_mode & 0o777) == 0o644


def test_html_subsampling_and_escaping(racket, tmp_path):
    tr = Trajectory(
        racket.t, racket.quaternion, racket.omega, RigidBody(RACKET_I, name="</script><b>x & y</b>"), method="m"
    )
    out = tmp_path / "a.htm"
    an.animate(tr, out, max_samples=100)
    text = out.read_text()
    assert "</script><b>" not in text and "&lt;/script&gt;&lt;b&gt;x &amp; y" in text
    d = _page_data(text)
    assert d["title"].startswith("</script><b>x & y</b>")
    assert len(d["t"]) == 100 and d["t"][0] == racket.t[0] and d["t"][-1] == racket.t[-1]
    with pytest.raises(InvalidInputError, match="max_samples must be >= 2"):
        an.animate(tr, out, max_samples=1)


def _browser():
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


def test_html_renders_in_headless_chromium(racket, tmp_path):
    browser = _browser()
    if browser is None:
        pytest.skip("Chromium is not installed (apt-get install chromium); the HTML page is not rendered")
    page = tmp_path / "racket.html"
    an.animate(racket, page)
    shot = tmp_path / "shot.png"
    cmd = [
        browser,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--enable-logging=stderr",
        "--v=0",
        f"--user-data-dir={tmp_path / 'profile'}",
        f"--screenshot={shot}",
        "--window-size=800,600",
        page.resolve().as_uri(),
    ]
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=90)
    except subprocess.TimeoutExpired:
        pytest.skip("headless Chromium did not finish within 90 s")
    if not shot.exists():
        if res.returncode != 0:
            pytest.skip(f"headless Chromium could not run (rc={res.returncode}): {res.stderr[-300:]}")
        pytest.fail(f"Chromium ran but wrote no screenshot: {res.stderr[-300:]}")
    errors = [ln for ln in res.stderr.splitlines() if "CONSOLE" in ln and "Uncaught" in ln]
    assert not errors, errors  # no JavaScript exception
    from PIL import Image

    img = np.asarray(Image.open(shot).convert("RGB"))
    assert img.shape == (600, 800, 3)
    centre = (slice(150, 420), slice(250, 550))
    frac = _face_pixel_fraction(img, centre)
    assert frac > 0.08, f"only {frac:.1%} of the centre shows the box's face colours"
    # the box is where it is drawn: nothing of it in the margins of the page
    assert _face_pixel_fraction(img, (slice(0, 600), slice(0, 60))) < 0.01


# ---------------------------------------------------------------------------
# GIF / MP4
# ---------------------------------------------------------------------------
def test_gif_frames_size_and_motion(racket, tmp_path):
    from PIL import Image

    out = tmp_path / "racket.gif"
    an.animate(racket, out, fps=5, duration=1.2, size=(160, 120))
    assert os.listdir(tmp_path) == ["racket.gif"]
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames == 6 and im.size == (160, 120)
        assert im.info["duration"] == 200
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB"), float))
    assert _face_pixel_fraction(frames[0]) > 0.03
    # the racket turns: frames differ
    assert np.mean(np.abs(frames[0] - frames[2])) > 1.0


def test_mp4_needs_ffmpeg(racket, tmp_path, monkeypatch):
    monkeypatch.setitem(matplotlib.rcParams, "animation.ffmpeg_path", "/nonexistent/ffmpeg-for-test")
    out = tmp_path / "a.mp4"
    out.write_bytes(b"old")
    with pytest.raises(MissingDependencyError, match=r"needs the ffmpeg program.*install ffmpeg.*\.html or \.gif"):
        an.animate(racket, out, fps=5, duration=1)
    assert out.read_bytes() == b"old" and os.listdir(tmp_path) == ["a.mp4"]


def test_mp4_with_ffmpeg(racket, tmp_path):
    if shutil.which(matplotlib.rcParams["animation.ffmpeg_path"]) is None:
        pytest.skip("ffmpeg is not installed")
    out = tmp_path / "a.mp4"
    an.animate(racket, out, fps=5, duration=1, size=(161, 120))
    assert out.read_bytes()[4:8] == b"ftyp"


def test_animate_errors(racket, tmp_path):
    out = tmp_path / "a.html"
    with pytest.raises(InvalidInputError, match=r"unsupported file extension '\.avi'; use \.html"):
        an.animate(racket, tmp_path / "a.avi")
    for fps in (0, -1, np.nan, True, "30"):
        with pytest.raises(InvalidInputError, match="fps must be a positive number"):
            an.animate(racket, out, fps=fps)
    for dur in (0, -2.0, np.inf):
        with pytest.raises(InvalidInputError, match="duration must be None or a positive number"):
            an.animate(racket, out, duration=dur)
    for size in ((10, 10), (640,), "big"):
        with pytest.raises(InvalidInputError, match="size must be"):
            an.animate(racket, out, size=size)
    with pytest.raises(InvalidInputError, match="index=2 given for a trajectory of one body"):
        an.animate(racket, out, index=2)
    with pytest.raises(TypeError, match="out must be a file name"):
        an.animate(racket, None)
    with pytest.raises(TypeError, match="traj must be an eulerpoisson Trajectory"):
        an.animate(np.zeros((3, 4)), out)
    assert not out.exists()


def test_batched_body_and_default_duration(racket, tmp_path):
    t = racket.t[:200]
    q2, w2 = reference_motion([1.0, 2.0, 2.5], [0.1, 0.2, 0.3], np.array([1.0, 0, 0, 0]), t)
    body = RigidBody(np.array([RACKET_I, [1.0, 2.0, 2.5]]), name="pair")
    tr = Trajectory(t, np.stack([racket.quaternion[:200], q2]), np.stack([racket.omega[:200], w2]), body)
    an.animate(tr, tmp_path / "b.html", index=1)
    d = _page_data((tmp_path / "b.html").read_text())
    np.testing.assert_allclose(d["moments"], [1.0, 2.0, 2.5])
    np.testing.assert_allclose(np.abs(np.sum(np.array(d["q"]) * q2, 1)), 1, atol=1e-6)
    assert d["duration"] == 20.0  # span 39.8 s clipped to 20 s
    with pytest.raises(InvalidInputError, match="out of range"):
        an.animate(tr, tmp_path / "c.html", index=2)
