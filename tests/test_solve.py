"""The solve driver, the Trajectory object and its files."""

import json

import numpy as np
import pytest

import eulerpoisson as ep
from _reference import quaternion_distance, reference_motion
from eulerpoisson import Attitude, RigidBody
from eulerpoisson.errors import EulerPoissonError, InvalidInertiaError, InvalidInputError
from eulerpoisson.solvers import available_methods, solve
from eulerpoisson.trajectory import Trajectory

I123 = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]


def random_rotation(rng):
    return Attitude.random(rng=rng).as_matrix()


# ---------------------------------------------------------------------------
# argument checking
# ---------------------------------------------------------------------------
def test_exactly_one_initial_condition():
    with pytest.raises(TypeError, match="exactly one of omega0"):
        solve(I123, 1.0)
    with pytest.raises(TypeError, match="exactly one of omega0"):
        solve(I123, 1.0, omega0=W0, m0=W0)


def test_unknown_method_and_option():
    with pytest.raises(InvalidInputError, match="unknown method 'nope'; available methods: .*exact"):
        solve(I123, 1.0, omega0=W0, method="nope")
    with pytest.raises(TypeError, match="solve\\(\\) got an unexpected keyword argument .bogus."):
        solve(I123, 1.0, omega0=W0, bogus=3)


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        (dict(t=[[0.0, 1.0]]), InvalidInputError, "1-D array"),
        (dict(omega0=[1.0, np.nan, 0.0]), InvalidInputError, "omega0 contains NaN"),
        (dict(omega0=[1.0, 2.0]), InvalidInputError, r"omega0 must have shape \(\.\.\., 3\)"),
        (dict(t=[0.0, np.inf]), InvalidInputError, "t contains NaN or infinite"),
        (dict(attitude0=[1.0, 0.1, 0.0, 0.0]), InvalidInputError, "unit quaternion"),
        (dict(body=[1.0, 1.0, 3.0]), InvalidInertiaError, "triangle inequality"),
        (dict(body=[1.0, -1.0, 1.0]), InvalidInertiaError, "positive definite"),
        (dict(body="abc"), TypeError, "RigidBody or an inertia array"),
        (dict(t="1.0"), TypeError, "t must be numeric"),
    ],
)
def test_bad_arguments(kwargs, exc, match):
    args = dict(body=I123, t=[0.0, 1.0], omega0=W0)
    args.update(kwargs)
    body = args.pop("body")
    t = args.pop("t")
    with pytest.raises(exc, match=match):
        solve(body, t, **args)


def test_registry_lists_exact():
    assert "exact" in available_methods()


# ---------------------------------------------------------------------------
# the exact method through the driver, against an independent integration
# ---------------------------------------------------------------------------
def test_exact_matches_reference_full_tensor_and_attitude(rng):
    R = random_rotation(rng)
    I = R @ np.diag([1.3, 2.1, 2.9]) @ R.T
    q0 = Attitude.random(rng=rng).as_quaternion()
    w0 = rng.standard_normal(3)
    t = np.array([3.0, -2.0, 0.0, 7.5, 1.0])  # unsorted, negative
    tr = solve(I, t, omega0=w0, attitude0=q0)
    qr, wr = reference_motion(I, w0, q0, t)
    assert np.max(quaternion_distance(tr.quaternion, qr)) < 1e-10
    assert np.max(np.abs(tr.omega - wr)) < 1e-10 * np.max(np.abs(wr))
    np.testing.assert_allclose(tr.t, t)


def test_m0_equals_omega0(rng):
    body = RigidBody([1.0, 2.0, 2.5])
    q0 = Attitude.random(rng=rng)
    w0 = np.array([0.3, -0.7, 1.1])
    m0 = q0.apply(body.angular_momentum(w0))
    t = np.linspace(0, 5, 7)
    a = solve(body, t, omega0=w0, attitude0=q0)
    b = solve(body, t, m0=m0, attitude0=q0)
    np.testing.assert_allclose(a.omega, b.omega, rtol=1e-13, atol=1e-14)
    assert np.max(quaternion_distance(a.quaternion, b.quaternion)) < 1e-13


