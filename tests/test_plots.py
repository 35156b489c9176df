"""Tests of eulerpoisson.viz.plots: the data drawn is checked against closed forms and an independent scipy solution."""

import os
import sys

import numpy as np
import pytest
from scipy.spatial import cKDTree

matplotlib = pytest.importorskip("matplotlib")

from _reference import reference_motion  # noqa: E402
from eulerpoisson.attitude import matrix_from_quaternion, quaternion_from_chart  # noqa: E402
from eulerpoisson.errors import InvalidInputError, MissingDependencyError  # noqa: E402
from eulerpoisson.model.body import RigidBody  # noqa: E402
from eulerpoisson.trajectory import Trajectory  # noqa: E402
from eulerpoisson.viz import plots  # noqa: E402

EPS = np.finfo(float).eps
RACKET_I = np.array([3.0, 5.0, 7.0])
RACKET_OMEGA0 = np.array([0.0, 0.4, 0.01 / 7.0])  # M0 = (0, 2, 0.01): near the intermediate axis


@pytest.fixture(scope="module")
def racket():
    """The tennis racket, by an independent DOP853 integration (not eulerpoisson's solvers)."""
    t = np.linspace(0.0, 150.0, 1501)
    q, w = reference_motion(RACKET_I, RACKET_OMEGA0, np.array([1.0, 0, 0, 0]), t, rtol=1e-11, atol=1e-12)
    return Trajectory(t, q, w, RigidBody(RACKET_I, name="tennis racket"), method="dop853-reference")


def spin(w=0.7, T=401, t_end=20.0, moments=(1.0, 2.0, 2.5), growth=0.0):
    """Permanent rotation about principal axis 3 in closed form: q = (cos(wt/2), 0, 0, sin(wt/2)).

    With ``growth`` = eps the angular velocity is scaled by (1 + eps t) (a fake drift with known size).
    """
    t = np.linspace(0.0, t_end, T)
    q = np.stack([np.cos(w * t / 2), 0 * t, 0 * t, np.sin(w * t / 2)], -1)
    om = np.zeros((T, 3))
    om[:, 2] = w * (1.0 + growth * t)
    return Trajectory(t, q, om, RigidBody(list(moments)), method="closed-form")


def _lines_by_label(ax):
    return {ln.get_label(): ln for ln in ax.get_lines()}


# ---------------------------------------------------------------------------
# chart restarts for the Gibbs picture
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("radius", [1.0, 0.5])
def test_chart_segments_permanent_rotation_closed_form(radius):
    w, T, t_end = 0.7, 2001, 40.0
    tr = spin(w=w, T=T, t_end=t_end)
    dt = t_end / (T - 1)
    segs = plots.chart_segments(tr.quaternion, radius)
    # the relative angle reaches 2 atan(r) after tau = 2 atan(r)/w: restart at the first sample past it
    tau = 2 * np.arctan(radius) / w
    assert len(segs) == int(np.floor(t_end / tau)) + 1 or len(segs) == int(np.floor(t_end / (tau + dt))) + 1
    for k, (idx, n, ref) in enumerate(segs):
        tc = tr.t[idx[0]]
        np.testing.assert_allclose(ref, tr.quaternion[idx[0]], atol=0)
        # local Gibbs vector about the spin axis: n = (0, 0, tan(w (t - tc)/2))
        np.testing.assert_allclose(n[:, :2], 0, atol=1e-15)
        np.testing.assert_allclose(n[:, 2], np.tan(w * (tr.t[idx] - tc) / 2), rtol=1e-12, atol=1e-15)
        if k < len(segs) - 1:
            dur = tr.t[idx[-1]] - tc
            assert tau < dur <= tau + dt + 1e-12
            assert np.all(np.linalg.norm(n[:-1], axis=1) <= radius)
            assert np.linalg.norm(n[-1]) > radius
            assert segs[k + 1][0][0] == idx[-1]  # the next chart starts at the restart sample


def test_chart_segments_round_trip_racket(racket):
    segs = plots.chart_segments(racket.quaternion, 1.0)
    assert len(segs) > 5
    covered = np.unique(np.concatenate([idx for idx, _, _ in segs]))
    np.testing.assert_array_equal(covered, np.arange(len(racket.t)))
    for idx, n, ref in segs:
        assert np.all(n[0] == 0)
        back = quaternion_from_chart(ref, n)
        dots = np.abs(np.sum(back * racket.quaternion[idx], -1))
        np.testing.assert_allclose(dots, 1.0, atol=1e-13)  # same rotation (q and -q)
        assert np.all(np.linalg.norm(n[:-1], axis=1) <= 1.0)
        assert np.all(np.linalg.norm(n, axis=1) <= 4.0)


