"""Checks of the independent high-precision torque reference (tests/_torque_reference.py).

The reference is used as truth by the package's tests, so it is checked here on its own,
without any eulerpoisson code:

1. against an independent scipy DOP853 integration (rtol = atol = 1e-13) for the free body and
   for every kind of torque (agreement ~1e-12, asserted at 1e-10);
2. conservation, to < 1e-25 relative over t = 10, of the closed-form integrals (energy, vertical
   momentum, Kovalevskaya, Goryachev-Chaplygin, Jacobi, Lagrange I3 Omega3, space angular
   momentum); the sign-flipped variants are shown NOT to be conserved, so these checks do
   discriminate;
3. self-consistency: dps=30 vs dps=45 and a different Taylor order (step control) agree to 1e-25;
4. exact solutions: a constant body torque from rest about a principal axis
   (Omega = tau t / I, q = rotation by tau t^2 / (2 I)), the torque-free symmetric top, a constant
   space torque (L(t) = L0 + tau_s t), the gravity-gradient relative equilibrium.
"""

import hashlib
import math

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import _torque_reference as tr
from _reference import qmul_floats

T_END = 10.0
TIMES = np.array([0.0, 2.5, 5.0, 7.5, T_END])
G = np.array([0.0, 0.0, -9.81])
Q0 = np.array([0.9, 0.2, -0.3, 0.1]) / np.linalg.norm([0.9, 0.2, -0.3, 0.1])
W0 = np.array([0.7, -1.1, 2.3])
I_FULL = np.array([[2.0, 0.1, -0.2], [0.1, 3.0, 0.3], [-0.2, 0.3, 4.0]])
HEAVY = [(1.3, np.array([0.1, 0.2, 0.5]), G)]
TWO_GRAVITIES = HEAVY + [(0.4, np.array([-0.3, 0.0, 0.2]), np.array([1.0, 0.5, -2.0]))]
NU = 0.9
TAU_B = np.array([0.3, -0.2, 0.5])
TAU_S = np.array([0.1, 0.4, -0.3])

CASES = {
    "free": {},
    "gravity": {"gravity": HEAVY},
    "two_gravities": {"gravity": TWO_GRAVITIES},
    "gravity_gradient": {"gravity_gradient": NU},
    "body_torque": {"body_torque": TAU_B},
    "space_torque": {"space_torque": TAU_S},
    "all": {"gravity": HEAVY, "gravity_gradient": NU, "body_torque": TAU_B, "space_torque": TAU_S},
}


@pytest.fixture(scope="module")
def run(run_once):
    """``run(name, ...)``: a memoised reference run (the mp version), so that one run serves several tests.

    Memoised for the whole test run (``run_once`` of tests/conftest.py), not only in this process: the tests
    that share a run may go to different pytest-xdist workers, and the runs are most of this file's time.
    """

    def run_(name, inertia=I_FULL, q0=Q0, w0=W0, t=TIMES, dps=40, order=None, **kw):
        kw = dict(CASES[name], **kw) if name in CASES else kw
        key = repr(
            (
                name,
                dps,
                order,
                np.asarray(inertia).tolist(),
                np.asarray(q0).tolist(),
                np.asarray(w0).tolist(),
                np.asarray(t).tolist(),
                sorted((k, _plain(v)) for k, v in kw.items()),
            )
        )
        label = "test_torque_reference-" + hashlib.sha256(key.encode()).hexdigest()[:20]
        return run_once(label, lambda: tr.reference_motion_mp(inertia, q0, w0, t, dps=dps, order=order, **kw))

    return run_


def _plain(v):
    """Nested lists / floats of a torque parameter, for the memo key."""
    if isinstance(v, (list, tuple)):
        return [_plain(a) for a in v]
    return np.asarray(v).tolist()


def as_float(rows):
    return np.array([[float(a) for a in r] for r in rows])


def max_rel_drift(values):
    """max_i |v_i - v_0| / max(|v_0|, 1e-300) for a sequence of mpf."""
    with mpmath.workdps(60):
        v0 = values[0]
        return max(abs(v - v0) for v in values) / max(abs(v0), mpmath.mpf("1e-300"))


def max_abs_diff(a, b):
    with mpmath.workdps(60):
        return max(abs(x - y) for ra, rb in zip(a, b) for x, y in zip(ra, rb))


