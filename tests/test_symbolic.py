"""Tests of eulerpoisson.paper.symbolic against independent numeric truth.

The derivation is compared with numbers computed without it: scipy's rotation
of a quaternion, finite differences of R(n(t)), a kinetic energy built from
finite-difference angular velocities, numerical gradients, a high-precision
mpmath ODE solution and scipy's solve_ivp.
"""

from __future__ import annotations

import numpy as np
import pytest

sp = pytest.importorskip("sympy")

from eulerpoisson.errors import InvalidInputError  # noqa: E402
from eulerpoisson.paper import symbolic as S  # noqa: E402

RNG = np.random.default_rng(12345)
I_GEN = np.array([[2.0, 0.3, -0.2], [0.3, 3.0, 0.4], [-0.2, 0.4, 4.5]])  # general, non-diagonal


@pytest.fixture(scope="module")
def D():
    return S.derive("general")


def _num(D, expr, n=None, ndot=None, pi=None, inertia=I_GEN, extra=None):
    """Evaluate a derived expression numerically (float) at the given point."""
    sub = {}
    if n is not None:
        sub.update(dict(zip(D.n, n)))
    if ndot is not None:
        sub.update(dict(zip(D.ndot, ndot)))
    if pi is not None:
        sub.update(dict(zip(D.pi, pi)))
    if inertia is not None:
        I11, I12, I13, I22, I23, I33 = D.inertia_symbols
        sub.update(
            {
                I11: inertia[0, 0],
                I12: inertia[0, 1],
                I13: inertia[0, 2],
                I22: inertia[1, 1],
                I23: inertia[1, 2],
                I33: inertia[2, 2],
            }
        )
    if extra:
        sub.update(extra)
    # the numbers substituted at 30 digits (no lambdify: printing and compiling each expression took longer
    # than evaluating it)
    value = sp.N(expr.xreplace({s: sp.Float(float(v), 30) for s, v in sub.items()}), 30)
    return np.array(value.tolist() if isinstance(value, sp.MatrixBase) else value, dtype=float)


def _R_numpy(n):
    """R(n) from the unit quaternion (1, n)/|(1, n)| via scipy (scalar-last)."""
    from scipy.spatial.transform import Rotation

    q = np.concatenate([n, [1.0]])
    return Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()


def _vee(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


# --------------------------------------------------------------------------- kinematics


def test_R_is_scipy_rotation_orthogonal_det1(D):
    for _ in range(5):
        n = RNG.normal(size=3)
        R = _num(D, D.R, n=n, inertia=None)
        assert np.allclose(R, _R_numpy(n), atol=1e-13)
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-13)
        assert np.isclose(np.linalg.det(R), 1.0, atol=1e-13)


def test_R_quaternion_and_axis_angle_agree(D):
    # the rotation by alpha about unit k, built from the construction of eq. 1.7
    k = np.array([1.0, -2.0, 2.0]) / 3.0
    alpha = 1.2
    Rk = np.array(S.rotation_from_axis_angle(sp.Matrix(k), np.cos(alpha), np.sin(alpha)), dtype=float)
    n = k * np.tan(alpha / 2)
    assert np.allclose(Rk, _num(D, D.R, n=n, inertia=None), atol=1e-14)
    assert np.allclose(Rk @ k, k)


def test_Omega_from_finite_differences(D):
    for _ in range(3):
        n0, v = RNG.normal(size=3), RNG.normal(size=3)
        h = 1e-6
        Rp, Rm, R0 = _R_numpy(n0 + h * v), _R_numpy(n0 - h * v), _R_numpy(n0)
        Rdot = (Rp - Rm) / (2 * h)
        Om_fd = _vee(R0.T @ Rdot)
        om_fd = _vee(Rdot @ R0.T)
        assert np.allclose(_num(D, D.Omega_of_velocity, n=n0, ndot=v, inertia=None).ravel(), Om_fd, atol=1e-8)
        assert np.allclose(_num(D, D.omega_of_velocity, n=n0, ndot=v, inertia=None).ravel(), om_fd, atol=1e-8)


