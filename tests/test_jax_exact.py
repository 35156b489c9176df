"""The exact free motion in JAX (issue 24) against the NumPy closed form.

Values: ``eulerpoisson.jax.exact_motion`` against ``ep.solve(..., method="exact")`` and
``motion.exact_motion`` (NumPy path) on the reference cases and on random bodies of every kind
(near and on the separatrix, symmetric tops, spheres, equilibria, full tensors, negative and long
times). Derivatives (forward and reverse) against central differences of the NumPy path and the
equations of motion. Shapes are kept fixed so that a few compilations serve every test.
"""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")

import jax.numpy as jnp  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import _jax_programs as programs  # noqa: E402  (tests/: the compiled programs the JAX test files share)
import eulerpoisson as ep  # noqa: E402
from eulerpoisson.attitude.core import quaternion_from_rotation_matrix  # noqa: E402
from eulerpoisson.errors import InvalidInertiaError, InvalidInputError, PrecisionError  # noqa: E402
from eulerpoisson.jax.exact import exact_motion  # noqa: E402
from eulerpoisson.oracle import reference_cases  # noqa: E402
from eulerpoisson.solvers.exact import motion  # noqa: E402

EPS = np.finfo(float).eps
T = 201  # every value test uses inertia (3,) or (3, 3) and t (T,): one compilation each


def _jit(fn):
    return jax.jit(fn)


_F = _jit(exact_motion)


def _run(I, q0, w0, t):
    with jax.enable_x64(True):
        q, w = _F(
            jnp.asarray(I, jnp.float64), jnp.asarray(q0, jnp.float64), jnp.asarray(w0, jnp.float64), jnp.asarray(t)
        )
        return np.asarray(q), np.asarray(w)


def _qmul(p, q):
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    return np.concatenate([pw * qw - np.sum(pv * qv, -1, keepdims=True), pw * qv + qw * pv + np.cross(pv, qv)], -1)


def _reference(I, q0, w0, t):
    """The NumPy closed form, composed as ``ep.solve(..., method="exact")`` does.

    ``motion.exact_motion`` in the principal frame of ``ep.RigidBody`` (``R = R0 P R_P P^T``); not
    ``ep.solve`` itself, whose output sequence is made continuous from sample to sample (its
    quaternion signs at sparse times are a property of the sampling, not of ``t``).
    """
    I, q0, w0, t = (np.asarray(x, float) for x in (I, q0, w0, t))
    q0 = q0 / np.linalg.norm(q0)
    if I.shape == (3,):
        Mp, q_rel = motion.exact_motion(I, I * w0, t, compiled=False)
        return _qmul(q0, q_rel), Mp / I
    body = ep.RigidBody(I)
    Ip, P = body.principal_moments, body.principal_axes
    Mp, q_rel = motion.exact_motion(Ip, P.T @ (I @ w0), t, compiled=False)
    qP = quaternion_from_rotation_matrix(P)
    q_rel = _qmul(_qmul(qP, q_rel), qP * np.array([1.0, -1.0, -1.0, -1.0]))
    return _qmul(q0, q_rel), (Mp / Ip) @ P.T


def _angle(q1, q2):
    """Rotation angle between attitudes (sign-insensitive) and the sign of their dot product."""
    d = np.sum(q1 * q2, -1)
    s = np.where(d < 0, -1.0, 1.0)[..., None]
    return 2 * np.arcsin(np.clip(np.linalg.norm(q1 - s * q2, axis=-1) / 2, 0, 1)), d


def _assert_agree(I, q0, w0, t, what=""):
    q, w = _run(I, q0, w0, t)
    qr, wr = _reference(I, q0, w0, t)
    ang, dot = _angle(q, qr)
    speed = np.max(np.abs(wr))  # (no norm: it underflows for tiny rates)
    # 1e-14 rad, plus the conditioning of the phase (a few ulp times |Omega| t) at long times
    tol = 1e-14 + 8 * EPS * speed * np.abs(t)
    assert np.all(ang <= tol), f"{what}: attitude error {np.max(ang - tol + 1e-14):.3e} rad"
    assert np.all(dot > 0), f"{what}: the quaternion sign differs"
    werr = np.max(np.abs(w - wr), axis=-1) / max(speed, 1e-300)
    assert np.all(werr <= 1e-14 + 8 * EPS * speed * np.abs(t)), f"{what}: omega error {np.max(werr):.3e}"


