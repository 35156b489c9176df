"""Tests of eulerpoisson.attitude: conversions, the paper's matrices (eq. 1.7-1.14), charts, Attitude."""

from __future__ import annotations

import itertools
import warnings

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from eulerpoisson import attitude as at
from eulerpoisson.attitude import Attitude
from eulerpoisson.errors import InvalidInertiaError, InvalidInputError, SingularChartError
from eulerpoisson.model.body import RigidBody

try:  # tests/ as a package or as a plain directory on sys.path
    from . import strategies as S
except ImportError:  # pragma: no cover
    import strategies as S

EPS = np.finfo(float).eps
SCIPY_ND = hasattr(Rotation.identity(), "shape")  # scipy >= 1.17: N-D rotation batches
PROP = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
FEW = settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------------------
# helpers (independent of the code under test)
# ---------------------------------------------------------------------------
def qdist(q1, q2):
    """Distance between quaternions up to sign, per batch element."""
    q1 = q1 / np.linalg.norm(q1, axis=-1, keepdims=True)
    q2 = q2 / np.linalg.norm(q2, axis=-1, keepdims=True)
    return np.minimum(np.abs(q1 - q2).max(-1), np.abs(q1 + q2).max(-1))


def np_quat_mul(p, q):
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    return np.concatenate([pw * qw - np.sum(pv * qv, -1, keepdims=True), pw * qv + qw * pv + np.cross(pv, qv)], -1)


def scipy_rot(q):
    return Rotation.from_quat(np.roll(np.asarray(q, float), -1, -1))


def rel_err(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300))


def vec_rel_err(a, b):
    """max over the batch of |a - b| / |b| (vector norms)."""
    return np.max(np.linalg.norm(a - b, axis=-1) / np.linalg.norm(b, axis=-1))


mpmath.mp.dps = 40


def mp_gibbs_from_axis_angle(k, alpha):
    """n = k tan(alpha/2) in 40 digits, for float inputs taken as exact."""
    t = mpmath.tan(mpmath.mpf(float(alpha)) / 2)
    return np.array([float(mpmath.mpf(float(ki)) * t) for ki in k])


def mp_gibbs_from_rotvec(r):
    r = [mpmath.mpf(float(x)) for x in r]
    th = mpmath.sqrt(sum(x * x for x in r))
    f = mpmath.tan(th / 2) / th
    return np.array([float(x * f) for x in r])


# ---------------------------------------------------------------------------
# strategies module sanity (other helpers import it)
# ---------------------------------------------------------------------------
@FEW
@given(q=S.quaternions(), n=S.gibbs_vectors(), R=S.rotation_matrices())
def test_strategies_shapes_and_units(q, n, R):
    assert q.shape[:-1] in S.BATCH_SHAPES and q.shape[-1] == 4
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-15)
    assert n.shape[-1] == 3 and np.all(np.isfinite(n))
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape), atol=1e-14)


@FEW
@given(q=S.quaternions(kind="near_pi", shape=(200,), random_sign=False))
def test_strategy_near_pi_is_on_both_sides(q):
    w = q[..., 0]
    assert np.all(np.abs(w) < 1.1e-7) and np.all(np.abs(w) > 2e-8)
    assert np.any(w > 0) and np.any(w < 0)


# ---------------------------------------------------------------------------
# quaternion basics
# ---------------------------------------------------------------------------
@PROP
@given(p=S.quaternions(shape=(5,)), q=S.quaternions(shape=(5,)))
def test_quaternion_product_is_matrix_product(p, q):
    pq = at.quaternion_multiply(p, q)
    np.testing.assert_allclose(
        at.matrix_from_quaternion(pq), at.matrix_from_quaternion(p) @ at.matrix_from_quaternion(q), atol=1e-14
    )
    np.testing.assert_allclose(pq, np_quat_mul(p, q), atol=1e-15)
    # conjugate is the inverse
    e = at.quaternion_multiply(p, at.quaternion_conjugate(p))
    np.testing.assert_allclose(e, np.broadcast_to([1.0, 0, 0, 0], e.shape), atol=1e-15)


@PROP
@given(q=S.quaternions(), scale=st.sampled_from([1e-300, 1e-5, 1.0, 3.0, 1e200, 1e300]))
def test_normalize_and_canonical(q, scale):
    qn = at.quaternion_normalize(q * scale)
    np.testing.assert_allclose(qn, q, atol=4 * EPS)
    c = at.quaternion_canonical(-q * scale)
    assert np.all(c[..., 0] >= 0)
    assert np.all(qdist(c, q) <= 4 * EPS)
    # w = 0: first nonzero vector component positive
    np.testing.assert_array_equal(at.quaternion_canonical([0.0, 0.0, -3.0, 4.0]), [0.0, 0.0, 0.6, -0.8])


def test_matrix_from_quaternion_formula():
    # R = (w^2 - v.v) 1 + 2 v v^T + 2 w [v]x, 90 degrees about z maps x to y
    q = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]
    np.testing.assert_allclose(at.matrix_from_quaternion(q) @ [1.0, 0, 0], [0.0, 1.0, 0.0], atol=4 * EPS)
    np.testing.assert_allclose(at.skew([1.0, 2.0, 3.0]) @ [4.0, 5.0, 6.0], np.cross([1, 2, 3], [4, 5, 6]))
    np.testing.assert_array_equal(at.unskew(at.skew([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0])


@PROP
@given(q=S.quaternions())
def test_matrix_from_quaternion_matches_scipy_and_is_rotation(q):
    R = at.matrix_from_quaternion(q)
    np.testing.assert_allclose(R, scipy_rot(q).as_matrix().reshape(R.shape), atol=1e-15)
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape), atol=1e-15)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-15)


@PROP
@given(R=S.rotation_matrices())
def test_quaternion_from_matrix_matches_scipy(R):
    q = at.quaternion_from_matrix(R)
    assert np.all(q[..., 0] >= 0)
    ref = np.roll(Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(), 1, -1).reshape(q.shape)
    assert np.all(qdist(q, ref) <= 1e-15)
    np.testing.assert_allclose(at.matrix_from_quaternion(q), R, atol=1e-15)