def test_A_and_Atilde(D):
    assert sp.simplify(D.A * D.Atilde - sp.eye(3)) == sp.zeros(3, 3)
    n = D.n
    expected = sp.Matrix(
        3, 3, lambda i, j: int(i == j) + n[i] * n[j] + sum(S.levi_civita(i, j, k) * n[k] for k in range(3))
    )
    assert sp.expand(D.Atilde - expected) == sp.zeros(3, 3)


def test_metric_against_numeric_kinetic_energy(D):
    """G from polarisation of L = 1/2 Omega.I Omega with Omega from finite differences of R(n(t))."""
    n0 = RNG.normal(size=3)
    h = 1e-6

    def L(v):
        Rdot = (_R_numpy(n0 + h * v) - _R_numpy(n0 - h * v)) / (2 * h)
        Om = _vee(_R_numpy(n0).T @ Rdot)
        return 0.5 * Om @ I_GEN @ Om

    E = np.eye(3)
    G_num = np.array([[L(E[i] + E[j]) - L(E[i]) - L(E[j]) for j in range(3)] for i in range(3)])
    G = _num(D, D.G, n=n0)
    assert np.allclose(G, G_num, rtol=1e-7, atol=1e-8)
    assert np.allclose(_num(D, D.Ginv, n=n0) @ G, np.eye(3), atol=1e-12)
    # the metric is 4 I at the origin
    assert np.allclose(_num(D, D.G, n=np.zeros(3)), 4 * I_GEN)


def test_euler_homogeneity_and_legendre(D):
    assert S.is_zero(D.euler_homogeneity)
    n, p = RNG.normal(size=3), RNG.normal(size=3)
    v = _num(D, D.velocity_of_momenta, n=n, pi=p).ravel()
    L = float(_num(D, D.L, n=n, ndot=v))
    H = float(_num(D, D.H, n=n, pi=p))
    assert np.isclose(H, p @ v - L, rtol=1e-12)


def test_hamilton_equations_numeric_gradient_and_rhs(D):
    n, p = RNG.normal(size=3) * 0.7, RNG.normal(size=3)
    h = 1e-6
    Hf = sp.lambdify(list(D.n) + list(D.pi) + list(D.inertia_symbols), D.H, "numpy")
    Iv = [I_GEN[0, 0], I_GEN[0, 1], I_GEN[0, 2], I_GEN[1, 1], I_GEN[1, 2], I_GEN[2, 2]]

    def H(z):
        return Hf(*z, *Iv)

    z = np.concatenate([n, p])
    grad = np.array([(H(z + h * e) - H(z - h * e)) / (2 * h) for e in np.eye(6)])
    ndot = _num(D, D.ndot_canonical, n=n, pi=p).ravel()
    pidot = _num(D, D.pidot_canonical, n=n, pi=p).ravel()
    assert np.allclose(ndot, grad[3:], atol=1e-8)
    assert np.allclose(pidot, -grad[:3], atol=1e-8)
    assert np.allclose(np.concatenate([ndot, pidot]), S.hamilton_rhs(z, np.linalg.inv(I_GEN)), atol=1e-12)


def test_m_is_inertia_free_and_conserved_numerically(D):
    from scipy.integrate import solve_ivp

    assert not (D.m_canonical.free_symbols & set(D.inertia_symbols))
    mf = sp.lambdify(list(D.n) + list(D.pi), D.m_canonical, "numpy")
    Kinv = np.linalg.inv(I_GEN)
    z0 = np.concatenate([[0.1, -0.2, 0.3], [1.0, -0.4, 0.7]])
    sol = solve_ivp(
        lambda t, z: S.hamilton_rhs(z, Kinv), (0, 3), z0, rtol=1e-11, atol=1e-12, t_eval=np.linspace(0, 3, 7)
    )
    ms = np.array([np.asarray(mf(*z), dtype=float).ravel() for z in sol.y.T])
    assert np.allclose(ms, ms[0], atol=1e-9)
    # and m = R I Omega numerically (Omega from the velocity)
    n, p = z0[:3], z0[3:]
    Om = _num(D, D.Omega_canonical, n=n, pi=p).ravel()
    assert np.allclose(ms[0], _R_numpy(n) @ I_GEN @ Om, atol=1e-12)