# ---------------------------------------------------------------------------
# values
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(reference_cases()))
def test_reference_cases_agree_with_the_numpy_closed_form(name):
    case = reference_cases()[name]
    t = np.linspace(0.0, case.t_end, T)
    _assert_agree(case.inertia_array, case.quaternion0, case.omega0, t, name)


def _times(scale):
    return np.concatenate([[0.0, 1e-9, -0.3], np.linspace(-20.0, 60.0, T - 5), [-1e3, 1e4]]) * scale


RACKET = np.array([3.0, 5.0, 8.0])


def _sep_omega(rel, side):
    """omega0 of the racket at 1 - k^2 ~ rel from the separatrix (side -1: about axis 1, +1: axis 3)."""
    M1 = 0.3 * RACKET[0]
    M3 = np.sqrt(M1**2 * (RACKET[1] - RACKET[0]) / RACKET[0] * RACKET[2] / (RACKET[2] - RACKET[1]))
    M3 = M3 * (1.0 + side * rel) if rel else M3
    return np.array([M1 / RACKET[0], 0.2, M3 / RACKET[2]])


SPECIAL = [
    pytest.param(RACKET, _sep_omega(1e-6, -1), id="separatrix-1e-6-A"),
    pytest.param(RACKET, _sep_omega(1e-6, 1), id="separatrix-1e-6-B"),
    pytest.param(RACKET, _sep_omega(1e-12, -1), id="separatrix-1e-12-A"),
    pytest.param(RACKET, _sep_omega(1e-12, 1), id="separatrix-1e-12-B"),
    pytest.param(RACKET, _sep_omega(0.0, 0), id="separatrix-exact"),
    pytest.param(RACKET, np.array([0.0, 0.4, 0.0]), id="middle-axis"),
    pytest.param(RACKET, np.array([0.0, 0.0, -0.4]), id="axis-3"),
    pytest.param(RACKET, np.array([0.7, 0.0, 0.0]), id="axis-1"),
    pytest.param(RACKET, np.zeros(3), id="at-rest"),
    pytest.param(np.array([2.0, 2.0, 3.0]), np.array([0.3, -0.5, 0.8]), id="symmetric-I1=I2"),
    pytest.param(np.array([2.0, 3.0, 3.0]), np.array([0.3, -0.5, 0.8]), id="symmetric-I2=I3"),
    pytest.param(np.array([2.0, 3.0, 2.0]), np.array([0.3, -0.5, 0.8]), id="symmetric-unsorted"),
    pytest.param(np.array([2.0, 2.0, 2.0]), np.array([0.3, -0.5, 0.8]), id="sphere"),
    pytest.param(np.array([8.0, 3.0, 5.0]), np.array([0.1, 0.3, -0.2]), id="unsorted"),
    pytest.param(np.array([1e-3, 2e-3, 2.5e-3]), np.array([3e4, -1e4, 2e4]), id="scaled"),
]


@pytest.mark.parametrize(("inertia", "omega0"), SPECIAL)
def test_special_bodies_agree(inertia, omega0):
    q0 = np.array([0.9, 0.1, -0.3, 0.2])
    _assert_agree(inertia, q0, omega0, _times(1.0), "special")


def _rotation(a, b, c):
    q = np.array(
        [np.cos(a), np.sin(a) * np.cos(b), np.sin(a) * np.sin(b) * np.cos(c), np.sin(a) * np.sin(b) * np.sin(c)]
    )
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(1.0, 2.0), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
    st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
    st.sampled_from(["moments", "tensor", "symmetric-tensor"]),
)
def test_random_bodies_agree(moments, omega0, angles, kind):
    I = np.array(moments)
    w0 = np.array(omega0)
    if kind == "moments":
        inertia = I
    else:
        if kind == "symmetric-tensor":
            I[1] = I[0]
        R = _rotation(*angles)
        inertia = R @ np.diag(I) @ R.T
        inertia = 0.5 * (inertia + inertia.T)
    _assert_agree(inertia, [1.0, 0.2, -0.1, 0.3], w0, _times(1.0), kind)


