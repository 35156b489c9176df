"""The symplectic integrators and the chart machinery they rely on.

Truth: finite differences / complex-step derivatives of the Hamiltonians,
order conditions of the Gauss tableaux, the independent DOP853 reference
(tests/_reference.py), and exact conservation laws.
"""

import numpy as np
import pytest

from _reference import quaternion_distance, reference_motion
from eulerpoisson import EulerPoissonError, InvalidInputError
from eulerpoisson.attitude import (
    gibbs_compose,
    gibbs_rate_from_omega,
    inverse_conversion_matrix,
    matrix_from_gibbs,
    matrix_from_quaternion,
)
from eulerpoisson.solvers import charts as ch
from eulerpoisson.solvers import solve
from eulerpoisson.solvers.symplectic.method import (
    Symplectic,
    gauss_step,
    gauss_tableau,
    splitting_advance,
    splitting_sequence,
)

I3 = np.array([1.0, 2.0, 3.0])
INV = (1.0 / I3)[:, None]
W0 = np.array([1.0, 0.3, 0.6])


def symplectic_form(d):
    k = d // 2
    return np.block([[np.zeros((k, k)), np.eye(k)], [-np.eye(k), np.zeros((k, k))]])


def complex_step_jacobian(f, x, eps=1e-30):
    """Jacobian of f: R^D -> R^D at x (D,), exact to round-off for real-analytic f."""
    D = x.shape[0]
    J = np.empty((D, D))
    for k in range(D):
        xc = x.astype(complex)[:, None]
        xc[k, 0] += eps * 1j
        J[:, k] = f(xc)[:, 0].imag / eps
    return J


def symplecticity_defect(J):
    O = symplectic_form(J.shape[0])
    return np.max(np.abs(J.T @ O @ J - O)) / max(1.0, np.max(np.abs(J)) ** 2)


def compose(a, b):
    """Gibbs vector of R(a)R(b), component first, complex-safe (independent of attitude.gibbs_compose)."""
    return (a + b + ch.cross(a, b)) / (1.0 - ch.dot(a, b))


def random_state(rng, nmax=0.8):
    n = rng.normal(size=3)
    n *= nmax * rng.uniform(0.3, 1.0) / np.linalg.norm(n)
    return n, rng.normal(size=3)


# ---------------------------------------------------------------------------
# tableaux
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("s", [1, 2, 3])
def test_gauss_tableau_order_and_symplecticity_conditions(s):
    tab = gauss_tableau(s)
    A, b, c = tab.A, tab.b, tab.c
    for k in range(1, 2 * s + 1):  # B(2s): quadrature order 2s
        assert abs(b @ c ** (k - 1) - 1.0 / k) < 1e-15
    for k in range(1, s + 1):  # C(s): stage order s
        np.testing.assert_allclose(A @ c ** (k - 1), c**k / k, atol=1e-15)
    # the symplecticity condition of RK methods b_i a_ij + b_j a_ji = b_i b_j
    Mt = b[:, None] * A + (b[:, None] * A).T - np.outer(b, b)
    assert np.max(np.abs(Mt)) < 1e-15
    assert tab.order == 2 * s


@pytest.mark.parametrize("s", [1, 2, 3])
def test_extrapolation_reproduces_polynomials(s):
    tab = gauss_tableau(s)
    for k in range(1, s + 1):  # u(theta) = theta**k: Z_j = c_j**k, guess u(1 + c_i) - u(1)
        np.testing.assert_allclose(tab.extrapolation @ tab.c**k, (1 + tab.c) ** k - 1, atol=1e-14)


def test_gauss_tableau_bad_stages():
    with pytest.raises(InvalidInputError, match="1, 2 or 3 stages"):
        gauss_tableau(4)