def test_chart_segments_coarse_sampling_leaves_gap():
    # samples 170 degrees apart: beyond jump_limit -> the sample is not drawn in the old chart
    ang = np.radians(170.0) * np.arange(4)
    q = np.stack([np.cos(ang / 2), 0 * ang, 0 * ang, np.sin(ang / 2)], -1)
    segs = plots.chart_segments(q, 1.0)
    assert [list(s[0]) for s in segs] == [[0], [1], [2], [3]]


def test_chart_segments_errors():
    with pytest.raises(InvalidInputError, match=r"q must have shape \(\.\.\., 4\)"):
        plots.chart_segments(np.zeros((5, 3)))
    with pytest.raises(InvalidInputError, match=r"q must have shape \(T, 4\)"):
        plots.chart_segments(np.ones((2, 5, 4)))
    with pytest.raises(InvalidInputError, match="chart_radius must be positive"):
        plots.chart_segments(np.array([[1.0, 0, 0, 0]] * 3), chart_radius=0.0)
    with pytest.raises(InvalidInputError, match="chart_radius must be positive"):
        plots.chart_segments(np.array([[1.0, 0, 0, 0]] * 3), chart_radius=np.inf)


# ---------------------------------------------------------------------------
# polhode geometry
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("moments", [(3.0, 5.0, 7.0), (1.0, 1.7, 2.2), (2.5, 1.0, 3.0)])
def test_sphere_conic_lies_on_both_quadrics(moments):
    I = np.array(moments)
    a = np.sort(1 / I)
    L = 1.7
    levels = list(np.linspace(a[0], a[2], 9)[1:-1]) + [a[1]]
    for D in levels:
        curves = plots.sphere_conic(I, D, L, n=200)
        assert curves, D
        for c in curves:
            np.testing.assert_allclose(np.linalg.norm(c, axis=1), L, rtol=1e-12)
            np.testing.assert_allclose(np.sum(c**2 / I, axis=1), L**2 * D, rtol=1e-11)


def test_sphere_conic_separatrices_and_degenerate_levels():
    I = np.array([3.0, 5.0, 7.0])
    L = 2.0
    sep = plots.sphere_conic(I, 1 / 5.0, L, n=400)
    assert len(sep) == 2
    for c in sep:  # great circles through +-L e2
        assert np.min(np.linalg.norm(c - [0, L, 0], axis=1)) < 1e-12
        normal = np.cross(c[0], c[100])
        np.testing.assert_allclose(c @ normal, 0, atol=1e-12)  # a plane through the centre: a great circle
        assert abs(normal[1]) < 1e-12 * np.linalg.norm(normal)  # containing e2, so also -L e2
    # permanent rotation about the largest and smallest axes: single points
    for D, j in ((1 / 7.0, 2), (1 / 3.0, 0)):
        pts = plots.sphere_conic(I, D, L)
        assert len(pts) == 2 and all(p.shape == (1, 3) for p in pts)
        np.testing.assert_allclose(np.abs(np.concatenate(pts))[:, j], L)
    assert plots.sphere_conic(I, 1 / 8.0, L) == []  # energy below the minimum
    assert plots.sphere_conic([2.0, 2.0, 2.0], 0.5, L) == []  # sphere: no curves
    # symmetric top: the separatrix level 1/I2 = 1/I1 is the equator of the unique axis
    eq = plots.sphere_conic([2.0, 2.0, 3.0], 0.5, L)
    assert len(eq) == 1
    np.testing.assert_allclose(eq[0][:, 2], 0, atol=1e-15)


def test_polhode_curve_matches_computed_path(racket):
    """The drawn intersection curve is where the independently integrated M(t) lies."""
    M = racket.M
    L = np.linalg.norm(M[0])
    D = 2 * racket.energy[0] / L**2
    curve = np.concatenate(plots.sphere_conic(RACKET_I, D, L, n=4000))
    dist, _ = cKDTree(curve).query(M)
    assert np.max(dist) < 5e-3 * L  # the curve's point spacing is ~ 2e-3 L


