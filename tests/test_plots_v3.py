"""Pictures, third pass (issue 22, item 16): what a figure draws is what holds, and every curve is visible.

* ``polhode`` under torque draws no momentum sphere, separatrices or
  energy curve (they hold for the free body only); a Lagrange top draws the
  plane of its conserved M₃; the figure says so;
* the decimated ``omega`` of a long run: the min/max envelope translucent
  underneath, the mean per column on top (no component hidden);
* ``invariants``: every curve listed is visible (stacked widest-lowest), the
  legend outside the data; under torque the integrals of the model;
* fit and validate figures name the time unit and the rate unit;
* ``plot(..., t_start=, t_end=)`` and ``plot --t-start/--t-end``: a window of
  a run in memory, or of a Zarr store read lazily (binary search on its times).

The checks are on the figure's content (artists, labels, alpha, z-order,
legend placement), not on pixels.
"""

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.errors import InvalidInputError  # noqa: E402
from eulerpoisson.model.torques import Gravity, GravityGradient  # noqa: E402
from eulerpoisson.viz import plots  # noqa: E402
from eulerpoisson.viz.decimate import DEFAULT_BINS, MinMaxEnvelope  # noqa: E402
from eulerpoisson.viz.polhode import TORQUE_NOTE  # noqa: E402

EPS = np.finfo(float).eps
FREE_ONLY = ("separatrices", "other polhodes", "|M| = L ∩ energy ellipsoid")


def _labels(ax):
    return [ln.get_label() for ln in ax.get_lines()]