def test_brackets_numeric(D):
    """{m_i, m_j} from numerical gradients of m(n, pi) equals eps_ijk m_k."""
    mf = sp.lambdify(list(D.n) + list(D.pi), D.m_canonical, "numpy")

    def m(z):
        return np.asarray(mf(*z), dtype=float).ravel()

    z = RNG.normal(size=6)
    h = 1e-6
    J = np.array([(m(z + h * e) - m(z - h * e)) / (2 * h) for e in np.eye(6)]).T  # (3, 6)
    P = np.block([[np.zeros((3, 3)), np.eye(3)], [-np.eye(3), np.zeros((3, 3))]])
    mm_num = J @ P @ J.T
    mv = m(z)
    eps_m = np.array([[sum(S.levi_civita(i, j, k) * mv[k] for k in range(3)) for j in range(3)] for i in range(3)])
    assert np.allclose(mm_num, eps_m, atol=1e-7)
    B, C = D.brackets("nm")
    assert sp.expand(
        C - sp.Matrix(3, 3, lambda i, j: sum(S.levi_civita(i, j, k) * D.m_sym[k] for k in range(3)))
    ) == sp.zeros(3, 3)
    assert sp.expand(B - D.Atilde / 2) == sp.zeros(3, 3)


def test_poisson_tensor_pfaffian(D):
    P = D.poisson_tensor("nm")
    assert P.shape == (6, 6)
    assert sp.simplify(P + P.T) == sp.zeros(6, 6)
    det = S.rsimp(P.det(method="berkowitz"))
    assert sp.simplify(det - (1 + D.nsq) ** 4 / 64) == 0
    assert (
        D.poisson_tensor("canonical")
        == sp.BlockMatrix([[sp.zeros(3), sp.eye(3)], [-sp.eye(3), sp.zeros(3)]]).as_explicit()
    )


def test_cyclic_tensor_identity(D):
    T = S.cyclic_tensor(D.n)
    for i in range(3):
        for j in range(3):
            for k in range(3):
                assert sp.expand(T[i][j][k] - D.nsq * S.levi_civita(i, j, k)) == 0


def test_geodesic_equations_match_euler_lagrange_numerically(D):
    n, nd, ndd = RNG.normal(size=3) * 0.5, RNG.normal(size=3), RNG.normal(size=3)
    extra = dict(zip(D.nddot, ndd))
    EL = _num(D, D.euler_lagrange, n=n, ndot=nd, extra=extra).ravel()
    geo = _num(D, D.geodesic, n=n, ndot=nd, extra=extra).ravel()
    G = _num(D, D.G, n=n)
    assert np.allclose(EL, G @ geo, atol=1e-10)


def test_diagonal_derivation_consistent_with_general():
    Dd, Dg = S.derive("diagonal"), S.derive("general")
    I1, I2, I3 = Dd.inertia_symbols
    I11, I12, I13, I22, I23, I33 = Dg.inertia_symbols
    rep = {I12: 0, I13: 0, I23: 0, I11: I1, I22: I2, I33: I3}
    assert S.is_zero(Dg.H.xreplace(rep) - Dd.H)
    assert S.derive("diagonal") is Dd  # cached


# --------------------------------------------------------------------------- helpers and errors


def test_poisson_bracket_shapes_and_canonical():
    q = sp.symbols("q1:3")
    p = sp.symbols("p1:3")
    assert S.poisson_bracket(q[0], p[0], q, p) == 1
    assert S.poisson_bracket(p[0], q[0], q, p) == -1
    M = S.poisson_bracket(sp.Matrix(q), sp.Matrix(p), q, p)
    assert M == sp.eye(2)
    v = S.poisson_bracket(sp.Matrix(q), p[1], q, p)
    assert v.shape == (2, 1) and list(v) == [0, 1]
    with pytest.raises(InvalidInputError, match="equal length"):
        S.poisson_bracket(q[0], p[0], q, p[:1])
    with pytest.raises(InvalidInputError, match="Symbols only"):
        S.poisson_bracket(q[0], p[0], [q[0] + 1, q[1]], p)