def test_vmap_jit_and_broadcasting_give_the_same_values():
    rng = np.random.default_rng(5)
    I = rng.uniform(1.0, 2.0, (4, 3))
    I[1] = [1.0, 1.0, 1.5]
    w0 = rng.normal(size=(4, 3))
    w0[2] = [0.0, 0.7, 0.0]
    q0 = rng.normal(size=(4, 4))
    t = np.linspace(-5.0, 50.0, 6)
    with jax.enable_x64(True):
        Ij, wj, qj, tj = (jnp.asarray(x) for x in (I, w0, q0, t))
        qb, wb = jax.jit(exact_motion)(Ij[:, None, :], qj[:, None, :], wj[:, None, :], tj)  # (4, 6, ...)
        qv, wv = jax.vmap(exact_motion, in_axes=(0, 0, 0, None))(Ij, qj, wj, tj)
        # one time per body, elementwise broadcasting
        qe, we = jax.jit(exact_motion)(Ij, qj, wj, tj[:4])
    assert qb.shape == (4, 6, 4) and wb.shape == (4, 6, 3)
    # each is its own compiled program (XLA fuses and vectorizes each its own way): equal to
    # round-off, a few ulp times the phase |Omega| t
    atol = 1e-13
    np.testing.assert_allclose(np.asarray(qv), np.asarray(qb), rtol=0, atol=atol)
    np.testing.assert_allclose(np.asarray(wv), np.asarray(wb), rtol=0, atol=atol * np.max(np.abs(wb)))
    np.testing.assert_allclose(np.asarray(qe), np.asarray(qb)[np.arange(4), np.arange(4)], rtol=0, atol=atol)
    for k in range(4):
        q, w = _run(I[k], q0[k], w0[k], np.concatenate([t, np.zeros(T - t.size)]))
        np.testing.assert_allclose(q[: t.size], np.asarray(qb)[k], rtol=0, atol=atol)


# ---------------------------------------------------------------------------
# derivatives
# ---------------------------------------------------------------------------
def _central(fun, x, dx, h):
    qp, wp = fun(x + h * dx)
    qm, wm = fun(x - h * dx)
    return (qp - qm) / (2 * h), (wp - wm) / (2 * h)


def _jvp_all(I, q0, w0, t, dI, dq0, dw0, dt):
    """``jax.jvp`` of ``exact_motion``: the session's one forward program (tests/_jax_programs.py)."""
    return programs.jvp(I, q0, w0, t, dI, dq0, dw0, dt)


DERIV_BODIES = [
    pytest.param(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0.3, -0.4]), id="generic"),
    pytest.param(RACKET, _sep_omega(1e-6, -1), id="separatrix-1e-6-A"),
    pytest.param(RACKET, _sep_omega(1e-6, 1), id="separatrix-1e-6-B"),
    pytest.param(np.array([2.0, 2.0, 3.0]), np.array([0.3, -0.5, 0.8]), id="symmetric-I1=I2"),
    pytest.param(np.array([2.0, 3.0, 3.0]), np.array([0.3, -0.5, 0.8]), id="symmetric-I2=I3"),
    pytest.param(
        np.array([[2.0, 0.1, 0.0], [0.1, 1.5, -0.2], [0.0, -0.2, 1.2]]), np.array([0.7, -1.1, 2.0]), id="tensor"
    ),
]


