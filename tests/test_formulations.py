"""Tests of the paper's formulations (src/eulerpoisson/formulations.py).

Truth used: finite-difference / complex-step gradients (vector field = P grad H,
Jacobi identity, involution), the canonical Poisson tensor pushed forward by
finite-difference Jacobians of the conversions, the Levi-Civita formula with
finite-difference metric derivatives, an independent quaternion integration
(tests/_reference.py), the closed-form motion of a symmetric top, and
closed-form determinants.
"""

import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from _reference import quaternion_distance, reference_motion
from eulerpoisson.attitude import (
    inverse_conversion_matrix,
    matrix_from_gibbs,
    metric,
    omega_from_gibbs_rate,
)
from eulerpoisson.errors import (
    InvalidInertiaError,
    InvalidInputError,
    MissingDependencyError,
    SingularChartError,
)
from eulerpoisson.model import formulations as F
from eulerpoisson.model.body import RigidBody

NAMES = list(F.FORMULATIONS)
EPS = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    EPS[_i, _j, _k], EPS[_i, _k, _j] = 1.0, -1.0


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------
def full_inertia(seed, moments=(1.0, 1.7, 2.3)):
    """A non-diagonal inertia tensor: P diag(moments) P^T with a random rotation P."""
    P = Rotation.random(random_state=seed).as_matrix()
    return P @ np.diag(moments) @ P.T


def random_common(rng, batch, wmin=0.35):
    """Random attitudes (quaternion w >= wmin, so |n| <= sqrt(1/wmin^2 - 1)) and angular velocities."""
    q = rng.standard_normal(batch + (4,))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    q[..., 0] = np.maximum(np.abs(q[..., 0]), wmin)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q, rng.standard_normal(batch + (3,))


def fd_grad(f, x, h=1e-6):
    """Central differences of f: (..., d) -> (..., *k) ; returns (..., *k, d)."""
    cols = []
    for a in range(x.shape[-1]):
        e = np.zeros(x.shape[-1])
        e[a] = h
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.stack(cols, -1)


def bracket(P, gf, gg):
    return np.einsum("...a,...ab,...b->...", gf, P, gg)


@pytest.fixture(scope="module")
def body():
    return RigidBody(full_inertia(7))


@pytest.fixture(scope="module")
def states(body):
    rng = np.random.default_rng(11)
    q, w = random_common(rng, (6,))
    return {name: F.formulation(name, body).from_common(q, w) for name in NAMES}


# ---------------------------------------------------------------------------
# registry and layout
# ---------------------------------------------------------------------------
def test_registry_and_layout(body):
    assert set(F.FORMULATIONS) == {"euler-poisson", "canonical", "momentum", "velocity", "geodesic"}
    for name in NAMES:
        f = F.formulation(name, body)
        assert f.name == name and isinstance(f, F.Formulation)
        assert len(f.variables) == f.dimension == (12 if name == "euler-poisson" else 6)
        covered = sorted(i for sl in f.layout.values() for i in range(f.dimension)[sl])
        assert covered == list(range(f.dimension))
        assert f.equations and "vector_field" in f.equations
    assert isinstance(F.formulation("n_Omega", body), F.Velocity)
    assert isinstance(F.formulation("R-Omega", [1.0, 2.0, 2.5]), F.EulerPoisson)
    assert isinstance(F.formulation("Lagrangian", body), F.Geodesic)


@pytest.mark.parametrize("name", NAMES)
def test_pack_unpack(name, body, states):
    f = F.formulation(name, body)
    x = states[name]
    blocks = f.unpack(x)
    assert set(blocks) == set(f.layout)
    np.testing.assert_array_equal(f.pack(**blocks), x)


# ---------------------------------------------------------------------------
# Hamiltonian structure
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_vector_field_is_poisson_tensor_times_grad_H(name, body, states):
    f = F.formulation(name, body)
    rng = np.random.default_rng(3)
    x = states[name]
    if name != "euler-poisson":  # any point of R^6 is a phase-space point
        x = np.concatenate([x, rng.standard_normal((4, 6)) * [1.5, 1.5, 1.5, 1, 1, 1]])
    gH = fd_grad(f.hamiltonian, x)
    lhs = np.einsum("...ab,...b->...a", f.poisson_tensor(x), gH)
    vf = f.vector_field(x)
    assert vf.shape == x.shape
    np.testing.assert_allclose(lhs, vf, atol=1e-8 * np.max(np.abs(vf)))