# ----------------------------------------------------------------------------- scipy DOP853, written here


def _rot(q):
    """R(q / |q|), rows as tuples."""
    n = math.sqrt(sum(a * a for a in q))
    w, x, y, z = (a / n for a in q)
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )


def _mv(A, v):
    return tuple(a[0] * v[0] + a[1] * v[1] + a[2] * v[2] for a in A)


def _mtv(A, v):
    """A^T v."""
    return tuple(A[0][i] * v[0] + A[1][i] * v[1] + A[2][i] * v[2] for i in range(3))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dop853(inertia, q0, w0, t, gravity=None, gravity_gradient=None, body_torque=None, space_torque=None):
    """scipy's DOP853 at rtol = atol = 1e-13 on q' = q (x) (0, W) / 2, I W' = (I W) x W + tau.

    The right-hand side is written in plain Python floats: NumPy's overhead on 3-vectors made it
    several times slower, and it is called some 10^4 times per run.
    """
    I = np.diag(inertia) if np.ndim(inertia) == 1 else np.asarray(inertia, float)
    Iinv = np.linalg.inv(I)
    I_, Iinv_ = tuple(map(tuple, I.tolist())), tuple(map(tuple, Iinv.tolist()))
    grav = [
        (float(m), tuple(np.asarray(c, float).tolist()), tuple(np.asarray(g, float).tolist()))
        for m, c, g in gravity or []
    ]
    tau_b = None if body_torque is None else tuple(np.asarray(body_torque, float).tolist())
    tau_s = None if space_torque is None else tuple(np.asarray(space_torque, float).tolist())

    def f(s, y):
        qw, qx, qy, qz, w1, w2, w3 = y.tolist()
        q, w = (qw, qx, qy, qz), (w1, w2, w3)
        R = _rot(q)
        tau = [0.0, 0.0, 0.0]
        for m, c, g in grav:
            gb = _mtv(R, g)
            tau = [a + b for a, b in zip(tau, _cross(c, (m * gb[0], m * gb[1], m * gb[2])))]
        if gravity_gradient is not None:
            nu = gravity_gradient
            rb = _mtv(R, (math.cos(nu * s), math.sin(nu * s), 0.0))
            tau = [a + 3 * nu**2 * b for a, b in zip(tau, _cross(rb, _mv(I_, rb)))]
        if tau_b is not None:
            tau = [a + b for a, b in zip(tau, tau_b)]
        if tau_s is not None:
            tau = [a + b for a, b in zip(tau, _mtv(R, tau_s))]
        qd = qmul_floats(q, (0.0, w1, w2, w3))
        rhs = [a + b for a, b in zip(_cross(_mv(I_, w), w), tau)]
        return [0.5 * qd[0], 0.5 * qd[1], 0.5 * qd[2], 0.5 * qd[3], *_mv(Iinv_, rhs)]

    sol = solve_ivp(f, (0.0, t[-1]), np.concatenate([q0, w0]), method="DOP853", t_eval=t, rtol=1e-13, atol=1e-13)
    assert sol.success
    return sol.y.T[:, :4], sol.y.T[:, 4:]


# ----------------------------------------------------------------------------- 1. against DOP853


@pytest.mark.parametrize("name", list(CASES))
def test_agrees_with_dop853(name, run):
    q, w = run(name)
    qd, wd = dop853(I_FULL, Q0, W0, TIMES, **CASES[name])
    q, w = as_float(q), as_float(w)
    assert np.max(np.abs(w - wd)) / np.max(np.abs(w)) < 1e-10
    assert np.max(np.abs(q - qd)) < 1e-10


def test_float_api_matches_mp_api_and_handles_time_order(run):
    t = np.array([7.5, 0.0, 2.5, 7.5, 10.0])  # unsorted, with a repeat and t = 0
    q, w = tr.reference_motion(I_FULL, Q0, W0, t, gravity=HEAVY)
    assert q.shape == (5, 4) and w.shape == (5, 3) and q.dtype == np.float64
    qm, wm = run("gravity")
    idx = [3, 0, 1, 3, 4]
    np.testing.assert_array_equal(q, as_float(qm)[idx])
    np.testing.assert_array_equal(w, as_float(wm)[idx])
    np.testing.assert_allclose(q[1], Q0, rtol=0, atol=3e-16)
    np.testing.assert_array_equal(w[1], W0)
    qs, ws = tr.reference_motion(I_FULL, Q0, W0, 2.5, gravity=HEAVY)  # scalar time
    np.testing.assert_array_equal(qs[0], q[2])
    np.testing.assert_array_equal(ws[0], w[2])
    with pytest.raises(ValueError):
        tr.reference_motion(I_FULL, Q0, W0, [-1.0])