def _texts(fig):
    out = []
    for ax in fig.axes:
        out += [t.get_text() for t in ax.texts] + [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
    return out + [t.get_text() for t in fig.texts]


def _legend_outside_axes(fig, ax):
    """The legend of ``ax`` lies outside the axes' data area (its bbox does not overlap the axes' bbox)."""
    fig.canvas.draw() if hasattr(fig.canvas, "draw") else None
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    leg = ax.get_legend()
    assert leg is not None
    lb = leg.get_window_extent()
    axb = ax.get_window_extent()
    overlap_x = min(lb.x1, axb.x1) - max(lb.x0, axb.x0)
    overlap_y = min(lb.y1, axb.y1) - max(lb.y0, axb.y0)
    return overlap_x <= 0.5 or overlap_y <= 0.5


@pytest.fixture(scope="module")
def top():
    body = ep.RigidBody([1.0, 1.0, 0.5], name="heavy top")
    h = np.radians(60.0) / 2
    return ep.solve(
        body,
        np.linspace(0.0, 6.0, 1201),
        omega0=[0.0, 0.0, 8.0],
        attitude0=[np.cos(h), np.sin(h), 0.0, 0.0],
        torque=Gravity(1.0, [0.0, 0.0, 0.3], [0.0, 0.0, -9.81]),
        method="taylor",
    )


@pytest.fixture(scope="module")
def orbit():
    return ep.solve(
        [3.0, 5.0, 8.0],
        np.linspace(0.0, 60.0, 1201),
        omega0=[0.01, 0.4, 0.01],
        torque=GravityGradient(0.1),
        method="taylor",
    )


@pytest.fixture(scope="module")
def racket():
    return ep.solve([3.0, 5.0, 8.0], np.linspace(0.0, 400.0, 4001), omega0=[0.0, 0.4, 0.01 / 8])


@pytest.fixture(scope="module")
def long_racket():
    return ep.solve([3.0, 5.0, 8.0], np.linspace(0.0, 4000.0, 30_001), omega0=[0.0, 0.4, 0.01 / 8])


# ---------------------------------------------------------------------------
# polhode under torque
# ---------------------------------------------------------------------------
def test_polhode_of_the_free_body_keeps_its_invariant_surfaces(racket):
    fig = plots.plot(racket, "polhode")
    ax = fig.axes[0]
    assert set(FREE_ONLY) <= set(_labels(ax))
    assert any(type(c).__name__ == "Line3DCollection" for c in ax.collections)  # the |M| = L sphere
    assert TORQUE_NOTE not in " ".join(_texts(fig))


def test_polhode_under_a_torque_draws_only_the_path_and_says_so(orbit):
    fig = plots.plot(orbit, "polhode")
    ax = fig.axes[0]
    labels = _labels(ax)
    assert not set(FREE_ONLY) & set(labels), labels  # they hold for the free body only
    assert not any(type(c).__name__ == "Line3DCollection" for c in ax.collections)  # no |M| = L sphere
    assert "M(t) computed" in labels
    assert "under torque (GravityGradient)" in ax.get_title()
    assert any(TORQUE_NOTE in t and "conserves nothing" in t for t in _texts(fig))
    # the path is drawn whole, inside the limits (|M| changes: the limits follow the path, not |M(t0)|)
    path = next(ln for ln in ax.get_lines() if ln.get_label() == "M(t) computed")
    xyz = np.array(path.get_data_3d())
    assert np.max(np.abs(xyz)) <= ax.get_xlim()[1]


def test_polhode_of_a_lagrange_top_draws_the_plane_of_its_conserved_M3(top):
    fig = plots.plot(top, "polhode")
    ax = fig.axes[0]
    labels = _labels(ax)
    assert not set(FREE_ONLY) & set(labels)
    plane = [lb for lb in labels if lb.startswith("M·e₃ = M₃(t₀)")]
    assert plane, labels
    assert any("Lagrange top keeps M₃" in t for t in _texts(fig))
    # the drawn path lies in the drawn plane: M·u is constant along it (u: the symmetry axis, principal frame)
    ring = np.array(next(ln for ln in ax.get_lines() if ln.get_label() == plane[0]).get_data_3d()).T
    centre = ring.mean(axis=0)
    u = np.cross(ring[10] - centre, ring[50] - centre)
    u /= np.linalg.norm(u)
    path = np.array(next(ln for ln in ax.get_lines() if ln.get_label() == "M(t) computed").get_data_3d()).T
    np.testing.assert_allclose(path @ u, centre @ u, atol=1e-9 * np.max(np.abs(path)))
    assert np.ptp(np.linalg.norm(path, axis=1)) > 1e-3  # while |M| does change


# ---------------------------------------------------------------------------
# omega of a long run: band translucent, mean on top
# ---------------------------------------------------------------------------
def test_long_omega_draws_translucent_envelopes_under_mean_lines(long_racket):
    from matplotlib.collections import LineCollection

    fig = plots.plot(long_racket, "omega")
    ax = fig.axes[0]
    bands = {ln.get_label(): ln for ln in ax.get_lines() if ln.get_label().startswith("Ω")}
    means = {c.get_label(): c for c in ax.collections if isinstance(c, LineCollection)}
    assert sorted(bands) == sorted(means) == ["Ω₁", "Ω₂", "Ω₃"]
    t, w = long_racket.t, long_racket.omega
    width = (t[-1] - t[0]) / DEFAULT_BINS
    col = MinMaxEnvelope(t[0], t[-1], 1).bins_of(t)
    for i, name in enumerate(["Ω₁", "Ω₂", "Ω₃"]):
        band, mean = bands[name], means[name]
        assert band.get_alpha() is not None and band.get_alpha() <= 0.4  # translucent: no band hides another
        assert mean.get_alpha() in (None, 1.0)
        assert mean.get_zorder() > max(b.get_zorder() for b in bands.values())  # every mean above every band
        # the mean line is the mean of the samples of every column
        (seg,) = mean.get_segments()
        used = np.unique(col)
        want = np.bincount(col, weights=w[:, i], minlength=DEFAULT_BINS)[used] / np.bincount(col)[used]
        np.testing.assert_allclose(seg[:, 1], want, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(seg[:, 0], t[0] + (used + 0.5) * width, rtol=1e-12)
    leg = ax.get_legend()
    assert [tx.get_text() for tx in leg.get_texts()] == ["Ω₁", "Ω₂", "Ω₃"]
    assert all((h.get_alpha() or 1.0) == 1.0 for h in leg.legend_handles)  # the legend shows the (opaque) mean lines
    assert _legend_outside_axes(fig, ax)
    assert any("band: min/max, line: mean" in tx for tx in _texts(fig))


def test_short_omega_legend_is_outside_the_data(racket):
    fig = plots.plot(racket, "omega")
    assert _legend_outside_axes(fig, fig.axes[0])


# ---------------------------------------------------------------------------
# invariants: every listed curve is visible
# ---------------------------------------------------------------------------
def test_invariants_every_listed_curve_is_visible(racket):
    fig = plots.plot(racket, "invariants")
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines() if not ln.get_label().startswith("_")}
    assert list(lines) == ["E", "|m|", "m₁", "m₂", "m₃"]
    peaks = {k: np.max(ln.get_ydata()) for k, ln in lines.items()}
    order = sorted(lines, key=lambda k: -peaks[k])  # the largest lowest and widest, each next above and thinner
    z = [lines[k].get_zorder() for k in order]
    lw = [lines[k].get_linewidth() for k in order]
    assert z == sorted(z) and len(set(z)) == 5
    assert lw == sorted(lw, reverse=True) and len(set(lw)) == 5
    assert all((lines[k].get_alpha() or 1.0) == 1.0 for k in lines)  # opaque: each shows as its own colour
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert [t.split()[0] for t in texts] == ["E", "|m|", "m₁", "m₂", "m₃"]
    assert all("max" in t or "≤ ε" in t for t in texts)
    assert _legend_outside_axes(fig, ax)


def test_invariants_under_torque_are_the_integrals_of_the_model(top):
    fig = plots.plot(top, "invariants")
    ax = fig.axes[0]
    labels = [lb for lb in _labels(ax) if not lb.startswith("_")]
    assert labels == ["E", "m·ĝ", "M₃ (symmetry axis)"]  # not the kinetic energy and |m|, which change under gravity
    for ln in ax.get_lines():
        if ln.get_label() in labels:
            assert np.max(ln.get_ydata()) < 1e-10  # conserved (taylor at tol 1e-15), unlike the kinetic energy
    assert "torque: Gravity" in ax.get_title()
    drift = top.drift()
    np.testing.assert_allclose(
        [np.max(ln.get_ydata()) for ln in ax.get_lines() if ln.get_label() in labels],
        [max(drift[k], EPS) for k in ("energy", "m_vertical", "M3")],
        rtol=1e-6,
    )


def test_invariants_of_a_model_without_integrals_say_so():
    tr = ep.solve(
        [3.0, 5.0, 8.0], np.linspace(0.0, 5.0, 101), omega0=[0.1, 0.2, 0.3], torque=ep.torques.BodyTorque([0.1, 0, 0])
    )
    assert tr.drift() == {}  # a constant body torque on an asymmetric body: no known integral
    fig = plots.plot(tr, "invariants")
    ax = fig.axes[0]
    assert not [lb for lb in _labels(ax) if not lb.startswith("_")]
    assert any("no integral of motion is known" in t for t in _texts(fig))


# ---------------------------------------------------------------------------
# fit and validate figures: units, legends outside
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fit_result():
    from eulerpoisson.estimation.residuals import exp_quaternion
    from eulerpoisson.numerics.quaternion import qmul

    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 40.0, 81)
    truth = ep.solve([0.3, 0.35, 0.43], t, omega0=[0.3, -0.2, 1.0])
    sa, sw = 1e-3, 2e-3
    q = qmul(truth.quaternion, exp_quaternion(sa * rng.standard_normal((t.size, 3))))
    w = truth.omega + sw * rng.standard_normal((t.size, 3))
    return ep.fit(t, attitude=q, attitude_sigma=sa, omega=w, omega_sigma=sw)