def test_splitting_sequences():
    s2 = splitting_sequence(2)
    assert [a for a, _ in s2] == [0, 1, 2, 1, 0]
    for order in (2, 4):
        seq = splitting_sequence(order)
        for axis in range(3):  # each piece gets total time h
            assert abs(sum(f for a, f in seq if a == axis) - 1.0) < 1e-14
        assert seq[0][0] == seq[-1][0]
        fr = [f for _, f in seq]
        np.testing.assert_allclose(fr, fr[::-1], atol=1e-15)  # symmetric
    with pytest.raises(InvalidInputError, match="splitting order"):
        splitting_sequence(3)


# ---------------------------------------------------------------------------
# Hamilton's equations, eq. 1.15-1.17 and 1.30
# ---------------------------------------------------------------------------
def test_canonical_field_is_hamiltonian_and_eq_1_16_misprint(rng):
    for _ in range(5):
        n, p = random_state(rng, 2.0)
        y = np.r_[n, p][:, None]
        f = ch.canonical_field(y, INV)[:, 0]
        # gradient of H (eq. 1.15) by complex step
        grad = np.empty(6)
        for k in range(6):
            yc = y.astype(complex)
            yc[k, 0] += 1e-30j
            grad[k] = ch.hamiltonian(yc[:3], yc[3:], INV)[0].imag / 1e-30
        np.testing.assert_allclose(f[:3], grad[3:], rtol=1e-13, atol=1e-14)  # ndot = dH/dpi
        np.testing.assert_allclose(f[3:], -grad[:3], rtol=1e-13, atol=1e-14)  # pidot = -dH/dn
        # eq. 1.16 as printed: pidot_i = -1/4 [d_ij (n.pi) + pi_i n_j + eps_ijk n_k] (I^-1 At pi)_j
        W = ch.omega_from_pi(n[:, None], p[:, None], INV)[:, 0]
        printed = -0.5 * ((n @ p) * W + (n @ W) * p + np.cross(W, n))
        assert np.max(np.abs(printed - f[3:])) > 1e-3
        # the n-equation is eq. 1.30 with Omega = I^-1 At pi / 2 (eq. 1.26)
        np.testing.assert_allclose(f[:3], gibbs_rate_from_omega(n, W), rtol=1e-13, atol=1e-14)
        np.testing.assert_allclose(W, 0.5 * (inverse_conversion_matrix(n) @ p) / I3, rtol=1e-13)
        # H = E = Omega.I Omega / 2 and m = R(n) I Omega (eq. 1.17, 1.25)
        assert abs(ch.hamiltonian(n[:, None], p[:, None], INV)[0] - 0.5 * W @ (I3 * W)) < 1e-13 * (1 + W @ W)
        m = ch.spatial_momentum(n[:, None], p[:, None])[:, 0]
        np.testing.assert_allclose(m, matrix_from_gibbs(n) @ (I3 * W), rtol=1e-13, atol=1e-13)
        # pi = 2 A I Omega inverts eq. 1.26
        np.testing.assert_allclose(ch.pi_from_omega(n[:, None], W[:, None], I3[:, None])[:, 0], p, rtol=1e-12)


def test_quaternion_field_is_hamiltonian(rng):
    def H(q, p):
        M = ch.body_momentum_from_qp(q, p, normalize=False)
        return 0.5 * ch.dot(M, M * INV)

    for _ in range(5):
        y = rng.normal(size=8)[:, None]
        f = ch.quaternion_field(y, INV)[:, 0]
        grad = np.empty(8)
        for k in range(8):
            yc = y.astype(complex)
            yc[k, 0] += 1e-30j
            grad[k] = H(yc[:4], yc[4:])[0].imag / 1e-30
        np.testing.assert_allclose(f[:4], grad[4:], rtol=1e-13, atol=1e-14)
        np.testing.assert_allclose(f[4:], -grad[:4], rtol=1e-13, atol=1e-14)
    # on |q| = 1, q.p = 0: M and m are the body and spatial angular momenta, qdot = q (0, Omega)/2
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    M = rng.normal(size=3)
    p = ch.qp_from_body_momentum(q[:, None], M[:, None])
    assert abs(q @ p[:, 0]) < 1e-15
    np.testing.assert_allclose(ch.body_momentum_from_qp(q[:, None], p)[:, 0], M, rtol=1e-14)
    np.testing.assert_allclose(
        ch.spatial_momentum_from_qp(q[:, None], p)[:, 0], matrix_from_quaternion(q) @ M, rtol=1e-13, atol=1e-14
    )
    f = ch.quaternion_field(np.r_[q, p[:, 0]][:, None], INV)[:4, 0]
    W = np.r_[0.0, M / I3]
    np.testing.assert_allclose(f, 0.5 * ch.qmul(q[:, None], W[:, None])[:, 0], atol=1e-15)