# ----------------------------------------------------------------------------- 2. integrals


@pytest.mark.parametrize("name", ["free", "gravity", "two_gravities"])
def test_energy_conserved(name, run):
    q, w = run(name)
    assert max_rel_drift(tr.energy(I_FULL, q, w, CASES[name].get("gravity"))) < 1e-25


def test_energy_is_not_conserved_with_the_wrong_potential_sign(run):
    q, w = run("gravity")
    flipped = [(-m, c, g) for m, c, g in HEAVY]
    assert max_rel_drift(tr.energy(I_FULL, q, w, flipped)) > 1e-3


def test_vertical_momentum_and_area_conserved(run):
    q, w = run("gravity")
    v = tr.vertical_momentum(I_FULL, q, w, G)
    a = tr.area_integral(I_FULL, q, w, G)
    assert max_rel_drift(v) < 1e-25
    with mpmath.workdps(60):  # mpf arithmetic rounds to the *current* precision (15 digits by default)
        assert max(abs(x + y) for x, y in zip(v, a)) < 1e-40


def test_space_angular_momentum_free_and_under_space_torque(run):
    q, w = run("free")
    L = tr.space_angular_momentum(I_FULL, q, w)
    assert max_abs_diff(L, [L[0]] * len(L)) < 1e-25 * float(mpmath.norm(mpmath.matrix(L[0])))
    # dL/dt = tau_s under a constant space torque alone: L(t) = L0 + tau_s t exactly
    q, w = run("space_torque")
    L = tr.space_angular_momentum(I_FULL, q, w)
    with mpmath.workdps(60):
        pred = [[L[0][j] + mpmath.mpf(TAU_S[j]) * mpmath.mpf(t) for j in range(3)] for t in TIMES]
    assert max_abs_diff(L, pred) < 1e-25


def test_unit_quaternion_conserved(run):
    for name in CASES:
        q, _ = run(name)
        with mpmath.workdps(60):
            assert max(abs(sum(a * a for a in qq) - 1) for qq in q) < 1e-40


def test_lagrange_top(run):
    I = np.array([1.5, 1.5, 0.8])
    grav = [(1.3, np.array([0.0, 0.0, 0.6]), G)]
    w0 = np.array([0.7, -1.1, 4.3])
    q, w = run("lagrange", inertia=I, w0=w0, gravity=grav)
    assert max_rel_drift(tr.lagrange_m3(I, w)) < 1e-25
    assert max_rel_drift(tr.energy(I, q, w, grav)) < 1e-25
    assert max_rel_drift(tr.vertical_momentum(I, q, w, G)) < 1e-25
    assert abs(float(w[-1][0]) - w0[0]) > 1e-2  # a non-trivial motion


@pytest.mark.parametrize("c", [(0.4, 0.0, 0.0), (0.25, -0.3, 0.0)])
def test_kovalevskaya(c, run):
    c = np.array(c)
    I = np.array([2.0, 2.0, 1.0]) * 0.7
    grav = [(1.3, c, G)]
    q, w = run("kovalevskaya", inertia=I, gravity=grav)
    K = tr.kovalevskaya_integral(I, q, w, 1.3, c, G)
    assert max_rel_drift(K) < 1e-25
    assert max_rel_drift(tr.energy(I, q, w, grav)) < 1e-25
    # discriminating: the opposite sign of the gravity term (or a wrong inertia) is not conserved
    assert max_rel_drift(tr.kovalevskaya_integral(I, q, w, -1.3, c, G)) > 1e-2
    assert max_rel_drift(tr.kovalevskaya_integral(I, q, w, 2 * 1.3, c, G)) > 1e-2