def test_integrals_constant_and_m_matches(rng):
    body = RigidBody([1.0, 2.0, 3.0])
    tr = solve(body, np.linspace(0, 50, 201), omega0=W0)
    d = tr.drift()
    assert set(d) == {"energy", "m_norm", "m_x", "m_y", "m_z"}
    assert max(d.values()) < 1e-13
    np.testing.assert_allclose(tr.m[0], body.angular_momentum(W0), atol=1e-15)


def test_batch_equals_single(rng):
    inertia = np.array([[1.0, 2.0, 3.0], [2.0, 2.0, 3.0], [1.5, 1.7, 3.1]])
    w0 = rng.standard_normal((3, 3))
    q0 = Attitude.random(3, rng=rng).as_quaternion()
    t = np.linspace(-4, 9, 11)
    batch = solve(RigidBody.from_moments(inertia), t, omega0=w0, attitude0=q0)
    assert batch.quaternion.shape == (3, 11, 4) and batch.omega.shape == (3, 11, 3)
    for i in range(3):
        one = solve(inertia[i], t, omega0=w0[i], attitude0=q0[i])
        np.testing.assert_allclose(batch.omega[i], one.omega, rtol=0, atol=1e-15)
        assert np.max(quaternion_distance(batch.quaternion[i], one.quaternion)) < 1e-15


def test_scalar_time_and_identity_default():
    tr = solve(I123, 0.0, omega0=W0)
    assert tr.t.shape == (1,)
    np.testing.assert_allclose(tr.quaternion[0], [1, 0, 0, 0], atol=1e-16)
    np.testing.assert_allclose(tr.omega[0], W0, atol=1e-16)


def test_quaternion_sign_is_continuous():
    tr = solve(I123, np.linspace(0, 40, 2001), omega0=[0.2, 3.0, 0.1])
    q = tr.quaternion
    assert np.all(np.sum(q[1:] * q[:-1], -1) > 0)


# ---------------------------------------------------------------------------
# Trajectory views
# ---------------------------------------------------------------------------
def test_gibbs_nan_and_flag_at_pi():
    body = RigidBody(I123)
    q = np.array([[1.0, 0, 0, 0], [0.0, 0.0, 0.0, 1.0], [np.cos(0.3), 0, np.sin(0.3), 0]])
    tr = Trajectory([0.0, 1.0, 2.0], q, np.zeros((3, 3)), body, "test")
    assert tr.gibbs_singular.tolist() == [False, True, False]
    assert np.all(np.isnan(tr.gibbs[1]))
    np.testing.assert_allclose(tr.gibbs[2], [0, np.tan(0.3), 0])


def test_trajectory_shape_check():
    with pytest.raises(InvalidInputError, match="inconsistent trajectory shapes"):
        Trajectory([0.0, 1.0], np.ones((3, 4)), np.ones((3, 3)), RigidBody(I123))


def test_particles_follow_eq_1_2(rng):
    masses = rng.uniform(0.5, 2.0, 5)
    pos = rng.standard_normal((5, 3))
    body = RigidBody.from_particles(masses, pos)
    t = np.linspace(0, 3, 5)
    tr = solve(body, t, omega0=[0.4, -1.0, 0.7])
    C0 = np.array([1.0, 2.0, 3.0])
    V0 = np.array([0.1, 0.0, -0.2])
    y = tr.particles(C0, V0)
    assert y.shape == (5, 5, 3)
    # eq. 1.2: y_N(t) = C0 + V0 t + R(t) x_N(0)
    np.testing.assert_allclose(y[0], C0 + body.positions, atol=1e-14)
    d0 = np.linalg.norm(y[0][:, None] - y[0][None], axis=-1)
    for k in range(5):
        dk = np.linalg.norm(y[k][:, None] - y[k][None], axis=-1)
        np.testing.assert_allclose(dk, d0, atol=1e-13)  # the constraints of eq. 1.1 hold
        com = (masses[:, None] * y[k]).sum(0) / masses.sum()
        np.testing.assert_allclose(com, C0 + V0 * t[k], atol=1e-14)
    with pytest.raises(InvalidInputError, match="no particles"):
        solve(I123, t, omega0=W0).particles()