@FEW
@given(qs=S.quaternions(shape=(30, 2)), rng=S.rngs())
def test_quaternion_make_continuous(qs, rng):
    # a smooth series along axis 0 (two independent series), signs scrambled
    steps = at.quaternion_from_rotvec(0.1 * rng.standard_normal((30, 2, 3)))
    series = np.empty_like(qs)
    series[0] = qs[0]
    for i in range(1, 30):
        series[i] = np_quat_mul(series[i - 1], steps[i])
    signs = rng.choice([-1.0, 1.0], (30, 2))
    signs[0] = 1.0
    out = at.quaternion_make_continuous(series * signs[..., None], axis=0)
    np.testing.assert_allclose(out, series, atol=1e-14)
    assert np.all(np.sum(out[1:] * out[:-1], -1) >= 0)
    # same along axis 1 of the swapped array, and with a negative axis
    out1 = at.quaternion_make_continuous(np.swapaxes(series * signs[..., None], 0, 1), axis=-2)
    np.testing.assert_allclose(out1, np.swapaxes(series, 0, 1), atol=1e-14)
    # the first sample keeps its sign, length-1 series unchanged
    neg = at.quaternion_make_continuous(-series, axis=0)
    np.testing.assert_allclose(neg, -series, atol=1e-14)
    np.testing.assert_array_equal(at.quaternion_make_continuous(series[:1]), series[:1])


def test_quaternion_make_continuous_errors():
    q = np.ones((4, 4))
    with pytest.raises(InvalidInputError, match="quaternion axis"):
        at.quaternion_make_continuous(q, axis=-1)
    with pytest.raises(InvalidInputError, match="quaternion axis"):
        at.quaternion_make_continuous(np.ones(4), axis=0)
    with pytest.raises(InvalidInputError, match="out of range"):
        at.quaternion_make_continuous(q, axis=2)
    with pytest.raises(TypeError, match="axis must be an integer"):
        at.quaternion_make_continuous(q, axis=0.5)


# ---------------------------------------------------------------------------
# Gibbs vector: paper eq. 1.7-1.9
# ---------------------------------------------------------------------------
@PROP
@given(ka=S.axis_angles())
def test_matrix_from_gibbs_is_eq_1_9_and_eq_1_7(ka):
    k, a = ka
    n = k * np.tan(a / 2)[..., None]
    R = at.matrix_from_gibbs(n)
    np.testing.assert_allclose(R, S.rodrigues_matrix(k, a), atol=2e-15)  # eq. 1.7
    # eq. 1.9 literally, where it does not overflow
    n2 = np.sum(n * n, -1)[..., None, None]
    eps3 = np.zeros((3, 3, 3))
    for i, j, l in itertools.permutations(range(3)):
        eps3[i, j, l] = np.linalg.det(np.eye(3)[[i, j, l]])
    lit = ((1 - n2) * np.eye(3) + 2 * n[..., :, None] * n[..., None, :] - 2 * np.einsum("ijk,...k->...ij", eps3, n)) / (
        1 + n2
    )
    np.testing.assert_allclose(R, lit, atol=1e-15 * (1 + float(np.max(np.abs(n)))))
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape), atol=2e-15)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=2e-15)


@PROP
@given(q=S.quaternions())
def test_gibbs_quaternion_round_trip(q):
    n = at.gibbs_from_quaternion(q)
    np.testing.assert_allclose(n, q[..., 1:] / q[..., :1], rtol=4 * EPS)
    q2 = at.quaternion_from_gibbs(n)
    assert np.all(q2[..., 0] > 0)
    assert np.all(qdist(q2, q) <= 4 * EPS)
    # and back, relative accuracy at every angle (near pi |n| ~ 2e7)
    assert vec_rel_err(at.gibbs_from_quaternion(q2), n) <= 8 * EPS


@pytest.mark.parametrize("mag", [1e8, 1e154, 1e200, 1e300, 1.7e308])
def test_huge_gibbs_is_rotation_by_pi(mag):
    k = np.array([2.0, -3.0, 6.0]) / 7.0
    R = at.matrix_from_gibbs(mag * k)
    expected = 2 * np.outer(k, k) - np.eye(3)  # rotation by pi about k
    np.testing.assert_allclose(R, expected, atol=2 / mag + 4 * EPS)
    q = at.quaternion_from_gibbs(mag * k)
    assert np.all(np.isfinite(q)) and q[0] > 0
    np.testing.assert_allclose(q[0], 1 / mag, rtol=4 * EPS)
    np.testing.assert_allclose(q[1:], k, rtol=4 * EPS)
    np.testing.assert_allclose(at.gibbs_from_quaternion(q), mag * k, rtol=8 * EPS)
    # A(n) = (1 + [n]x)/(1 + n^2) does not overflow either
    A = at.conversion_matrix(mag * k)
    assert np.all(np.isfinite(A))
    expected_A = np.eye(3) * (1.0 / mag / mag) + at.skew(k) / mag  # (1 + [n]x)/(1 + n^2), |n| >> 1
    np.testing.assert_allclose(A, expected_A, rtol=1e-15, atol=1e-300)


def test_tiny_gibbs():
    n = np.array([1e-300, -2e-300, 3e-300])
    q = at.quaternion_from_gibbs(n)
    np.testing.assert_array_equal(q[1:], n)
    np.testing.assert_array_equal(at.gibbs_from_quaternion(q), n)
    np.testing.assert_array_equal(at.matrix_from_gibbs(n), np.eye(3) + at.skew(2 * n))


# ---------------------------------------------------------------------------
# near alpha = pi (1e-7 from pi, both sides): measured accuracy
# ---------------------------------------------------------------------------
NEAR_PI = [np.pi - 1e-7, np.pi - 3.3e-7, np.pi + 1e-7, np.pi + 2.7e-7]


@pytest.mark.parametrize("alpha", NEAR_PI)
def test_near_pi_gibbs_accuracy_vs_mpmath(alpha):
    k = np.array([0.48, -0.6, 0.64])
    k = k / np.linalg.norm(k)
    exact = mp_gibbs_from_axis_angle(k, alpha)
    # axis-angle and quaternion: a few ulps
    assert vec_rel_err(at.gibbs_from_axis_angle(k, alpha), exact) <= 8 * EPS
    q = at.quaternion_from_axis_angle(k, alpha)
    assert vec_rel_err(at.gibbs_from_quaternion(q), exact) <= 8 * EPS
    assert vec_rel_err(at.gibbs_from_quaternion(-q), exact) <= 8 * EPS
    # rotation vector and MRP: double-double, a few ulps of the exact value for the float input
    r = k * alpha
    assert vec_rel_err(at.gibbs_from_rotvec(r), mp_gibbs_from_rotvec(r)) <= 16 * EPS
    p = k * np.tan(alpha / 4)
    pm = [mpmath.mpf(float(x)) for x in p]
    p2 = sum(x * x for x in pm)
    exact_p = np.array([float(2 * x / (1 - p2)) for x in pm])
    assert vec_rel_err(at.gibbs_from_mrp(p), exact_p) <= 16 * EPS
    # quaternion -> matrix -> quaternion -> gibbs: the matrix holds w only to ~eps absolutely,
    # so the relative error of n is ~eps/(pi - alpha) ~ 1e-9 (measured: <= 3e-9 at 1e-7 from pi)
    n_mat = at.gibbs_from_matrix(at.matrix_from_quaternion(q))
    assert vec_rel_err(n_mat, exact) <= 2e-9 * (1e-7 / abs(np.pi - alpha)) + 16 * EPS
    # the reverse directions are well conditioned
    ax, ang = at.axis_angle_from_gibbs(exact)
    true_angle = float(2 * mpmath.atan(mpmath.sqrt(sum(mpmath.mpf(float(x)) ** 2 for x in exact))))
    assert abs(ang - true_angle) <= 4 * EPS
    assert np.max(np.abs(ax - np.sign(np.pi - alpha) * k)) <= 4 * EPS