def test_fit_figures_name_the_units_and_keep_legends_off_the_data(fit_result):
    import matplotlib.pyplot as plt

    for fig in (fit_result.plot_residuals(), fit_result.plot_fit()):
        try:
            labels = [a.get_ylabel() for a in fig.axes]
            assert fig.axes[-1].get_xlabel() == "time t [s]"
            assert not any("[rate]" in lb for lb in labels), labels
            assert any("[rad/s]" in lb for lb in labels), labels
            for a in fig.axes:
                assert _legend_outside_axes(fig, a)
        finally:
            plt.close(fig)
    fig = fit_result.plot_polhode()
    try:
        assert "[rad/s]" in fig.axes[0].get_xlabel()
    finally:
        plt.close(fig)


def test_fit_figures_use_a_time_unit_the_data_carry(fit_result, monkeypatch):
    import matplotlib.pyplot as plt

    from eulerpoisson.estimation import plots as fplots

    class WithUnit:
        def __init__(self, res):
            self._res = res
            self.time_unit = "min"

        def __getattr__(self, name):
            return getattr(self._res, name)

    assert fplots.time_unit(fit_result) == "s"
    fig = fplots.plot_residuals(WithUnit(fit_result))
    try:
        assert fig.axes[-1].get_xlabel() == "time t [min]"
        assert any("[rad/min]" in a.get_ylabel() for a in fig.axes)
    finally:
        plt.close(fig)


