"""Bad inputs to Trajectory (and its files), flip_times, the elliptic parameters and RigidBody.

Every error path raises a specific exception naming the argument (or file), its value or
shape and what was expected; the fixes that scale by powers of two are checked against
exact homogeneity and closed forms.
"""

import re
import warnings

import numpy as np
import pytest

from eulerpoisson import RigidBody
from eulerpoisson.analysis import elliptic_parameters, flip_times, momentum_period, tennis_racket_half_period
from eulerpoisson.errors import EulerPoissonError, InvalidInertiaError, InvalidInputError
from eulerpoisson.solvers import solve
from eulerpoisson.trajectory import Trajectory

I123 = [1.0, 2.0, 3.0]
W0 = [0.1, 1.0, 0.05]
TINY = np.finfo(float).tiny


# ---------------------------------------------------------------------------
# Trajectory.from_netcdf on malformed files
# ---------------------------------------------------------------------------
@pytest.fixture
def good_ds():
    pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    tr = solve(I123, np.linspace(0.0, 2.0, 3), omega0=W0)
    return tr.to_xarray()


def _write(ds, path):
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def _match(path, text):
    return re.escape(str(path)) + ".*" + text


def test_from_netcdf_missing_variable(good_ds, tmp_path):
    p = _write(good_ds.drop_vars("inertia"), tmp_path / "noinertia.nc")
    with pytest.raises(InvalidInputError, match=_match(p, r"\['inertia'\] missing")):
        Trajectory.from_netcdf(p)


@pytest.mark.parametrize(
    "key, value, text",
    [
        ("batch_shape", "[7]", r"variable quaternion has shape \(3, 4\), expected \(7, 3, 4\)"),
        ("batch_shape", "[2, 3", "attribute batch_shape is not valid JSON"),
        ("batch_shape", "[1.5]", "batch_shape must be a JSON list of non-negative integers"),
        ("batch_shape", "{}", "batch_shape must be a JSON list"),
        ("eulerpoisson_format_version", "abc", "eulerpoisson_format_version must be a positive integer, got 'abc'"),
        ("eulerpoisson_format_version", 0, "eulerpoisson_format_version must be a positive integer"),
        ("eulerpoisson_format_version", 1.5, "eulerpoisson_format_version must be a positive integer"),
        ("method_options", "{not json", "attribute method_options is not valid JSON"),
        ("stats", "[1, 2]", "attribute stats must be a JSON object"),
    ],
)
def test_from_netcdf_bad_attributes(good_ds, tmp_path, key, value, text):
    ds = good_ds.copy()
    ds.attrs[key] = value
    p = _write(ds, tmp_path / "bad.nc")
    with pytest.raises(InvalidInputError, match=_match(p, text)):
        Trajectory.from_netcdf(p)


def test_from_netcdf_bad_values_name_the_file(good_ds, tmp_path):
    ds = good_ds.copy(deep=True)
    ds["quaternion"].values[:] = np.nan
    p = _write(ds, tmp_path / "nanq.nc")
    with pytest.raises(InvalidInputError, match=_match(p, "quaternion contains NaN")):
        Trajectory.from_netcdf(p)
    ds = good_ds.copy(deep=True)
    ds["inertia"].values[:] = -np.eye(3)
    p = _write(ds, tmp_path / "neg.nc")
    with pytest.raises(InvalidInertiaError, match=_match(p, "not positive definite")):
        Trajectory.from_netcdf(p)
    # an edited (here non-physical) inertia no longer matches the stored M = I Omega
    ds = good_ds.copy(deep=True)
    ds["inertia"].values[:] = np.diag([1.0, 1.0, 5.0])
    p = _write(ds, tmp_path / "edited.nc")
    with pytest.raises(InvalidInputError, match=_match(p, "inconsistent file: the stored body angular momentum M")):
        Trajectory.from_netcdf(p)


@pytest.mark.parametrize("arg", [None, 123, 1.5, ["a.nc"]])
def test_from_netcdf_path_type(arg):
    with pytest.raises(TypeError, match="path must be a file name"):
        Trajectory.from_netcdf(arg)


