"""The JAX torques and the exact-flow splitting integrator (issue 24).

Truths: the NumPy torques' own ``evaluate`` (to 1e-15 of the torque's natural magnitude), the
package's Taylor integrator at ``tol=1e-15`` (measured orders 2 and 4), its ``rk`` integrator for a
damping torque, the package's own splitting ``method="symplectic", scheme="exact_splitting(4)"``
(the same scheme, in NumPy/numba: agreement to round-off), and central differences (gradients).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")

import jax.numpy as jnp  # noqa: E402

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.attitude.quaternion import matrix_from_unit_quaternion  # noqa: E402
from eulerpoisson.jax import torques as jt  # noqa: E402
from eulerpoisson.jax.splitting import composition, integrate, quaternion_from_matrix, rk4_free_flow  # noqa: E402
from strategies import inertia_tensors, quaternions  # noqa: E402

RNG = np.random.default_rng(20240)
N = 6
Q = RNG.normal(size=(N, 4))
Q /= np.linalg.norm(Q, axis=-1, keepdims=True)
W = RNG.normal(size=(N, 3))
T = RNG.uniform(0.0, 10.0, size=N)
_A = RNG.normal(size=(N, 3, 3))
INERTIA = _A @ _A.transpose(0, 2, 1) + np.eye(3)
R = matrix_from_unit_quaternion(Q)

I_TENSOR = np.array([[2.0, 0.1, -0.05], [0.1, 2.5, 0.2], [-0.05, 0.2, 1.0]])
Q0 = np.array([0.9, 0.1, 0.3, 0.2]) / np.linalg.norm([0.9, 0.1, 0.3, 0.2])
W0 = np.array([0.3, 1.0, 0.2])


@pytest.fixture(autouse=True)
def _x64():
    with jax.enable_x64(True):
        yield


def _norm(a):
    return np.linalg.norm(np.asarray(a, dtype=float), axis=-1)


# (NumPy torque, its natural magnitude per body: the scale of the rounding errors)
TORQUES = [
    pytest.param(
        ep.torques.Gravity(RNG.uniform(1, 2, N), RNG.normal(size=(N, 3)), RNG.normal(size=(N, 3))),
        lambda tq: tq.mass * _norm(tq.center_of_mass) * _norm(tq.g),
        id="gravity",
    ),
    pytest.param(ep.torques.Gravity(2.0, [0.0, 0.01, 0.1]), lambda tq: 2.0 * 0.1005 * 9.81, id="gravity-default-g"),
    pytest.param(
        ep.torques.GravityGradient(RNG.uniform(0.0, 1.0, N)),
        lambda tq: 3 * tq.mean_motion**2 * np.linalg.norm(INERTIA, axis=(-2, -1)),
        id="gravity-gradient",
    ),
    pytest.param(ep.torques.BodyTorque(RNG.normal(size=(N, 3))), lambda tq: _norm(tq.tau), id="body"),
    pytest.param(ep.torques.SpaceTorque(RNG.normal(size=(N, 3))), lambda tq: _norm(tq.tau), id="space"),
    pytest.param(
        ep.torques.MagneticDipoleTorque(RNG.normal(size=(N, 3)), RNG.normal(size=(N, 3))),
        lambda tq: _norm(tq.dipole) * _norm(tq.field),
        id="magnetic",
    ),
]


# ---------------------------------------------------------------------------
# torques
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("torque, scale", TORQUES)
def test_torque_matches_numpy_evaluate(torque, scale):
    twin = jt.from_torque(torque)
    got = np.asarray(twin(T, Q, W, INERTIA))
    want = torque.evaluate(T, R, W, INERTIA)
    assert got.shape == want.shape and got.dtype == np.float64
    err = np.max(np.abs(got - want), axis=-1)
    assert np.all(err <= 1e-15 * np.broadcast_to(scale(torque), err.shape)), err


@settings(max_examples=25, deadline=None)
@given(
    q=quaternions(shape=(4,)),
    inertia=inertia_tensors(shape=(4,)),
    t=st.floats(-50.0, 50.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_torques_match_numpy_evaluate_sampled(q, inertia, t, seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(4, 3))
    R4 = matrix_from_unit_quaternion(q)
    for tq, scale in (
        (ep.torques.Gravity(rng.uniform(0.1, 3.0), rng.normal(size=3), rng.normal(size=3)), None),
        (ep.torques.GravityGradient(rng.uniform(0.0, 2.0)), None),
        (ep.torques.SpaceTorque(rng.normal(size=(4, 3))), None),
        (ep.torques.MagneticDipoleTorque(rng.normal(size=3), rng.normal(size=(4, 3))), None),
    ):
        want = tq.evaluate(t, R4, w, inertia)
        got = np.asarray(jt.from_torque(tq)(t, q, w, inertia))
        if isinstance(tq, ep.torques.Gravity):
            scale = tq.mass * np.linalg.norm(tq.center_of_mass) * np.linalg.norm(tq.g)
        elif isinstance(tq, ep.torques.GravityGradient):
            scale = 3 * tq.mean_motion**2 * np.linalg.norm(inertia, axis=(-2, -1))
        elif isinstance(tq, ep.torques.SpaceTorque):
            scale = np.linalg.norm(tq.tau, axis=-1)
        else:
            scale = np.linalg.norm(tq.dipole) * np.linalg.norm(tq.field, axis=-1)
        err = np.max(np.abs(got - want), axis=-1)
        assert np.all(err <= 1e-15 * np.broadcast_to(scale, err.shape) + 1e-300), (tq, err, scale)


def test_torque_sum_list_and_moments():
    tqs = [
        ep.torques.GravityGradient(0.3),
        ep.torques.SpaceTorque([0.1, -0.2, 0.3]),
        ep.torques.Gravity(1.0, [0, 0, 0.2]),
    ]
    twin = jt.from_torque(tqs)
    assert isinstance(twin, jt.TorqueSum) and len(twin.terms) == 3 and twin.time_dependent
    moments = np.array([1.0, 2.0, 2.5])
    want = sum(tq.evaluate(T, R, W, np.diag(moments)) for tq in tqs)
    np.testing.assert_allclose(np.asarray(twin(T, Q, W, moments)), want, rtol=0, atol=1e-14)
    assert jt.from_torque([]) is None and jt.from_torque(None) is None and jt.from_torque(twin) is twin


def test_torque_time_dependent_field_and_function_torque():
    def field(t):
        return jnp.stack([jnp.cos(t), jnp.sin(t), 0.5 + 0.0 * t], -1)

    mag = jt.MagneticDipoleTorque([0.1, 0.2, 0.3], field)
    ref = ep.torques.MagneticDipoleTorque([0.1, 0.2, 0.3], lambda t: np.stack([np.cos(t), np.sin(t), 0.5 + 0 * t], -1))
    np.testing.assert_allclose(np.asarray(mag(T, Q, W)), ref.evaluate(T, R, W, INERTIA), rtol=0, atol=1e-15)
    assert mag.time_dependent and not mag.depends_on_omega
    drag = jt.FunctionTorque(lambda t, q, omega: -0.1 * omega)
    np.testing.assert_array_equal(np.asarray(drag(T, Q, W)), -0.1 * W)
    assert drag.depends_on_omega


def test_torque_pytree_grad_and_vmap():
    top = jt.Gravity(1.5, [0.1, 0.2, 0.3], [0.0, 0.0, -9.81])
    leaves, treedef = jax.tree_util.tree_flatten(top)
    assert len(leaves) == 3
    # d tau / d mass = tau / mass (linear in the mass)
    g = jax.jacfwd(lambda m: jt.Gravity(m, top.center_of_mass, top.g)(0.0, Q[0], W[0]))(1.5)
    np.testing.assert_allclose(np.asarray(g), np.asarray(top(0.0, Q[0], W[0])) / 1.5, rtol=1e-15)
    batched = jax.vmap(lambda tq, q: tq.evaluate(0.0, q, W[0]))(
        jt.Gravity(jnp.ones(N), jnp.asarray(RNG.normal(size=(N, 3))), jnp.broadcast_to(top.g, (N, 3))), jnp.asarray(Q)
    )
    assert batched.shape == (N, 3)


def test_torque_errors():
    with pytest.raises(ep.UnsupportedModelError, match="no JAX twin: a Python function"):
        jt.from_torque(ep.torques.CallableTorque(lambda t, q, omega: -omega))
    with pytest.raises(ep.UnsupportedModelError, match="no JAX twin: a Python function"):
        jt.from_torque(lambda t, q, omega: -omega)
    with pytest.raises(ep.UnsupportedModelError, match="field is a NumPy function"):
        jt.from_torque(ep.torques.MagneticDipoleTorque([0, 0, 1.0], lambda t: [np.cos(t), 0.0, 0.0]))
    with pytest.raises(ep.UnsupportedModelError, match="UnrecordedTorque"):
        jt.from_torque(ep.torques.UnrecordedTorque("CallableTorque('damping')"))
    with pytest.raises(ep.InvalidInputError, match="torque must be an eulerpoisson.torques.Torque"):
        jt.from_torque(3.0)
    with pytest.raises(
        ep.InvalidInputError, match=r"Gravity: center_of_mass must have shape \(\.\.\., 3\), got \(2,\)"
    ):
        jt.Gravity(1.0, [0.0, 1.0])
    with pytest.raises(ep.InvalidInputError, match="GravityGradient needs the inertia"):
        jt.GravityGradient(0.1)(0.0, Q[0], W[0])
    with pytest.raises(ep.InvalidInputError, match="FunctionTorque: func must be a callable"):
        jt.FunctionTorque(1.0)
    with pytest.raises(ep.InvalidInputError, match="every term must be a JaxTorque"):
        jt.TorqueSum([jt.BodyTorque([0, 0, 1.0]), 2.0])


def test_quaternion_from_matrix_roundtrip():
    for q in np.concatenate([Q, np.eye(4)]):
        got = np.array(quaternion_from_matrix(matrix_from_unit_quaternion(q)))
        got *= np.sign(got @ q)
        np.testing.assert_allclose(got, q, rtol=0, atol=2e-16 * 8)


# ---------------------------------------------------------------------------
# the integrator
# ---------------------------------------------------------------------------
# The exact free flow compiles slowly (tens of seconds per configuration): the tests with it share
# one configuration per order (the same torque structure, shapes, n_steps and save_every), and the
# tests of the plumbing (jit, vmap, save_every, float32, errors) run with the stand-in flow.
STANDIN = functools.partial(rk4_free_flow, substeps=16)
N_STEPS = 8


def _torque(nu=0.7):
    """Gravity, gravity gradient (time dependent), constant body and space torques, a magnetic dipole."""
    return [
        ep.torques.Gravity(1.0, [0.02, 0.01, 0.1]),
        ep.torques.GravityGradient(nu),
        ep.torques.SpaceTorque([0.05, -0.02, 0.1]),
        ep.torques.BodyTorque([0.0, 0.03, 0.0]),
        ep.torques.MagneticDipoleTorque([0.1, 0.2, 0.3], [0.3, 0.0, -0.2]),
    ]


def _chain(order, torque, t_end, pieces, q0=Q0, w0=W0, inertia=I_TENSOR, **kw):
    """``pieces`` consecutive runs of N_STEPS steps to t_end (one compiled function for every step size)."""
    q, w = q0, w0
    for k in range(pieces):
        res = integrate(
            inertia, q, w, t_end * (k + 1) / pieces, N_STEPS, torque, order=order, t0=t_end * k / pieces,
            save_every=N_STEPS, **kw,
        )  # fmt: skip
        q, w = res.quaternion[..., -1, :], res.omega[..., -1, :]
    return np.asarray(q), np.asarray(w)


def _attitude_error(q, q_ref):
    """Rotation angle between two attitudes (rad)."""
    v = ep.attitude.quaternion_multiply(q_ref * np.array([1.0, -1.0, -1.0, -1.0]), q)
    return 2.0 * np.arctan2(np.linalg.norm(v[..., 1:], axis=-1), np.abs(v[..., 0]))


@pytest.mark.parametrize("order", [2, 4])
def test_measured_order_against_taylor(order):
    """Global errors at t = 1 under step halving (8, 16, 32 steps) against Taylor at tol 1e-15."""
    torque = _torque()
    ref = ep.solve(I_TENSOR, [0.0, 1.0], omega0=W0, attitude0=Q0, torque=torque, method="taylor", tol=1e-15)
    errs = []
    for pieces in (1, 2, 4):
        q, w = _chain(order, torque, 1.0, pieces)
        errs.append(
            max(
                np.max(np.abs(w - ref.omega[-1])) / np.linalg.norm(ref.omega[-1]),
                _attitude_error(q, ref.quaternion[-1]),
            )
        )
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(rates - order) < 0.2), (errs, rates)
    assert errs[-1] < (1e-4 if order == 2 else 1e-6)


@pytest.mark.parametrize("order", [2, 4])
def test_matches_package_exact_splitting(order):
    """The same scheme as method="symplectic", scheme="exact_splitting(4)": agreement to round-off."""
    scheme = "exact_splitting" if order == 2 else "exact_splitting4"
    torque = _torque(nu=0.2)
    q, w = _chain(order, torque, 2.0, 1)
    pk = ep.solve(
        I_TENSOR, [0.0, 2.0], omega0=W0, attitude0=Q0, torque=torque, method="symplectic", scheme=scheme, dt=0.25
    )
    assert pk.stats["steps"] == N_STEPS
    assert _attitude_error(q, pk.quaternion[-1]) < 1e-13
    np.testing.assert_allclose(w, pk.omega[-1], rtol=0, atol=1e-13 * np.max(np.abs(pk.omega)))


def test_free_body_is_exact():
    """Zero torques (the same compiled function): the exact motion, whatever the step."""
    zero = jt.TorqueSum(
        [
            jt.Gravity(0.0, [0.02, 0.01, 0.1]),
            jt.GravityGradient(0.0),
            jt.SpaceTorque(np.zeros(3)),
            jt.BodyTorque(np.zeros(3)),
            jt.MagneticDipoleTorque(np.zeros(3), [0.3, 0.0, -0.2]),
        ]
    )
    assert jax.tree_util.tree_structure(zero) == jax.tree_util.tree_structure(jt.from_torque(_torque()))
    q, w = _chain(4, zero, 3.0, 1)
    ref = ep.solve(I_TENSOR, [0.0, 3.0], omega0=W0, attitude0=Q0, method="exact")
    assert _attitude_error(q, ref.quaternion[-1]) < 1e-13
    np.testing.assert_allclose(w, ref.omega[-1], rtol=0, atol=1e-13)


def test_damping_omega_dependent_order():
    """A torque that depends on omega and t: RK4 kicks keep the orders (truth: the package's rk at tol 1e-13)."""

    def damping_np(t, q, omega):
        return -0.3 * omega + 0.1 * np.cos(t)[..., None] * np.array([1.0, 0.0, 0.0])

    def damping(t, q, omega):
        return -0.3 * omega + 0.1 * jnp.cos(t)[..., None] * jnp.array([1.0, 0.0, 0.0])

    drag = jt.FunctionTorque(damping)
    ref = ep.solve(I_TENSOR, [0.0, 1.0], omega0=W0, attitude0=Q0, torque=damping_np, method="rk", tol=1e-13)
    flow = functools.partial(rk4_free_flow, substeps=64)  # its error, (h/64)^4, is far below the splitting's
    for order in (2, 4):
        errs = [np.max(np.abs(_chain(order, drag, 1.0, p, _free_flow=flow)[1] - ref.omega[-1])) for p in (1, 2)]
        assert abs(np.log2(errs[0] / errs[1]) - order) < 0.2, (order, errs)


def test_jit_vmap_save_every_float32_batches():
    # Strang's composition (one free flow a step; Yoshida's has three, in every program below, which then compile
    # in half again the time): the plumbing does not depend on the order, which the tests above check
    torque = jt.from_torque(_torque())
    run = functools.partial(integrate, n_steps=12, torque=torque, order=2, _free_flow=STANDIN)
    full = run(I_TENSOR, Q0, W0, 1.2)
    assert full.t.shape == (13,) and full.quaternion.shape == (13, 4) and full.omega.shape == (13, 3)
    np.testing.assert_allclose(np.asarray(full.t), np.linspace(0.0, 1.2, 13), rtol=0, atol=1e-15)
    sub = run(I_TENSOR, Q0, W0, 1.2, save_every=4)
    np.testing.assert_allclose(np.asarray(sub.omega), np.asarray(full.omega[::4]), rtol=0, atol=1e-14)
    jitted = jax.jit(run)(I_TENSOR, Q0, W0, 1.2)
    np.testing.assert_allclose(np.asarray(jitted.omega), np.asarray(full.omega), rtol=0, atol=1e-14)
    # vmap over the initial rates, over the torque's parameters, and the batched call
    ws = np.stack([W0, 2 * W0, -W0])
    batched = run(I_TENSOR, Q0, ws, 1.2)
    assert batched.omega.shape == (3, 13, 3)
    mapped = jax.vmap(lambda w: run(I_TENSOR, Q0, w, 1.2).omega)(ws)
    np.testing.assert_allclose(np.asarray(mapped), np.asarray(batched.omega), rtol=0, atol=1e-14)
    for k in range(3):
        one = run(I_TENSOR, Q0, ws[k], 1.2)
        np.testing.assert_allclose(np.asarray(batched.omega[k]), np.asarray(one.omega), rtol=0, atol=1e-14)
    masses = jnp.array([0.5, 1.0, 2.0])
    by_mass = jax.vmap(
        lambda m: integrate(
            I_TENSOR, Q0, W0, 1.2, 12, jt.Gravity(m, [0.02, 0.01, 0.1]), order=2, _free_flow=STANDIN
        ).omega[-1]
    )(masses)
    tops = integrate(I_TENSOR, Q0, W0, 1.2, 12, jt.Gravity(masses, [0.02, 0.01, 0.1]), order=2, _free_flow=STANDIN)
    assert tops.omega.shape == (3, 13, 3)  # the torque's batch broadcasts with the state
    np.testing.assert_allclose(np.asarray(by_mass), np.asarray(tops.omega[:, -1]), rtol=0, atol=1e-14)
    single = run(I_TENSOR, Q0, W0, 1.2, dtype=jnp.float32)
    assert single.omega.dtype == jnp.float32 and single.quaternion.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(single.omega), np.asarray(full.omega), rtol=0, atol=2e-5)