def test_validate_figure_names_the_time_unit_and_keeps_legends_off_the_data(tmp_path):
    from eulerpoisson.oracle import plot_report, run_from_arrays, validate

    tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 20.0, 201), omega0=[0.05, 1.0, 0.05])
    rep = validate(run_from_arrays(tr.t, tr.quaternion, tr.omega), [1.0, 2.0, 2.5], tolerance=1e-6)
    fig = plot_report(rep)
    assert fig.axes[-1].get_xlabel() == "time t [s]"
    assert fig.axes[0].get_ylabel() == "attitude error [rad]"
    for a in fig.axes:
        assert _legend_outside_axes(fig, a)


# ---------------------------------------------------------------------------
# a window of a long run
# ---------------------------------------------------------------------------
def test_window_of_a_run_in_memory(racket):
    fig = plots.plot(racket, "omega", t_start=100.0, t_end=150.0)
    ax = fig.axes[0]
    x = ax.get_lines()[0].get_xdata()
    assert x.min() >= 100.0 and x.max() <= 150.0
    assert ax.get_xlim() == (100.0, 150.0)
    sel = (racket.t >= 100.0) & (racket.t <= 150.0)
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), racket.omega[sel, 0])
    # one end open
    x = plots.plot(racket, "omega", t_start=390.0).axes[0].get_lines()[0].get_xdata()
    assert x.min() >= 390.0 and x.max() == 400.0
    for kind in plots.KINDS:
        if kind != "apex":
            plots.plot(racket, kind, t_start=50.0, t_end=120.0)


def test_window_invariants_stay_relative_to_the_start_of_the_run():
    t = np.linspace(0.0, 20.0, 401)
    w = 0.7
    q = np.stack([np.cos(w * t / 2), 0 * t, 0 * t, np.sin(w * t / 2)], -1)
    om = np.zeros((t.size, 3))
    om[:, 2] = w * (1.0 + 1e-4 * t)  # a known drift: |m| grows by 1e-4 t
    tr = ep.Trajectory(t, q, om, ep.RigidBody([1.0, 2.0, 2.5]), method="closed-form")
    fig = plots.plot(tr, "invariants", t_start=10.0, t_end=20.0)
    ax = fig.axes[0]
    m = next(ln for ln in ax.get_lines() if ln.get_label() == "|m|")
    np.testing.assert_allclose(m.get_xdata(), t[t >= 10.0])
    np.testing.assert_allclose(m.get_ydata(), 1e-4 * t[t >= 10.0], rtol=1e-9)  # from t0 = 0, not from t = 10
    assert "the first sample of the run, t₀ = 0" in ax.get_title()