def test_plot_polhode_draws_principal_components():
    # a full inertia tensor: the path is drawn in principal components P^T M
    rng = np.random.default_rng(3)
    Qm, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    inertia = Qm @ np.diag([1.0, 2.0, 2.6]) @ Qm.T
    t = np.linspace(0, 10, 201)
    q, w = reference_motion(inertia, np.array([0.3, -0.5, 0.8]), np.array([1.0, 0, 0, 0]), t)
    body = RigidBody(inertia)
    tr = Trajectory(t, q, w, body, method="ref")
    fig = plots.plot_polhode(tr, family=2)
    ax = fig.axes[0]
    line = _lines_by_label(ax)["M(t) computed"]
    xyz = np.array(line.get_data_3d()).T
    np.testing.assert_allclose(xyz, tr.M @ body.principal_axes, atol=1e-12)
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert "separatrices" in labels and "other polhodes" in labels
    assert ax.get_xlabel().startswith("M₁ [kg m²/s]")


# ---------------------------------------------------------------------------
# invariants
# ---------------------------------------------------------------------------
def test_invariant_drift_known_injected_drift():
    eps_ = 1e-4
    tr = spin(growth=eps_, T=201, t_end=20.0)
    fig = plots.plot_invariants(tr)
    lines = _lines_by_label(fig.axes[0])
    t = tr.t
    # E = E0 (1 + eps t)^2, |m| = |m0| (1 + eps t), m = (0, 0, m3(t))
    np.testing.assert_allclose(lines["E"].get_ydata()[1:], ((1 + eps_ * t) ** 2 - 1)[1:], rtol=1e-9)
    np.testing.assert_allclose(lines["|m|"].get_ydata()[1:], (eps_ * t)[1:], rtol=1e-9)
    np.testing.assert_allclose(lines["m₃"].get_ydata()[1:], (eps_ * t)[1:], rtol=1e-9)
    # exactly zero drift is floored at machine epsilon so that the log scale can show it
    assert lines["E"].get_ydata()[0] == EPS
    assert np.all(lines["m₁"].get_ydata() <= 2 * EPS) and np.all(lines["m₁"].get_ydata() >= EPS)
    assert fig.axes[0].get_yscale() == "log"
    assert "dimensionless" in fig.axes[0].get_ylabel()


def test_invariants_closed_form_is_roundoff_and_matches_drift(racket):
    tr = spin(T=101)
    fig = plots.plot_invariants(tr)
    for ln in fig.axes[0].get_lines():
        if ln.get_label() in ("E", "|m|", "m₁", "m₂", "m₃"):
            assert np.max(ln.get_ydata()) < 20 * EPS, ln.get_label()
    # the largest value of each curve is what Trajectory.drift reports
    one = plots.select_body(racket)
    curves = plots.invariant_drift(one)
    drift = racket.drift()
    for key, dkey in (("E", "energy"), ("|m|", "m_norm"), ("m₁", "m_x"), ("m₂", "m_y"), ("m₃", "m_z")):
        assert np.max(curves[key]) == pytest.approx(drift[dkey], rel=1e-12, abs=1e-300)
    assert drift["energy"] < 1e-8  # the reference integration conserves energy


def test_invariants_reference_is_first_given_time_for_unsorted_t(racket):
    perm = np.random.default_rng(1).permutation(len(racket.t))
    perm = np.concatenate([[100], perm[perm != 100]])  # t[0] is a mid-trajectory time
    tr = Trajectory(racket.t[perm], racket.quaternion[perm], racket.omega[perm], racket.body, method="m")
    one = plots.select_body(tr)
    assert np.all(np.diff(one.t) > 0)
    curves = plots.invariant_drift(one)
    assert curves["E"][100] == 0.0  # sorted position of the reference sample
    assert np.max(curves["E"]) == pytest.approx(tr.drift()["energy"], rel=1e-12)


