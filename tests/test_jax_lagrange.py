"""The Lagrange top in JAX (issue 24) against the NumPy closed form.

Truths: :func:`eulerpoisson.solvers.exact.lagrange.lagrange_top_motion` (values to 1e-13: the
attitude as a rotation angle, the rates relative to their size) and its central differences
(``jax.jacfwd`` with respect to ``omega0``, ``q0`` (body-frame rotations), ``A``, ``C`` and ``t``).
"""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")

import jax.numpy as jnp  # noqa: E402

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.jax.lagrange import lagrange_top_motion  # noqa: E402
from eulerpoisson.solvers.exact.lagrange import lagrange_top_motion as lagrange_np  # noqa: E402


@pytest.fixture(autouse=True)
def _x64():
    with jax.enable_x64(True):
        yield


def _unit(q):
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q)


G = [0.0, 0.0, -9.81]
#: name: (A, C, mass, ell, g, q0, omega0)
TOPS = {
    "sleeping": (1.0, 0.5, 1.0, 0.3, G, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 20.0]),
    "fast": (1.0, 1.5, 0.5, 0.1, G, _unit([0.9, 0.1, 0.1, 0.0]), [1.0, -2.0, 80.0]),
    "slow": (1.2, 0.4, 1.0, 0.5, [0.1, 0.2, -9.81], _unit([0.7, 0.6, 0.2, 0.3]), [0.2, 0.1, 0.3]),
    "nutating": (1.0, 0.6, 2.0, 0.2, G, _unit([0.9, 0.3, 0.2, 0.1]), [0.5, -0.3, 3.0]),
    "pendulum": (1.0, 0.3, 1.0, -0.4, G, _unit([0.8, 0.5, 0.1, 0.3]), [0.0, 0.4, 0.0]),
    "looping": (1.0, 0.8, 1.0, 0.25, [0.0, 9.81, 0.0], _unit([0.6, 0.2, 0.7, 0.1]), [2.0, 1.5, 1.0]),
    "free": (1.0, 0.5, 0.0, 0.3, G, _unit([0.8, 0.5, 0.1, 0.3]), [0.3, 0.4, 2.0]),
}
T = np.array([-3.0, 0.0, 0.37, 1.0, 2.5, 7.0])


def _stacked(names):
    cols = list(zip(*(TOPS[n] for n in names)))
    return [np.asarray(c, dtype=float) for c in cols]


def _angle(qa, qb):
    """Rotation angle (rad) between attitudes (..., 4)."""
    w = np.abs(np.sum(qa * qb, axis=-1))
    v = np.linalg.norm(
        qa[..., :1] * qb[..., 1:] - qb[..., :1] * qa[..., 1:] - np.cross(qa[..., 1:], qb[..., 1:]), axis=-1
    )
    return 2.0 * np.arctan2(v, w)


def test_agrees_with_numpy_on_several_tops():
    names = list(TOPS)
    args = _stacked(names)
    q_np, w_np = lagrange_np(*args, T)
    q_jx, w_jx = lagrange_top_motion(*args, T)
    assert q_jx.shape == (len(names), T.size, 4) and w_jx.shape == (len(names), T.size, 3)
    assert q_jx.dtype == jnp.float64
    ang = _angle(np.asarray(q_jx), q_np)
    rate = np.max(np.abs(np.asarray(w_jx) - w_np), axis=-1) / np.max(np.abs(w_np), axis=(-2, -1))[:, None]
    # 1e-13 rad, and a few ulp of the accumulated rotation angle |omega0| |t| (80 rad/s over 7 s)
    tol = 1e-13 * (1.0 + np.linalg.norm(args[6], axis=-1)[:, None] * np.abs(T) / 100.0)
    assert np.all(ang <= tol), dict(zip(names, (ang / tol).max(-1)))
    assert np.all(rate <= 1e-13), dict(zip(names, rate.max(-1)))
    # at t = 0 the initial state itself
    np.testing.assert_array_equal(np.asarray(q_jx)[:, 1], args[5])
    np.testing.assert_array_equal(np.asarray(w_jx)[:, 1], args[6])


DERIV_TOPS = ["fast", "slow", "nutating", "pendulum", "looping"]


def _rot(q, eps):
    """q (x) exp(eps / 2): a body-frame rotation by the small vector eps."""
    a = np.linalg.norm(eps)
    r = np.concatenate([[np.cos(a / 2)], np.sinc(a / (2 * np.pi)) * 0.5 * eps])
    return ep.attitude.quaternion_multiply(q, r)


def _rot_jax(q, eps):
    r = jnp.concatenate([jnp.ones(1), 0.5 * eps])  # first order in eps (what jacfwd at 0 sees)
    w = q[0] * r[0] - jnp.dot(q[1:], r[1:])
    v = q[0] * r[1:] + r[0] * q[1:] + jnp.cross(q[1:], r[1:])
    return jnp.concatenate([w[None], v])