def _grad_check(loss, args, eps=1e-6, rtol=1e-6):
    # one compiled program gives the gradient and the values of the central differences (the loss itself):
    # every argument a float64 array, so that no call differs from another by a weak type
    args = tuple(np.asarray(a, dtype=np.float64) for a in args)
    value_and_grad = jax.jit(jax.value_and_grad(loss, argnums=tuple(range(len(args)))))
    _, grads = value_and_grad(*args)

    def f(*a):
        return value_and_grad(*a)[0]

    for k, g in enumerate(grads):
        g = np.ravel(np.asarray(g))
        assert np.all(np.isfinite(g))
        base = np.ravel(np.asarray(args[k], dtype=float))
        for i in range(base.size):
            up, dn = base.copy(), base.copy()
            up[i] += eps
            dn[i] -= eps
            a_up, a_dn = list(args), list(args)
            a_up[k] = up.reshape(np.shape(args[k]))
            a_dn[k] = dn.reshape(np.shape(args[k]))
            fd = (float(f(*a_up)) - float(f(*a_dn))) / (2 * eps)
            assert abs(g[i] - fd) <= rtol * max(1.0, abs(fd)), (k, i, g[i], fd)


def test_grad_matches_central_differences():
    """d loss / d (omega0, mass, t_end, inertia tensor) through the splitting (the stand-in flow)."""

    def loss(w0, mass, t_end, inertia):
        top = jt.Gravity(mass, [0.02, 0.01, 0.1]) + jt.GravityGradient(0.5)
        res = integrate(inertia, Q0, w0, t_end, 6, top, order=4, _free_flow=STANDIN)
        return jnp.sum(res.omega[-1] ** 2) + res.quaternion[-1, 1]

    _grad_check(loss, (jnp.asarray(W0), 1.3, 0.8, jnp.asarray(I_TENSOR)))