def test_from_netcdf_good_files_round_trip_bit_exact(tmp_path):
    pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    tr = solve(
        RigidBody.from_moments([[1.0, 2.0, 2.5], [2.0, 2.0, 3.0]]),
        np.linspace(0, 2, 4),
        omega0=[[0.3, -1.0, 0.2], [1.0, 0.5, 0.1]],
    )
    tr.to_netcdf(tmp_path / "b.nc")
    back = Trajectory.from_netcdf(tmp_path / "b.nc")
    for a in ("t", "quaternion", "omega"):
        np.testing.assert_array_equal(getattr(back, a), getattr(tr, a))
    np.testing.assert_array_equal(back.body.inertia, tr.body.inertia)
    # an empty trajectory is a valid file too
    te = solve(I123, [], omega0=W0)
    te.to_netcdf(tmp_path / "e.nc")
    be = Trajectory.from_netcdf(tmp_path / "e.nc")
    assert len(be) == 0 and repr(be) == "Trajectory(method='exact', T=0, t=[])"


def test_from_netcdf_not_a_trajectory_still_eulerpoisson_error(tmp_path):
    bad = tmp_path / "junk.nc"
    bad.write_text("hello")
    with pytest.raises(EulerPoissonError, match="not a readable NetCDF"):
        Trajectory.from_netcdf(bad)


# ---------------------------------------------------------------------------
# Trajectory constructor, empty trajectories
# ---------------------------------------------------------------------------
def test_zero_dimensional_time_rejected():
    with pytest.raises(InvalidInputError, match=r"t must be a 1-D array of output times, shape \(T,\); got shape \(\)"):
        Trajectory(0.0, [1, 0, 0, 0], [0, 0, 0], RigidBody(I123))
    with pytest.raises(InvalidInputError, match=r"t must be a 1-D.*got shape \(1, 2\)"):
        Trajectory([[0.0, 1.0]], [[1, 0, 0, 0]] * 2, [[0, 0, 0]] * 2, RigidBody(I123))


def test_empty_trajectory_repr_and_drift():
    tr = solve(I123, [], omega0=[1.0, 0.0, 0.0])
    assert repr(tr) == "Trajectory(method='exact', T=0, t=[])"
    assert tr.energy.shape == (0,) and tr.m.shape == (0, 3)
    with pytest.raises(InvalidInputError, match=r"no output times \(T = 0\)"):
        tr.drift()
    tb = solve([[1.0, 2.0, 3.0], [1.0, 2.0, 2.5]], [], omega0=[1.0, 0.0, 0.0])
    assert repr(tb) == "Trajectory(method='exact', T=0, t=[], batch_shape=(2,))"
    with pytest.raises(InvalidInputError, match="no output times"):
        tb.drift()
    te = Trajectory([], np.zeros((0, 4)), np.zeros((0, 3)), RigidBody(I123))
    assert "T=0, t=[]" in repr(te)


def test_trajectory_argument_types():
    q, w = [[1.0, 0, 0, 0]] * 2, [[0.0, 0, 0]] * 2
    with pytest.raises(TypeError, match="body must be a RigidBody, got str 'x'"):
        Trajectory([0, 1], q, w, body="x")
    with pytest.raises(InvalidInputError, match=r"body's batch shape \(5,\) does not broadcast.*batch shape \(\)"):
        Trajectory([0, 1], q, w, RigidBody([I123] * 5))
    with pytest.raises(TypeError, match="method must be a string"):
        Trajectory([0, 1], q, w, RigidBody(I123), method=3)
    with pytest.raises(TypeError, match="options must be a dict"):
        Trajectory([0, 1], q, w, RigidBody(I123), options="abc")
    # a single body broadcasts over a batch of states
    tr = Trajectory([0, 1], [q, q], [w, w], RigidBody(I123))
    assert tr.batch_shape == (2,) and tr.energy.shape == (2, 2)