@PROP
@given(q=S.quaternions(kind="near_pi"))
def test_near_pi_matrix_round_trip_keeps_n_to_condition(q):
    n = at.gibbs_from_quaternion(q)
    n2 = at.gibbs_from_matrix(at.matrix_from_quaternion(q))
    # relative error bounded by a small multiple of eps * |n| (condition number ~ 1/(pi - alpha))
    err = np.linalg.norm(n2 - n, axis=-1) / np.linalg.norm(n, axis=-1)
    assert np.all(err <= 8 * EPS * np.linalg.norm(n, axis=-1))


# ---------------------------------------------------------------------------
# near the identity (angle ~1e-8): relative accuracy against series / mpmath
# ---------------------------------------------------------------------------
@PROP
@given(ka=S.axis_angles(kind="near_identity"))
def test_near_identity_relative_accuracy(ka):
    k, a = ka
    r = k * a[..., None]
    # tan(a/2) = a/2 (1 + a^2/12 + ...), a^2/12 < 1e-16: n = r/2 to the last bit
    n_exact = r / 2
    assert vec_rel_err(at.gibbs_from_rotvec(r), n_exact) <= 4 * EPS
    assert vec_rel_err(at.rotvec_from_gibbs(n_exact), r) <= 4 * EPS
    assert vec_rel_err(at.mrp_from_gibbs(n_exact), r / 4) <= 4 * EPS
    assert vec_rel_err(at.gibbs_from_mrp(r / 4), n_exact) <= 4 * EPS
    q = at.quaternion_from_rotvec(r)
    assert vec_rel_err(at.rotvec_from_quaternion(q), r) <= 4 * EPS
    ax, ang = at.axis_angle_from_quaternion(q)
    np.testing.assert_allclose(ang, np.abs(a), rtol=4 * EPS)
    # the matrix keeps the small off-diagonal entries to full relative accuracy
    assert vec_rel_err(at.gibbs_from_matrix(at.matrix_from_gibbs(n_exact)), n_exact) <= 8 * EPS
    # Euler angles: Tait-Bryan middle angle without the pi/2 cancellation
    ang3 = np.stack([a, -0.7 * a, 0.3 * a], -1)
    for seq in ("xyz", "ZYX", "yxz"):
        e = at.euler_from_quaternion(seq, at.quaternion_from_euler(seq, ang3))
        np.testing.assert_allclose(e, ang3, rtol=32 * EPS, atol=0)


def test_near_identity_vs_mpmath_single():
    r = np.array([3e-9, -4e-9, 1.2e-8])
    assert vec_rel_err(at.gibbs_from_rotvec(r), mp_gibbs_from_rotvec(r)) <= 2 * EPS
    n = at.gibbs_from_rotvec(r)
    assert vec_rel_err(at.rotvec_from_gibbs(n), r) <= 2 * EPS


# ---------------------------------------------------------------------------
# every pair of representations, via Attitude
# ---------------------------------------------------------------------------
REPS = ["quaternion", "matrix", "gibbs", "axis_angle", "rotvec", "mrp", "euler", "scipy"]


def _to(att, rep, seq):
    if rep == "quaternion":
        return att.as_quaternion()
    if rep == "axis_angle":
        return att.as_axis_angle()
    if rep == "euler":
        return att.as_euler(seq)
    return getattr(att, f"as_{rep}")()


def _from(x, rep, seq):
    if rep == "quaternion":
        return Attitude.from_quaternion(x)
    if rep == "axis_angle":
        return Attitude.from_axis_angle(*x)
    if rep == "euler":
        return Attitude.from_euler(seq, x)
    return getattr(Attitude, f"from_{rep}")(x)


@pytest.mark.parametrize("a, b", list(itertools.permutations(REPS, 2)))
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(q=S.quaternions(), seq=S.euler_sequences())
def test_round_trip_every_pair(a, b, q, seq):
    att = Attitude(q)
    x = _to(att, a, seq)
    att2 = _from(x, a, seq)
    y = _to(att2, b, seq)
    att3 = _from(y, b, seq)
    assert att3.shape == att.shape
    np.testing.assert_allclose(att3.as_matrix(), att.as_matrix(), atol=1e-14)
    assert np.all(att.angle_to(att3) <= 1e-14)


@PROP
@given(q=S.quaternions())
def test_round_trip_values_through_gibbs(q):
    """X -> gibbs -> X returns X itself (not only the rotation), for the well-defined X."""
    att = Attitude(q)
    n = att.as_gibbs()
    nn = np.linalg.norm(n, axis=-1)
    tol = 16 * EPS * (1 + nn)  # conditioning ~ 1/(pi - alpha) ~ |n|
    for to_g, from_g, rep in [
        (at.gibbs_from_rotvec, at.rotvec_from_gibbs, att.as_rotvec()),
        (at.gibbs_from_mrp, at.mrp_from_gibbs, att.as_mrp()),
        (lambda R: at.gibbs_from_matrix(R), at.matrix_from_gibbs, att.as_matrix()),
    ]:
        g = to_g(rep)
        assert np.all(np.linalg.norm(g - n, axis=-1) <= tol * nn + 1e-300)
        back = from_g(g)
        np.testing.assert_allclose(back, rep, atol=1e-14)
    k, ang = att.as_axis_angle()
    g = at.gibbs_from_axis_angle(k, ang)
    assert np.all(np.linalg.norm(g - n, axis=-1) <= tol * nn + 1e-300)
    k2, ang2 = at.axis_angle_from_gibbs(n)
    np.testing.assert_allclose(ang2, ang, atol=4 * EPS)
    np.testing.assert_allclose(k2, k, atol=4 * EPS)


