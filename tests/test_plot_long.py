"""Pictures of long runs (issue 12, item 7): decimated, piece by piece, and no quadratic Gibbs charts.

* a time series longer than ``DECIMATE_ABOVE`` is drawn as the min/max of
  its samples per pixel column: a few thousand points, whose envelope
  contains every sample (and whose extremes are the samples' extremes);
* a Zarr store is drawn from its chunks, never loaded whole;
* ``chart_segments`` used to multiply the whole rest of the run for every
  chart (295 s for 10^6 samples); it is linear now, and ``plot_gibbs``
  draws at most ``MAX_CHARTS`` charts of a long run.
"""

import time

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.io.read import LazyTrajectory  # noqa: E402
from eulerpoisson.numerics.quaternion import qmul  # noqa: E402
from eulerpoisson.viz import plots  # noqa: E402
from eulerpoisson.viz.decimate import DEFAULT_BINS, MinMaxEnvelope  # noqa: E402

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]
T_LONG = 60_000


@pytest.fixture(scope="module")
def long_run():
    return ep.solve(I, np.linspace(0.0, 600.0, T_LONG), omega0=W0)


@pytest.fixture(scope="module")
def store(tmp_path_factory, long_run):
    from eulerpoisson.io.stream import solve_to_file

    path = tmp_path_factory.mktemp("long") / "long.zarr"
    solve_to_file(I, (0.0, 600.0, T_LONG), path, omega0=W0, chunk=7_000, progress=False)
    return path


def _lines(ax):
    return {ln.get_label(): ln for ln in ax.get_lines()}


def _check_envelope(x, y, t, values):
    """Every sample lies within the plotted [min, max] of its column; the extremes are attained."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    assert x.size <= 2 * DEFAULT_BINS and x.size % 2 == 0
    assert np.all(x[0::2] == x[1::2])  # two points per column
    t0, t1 = float(t.min()), float(t.max())
    w = (t1 - t0) / DEFAULT_BINS
    col_of_point = np.round((x[0::2] - t0) / w - 0.5).astype(int)
    lo = np.minimum(y[0::2], y[1::2])
    hi = np.maximum(y[0::2], y[1::2])
    col = np.clip(np.floor((t - t0) / w).astype(int), 0, DEFAULT_BINS - 1)
    pos = np.searchsorted(col_of_point, col)
    assert np.all(col_of_point[pos] == col), "a sample's column is missing from the picture"
    assert np.all(lo[pos] <= values) and np.all(values <= hi[pos])
    assert lo.min() == values.min() and hi.max() == values.max()
    # and tight: every column's extremes are values of its own samples
    for c in np.unique(col)[:: max(1, len(np.unique(col)) // 50)]:
        sel = values[col == c]
        k = np.searchsorted(col_of_point, c)
        assert lo[k] == sel.min() and hi[k] == sel.max()


def test_omega_of_a_long_run_is_decimated_and_contains_every_sample(long_run):
    fig = plots.plot_omega(long_run)
    lines = _lines(fig.axes[0])
    for i in range(3):
        ln = lines[f"Ω{'₁₂₃'[i]}"]
        assert len(ln.get_xdata()) < T_LONG / 10  # decimated (it drew all 60 000 points before)
        _check_envelope(ln.get_xdata(), ln.get_ydata(), long_run.t, long_run.omega[:, i])


def test_invariants_of_a_long_run_are_decimated(long_run):
    fig = plots.plot_invariants(long_run)
    lines = _lines(fig.axes[0])
    one = plots.select_body(long_run)
    curves = plots.invariant_drift(one)
    eps = np.finfo(float).eps
    for key, y in curves.items():
        ln = lines[key]
        assert len(ln.get_xdata()) <= 2 * DEFAULT_BINS
        # the drift of the decimated path is computed without the rotation matrices: within round-off
        yl = np.asarray(ln.get_ydata())
        assert np.nanmax(yl) <= max(np.max(np.maximum(y, eps)) * (1 + 1e-6), 64 * eps)


def test_store_plots_from_chunks_without_loading(store, long_run, monkeypatch):
    lz = ep.Trajectory.open(store)
    assert isinstance(lz, LazyTrajectory)

    def refuse(*a, **k):
        raise AssertionError("the store was loaded whole")

    monkeypatch.setattr(LazyTrajectory, "load", refuse)
    fig = plots.plot(lz, "omega")
    lines = _lines(fig.axes[0])
    ref = plots.plot_omega(long_run)
    for i in range(3):
        label = f"Ω{'₁₂₃'[i]}"
        ln = lines[label]
        _check_envelope(ln.get_xdata(), ln.get_ydata(), long_run.t, long_run.omega[:, i])
        # the same picture as from memory (the closed form streamed chunk by chunk is bit for bit the same)
        np.testing.assert_array_equal(ln.get_ydata(), _lines(ref.axes[0])[label].get_ydata())
    for kind in ("invariants", "polhode", "gibbs", "attitude", "apex"):
        plots.plot(lz, kind)


def test_envelope_does_not_depend_on_the_pieces(long_run, monkeypatch):
    """Memory is bounded by the piece: small pieces give the same picture."""
    big = plots.plot_omega(long_run)
    from eulerpoisson.viz import long_runs

    monkeypatch.setattr(long_runs, "PIECE", 997)
    small = plots.plot_omega(long_run)
    for a, b in zip(big.axes[0].get_lines(), small.axes[0].get_lines()):
        np.testing.assert_array_equal(a.get_ydata(), b.get_ydata())


def test_envelope_any_order_and_nan():
    env = MinMaxEnvelope(0.0, 10.0, 1, nbins=10)
    rng = np.random.default_rng(3)
    t = rng.uniform(0, 10, 1000)
    y = rng.normal(size=1000)
    y[::17] = np.nan
    env.add(t, y)
    x, yy = env.points()
    col = np.clip(np.floor(t).astype(int), 0, 9)
    for c in range(10):
        sel = y[col == c]
        assert np.nanmin(sel) == np.nanmin(yy[2 * c : 2 * c + 2]) and np.nanmax(sel) == np.nanmax(yy[2 * c : 2 * c + 2])
    dec = MinMaxEnvelope(0.0, 10.0, 1, nbins=10)  # decreasing times: the monotonic path, reversed
    order = np.argsort(-t)
    dec.add(t[order], y[order])
    np.testing.assert_array_equal(dec.points()[1], yy)


def _old_chart_segments(q, r=1.0, jump_limit=4.0):
    """The previous implementation (quadratic), as the reference of the charts."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    conj = np.array([1.0, -1.0, -1.0, -1.0])
    T = q.shape[0]
    segs = []
    start = 0
    while start < T:
        ref = q[start]
        rel = qmul(ref * conj, q[start:])
        rel[0] = (1.0, 0.0, 0.0, 0.0)
        w, v = rel[:, 0], rel[:, 1:]
        hit = np.flatnonzero(np.linalg.norm(v, axis=1) > r * np.abs(w))
        if hit.size == 0:
            segs.append((np.arange(start, T), v / w[:, None], ref))
            break
        h = int(hit[0])
        big = np.linalg.norm(v[h]) > jump_limit * r * abs(w[h])
        end = h if big else h + 1
        segs.append((np.arange(start, start + end), v[:end] / w[:end, None], ref))
        start = start + h
    return segs