# ---------------------------------------------------------------------------
# flip_times
# ---------------------------------------------------------------------------
def test_flip_at_an_exactly_zero_sample():
    # Omega_3(0) = 0 exactly, and Omega_3 changes sign there; flips every half period 2K/lambda
    tr = solve(I123, np.linspace(-20.0, 20.0, 41), omega0=[0.1, 1.0, 0.0])
    assert tr.omega[20, 2] == 0.0
    half = tennis_racket_half_period(I123, np.array(I123) * [0.1, 1.0, 0.0])
    flips = flip_times(tr, 2)
    np.testing.assert_allclose(flips, [-half, 0.0, half], rtol=1e-12, atol=1e-12)
    rough = flip_times(tr, 2, refine=False)
    assert rough.size == 3 and rough[1] == 0.0  # the zero sample itself
    np.testing.assert_allclose(rough[[0, 2]], [-half, half], rtol=1e-2)


def _synthetic(values):
    n = len(values)
    w = np.zeros((n, 3))
    w[:, 1] = values
    return Trajectory(np.arange(float(n)), np.tile([1.0, 0, 0, 0], (n, 1)), w, RigidBody(I123))


@pytest.mark.parametrize(
    "values, expected",
    [
        ([1.0, 0.0, 1.0], []),  # a touch: no sign change
        ([-1.0, 0.0, 0.0, 1.0], [1.5]),  # a run of zeros between opposite signs: one flip, mid-run
        ([0.0, 1.0, -1.0], [1.5]),  # a leading zero is not a flip
        ([1.0, -1.0, 0.0], [0.5]),  # nor a trailing one
        ([0.0, 0.0, 0.0], []),
        ([1.0, 0.0, -1.0, 0.0, 1.0], [1.0, 3.0]),
        ([2.0, -1.0, -3.0, 1.0], [2.0 / 3.0, 2.75]),  # linear interpolation, no zeros
    ],
)
def test_flip_zero_rules(values, expected):
    np.testing.assert_allclose(flip_times(_synthetic(values), 1, refine=False), expected, rtol=0, atol=1e-15)


def test_flip_times_argument_checks():
    tr = solve(I123, np.linspace(0.0, 10.0, 11), omega0=W0)
    with pytest.raises(TypeError, match="component must be an integer 0, 1 or 2, got float 1.0"):
        flip_times(tr, component=1.0)
    with pytest.raises(TypeError, match="component must be an integer 0, 1 or 2, got bool True"):
        flip_times(tr, component=True)
    with pytest.raises(TypeError, match="component must be an integer"):
        flip_times(tr, component=np.True_)
    with pytest.raises(InvalidInputError, match="component must be 0, 1 or 2, got 3"):
        flip_times(tr, component=3)
    with pytest.raises(TypeError, match="flip_times takes a Trajectory.*got str 'x'"):
        flip_times("x")
    with pytest.raises(TypeError, match="refine must be True or False"):
        flip_times(tr, refine="no")
    # numpy integers are integers
    np.testing.assert_array_equal(flip_times(tr, np.int64(1), refine=False), flip_times(tr, 1, refine=False))


# ---------------------------------------------------------------------------
# elliptic_parameters / momentum_period
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("inertia", [[-1.0, 2.0, 3.0], [0.0, 2.0, 3.0]])
def test_elliptic_inertia_validated(inertia):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidInertiaError, match=r"inertia is not positive definite: principal moments \["):
            momentum_period(inertia, [1.0, 0.1, 0.5])
        with pytest.raises(InvalidInertiaError, match="not positive definite"):
            elliptic_parameters(inertia, [1.0, 0.1, 0.5])