# ---------------------------------------------------------------------------
# charts
# ---------------------------------------------------------------------------
def test_cotangent_lift_is_the_transposed_jacobian_of_the_transition(rng):
    for _ in range(5):
        nc, _ = random_state(rng, 0.9)
        n_new, p = random_state(rng, 0.9)
        n_old = gibbs_compose(nc, n_new)  # R(n_old) = R(nc) R(n_new)
        h = 1e-6
        J = np.stack(
            [(gibbs_compose(nc, n_new + h * e) - gibbs_compose(nc, n_new - h * e)) / (2 * h) for e in np.eye(3)], axis=1
        )  # d n_old / d n_new
        lift = ch.cotangent_lift(n_old[:, None], p[:, None], n_new[:, None])[:, 0]
        np.testing.assert_allclose(lift, J.T @ p, rtol=1e-8, atol=1e-9)
        # at n_new = 0 (the re-centring) the lift is At(n) pi = 2 I Omega: Omega unchanged
        p0 = ch.cotangent_lift(n_old[:, None], p[:, None], np.zeros((3, 1)))
        np.testing.assert_allclose(p0[:, 0], inverse_conversion_matrix(n_old) @ p, rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(
            ch.omega_from_pi(np.zeros((3, 1)), p0, INV),
            ch.omega_from_pi(n_old[:, None], p[:, None], INV),
            rtol=1e-13,
            atol=1e-15,
        )


def test_cotangent_lift_is_canonical(rng):
    nc = np.array([0.4, -0.7, 0.2])[:, None]

    def transition(y):  # old chart -> chart centred at R(nc)
        n_new = compose(-nc, y[:3])
        return np.concatenate([n_new, ch.cotangent_lift(y[:3], y[3:], n_new)])

    for _ in range(3):
        n, p = random_state(rng, 0.8)
        J = complex_step_jacobian(transition, np.r_[n, p])
        assert symplecticity_defect(J) < 1e-13


def test_change_chart_keeps_attitude_velocity_energy_momentum(rng):
    B = 8
    qc = rng.normal(size=(4, B))
    qc /= np.linalg.norm(qc, axis=0)
    n = rng.normal(size=(3, B)) * np.array([0.2, 2.0] * 4)  # half of them beyond the threshold
    p = rng.normal(size=(3, B))
    qc2, n2, p2, changed = ch.change_chart(qc, n, p, 1.0)
    np.testing.assert_array_equal(changed, np.linalg.norm(n, axis=0) > 1.0)
    assert np.all(n2[:, changed] == 0) and np.all(n2[:, ~changed] == n[:, ~changed])
    q_before = ch.qmul(qc, ch.quaternion_from_gibbs(n))
    q_after = ch.qmul(qc2, ch.quaternion_from_gibbs(n2))
    assert np.max(quaternion_distance(q_before.T, q_after.T)) < 1e-15 * 10
    np.testing.assert_allclose(ch.omega_from_pi(n2, p2, INV), ch.omega_from_pi(n, p, INV), rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(ch.hamiltonian(n2, p2, INV), ch.hamiltonian(n, p, INV), rtol=1e-13)
    m_before = np.einsum("bij,jb->ib", matrix_from_quaternion(qc.T), ch.spatial_momentum(n, p))
    m_after = np.einsum("bij,jb->ib", matrix_from_quaternion(qc2.T), ch.spatial_momentum(n2, p2))
    np.testing.assert_allclose(m_after, m_before, rtol=1e-13, atol=1e-13)


def test_state_dependent_recentring_is_not_exactly_symplectic():
    """Documents why the Gibbs-chart Gauss method is symplectic only between chart changes."""
    tab = gauss_tableau(2)
    x = np.array([0.7, -0.6, 0.5, 1.0, 0.4, 1.5])

    def step(y):
        return gauss_step(y, 0.1, INV, tab, iterations=40)[0]

    def switched(y, nc=None):
        nc = y[:3] if nc is None else nc
        n2 = compose(-nc, y[:3])
        z = step(np.concatenate([n2, ch.cotangent_lift(y[:3], y[3:], n2)]))
        n1 = compose(nc, z[:3])
        return np.concatenate([n1, ch.cotangent_lift(z[:3], z[3:], n1)])

    fixed = x[:3, None].astype(complex)
    assert symplecticity_defect(complex_step_jacobian(lambda y: switched(y, fixed), x)) < 1e-13
    assert symplecticity_defect(complex_step_jacobian(switched, x)) > 1e-9


# ---------------------------------------------------------------------------
# one-step maps: symplectic, symmetric
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("s", [1, 2, 3])
@pytest.mark.parametrize("variables", ["gibbs", "quaternion"])
def test_gauss_step_is_symplectic(s, variables, rng):
    tab = gauss_tableau(s)
    if variables == "gibbs":
        n, p = random_state(rng, 0.9)
        x, field = np.r_[n, p], ch.canonical_field
    else:
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        x, field = np.r_[q, ch.qp_from_body_momentum(q[:, None], rng.normal(size=(3, 1)))[:, 0]], ch.quaternion_field
    J = complex_step_jacobian(lambda y: gauss_step(y, 0.2, INV, tab, iterations=60, field=field)[0], x)
    assert symplecticity_defect(J) < 1e-12
    assert np.max(np.abs(J - np.eye(x.size))) > 1e-2  # a real step, not the identity


@pytest.mark.parametrize("order", [2, 4])
def test_splitting_is_symplectic_in_canonical_coordinates(order, rng):
    """The splitting step written in (n, pi) is a symplectic map of R^6."""
    seq = splitting_sequence(order)

    def step(y):
        n, p = y[:3], y[3:]
        q = ch.quaternion_from_gibbs(n)
        M = 0.5 * ch.apply_At(n, p)
        q1, M1 = splitting_advance(q, M, INV, 0.15, 3, seq)
        n1 = q1[1:] / q1[0]
        return np.concatenate([n1, ch.pi_from_omega(n1, M1, np.ones((3, 1)))])

    n, p = random_state(rng, 0.3)
    J = complex_step_jacobian(step, np.r_[n, p])
    assert symplecticity_defect(J) < 1e-12


@pytest.mark.parametrize("field,dim", [(ch.canonical_field, 6), (ch.quaternion_field, 8)])
def test_gauss_step_is_symmetric(field, dim, rng):
    tab = gauss_tableau(2)
    y0 = rng.normal(size=(dim, 4)) * 0.5
    y1, _, _ = gauss_step(y0, 0.1, np.repeat(INV, 4, axis=1), tab, field=field)
    yb, _, _ = gauss_step(y1, -0.1, np.repeat(INV, 4, axis=1), tab, field=field)
    np.testing.assert_allclose(yb, y0, atol=1e-14)
    assert np.max(np.abs(y1 - y0)) > 1e-3


# ---------------------------------------------------------------------------
# conservation
# ---------------------------------------------------------------------------
def test_quadratic_invariants_exact_for_quaternion_gauss(rng):
    tab = gauss_tableau(2)
    q = rng.normal(size=(4, 3))
    q /= np.linalg.norm(q, axis=0)
    y = np.concatenate([q, ch.qp_from_body_momentum(q, rng.normal(size=(3, 3)))])
    inv = np.repeat(INV, 3, axis=1)
    m0 = ch.spatial_momentum_from_qp(y[:4], y[4:])
    for _ in range(300):
        y, _, _ = gauss_step(y, 0.1, inv, tab, field=ch.quaternion_field)
    assert np.max(np.abs(ch.dot4(y[:4], y[:4]) - 1.0)) < 1e-14
    assert np.max(np.abs(ch.dot4(y[:4], y[4:]))) < 1e-13
    np.testing.assert_allclose(ch.spatial_momentum_from_qp(y[:4], y[4:]), m0, atol=1e-13)


@pytest.mark.parametrize(
    "opts", [{"scheme": "splitting"}, {"scheme": "splitting4"}, {"scheme": "gauss4", "variables": "quaternion"}]
)
def test_m_conserved_to_round_off(opts):
    body = [[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]]  # full tensor
    t = np.linspace(0.0, 60.0, 7)
    tr = solve(
        body, t, omega0=[0.9, -1.3, 0.5], attitude0=[0.5, 0.5, -0.5, 0.5], method="symplectic", dt=0.1, **opts
    )  # ~0.2 rad per step, 600 steps
    d = tr.drift()
    assert max(d["m_x"], d["m_y"], d["m_z"], d["m_norm"]) < 1e-13, d
    assert 1e-12 < d["energy"] < 1e-2  # energy is not exact
    if opts["scheme"].startswith("splitting"):
        Mn = np.linalg.norm(tr.M, axis=-1)
        assert np.max(np.abs(Mn - Mn[0])) < 1e-13 * Mn[0]


def test_gibbs_gauss_m_error_is_discretization_error():
    """In (n, pi) m is cubic, not conserved exactly: its error converges like dt**4 (gauss4)."""
    t = np.array([0.0, 10.0])
    e = []
    for dt in (0.1, 0.05):
        d = solve(I3, t, omega0=W0, method="symplectic", scheme="gauss4", variables="gibbs", dt=dt).drift()
        e.append(max(d["m_x"], d["m_y"], d["m_z"]))
    assert e[1] > 1e-12
    assert 10 < e[0] / e[1] < 25


def windowed_drift(E, nwin=10):
    """Max |E - E0| per window, and the fitted growth over the run relative to the overall max."""
    err = np.abs(E - E[0]) / abs(E[0])
    w = np.array([x.max() for x in np.array_split(err[1:], nwin)])
    slope = np.polyfit(np.arange(nwin), w, 1)[0]
    return w, slope * nwin / w.max()


@pytest.mark.parametrize(
    "opts,nsteps,bound",
    [
        ({"scheme": "splitting"}, 100_000, 1e-3),
        ({"scheme": "gauss2", "variables": "quaternion"}, 3_000, 1e-3),
    ],
)
def test_energy_error_bounded_without_drift(opts, nsteps, bound):
    """Long runs (0.2 rad per step): the windowed max energy error does not grow."""
    dt = 0.2 / np.linalg.norm(W0)
    t = np.linspace(0.0, nsteps * dt, 2001)
    tr = solve(I3, t, omega0=W0, method="symplectic", dt=dt, **opts)
    w, growth = windowed_drift(tr.energy)
    assert w.max() < bound
    assert abs(growth) < 0.1, (w, growth)  # a linear drift would give ~1


def test_gibbs_chart_changes_make_the_energy_drift_like_h_to_the_p():
    """Documented limitation: the modified energy differs per chart, so it drifts by O(h^p) per chart change."""
    t = np.linspace(0.0, 40.0, 11)
    drifts = []
    for dt in (0.05, 0.025):
        tr = solve(I3, t, omega0=W0, method="symplectic", scheme="gauss2", variables="gibbs", dt=dt)
        w, growth = windowed_drift(tr.energy, nwin=5)
        assert growth > 0.5  # grows steadily
        assert tr.stats["chart_changes"] > 25
        drifts.append(w.max())
    assert 3 < drifts[0] / drifts[1] < 5  # O(h^2) for gauss2


# ---------------------------------------------------------------------------
# accuracy through the public API
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "opts,tol",
    [  # measured errors x 3 (0.03 rad per step over 9 time units)
        ({"scheme": "gauss2", "variables": "gibbs"}, 6e-3),
        ({"scheme": "gauss4", "variables": "gibbs"}, 5e-8),
        ({"scheme": "gauss6", "variables": "gibbs"}, 3e-12),
        ({"scheme": "gauss4", "variables": "quaternion"}, 2e-8),
        ({"scheme": "gauss6", "variables": "quaternion"}, 1e-12),
        ({"scheme": "gauss4", "variables": "gibbs", "chart_threshold": 0.0}, 7e-8),
        (
            {"scheme": "gauss4", "variables": "gibbs", "chart_threshold": 3.0},
            3e-7,
        ),  # larger |n|: larger error constants
        ({"scheme": "splitting"}, 1.2e-4),
        ({"scheme": "splitting4"}, 1.5e-7),
    ],
)
def test_schemes_agree_with_reference(opts, tol):
    body = [[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]]
    q0 = np.array([0.5, 0.5, -0.5, 0.5])
    w0 = np.array([0.9, -1.3, 0.5])
    t = np.array([-3.0, 0.0, 2.0, 6.0])
    q_ref, w_ref = reference_motion(body, w0, q0, t)
    tr = solve(body, t, omega0=w0, attitude0=q0, method="symplectic", dt=0.02, **opts)
    assert np.max(quaternion_distance(tr.quaternion, q_ref)) < tol
    assert np.max(np.abs(tr.omega - w_ref)) < tol * 2


def test_nominal_order_and_defaults():
    assert Symplectic().nominal_order() == 4 == Symplectic.order
    for scheme, p in [("gauss2", 2), ("gauss4", 4), ("gauss6", 6), ("splitting", 2), ("splitting4", 4)]:
        assert Symplectic(scheme=scheme).nominal_order() == p
    tr = solve(I3, [0.0, 1.0], omega0=W0, method="symplectic")
    assert tr.stats["dt"] == pytest.approx(0.05 / np.linalg.norm(W0))
    assert tr.stats["steps"] == int(np.ceil(np.linalg.norm(W0) / 0.05 - 1e-9))


def test_body_at_rest():
    q0 = [0.0, 0.6, 0.0, 0.8]  # rotation by pi: no Gibbs vector, no problem
    for scheme in ("gauss4", "splitting"):
        tr = solve(I3, [-5.0, 0.0, 5.0], omega0=[0.0, 0.0, 0.0], attitude0=q0, method="symplectic", scheme=scheme)
        np.testing.assert_allclose(np.abs(tr.quaternion @ np.array(q0)), 1.0, atol=1e-15)
        assert np.all(tr.omega == 0)


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "opts,match",
    [
        ({"scheme": "gauss8"}, "unknown scheme"),
        ({"scheme": 4}, "unknown scheme"),
        ({"variables": "euler"}, "unknown variables"),
        ({"dt": 0.0}, "dt must be"),
        ({"dt": float("nan")}, "dt must be"),
        ({"dt": "0.1"}, "dt must be"),
        ({"max_iter": 0}, "max_iter"),
        ({"max_iter": 2.5}, "max_iter"),
        ({"chart_threshold": -1.0}, "chart_threshold"),
        ({"chart_threshold": "big"}, "chart_threshold"),
    ],
)
def test_bad_options(opts, match):
    with pytest.raises(InvalidInputError, match=match):
        solve(I3, [0.0, 1.0], omega0=W0, method="symplectic", **opts)


def test_iteration_failures_are_reported():
    with pytest.raises(EulerPoissonError, match="reduce dt"):
        solve(I3, [0.0, 100.0], omega0=W0, method="symplectic", dt=50.0)
    with pytest.raises(EulerPoissonError, match="did not converge in max_iter=2"):
        solve(I3, [0.0, 1.0], omega0=W0, method="symplectic", max_iter=2)
    with pytest.raises(EulerPoissonError, match="did not converge"):
        solve(I3, [0.0, 1.0], omega0=W0, method="symplectic", variables="quaternion", max_iter=2)