@pytest.mark.parametrize("name", NAMES)
def test_poisson_tensor_antisymmetric(name, body, states):
    P = F.formulation(name, body).poisson_tensor(states[name])
    np.testing.assert_array_equal(P, -np.swapaxes(P, -1, -2))


def jacobi_residual(ptensor, x, h=1e-5):
    P = ptensor(x)
    dP = fd_grad(ptensor, x, h)  # (..., a, b, l) = d_l P_ab
    t = np.einsum("...al,...bcl->...abc", P, dP)
    J = t + np.einsum("...abc->...bca", t) + np.einsum("...abc->...cab", t)
    return np.max(np.abs(J)) / max(np.max(np.abs(P)) * np.max(np.abs(dP)), 1e-300)


@pytest.mark.parametrize("name", NAMES)
def test_jacobi_identity(name, body, states):
    f = F.formulation(name, body)
    x = states[name][:3]
    if name == "euler-poisson":  # the Lie-Poisson tensor obeys Jacobi off the group too
        x = x + 0.3 * np.random.default_rng(5).standard_normal(x.shape)
    assert jacobi_residual(f.poisson_tensor, x) < 1e-8


def test_jacobi_check_detects_a_non_poisson_tensor(body, states):
    """Negative control: doubling the {Omega, Omega} block breaks the Jacobi identity."""
    f = F.formulation("velocity", body)

    def wrong(x):
        P = f.poisson_tensor(x)
        P[..., 3:, 3:] *= 2.0
        return P

    assert jacobi_residual(wrong, states["velocity"][:3]) > 1e-3


@pytest.mark.parametrize("name", [n for n in NAMES if n != "euler-poisson"])
def test_poisson_determinant_closed_form(name, body, states):
    f = F.formulation(name, body)
    x = states[name]
    d = f.poisson_determinant(x)
    np.testing.assert_allclose(np.linalg.det(f.poisson_tensor(x)), d, rtol=1e-9)
    assert np.all(d > 0)


def test_euler_poisson_tensor_rank_and_casimirs(body, states):
    f = F.formulation("euler-poisson", body)
    x = states["euler-poisson"]
    P = f.poisson_tensor(x)
    sv = np.linalg.svd(P, compute_uv=False)
    assert np.all(sv[..., 5] > 1e-3 * sv[..., 0]) and np.all(sv[..., 6] < 1e-12 * sv[..., 0])
    assert f.rank == 6 and np.all(f.poisson_determinant(x) == 0)
    # Casimirs (R R^T)_ij have zero bracket with every coordinate, and equal delta_ij here
    gC = fd_grad(f.casimirs, x)  # (..., 6, 12)
    assert np.max(np.abs(np.einsum("...ab,...kb->...ka", P, gC))) < 1e-8
    np.testing.assert_allclose(f.casimirs(x), np.broadcast_to([1, 0, 0, 1, 0, 1.0], (6, 6)), atol=1e-14)


@pytest.mark.parametrize("name", ["euler-poisson", "momentum", "velocity", "geodesic"])
def test_poisson_tensor_is_canonical_one_pushed_forward(name, body, states):
    """P_target(phi(z)) = J P_can J^T with J the Jacobian of the conversion phi from (n, pi)."""
    can = F.formulation("canonical", body)
    f = F.formulation(name, body)
    z = states["canonical"]
    J = fd_grad(lambda y: can.convert(y, f), z)
    expected = J @ can.poisson_tensor(z) @ np.swapaxes(J, -1, -2)
    got = f.poisson_tensor(can.convert(z, f))
    np.testing.assert_allclose(got, expected, atol=1e-8 * np.max(np.abs(got)))