def test_kovalevskaya_formula_matches_the_written_form():
    """K = (w1^2 - w2^2 - mu g1)^2 + (2 w1 w2 - mu g2)^2, mu = mass |g| x0 / I3, gamma = R^T(-g_hat)."""
    I = np.array([2.0, 2.0, 1.0]) * 0.7
    q, w = np.array([0.8, 0.1, 0.5, -0.3]), np.array([0.3, -0.7, 1.1])
    with mpmath.workdps(50):
        R = tr.rotation_matrix(q)
        w = [mpmath.mpf(a) for a in w]
        gam = [R[2][i] for i in range(3)]  # R^T e_z (g = -9.81 e_z)
        mu = mpmath.mpf(1.3) * mpmath.mpf(9.81) * mpmath.mpf(0.4) / mpmath.mpf(0.7)
        K = (w[0] ** 2 - w[1] ** 2 - mu * gam[0]) ** 2 + (2 * w[0] * w[1] - mu * gam[1]) ** 2
        assert abs(K - tr.kovalevskaya_integral(I, q, w, 1.3, [0.4, 0, 0], G)) < 1e-40


def _gc_initial(c_y):
    """GC case with the area integral exactly zero: q0 = (w, x, y, 0), Omega0 = 2 (x, y, 0)."""
    q0 = np.array([0.8, 0.3, -0.45, 0.0])
    w0 = np.array([2 * q0[1], 2 * q0[2], 0.0])
    return q0, w0, np.array([0.4, c_y, 0.0])


@pytest.mark.parametrize("c_y", [0.0, -0.3])
def test_goryachev_chaplygin_on_zero_area(c_y, run):
    I = np.array([4.0, 4.0, 1.0]) * 0.7
    q0, w0, c = _gc_initial(c_y)
    grav = [(1.3, c, G)]
    q, w = run("gc", inertia=I, q0=q0, w0=w0, gravity=grav)
    area = tr.area_integral(I, q, w, G)
    assert max(abs(a) for a in area) < 1e-40
    Gc = tr.goryachev_chaplygin_integral(I, q, w, 1.3, c, G)
    assert max_rel_drift(Gc) < 1e-25
    # the '+' sign (G = w3 (w1^2 + w2^2) + mu w1 gamma3) is not conserved
    assert max_rel_drift(tr.goryachev_chaplygin_integral(I, q, w, -1.3, c, G)) > 1e-2
    assert abs(float(w[-1][2])) > 1e-2  # a non-trivial motion


def test_goryachev_chaplygin_needs_zero_area(run):
    I = np.array([4.0, 4.0, 1.0]) * 0.7
    c = np.array([0.4, 0.0, 0.0])
    grav = [(1.3, c, G)]
    q, w = run("gc_area", inertia=I, gravity=grav)
    area = tr.area_integral(I, q, w, G)
    assert abs(float(area[0])) > 0.5 and max_rel_drift(area) < 1e-25
    assert max_rel_drift(tr.goryachev_chaplygin_integral(I, q, w, 1.3, c, G)) > 1e-2


def test_goryachev_chaplygin_derivative_off_zero_area():
    """Central difference of G along the motion = -(kappa / (4 I3)) (x0 w2 - y0 w1) (I Omega).gamma."""
    I3, mass = 0.7, 1.3
    I = np.array([4.0, 4.0, 1.0]) * I3
    c = np.array([0.25, -0.3, 0.0])
    d = 1e-12
    ts = [3.0 - d, 3.0, 3.0 + d]
    q, w = tr.reference_motion_mp(I, Q0, W0, ts, gravity=[(mass, c, G)], dps=60)
    Gv = tr.goryachev_chaplygin_integral(I, q, w, mass, c, G, dps=60)
    area = tr.area_integral(I, q[1], w[1], G, dps=60)
    with mpmath.workdps(60):
        num = (Gv[2] - Gv[0]) / (mpmath.mpf(ts[2]) - mpmath.mpf(ts[0]))
        kappa = mpmath.mpf(mass) * mpmath.mpf(9.81) / mpmath.mpf(I3)
        pred = -kappa * (mpmath.mpf(c[0]) * w[1][1] - mpmath.mpf(c[1]) * w[1][0]) * area / (4 * mpmath.mpf(I3))
        assert abs(pred) > 0.1
        assert abs(num - pred) < 1e-15 * abs(pred)


