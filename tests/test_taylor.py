"""The ``taylor`` method: the paper's Lie series (eq. 1.23.1) as a Taylor integrator.

Truth used here, independent of the code under test: closed forms (rotation
about a principal axis, the symmetric top with any inertia tensor), mpmath's
own Taylor ODE solver ``mpmath.odefun`` at 32 digits on the quaternion form
of the equations, scipy's DOP853 (``tests/_reference.py``), SymPy Lie
derivatives of the Hamiltonian (eq. 1.15), conservation of E and m, the
exact time-reversal symmetry, and the ``exact`` method when it is available.
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from _limits import HANG_GUARD_S
from _reference import _qmul as ref_qmul
from _reference import quaternion_distance, reference_motion
from eulerpoisson import Attitude, RigidBody
from eulerpoisson.errors import EulerPoissonError, InvalidInputError
from eulerpoisson.solvers import get_method, solve
from eulerpoisson.solvers.taylor import kernels as K
from eulerpoisson.solvers.taylor.method import (
    DEFAULT_FIXED_ORDER,
    auto_order,
    integrate_principal,
    lie_series_coefficients,
    taylor_coefficients,
)

EPS = np.finfo(float).eps
I123 = np.array([1.0, 2.0, 3.0])
W0 = np.array([1.0, 0.1, 0.5])


# ---------------------------------------------------------------------------
# independent closed forms
# ---------------------------------------------------------------------------
def axis_quaternion(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * k])


def rotate(axis, angle, v):
    """Rodrigues' rotation of v about axis by angle."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    return v * math.cos(angle) + np.cross(k, v) * math.sin(angle) + k * np.dot(k, v) * (1 - math.cos(angle))


def symmetric_top(I1, I3, Q, q0, w0, t):
    """Closed-form motion of a symmetric top with inertia Q diag(I1, I1, I3) Q^T.

    R(t) = exp(t [m]x / I1) R0 exp(-lam t [a]x), a = Q e3, lam = (I3 - I1)(a.W0)/I1
    (then R^T dR/dt = [M]x/I1 - lam [a]x = [W]x), and M(t) = exp(lam t [a]x) M0.
    """
    I = Q @ np.diag([I1, I1, I3]) @ Q.T
    a = Q[:, 2]
    M0 = I @ w0
    R0 = Attitude(q0).as_matrix()
    m = R0 @ M0
    lam = (I3 - I1) * np.dot(a, w0) / I1
    qs, ws = [], []
    for tk in t:
        qk = ref_qmul(ref_qmul(axis_quaternion(m, np.linalg.norm(m) * tk / I1), q0), axis_quaternion(a, -lam * tk))
        qs.append(qk)
        ws.append(np.linalg.solve(I, rotate(a, lam * tk, M0)))
    return I, np.array(qs), np.array(ws)


def random_rotation(seed):
    return Attitude.random(rng=np.random.default_rng(seed)).as_matrix()


# ---------------------------------------------------------------------------
# Taylor coefficients
# ---------------------------------------------------------------------------
def test_coefficients_principal_axis_rotation_are_tan_series():
    # rotation about e1 at rate w: n = e1 tan(w t / 2), Omega constant
    mp = pytest.importorskip("mpmath")
    w = 1.7
    nk, wk = taylor_coefficients([0.0, 0.0, 0.0], [w, 0.0, 0.0], I123, 25)
    with mp.workdps(30):
        ref = [float(c) for c in mp.taylor(lambda s: mp.tan(w * s / 2), 0, 25)]
    np.testing.assert_allclose(nk[:, 0], ref, rtol=1e-14, atol=1e-30)
    assert np.all(nk[:, 1:] == 0) and np.all(wk[1:] == 0)
    np.testing.assert_array_equal(wk[0], [w, 0.0, 0.0])


def test_compiled_coefficients_equal_generic_ones():
    rng = np.random.default_rng(1)
    moments = np.sort(rng.uniform(1, 3, (4, 3)), axis=1)
    n0 = rng.uniform(-1, 1, (4, 3))
    w0 = rng.standard_normal((4, 3))
    Nc, Wc = K.coefficients_numba(moments, n0, w0, 22)
    Ng, Wg = taylor_coefficients(n0, w0, moments, 22)
    np.testing.assert_allclose(Nc, np.moveaxis(Ng, 0, 1), rtol=1e-13, atol=1e-15 * np.abs(Nc).max())
    np.testing.assert_allclose(Wc, np.moveaxis(Wg, 0, 1), rtol=1e-13, atol=1e-15 * np.abs(Wc).max())
    # the full-tensor recurrence (M = I Omega) agrees with the principal-frame one
    Nt, Wt = taylor_coefficients(n0, w0, moments[:, :, None] * np.eye(3), 22)
    np.testing.assert_allclose(Nt, Ng, rtol=1e-12, atol=1e-14 * np.abs(Ng).max())
    np.testing.assert_allclose(Wt, Wg, rtol=1e-12, atol=1e-14 * np.abs(Wg).max())


def _series_mul(a, b):
    """Truncated product of coefficient arrays (K+1, ...) (numpy, test side)."""
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
    for k in range(a.shape[0]):
        for j in range(k + 1):
            out[k] += a[j] * b[k - j]
    return out