# ---------------------------------------------------------------------------
# files
# ---------------------------------------------------------------------------
def test_netcdf_round_trip(tmp_path, rng):
    R = random_rotation(rng)
    body = RigidBody(R @ np.diag([1.0, 2.0, 2.5]) @ R.T, name="probe")
    tr = solve(body, np.linspace(0, 10, 21), omega0=[0.5, 1.0, -0.3])
    path = tmp_path / "run.nc"
    tr.to_netcdf(path)
    back = Trajectory.from_netcdf(path)
    np.testing.assert_array_equal(back.t, tr.t)
    np.testing.assert_array_equal(back.quaternion, tr.quaternion)
    np.testing.assert_array_equal(back.omega, tr.omega)
    np.testing.assert_allclose(back.body.inertia, body.inertia, rtol=0, atol=1e-15)
    assert back.method == "exact" and back.body.name == "probe"
    ds = tr.to_xarray()
    assert ds["omega"].attrs["units"] == "rad s-1"
    assert ds.attrs["eulerpoisson_version"] == ep.__version__
    assert "scalar first" in ds.attrs["eulerpoisson_conventions"]
    assert not list(tmp_path.glob(".run.nc.*"))  # no temporary file left


def test_netcdf_batch_and_particles_round_trip(tmp_path, rng):
    t = np.linspace(0, 2, 5)
    tr = solve(RigidBody.from_moments([[1.0, 2.0, 2.5], [2.0, 2.0, 3.0]]), t, omega0=rng.standard_normal((2, 3)))
    tr.to_netcdf(tmp_path / "b.nc")
    back = Trajectory.from_netcdf(tmp_path / "b.nc")
    assert back.batch_shape == (2,)
    np.testing.assert_array_equal(back.omega, tr.omega)
    body = RigidBody.from_particles([1.0, 2.0, 3.0], [[0, 0, 0], [1, 0, 0], [0, 1, 0.5]])
    tp = solve(body, t, omega0=[1.0, 0.0, 0.2])
    tp.to_netcdf(tmp_path / "p.nc")
    bp = Trajectory.from_netcdf(tmp_path / "p.nc")
    np.testing.assert_allclose(bp.particles(), tp.particles(), atol=1e-14)


def test_atomic_write_leaves_old_file_on_failure(tmp_path, monkeypatch):
    from eulerpoisson.io.atomic import atomic_path

    path = tmp_path / "keep.txt"
    path.write_text("old")
    with pytest.raises(KeyboardInterrupt):
        with atomic_path(path) as tmp:
            with open(tmp, "w") as fh:
                fh.write("half")
            raise KeyboardInterrupt
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_from_netcdf_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        Trajectory.from_netcdf(tmp_path / "missing.nc")
    bad = tmp_path / "bad.nc"
    bad.write_text("not a netcdf file")
    with pytest.raises(EulerPoissonError, match="not a readable NetCDF"):
        Trajectory.from_netcdf(bad)
    import xarray as xr

    other = tmp_path / "other.nc"
    xr.Dataset({"x": ("a", np.arange(3.0))}).to_netcdf(other, engine="h5netcdf")
    with pytest.raises(EulerPoissonError, match="not an eulerpoisson trajectory"):
        Trajectory.from_netcdf(other)
    tr = solve(I123, [0.0, 1.0], omega0=W0)
    ds = tr.to_xarray()
    ds.attrs["eulerpoisson_format_version"] = 99
    newer = tmp_path / "newer.nc"
    ds.to_netcdf(newer, engine="h5netcdf")
    with pytest.raises(EulerPoissonError, match="newer than this eulerpoisson"):
        Trajectory.from_netcdf(newer)


def test_options_and_stats_serialized(tmp_path):
    tr = solve(I123, [0.0, 1.0], omega0=W0)
    ds = tr.to_xarray()
    assert json.loads(ds.attrs["method_options"]) == {}
    assert "wall_time" in json.loads(ds.attrs["stats"])