@pytest.mark.slow
@pytest.mark.parametrize(("inertia", "omega0"), DERIV_BODIES)
def test_forward_derivatives_match_central_differences(inertia, omega0):
    """jvp along every input coordinate against central differences (relative step 1e-6) of NumPy."""
    q0 = np.array([0.9, 0.1, -0.3, 0.2])
    t = np.array([0.5, 3.0, 7.0])
    rng = np.random.default_rng(3)
    dirs = [("I", np.eye(3)[k]) for k in range(3)] if inertia.shape == (3,) else []
    if inertia.shape == (3, 3):
        for i, j in ((0, 0), (1, 1), (0, 1), (1, 2)):
            e = np.zeros((3, 3))
            e[i, j] = e[j, i] = 1.0
            dirs.append(("I", e))
    dirs += [("w", np.eye(3)[k]) for k in range(3)] + [("q", rng.normal(size=4))]
    for which, d in dirs:
        zeros = [np.zeros_like(inertia), np.zeros(4), np.zeros(3)]
        k = {"I": 0, "q": 1, "w": 2}[which]
        zeros[k] = d
        _, _, dq, dw = _jvp_all(inertia, q0, omega0, t, *zeros, np.zeros_like(t))
        x = (inertia, q0, omega0)[k]
        h = 1e-6 * max(np.max(np.abs(x)), 1e-3)

        def fun(xx, k=k):
            a = [inertia, q0, omega0]
            a[k] = xx
            return _reference(a[0], a[1], a[2], t)

        cq, cw = _central(fun, x, d, h)
        assert np.all(np.isfinite(dq)) and np.all(np.isfinite(dw))
        sq = max(np.max(np.abs(cq)), 1e-3)
        sw = max(np.max(np.abs(cw)), 1e-3)
        assert np.max(np.abs(dq - cq)) <= 1e-6 * sq, (which, d, dq, cq)
        assert np.max(np.abs(dw - cw)) <= 1e-6 * sw, (which, d, dw, cw)


@pytest.mark.slow
def test_reverse_derivatives_agree_with_forward_and_time_derivative_is_the_equations_of_motion():
    I = np.array([[2.0, 0.1, 0.0], [0.1, 1.5, -0.2], [0.0, -0.2, 1.2]])
    q0 = np.array([0.9, 0.1, -0.3, 0.2])
    w0 = np.array([0.7, -1.1, 2.0])
    t = np.array([0.0, 0.5, 4.0])
    # jax.jacrev: one vjp (reverse mode) per output entry, of the session's one reverse program
    jr = programs.jacrev(I, q0, w0, t)  # [output][input]
    rng = np.random.default_rng(11)
    dI = rng.normal(size=(3, 3))
    dI = dI + dI.T
    tans = (dI, rng.normal(size=4), rng.normal(size=3), rng.normal(size=3))
    q, w, dq, dw = _jvp_all(I, q0, w0, t, *tans)
    for out, fwd in ((0, dq), (1, dw)):
        rev = sum(np.tensordot(jr[out][k], tans[k], axes=tans[k].ndim) for k in range(4))
        assert np.all(np.isfinite(rev))
        np.testing.assert_allclose(rev, fwd, rtol=0, atol=1e-12 * max(np.max(np.abs(fwd)), 1.0))
    # d/dt: dq/dt = q (x) (0, Omega)/2 and I dOmega/dt = (I Omega) x Omega
    z = (np.zeros((3, 3)), np.zeros(4), np.zeros(3))
    _, _, dq_dt, dw_dt = _jvp_all(I, q0, w0, t, *z, np.ones(3))
    np.testing.assert_allclose(dq_dt, 0.5 * _qmul(q, np.concatenate([np.zeros((3, 1)), w], -1)), rtol=0, atol=1e-12)
    np.testing.assert_allclose(dw_dt, np.linalg.solve(I, np.cross(w @ I.T, w).T).T, rtol=0, atol=1e-12)