def test_canonical_recurrence_agrees_with_n_omega_recurrence():
    # two different recurrences on two different systems (eq. 1.16 and 1.30),
    # linked by pi = 2 A I Omega (eq. 1.26), i.e. (1 + n^2) pi = 2 (M + n x M)
    R = random_rotation(3)
    I = R @ np.diag([1.2, 1.9, 2.6]) @ R.T
    n0 = np.array([0.3, -0.2, 0.5])
    w0 = np.array([0.7, -0.4, 1.1])
    M0 = I @ w0
    pi0 = 2 * (M0 + np.cross(n0, M0)) / (1 + n0 @ n0)
    K_ = 16
    nk, wk = taylor_coefficients(n0, w0, I, K_)
    nk2, pk = lie_series_coefficients(n0, pi0, I, K_)
    np.testing.assert_allclose(nk2, nk, rtol=0, atol=1e-13 * np.abs(nk).max())
    Mk = wk @ I.T
    # (1 + n.n) as a series
    d = np.zeros(K_ + 1)
    for k in range(K_ + 1):
        d[k] = sum(nk[j] @ nk[k - j] for j in range(k + 1))
    d[0] += 1
    lhs = _series_mul(pk, d[:, None])
    cross = np.zeros_like(Mk)
    for k in range(K_ + 1):
        cross[k] = sum(np.cross(nk[j], Mk[k - j]) for j in range(k + 1))
    rhs = 2 * (Mk + cross)
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-12 * np.abs(rhs).max())