# ---------------------------------------------------------------------------
# omega, attitude, gibbs pictures
# ---------------------------------------------------------------------------
def test_plot_omega_data_labels_and_racket_flips(racket):
    fig = plots.plot_omega(racket, linewidth=2.0)
    ax = fig.axes[0]
    lines = _lines_by_label(ax)
    for i in range(3):
        ln = lines[f"Ω{'₁₂₃'[i]}"]
        np.testing.assert_array_equal(ln.get_xdata(), racket.t)
        np.testing.assert_array_equal(ln.get_ydata(), racket.omega[:, i])
        assert ln.get_linewidth() == 2.0
    # the tennis racket: Omega_2 turns over twice in 150 s (at about 37 s and 113 s)
    w2 = racket.omega[:, 1]
    flips = racket.t[1:][np.sign(w2[1:]) != np.sign(w2[:-1])]
    assert len(flips) == 2 and 30 < flips[0] < 45 and 105 < flips[1] < 120
    assert ax.get_xlabel() == "time t [s]" and "[rad/s]" in ax.get_ylabel()
    title = ax.get_title()
    assert "tennis racket" in title and "I = (3, 5, 7)" in title and "dop853-reference" in title


def test_plot_attitude_traces_axes_and_m():
    w = 0.9
    tr = spin(w=w, T=101)
    fig = plots.plot_attitude(tr)
    ax = fig.axes[0]
    lines = _lines_by_label(ax)
    R = matrix_from_quaternion(tr.quaternion)
    for i in range(3):
        xyz = np.array(lines[next(k for k in lines if k.startswith(f"axis {i + 1} "))].get_data_3d()).T
        np.testing.assert_allclose(xyz, R[:, :, i], atol=1e-15)
    # the spin axis stays at z = m/|m|; axis 1 goes round the equator
    star = next(c for c in ax.collections if c.get_label() == "m/|m| (fixed)")
    np.testing.assert_allclose(np.array(star._offsets3d).ravel(), [0, 0, 1], atol=1e-15)
    assert ax.get_xlabel() == "x [dimensionless]" and "in the space frame" in ax.get_title()


def test_plot_gibbs_marks_restarts(racket):
    fig = plots.plot_gibbs(racket, chart_radius=1.0)
    ax = fig.axes[0]
    nseg = len(plots.chart_segments(racket.quaternion, 1.0))
    restarts = next(c for c in ax.collections if c.get_label().startswith("chart restart"))
    assert f"({nseg - 1}×)" in restarts.get_label()
    pts = np.array(restarts._offsets3d).T
    assert pts.shape == (nseg - 1, 3)
    assert np.all(np.linalg.norm(pts, axis=1) > 1.0)
    assert "dimensionless" in ax.get_xlabel()
    assert len(fig.axes) == 2  # the colour bar of chart start times
    with pytest.raises(InvalidInputError, match="chart_radius"):
        plots.plot_gibbs(racket, chart_radius=-1)


# ---------------------------------------------------------------------------
# files, dispatch, batches, errors
# ---------------------------------------------------------------------------
MAGIC = {"png": b"\x89PNG\r\n\x1a\n", "pdf": b"%PDF", "svg": b"<?xml"}


@pytest.mark.parametrize(
    "kind,fmt", [("omega", "svg"), ("invariants", "pdf"), ("polhode", "png"), ("gibbs", "png"), ("attitude", "png")]
)
def test_plot_writes_files_atomically(racket, tmp_path, kind, fmt):
    out = tmp_path / "sub" / f"{kind}.{fmt}"
    fig = plots.plot(racket, kind, out=out, dpi=40)
    assert out.read_bytes()[: len(MAGIC[fmt])] == MAGIC[fmt]
    assert os.listdir(out.parent) == [out.name]  # no temporary file left
    assert (out.stat().st_mode & 0o777) == 0o644
    if fmt == "png":
        img = matplotlib.image.imread(out)
        w, h = fig.get_size_inches() * 40
        assert img.shape[:2] == (round(h), round(w))
        # not a blank image
        assert np.std(img[..., :3]) > 0.05


def test_plot_failed_save_keeps_old_file(racket, tmp_path, monkeypatch):
    out = tmp_path / "omega.png"
    out.write_bytes(b"old")

    def boom(self, *a, **k):
        raise RuntimeError("disk full")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        plots.plot(racket, "omega", out=out)
    assert out.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["omega.png"]


def test_plot_all(racket, tmp_path):
    paths = plots.plot_all(spin(T=51), tmp_path, fmt="svg", prefix="r_", dpi=30)
    assert set(paths) == set(plots.KINDS)
    assert sorted(os.listdir(tmp_path)) == sorted(f"r_{k}.svg" for k in plots.KINDS)
    with pytest.raises(InvalidInputError, match="fmt='jpg' is not supported"):
        plots.plot_all(racket, tmp_path, fmt="jpg")


