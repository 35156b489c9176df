"""Tests of the closed-form Lagrange top (:mod:`eulerpoisson.solvers.exact.lagrange`).

References are independent integrations of the Euler-Poisson equations in the
``(q, Omega)`` variables: scipy's DOP853 at ``rtol = atol = 1e-13`` (agreement
``<= 1e-10``) and, for the round-off claim, the Taylor integrator of
tests/_torque_reference.py at 34 digits (agreement ``<= 1e-13`` at ``t = 10``).
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from _reference import qmul_floats
from eulerpoisson.solvers.exact.lagrange import lagrange_top_motion

pytest.importorskip("mpmath")
import _torque_reference as tr  # noqa: E402

G = [0.0, 0.0, -9.81]
_TH = 1e-9  # tilt of the "near the vertical" cases


def _unit(q):
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q)


def _steady_precession():
    A, C, P = 1.0, 0.7, 4.0
    th = 1.2
    q0 = np.array([np.cos(th / 2), 0.0, np.sin(th / 2), 0.0])
    w, x, y, z = q0
    g1, g2 = 2 * (x * z - w * y), 2 * (y * z + w * x)
    u0 = 1 - 2 * (x * x + y * y)
    lam = 1.3  # Omega_perp = lam gamma_perp, p'(u0) = 0
    o3 = (P + A * u0 * lam**2) / (C * lam)
    return (A, C, 1.0, 0.5, [0.0, 0.0, -8.0], q0, [lam * g1, lam * g2, o3])


def _near_separatrix_spin():
    A, C, P = 1.0, 0.7, 4.0
    th = 1.2
    q0 = np.array([np.cos(th / 2), np.sin(th / 2), 0.0, 0.0])
    w, x, y, z = q0
    g2 = 2 * (y * z + w * x)
    o3 = 1.5
    o2 = C * o3 * (2 * x * x) / (A * g2)  # M_z = M_3
    o1 = np.sqrt(2 * P * (2 * x * x) / A - o2**2)  # E' = P
    return (A, C, 1.0, 0.5, [0.0, 0.0, -8.0], q0, [o1, o2, o3])


# (A, C, mass, ell, g, q0, omega0)
CASES = {
    "nutation": (1.0, 0.6, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [1.0, -0.5, 8.0]),
    "nutation_ell_negative": (1.0, 0.6, 1.0, -0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [1.0, -0.5, 8.0]),
    "looping": (1.0, 0.6, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [3.0, -2.5, 8.0]),
    "cusp": (1.0, 0.6, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [0.0, 0.0, 8.0]),
    "oblique_gravity": (1.3, 1.1, 2.0, -0.3, [1.0, -2.0, -5.0], _unit([1, 1, -1, 1]), [0.3, 2.0, -3.0]),
    "gravity_along_x": (0.8, 1.2, 1.5, 0.7, [3.0, 0.0, 0.0], _unit([0.2, -0.4, 0.8, 0.1]), [1.0, 1.0, 4.0]),
    "spherical_A_eq_C": (1.0, 1.0, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [1.0, -0.5, 2.0]),
    "flat_C_eq_2A": (1.0, 2.0, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [1.0, -0.5, 2.0]),
    "free_ell_zero": (1.0, 0.6, 1.0, 0.0, G, _unit([0.9, 0.3, 0.2, 0.1]), [1.0, -0.5, 8.0]),
    "free_g_zero": (1.0, 0.3, 1.0, 0.4, [0.0, 0.0, 0.0], _unit([0.9, 0.3, 0.2, 0.1]), [2.0, -0.5, 3.0]),
    "pendulum_from_rest": (1.0, 0.6, 1.0, 0.4, G, _unit([0.9, 0.3, 0.2, 0.1]), [0.0, 0.0, 0.0]),
    "rotating_pendulum": (1.0, 0.6, 1.0, 0.4, G, [0.0, 1.0, 0.0, 0.0], [7.0, 0.0, 0.0]),
    "sleeping_stable": (1.0, 0.6, 1.0, 0.4, G, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 20.0]),
    "sleeping_unstable": (1.0, 0.6, 1.0, 0.4, G, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
    "hanging_spin": (1.0, 0.6, 1.0, -0.4, G, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 3.0]),
    "upright_equilibrium": (1.0, 0.6, 1.0, 0.4, G, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
    "hanging_equilibrium": (1.0, 0.6, 1.0, 0.4, G, [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
    "through_vertical": (1.0, 0.6, 1.0, 0.4, G, [1.0, 0.0, 0.0, 0.0], [1.0, 0.5, 3.0]),
    "through_bottom": (1.0, 0.6, 1.0, 0.4, G, [0.0, 1.0, 0.0, 0.0], [1.0, 0.5, 3.0]),
    "near_vertical": (1.0, 0.6, 1.0, 0.4, G, [np.cos(_TH / 2), np.sin(_TH / 2), 0, 0], [1.0, 0.5, 3.0]),
    "near_bottom": (1.0, 0.6, 1.0, 0.4, G, [np.sin(_TH / 2), np.cos(_TH / 2), 0, 0], [1.0, 0.5, 3.0]),
    "steady_precession": _steady_precession(),
    "fast_gyroscope": (1.0, 0.7, 1.0, 0.5, [0.0, 0.0, -8.0], _unit([0.8, 0.0, 0.6, 0.0]), [0.1, 0.0, 30.0]),
}
# the separatrix cases are sensitive (hyperbolic point): compared over shorter times
SEPARATRIX = {
    # plane pendulum from the bottom with exactly the separatrix energy (m = 1)
    "separatrix_pendulum": (1.0, 0.7, 1.0, 0.5, [0.0, 0.0, -8.0], [0.0, 1.0, 0.0, 0.0], [4.0, 0.0, 0.0]),
    "near_separatrix_spin": _near_separatrix_spin(),
}


# ---------------------------------------------------------------------------
# independent references
# ---------------------------------------------------------------------------
def _qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ]
    )


def _rhs(t, y, A, C, mass, ell, g):
    """q' = q (x) (0, Omega) / 2, I Omega' = (I Omega) x Omega + (0, 0, ell) x (mass R^T g), I = diag(A, A, C).

    In plain Python floats: NumPy's overhead on 3- and 4-vectors made this 30x slower, and DOP853 at
    1e-13 calls it some 10^4 times per case.
    """
    qw, qx, qy, qz, o1, o2, o3 = y.tolist()
    q = (qw, qx, qy, qz)
    _, gb1, gb2, _ = qmul_floats(qmul_floats((qw, -qx, -qy, -qz), (0.0, *g)), q)  # R^T g
    a1, a2, a3 = A * o1, A * o2, C * o3  # I Omega
    qd = qmul_floats(q, (0.0, o1, o2, o3))
    return [
        0.5 * qd[0],
        0.5 * qd[1],
        0.5 * qd[2],
        0.5 * qd[3],
        (a2 * o3 - a3 * o2 - ell * mass * gb2) / A,
        (a3 * o1 - a1 * o3 + ell * mass * gb1) / A,
        (a1 * o2 - a2 * o1) / C,
    ]


def _dop853(case, t):
    A, C, mass, ell, g, q0, om0 = case
    y0 = np.r_[np.asarray(q0, float), np.asarray(om0, float)]
    out = np.empty((len(t), 7))
    for sel in (t > 0, t < 0):
        if np.any(sel):
            ts = t[sel]
            order = np.argsort(np.abs(ts))
            sol = solve_ivp(
                _rhs,
                (0.0, ts[order][-1]),
                y0,
                method="DOP853",
                rtol=1e-13,
                atol=1e-13,
                t_eval=ts[order],
                args=(float(A), float(C), float(mass), float(ell), tuple(float(v) for v in g)),
            )
            res = np.empty((len(ts), 7))
            res[order] = sol.y.T
            out[sel] = res
    out[t == 0] = y0
    return out[:, :4], out[:, 4:]


def _mp_taylor(case, t_end, dps=34):
    """The motion at ``t_end`` by tests/_torque_reference.py's Taylor integrator at ``dps`` digits (any sign of
    ``t_end``: (q(-t), -Omega(-t)) is the motion from (q0, -Omega0), the equations being even in Omega)."""
    A, C, mass, ell, g, q0, om0 = case
    s = 1.0 if t_end >= 0 else -1.0
    q, om = tr.reference_motion(
        [A, A, C], q0, s * np.asarray(om0, float), [abs(t_end)], gravity=(mass, (0.0, 0.0, ell), g), dps=dps
    )
    return q[0], s * om[0]


def _qdist(q, qr):
    s = np.sign(np.sum(q * qr, axis=-1))[..., None]
    s = np.where(s == 0, 1.0, s)
    return np.max(np.abs(q - s * qr))


def _rot(q, v):
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _invariants(case, q, om):
    A, C, mass, ell, g, _, _ = case
    inertia = np.array([A, A, C])
    g = np.asarray(g, float)
    E = 0.5 * np.sum(inertia * om * om, -1) - mass * np.sum(g * _rot(q, np.array([0.0, 0.0, ell])), -1)
    mg = np.sum(_rot(q, inertia * om) * g, -1) / max(np.linalg.norm(g), 1e-300)
    return E, mg, C * om[..., 2]


# ---------------------------------------------------------------------------
# accuracy
# ---------------------------------------------------------------------------
T_CHECK = np.array([0.0, 0.7, -1.3, 3.0, -4.5, 10.0])


@pytest.mark.parametrize("name", sorted(CASES))
def test_against_dop853(name):
    case = CASES[name]
    q, om = lagrange_top_motion(*case, T_CHECK)
    qr, omr = _dop853(case, T_CHECK)
    assert _qdist(q, qr) <= 1e-10
    assert np.max(np.abs(om - omr)) <= 1e-10 * max(1.0, np.max(np.abs(omr)))


@pytest.mark.parametrize("name", sorted(SEPARATRIX))
def test_separatrix_against_dop853(name):
    case = SEPARATRIX[name]
    t = np.array([0.0, 0.5, -1.0, 2.0, 3.0])
    q, om = lagrange_top_motion(*case, t)
    qr, omr = _dop853(case, t)
    assert _qdist(q, qr) <= 1e-10
    assert np.max(np.abs(om - omr)) <= 1e-10 * max(1.0, np.max(np.abs(omr)))


@pytest.mark.parametrize(
    "name, t_end",
    [("nutation", 10.0), ("looping", -10.0), ("near_bottom", 10.0), ("through_vertical", 10.0)],
)
def test_against_mpmath_roundoff(name, t_end):
    """Round-off accuracy: <= 1e-13 against a 34-digit Taylor integration."""
    case = CASES[name]
    q, om = lagrange_top_motion(*case, np.array([t_end]))
    qr, omr = _mp_taylor(case, t_end)
    assert _qdist(q[0], qr) <= 1e-13
    assert np.max(np.abs(om[0] - omr)) <= 1e-13 * max(1.0, np.max(np.abs(omr)))


def test_separatrix_closed_form():
    """Plane pendulum on the separatrix: Omega_1 = 2 w sech(w t), w = sqrt(P/A)."""
    case = SEPARATRIX["separatrix_pendulum"]
    t = np.linspace(-6.0, 6.0, 41)
    q, om = lagrange_top_motion(*case, t)
    wp = 2.0  # sqrt(P/A) with P = mass |g| |ell| = 4, A = 1
    np.testing.assert_allclose(om[:, 0], 2.0 * wp / np.cosh(wp * t), rtol=1e-13, atol=1e-15)
    np.testing.assert_array_equal(om[:, 1:], 0.0)
    theta = 4.0 * np.arctan(np.exp(wp * t)) - np.pi  # rotation angle about x from the bottom
    ref = np.stack([-np.sin(theta / 2), np.cos(theta / 2), 0 * t, 0 * t], axis=-1)  # q_x(theta) (0,1,0,0)
    assert _qdist(q, ref) <= 1e-14


# ---------------------------------------------------------------------------
# conservation, structure
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name",
    [
        "nutation",
        "looping",
        "oblique_gravity",
        "through_bottom",
        "pendulum_from_rest",
        "free_ell_zero",
        "near_vertical",
        "spherical_A_eq_C",
    ],
)
def test_conservation_long_time(name):
    case = CASES[name]
    t = np.linspace(-1000.0, 1000.0, 4001)
    q, om = lagrange_top_motion(*case, t)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-15)
    A, C, mass, ell, g, q0, om0 = case
    e0, m0, k0 = _invariants(case, np.asarray(q0, float), np.asarray(om0, float))
    E, mg, M3 = _invariants(case, q, om)
    P = mass * np.linalg.norm(g) * abs(ell)
    scale_e = 0.5 * (A * np.dot(om0[:2], om0[:2]) + C * om0[2] ** 2) + P + 1e-300
    scale_m = np.linalg.norm(np.array([A, A, C]) * np.asarray(om0)) + 1e-300
    assert np.max(np.abs(E - e0)) <= 3e-14 * max(scale_e, 1.0)
    assert np.max(np.abs(mg - m0)) <= 3e-14 * max(scale_m, 1.0)
    np.testing.assert_array_equal(M3, k0)


def test_t0_returns_initial_state_exactly():
    q0 = np.array([0.9, 0.3, 0.2, 0.1])
    q0 = q0 / np.linalg.norm(q0) * (1 + 3e-9)  # within the 1e-8 tolerance, not normalised
    om0 = np.array([1.0, -0.5, 8.0])
    for case in (CASES["nutation"], CASES["free_g_zero"], CASES["sleeping_stable"]):
        A, C, mass, ell, g = case[:5]
        q, om = lagrange_top_motion(A, C, mass, ell, g, q0, om0, np.array([1.0, 0.0, -2.0, 0.0]))
        np.testing.assert_array_equal(q[[1, 3]], [q0, q0])
        np.testing.assert_array_equal(om[[1, 3]], [om0, om0])
        np.testing.assert_allclose(np.linalg.norm(q[[0, 2]], axis=-1), 1.0, atol=1e-15)


@pytest.mark.parametrize("name", ["nutation", "looping", "through_vertical", "free_ell_zero", "sleeping_stable"])
def test_time_reversal(name):
    """q(-t; q0, W0) = q(t; q0, -W0) and W(-t; W0) = -W(t; -W0)."""
    A, C, mass, ell, g, q0, om0 = CASES[name]
    t = np.array([0.3, 2.0, 7.5])
    q1, om1 = lagrange_top_motion(A, C, mass, ell, g, q0, om0, -t)
    q2, om2 = lagrange_top_motion(A, C, mass, ell, g, q0, -np.asarray(om0), t)
    assert _qdist(q1, q2) <= 1e-13
    np.testing.assert_allclose(om1, -om2, atol=1e-13 * max(1.0, np.max(np.abs(om0))))


def test_unordered_times():
    case = CASES["looping"]
    t = np.array([5.0, -3.0, 0.2, 9.0, -0.1, 0.0])
    q, om = lagrange_top_motion(*case, t)
    order = np.argsort(t)
    qs, oms = lagrange_top_motion(*case, t[order])
    np.testing.assert_allclose(q[order], qs, rtol=0, atol=1e-15)
    np.testing.assert_allclose(om[order], oms, rtol=0, atol=1e-14)


def test_semigroup_large_time():
    """Propagating 500 + 500 equals 1000 (secular part of the angle integrals)."""
    case = CASES["near_bottom"]
    A, C, mass, ell, g, q0, om0 = case
    q, om = lagrange_top_motion(*case, np.array([500.0, 1000.0]))
    q2, om2 = lagrange_top_motion(A, C, mass, ell, g, q[0], om[0], np.array([500.0]))
    assert _qdist(q2[0], q[1]) <= 1e-11
    np.testing.assert_allclose(om2[0], om[1], atol=1e-11)


def test_batch_equals_one_by_one():
    names = ["nutation", "looping", "through_bottom", "free_g_zero", "sleeping_unstable", "oblique_gravity"]
    cases = [CASES[n] for n in names]
    A = np.array([c[0] for c in cases]).reshape(2, 3)
    C = np.array([c[1] for c in cases]).reshape(2, 3)
    mass = np.array([c[2] for c in cases]).reshape(2, 3)
    ell = np.array([c[3] for c in cases]).reshape(2, 3)
    g = np.array([c[4] for c in cases], float).reshape(2, 3, 3)
    q0 = np.array([c[5] for c in cases], float).reshape(2, 3, 4)
    om0 = np.array([c[6] for c in cases], float).reshape(2, 3, 3)
    t = np.array([-2.0, 0.0, 1.5, 30.0])
    q, om = lagrange_top_motion(A, C, mass, ell, g, q0, om0, t)
    assert q.shape == (2, 3, 4, 4) and om.shape == (2, 3, 4, 3)
    for k, case in enumerate(cases):
        qk, omk = lagrange_top_motion(*case, t)
        i, j = divmod(k, 3)
        np.testing.assert_allclose(q[i, j], qk, rtol=0, atol=1e-15)
        np.testing.assert_allclose(om[i, j], omk, rtol=0, atol=1e-14)
    # broadcasting of scalars against batched vectors
    q, om = lagrange_top_motion(1.0, 0.6, 1.0, [0.4, -0.4, 0.0], G, CASES["nutation"][5], [1.0, -0.5, 8.0], t)
    assert q.shape == (3, 4, 4)
    assert lagrange_top_motion(*CASES["nutation"], np.array([]))[0].shape == (0, 4)


def test_gravity_direction_covariance():
    """Rotating g and q0 by the same space rotation rotates q(t) and leaves Omega(t)."""
    A, C, mass, ell, g, q0, om0 = CASES["nutation"]
    r = _unit([0.3, -0.5, 0.7, 0.4])
    g2 = _rot(r, np.asarray(g, float))
    q02 = _qmul(r, q0)
    t = np.array([0.5, 4.0, -9.0])
    q1, om1 = lagrange_top_motion(A, C, mass, ell, g, q0, om0, t)
    q2, om2 = lagrange_top_motion(A, C, mass, ell, g2, q02, om0, t)
    assert _qdist(q2, np.array([_qmul(r, qq) for qq in q1])) <= 1e-14
    np.testing.assert_allclose(om2, om1, atol=1e-13)


def test_free_top_explicit():
    """g = 0, ell = 0 and mass = 0 all give the free symmetric top."""
    A, C, mass, ell, g, q0, om0 = CASES["nutation"]
    t = np.array([-3.0, 0.4, 12.0])
    q1, om1 = lagrange_top_motion(A, C, mass, 0.0, g, q0, om0, t)
    q2, om2 = lagrange_top_motion(A, C, mass, ell, [0.0, 0.0, 0.0], q0, om0, t)
    q3, om3 = lagrange_top_motion(A, C, 0.0, ell, g, q0, om0, t)
    np.testing.assert_array_equal(q1, q2)
    np.testing.assert_array_equal(q1, q3)
    np.testing.assert_array_equal(om1, om3)
    # body angular velocity rotates about e3 at rate Omega3 (A - C)/A, |Omega_perp| fixed
    b = om0[2] * (A - C) / A
    ref = np.stack(
        [
            om0[0] * np.cos(b * t) + om0[1] * np.sin(b * t),
            -om0[0] * np.sin(b * t) + om0[1] * np.cos(b * t),
            np.full_like(t, om0[2]),
        ],
        axis=-1,
    )
    np.testing.assert_allclose(om1, ref, atol=1e-14)


@pytest.mark.parametrize("gz", [1e-300, 1e-200, 1e-100, 1e-20, 1e6, 1e12])
def test_extreme_gravity_scales(gz):
    """Tiny gravity tends to the free top; huge gravity keeps the invariants."""
    A, C, mass, ell, _, q0, om0 = CASES["nutation"]
    case = (A, C, mass, ell, [0.0, 0.0, -gz], q0, om0)
    t = np.array([-5.0, 0.3, 5.0])
    q, om = lagrange_top_motion(*case, t)
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(om))
    if gz < 1e-15:
        qf, omf = lagrange_top_motion(A, C, mass, 0.0, [0.0, 0.0, -1.0], q0, om0, t)
        assert _qdist(q, qf) <= 1e-13
        np.testing.assert_allclose(om, omf, atol=1e-13)
    else:
        case_n = (A, C, mass, ell, [0.0, 0.0, -1.0], q0, om0)  # invariants with unit g
        e0, m0, _ = _invariants(case_n, np.asarray(q0), np.asarray(om0, float))
        E, mg, _ = _invariants(case_n, q, om)

        # E computed with g=1: kinetic + gz * potential; compare the total energy
        def pot(qq):
            return -mass * np.sum(np.array([0, 0, -1.0]) * _rot(qq, np.array([0.0, 0.0, ell])), -1)

        kin = E - pot(q)
        kin0 = e0 - pot(np.asarray(q0))
        tot, tot0 = kin + gz * pot(q), kin0 + gz * pot(np.asarray(q0))
        assert np.max(np.abs(tot - tot0)) <= 1e-14 * (abs(kin0) + gz * mass * ell)
        np.testing.assert_allclose(mg, m0, rtol=0, atol=1e-13 * np.sqrt((abs(kin0) + gz * mass * ell) * C))


@pytest.mark.parametrize(
    "name", ["sleeping_stable", "sleeping_unstable", "hanging_spin", "upright_equilibrium", "hanging_equilibrium"]
)
def test_sleeping_and_equilibria(name):
    """u = +-1 for all time: q(t) = q0 q_z(Omega3 t)."""
    A, C, mass, ell, g, q0, om0 = CASES[name]
    t = np.array([-50.0, 0.3, 1000.0])
    q, om = lagrange_top_motion(A, C, mass, ell, g, q0, om0, t)
    half = 0.5 * om0[2] * t
    ref = np.array([_qmul(q0, [np.cos(h), 0.0, 0.0, np.sin(h)]) for h in half])
    assert _qdist(q, ref) <= 1e-13
    np.testing.assert_array_equal(om, np.broadcast_to(om0, om.shape))


# ---------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------
_GOOD = dict(
    A=1.0, C=0.6, mass=1.0, ell=0.4, g=G, q0=[1.0, 0.0, 0.0, 0.0], omega0=[0.1, 0.2, 3.0], t=np.array([0.0, 1.0])
)


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(A=0.0), "A must be > 0"),
        (dict(A=-1.0), "A must be > 0"),
        (dict(C=0.0), "C must be > 0"),
        (dict(C=2.5), "triangle inequality"),
        (dict(mass=-1.0), "mass must be >= 0"),
        (dict(A=np.nan), "A must be finite"),
        (dict(C=np.inf), "C must be finite"),
        (dict(mass=np.nan), "mass must be finite"),
        (dict(ell=np.nan), "ell must be finite"),
        (dict(g=[0.0, np.nan, 1.0]), "g must be finite"),
        (dict(q0=[np.nan, 0, 0, 1]), "q0 must be finite"),
        (dict(omega0=[0, 0, np.nan]), "omega0 must be finite"),
        (dict(t=[0.0, np.nan]), "t must be finite"),
        (dict(q0=[1.0, 2e-4, 0.0, 0.0]), "q0 must be a unit quaternion"),
        (dict(q0=[2.0, 0.0, 0.0, 0.0]), "q0 must be a unit quaternion"),
        (dict(q0=[1.0, 0.0, 0.0]), r"q0 must have shape \(\.\.\., 4\)"),
        (dict(g=[0.0, -9.81]), r"g must have shape \(\.\.\., 3\)"),
        (dict(omega0=[[0.0, 0.0, 1.0, 2.0]]), r"omega0 must have shape \(\.\.\., 3\)"),
        (dict(t=[[0.0, 1.0]]), "t must be one-dimensional"),
        (dict(A=[1.0, 2.0], C=[0.5, 0.6, 0.7]), "do not broadcast"),
        (dict(omega0=np.zeros((2, 3)), q0=np.tile([1.0, 0, 0, 0], (3, 1))), "do not broadcast"),
        (dict(A="abc"), "A must be a real array"),
    ],
)
def test_bad_input(change, match):
    kw = dict(_GOOD)
    kw.update(change)
    with pytest.raises(ValueError, match=match):
        lagrange_top_motion(**kw)