@pytest.mark.parametrize("name", NAMES)
def test_integrals_in_involution(name, body, states):
    f = F.formulation(name, body)
    x = states[name]
    P = f.poisson_tensor(x)
    integ = f.integrals(x)
    g = {k: fd_grad(lambda y, k=k: f.integrals(y)[k], x) for k in ("H", "m2", "m3", "m")}
    scale = np.max(np.abs(g["m2"])) * np.max(np.abs(g["H"]))
    for a, b in (("H", "m2"), ("H", "m3"), ("m2", "m3")):
        assert np.max(np.abs(bracket(P, g[a], g[b]))) < 1e-8 * scale, (a, b)
    # {H, m_i} = 0 (eq. 1.19), {m_i, m2} = 0 (eq. 1.23), {m_i, m_j} = eps_ijk m_k
    Hm = np.einsum("...a,...ab,...ib->...i", g["H"], P, g["m"])
    mm = np.einsum("...ia,...ab,...jb->...ij", g["m"], P, g["m"])
    mm2 = np.einsum("...ia,...ab,...b->...i", g["m"], P, g["m2"])
    assert np.max(np.abs(Hm)) < 1e-8 * scale
    assert np.max(np.abs(mm2)) < 1e-8 * scale
    np.testing.assert_allclose(mm, np.einsum("ijk,...k->...ij", EPS, integ["m"]), atol=1e-8)