def test_batched_trajectory_index(racket):
    t = racket.t[:300]
    q2, w2 = reference_motion([1.0, 2.0, 2.5], [0.1, 0.2, 0.3], np.array([1.0, 0, 0, 0]), t)
    body = RigidBody(np.array([RACKET_I, [1.0, 2.0, 2.5]]))
    tr = Trajectory(t, np.stack([racket.quaternion[:300], q2]), np.stack([racket.omega[:300], w2]), body, method="b")
    fig = plots.plot_omega(tr, index=1)
    np.testing.assert_array_equal(_lines_by_label(fig.axes[0])["Ω₂"].get_ydata(), w2[:, 1])
    assert "I = (1, 2, 2.5)" in fig.axes[0].get_title()
    fig = plots.plot(tr, "polhode", index=(0,))
    assert "I = (3, 5, 7)" in fig.axes[0].get_title()
    for bad in (2, -3, (0, 1), 1.0, "0", True):
        with pytest.raises(InvalidInputError, match="index"):
            plots.plot_omega(tr, index=bad)
    with pytest.raises(InvalidInputError, match="index=1 given for a trajectory of one body"):
        plots.plot_omega(racket, index=1)


def test_draw_into_given_axes_and_figure(racket):
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot(1, 2, 1)
    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    assert plots.plot_omega(racket, ax=ax) is fig
    assert plots.plot_attitude(racket, ax=ax3) is fig
    assert len(ax.get_lines()) >= 3
    fig2 = Figure()
    assert plots.plot_gibbs(racket, fig=fig2) is fig2
    with pytest.raises(InvalidInputError, match="projection='3d'"):
        plots.plot_polhode(racket, ax=ax)
    with pytest.raises(InvalidInputError, match="2-D: ax must not be a 3-D axes"):
        plots.plot_invariants(racket, ax=ax3)
    with pytest.raises(InvalidInputError, match="ax must be a matplotlib Axes"):
        plots.plot_omega(racket, ax="left")
    with pytest.raises(InvalidInputError, match="fig must be a matplotlib Figure"):
        plots.plot_omega(racket, fig=42)


def test_plot_errors(racket, tmp_path):
    with pytest.raises(InvalidInputError, match="unknown plot kind 'nutation'; available kinds: omega"):
        plots.plot(racket, "nutation")
    with pytest.raises(InvalidInputError, match=r"unsupported file extension '\.jpg'; use one of \.png"):
        plots.plot(racket, "omega", out=tmp_path / "x.jpg")
    assert not (tmp_path / "x.jpg").exists()
    with pytest.raises(TypeError, match="out must be a file name"):
        plots.plot(racket, "omega", out=3)
    with pytest.raises(TypeError, match="traj must be an eulerpoisson Trajectory, got dict"):
        plots.plot({"t": [0, 1]}, "omega")
    one_time = Trajectory([0.0], [[1.0, 0, 0, 0]], [[0.0, 1.0, 0]], RigidBody([1.0, 2.0, 2.5]))
    with pytest.raises(InvalidInputError, match="at least two distinct times"):
        plots.plot(one_time, "omega")


def test_missing_matplotlib_is_reported(racket, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(MissingDependencyError, match=r"eulerpoisson\[plot\]"):
        plots.plot_omega(racket)


def test_body_at_rest_and_time_unit():
    t = np.linspace(0, 1, 11)
    q = np.tile([1.0, 0, 0, 0], (11, 1))
    tr = Trajectory(t, q, np.zeros((11, 3)), RigidBody([1.0, 2.0, 2.5], name="brick"), options={"time_unit": "min"})
    for kind in plots.KINDS:
        fig = plots.plot(tr, kind)
        assert "brick" in fig.axes[0].get_title()
    fig = plots.plot_omega(tr)
    assert fig.axes[0].get_xlabel() == "time t [min]" and "[rad/min]" in fig.axes[0].get_ylabel()


def test_exact_solver_pictures_if_available():
    from eulerpoisson.solvers import solve

    tr = solve(RACKET_I, np.linspace(0, 150, 601), omega0=RACKET_OMEGA0, method="exact")
    curves = plots.invariant_drift(plots.select_body(tr))
    for key, c in curves.items():
        assert np.max(c) < 1e-12, key  # exact solution: round-off-level drift
