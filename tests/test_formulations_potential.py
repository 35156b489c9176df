"""The paper's formulations with a potential (heavy top, gravity gradient) and the SymPy heavy top.

Truth used: central finite differences of the Hamiltonian and of the
potential (P grad H = vector field, dU/dn = -2 A tau), the Taylor integrator
of ``eulerpoisson.solve`` (an independent code path: Euler-Poisson equations
in quaternions with Poisson vectors), and exact rational arithmetic for the
symbolic derivation (identities reduced to polynomial numerators, vector
field evaluated over Q).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import eulerpoisson as ep
from eulerpoisson.errors import InvalidInputError, UnsupportedModelError
from eulerpoisson.model import formulations as F
from eulerpoisson.paper import heavy_top as HT  # imports SymPy only when used
from eulerpoisson.torques import BodyTorque, Gravity, GravityGradient, SpaceTorque

NAMES = list(F.FORMULATIONS)
I_GEN = np.array([[2.0, 0.3, -0.2], [0.3, 3.0, 0.4], [-0.2, 0.4, 4.5]])  # general, non-diagonal

TORQUES = {
    "gravity": Gravity(mass=1.3, center_of_mass=[0.1, -0.2, 0.3], g=[0.3, -1.0, -9.0]),
    "gravity_gradient": GravityGradient(0.7),
    "two_gravities": [Gravity(1.0, [0.0, 0.1, 0.2], [0.0, 0.0, -2.0]), Gravity(0.5, [0.3, 0.0, 0.0], [0.0, 0.0, -4.0])],
}


def random_common(rng, batch, wmin=0.4):
    q = rng.standard_normal(batch + (4,))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    q[..., 0] = np.maximum(np.abs(q[..., 0]), wmin)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q, rng.standard_normal(batch + (3,))


def fd_grad(f, x, h=1e-4):
    """Fourth-order central differences of f: (..., d) -> (...); returns (..., d)."""
    cols = []
    for a in range(x.shape[-1]):
        e = np.zeros(x.shape[-1])
        e[a] = h
        fp1, fm1 = np.asarray(f(x + e)), np.asarray(f(x - e))
        fp2, fm2 = np.asarray(f(x + 2 * e)), np.asarray(f(x - 2 * e))
        cols.append((8.0 * (fp1 - fm1) - (fp2 - fm2)) / (12.0 * h))
    return np.stack(cols, -1)


# ---------------------------------------------------------------------------
# Hamiltonian structure
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("tname", list(TORQUES))
@pytest.mark.parametrize("name", NAMES)
def test_vector_field_is_poisson_tensor_times_grad_H(name, tname):
    f = ep.formulation(name, I_GEN, torque=TORQUES[tname])
    rng = np.random.default_rng(3)
    x = f.from_common(*random_common(rng, (5,)))
    t = 0.37
    gH = fd_grad(lambda z: f.hamiltonian(z, t), x)
    lhs = np.einsum("...ab,...b->...a", f.poisson_tensor(x), gH)
    vf = f.vector_field(x, t)
    assert vf.shape == x.shape
    np.testing.assert_allclose(lhs, vf, rtol=0, atol=1e-9 * np.max(np.abs(vf)))
    # the torque changes the vector field, the Poisson tensor is that of the free body
    free = ep.formulation(name, I_GEN)
    assert np.max(np.abs(vf - free.vector_field(x))) > 1e-3
    np.testing.assert_array_equal(f.poisson_tensor(x), free.poisson_tensor(x))
    np.testing.assert_allclose(f.hamiltonian(x, t), free.hamiltonian(x) + f.potential(x, t), rtol=1e-14, atol=1e-14)
    np.testing.assert_array_equal(f.rhs(t, x[0]), f.vector_field(x[0], t))


@pytest.mark.parametrize("tname", list(TORQUES))
def test_dU_dn_is_minus_2A_tau_finite_differences(tname):
    f = ep.formulation("canonical", I_GEN, torque=TORQUES[tname])
    rng = np.random.default_rng(5)
    x = f.from_common(*random_common(rng, (6,)))
    t = 1.3
    gU = fd_grad(lambda z: f.potential(z, t), x)[..., :3]
    assert np.max(np.abs(fd_grad(lambda z: f.potential(z, t), x)[..., 3:])) == 0.0  # U = U(n)
    dU = f.potential_gradient(x, t)
    np.testing.assert_allclose(dU, gU, rtol=0, atol=1e-9 * np.max(np.abs(gU)))
    tau = f.torque(x, t)
    from eulerpoisson.attitude import conversion_matrix

    A = conversion_matrix(x[..., :3])
    np.testing.assert_allclose(dU, -2.0 * np.einsum("...ij,...j->...i", A, tau), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(F.gibbs_potential_gradient(x[..., :3], tau), dU, rtol=1e-13, atol=1e-13)
    # the opposite sign (or A^T) is wrong
    assert np.max(np.abs(dU - 2.0 * np.einsum("...ji,...j->...i", A, -tau))) > 1e-3
    # pi-dot = pi-dot(free) - dU/dn
    free = ep.formulation("canonical", I_GEN)
    np.testing.assert_allclose(f.vector_field(x, t)[..., 3:] - free.vector_field(x)[..., 3:], -dU, atol=1e-12)
    np.testing.assert_array_equal(f.vector_field(x, t)[..., :3], free.vector_field(x)[..., :3])


def test_torque_matches_the_torque_classes():
    rng = np.random.default_rng(8)
    q, w = random_common(rng, (4,))
    R = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    for tq in (TORQUES["gravity"], TORQUES["gravity_gradient"]):
        for name in NAMES:
            f = ep.formulation(name, I_GEN, torque=tq)
            x = f.from_common(q, w)
            np.testing.assert_allclose(f.torque(x, 0.4), tq.evaluate(0.4, R, w, I_GEN), atol=1e-13)
            np.testing.assert_allclose(f.potential(x, 0.4), tq.potential(0.4, R, I_GEN), atol=1e-13)


def test_free_body_unchanged_and_old_signature():
    rng = np.random.default_rng(2)
    q, w = random_common(rng, (3,))
    for name in NAMES:
        a, b = F.formulation(name, I_GEN), F.formulation(name, I_GEN, torque=None)
        c = F.formulation(name, I_GEN, torque=[])
        x = a.from_common(q, w)
        assert a.is_free and b.is_free and c.is_free and not a.time_dependent
        np.testing.assert_array_equal(a.vector_field(x), c.vector_field(x, 5.0))
        np.testing.assert_array_equal(a.hamiltonian(x), b.hamiltonian(x, 2.0))
        assert set(a.integrals(x)) == {"H", "m", "m2", "m3"}
        np.testing.assert_array_equal(a.potential(x), 0.0)
        np.testing.assert_array_equal(a.torque(x), 0.0)


def test_model_and_formulation_carry_the_torque():
    top = TORQUES["gravity"]
    model = ep.Model(I_GEN, top)
    f = ep.formulation("canonical", model)
    assert f.torques == (top,) and not f.is_free
    g = ep.formulation("canonical", f)  # a formulation as body keeps its torques
    assert g.torques == (top,)
    assert "Gravity" in repr(f)
    gg = ep.formulation("velocity", I_GEN, torque=TORQUES["gravity_gradient"])
    assert gg.time_dependent and not f.time_dependent


def test_batched_torques_and_times():
    rng = np.random.default_rng(4)
    q, w = random_common(rng, (3,))
    top = Gravity(mass=[1.0, 2.0, 3.0], center_of_mass=[0.1, 0.0, 0.2])
    f = ep.formulation("canonical", I_GEN, torque=top)
    x = f.from_common(q, w)
    vf = f.vector_field(x)
    for i in range(3):
        fi = ep.formulation("canonical", I_GEN, torque=top[i])
        np.testing.assert_allclose(vf[i], fi.vector_field(x[i]), rtol=1e-14, atol=1e-14)
    # one state, three masses: broadcasting
    assert f.vector_field(x[0]).shape == (3, 6)
    assert f.hamiltonian(x[0]).shape == (3,)
    # times broadcast against the states
    gg = ep.formulation("canonical", I_GEN, torque=TORQUES["gravity_gradient"])
    t = np.array([0.0, 0.5, 1.0])
    vt = gg.vector_field(x, t)
    for i in range(3):
        np.testing.assert_array_equal(vt[i], gg.vector_field(x[i], t[i]))
    assert gg.hamiltonian(x[0], t).shape == (3,)


# ---------------------------------------------------------------------------
# motion: DOP853 on the vector fields against the Taylor integrator
# ---------------------------------------------------------------------------
T_EVAL = np.linspace(0.0, 2.0, 9)
Q0 = np.array([0.9, 0.2, -0.3, 0.25]) / np.linalg.norm([0.9, 0.2, -0.3, 0.25])
W0 = np.array([0.3, -0.2, 0.5])
MOTION_TORQUES = {
    "heavy_top": Gravity(mass=1.3, center_of_mass=[0.1, -0.2, 0.3], g=[0.3, -1.0, -1.0]),
    "gravity_gradient": GravityGradient(0.9),
}


def _motions():
    out = {}
    for label, tq in MOTION_TORQUES.items():
        ref = ep.solve(I_GEN, T_EVAL, omega0=W0, attitude0=Q0, torque=tq, method="taylor", tol=1e-15)
        sols = {}
        for name in NAMES:
            f = ep.formulation(name, I_GEN, torque=tq)
            sol = solve_ivp(
                f.rhs, (0.0, T_EVAL[-1]), f.from_common(Q0, W0), method="DOP853", t_eval=T_EVAL, rtol=1e-13, atol=1e-13
            )
            assert sol.success
            sols[name] = sol.y.T
        out[label] = (ref, sols)
    return out


@pytest.fixture(scope="module")
def motions(run_once):
    """:func:`_motions`, computed once per test run (``run_once`` of tests/conftest.py): the tests that use it
    may run on different pytest-xdist workers."""
    return run_once("test_formulations_potential-motions", _motions)


@pytest.mark.parametrize("label", list(MOTION_TORQUES))
def test_motion_agrees_with_taylor(label, motions):
    ref, sols = motions[label]
    # the motion turns the body well away from its initial attitude
    assert np.min(np.abs(np.sum(ref.quaternion * Q0, -1))) < 0.9
    for name, y in sols.items():
        f = ep.formulation(name, I_GEN, torque=MOTION_TORQUES[label])
        q, w = f.to_common(y)
        q = q * np.sign(np.sum(q * ref.quaternion, -1))[:, None]
        assert np.max(np.abs(q - ref.quaternion)) < 1e-9, name
        assert np.max(np.abs(w - ref.omega)) < 1e-9, name


def test_heavy_top_energy_and_vertical_momentum_conserved(motions):
    ref, sols = motions["heavy_top"]
    tq = MOTION_TORQUES["heavy_top"]
    for name, y in sols.items():
        f = ep.formulation(name, I_GEN, torque=tq)
        ints = f.integrals(y, T_EVAL)
        assert set(ints) == {"H", "m_vertical"}
        for k in ints:
            assert np.ptp(ints[k]) < 1e-11 * max(1.0, abs(ints[k][0])), (name, k)
        # the potential really varies along the motion (energy exchange)
        assert np.ptp(f.potential(y)) > 1e-2
        ghat = tq.g / np.linalg.norm(tq.g)
        np.testing.assert_allclose(ints["m_vertical"], f.spatial_momentum(y) @ ghat, atol=1e-14)
        # the model's energy (eulerpoisson.Model) is the same function
        np.testing.assert_allclose(ints["H"], ref.integrals()["energy"], rtol=1e-10, atol=1e-10)


def test_gravity_gradient_jacobi_conserved_energy_not(motions):
    _, sols = motions["gravity_gradient"]
    for name, y in sols.items():
        f = ep.formulation(name, I_GEN, torque=MOTION_TORQUES["gravity_gradient"])
        ints = f.integrals(y, T_EVAL)
        assert set(ints) == {"H", "jacobi"}
        assert np.ptp(ints["jacobi"]) < 1e-11, name
        assert np.ptp(ints["H"]) > 1e-2, name


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("tq", [BodyTorque([0.0, 0.0, 1.0]), SpaceTorque([1.0, 0.0, 0.0]), lambda t, q, w: 0.0 * w])
def test_non_conservative_torque_rejected(tq):
    for name in NAMES:
        with pytest.raises(ValueError, match="conservative torques: eulerpoisson.torques.Gravity"):
            ep.formulation(name, I_GEN, torque=tq)
    with pytest.raises(UnsupportedModelError, match="derives from no potential"):
        F.Canonical(I_GEN, torque=[TORQUES["gravity"], tq])


def test_bad_torque_arguments():
    with pytest.raises(TypeError, match="torque must be"):
        ep.formulation("canonical", I_GEN, torque="gravity")
    with pytest.raises(TypeError, match="not both"):
        ep.formulation("canonical", ep.Model(I_GEN, TORQUES["gravity"]), torque=TORQUES["gravity"])
    with pytest.raises(InvalidInputError, match="batch shapes"):
        ep.formulation(
            "canonical", ep.RigidBody(np.stack([I_GEN, I_GEN])), torque=Gravity([1.0, 2.0, 3.0], [0.0, 0.0, 0.1])
        )
    f = ep.formulation("canonical", I_GEN, torque=TORQUES["gravity_gradient"])
    x = np.zeros(6)
    with pytest.raises(InvalidInputError, match="t must be|t "):
        f.vector_field(x, np.nan)
    with pytest.raises(TypeError, match="t must be"):
        f.hamiltonian(x, "now")
    with pytest.raises(InvalidInputError, match="state of the 'canonical' formulation"):
        f.potential_gradient(np.zeros(5))
    with pytest.raises(InvalidInputError, match="tau"):
        F.gibbs_potential_gradient(np.zeros(3), np.zeros(2))


# ---------------------------------------------------------------------------
# the SymPy derivation of the heavy top
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def D():
    pytest.importorskip("sympy")
    return HT.derive_heavy_top("general")


# The checks of the general derivation that need its Legendre transform H and Hamilton's equations (most
# of this file's time: D caches them) run in one test: split into several tests, each pytest-xdist worker
# that ran one of them derived them again.
def _check_identities_exact(D):
    failed = [name for name in HT.HeavyTopDerivation.IDENTITIES if D.identity(name) is not True]
    assert not failed, f"identities that do not hold exactly: {failed}"
    ids = D.identities()
    assert list(ids) == list(D.IDENTITIES) and all(ids.values())


def _check_wrong_sign_is_detected(D):
    # the exactness test is not vacuous: +2 A tau and -dH0/dn + dU/dn are not identities
    C = D.ctx
    tq = [sum((D._fA[i][j] * D._ftorque[j] for j in range(3)), C.const(0)) for i in range(3)]
    assert not D._zero([D._fdU[i] - 2 * tq[i] for i in range(3)])
    assert not D._zero([D._fpidot[i] + D._fH0.diff(D.n[i]) - D._fdU[i] for i in range(3)])


def _check_matches_numeric_vector_field(D):
    rng = np.random.default_rng(17)
    for _ in range(4):
        n, pi, I, mass, c, g = HT._random_point(rng)
        derived = D.evaluate(n, pi, I, mass, c, g)
        exact = D.evaluate(n, pi, I, mass, c, g, exact=True)
        assert all(isinstance(v, Fraction) for v in exact)
        np.testing.assert_array_equal(derived, [float(v) for v in exact])
        f = ep.formulation(
            "canonical",
            np.array(I, dtype=float),
            torque=Gravity(float(mass), [float(v) for v in c], [float(v) for v in g]),
        )
        numeric = f.vector_field(np.array([float(v) for v in n + pi]))
        np.testing.assert_allclose(numeric, derived, rtol=1e-12, atol=1e-12)
    # also from floats (converted exactly)
    z = np.array([0.3, -0.1, 0.7, 1.0, -2.0, 0.5])
    f = ep.formulation("canonical", I_GEN, torque=TORQUES["gravity"])
    tq = TORQUES["gravity"]
    d = D.evaluate(z[:3], z[3:], I_GEN, 1.3, tq.center_of_mass, tq.g)
    np.testing.assert_allclose(f.vector_field(z), d, rtol=1e-12, atol=1e-12)
    # and check_heavy_top, the package's own comparison, without the identities
    res = HT.check_heavy_top(points=3, seed=1, identities=False)
    assert res.passed and res.points == 3 and res.max_difference < 1e-12 and res.identities == {}


def _check_expressions(D):
    import sympy as sp

    # U, H symbols and shapes; H0 is the paper's eq. 1.15 with the corrected Atilde
    assert D.U.free_symbols >= {D.mass, *D.c, *D.g}
    assert D.vector_field.shape == (6, 1)
    assert D.dU_dn.shape == D.torque.shape == D.pidot.shape == (3, 1)
    n = sp.Matrix([sp.Rational(1, 3), sp.Rational(-1, 2), sp.Rational(1, 5)])
    at0 = dict(zip(D.n, n))
    s = 1 + (n.T * n)[0]
    R = (
        (1 - (n.T * n)[0]) * sp.eye(3)
        + 2 * n * n.T
        - 2 * sp.Matrix(3, 3, lambda i, j: sum(sp.LeviCivita(i, j, k) * n[k] for k in range(3)))
    ) / s  # paper eq. 1.9
    assert sp.simplify(D.R.xreplace(at0) - R) == sp.zeros(3, 3)
    assert sp.expand(D.U.xreplace(at0) + D.mass * (D.g.T * R * D.c)[0]) == 0


def test_heavy_top_general_derivation(D):
    """Every identity of ``HeavyTopDerivation.IDENTITIES`` holds exactly (and ``identities()`` says so), a wrong
    sign is detected, the expressions have their shapes and the paper's R and U, and the derived vector field
    equals the numeric canonical formulation's."""
    _check_identities_exact(D)
    _check_wrong_sign_is_detected(D)
    _check_expressions(D)
    _check_matches_numeric_vector_field(D)