def _spin(n, rate=0.1, wobble=0.0):
    k = np.arange(n)
    th = rate * k
    ax = np.stack([np.sin(wobble * k), np.zeros(n), np.cos(wobble * k)], -1)
    return np.concatenate([np.cos(th / 2)[:, None], np.sin(th / 2)[:, None] * ax], -1)


def test_chart_segments_unchanged(long_run):
    for q in (long_run.quaternion[:20_000], _spin(3000, 0.1, 0.01), _spin(500, 1.9)):  # the last: coarse jumps
        new = plots.chart_segments(q)
        old = _old_chart_segments(q)
        assert len(new) == len(old)
        for (i1, n1, r1), (i2, n2, r2) in zip(new, old):
            np.testing.assert_array_equal(i1, i2)
            np.testing.assert_array_equal(n1, n2)
            np.testing.assert_array_equal(r1, r2)


def test_chart_segments_linear_time():
    """200 000 samples, a chart every 16 samples: the quadratic split took minutes."""
    q = _spin(200_000, 0.1, 1e-4)
    start = time.perf_counter()
    segs = plots.chart_segments(q)
    elapsed = time.perf_counter() - start
    assert len(segs) > 10_000
    assert elapsed < 60.0, elapsed  # about 2 s quiet (0.5 s compiled and warm); the quadratic split took minutes
    b_np = plots._chart_bounds_numpy(q / np.linalg.norm(q, axis=1, keepdims=True), 1.0, 4.0)
    assert b_np == [(int(i[0]), int(i[-1]) + 1) for i, _, _ in segs]


def test_gibbs_of_a_long_run_draws_a_bounded_number_of_charts():
    t = np.linspace(0.0, 4000.0, 80_001)
    tr = ep.solve(I, t, omega0=[2.0, 0.2, 1.0])
    start = time.perf_counter()
    fig = plots.plot_gibbs(tr)
    assert time.perf_counter() - start < 60.0  # about 2 s quiet: a guard against the unbounded drawing, not a timing
    ax = fig.axes[0]
    texts = [tx.get_text() for tx in ax.texts]
    assert any("charts drawn" in s for s in texts), texts
    assert len(ax.get_lines()) <= plots.MAX_CHARTS + 3