@pytest.mark.slow
def test_derivatives_are_finite_where_the_closed_form_is_singular():
    """Reverse mode at the singular states of the closed form, every body a diagonal tensor: one reverse program.

    The principal axes of a diagonal tensor are the body axes (``eigh`` gives exactly the diagonal and the
    identity), so the closed form runs at exactly the state it has for those moments (the same values, bit for
    bit) and the cotangent of the moments is the diagonal of the tensor's: a derivative of the closed form that is
    not finite shows here as it would with the moments given. (The reverse program of a (3,) inertia, another
    ~20 s of CPU to compile, is checked against central differences by test_jax_splitting.py's exact flow.)
    """
    bodies = [
        (np.diag(RACKET), _sep_omega(0.0, 0)),  # on the separatrix
        (np.diag(RACKET), np.array([0.0, 0.4, 0.0])),  # the unstable middle axis
        (np.diag(RACKET), np.zeros(3)),  # at rest
        (np.diag([2.0, 2.0, 2.0]), np.array([0.3, -0.5, 0.8])),  # a sphere
        (np.diag([1.0, 1.0, 1.5]), np.array([0.3, 0.2, 1.0])),  # a repeated eigenvalue
        (np.diag([2.0, 2.0, 2.0]), np.array([0.3, 0.2, 1.0])),
    ]
    t = np.array([0.0, 1.0, 5.0])
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    for I, w0 in bodies:
        # the gradient of sum(q) + sum(w): the vjp of ones (the session's one reverse program)
        g = programs.vjp(I, q0, w0, t, np.ones((t.size, 4)), np.ones((t.size, 3)))
        for leaf in g:
            assert np.all(np.isfinite(np.asarray(leaf))), (I, w0)


# ---------------------------------------------------------------------------
# float32, errors
# ---------------------------------------------------------------------------
def test_float32_runs_and_is_accurate_to_its_precision():
    f32 = jax.jit(lambda *a: exact_motion(*a, dtype=jnp.float32))
    for name, case in reference_cases().items():
        t = np.concatenate([[10.0, 100.0], np.zeros(T - 2)])
        q, _ = f32(*(jnp.asarray(x, jnp.float32) for x in (case.inertia_array, case.quaternion0, case.omega0, t)))
        assert q.dtype == jnp.float32
        q64, _ = _run(case.inertia_array, case.quaternion0, case.omega0, t)
        ang, _ = _angle(np.asarray(q, float), q64)
        assert ang[0] < 1e-3 and ang[1] < 1e-2, (name, ang[:2])


def test_errors_name_the_argument():
    good = ([1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0], [0.1, 0.2, 0.3], 1.0)
    cases = [
        ((([1.0, 2.0],) + good[1:]), InvalidInertiaError, "inertia must have shape"),
        ((([1.0, -2.0, 3.0],) + good[1:]), InvalidInertiaError, "positive definite"),
        ((([1.0, np.nan, 3.0],) + good[1:]), InvalidInertiaError, "inertia must be finite"),
        (((np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]]),) + good[1:]), InvalidInertiaError, "not symmetric"),
        (((np.diag([1.0, -1.0, 2.0]),) + good[1:]), InvalidInertiaError, "positive definite"),
        ((good[0], [1.0, 0.0, 0.0], good[2], 1.0), InvalidInputError, "quaternion0 must have shape"),
        ((good[0], [0.0, 0.0, 0.0, 0.0], good[2], 1.0), InvalidInputError, "quaternion0 must be a non-zero"),
        ((good[0], good[1], [0.1, 0.2], 1.0), InvalidInputError, "omega0 must have shape"),
        ((good[0], good[1], [0.1, np.inf, 0.2], 1.0), InvalidInputError, "omega0 must be finite"),
        ((good[:3] + (np.array([0.0, np.nan]),)), InvalidInputError, "t must be finite"),
        ((good[0], good[1], np.zeros((2, 3)), np.zeros(3)), InvalidInputError, "do not broadcast"),
        ((good[:3] + ("abc",)), InvalidInputError, "t must be a real array"),
    ]
    for args, exc, match in cases:
        with pytest.raises(exc, match=match):
            exact_motion(*args)
    # under tracing only shapes are checked; float64 needs 64-bit floats when traced
    with pytest.raises(InvalidInputError, match="omega0 must have shape"):
        jax.jit(lambda w: exact_motion(good[0], good[1], w, 1.0, dtype=jnp.float32))(jnp.zeros(2, jnp.float32))
    if not jax.config.jax_enable_x64:
        with pytest.raises(PrecisionError):
            jax.jit(lambda w: exact_motion(good[0], good[1], w, 1.0))(jnp.zeros(3, jnp.float32))