def test_rsimp_is_zero_inverse3():
    x, y = sp.symbols("x y")
    assert S.rsimp((x**2 - 1) / (x - 1)) == x + 1
    assert S.is_zero(1 / (1 + x**2) - 1 / (1 + x**2))
    assert not S.is_zero(x / (1 + y))
    M = sp.Matrix([[1, x, 0], [0, 1, 0], [0, 0, 1 + y**2]])
    assert sp.simplify(S.inverse3(M) * M - sp.eye(3)) == sp.zeros(3, 3)
    with pytest.raises(InvalidInputError, match="rational function"):
        S.rsimp(sp.sin(x))
    with pytest.raises(InvalidInputError, match="singular"):
        S.inverse3(sp.Matrix([[1, 2, 3], [2, 4, 6], [0, 0, 1]]))
    with pytest.raises(InvalidInputError, match="shape"):
        S.inverse3(sp.eye(2))


def test_derive_errors(D):
    with pytest.raises(InvalidInputError, match="inertia must be one of"):
        S.derive("spherical")
    with pytest.raises(InvalidInputError, match="chart must be one of"):
        D.to_chart(D.H, "polar")
    with pytest.raises(InvalidInputError, match="chart must be one of"):
        D.brackets("canonical")
    with pytest.raises(InvalidInputError, match="quantity name must be one of"):
        D.quantity("spin", "nm")


def test_quantity_in_charts(D):
    # the Hamiltonian in (n, Omega) is 1/2 Omega.I Omega (eq. 1.27), computed independently here
    Om = D.Omega_sym
    assert S.is_zero(D.quantity("H", "nOmega") - (Om.T * D.I * Om)[0] / 2)
    assert D.quantity("mdot", "nm") == sp.zeros(3, 1)


# --------------------------------------------------------------------------- Lie series


def test_lie_series_low_orders_exact(D):
    I = sp.Matrix([[3, 1, 0], [1, 2, sp.Rational(1, 2)], [0, sp.Rational(1, 2), 4]])
    pi0 = [1, sp.Rational(-2, 3), 3]
    C = S.taylor_coefficients(2, inertia=I, pi0=pi0)
    rep = dict(zip(D.inertia_symbols, [I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]]))
    at0 = {**rep, **dict(zip(D.n, [0, 0, 0])), **dict(zip(D.pi, pi0))}
    f = sp.Matrix.vstack(D.ndot_canonical, D.pidot_canonical)
    assert list(C.row(0)) == [0, 0, 0] + pi0
    assert list(C.row(1)) == [sp.nsimplify(x) for x in f.xreplace(at0)]
    # second coefficient = 1/2 d/dt f = 1/2 (df/dz) f, at z0: the derivative of f along the line
    # z0 + s f(z0) at s = 0 (the chain rule; the same numbers as the full Jacobian, without its 36
    # derivatives of the general-inertia expressions)
    z = list(D.n) + list(D.pi)
    z0 = [0, 0, 0] + pi0
    f0 = list(f.xreplace(at0))
    s = sp.Symbol("s")
    line = {**rep, **{zi: z0i + s * fi for zi, z0i, fi in zip(z, z0, f0)}}
    c2 = [sp.diff(x.xreplace(line), s).xreplace({s: 0}) / 2 for x in f]
    assert [sp.nsimplify(x) for x in C.row(2)] == [sp.nsimplify(sp.simplify(x)) for x in c2]


def test_taylor_coefficients_against_mpmath_high_precision():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    Iv = [[2, 0.5, 0], [0.5, 3, 0.25], [0, 0.25, 4]]
    K = mp.matrix(Iv) ** -1

    def F(t, z):
        n, p = mp.matrix(z[:3]), mp.matrix(z[3:])
        N = mp.matrix([[0, n[2], -n[1]], [-n[2], 0, n[0]], [n[1], -n[0], 0]])
        At = mp.eye(3) + n * n.T + N
        w = K * (At * p)
        P = mp.matrix([[0, p[2], -p[1]], [-p[2], 0, p[0]], [p[1], -p[0], 0]])
        B = (n.T * p)[0] * mp.eye(3) + p * n.T + P
        nd, pd = At.T * w / 4, -(B * w) / 4
        return [nd[0], nd[1], nd[2], pd[0], pd[1], pd[2]]

    sol = mp.odefun(F, 0, [0, 0, 0, 1, mp.mpf(-0.5), mp.mpf(0.75)])
    h, M = mp.mpf("1e-3"), 12
    ts = [j * h for j in range(M)]
    V = mp.matrix([[t**k for k in range(M)] for t in ts])
    Y = [sol(t) for t in ts]
    ref = np.array([[float(mp.lu_solve(V, mp.matrix([y[a] for y in Y]))[k]) for a in range(6)] for k in range(6)])
    mp.mp.dps = 15
    C = S.taylor_coefficients(5, inertia=Iv, pi0=[1, -0.5, 0.75], as_float=True)
    assert C.shape == (6, 6)
    assert np.allclose(C, ref, atol=1e-12, rtol=0)