# ---------------------------------------------------------------------------
# conversions
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("src", NAMES)
def test_conversions_round_trip(src, body, states):
    f = F.formulation(src, body)
    x = states[src]
    q, w = f.to_common(x)
    np.testing.assert_allclose(f.from_common(q, w), x, rtol=1e-12, atol=1e-12)
    for dst in NAMES:
        y = f.convert(x, dst)
        np.testing.assert_allclose(F.formulation(dst, body).convert(y, f), x, rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_physical_quantities_agree(name, body, states):
    """Quaternion, matrix, Gibbs vector, Omega, M, m, H of every formulation describe the same state."""
    ref = F.formulation("velocity", body)
    f = F.formulation(name, body)
    x = states[name]
    xv = states["velocity"]
    n, W = xv[..., :3], xv[..., 3:]
    R = matrix_from_gibbs(n)
    I = body.inertia
    assert np.max(quaternion_distance(f.quaternion(x), ref.quaternion(xv))) < 1e-13
    np.testing.assert_allclose(f.matrix(x), R, atol=1e-13)
    np.testing.assert_allclose(f.gibbs(x), n, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(f.omega(x), W, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(f.body_momentum(x), W @ I, rtol=1e-12, atol=1e-13)
    m = np.einsum("...ij,...j->...i", R, W @ I)
    np.testing.assert_allclose(f.spatial_momentum(x), m, rtol=1e-12, atol=1e-13)
    ints = f.integrals(x)
    np.testing.assert_allclose(ints["H"], 0.5 * np.einsum("...i,ij,...j->...", W, I, W), rtol=1e-12)
    np.testing.assert_allclose(ints["m"], m, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(ints["m2"], np.sum(m * m, -1), rtol=1e-12)
    np.testing.assert_allclose(ints["m3"], m[..., 2], rtol=1e-12, atol=1e-13)


def test_paper_momentum_relations(body, states):
    """Eq. 1.11, 1.14, 1.17, 1.26: Omega = 2 A^T ndot, pi = G ndot = 2 A I Omega, m = Ã^T pi / 2."""
    n, pi = states["canonical"][..., :3], states["canonical"][..., 3:]
    ndot = states["geodesic"][..., 3:]
    W = states["velocity"][..., 3:]
    np.testing.assert_allclose(omega_from_gibbs_rate(n, ndot), W, rtol=1e-12)
    np.testing.assert_allclose(F.canonical_momentum(n, ndot, body), pi, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", metric(n, body), ndot), pi, rtol=1e-12, atol=1e-13)
    m = 0.5 * np.einsum("...ji,...j->...i", inverse_conversion_matrix(n), pi)
    np.testing.assert_allclose(m, states["momentum"][..., 3:], rtol=1e-12, atol=1e-13)


# ---------------------------------------------------------------------------
# the same motion in every formulation
# ---------------------------------------------------------------------------
T_EVAL = np.linspace(0.0, 5.0, 11)


def integrate(f, x0):
    sol = solve_ivp(f.rhs, (0.0, T_EVAL[-1]), x0, method="DOP853", t_eval=T_EVAL, rtol=1e-12, atol=1e-12)
    assert sol.success
    return sol.y.T


@pytest.fixture(scope="module")
def motions(body):
    """Each formulation integrated from (q0, Omega0), plus the independent reference."""
    out = {}
    for label, q0 in (("identity", np.array([1.0, 0, 0, 0])), ("tilted", np.array([0.9, 0.2, -0.3, 0.25]))):
        q0 = q0 / np.linalg.norm(q0)
        W0 = np.array([0.25, -0.3, 0.2])
        ref = reference_motion(body.inertia, W0, q0, T_EVAL)
        sols = {}
        for name in NAMES:
            f = F.formulation(name, body)
            sols[name] = integrate(f, f.from_common(q0, W0))
        out[label] = (ref, sols)
    return out


@pytest.mark.parametrize("label", ["identity", "tilted"])
def test_all_formulations_give_the_same_motion(label, body, motions):
    (qref, wref), sols = motions[label]
    if label == "identity":  # the geodesic through n = 0 with ndot(0) = Omega0 / 2
        np.testing.assert_allclose(sols["geodesic"][0], [0, 0, 0, 0.125, -0.15, 0.1], atol=1e-15)
    for name, y in sols.items():
        f = F.formulation(name, body)
        q, w = f.to_common(y)
        assert np.max(quaternion_distance(q, qref)) < 2e-10, name
        np.testing.assert_allclose(w, wref, atol=2e-10, err_msg=name)
    # the motion goes well away from the identity (rotation angle > 1.5 rad)
    assert np.max(2 * np.arccos(np.abs(qref[:, 0]))) > 1.5


@pytest.mark.parametrize("label", ["identity", "tilted"])
def test_integrals_conserved_along_solutions(label, body, motions):
    _, sols = motions[label]
    for name, y in sols.items():
        f = F.formulation(name, body)
        ints = f.integrals(y)
        for k in ("H", "m2", "m3"):
            assert np.max(np.abs(ints[k] - ints[k][0])) < 1e-10 * max(1.0, abs(ints[k][0])), (name, k)
        assert np.max(np.abs(ints["m"] - ints["m"][0])) < 1e-10, name
        if name == "euler-poisson":
            cas = f.casimirs(y)
            assert np.max(np.abs(cas - cas[0])) < 1e-10


def test_symmetric_top_closed_form():
    """A symmetric top (non-diagonal tensor): R(t) = exp(t[m]x/I1) R0 exp(nu t [a]x), nu = (1/I3 - 1/I1) a.M0."""
    I1, I3 = 1.2, 2.0
    P = Rotation.random(random_state=4).as_matrix()
    I = P @ np.diag([I1, I1, I3]) @ P.T
    a = P[:, 2]
    body = RigidBody(I)
    R0 = Rotation.from_rotvec([0.3, 0.1, -0.2]).as_matrix()
    W0 = np.array([0.2, 0.35, -0.15])
    M0 = I @ W0
    m = R0 @ M0
    nu = (1 / I3 - 1 / I1) * (a @ M0)
    t = T_EVAL
    Rt = (
        Rotation.from_rotvec(t[:, None] * m / I1).as_matrix()
        @ R0
        @ Rotation.from_rotvec(nu * t[:, None] * a).as_matrix()
    )
    Mt = np.einsum("tji,j->ti", Rt, m)
    Wt = Mt / I1 + (1 / I3 - 1 / I1) * (Mt @ a)[:, None] * a
    q0 = Rotation.from_matrix(R0).as_quat(scalar_first=True)
    for name in ("canonical", "geodesic", "momentum"):
        f = F.formulation(name, body)
        y = integrate(f, f.from_common(q0, W0))
        np.testing.assert_allclose(f.matrix(y), Rt, atol=1e-10, err_msg=name)
        np.testing.assert_allclose(f.omega(y), Wt, atol=1e-10, err_msg=name)


# ---------------------------------------------------------------------------
# Lagrangian side: metric, Christoffel symbols, geodesics
# ---------------------------------------------------------------------------
def test_metric_derivative_matches_finite_differences(body, states):
    n = states["geodesic"][..., :3]
    dG = F.metric_derivative(n, body)
    fd = np.moveaxis(fd_grad(lambda y: metric(y, body), n), -1, -3)  # (..., k, i, j)
    np.testing.assert_allclose(dG, fd, atol=1e-8 * np.max(np.abs(dG)))


def test_christoffel_closed_form(body, states):
    n = states["geodesic"][..., :3]
    Gam = F.christoffel(n, body)
    assert Gam.shape == n.shape[:-1] + (3, 3, 3)
    np.testing.assert_allclose(Gam, np.swapaxes(Gam, -1, -2), atol=1e-15)
    # Levi-Civita formula with finite-difference metric derivatives (independent of metric_derivative)
    fd = np.moveaxis(fd_grad(lambda y: metric(y, body), n), -1, -3)
    np.testing.assert_allclose(Gam, F.christoffel_from_metric(n, body, dG=fd), atol=1e-8 * np.max(np.abs(Gam)))
    np.testing.assert_allclose(Gam, F.christoffel_from_metric(n, body), atol=1e-13 * np.max(np.abs(Gam)))
    # metric compatibility: d_k G_ij = Gamma^l_ki G_lj + Gamma^l_kj G_il
    G = metric(n, body)
    rhs = np.einsum("...lki,...lj->...kij", Gam, G)
    np.testing.assert_allclose(fd, rhs + np.swapaxes(rhs, -1, -2), atol=1e-8 * np.max(np.abs(fd)))


def test_christoffel_sphere_is_projective():
    """I = c 1: Gamma^i_jk = -(n_j d_ik + n_k d_ij)/(1+n^2) and geodesics are straight lines."""
    rng = np.random.default_rng(2)
    n = rng.standard_normal((5, 3))
    s = 1 + np.sum(n * n, -1)
    d = np.eye(3)
    expected = -(n[:, None, :, None] * d[:, None, :] + n[:, None, None, :] * d[:, :, None]) / s[:, None, None, None]
    np.testing.assert_allclose(F.christoffel(n, [2.0, 2.0, 2.0]), expected, atol=1e-14)
    f = F.formulation("geodesic", [2.0, 2.0, 2.0])
    v0 = np.array([0.1, 0.03, -0.07])
    y = integrate(f, np.concatenate([[0.1, -0.2, 0.3], v0]))
    dirs = y[1:, :3] - y[0, :3]
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.abs(dirs @ v0) / np.linalg.norm(v0), 1.0, atol=1e-10)
    assert np.linalg.norm(y[-1, :3] - y[0, :3]) > 0.5


def test_geodesic_acceleration_and_lagrangian(body, states):
    x = states["geodesic"]
    n, v = x[..., :3], x[..., 3:]
    Gam = F.christoffel(n, body)
    acc = F.geodesic_acceleration(n, v, body)
    np.testing.assert_allclose(acc, -np.einsum("...ijk,...j,...k->...i", Gam, v, v), atol=1e-13 * np.max(np.abs(acc)))
    np.testing.assert_allclose(F.formulation("geodesic", body).vector_field(x)[..., 3:], acc, rtol=1e-14)
    # eq. 1.13, last form, and L = Omega.I.Omega / 2
    u = v - np.cross(n, v)
    s = 1 + np.sum(n * n, -1)
    L_paper = 2 / s**2 * np.einsum("...i,ij,...j->...", u, body.inertia, u)
    L = F.lagrangian(n, v, body)
    np.testing.assert_allclose(L, L_paper, rtol=1e-13)
    np.testing.assert_allclose(L, 0.5 * np.einsum("...i,...ij,...j->...", v, metric(n, body), v), rtol=1e-13)
    # Legendre: H(n, G ndot) = L(n, ndot)
    can = F.formulation("canonical", body)
    np.testing.assert_allclose(
        can.hamiltonian(np.concatenate([n, F.canonical_momentum(n, v, body)], -1)), L, rtol=1e-13
    )
    g = F.formulation("geodesic", body)
    np.testing.assert_allclose(g.momenta(x), F.canonical_momentum(n, v, body), rtol=1e-14)
    np.testing.assert_allclose(g.christoffel(x), Gam, rtol=1e-14)
    np.testing.assert_allclose(g.metric(x), metric(n, body), rtol=1e-14)


# ---------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------
def test_kernels_on_tuples_of_floats_match_batched(body, states):
    x = states["canonical"][0]
    n, p = tuple(x[:3]), tuple(x[3:])
    Iinv = tuple(tuple(r) for r in body.inertia_inv)
    nd, pd = F.canonical_rhs(n, p, Iinv)
    np.testing.assert_allclose(np.array(nd + pd), F.formulation("canonical", body).vector_field(x), rtol=1e-14)


def test_canonical_kernel_complex_step(body, states):
    """Hamilton's equations exactly: (dH/dpi, -dH/dn) by complex step equals canonical_rhs."""
    Iinv = body.inertia_inv
    for x in states["canonical"]:
        grad = np.empty(6)
        for a in range(6):
            z = x.astype(complex)
            z[a] += 1e-30j
            grad[a] = np.imag(F.canonical_hamiltonian(z[:3], z[3:], Iinv)) / 1e-30
        nd, pd = F.canonical_rhs(x[:3], x[3:], Iinv)
        np.testing.assert_allclose(np.array(nd), grad[3:], rtol=1e-14, atol=1e-15)
        np.testing.assert_allclose(np.array(pd), -grad[:3], rtol=1e-14, atol=1e-15)


def test_kernels_are_polynomial_in_sympy():
    sp = pytest.importorskip("sympy")
    n = sp.symbols("n1:4")
    p = sp.symbols("p1:4")
    J = sp.symbols("J1:4")
    Iinv = [[J[0], 0, 0], [0, J[1], 0], [0, 0, J[2]]]
    nd, pd = F.canonical_rhs(n, p, Iinv)
    # ndot: degree 4 in n, linear in pi; pidot: degree 3 in n, quadratic in pi
    for exprs, dn, dp in ((nd, 4, 1), (pd, 3, 2)):
        for e in exprs:
            e = sp.expand(e)
            assert sp.Poly(e, *n).total_degree() == dn and sp.Poly(e, *p).total_degree() == dp
    assert sp.expand(F.canonical_hamiltonian(n, p, Iinv)).is_polynomial(*n, *p)


@pytest.mark.slow
def test_numba_kernels(body, states):
    pytest.importorskip("numba")
    nk = F.numba_kernels()
    I, Iinv = body.inertia, body.inertia_inv
    x = states["geodesic"][0]
    nd, a = nk.geodesic_rhs(x[:3], x[3:], I, Iinv)
    np.testing.assert_allclose(np.array(nd + a), F.formulation("geodesic", body).vector_field(x), rtol=1e-14)
    y = states["canonical"][0]
    nd, pd = nk.canonical_rhs(y[:3], y[3:], Iinv)
    np.testing.assert_allclose(np.array(nd + pd), F.formulation("canonical", body).vector_field(y), rtol=1e-14)


def test_batched_bodies_broadcast(states):
    I = np.stack([full_inertia(1), full_inertia(2, (1.0, 1.5, 2.0))])
    bodies = RigidBody(I)
    x = states["canonical"][:4]
    for name in ("canonical", "geodesic", "velocity", "momentum", "euler-poisson"):
        y = F.formulation("canonical", RigidBody(I[0])).convert(x, name)
        f = F.formulation(name, bodies)
        vf = f.vector_field(y[:, None, :])
        P = f.poisson_tensor(y[:, None, :])
        H = f.hamiltonian(y[:, None, :])
        assert vf.shape == (4, 2, y.shape[-1]) and P.shape == (4, 2) + (y.shape[-1],) * 2 and H.shape == (4, 2)
        for b in range(2):
            fb = F.formulation(name, RigidBody(I[b]))
            np.testing.assert_allclose(vf[:, b], fb.vector_field(y), rtol=1e-13, atol=1e-14)
            np.testing.assert_allclose(P[:, b], fb.poisson_tensor(y), rtol=1e-13, atol=1e-14)
            np.testing.assert_allclose(H[:, b], fb.hamiltonian(y), rtol=1e-13)


# ---------------------------------------------------------------------------
# the paper's printed formulas, machine-checked
# ---------------------------------------------------------------------------
def nhat(n):
    return np.einsum("ijp,...p->...ij", EPS, n)


def cyclic(n):
    """The paper's (nhat_ij n_k + cycle(ijk)), shape (..., 3, 3, 3)."""
    t = np.einsum("...ij,...k->...ijk", nhat(n), n)
    return t + np.einsum("...ijk->...jki", t) + np.einsum("...ijk->...kij", t)


def test_paper_eq_1_16_printed_pidot_is_a_misprint(body, states):
    """Printed: pidot_i = -1/4 [d_ij (n.pi) + pi_i n_j + eps_ijk n_k](I^-1 Ã pi)_j; correct: eps_ijk pi_k."""
    f = F.formulation("canonical", body)
    x = states["canonical"]
    n, p = x[..., :3], x[..., 3:]
    u = np.einsum("ij,...j->...i", body.inertia_inv, np.einsum("...ij,...j->...i", inverse_conversion_matrix(n), p))
    npi = np.sum(n * p, -1)

    def pidot(last):
        K = (
            npi[..., None, None] * np.eye(3)
            + p[..., :, None] * n[..., None, :]
            + np.einsum("ijk,...k->...ij", EPS, last)
        )
        return -0.25 * np.einsum("...ij,...j->...i", K, u)

    minus_dHdn = -fd_grad(f.hamiltonian, x)[..., :3]
    np.testing.assert_allclose(pidot(p), minus_dHdn, atol=1e-8)
    np.testing.assert_allclose(f.vector_field(x)[..., 3:], pidot(p), rtol=1e-13, atol=1e-14)
    assert np.max(np.abs(pidot(n) - minus_dHdn)) > 1e-2 * np.max(np.abs(minus_dHdn))


def test_paper_eq_1_21_and_1_22(body, states):
    """Printed {n_i, m_j} and {m_i, m_j}; the cyclic term equals n^2 eps_ijk, so {m_i, m_j} = eps_ijk m_k."""
    x = states["momentum"]
    n, m = x[..., :3], x[..., 3:]
    P = F.formulation("momentum", body).poisson_tensor(x)
    s = 1 + np.sum(n * n, -1)
    nm = 0.5 * (np.einsum("ijk,...k->...ij", EPS, n) + np.eye(3) + n[..., :, None] * n[..., None, :])
    mm = np.einsum("...ijk,...k->...ij", EPS + cyclic(n), m) / s[..., None, None]
    np.testing.assert_allclose(P[..., :3, 3:], nm, atol=1e-14)
    np.testing.assert_allclose(P[..., 3:, 3:], mm, atol=1e-13)
    np.testing.assert_allclose(cyclic(n), np.sum(n * n, -1)[..., None, None, None] * EPS, atol=1e-13)
    # eq. 1.22: (nhat_ij n_k + cycle) m_k m_j = 0
    assert np.max(np.abs(np.einsum("...ijk,...k,...j->...i", cyclic(n), m, m))) < 1e-12


def test_paper_eq_1_28_and_1_29(body, states):
    """Printed {n_i, Omega_j}, {Omega_i, Omega_j} and the identity (1.29)."""
    x = states["velocity"]
    n, W = x[..., :3], x[..., 3:]
    Iinv = body.inertia_inv
    M = W @ body.inertia
    s = 1 + np.sum(n * n, -1)
    P = F.formulation("velocity", body).poisson_tensor(x)
    nW = 0.5 * np.einsum(
        "...ik,kj->...ij", -np.einsum("ikp,...p->...ik", EPS, n) + np.eye(3) + n[..., :, None] * n[..., None, :], Iinv
    )
    WW = -np.einsum("ia,jb,...abc,...c->...ij", Iinv, Iinv, EPS + cyclic(n), M) / s[..., None, None]
    np.testing.assert_allclose(P[..., :3, 3:], nW, atol=1e-14)
    np.testing.assert_allclose(P[..., 3:, 3:], WW, atol=1e-13)
    lhs = np.einsum("...abc,...c,...b->...a", cyclic(n), M, W)
    np.testing.assert_allclose(lhs, -np.sum(n * n, -1)[..., None] * np.cross(M, W), atol=1e-12)


def test_paper_eq_1_18_left_and_right_momenta_commute(body, states):
    f = F.formulation("canonical", body)
    x = states["canonical"]

    def a_t_pi(y):  # (Ã^T pi)_i = 2 m_i
        return np.einsum("...ji,...j->...i", inverse_conversion_matrix(y[..., :3]), y[..., 3:])

    def a_pi(y):  # (Ã pi)_j = 2 M_j
        return np.einsum("...ij,...j->...i", inverse_conversion_matrix(y[..., :3]), y[..., 3:])

    br = np.einsum("...ia,...ab,...jb->...ij", fd_grad(a_t_pi, x), f.poisson_tensor(x), fd_grad(a_pi, x))
    assert np.max(np.abs(br)) < 1e-8


def test_paper_metric_at_origin_and_energy_footnote(body):
    """G(0) = 4I (the text says G -> delta); at n = 0, E = I^-1_ij m_i m_j / 2 (the footnote omits 1/2)."""
    np.testing.assert_allclose(metric(np.zeros(3), body), 4 * body.inertia, rtol=1e-15)
    f = F.formulation("momentum", body)
    m = np.array([0.3, -1.2, 0.7])
    x = np.concatenate([np.zeros(3), m])
    np.testing.assert_allclose(f.hamiltonian(x), 0.5 * m @ body.inertia_inv @ m, rtol=1e-14)


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_wrong_state_shape(name, body):
    f = F.formulation(name, body)
    d = f.dimension
    with pytest.raises(InvalidInputError, match=rf"state of the '{name}' formulation must have shape \(\.\.\., {d}\)"):
        f.vector_field(np.zeros(d - 1))
    with pytest.raises(InvalidInputError, match=r"must have shape"):
        f.poisson_tensor(np.zeros((2, d + 1)))


@pytest.mark.parametrize("method", ["vector_field", "hamiltonian", "poisson_tensor", "integrals", "to_common"])
def test_nan_state(method, body, states):
    f = F.formulation("canonical", body)
    x = states["canonical"].copy()
    x[1, 4] = np.nan
    with pytest.raises(InvalidInputError, match="NaN or infinite"):
        getattr(f, method)(x)


def test_unknown_name_and_bad_arguments(body):
    with pytest.raises(InvalidInputError, match=r"unknown formulation 'hamilton-jacobi'; expected one of"):
        F.formulation("hamilton-jacobi", body)
    with pytest.raises(TypeError, match="formulation name must be a string"):
        F.formulation(3, body)
    with pytest.raises(InvalidInertiaError, match="triangle inequality"):
        F.formulation("canonical", [1.0, 1.0, 3.0])
    f = F.formulation("canonical", body)
    with pytest.raises(InvalidInputError, match=r"needs the blocks \['n', 'pi'\]"):
        f.pack(n=np.zeros(3), m=np.zeros(3))
    with pytest.raises(InvalidInputError, match=r"pi must have shape \(\.\.\., 3\)"):
        f.pack(n=np.zeros(3), pi=np.zeros(4))
    with pytest.raises(InvalidInputError, match="unknown formulation 'bogus'"):
        f.convert(np.zeros(6), "bogus")
    with pytest.raises(InvalidInputError, match=r"n must have shape \(\.\.\., 3\)"):
        F.christoffel(np.zeros(4), body)
    with pytest.raises(InvalidInputError, match=r"ndot contains NaN"):
        F.lagrangian(np.zeros(3), [np.nan, 0, 0], body)


def test_singular_chart_and_non_rotation(body):
    q_pi = np.array([0.0, 0.0, 1.0, 0.0])  # rotation by pi: n is infinite
    for name in ("canonical", "momentum", "velocity", "geodesic"):
        with pytest.raises(SingularChartError, match="alpha = pi"):
            F.formulation(name, body).from_common(q_pi, np.ones(3))
    ep = F.formulation("euler-poisson", body)
    x = ep.from_common(q_pi, np.ones(3))  # fine in (R, Omega)
    with pytest.raises(SingularChartError, match="alpha = pi"):
        ep.convert(x, "canonical")
    bad = np.concatenate([2.0 * np.eye(3).ravel(), np.ones(3)])
    with pytest.raises(InvalidInputError, match="not a rotation matrix"):
        ep.to_common(bad)


def test_numba_missing(monkeypatch):
    monkeypatch.setitem(sys.modules, "numba", None)
    with pytest.raises(MissingDependencyError, match=r"eulerpoisson\[fast\]"):
        F.numba_kernels()