@pytest.mark.slow
def test_jacfwd_vmap_match_numpy_central_differences():
    """One compilation of the derivatives (about a minute on one core: the special functions' JVP)."""
    args = _stacked(DERIV_TOPS)
    A, C, mass, ell, g, q0, w0 = args
    t = T[2:]  # t != 0

    def single(w, eps, a, c, tt, mass, ell, g, q):
        out = lagrange_top_motion(a, c, mass, ell, g, _rot_jax(q, eps), w, tt)
        return out, out

    jac = jax.jit(
        jax.vmap(jax.jacfwd(single, argnums=(0, 1, 2, 3, 4), has_aux=True), in_axes=(0, None, 0, 0, None, 0, 0, 0, 0))
    )
    (jac_q, jac_w), (qv, wv) = jac(w0, jnp.zeros(3), A, C, t, mass, ell, g, q0)
    jw, je, jA, jC, jt = ((jq, jw_) for jq, jw_ in zip(jac_q, jac_w))
    # vmap of the one-top function = the batched call (of every top at every time of T: the program that
    # test_agrees_with_numpy_on_several_tops compiles, not one more; these tops at these times cut from it)
    rows = [list(TOPS).index(name) for name in DERIV_TOPS]
    q_all, w_all = lagrange_top_motion(*_stacked(list(TOPS)), T)
    q_b, w_b = q_all[rows, 2:], w_all[rows, 2:]
    np.testing.assert_allclose(np.asarray(qv), np.asarray(q_b), rtol=0, atol=1e-13)
    np.testing.assert_allclose(np.asarray(wv), np.asarray(w_b), rtol=0, atol=1e-14 * np.max(np.abs(np.asarray(w_b))))

    h = 1e-6

    def numpy_fd(i, make):
        up = lagrange_np(*make(+h), t)
        dn = lagrange_np(*make(-h), t)
        return (up[0] - dn[0]) / (2 * h), (up[1] - dn[1]) / (2 * h)

    for i, name in enumerate(DERIV_TOPS):
        base = [A[i], C[i], mass[i], ell[i], g[i], q0[i], w0[i]]
        scale_w = np.max(np.abs(np.asarray(w_b[i])))

        def check(jq, jw_, fd, what, k, name=name, scale_w=scale_w):
            tol_q = 2e-6 * max(1.0, np.max(np.abs(fd[0])))
            tol_w = 2e-6 * max(scale_w, np.max(np.abs(fd[1])))
            assert np.max(np.abs(np.asarray(jq) - fd[0])) <= tol_q, (name, what, k, np.asarray(jq), fd[0])
            assert np.max(np.abs(np.asarray(jw_) - fd[1])) <= tol_w, (name, what, k)

        for k in range(3):
            e = np.eye(3)[k]

            def mk_w(s, e=e, base=base):
                b = list(base)
                b[6] = base[6] + s * e
                return b

            def mk_q(s, e=e, base=base):
                b = list(base)
                b[5] = _rot(base[5], s * e)
                return b

            check(jw[0][i][..., k], jw[1][i][..., k], numpy_fd(i, mk_w), "omega0", k)
            check(je[0][i][..., k], je[1][i][..., k], numpy_fd(i, mk_q), "q0", k)
        for what, jj, idx in (("A", jA, 0), ("C", jC, 1)):

            def mk(s, idx=idx, base=base):
                b = list(base)
                b[idx] = base[idx] + s
                return b

            check(jj[0][i], jj[1][i], numpy_fd(i, mk), what, 0)
        # d/dt: the diagonal of the Jacobian against central differences in time
        up = lagrange_np(*base, t + h)
        dn = lagrange_np(*base, t - h)
        diag_q = np.stack([np.asarray(jt[0][i])[j, :, j] for j in range(t.size)])
        diag_w = np.stack([np.asarray(jt[1][i])[j, :, j] for j in range(t.size)])
        check(diag_q, diag_w, ((up[0] - dn[0]) / (2 * h), (up[1] - dn[1]) / (2 * h)), "t", 0)
        for arr in (jw, je, jA, jC):
            assert np.all(np.isfinite(np.asarray(arr[0][i]))) and np.all(np.isfinite(np.asarray(arr[1][i])))


def test_errors():
    good = TOPS["slow"]
    with pytest.raises(ep.InvalidInputError, match="C must satisfy C <= 2 A"):
        lagrange_top_motion(1.0, 2.5, *good[2:], T)
    with pytest.raises(ep.InvalidInputError, match="A must be > 0"):
        lagrange_top_motion(-1.0, 0.5, *good[2:], T)
    with pytest.raises(ep.InvalidInputError, match="mass must be >= 0"):
        lagrange_top_motion(1.0, 0.5, -1.0, *good[3:], T)
    with pytest.raises(ep.InvalidInputError, match="q0 must be a unit quaternion"):
        lagrange_top_motion(*good[:5], [1.0, 0.1, 0.0, 0.0], good[6], T)
    with pytest.raises(ep.InvalidInputError, match=r"q0 must have shape \(\.\.\., 4\), got \(3,\)"):
        lagrange_top_motion(*good[:5], [1.0, 0.0, 0.0], good[6], T)
    with pytest.raises(ep.InvalidInputError, match=r"t must be one-dimensional \(T,\), got shape \(\)"):
        lagrange_top_motion(*good, 1.0)
    with pytest.raises(ep.InvalidInputError, match="do not broadcast"):
        lagrange_top_motion([1.0, 1.0], [0.5, 0.5, 0.5], *good[2:], T)
    with pytest.raises(ep.InvalidInputError, match="omega0 must be finite"):
        lagrange_top_motion(*good[:6], [np.nan, 0.0, 0.0], T)
    with jax.enable_x64(False):
        with pytest.raises(ep.errors.PrecisionError, match="lagrange_top_motion computes in float64 by default"):
            jax.jit(lambda w: lagrange_top_motion(*good[:6], w, T)[1])(jnp.zeros(3, jnp.float32))