@pytest.mark.parametrize("order", [2, 3, 5])
def test_lie_series_truncation_error_scales(order):
    chk = S.check_lie_series(order, I_GEN, [1.0, -0.5, 0.8])
    assert abs(chk.slope - (order + 1)) < 0.3
    assert chk.expected_slope == order + 1
    assert np.all(chk.errors > 0)


def test_lie_series_nonzero_n0_and_symbolic():
    chk = S.check_lie_series(4, [1.0, 2.0, 3.5], [0.3, -0.7, 1.1], n0=[0.4, -0.2, 0.9])
    assert abs(chk.slope - 5) < 0.3
    n_t, pi_t = S.lie_series(2, inertia="diagonal")
    t = sp.Symbol("t")
    I1, I2, I3 = S.derive("diagonal").inertia_symbols
    p1, p2, p3 = sp.symbols("pi0_1:4", real=True)
    assert sp.simplify(n_t[0].coeff(t, 1) - p1 / (4 * I1)) == 0
    assert n_t.shape == (3, 1) and pi_t.shape == (3, 1)
    assert sp.Poly(n_t[0], t).degree() == 2
    n1, _ = S.lie_series(1, inertia=[1, 2, 3], pi0=[4, 0, 0])
    assert n1.T == sp.Matrix([[t, 0, 0]])


@pytest.mark.parametrize("order", [-1, 17, 1.5, True, "3"])
def test_lie_series_bad_order(order):
    with pytest.raises(InvalidInputError, match="order must be an integer"):
        S.lie_series(order, inertia=[1, 2, 3], pi0=[1, 0, 0])


def test_lie_series_bad_inputs():
    with pytest.raises(InvalidInputError, match="inertia must have shape"):
        S.taylor_coefficients(2, inertia=[1, 2], pi0=[1, 0, 0])
    with pytest.raises(InvalidInputError, match="symmetric"):
        S.taylor_coefficients(2, inertia=[[1, 2, 0], [0, 1, 0], [0, 0, 1]], pi0=[1, 0, 0])
    with pytest.raises(InvalidInputError, match="invertible"):
        S.taylor_coefficients(2, inertia=[1, 0, 3], pi0=[1, 0, 0])
    with pytest.raises(InvalidInputError, match="pi0 must be a 3-vector"):
        S.taylor_coefficients(2, inertia=[1, 2, 3], pi0=[1, 0])
    with pytest.raises(InvalidInputError, match="finite"):
        S.taylor_coefficients(2, inertia=[1, 2, 3], pi0=[1, float("nan"), 0])
    with pytest.raises(InvalidInputError, match="as_float"):
        S.taylor_coefficients(2, inertia="diagonal", as_float=True)
    with pytest.raises(InvalidInputError, match="inertia must be None"):
        S.taylor_coefficients(2, inertia="round")
    with pytest.raises(InvalidInputError, match="order must be >= 1"):
        S.check_lie_series(0, [1, 2, 3], [1, 0, 0])
    with pytest.raises(InvalidInputError, match="numeric inertia"):
        S.check_lie_series(2, None, [1, 0, 0])
    with pytest.raises(InvalidInputError, match="times must be"):
        S.check_lie_series(2, [1, 2, 3], [1, 0, 0], times=[0.1, -0.2])
    with pytest.raises(InvalidInputError, match="numeric pi0"):
        S.check_lie_series(2, [1, 2, 3], None)
    with pytest.raises(InvalidInputError, match="hamilton_rhs: z must have shape"):
        S.hamilton_rhs([1.0, 2.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