@pytest.mark.slow
def test_grad_through_the_exact_flow():
    """End to end with the exact flow (a long compilation: reverse mode through the elliptic functions)."""

    def loss(w0, mass, t_end):
        res = integrate([1.0, 2.0, 2.5], Q0, w0, t_end, 4, jt.Gravity(mass, [0.02, 0.01, 0.1]), order=2)
        return jnp.sum(res.omega[-1] ** 2) + res.quaternion[-1, 1]

    _grad_check(loss, (jnp.asarray(W0), 1.3, 0.8))


def test_rk4_free_flow_and_composition():
    q, w = rk4_free_flow(np.array([1.0, 2.0, 2.5]), Q0, W0, 1.0, substeps=64)
    ref = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=W0, attitude0=Q0, method="rk", tol=1e-13)
    np.testing.assert_allclose(np.asarray(w), ref.omega[-1], rtol=0, atol=1e-8)
    assert _attitude_error(np.asarray(q), ref.quaternion[-1]) < 1e-8
    c, d = composition(4)
    assert abs(sum(c) - 1) < 1e-15 and abs(sum(d) - 1) < 1e-15 and d[1] < 0


def test_integrate_errors():
    with pytest.raises(ep.InvalidInputError, match="n_steps must be a Python int"):
        integrate(I_TENSOR, Q0, W0, 1.0, 2.5)
    with pytest.raises(ep.InvalidInputError, match="n_steps must be an int >= 1, got 0"):
        integrate(I_TENSOR, Q0, W0, 1.0, 0)
    with pytest.raises(ep.InvalidInputError, match=r"save_every \(3\) must divide n_steps \(10\)"):
        integrate(I_TENSOR, Q0, W0, 1.0, 10, save_every=3)
    with pytest.raises(ep.InvalidInputError, match="order must be 2 or 4, got 3"):
        integrate(I_TENSOR, Q0, W0, 1.0, 10, order=3)
    with pytest.raises(ep.InvalidInputError, match=r"inertia must have shape \(\.\.\., 3\) .* got \(2,\)"):
        integrate([1.0, 2.0], Q0, W0, 1.0, 10)
    with pytest.raises(ep.InvalidInputError, match=r"quaternion0 must have shape \(\.\.\., 4\), got \(3,\)"):
        integrate(I_TENSOR, W0, W0, 1.0, 10)
    with pytest.raises(ep.InvalidInputError, match=r"omega0 must have shape \(\.\.\., 3\), got \(4,\)"):
        integrate(I_TENSOR, Q0, Q0, 1.0, 10)
    with pytest.raises(ep.UnsupportedModelError, match="no JAX twin"):
        integrate(I_TENSOR, Q0, W0, 1.0, 10, lambda t, q, omega: -omega)
    with pytest.raises(ep.InvalidInputError, match="omega0 must be a real array"):
        integrate(I_TENSOR, Q0, "fast", 1.0, 10)


def test_precision_error_when_traced_without_x64():
    with jax.enable_x64(False):
        with pytest.raises(ep.errors.PrecisionError, match="integrate computes in float64 by default"):
            jax.jit(lambda w: integrate(I_TENSOR, Q0, w, 1.0, 4).omega)(jnp.asarray(W0, dtype=jnp.float32))