@pytest.mark.parametrize(
    "kw,match",
    [
        ({"t_start": 200.0, "t_end": 100.0}, "t_start=200.0 is after t_end=100.0"),
        ({"t_start": 500.0}, r"holds 0 sample\(s\) of the run \(times from 0 to 400\)"),
        ({"t_start": 100.0, "t_end": 100.05}, r"holds 1 sample\(s\)"),
        ({"t_end": float("nan")}, "t_end must be a finite time"),
        ({"t_start": "10"}, "t_start must be a number"),
    ],
)
def test_window_errors(racket, kw, match):
    with pytest.raises(InvalidInputError, match=match):
        plots.plot(racket, "omega", **kw)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    pytest.importorskip("zarr")
    from eulerpoisson.io.stream import solve_to_file

    path = tmp_path_factory.mktemp("win") / "long.zarr"
    solve_to_file([3.0, 5.0, 8.0], (0.0, 600.0, 60_001), path, omega0=[0.0, 0.4, 0.01 / 8], chunk=4_000, progress=False)
    return path


def test_window_of_a_store_is_read_lazily(store, monkeypatch):
    from eulerpoisson.io.read import LazyTrajectory
    from eulerpoisson.viz.long_runs import StoreWindow, window

    lz = ep.Trajectory.open(store)
    reads = []
    real = LazyTrajectory.read_arrays

    def spy(self, names, a=0, b=None, step=1, **kw):
        if not isinstance(self, StoreWindow):
            reads.append((tuple(names), a, b))
        return real(self, names, a, b, step, **kw)

    def refuse(*a, **k):
        raise AssertionError("the store was loaded whole")

    monkeypatch.setattr(LazyTrajectory, "read_arrays", spy)
    monkeypatch.setattr(LazyTrajectory, "load", refuse)
    win = window(lz, 100.0, 130.0)
    assert isinstance(win, StoreWindow) and len(win) == 3001
    assert win[0].t[0] == 100.0 and win[-1].t[0] == 130.0
    search = [r for r in reads if r[2] is not None and r[2] - r[1] == 1]
    assert len(search) <= 2 * 17 + 2  # a binary search: log2(60 001) probes per end
    reads.clear()
    fig = plots.plot(lz, "omega", t_start=100.0, t_end=130.0)
    big = [r for r in reads if r[0] != ("time",) or r[2] - r[1] > 1]
    assert big and all(10_000 <= a and b <= 13_001 for _, a, b in big), big  # only the window is read
    ax = fig.axes[0]
    assert ax.get_xlim() == (100.0, 130.0)
    # the same picture as the window of the run in memory
    mem = lz.read(10_000, 13_001)
    band = next(ln for ln in ax.get_lines() if ln.get_label() == "Ω₁")
    assert np.min(band.get_ydata()) == np.min(mem.omega[:, 0]) and np.max(band.get_ydata()) == np.max(mem.omega[:, 0])
    for kind in ("invariants", "polhode", "attitude"):
        plots.plot(lz, kind, t_start=100.0, t_end=130.0)


def test_cli_plot_window(tmp_path, capsys):
    from eulerpoisson.cli.main import main

    tr = ep.solve([3.0, 5.0, 8.0], np.linspace(0.0, 100.0, 1001), omega0=[0.0, 0.4, 0.01 / 8])
    nc = tmp_path / "run.nc"
    tr.to_netcdf(nc)
    out = tmp_path / "w.png"
    assert main(["plot", str(nc), "--kind", "omega", "--t-start", "20", "--t-end", "40", "--out", str(out)]) == 0
    assert out.exists()
    capsys.readouterr()
    assert main(["plot", str(nc), "--kind", "omega", "--t-start", "x", "--out", str(tmp_path / "x.png")]) == 2
    assert "--t-start: 'x' is not a number" in capsys.readouterr().err
    assert (
        main(["plot", str(nc), "--kind", "omega", "--t-start", "50", "--t-end", "40", "--out", str(tmp_path / "y.png")])
        == 2
    )
    assert "--t-start 50 is after --t-end 40" in capsys.readouterr().err
    assert main(["plot", str(nc), "--kind", "omega", "--t-start", "500", "--out", str(tmp_path / "z.png")]) == 2
    assert "holds 0 sample(s)" in capsys.readouterr().err
    assert not (tmp_path / "z.png").exists()
    assert main(["plot", str(nc), "--kind", "atlas", "--t-start", "5", "--out", str(tmp_path / "a.png")]) == 2
    assert "--kind atlas draws a whole sweep" in capsys.readouterr().err