def _sympy_lie_terms(order, moments, pi0):
    """L_X^k z / k! at n = 0 from SymPy derivatives of H (eq. 1.15), exact rationals.

    L_X f = {f, H} lowers the degree in n by at most one, so L_X^k z is kept to
    degree order - k in n (exact for the terms returned). The polynomials are SymPy's
    sparse polynomials over QQ (``sympy.ring``): the exact operations of ``sympy.Poly``,
    8x faster.
    """
    sp = pytest.importorskip("sympy")
    n = sp.symbols("n1:4")
    p = sp.symbols("p1:4")
    nv, pv = sp.Matrix(n), sp.Matrix(p)
    skew = sp.Matrix([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    u = (sp.eye(3) + nv * nv.T - skew) * pv  # A~ pi
    ring, *gens = sp.ring(list(n) + list(p), sp.QQ)
    H = ring(sp.Rational(1, 8) * sum(u[i] ** 2 / sp.Rational(moments[i]) for i in range(3)))
    dHdn = [H.diff(x) for x in gens[:3]]
    dHdp = [H.diff(x) for x in gens[3:]]
    p0 = [sp.Rational(v) for v in pi0]

    def at_origin(f):  # value at n = 0, pi = pi0
        return sum(
            (
                ring.domain.to_sympy(c) * p0[0] ** m[3] * p0[1] ** m[4] * p0[2] ** m[5]
                for m, c in f.terms()
                if m[:3] == (0, 0, 0)
            ),
            sp.Integer(0),
        )

    out = np.zeros((order + 1, 6))
    for a, f in enumerate(gens):
        for k in range(order + 1):
            out[k, a] = float(at_origin(f) / math.factorial(k))
            if k < order:
                g = sum((f.diff(gens[i]) * dHdp[i] - f.diff(gens[3 + i]) * dHdn[i] for i in range(3)), ring.zero)
                f = ring({m: c for m, c in g.terms() if sum(m[:3]) <= order - k - 1})
    return out[:, :3], out[:, 3:]


def test_lie_series_terms_match_sympy_lie_derivatives():
    # paper eq. 1.23.1 itself: z_k = L_X^k z / k! from the Hamiltonian (1.15), n0 = 0
    moments = ["1", "2", "3"]
    pi0 = ["2", "1/4", "3"]
    order = 5
    n_ref, p_ref = _sympy_lie_terms(order, moments, pi0)
    pi0f = np.array([2.0, 0.25, 3.0])
    nk, pk = lie_series_coefficients([0.0, 0.0, 0.0], pi0f, [1.0, 2.0, 3.0], order)
    np.testing.assert_allclose(nk, n_ref, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(pk, p_ref, rtol=1e-14, atol=1e-15)
    # the (n, Omega) recurrence gives the same n terms: Omega0 = I^-1 pi0 / 2 at n0 = 0
    nk2, _ = taylor_coefficients([0.0, 0.0, 0.0], pi0f / (2 * np.array([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0], order)
    np.testing.assert_allclose(nk2, n_ref, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("case", ["diagonal_order8", "full_tensor_n0_order4"])
def test_lie_series_terms_match_symbolic_audit(case):
    sp = pytest.importorskip("sympy", reason="the symbolic extra (sympy) is not installed")
    from eulerpoisson.paper.symbolic import lie_series

    pi0 = [sp.Rational(3, 2), sp.Rational(-1, 2), sp.Rational(1)]
    if case == "diagonal_order8":
        order = 8
        Isym = [sp.Integer(1), sp.Rational(3, 2), sp.Integer(2)]
        n0 = [0, 0, 0]
        I = np.diag([float(x) for x in Isym])
        inertia = np.diag(I)
    else:
        order = 4
        # R diag(1, 3/2, 2) R^T with the rational rotation R = [[2,-1,2],[2,2,-1],[-1,2,2]]/3
        Isym = sp.Matrix(
            [
                [sp.Rational(3, 2), sp.Rational(-1, 3), sp.Rational(1, 3)],
                [sp.Rational(-1, 3), sp.Rational(4, 3), 0],
                [sp.Rational(1, 3), 0, sp.Rational(5, 3)],
            ]
        )
        n0 = [sp.Rational(1, 5), sp.Rational(-1, 10), sp.Rational(3, 10)]
        I = np.array(Isym.tolist(), dtype=float)
        inertia = I
    t = sp.Symbol("t")
    kw = {} if case == "diagonal_order8" else {"n0": n0}
    n_t, pi_t = lie_series(order, inertia=Isym, pi0=pi0, t=t, **kw)

    def coeffs(expr):
        c = sp.Poly(expr, t).all_coeffs()[::-1]
        return np.array([float(x) for x in c] + [0.0] * (order + 1 - len(c)))

    n_ref = np.stack([coeffs(n_t[i]) for i in range(3)], axis=-1)
    p_ref = np.stack([coeffs(pi_t[i]) for i in range(3)], axis=-1)
    pif = np.array([float(x) for x in pi0])
    n0f = np.array([float(x) for x in n0])
    nk, pk = lie_series_coefficients(n0f, pif, inertia, order)
    np.testing.assert_allclose(nk, n_ref, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(pk, p_ref, rtol=1e-13, atol=1e-15)
    # the (n, Omega) recurrence: Omega0 = I^-1 A~(n0) pi0 / 2 (eq. 1.26)
    Api = pif + n0f * (n0f @ pif) - np.cross(n0f, pif)
    nk2, _ = taylor_coefficients(n0f, np.linalg.solve(I, Api) / 2, inertia, order)
    np.testing.assert_allclose(nk2, n_ref, rtol=1e-13, atol=1e-15)


# ---------------------------------------------------------------------------
# higher precision: the same recurrence in mpmath and longdouble
# ---------------------------------------------------------------------------
def test_mpmath_coefficients_reproduce_float64_and_tan_series():
    mp = pytest.importorskip("mpmath")
    with mp.workdps(30):
        n0 = np.array([mp.mpf(0)] * 3, dtype=object)
        w0 = np.array([mp.mpf(1), mp.mpf("0.125"), mp.mpf("0.5")], dtype=object)
        m = np.array([mp.mpf(1), mp.mpf(2), mp.mpf(3)], dtype=object)
        nk, wk = taylor_coefficients(n0, w0, m, 20)
        assert isinstance(nk[5, 0], mp.mpf)
        nf, wf = taylor_coefficients(np.zeros(3), [1.0, 0.125, 0.5], I123, 20)
        np.testing.assert_allclose(nk.astype(float), nf, rtol=1e-14, atol=1e-16)
        np.testing.assert_allclose(wk.astype(float), wf, rtol=1e-14, atol=1e-16)
        # closed form to 28 digits: rotation about a principal axis
        w = mp.mpf(3) / 7
        nk, _ = taylor_coefficients(n0, np.array([mp.mpf(0), mp.mpf(0), w], dtype=object), m, 15)
        with mp.workdps(60):
            ref = mp.taylor(lambda s: mp.tan(w * s / 2), 0, 15)
        assert max(abs(nk[k, 2] - ref[k]) for k in range(16)) < mp.mpf("1e-28")


def _mp_truth():
    """The motion at t = -1, 2, 4 by mpmath.odefun (its own Taylor method) at 32 digits,
    on the quaternion form dq/dt = q (x) (0, W)/2 and Euler's equations."""
    import mpmath as mp

    I = [mp.mpf(1), mp.mpf(2), mp.mpf(3)]
    w0 = [mp.mpf(1), mp.mpf("0.125"), mp.mpf("0.5")]

    def f(_, y):
        q0, q1, q2, q3, w1, w2, w3 = y
        return [
            (-q1 * w1 - q2 * w2 - q3 * w3) / 2,
            (q0 * w1 + q2 * w3 - q3 * w2) / 2,
            (q0 * w2 - q1 * w3 + q3 * w1) / 2,
            (q0 * w3 + q1 * w2 - q2 * w1) / 2,
            (I[1] - I[2]) / I[0] * w2 * w3,
            (I[2] - I[0]) / I[1] * w3 * w1,
            (I[0] - I[1]) / I[2] * w1 * w2,
        ]

    out = {}
    with mp.workdps(32):
        y0 = [mp.mpf(1), 0, 0, 0] + w0
        fwd = mp.odefun(f, 0, y0)
        out[2.0] = fwd(2)
        out[4.0] = fwd(4)
        # backwards: integrate the time-reversed system (W -> -W) forward to 1
        bwd = mp.odefun(f, 0, [mp.mpf(1), 0, 0, 0] + [-x for x in w0])
        yb = bwd(1)
        out[-1.0] = yb[:4] + [-x for x in yb[4:]]
    return out


@pytest.fixture(scope="module")
def mp_truth(run_once):
    """:func:`_mp_truth`, computed once per test run (``run_once`` of tests/conftest.py): the two tests that use
    it may run on different pytest-xdist workers, and it is most of their cost."""
    pytest.importorskip("mpmath")
    return run_once("test_taylor-mp_truth", _mp_truth)


def test_mpmath_integration_converges_to_30_digits(mp_truth):
    mp = pytest.importorskip("mpmath")
    t = [2.0, -1.0]
    with mp.workdps(32):
        m = np.array([mp.mpf(1), mp.mpf(2), mp.mpf(3)], dtype=object)
        w0 = np.array([mp.mpf(1), mp.mpf("0.125"), mp.mpf("0.5")], dtype=object)
        tt = np.array([mp.mpf(x) for x in t], dtype=object)
        errs = []
        for tol in (1e-20, 1e-30):
            q, om, st = integrate_principal(m, w0, tt, tol=tol)
            assert st["backend"] == "numpy" and st["max_order"] == auto_order(tol)
            err = max(
                max(abs(q[i, c] - mp_truth[tk][c]) for c in range(4))
                + max(abs(om[i, c] - mp_truth[tk][4 + c]) for c in range(3))
                for i, tk in enumerate(t)
            )
            errs.append(float(err))
    assert errs[0] < 1e-18
    assert errs[1] < 1e-28
    # longdouble runs the same code
    ld = np.longdouble
    q, om, _ = integrate_principal(I123.astype(ld), np.array([1, 0.125, 0.5], ld), np.array(t, ld), tol=1e-18)
    assert q.dtype == ld
    for i, tk in enumerate(t):
        ref = np.array([float(x) for x in mp_truth[tk]])
        assert np.max(np.abs(q[i].astype(float) - ref[:4])) < 1e-15
        ref_ld = np.array([ld(float(x)) + ld(float(x - float(x))) for x in mp_truth[tk][:4]])
        assert float(np.max(np.abs(q[i] - ref_ld))) < 1e-17
    # and float64 at machine precision
    q, om, _ = integrate_principal(I123, [1, 0.125, 0.5], t, tol=EPS)
    for i, tk in enumerate(t):
        ref = np.array([float(x) for x in mp_truth[tk]])
        assert np.max(np.abs(q[i] - ref[:4])) < 2e-15
        assert np.max(np.abs(om[i] - ref[4:])) < 2e-15


def test_mpmath_integration_through_chart_changes_stays_exact(mp_truth):
    """The generic path keeps the working precision through chart changes and many steps:
    no sum (time, state, fold) may silently fall back to float64 (a Python int 0 plus a
    float64 step is a float64, which cost 1e-17 after a few steps)."""
    mp = pytest.importorskip("mpmath")
    t = [2.0, 4.0]
    with mp.workdps(30):
        m = np.array([mp.mpf(1), mp.mpf(2), mp.mpf(3)], dtype=object)
        w0 = np.array([mp.mpf(1), mp.mpf("0.125"), mp.mpf("0.5")], dtype=object)
        for thr, tt in ((1.0, np.array([mp.mpf(x) for x in t], dtype=object)), (0.0, np.array(t))):
            q, om, st = integrate_principal(m, w0, tt, tol=1e-28, chart_threshold=thr)
            assert st["chart_changes"] >= 2
            assert all(isinstance(x, mp.mpf) for x in q.ravel())
            for i, tk in enumerate(t):
                err = max(abs(q[i, c] - mp_truth[tk][c]) for c in range(4))
                err = max(err, max(abs(om[i, c] - mp_truth[tk][4 + c]) for c in range(3)))
                assert err < mp.mpf("1e-25"), (thr, tk, err)


def test_float64_round_off_is_compensated():
    """At tol = eps the error is round-off; the compensated (two-sum) state update keeps it
    near a few eps at t = 100 (it was 2e-14 with plain sums), judged against the same
    integrator in 80-bit long double (truncation there 1e-19), for random bodies."""
    ld = np.longdouble
    if np.finfo(ld).eps > 1e-18:
        pytest.skip("long double is not 80-bit here")
    rng = np.random.default_rng(1)
    m = np.sort(rng.uniform(1, 3, (8, 3)), axis=1)
    w0 = rng.standard_normal((8, 3))
    w0[0] = W0
    m[0] = I123
    t = np.array([100.0])
    qr, wr, _ = integrate_principal(
        m.astype(ld),
        w0.astype(ld),
        t.astype(ld),
        q0=np.tile(np.array([1, 0, 0, 0], ld), (8, 1)),
        tol=2e-19,
        backend="numpy",
    )
    for backend in ("auto", "numpy"):
        q, om, _ = integrate_principal(m, w0, t, tol=EPS, backend=backend)
        eq = np.abs(q - qr.astype(float)).max(axis=(1, 2))
        ew = np.abs(om - wr.astype(float)).max(axis=(1, 2))
        assert np.median(eq) < 4e-15 and eq.max() < 1.5e-14, eq
        assert np.median(ew) < 3e-15 and ew.max() < 1e-14, ew
    # energy and |M| at t = 2000 (about 260 turns), relative error a few eps (was 2e-14)
    t = np.linspace(0.0, 2000.0, 21)
    q, om, _ = integrate_principal(I123, W0, t, tol=EPS)
    assert np.max(np.abs((I123 * om**2).sum(-1) / (I123 * W0**2).sum() - 1)) < 8e-15
    assert np.max(np.abs(np.linalg.norm(I123 * om, axis=-1) / np.linalg.norm(I123 * W0) - 1)) < 8e-15


# ---------------------------------------------------------------------------
# accuracy of solve(..., method="taylor")
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "I1, I3, w0, seed",
    [
        (2.0, 3.0, [1.0, 0.1, 0.5], None),  # oblate, diagonal
        (3.0, 1.0, [0.3, 0.2, 5.0], None),  # prolate, fast spin about the axis
        (1.5, 2.5, [0.4, -1.2, 0.8], 7),  # full (non-diagonal) tensor, random attitude
    ],
)
def test_symmetric_top_closed_form_to_t100(I1, I3, w0, seed):
    Q = np.eye(3) if seed is None else random_rotation(seed)
    q0 = np.array([1.0, 0, 0, 0]) if seed is None else Attitude.random(rng=np.random.default_rng(seed)).as_quaternion()
    w0 = np.asarray(w0)
    t = np.array([0.0, 0.5, 13.0, 50.0, -20.0, 100.0])
    I, q_ref, w_ref = symmetric_top(I1, I3, Q, q0, w0, t)
    body = RigidBody(I if seed is not None else np.diag(I))
    tr = solve(body, t, omega0=w0, attitude0=q0, method="taylor")
    scale = 1 + np.linalg.norm(w0) * np.abs(t)  # angle turned
    assert np.all(quaternion_distance(tr.quaternion, q_ref) <= 1e-15 * scale + 1e-15)
    assert np.all(np.abs(tr.omega - w_ref).max(axis=-1) <= 1e-15 * scale * np.linalg.norm(w0))


@pytest.mark.parametrize(
    "name, inertia, w0, rel",
    [
        ("generic", [1.0, 2.0, 3.0], [1.0, 0.1, 0.5], 1e-15),
        # |M|^2/2E = I2 (1 - 3e-4): the flip times amplify any error in E, |M| (ill-conditioned)
        ("near_separatrix", [1.0, 2.0, 3.0], [0.05, 1.0, 0.02], 2e-14),
        ("fast", [1.0, 2.0, 3.0], [30.0, 5.0, 40.0], 3e-15),
        ("full_tensor", "random", [0.6, -0.9, 0.4], None),
    ],
)
def test_agrees_with_independent_references(name, inertia, w0, rel):
    if inertia == "random":
        R = random_rotation(11)
        inertia = R @ np.diag([1.1, 1.7, 2.5]) @ R.T
    t = np.array([0.0, 1.5, -2.0, 3.0]) if name == "fast" else np.array([0.0, 3.0, -10.0, 40.0, 100.0])
    q0 = Attitude.random(rng=np.random.default_rng(5)).as_quaternion()
    tr = solve(inertia, t, omega0=w0, attitude0=q0, method="taylor")
    # DOP853 at rtol = atol = 1e-13 (moderate accuracy)
    qr, wr = reference_motion(inertia, np.asarray(w0), q0, t)
    scale = 1 + np.linalg.norm(w0) * np.abs(t)
    assert np.all(quaternion_distance(tr.quaternion, qr) < 1e-12 * scale)
    assert np.all(np.abs(tr.omega - wr).max(-1) < 1e-12 * scale * np.linalg.norm(w0))
    # the integrals of motion
    d = tr.drift()
    assert d["energy"] < 3e-14 and d["m_norm"] < 3e-14
    assert max(d["m_x"], d["m_y"], d["m_z"]) < 3e-14
    # the same algorithm in longdouble (3 more digits) bounds the float64 round-off
    if not RigidBody(inertia).is_diagonal:
        return
    ld = np.longdouble
    ql, wl, _ = integrate_principal(
        np.asarray(inertia, ld), np.asarray(w0, ld), t.astype(ld), q0=q0.astype(ld), tol=float(np.finfo(ld).eps)
    )
    err = quaternion_distance(tr.quaternion, ql.astype(float))
    assert np.all(err < rel * scale + 1e-15), err


def test_agrees_with_exact_method_to_t100():
    R = random_rotation(2)
    cases = [
        ([1.0, 2.0, 3.0], [1.0, 0.1, 0.5]),
        ([2.0, 2.0, 3.0], [1.0, 0.1, 0.5]),
        ([1.0, 2.0, 3.0], [0.05, 1.0, 0.02]),
        ([1.0, 2.0, 3.0], [3.0, 0.5, 4.0]),
        (R @ np.diag([1.1, 1.7, 2.5]) @ R.T, [0.6, -0.9, 0.4]),
    ]
    t = np.array([0.0, -30.0, 7.0, 100.0])
    for inertia, w0 in cases:
        a = solve(inertia, t, omega0=w0, method="taylor", tol=1e-15)
        b = solve(inertia, t, omega0=w0, method="exact")
        scale = 1 + np.linalg.norm(w0) * np.abs(t) / 30  # round-off grows with the angle turned
        assert np.all(quaternion_distance(a.quaternion, b.quaternion) < 1e-13 * scale), (inertia, w0)
        assert np.all(np.abs(a.omega - b.omega).max(-1) < 1e-13 * scale * np.linalg.norm(w0)), (inertia, w0)


def test_error_is_proportional_to_tol():
    t = np.array([0.0, 20.0, 100.0])
    ld = np.longdouble
    ql, _, _ = integrate_principal(I123.astype(ld), W0.astype(ld), t.astype(ld), tol=float(np.finfo(ld).eps))
    for tol in (1e-6, 1e-9, 1e-12):
        tr = solve(I123, t, omega0=W0, method="taylor", tol=tol)
        err = quaternion_distance(tr.quaternion, ql.astype(float)).max()
        assert tol / 100 < err < 30 * tol, (tol, err)
        assert tr.stats["max_order"] == auto_order(tol)


@pytest.mark.parametrize("order, dts", [(DEFAULT_FIXED_ORDER, [0.4, 0.2, 0.1, 0.05]), (7, [0.25, 0.125, 0.0625])])
def test_fixed_step_convergence_order(order, dts):
    t = np.array([0.0, 2.3, -3.1, 5.0])
    q_ref, w_ref = reference_motion(I123, W0, np.array([1.0, 0, 0, 0]), t)
    errs = []
    for dt in dts:
        kw = {"dt": dt} if order == DEFAULT_FIXED_ORDER else {"dt": dt, "order": order}
        tr = solve(I123, t, omega0=W0, method="taylor", **kw)
        assert tr.stats["max_order"] == order
        assert tr.stats["steps"] == sum(math.ceil(x / dt - 1e-9) for x in (5.0, 3.1))
        errs.append(max(quaternion_distance(tr.quaternion, q_ref).max(), np.abs(tr.omega - w_ref).max()))
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:])) / np.log2(np.array(dts[:-1]) / np.array(dts[1:]))
    assert np.all(np.abs(slopes - order) < 0.5), slopes


def test_registry_attributes():
    cls = get_method("taylor")
    assert cls.refine == "dt" and cls.order == DEFAULT_FIXED_ORDER and cls.negative_times
    assert cls.options["tol"] == 1e-15 and cls.options["order"] is None and cls.options["dt"] is None


# ---------------------------------------------------------------------------
# charts through alpha = pi, long runs
# ---------------------------------------------------------------------------
def test_hundreds_of_chart_changes_conserve_integrals():
    t = np.linspace(0.0, 15.0, 1501)
    w0 = [30.0, 5.0, 40.0]  # about 8 turns per unit time
    tr = solve(I123, t, omega0=w0, method="taylor")
    assert tr.stats["chart_changes"] > 300
    assert np.sum(np.abs(tr.quaternion[:, 0]) < 0.02) > 5  # passes close to alpha = pi many times
    d = tr.drift()
    assert d["energy"] < 1e-13 and d["m_norm"] < 1e-13 and max(d["m_x"], d["m_y"], d["m_z"]) < 1e-13
    # the chart threshold is a free choice: the motion does not depend on it
    ref = None
    for thr in (0.0, 1.0, 5.0):
        q, om, st = integrate_principal(I123, w0, t[::100], chart_threshold=thr)
        if ref is None:
            ref = (q, om)
            assert st["chart_changes"] == st["steps"] - 1
            continue
        assert np.max(quaternion_distance(q, ref[0])) < 5e-15 * (1 + 50 * t[::100]).max()
        np.testing.assert_allclose(om, ref[1], rtol=0, atol=2e-15 * 50 * (50 * 15))


def test_batch_equals_bodies_solved_alone():
    rng = np.random.default_rng(4)
    Rs = [random_rotation(s) for s in range(6)]
    inertia = np.array([R @ np.diag(np.sort(rng.uniform(1, 2, 3))) @ R.T for R in Rs]).reshape(2, 3, 3, 3)
    w0 = rng.standard_normal((2, 3, 3)) * np.array([1.0, 5.0, 0.2])[:, None]
    q0 = Attitude.random((2, 3), rng=rng).as_quaternion()
    t = np.array([4.0, -2.5, 0.0, 11.0])
    batch = solve(RigidBody(inertia), t, omega0=w0, attitude0=q0, method="taylor")
    assert batch.quaternion.shape == (2, 3, 4, 4)
    # compiled: a batch of 6 runs the lane (SIMD) kernel, a body alone the scalar one: the
    # same steps, round-off apart (LLVM fuses a few multiply-adds differently in vector
    # code); NumPy path: reductions over batches of another size may sum in another order
    atol = 1e-14 if K.USE_NUMBA else 1e-13
    steps = 0
    for i in range(2):
        for j in range(3):
            one = solve(RigidBody(inertia[i, j]), t, omega0=w0[i, j], attitude0=q0[i, j], method="taylor")
            np.testing.assert_allclose(batch.quaternion[i, j], one.quaternion, rtol=0, atol=atol)
            np.testing.assert_allclose(batch.omega[i, j], one.omega, rtol=0, atol=atol)
            steps += one.stats["steps"]
    assert batch.stats["steps"] == steps
    # diagonal bodies with different moments, broadcast initial velocity
    moments = np.array([[1.0, 2.0, 3.0], [2.0, 2.0, 3.5], [1.0, 1.5, 2.0]])
    b2 = solve(moments[:, :, None] * np.eye(3), t, omega0=[0.3, 1.0, -0.2], method="taylor")
    for i in range(3):
        one = solve(moments[i], t, omega0=[0.3, 1.0, -0.2], method="taylor")
        np.testing.assert_allclose(b2.quaternion[i], one.quaternion, rtol=0, atol=atol)
        np.testing.assert_allclose(b2.omega[i], one.omega, rtol=0, atol=atol)


def _lane_batch(rng, B):
    """B bodies whose step counts differ by 100x (lanes are refilled at different times),
    with a symmetric top, a sphere, a body at rest and one with a NaN velocity."""
    m = np.sort(rng.uniform(1.0, 3.0, (B, 3)), axis=1)
    m[1] = [1.0, 1.0, 1.7]
    m[2] = [2.0, 2.0, 2.0]
    w0 = rng.standard_normal((B, 3)) * rng.choice([0.05, 1.0, 5.0], (B, 1))
    w0[3] = 0.0
    w0[4, 1] = np.nan
    q0 = Attitude.random(B, rng=rng).as_quaternion()
    return m, w0, q0


@pytest.mark.skipif(not K.USE_NUMBA, reason="the lane kernel is compiled (numba not in use)")
@pytest.mark.parametrize("dt, order", [(None, 20), (None, 9), (0.07, 12), (0.5, 1)])
def test_lane_kernel_equals_scalar_kernel(dt, order):
    rng = np.random.default_rng(11)
    B = 2 * K.LANES_TAYLOR + 5  # idle lanes at the end
    m, w0, q0 = _lane_batch(rng, B)
    t = np.array([3.0, -7.5, 0.0, 12.0, -0.25, 3.0, 25.0])
    max_steps = 800 if order == 20 else 4000  # order 20: the two fastest bodies need ~1000
    kw = dict(tol=1e-15 if order == 20 else 1e-9, order=order, dt=dt, max_steps=max_steps, threshold=1.0)
    qs, ws, ss = K.integrate_numba(m, w0, q0, t, lanes=False, **kw)
    ql, wl, sl = K.integrate_numba(m, w0, q0, t, lanes=True, **kw)
    # the same steps, chart changes and verdicts, body by body
    np.testing.assert_array_equal(sl, ss)
    assert ss[4, 2] == K.STATUS_NONFINITE and ss[3, 2] == K.STATUS_OK
    assert set(ss[:, 2]) >= {K.STATUS_OK, K.STATUS_NONFINITE}
    if dt is None and order == 20:  # the fastest bodies run out of steps
        assert K.STATUS_MAX_STEPS in ss[:, 2]
    assert ss[:, 1].max() > 10  # chart changes happen
    ok = ss[:, 2] == K.STATUS_OK
    scale = np.maximum(np.abs(w0[ok]).max(axis=1), 1e-300)[:, None, None]
    # round-off, relative to the angle turned (|w| t) and to |w| (measured: <= 1.5e-16)
    turns = 1 + scale * np.abs(t)[None, :, None]
    assert np.max(np.abs(ql[ok] - qs[ok]) / turns) < 1e-14
    assert np.max(np.abs(wl[ok] - ws[ok]) / (scale * turns)) < 1e-14
    np.testing.assert_array_equal(wl[3], np.zeros((t.size, 3)))  # at rest
    # outputs of failed bodies are not written, in either kernel
    np.testing.assert_array_equal(ql[~ok] == 0, qs[~ok] == 0)


_LANES_PY_SCRIPT = r"""
import json, sys
import numpy as np
from eulerpoisson.solvers.taylor import kernels as K
m, w0, q0, t = (np.array(json.loads(a)) for a in sys.argv[1:5])
kw = dict(tol=1e-9, order=8, dt=None, max_steps=500, threshold=1.0)
a = K.integrate_numba(m, w0, q0, t, lanes=False, **kw)
b = K.integrate_numba(m, w0, q0, t, lanes=True, **kw)
print(json.dumps({"use_numba": K.USE_NUMBA, "equal": [bool(np.array_equal(x, y)) for x, y in zip(a, b)],
                  "stats": a[2].tolist()}))
"""


def test_lane_kernel_logic_equals_scalar_kernel_bit_for_bit_in_python():
    """Without the compiler both kernels run as plain Python (no fused multiply-add anywhere):
    the lane bookkeeping (refills, directions, idle lanes, failures) must then give
    exactly the scalar kernel's numbers."""
    rng = np.random.default_rng(12)
    m, w0, q0 = _lane_batch(rng, K.LANES_TAYLOR + 3)
    w0 *= 0.5
    t = np.array([1.5, -2.0, 0.0, 4.0, 1.5])
    args = [json.dumps(np.where(np.isnan(x), None, x).tolist()) for x in (m, w0, q0, t)]
    env = dict(os.environ, EULERPOISSON_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", _LANES_PY_SCRIPT, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        check=True,
    )
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["use_numba"] is False
    assert res["equal"] == [True, True, True]
    st = np.array(res["stats"])
    assert st[4, 2] == K.STATUS_NONFINITE and (st[:, 2] == K.STATUS_OK).sum() == len(st) - 1
    assert st[:, 1].sum() > 0


# ---------------------------------------------------------------------------
# output times, backward integration
# ---------------------------------------------------------------------------
def test_time_reversal_symmetry_and_unsorted_times():
    t = np.array([3.0, -7.5, 0.0, 12.0, -0.25, 3.0])
    a = solve(I123, t, omega0=W0, method="taylor")
    b = solve(I123, -t, omega0=-W0, method="taylor")
    # q(-t; W0) = q(t; -W0), W(-t; W0) = -W(t; -W0): exact symmetry of the recurrences
    sign = np.sign(np.sum(a.quaternion * b.quaternion, axis=-1, keepdims=True))
    np.testing.assert_allclose(a.quaternion, sign * b.quaternion, rtol=0, atol=1e-16)
    np.testing.assert_allclose(a.omega, -b.omega, rtol=0, atol=1e-16)
    np.testing.assert_array_equal(a.quaternion[0], a.quaternion[5])  # duplicate times
    assert quaternion_distance(a.quaternion[2], [1.0, 0, 0, 0]) < 1e-15
    np.testing.assert_array_equal(a.omega[2], W0)
    qr, wr = reference_motion(I123, W0, np.array([1.0, 0, 0, 0]), t[:5])  # scipy needs distinct times
    assert np.max(quaternion_distance(a.quaternion[:5], qr)) < 1e-12
    assert np.max(np.abs(a.omega[:5] - wr)) < 1e-12


def test_dense_output_does_not_change_the_steps():
    one = solve(I123, [9.0], omega0=W0, method="taylor")
    many = solve(I123, np.linspace(9.0, 0.0, 901), omega0=W0, method="taylor")
    assert one.stats["steps"] == many.stats["steps"]
    np.testing.assert_array_equal(one.quaternion[0], many.quaternion[0])
    np.testing.assert_array_equal(one.omega[0], many.omega[0])
    qr, wr = reference_motion(I123, W0, np.array([1.0, 0, 0, 0]), many.t)
    assert np.max(quaternion_distance(many.quaternion, qr)) < 5e-12  # DOP853's own error


def test_body_at_rest_and_principal_axis_spin():
    tr = solve(I123, [-5.0, 0.0, 1e6], omega0=[0.0, 0.0, 0.0], method="taylor")
    np.testing.assert_array_equal(tr.omega, 0.0)
    np.testing.assert_allclose(np.abs(tr.quaternion[:, 0]), 1.0)
    assert tr.stats["steps"] <= 4
    t = np.array([0.0, 1.0, 25.0])
    tr = solve(I123, t, omega0=[0.0, 2.0, 0.0], method="taylor")
    ref = np.array([axis_quaternion([0, 1, 0], 2.0 * tk) for tk in t])
    assert np.max(quaternion_distance(tr.quaternion, ref)) < 1e-14 * 50


# ---------------------------------------------------------------------------
# the compiled kernels and the NumPy fallback
# ---------------------------------------------------------------------------
_FALLBACK_SCRIPT = r"""
import json, sys
import numpy as np
from eulerpoisson.solvers.taylor import kernels as K
from eulerpoisson.solvers import solve
I = np.array(json.loads(sys.argv[1]))
w0 = np.array(json.loads(sys.argv[2]))
t = np.array(json.loads(sys.argv[3]))
tr = solve(I, t, omega0=w0, method="taylor")
print(json.dumps({"use_numba": K.USE_NUMBA, "backend": tr.stats["backend"], "steps": tr.stats["steps"],
                  "q": tr.quaternion.tolist(), "w": tr.omega.tolist()}))
"""


def test_numpy_fallback_in_subprocess_matches():
    I = (np.array([[1.0, 2.0, 3.0], [2.0, 2.0, 3.0], [1.0, 1.2, 2.0]])[:, :, None] * np.eye(3)).tolist()
    w0 = [[1.0, 0.1, 0.5], [-0.5, 2.0, 1.0], [3.0, 0.2, -4.0]]
    t = [0.0, 2.0, -3.0, 5.0]
    env = dict(os.environ, EULERPOISSON_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", _FALLBACK_SCRIPT, json.dumps(I), json.dumps(w0), json.dumps(t)],
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        check=True,
    )
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["use_numba"] is False and res["backend"] == "numpy"
    tr = solve(np.array(I), t, omega0=np.array(w0), method="taylor")
    assert tr.stats["backend"] == ("numba" if K.USE_NUMBA else "numpy")
    np.testing.assert_allclose(res["q"], tr.quaternion, rtol=0, atol=1e-14)
    np.testing.assert_allclose(res["w"], tr.omega, rtol=0, atol=1e-14 * 4)
    assert abs(res["steps"] - tr.stats["steps"]) <= 1


def test_numpy_backend_in_process_matches():
    rng = np.random.default_rng(8)
    m = np.sort(rng.uniform(1, 2, (5, 3)), axis=1)
    w0 = rng.standard_normal((5, 3))
    q0 = Attitude.random(5, rng=rng).as_quaternion()
    t = np.array([-4.0, 1.0, 6.0])
    qa, wa, sa = integrate_principal(m, w0, t, q0=q0, backend="numpy")
    qb, wb, sb = integrate_principal(m, w0, t, q0=q0)
    np.testing.assert_allclose(qa, qb, rtol=0, atol=1e-14)
    np.testing.assert_allclose(wa, wb, rtol=0, atol=1e-14)
    assert sa["steps"] == sb["steps"] and sa["chart_changes"] == sb["chart_changes"]
    # fixed steps too
    qa, wa, sa = integrate_principal(m, w0, t, q0=q0, dt=0.3, order=9, backend="numpy")
    qb, wb, sb = integrate_principal(m, w0, t, q0=q0, dt=0.3, order=9)
    np.testing.assert_allclose(qa, qb, rtol=0, atol=1e-14)
    assert sa["steps"] == sb["steps"]


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "opts, exc, match",
    [
        (dict(tol=1e-17), InvalidInputError, r"tol must be in \[machine epsilon"),
        (dict(tol=1.0), InvalidInputError, "tol must be in"),
        (dict(tol=float("nan")), InvalidInputError, "tol must be finite"),
        (dict(tol="small"), TypeError, "tol must be a real number"),
        (dict(order=1), InvalidInputError, "order must be between 2 and 200 with adaptive steps"),
        (dict(order=500), InvalidInputError, "order must be between 2 and 200"),
        (dict(order=2.5), TypeError, "order must be an integer"),
        (dict(dt=0.1, order=0), InvalidInputError, "order must be between 1 and 200 with a fixed step"),
        (dict(dt=-0.1), InvalidInputError, "dt must be > 0"),
        (dict(dt=0.0), InvalidInputError, "dt must be > 0"),
        (dict(max_steps=0), InvalidInputError, "max_steps must be > 0"),
        (dict(max_steps=2.5), InvalidInputError, "max_steps must be an integer"),
        (dict(chart_threshold=-1.0), InvalidInputError, "chart_threshold must be >= 0"),
        (dict(bogus=1), TypeError, "unexpected keyword argument 'bogus'"),
    ],
)
def test_bad_options(opts, exc, match):
    with pytest.raises(exc, match=match):
        solve(I123, [0.0, 1.0], omega0=W0, method="taylor", **opts)


def test_runtime_failures():
    with pytest.raises(EulerPoissonError, match="max_steps=5 exhausted"):
        solve(I123, [100.0], omega0=W0, method="taylor", max_steps=5)
    with pytest.raises(EulerPoissonError, match="non-finite"):
        solve(I123, [1.0], omega0=[1e300, 1e300, 1e300], method="taylor")
    with pytest.raises(EulerPoissonError, match="state of body 1 became non-finite"):
        integrate_principal(I123, [[1.0, 0, 0], [1e300, 1e300, 1e300]], [1.0], backend="numpy")
    with pytest.raises(EulerPoissonError, match="max_steps=3 exhausted"):
        integrate_principal(I123, W0, [-100.0], max_steps=3, backend="numpy")


@pytest.mark.parametrize(
    "call, exc, match",
    [
        (lambda: taylor_coefficients([0, 0, 0], W0, I123, -1), InvalidInputError, "order must be between 0"),
        (lambda: taylor_coefficients([0, 0, 0], W0, I123, 2.0), TypeError, "order must be an integer"),
        (lambda: taylor_coefficients([0, 0], W0, I123, 3), InvalidInputError, r"n0 must have shape \(\.\.\., 3\)"),
        (lambda: taylor_coefficients([0, 0, 0], W0, [1.0, 2.0], 3), InvalidInputError, "inertia must be three"),
        (lambda: taylor_coefficients([0, 0, np.nan], W0, I123, 3), InvalidInputError, "n0 contains NaN"),
        (lambda: lie_series_coefficients([0, 0, 0], [1, 2], I123, 3), InvalidInputError, "pi0 must have shape"),
        (lambda: integrate_principal(I123, W0, [1.0], backend="gpu"), InvalidInputError, "backend must be"),
        (lambda: integrate_principal([-1.0, 2, 3], W0, [1.0]), InvalidInputError, "moments must be > 0"),
        (lambda: integrate_principal(I123, W0, [[1.0]]), InvalidInputError, "t must be a scalar or a 1-D"),
        (lambda: integrate_principal(np.ones((2, 3)), np.ones((3, 3)), [1.0]), InvalidInputError, "do not broadcast"),
    ],
)
def test_bad_arguments_of_the_functions(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def test_numba_backend_unavailable_for_other_arithmetic():
    if not K.USE_NUMBA:
        pytest.skip("numba is not in use")
    with pytest.raises(InvalidInputError, match="backend='numba' is not available: the arithmetic is not float64"):
        integrate_principal(I123.astype(np.longdouble), W0.astype(np.longdouble), [1.0], backend="numba")