@PROP
@given(q=S.quaternions(), seq=S.euler_sequences())
def test_agreement_with_scipy(q, seq):
    att = Attitude(q)
    rot = scipy_rot(q)
    shape = att.shape
    np.testing.assert_allclose(att.as_rotvec(), rot.as_rotvec().reshape(shape + (3,)), atol=1e-14)
    np.testing.assert_allclose(att.as_matrix(), rot.as_matrix().reshape(shape + (3, 3)), atol=1e-15)
    # MRP: scipy also picks |p| <= 1 (ambiguous only exactly at pi)
    np.testing.assert_allclose(att.as_mrp(), rot.as_mrp().reshape(shape + (3,)), atol=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's gimbal-lock warning, irrelevant here
        e_ref = rot.as_euler(seq).reshape(shape + (3,))
    e = att.as_euler(seq)
    # compare the angles away from gimbal lock, where they are well defined
    # (near it, and for proper sequences near the identity, only the rotation is)
    mid = e_ref[..., 1]
    lock_dist = np.minimum(mid, np.pi - mid) if seq[0].lower() == seq[2].lower() else np.pi / 2 - np.abs(mid)
    ok = lock_dist > 1e-4
    d = np.angle(np.exp(1j * (e - e_ref)))[ok]
    assert np.max(np.abs(d), initial=0) <= 1e-11
    np.testing.assert_allclose(Attitude.from_euler(seq, e).as_matrix(), att.as_matrix(), atol=1e-14)
    # from_euler, from_rotvec and from_mrp agree with scipy too
    ang = e_ref
    qa = Attitude.from_euler(seq, ang).as_quaternion()
    qb = np.roll(Rotation.from_euler(seq, ang.reshape(-1, 3)).as_quat(), 1, -1).reshape(qa.shape)
    assert np.all(qdist(qa, qb) <= 1e-15)
    rv = rot.as_rotvec().reshape(shape + (3,))
    assert np.all(qdist(at.quaternion_from_rotvec(rv), q) <= 1e-15)


@FEW
@given(seq_ang=S.euler_angles(), deg=st.booleans())
def test_euler_ranges_and_degrees(seq_ang, deg):
    seq, ang = seq_ang
    q = at.quaternion_from_euler(seq, np.rad2deg(ang) if deg else ang, degrees=deg)
    np.testing.assert_allclose(q, at.quaternion_from_euler(seq, ang), atol=1e-15)
    e = at.euler_from_quaternion(seq, q, degrees=deg)
    half = 180.0 if deg else np.pi
    assert np.all(e[..., [0, 2]] > -half) and np.all(e[..., [0, 2]] <= half)
    if seq[0].lower() == seq[2].lower():
        assert np.all((e[..., 1] >= 0) & (e[..., 1] <= half))
    else:
        assert np.all(np.abs(e[..., 1]) <= half / 2)
    # generic angles in the canonical ranges come back unchanged
    np.testing.assert_allclose(np.deg2rad(e) if deg else e, ang, atol=1e-9)


@pytest.mark.parametrize("seq", S.EULER_SEQUENCES)
def test_euler_gimbal_lock_round_trip(seq):
    rng = np.random.default_rng(abs(hash(seq)) % 2**32)
    proper = seq[0].lower() == seq[2].lower()
    mids = [0.0, np.pi] if proper else [-np.pi / 2, np.pi / 2]
    for mid in mids:
        for delta in (0.0, 1e-16, 1e-12, 1e-9):  # at lock and near it (delta >= 1e-12 is not locked)
            ang = rng.uniform(-np.pi, np.pi, (50, 3))
            ang[:, 1] = mid + (delta if mid <= 0 else -delta)
            q = at.quaternion_from_euler(seq, ang)
            e = at.euler_from_quaternion(seq, q)
            q2 = at.quaternion_from_euler(seq, e)
            assert np.max(qdist(q, q2)) <= 1e-15, (seq, mid, delta)
            if delta == 0.0:
                np.testing.assert_array_equal(e[:, 2], 0.0)  # third angle zeroed at lock
    # degrees at exactly 90 / 180
    ang = [30.0, 180.0 if proper else 90.0, 40.0]
    q = at.quaternion_from_euler(seq, ang, degrees=True)
    e = at.euler_from_quaternion(seq, q, degrees=True)
    assert e[2] == 0.0
    assert qdist(at.quaternion_from_euler(seq, e, degrees=True), q) <= 1e-15


@pytest.mark.parametrize(
    "bad, msg",
    [
        ("xy", "3-letter"),
        (123, "3-letter"),
        ("xYz", "mixes lower case"),
        ("xxy", "consecutive"),
        ("xyy", "consecutive"),
        ("abc", "only contain"),
        ("", "3-letter"),
    ],
)
def test_euler_sequence_errors(bad, msg):
    with pytest.raises(InvalidInputError, match=msg):
        at.quaternion_from_euler(bad, [0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match=msg):
        at.euler_from_quaternion(bad, [1.0, 0.0, 0.0, 0.0])


# ---------------------------------------------------------------------------
# composition and inverse of Gibbs vectors (closed form vs matrix products)
# ---------------------------------------------------------------------------
@PROP
@given(data=st.data(), shape=S.batch_shapes())
def test_gibbs_compose_is_matrix_product(data, shape):
    k1 = data.draw(S.attitude_kinds())
    k2 = data.draw(S.attitude_kinds())
    n1 = data.draw(S.gibbs_vectors(shape, k1))
    n2 = data.draw(S.gibbs_vectors(shape, k2))
    try:
        n12 = at.gibbs_compose(n1, n2)
    except SingularChartError:  # product exactly at pi: impossible for continuous samples
        pytest.fail("unexpected singular composition")
    R12 = at.matrix_from_gibbs(n1) @ at.matrix_from_gibbs(n2)
    # the closed form loses ~eps*|n1||n2|/|1 - n1.n2| relatively; compare rotations
    scale = (1 + np.linalg.norm(n1, axis=-1)) * (1 + np.linalg.norm(n2, axis=-1))
    err = np.max(np.abs(at.matrix_from_gibbs(n12) - R12), axis=(-1, -2))
    assert np.all(err <= 64 * EPS * scale / (1 + np.linalg.norm(n12, axis=-1)) + 1e-14)
    # Attitude products agree with matrix products as well
    a = Attitude.from_gibbs(n1) * Attitude.from_gibbs(n2)
    np.testing.assert_allclose(a.as_matrix(), R12, atol=1e-14)
    b = Attitude.from_gibbs(n1) @ Attitude.from_gibbs(n2)
    np.testing.assert_allclose(b.as_matrix(), R12, atol=1e-14)
    # inverse
    np.testing.assert_allclose(
        at.matrix_from_gibbs(at.gibbs_inverse(n1)), np.swapaxes(at.matrix_from_gibbs(n1), -1, -2), atol=0
    )
    np.testing.assert_allclose(at.gibbs_compose(n1, at.gibbs_inverse(n1)), 0.0, atol=0)


def test_gibbs_compose_closed_form_and_overflow():
    n1, n2 = np.array([0.3, -0.2, 0.5]), np.array([-1.5, 0.4, 2.0])
    expected = (n1 + n2 + np.cross(n1, n2)) / (1 - n1 @ n2)
    np.testing.assert_allclose(at.gibbs_compose(n1, n2), expected, rtol=4 * EPS)
    # large arguments: scaled, no overflow; x-by-pi then (small about y) stays finite and correct
    big = np.array([1e200, 0.0, 0.0])
    out = at.gibbs_compose(big, [0.0, 0.5, 0.0])
    np.testing.assert_allclose(out, [1e200, 0.5, 0.5e200], rtol=4 * EPS)
    # inverse of a big one
    np.testing.assert_allclose(at.gibbs_compose(big, -big), 0.0)
    # broadcasting
    assert at.gibbs_compose(np.zeros((2, 3, 3)), n1).shape == (2, 3, 3)


def test_gibbs_compose_singular():
    with pytest.raises(SingularChartError, match="n1 . n2 = 1"):
        at.gibbs_compose([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    # pi about x times pi about y is pi about z: overflow is reported, not returned as inf
    with pytest.raises(SingularChartError, match="compose quaternions"):
        at.gibbs_compose([1e200, 0.0, 0.0], [0.0, 1e200, 0.0])


# ---------------------------------------------------------------------------
# the paper's matrices: A, A~ (eq. 1.12), R = A A~^T, Omega = 2 A^T ndot (eq. 1.11)
# ---------------------------------------------------------------------------
@PROP
@given(n=S.gibbs_vectors())
def test_conversion_matrices(n):
    A = at.conversion_matrix(n)
    At = at.inverse_conversion_matrix(n)
    nn = 1 + np.sum(n * n, -1)
    # eq. 1.12 literally (moderate |n| only, where it does not lose accuracy)
    lit = (np.eye(3) + at.skew(n)) / nn[..., None, None]
    np.testing.assert_allclose(A, lit, rtol=1e-14, atol=1e-14 / nn.max())
    np.testing.assert_allclose(At, np.eye(3) + n[..., :, None] * n[..., None, :] - at.skew(n), rtol=0, atol=0)
    # A A~ = 1 (this is what fixes the n_i n_j misprint of eq. 1.12)
    scale = float(np.max(nn))
    np.testing.assert_allclose(A @ At, np.broadcast_to(np.eye(3), A.shape), atol=8 * EPS * scale)
    # R = A A~^T equals eq. 1.9
    np.testing.assert_allclose(at.matrix_from_conversion(n), at.matrix_from_gibbs(n), atol=8 * EPS * scale)


def test_paper_misprint_nj_nj_is_not_the_inverse():
    n = np.array([0.3, -0.5, 0.7])
    A = at.conversion_matrix(n)
    printed = np.eye(3) + (n @ n) * np.eye(3) - at.skew(n)  # delta_ij + n_j n_j + eps_ijk n_k as printed
    assert np.max(np.abs(A @ printed - np.eye(3))) > 0.1
    np.testing.assert_allclose(A @ at.inverse_conversion_matrix(n), np.eye(3), atol=1e-15)


def _fd_omega(n0, nd, h):
    """Omega = unskew(R^T dR/dt) from a 4th-order central difference of R(n0 + t nd)."""
    Rm2, Rm1, Rp1, Rp2 = (at.matrix_from_gibbs(n0 + s * h[..., None] * nd) for s in (-2, -1, 1, 2))
    Rdot = (Rm2 - 8 * Rm1 + 8 * Rp1 - Rp2) / (12 * h[..., None, None])
    return at.unskew(np.swapaxes(at.matrix_from_gibbs(n0), -1, -2) @ Rdot)


@PROP
@given(n=S.gibbs_vectors(), rng=S.rngs())
def test_omega_from_gibbs_rate_vs_finite_difference(n, rng):
    nn = np.linalg.norm(n, axis=-1)
    # a rate with Omega = O(1): along n the rate must be ~ |n|^2, across it ~ |n|
    omega = rng.standard_normal(n.shape)
    nd = at.gibbs_rate_from_omega(n, omega)
    h = 1e-3 / (1 + nn)
    fd = _fd_omega(n, nd, h)
    om = at.omega_from_gibbs_rate(n, nd)
    # truncation ~ (h |n|)^4, rounding ~ eps / h
    tol = 1e-10 + 30 * EPS / h
    assert np.all(np.linalg.norm(fd - om, axis=-1) <= tol * (1 + np.linalg.norm(om, axis=-1)))
    # the two maps of eq. 1.11 and eq. 1.30 are inverse to each other
    np.testing.assert_allclose(om, omega, atol=1e-13 * (1 + nn.max()) ** 2)
    # Omega = 2 A^T ndot literally
    np.testing.assert_allclose(
        om, 2 * np.einsum("...ji,...j->...i", at.conversion_matrix(n), nd), rtol=1e-14, atol=1e-14
    )


def test_omega_from_gibbs_rate_closed_form():
    n, nd = np.array([0.2, -0.4, 1.1]), np.array([0.5, 0.1, -0.3])
    expected = 2 * (nd - np.cross(n, nd)) / (1 + n @ n)
    np.testing.assert_allclose(at.omega_from_gibbs_rate(n, nd), expected, rtol=1e-15)
    expected = 0.5 * (nd + np.cross(n, nd) + (n @ nd) * n)
    np.testing.assert_allclose(at.gibbs_rate_from_omega(n, nd), expected, rtol=1e-15)
    # broadcasting: one n, many rates
    assert at.omega_from_gibbs_rate(n, np.ones((4, 3))).shape == (4, 3)
    assert at.gibbs_rate_from_omega(np.ones((4, 3)), nd).shape == (4, 3)


@PROP
@given(n=S.gibbs_vectors(shape=(5,), kind="uniform"), I=S.inertia_tensors(shape=(5,)), rng=S.rngs())
def test_metric_eq_1_13_and_inverse_eq_1_14(n, I, rng):
    G = at.metric(n, I)
    Gi = at.inverse_metric(n, I)
    np.testing.assert_allclose(G @ Gi, np.broadcast_to(np.eye(3), G.shape), atol=1e-10 * (1 + np.max(n * n)) ** 2)
    np.testing.assert_allclose(G, np.swapaxes(G, -1, -2), atol=1e-14)
    assert np.all(np.linalg.eigvalsh(G) > 0)
    # L = 1/2 G ndot ndot = 1/2 Omega I Omega (eq. 1.13 with eq. 1.11)
    nd = rng.standard_normal(n.shape)
    om = at.omega_from_gibbs_rate(n, nd)
    L1 = 0.5 * np.einsum("...i,...ij,...j->...", nd, G, nd)
    L2 = 0.5 * np.einsum("...i,...ij,...j->...", om, I, om)
    # cancellation in ndot - n x ndot: relative error ~ eps |n|^2
    assert np.all(np.abs(L1 - L2) <= 1e-14 * (1 + np.sum(n * n, -1)) * np.abs(L2))
    # RigidBody or principal moments are accepted
    np.testing.assert_allclose(at.metric(n, RigidBody(I)), G, rtol=1e-15)
    np.testing.assert_allclose(at.metric(n[0], [1.0, 2.0, 2.5]), at.metric(n[0], np.diag([1.0, 2.0, 2.5])))
    np.testing.assert_allclose(at.inverse_metric(n, RigidBody(I)), Gi, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(
        at.inverse_metric(n[0], [1.0, 2.0, 2.5]), at.inverse_metric(n[0], np.diag([1.0, 2.0, 2.5])), rtol=1e-14
    )
    # the paper's asymptotics: G -> 4 I at n = 0
    np.testing.assert_allclose(at.metric(np.zeros(3), I[0]), 4 * I[0], rtol=1e-15)


def test_metric_rejects_bad_inertia():
    with pytest.raises(InvalidInputError, match="inertia must be three principal moments"):
        at.metric([0.0, 0.0, 0.0], [1.0, 2.0])
    with pytest.raises(InvalidInertiaError, match="not positive definite"):
        at.metric([0.0, 0.0, 0.0], [[1.0, 0, 0], [0, -1.0, 0], [0, 0, 1.0]])
    with pytest.raises(InvalidInertiaError, match="not positive definite"):
        at.inverse_metric([0.0, 0.0, 0.0], [0.0, 1.0, 1.0])
    with pytest.raises(InvalidInertiaError, match="triangle inequality"):
        at.metric([0.0, 0.0, 0.0], [1.0, 1.0, 3.0])
    with pytest.raises(InvalidInertiaError, match="not symmetric"):
        at.inverse_metric([0.0, 0.0, 0.0], [[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]])


# ---------------------------------------------------------------------------
# charts: R = R0 R(n), continuation through alpha = pi
# ---------------------------------------------------------------------------
@PROP
@given(data=st.data())
def test_chart_round_trip(data):
    q = data.draw(S.quaternions())
    q0 = data.draw(S.quaternions(shape=q.shape[:-1], kind="uniform"))
    n = at.gibbs_chart(q, q0)
    R = at.matrix_from_quaternion(q0) @ at.matrix_from_gibbs(n)
    np.testing.assert_allclose(R, at.matrix_from_quaternion(q), atol=1e-13)
    q2 = at.quaternion_from_chart(q0, n)
    assert np.all(qdist(q2, q) <= 1e-13)
    a = Attitude(q)
    # Attitude() renormalizes (1 ulp), which n = v/w amplifies by ~|n|
    nn = np.linalg.norm(n, axis=-1, keepdims=True)
    assert np.all(np.abs(a.as_chart(Attitude(q0)) - n) <= 8 * EPS * (1 + nn) ** 2)
    assert np.all(Attitude.from_chart(Attitude(q0), n).angle_to(a) <= 1e-13)
    # the chart at the identity is the global Gibbs vector
    np.testing.assert_allclose(at.gibbs_chart(q, [1.0, 0, 0, 0]), at.gibbs_from_quaternion(q), rtol=1e-15)


def test_trajectory_through_pi_with_charts():
    """Rotation about a fixed axis by alpha(t) from 0 to 2 pi: the global n blows up at pi, re-centred charts do not."""
    k = np.array([1.0, 2.0, 2.0]) / 3
    t = np.linspace(0.0, 2 * np.pi, 201)  # contains alpha = pi exactly (t[100])
    q = at.quaternion_from_axis_angle(k, t)
    q[100] = [0.0, *k]  # the exact rotation by pi
    with pytest.raises(SingularChartError, match="chart"):
        at.gibbs_from_quaternion(q)
    ref = q[0]
    local = []
    refs = []
    for qi in q:
        n = at.gibbs_chart(qi, ref)
        if np.linalg.norm(n) > 1.0:  # re-centre the chart on the current attitude
            ref = qi
            n = at.gibbs_chart(qi, ref)
        local.append(n)
        refs.append(ref)
    local = np.array(local)
    assert np.all(np.linalg.norm(local, axis=-1) <= 1.0)
    back = at.quaternion_from_chart(np.array(refs), local)
    assert np.max(qdist(back, q)) <= 1e-15
    # the local angular velocity from the chart coordinates is the true one (about k, rate 1)
    dt = t[1] - t[0]
    ref = q[100]
    n_loc = at.gibbs_chart(q[98:103], ref)
    nd = (n_loc[3] - n_loc[1]) / (2 * dt)
    np.testing.assert_allclose(at.omega_from_gibbs_rate(n_loc[2], nd), k, atol=1e-4)


def test_chart_singular():
    with pytest.raises(SingularChartError, match="relative to the chart reference"):
        at.gibbs_chart([0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="reference contains a zero quaternion"):
        at.gibbs_chart([1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0])


# ---------------------------------------------------------------------------
# singular chart at alpha = pi
# ---------------------------------------------------------------------------
def test_singular_chart_errors():
    with pytest.raises(SingularChartError, match=r"alpha = pi .* chart"):
        at.gibbs_from_quaternion([0.0, 0.0, 1.0, 0.0])
    with pytest.raises(SingularChartError, match="keep the quaternion"):
        at.gibbs_from_quaternion([[1.0, 0, 0, 0], [0.0, 0.0, 1.0, 0.0]])
    with pytest.raises(SingularChartError, match=r"batch index \(1,\)"):
        at.gibbs_from_quaternion([[1.0, 0, 0, 0], [0.0, 0.0, 1.0, 0.0]])
    with pytest.raises(SingularChartError, match="alpha = pi"):
        at.gibbs_from_matrix(np.diag([1.0, -1.0, -1.0]))
    with pytest.raises(SingularChartError, match="alpha = pi"):
        at.gibbs_from_mrp([0.0, -1.0, 0.0])
    with pytest.raises(SingularChartError, match="Attitude.as_chart"):
        Attitude([0.0, 1.0, 0.0, 0.0]).as_gibbs()
    with pytest.raises(SingularChartError, match="alpha = pi"):
        (Attitude.from_gibbs([0.0, 0.0, 1.0]) * Attitude.from_gibbs([0.0, 0.0, 1.0])).as_gibbs()
    # w so small that |n| overflows: also singular, never inf
    with pytest.raises(SingularChartError, match="alpha = pi"):
        at.gibbs_from_quaternion([1e-320, 1.0, 0.0, 0.0])
    # but w = 1e-300 is fine
    np.testing.assert_allclose(at.gibbs_from_quaternion([1e-300, 1.0, 0.0, 0.0]), [1e300, 0, 0], rtol=1e-15)


# ---------------------------------------------------------------------------
# input validation
# ---------------------------------------------------------------------------
def test_validation_errors():
    with pytest.raises(InvalidInputError, match=r"n must have shape \(\.\.\., 3\), got shape \(2,\)"):
        at.matrix_from_gibbs([1.0, 2.0])
    with pytest.raises(InvalidInputError, match="n contains NaN"):
        at.quaternion_from_gibbs([np.nan, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="q contains NaN or infinite"):
        at.gibbs_from_quaternion([np.inf, 0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="zero quaternion"):
        at.matrix_from_quaternion([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="quaternion contains a zero quaternion"):
        Attitude(np.zeros((2, 4)))
    with pytest.raises(TypeError, match="must be numeric"):
        at.quaternion_from_gibbs("abc")
    with pytest.raises(InvalidInputError, match=r"v must have shape"):
        at.skew(np.ones((3, 2)))
    with pytest.raises(InvalidInputError, match=r"S must have shape \(\.\.\., 3, 3\)"):
        at.unskew(np.ones(3))
    with pytest.raises(InvalidInputError, match="axis contains a zero vector"):
        at.quaternion_from_axis_angle([0.0, 0.0, 0.0], 1.0)
    with pytest.raises(InvalidInputError, match="do not broadcast"):
        at.quaternion_from_axis_angle(np.ones((5, 3)), np.ones(4))
    with pytest.raises(InvalidInputError, match="angle contains NaN"):
        at.quaternion_from_axis_angle([1.0, 0.0, 0.0], np.nan)
    with pytest.raises(InvalidInputError, match="rotvec contains NaN"):
        at.quaternion_from_rotvec([np.nan, 0, 0])
    with pytest.raises(InvalidInputError, match="overflows"):
        at.quaternion_from_rotvec([1.5e308, 1.5e308, 0])
    with pytest.raises(InvalidInputError, match="p must have shape"):
        at.quaternion_from_mrp([1.0])
    with pytest.raises(InvalidInputError, match="angles must have shape"):
        at.quaternion_from_euler("xyz", [1.0, 2.0])
    with pytest.raises(InvalidInputError, match="ndot contains NaN"):
        at.omega_from_gibbs_rate([0.0, 0, 0], [np.nan, 0, 0])
    with pytest.raises(InvalidInputError, match="omega must have shape"):
        at.gibbs_rate_from_omega([0.0, 0, 0], [1.0])
    with pytest.raises(InvalidInputError, match="n1 must have shape"):
        at.gibbs_compose([1.0], [0, 0, 0])


def test_quaternion_from_matrix_errors():
    with pytest.raises(InvalidInputError, match="not a rotation matrix.*max\\|R\\^T R - 1\\| = 3 and det R = 8"):
        at.quaternion_from_matrix(2 * np.eye(3))
    with pytest.raises(InvalidInputError, match=r"det R = -1"):
        at.quaternion_from_matrix(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InvalidInputError, match=r"batch index \(1,\)"):
        at.quaternion_from_matrix(np.stack([np.eye(3), np.diag([1.0, -1.0, 1.0])]))
    with pytest.raises(InvalidInputError, match="atol must be >= 0"):
        at.quaternion_from_matrix(np.eye(3), atol=-1.0)
    with pytest.raises(InvalidInputError, match="atol must be finite"):
        at.quaternion_from_matrix(np.eye(3), atol=np.nan)
    with pytest.raises(InvalidInputError, match=r"R must have shape \(\.\.\., 3, 3\)"):
        at.gibbs_from_matrix(np.eye(4))
    # within the tolerance: accepted, result is a nearby rotation
    R = at.matrix_from_gibbs([0.1, 0.2, 0.3]) + 1e-8
    q = at.quaternion_from_matrix(R)
    assert np.max(np.abs(at.matrix_from_quaternion(q) - R)) < 1e-7
    with pytest.raises(InvalidInputError, match="not a rotation matrix"):
        at.quaternion_from_matrix(R, atol=1e-10)


# ---------------------------------------------------------------------------
# Attitude container, scipy interop
# ---------------------------------------------------------------------------
@PROP
@given(q=S.quaternions())
def test_scipy_round_trip_with_batch_shapes(q):
    a = Attitude(q)
    if a.ndim > 1 and not SCIPY_ND:  # pragma: no cover - scipy < 1.17
        with pytest.raises(InvalidInputError, match="reshape"):
            a.as_scipy()
        a = a.reshape(-1)
        q = q.reshape(-1, 4)
    r = a.as_scipy()
    assert getattr(r, "shape", (len(r),) if a.ndim else ()) == a.shape  # N-D batches are kept, never flattened
    b = Attitude.from_scipy(r)
    assert b.shape == a.shape
    assert np.all(qdist(b.as_quaternion(), q) <= 4 * EPS)
    np.testing.assert_allclose(r.as_matrix(), a.as_matrix(), atol=1e-15)
    np.testing.assert_allclose(at.quaternion_from_scipy(at.scipy_from_quaternion(q)), b.as_quaternion())


def test_from_scipy_type_error():
    with pytest.raises(TypeError, match="must be a scipy Rotation"):
        Attitude.from_scipy(np.eye(3))


@PROP
@given(q=S.quaternions(shape=(2, 3)), v=S.angular_velocities(shape=(2, 3)))
def test_attitude_apply_inv_angle_to(q, v):
    a = Attitude(q)
    np.testing.assert_allclose(a.apply(v), np.einsum("...ij,...j->...i", at.matrix_from_quaternion(q), v), atol=1e-14)
    np.testing.assert_allclose(a.apply(a.apply(v), inverse=True), v, atol=1e-13)
    np.testing.assert_allclose(a.inv().apply(a.apply(v)), v, atol=1e-13)
    np.testing.assert_allclose(a.apply(v[0, 0]), np.einsum("...ij,j->...i", a.as_matrix(), v[0, 0]), atol=1e-14)
    assert np.all((a * a.inv()).magnitude() <= 1e-15)
    b = Attitude(q[::-1, ::-1])
    ref = (scipy_rot(q).inv() * scipy_rot(q[::-1, ::-1])).magnitude()
    np.testing.assert_allclose(a.angle_to(b), ref, atol=1e-14)
    np.testing.assert_allclose(a.angle_to(b), b.angle_to(a), atol=1e-15)
    np.testing.assert_allclose(a.magnitude(), scipy_rot(q).magnitude(), atol=1e-15)


def test_attitude_container():
    a = Attitude.random((2, 3), rng=1)
    q = a.as_quaternion()

    def same(att, ref):
        np.testing.assert_allclose(att.as_quaternion(), ref, rtol=0, atol=4 * EPS)

    assert a.shape == (2, 3) and a.ndim == 2 and a.size == 6 and len(a) == 2
    same(a[1], q[1])
    same(a[1, 2], q[1, 2])
    same(a[..., 0], q[..., 0, :])
    same(a[:, -1], q[:, -1])
    same(a[np.array([True, False])], q[[0]])
    same(a[:, None], q[:, None])
    assert a[1, 2].shape == () and a[:, None].shape == (2, 1, 3)
    with pytest.raises(IndexError):
        a[2]
    with pytest.raises(IndexError):
        a[0, 0, 0]  # never indexes into the quaternion axis
    assert [b.shape for b in a] == [(3,), (3,)]
    assert a.reshape(-1).shape == (6,) and a.reshape(3, 2).shape == (3, 2) and a.reshape((6, 1)).shape == (6, 1)
    same(a.reshape(-1), q.reshape(-1, 4))
    assert repr(a) == "Attitude(shape=(2, 3))"
    assert repr(Attitude.identity()) == "Attitude(quaternion=[1, 0, 0, 0])"
    assert repr(Attitude.from_gibbs([0.0, 0.0, 1.0])) == "Attitude(quaternion=[0.707107, 0, 0, 0.707107])"
    # views are copies
    out = a.as_quaternion()
    out[...] = 0
    np.testing.assert_array_equal(a.as_quaternion(), q)
    np.testing.assert_array_equal(Attitude(a).as_quaternion(), q)
    # identity and random
    assert Attitude.identity(4).shape == (4,)
    np.testing.assert_array_equal(Attitude.identity((2, 1)).as_matrix(), np.broadcast_to(np.eye(3), (2, 1, 3, 3)))
    np.testing.assert_array_equal(Attitude.random(3, rng=7).as_quaternion(), Attitude.random(3, rng=7).as_quaternion())
    # canonical view
    np.testing.assert_array_equal(Attitude([-1.0, 0.0, 0.0, 0.0]).as_quaternion(canonical=True), [1.0, 0, 0, 0])
    # broadcasting product
    assert (a * Attitude.identity(3)).shape == (2, 3)


def test_attitude_errors():
    one = Attitude.identity()
    with pytest.raises(TypeError, match="has no len"):
        len(one)
    with pytest.raises(TypeError, match="cannot be indexed"):
        one[0]
    with pytest.raises(TypeError, match="not iterable"):
        iter(one).__next__()
    with pytest.raises(TypeError, match="must be an Attitude"):
        one.angle_to(np.array([1.0, 0, 0, 0]))
    with pytest.raises(TypeError):
        one * 2.0
    with pytest.raises(TypeError):
        np.eye(3) @ one
    with pytest.raises(InvalidInputError, match="vectors must have shape"):
        one.apply([1.0, 2.0])


def test_haar_random_is_uniform():
    # the angle of a Haar rotation has density (1 - cos a)/pi on [0, pi]: mean = pi/2 + 2/pi
    ang = Attitude.random(20000, rng=3).magnitude()
    assert abs(ang.mean() - (np.pi / 2 + 2 / np.pi)) < 0.02


def test_as_scipy_raises_instead_of_flattening_on_old_scipy(monkeypatch):
    """With a scipy that cannot hold N-D batches, as_scipy raises (it never flattens silently)."""
    original = Rotation.from_quat

    def old_from_quat(quat, *args, **kwargs):
        if np.ndim(quat) > 2:
            raise ValueError("Expected `quat` to have shape (4,) or (N, 4)")
        return original(quat, *args, **kwargs)

    monkeypatch.setattr(Rotation, "from_quat", staticmethod(old_from_quat))
    a = Attitude.random((2, 3), rng=0)
    with pytest.raises(InvalidInputError, match=r"batch of shape \(2, 3\).*reshape\(-1\)"):
        a.as_scipy()
    assert len(a.reshape(-1).as_scipy()) == 6
    with pytest.raises(ValueError, match="cannot reshape"):
        a.reshape(4)


@pytest.mark.parametrize(("shape", "axis"), [((400, 4), 0), ((5, 300, 4), 1), ((300, 3, 4), 0), ((3, 5, 6, 4), -2)])
def test_quaternion_make_continuous_flips_where_the_summed_dot_product_is_negative(shape, axis, rng):
    # the reference: dot products by np.sum over the quaternion axis, a flip where one is negative, flips
    # accumulated along the series; near-orthogonal neighbours (dot products decided by rounding) included
    q = rng.standard_normal(shape)
    q[..., 0] *= 1e-9
    qm = np.moveaxis(q, axis, 0)
    dots = np.sum(qm[1:] * qm[:-1], axis=-1)
    flips = np.concatenate([np.zeros((1,) + dots.shape[1:], dtype=int), np.cumsum(dots < 0, axis=0)])
    want = np.moveaxis(qm * np.where(flips % 2 == 1, -1.0, 1.0)[..., None], 0, axis)
    got = at.quaternion_make_continuous(q, axis=axis)
    assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
    # a series without a flip comes back as a copy
    pos = np.abs(q)
    out = at.quaternion_make_continuous(pos, axis=axis)
    assert np.array_equal(out, pos) and out is not pos and not np.shares_memory(out, pos)
