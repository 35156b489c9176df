"""GIF export streams its frames to the file (issue 12, item 10).

matplotlib's PillowWriter kept every frame until the end (600 frames of
640x480: 36 s and 1 GB); ``GifStreamWriter`` quantizes and writes each frame
when the next one arrives, so at most two frames are held, and the file
grows frame by frame.
"""

import numpy as np
import pytest

pytest.importorskip("matplotlib")
PIL = pytest.importorskip("PIL")

from PIL import Image  # noqa: E402

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.viz import animate as an  # noqa: E402


def _frames(n, w=64, h=48):
    """Synthetic frames of a few colours: a square moving on a white background."""
    out = []
    for k in range(n):
        f = np.full((h, w, 3), 255, np.uint8)
        f[10:20, k % (w - 10) : k % (w - 10) + 10] = (214, 39, 40)
        f[30:40, 5:15] = (31, 119, 180)
        out.append(f)
    return out


def test_frames_are_written_as_they_come(tmp_path):
    path = tmp_path / "s.gif"
    wr = an.GifStreamWriter(fps=20)
    import matplotlib.figure

    fig = matplotlib.figure.Figure(figsize=(0.64, 0.48))
    frames = _frames(12)
    sizes = []
    with wr.saving(fig, path, 100):
        for f in frames:
            wr.add_frame(f)
            wr._fh.flush()
            sizes.append(path.stat().st_size)
            assert wr._pending is not None  # one frame waits (its display time may still grow), no more
    # the file grew while the frames came (PillowWriter wrote nothing before the end)
    assert sizes[0] > 0 and all(b > a for a, b in zip(sizes[1:-1], sizes[2:]))
    im = Image.open(path)
    assert im.n_frames == 12 and im.info.get("loop") == 0 and im.info.get("duration") == 50
    for k, f in enumerate(frames):
        im.seek(k)
        np.testing.assert_array_equal(np.asarray(im.convert("RGB")), f)


def test_identical_frames_lengthen_the_previous_one(tmp_path):
    path = tmp_path / "d.gif"
    wr = an.GifStreamWriter(fps=10)
    import matplotlib.figure

    fig = matplotlib.figure.Figure(figsize=(0.64, 0.48))
    f = _frames(3)
    with wr.saving(fig, path, 100):
        for g in (f[0], f[1], f[1], f[1], f[2]):
            wr.add_frame(g)
    im = Image.open(path)
    assert im.n_frames == 3
    durations = []
    for k in range(3):
        im.seek(k)
        durations.append(im.info["duration"])
    assert durations == [100, 300, 100]


def test_animate_gif_uses_the_streaming_writer(tmp_path, monkeypatch):
    from matplotlib import animation

    def forbidden(*a, **k):
        raise AssertionError("PillowWriter holds every frame in memory")

    monkeypatch.setattr(animation, "PillowWriter", forbidden)
    tr = ep.solve([3.0, 5.0, 8.0], np.linspace(0.0, 50.0, 501), omega0=[0.0, 0.4, 0.00125])
    out = an.animate(tr, tmp_path / "m.gif", fps=10, duration=3, size=(160, 120))
    im = Image.open(out)
    assert im.n_frames >= 25 and im.size == (160, 120)
    im.seek(im.n_frames - 1)
    last = np.asarray(im.convert("RGB"), float)
    assert (last < 250).any()  # something drawn