def test_jacobi_integral_gravity_gradient(run):
    q, w = run("gravity_gradient")
    J = tr.jacobi_integral(I_FULL, q, w, NU, TIMES)
    assert max_rel_drift(J) < 1e-25
    # wrong sign of the rotating-frame term, or no potential: not conserved
    L3 = [a[2] for a in tr.space_angular_momentum(I_FULL, q, w)]
    E = tr.energy(I_FULL, q, w)
    with mpmath.workdps(60):
        assert max_rel_drift([j + 2 * NU * l for j, l in zip(J, L3)]) > 1e-3
        assert max_rel_drift([e - NU * l for e, l in zip(E, L3)]) > 1e-3


# ----------------------------------------------------------------------------- 3. self-consistency


@pytest.mark.parametrize("name", ["free", "all"])
def test_precisions_and_step_controls_agree(name, run):
    q40, w40 = run(name)
    q30, w30 = run(name, dps=30)
    q45, w45 = run(name, dps=45)
    qo, wo = run(name, order=30)  # different order, hence a different step sequence
    assert max_abs_diff(q30 + w30, q45 + w45) < 1e-25
    assert max_abs_diff(q40 + w40, q45 + w45) < 1e-35
    assert max_abs_diff(qo + wo, q45 + w45) < 1e-35


# ----------------------------------------------------------------------------- 4. exact solutions


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_body_torque_from_rest_about_principal_axis(axis):
    I = np.array([1.5, 2.5, 3.5])
    tau = np.zeros(3)
    tau[axis] = 0.7
    q0 = np.array([0.6, -0.2, 0.3, 0.7])
    q, w = tr.reference_motion_mp(I, q0, np.zeros(3), TIMES, body_torque=tau)
    with mpmath.workdps(50):
        n = mpmath.sqrt(sum(mpmath.mpf(a) ** 2 for a in q0))
        qn = [mpmath.mpf(a) / n for a in q0]
        for t, qq, ww in zip(TIMES, q, w):
            rate = mpmath.mpf(0.7) / mpmath.mpf(I[axis])
            exact_w = [rate * t if i == axis else 0 for i in range(3)]
            assert max(abs(a - b) for a, b in zip(ww, exact_w)) < 1e-35
            ang = rate * mpmath.mpf(t) ** 2 / 2
            dq = [mpmath.cos(ang / 2)] + [mpmath.sin(ang / 2) if i == axis else 0 for i in range(3)]
            exact_q = _qmul_mp(qn, dq)
            assert max(abs(a - b) for a, b in zip(qq, exact_q)) < 1e-35


def _qmul_mp(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return [
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ]


def test_free_symmetric_top_closed_form(run):
    I = np.array([2.0, 2.0, 0.75])
    q, w = run("free", inertia=I)
    with mpmath.workdps(50):
        lam = (mpmath.mpf(I[2]) - mpmath.mpf(I[0])) / mpmath.mpf(I[0]) * mpmath.mpf(W0[2])
        for t, ww in zip(TIMES, w):
            c, s = mpmath.cos(lam * t), mpmath.sin(lam * t)
            # I1 w1' = (I1 - I3) w3 w2 = -lam I1 w2,  I1 w2' = lam I1 w1
            exact = [W0[0] * c - W0[1] * s, W0[0] * s + W0[1] * c, W0[2]]
            assert max(abs(a - b) for a, b in zip(ww, exact)) < 1e-35


def test_gravity_gradient_relative_equilibrium():
    """Principal axes along (orbit radial, -, orbit normal), Omega = nu e_z: q(t) = rotation nu t about z."""
    I = np.array([1.0, 2.0, 3.0])
    q, w = tr.reference_motion_mp(I, [1, 0, 0, 0], [0, 0, NU], TIMES, gravity_gradient=NU)
    with mpmath.workdps(50):
        for t, qq, ww in zip(TIMES, q, w):
            a = mpmath.mpf(NU) * mpmath.mpf(t) / 2
            assert max(abs(x - y) for x, y in zip(qq, [mpmath.cos(a), 0, 0, mpmath.sin(a)])) < 1e-35
            assert max(abs(x - y) for x, y in zip(ww, [0, 0, NU])) < 1e-35


def test_no_torque_at_rest_is_one_exact_step():
    stats = {}
    q, w = tr.reference_motion_mp(I_FULL, Q0, np.zeros(3), [T_END], stats=stats)
    assert stats["steps"] == 1
    assert all(a == 0 for a in w[0])