def test_elliptic_bad_arguments():
    with pytest.raises(InvalidInertiaError, match="below the smallest normal float64"):
        elliptic_parameters([5e-324, 2.0, 3.0], [1.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match=r"M0 contains NaN or infinite values"):
        elliptic_parameters(I123, [1.0, 0.0, np.nan])
    with pytest.raises(InvalidInputError, match=r"M0 must have shape \(\.\.\., 3\), got shape \(2,\)"):
        elliptic_parameters(I123, [1.0, 0.0])
    with pytest.raises(InvalidInputError, match=r"one body.*got shapes \(1, 3\) and \(3,\)"):
        elliptic_parameters([I123], [1.0, 0.0, 0.0])
    # the unphysical (3, 5, 9) racket stays accepted (no triangle inequality required)
    assert elliptic_parameters([3.0, 5.0, 9.0], [0.0, 2.0, 0.01])["axis"] == 2


@pytest.mark.parametrize("a", [1e200, 1e-200, 2.0**1000, 2.0**-1000])
def test_elliptic_parameters_scale_instead_of_overflow(a):
    # M = (a, 0, a), I = (1, 2, 3): L^2 = 2a^2, 2E = 4a^2/3, 2E I2 > L^2 (circulation about axis 1):
    # k^2 = (I3-I2)(L^2-2E I1)/((I2-I1)(2E I3-L^2)) = 1/3, lambda = sqrt((I2-I1)(2E I3-L^2)/(I1 I2 I3)) = a/sqrt(3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = elliptic_parameters(I123, [a, 0.0, a])
        T = momentum_period(I123, [a, 0.0, a])
    assert abs(p["k2"] - 1.0 / 3.0) <= 4e-16 and abs(p["k2c"] - 2.0 / 3.0) <= 4e-16
    assert abs(p["lam"] - a / np.sqrt(3.0)) <= 1e-15 * a / np.sqrt(3.0)
    assert abs(T * a - momentum_period(I123, [1.0, 0.0, 1.0])) <= 1e-15 * T * a


def test_elliptic_parameters_exact_homogeneity(rng):
    for _ in range(20):
        I = np.sort(rng.uniform(1.0, 3.0, 3))
        M = rng.standard_normal(3)
        p = elliptic_parameters(I, M)
        for eI, eM in ((0, 900), (0, -900), (700, 300), (-600, -900)):
            q = elliptic_parameters(np.ldexp(I, eI), np.ldexp(M, eM))
            assert q["k2"] == p["k2"] and q["k2c"] == p["k2c"]
            assert q["lam"] == np.ldexp(p["lam"], eM - eI)


def test_elliptic_out_of_range_is_an_error():
    with pytest.raises(InvalidInputError, match="not representable in float64"):
        elliptic_parameters([1e-300, 2e-300, 3e-300], [1e200, 0.0, 1e200])  # lambda ~ 1e500
    # lambda ~ 3e-308 is representable, the period 4K/lambda ~ 2e308 is not
    with pytest.raises(InvalidInputError, match="the period 4 K.*overflows float64"):
        momentum_period([1e300, 2e300, 3e300], [5.2e-8, 0.0, 5.2e-8])


# ---------------------------------------------------------------------------
# RigidBody
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("inertia", [[5e-324] * 3, np.eye(3) * 1e-310, [1e-310, 1.0, 1.0]])
def test_subnormal_moments_rejected(inertia):
    with pytest.raises(InvalidInertiaError, match=r"below the smallest normal float64.*principal moments \["):
        RigidBody(inertia, allow_unphysical=True)


def test_smallest_normal_moment_has_finite_inverse():
    b = RigidBody([TINY] * 3)
    assert np.all(np.isfinite(b.inertia_inv)) and b.inertia_inv[0, 0] == 1.0 / TINY


@pytest.mark.parametrize("value", ["yes", 1, 0, None, "False"])
def test_allow_unphysical_must_be_bool(value):
    with pytest.raises(TypeError, match="allow_unphysical must be True or False"):
        RigidBody(I123, allow_unphysical=value)
    with pytest.raises(TypeError, match="allow_unphysical must be True or False"):
        RigidBody.from_moments(I123, allow_unphysical=value)


def test_allow_unphysical_numpy_bool():
    assert RigidBody([3.0, 5.0, 9.0], allow_unphysical=np.True_).kind == "asymmetric"
    with pytest.raises(InvalidInertiaError, match="triangle inequality"):
        RigidBody([3.0, 5.0, 9.0], allow_unphysical=np.False_)


@pytest.mark.parametrize("shape", [(0, 3), (0, 3, 3), (2, 0, 3)])
def test_empty_batch_rejected(shape):
    with pytest.raises(InvalidInputError, match=r"inertia is an empty batch of shape .*at least one body"):
        RigidBody(np.zeros(shape))
    if shape[-1] == 3 and len(shape) != 3 or shape == (2, 0, 3):
        with pytest.raises(InvalidInputError, match="moments is an empty batch"):
            RigidBody.from_moments(np.zeros(shape))


def test_huge_tensors_are_scaled_not_nan(rng):
    R = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    base = R @ np.diag([1.0, 2.0, 2.5]) @ R.T
    ref = RigidBody(base)
    for e in (1000, -1000, 1021):
        b = RigidBody(np.ldexp(base, e))
        np.testing.assert_allclose(b.principal_moments, np.ldexp([1.0, 2.0, 2.5], e), rtol=1e-14)
        np.testing.assert_array_equal(b.principal_axes, ref.principal_axes)
        assert np.all(np.isfinite(b.inertia_inv)) and np.all(np.isfinite(b.mass_matrix))
        np.testing.assert_array_equal(b.mass_matrix, np.ldexp(ref.mass_matrix, e))
    big = RigidBody([1e308, 1.2e308, 1.5e308])
    assert big.kind == "asymmetric" and not big.is_planar
    with pytest.raises(InvalidInertiaError, match="triangle inequality"):
        RigidBody([1e307, 1e307, 1.7e308])
    # negative definite and huge: the message shows the moments, not inf
    with pytest.raises(InvalidInertiaError, match=r"principal moments \[-3e\+300, 1e\+300, 3e\+300\]"):
        RigidBody(np.array([[2.0, 1.0, 0], [1.0, 2.0, 0], [0, 0, -3.0]]) * 1e300)


def test_from_particles_scales_exactly(rng):
    m = rng.uniform(0.5, 2.0, 4)
    x = rng.standard_normal((4, 3))
    ref = RigidBody.from_particles(m, x)
    # I(s x, mu m) = mu s^2 I(x, m), exact for powers of two, far outside the range where m x x fits
    for em, ex in ((-1000, 660), (1000, -600), (-1000, -10), (900, 60)):
        b = RigidBody.from_particles(np.ldexp(m, em), np.ldexp(x, ex))
        np.testing.assert_array_equal(b.inertia, np.ldexp(ref.inertia, em + 2 * ex))
        np.testing.assert_array_equal(b.positions, np.ldexp(ref.positions, ex))
        np.testing.assert_array_equal(b.center_of_mass, np.ldexp(ref.center_of_mass, ex))


def test_from_particles_out_of_range_messages():
    pos = np.eye(3)
    with pytest.raises(
        InvalidInputError, match=r"overflows float64 \(masses up to 1 and positions .* up to 6\.66667e\+199"
    ):
        RigidBody.from_particles([1.0, 1.0, 1.0], 1e200 * pos)
    with pytest.raises(InvalidInputError, match=r"underflows float64 .*positions relative to the centre of mass"):
        RigidBody.from_particles([1.0, 1.0, 1.0], 1e-200 * pos)
    with pytest.raises(InvalidInputError, match="overflows float64"):
        RigidBody.from_particles([1.0, 1.0, 1.0], 1e154 * pos)  # entries fit, the largest moment does not


@pytest.mark.parametrize("where", ["quaternion", "omega"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_stored_attitudes_refuses_a_non_finite_value_of_a_few_samples(where, bad):
    # (a few samples are checked in plain floats, the rest by as_float_array: the same errors)
    from eulerpoisson.trajectory import stored_attitudes

    t = np.array([0.0, 1.0])
    q = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
    w = np.ones((2, 3))
    (q if where == "quaternion" else w)[1, 2] = bad
    with pytest.raises(InvalidInputError, match=f"{where} contains NaN or infinite values"):
        stored_attitudes(t, q, w)


def test_stored_attitudes_of_huge_finite_values_is_the_checked_result():
    # finite values whose sum overflows: the checked path stores them, it does not refuse them
    from eulerpoisson.trajectory import stored_attitudes

    t = np.array([0.0, 1.0])
    q = np.array([[2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, -3.0]])
    w = np.full((2, 3), 1e308)
    got = stored_attitudes(t, q, w)
    assert np.array_equal(got, Trajectory(t, q, w, RigidBody([1.0, 2.0, 3.0])).quaternion)
    assert np.array_equal(got, [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, -1.0]])