def test_heavy_top_diagonal_and_errors(D):
    # check_heavy_top with the identities of the diagonal derivation, whose H and Hamilton's equations the
    # checks of dd below use too (one test: one worker derives them)
    res = HT.check_heavy_top(points=2, seed=2, inertia="diagonal")
    assert res.passed and res.max_difference < 1e-12
    assert list(res.identities) == list(HT.HeavyTopDerivation.IDENTITIES) and all(res.identities.values())
    with pytest.raises(InvalidInputError, match="points"):
        HT.check_heavy_top(points=0)
    with pytest.raises(TypeError, match="points"):
        HT.check_heavy_top(points=1.5)
    dd = HT.derive_heavy_top("diagonal")
    assert HT.derive_heavy_top("diagonal") is dd
    assert dd.identity("dU_dn_is_minus_2A_tau") and dd.identity("pidot_closed_form")
    v = dd.evaluate([0, 0, 0], [1, 2, 3], [1, 2, 2.5], 1, [0, 0, 1], [0, 0, -1])
    f = ep.formulation("canonical", [1.0, 2.0, 2.5], torque=Gravity(1.0, [0, 0, 1], [0, 0, -1]))
    np.testing.assert_allclose(f.vector_field([0, 0, 0, 1, 2, 3]), v, rtol=1e-14, atol=1e-14)
    with pytest.raises(InvalidInputError, match="inertia must be one of"):
        HT.derive_heavy_top("spherical")
    with pytest.raises(InvalidInputError, match="identity name"):
        D.identity("nothing")
    args = dict(n=[0, 0, 0], pi=[1, 2, 3], inertia=I_GEN, mass=1.0, center_of_mass=[0, 0, 1], g=[0, 0, -1])
    with pytest.raises(InvalidInputError, match="n must have 3 components"):
        D.evaluate(**{**args, "n": [0, 0]})
    with pytest.raises(InvalidInputError, match="mass must be > 0"):
        D.evaluate(**{**args, "mass": -1.0})
    with pytest.raises(InvalidInputError, match="pi\\[1\\] must be finite"):
        D.evaluate(**{**args, "pi": [0, np.inf, 0]})
    with pytest.raises(TypeError, match="g\\[0\\] must be a real number"):
        D.evaluate(**{**args, "g": ["x", 0, 0]})
    with pytest.raises(InvalidInputError, match="inertia must be symmetric"):
        D.evaluate(**{**args, "inertia": [[1, 1, 0], [0, 1, 0], [0, 0, 1]]})
    with pytest.raises(InvalidInputError, match="inertia must be diagonal"):
        dd.evaluate(**args)
