r"""The Lagrange top (heavy symmetric top) in closed form, in JAX: jit-compiled, vectorized, differentiable.

A transcription of the NumPy reference :mod:`eulerpoisson.solvers.exact.lagrange` (its module
docstring derives every formula: the cubic :math:`p(u)` of the nutation and its roots, the
initial elliptic phase, the angle integrals of the third kind with period reduction and the shift
that resolves a near passage through the vertical, the least-squares initial phases, the exact
power-of-two rescaling, the special regimes) into ``jax.numpy``, with

* no Python control flow on values: the free symmetric top (``P = 0``), the steady motions (a
  double root: sleeping top, equilibria, steady precession) and the nutating top are all computed
  and selected by ``jnp.where``; the branch that is not selected gets safe arguments (a valid
  stand-in top, guarded denominators and square roots), so that no NaN or infinity reaches a
  derivative;
* the roots of the cubic by a safeguarded Newton-bisection of a fixed number of steps
  (``lax.fori_loop``, no ``while_loop``), followed by one Newton step that carries the derivative
  (the implicit-function derivative :math:`-\partial_pf/\partial_xf` of the root, the value
  unchanged);
* the Jacobi functions, :math:`K` and Carlson's :math:`R_F`, :math:`R_J` of
  :mod:`eulerpoisson.jax.elliptic`.

The public function is :func:`lagrange_top_motion`.

References
----------
.. [1] E. T. Whittaker, *A Treatise on the Analytical Dynamics of Particles and Rigid Bodies*,
   4th ed., Cambridge (1937), sections 71-72.
.. [2] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., section 35.
.. [3] B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer.
   Algorithms 10 (1995) 13-26; DLMF 19.25.14, 19.7.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import InvalidInputError
from ..solvers.exact.lagrange import check_top_ranges
from .doubledouble import safe_sqrt, straight
from .elliptic import ellipk_dd, jacobi_params, rf, rj, sncndn_dd
from .precision import as_float, float64_by_default
from .quaternion import qconj as _conj
from .quaternion import qmul as _qmul

__all__ = ["lagrange_top_motion"]

_UNIT_TOL = 1e-8
#: Newton-bisection steps of a root (the NumPy reference stops when the bracket stops shrinking,
#: after at most 200)
_BRACKET_ITERS = 200


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def _safe_div(a, b):
    """``a / b`` where ``b != 0``, else 0 (and a finite derivative)."""
    ok = b != 0.0
    return jnp.where(ok, a / jnp.where(ok, b, 1.0), 0.0)


def _safe_norm(v):
    s = jnp.sum(v * v, axis=-1)
    pos = s > 0.0
    return jnp.where(pos, jnp.sqrt(jnp.where(pos, s, 1.0)), 0.0)


def _frame_quaternion(a):
    """Unit quaternion ``q_f`` with ``R(q_f) a = e_z`` for unit vectors ``a`` (..., 3)."""
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    up = az >= 0.0
    by = jnp.where(up, ay, -ay)
    bz = jnp.where(up, az, -az)
    h = jnp.stack([1.0 + bz, by, -ax, jnp.zeros_like(ax)], axis=-1)
    h = h / jnp.sqrt(jnp.sum(h * h, axis=-1, keepdims=True))  # 1 + bz >= 1
    one, zero = jnp.ones_like(ax), jnp.zeros_like(ax)
    flip = jnp.where(up[..., None], jnp.stack([one, zero, zero, zero], -1), jnp.stack([zero, one, zero, zero], -1))
    return _qmul(h, flip)


# ---------------------------------------------------------------------------
# cubic roots
# ---------------------------------------------------------------------------
def _coeffs(uc, ec, rc, muc, A, P, M3):
    r"""Taylor coefficients of :math:`p(u_c + h)` (see the NumPy reference)."""
    a0 = 2.0 * A * ec * rc - muc * muc
    a1 = 2.0 * A * (-2.0 * uc * ec - P * rc) + 2.0 * muc * M3
    a2 = 2.0 * A * (2.0 * P * uc - ec) - M3 * M3
    a3 = 2.0 * A * P
    return a0, a1, a2, a3


def _poly(a, h):
    a0, a1, a2, a3 = a
    return a0 + h * (a1 + h * (a2 + h * a3)), a1 + h * (2.0 * a2 + h * 3.0 * a3)


def _bracket_roots(a, lo, hi, sgn):
    """Roots of cubics ``sum a_k h^k`` in ``[lo, hi]`` (all stacked on a leading axis; ``sgn`` +1 where the
    cubic is <= 0 left of its root, -1 for the opposite): safeguarded Newton-bisection of a fixed
    number of steps, each root frozen when the reference stops (its step no longer changes it or
    the bracket stops shrinking); then one Newton step that carries the derivative (the value kept)."""
    a_ng = tuple(jax.lax.stop_gradient(x) for x in a)
    lo = jax.lax.stop_gradient(lo)
    hi = jax.lax.stop_gradient(hi)

    def step(_, st):
        lo, hi, x, done = st
        f, df = _poly(a_ng, x)
        f = sgn * f
        df = sgn * df
        right = ~(f < 0.0)  # root at or left of x (NaN: far right)
        hi_n = jnp.where(right, x, hi)
        lo_n = jnp.where(right, lo, x)
        okd = jnp.isfinite(df) & (df != 0.0) & jnp.isfinite(f)
        xn = x - jnp.where(okd, f, 0.0) / jnp.where(okd, df, 1.0)
        bad = ~okd | ~jnp.isfinite(xn) | (xn <= lo_n) | (xn >= hi_n)
        mid = 0.5 * (lo_n + hi_n)
        xn = jnp.where(bad, mid, xn)
        fin = (xn == x) | (mid == lo_n) | (mid == hi_n) | (f == 0.0)
        keep = done | fin
        return jnp.where(done, lo, lo_n), jnp.where(done, hi, hi_n), jnp.where(keep, x, xn), keep

    x0 = 0.5 * (lo + hi)
    _, _, x, _ = jax.lax.fori_loop(0, _BRACKET_ITERS, step, (lo, hi, x0, jnp.zeros(x0.shape, bool)))
    x = jax.lax.stop_gradient(x)
    f, df = _poly(a, x)
    ok = jnp.isfinite(df) & (df != 0.0) & jnp.isfinite(f)
    return straight(x, x - jnp.where(ok, f, 0.0) / jnp.where(ok, df, 1.0))


# ---------------------------------------------------------------------------
# elliptic integrals of the third kind with period reduction
# ---------------------------------------------------------------------------
# ---------------------------------------------------------------------------
# the regimes
# ---------------------------------------------------------------------------
def _free_top(A, C, q0, om, t):
    """Free symmetric top ``q(t) = q_m(|m| t/A) q0 q_e3(b t)``; per body (...), ``t`` (..., T)."""
    Iom = jnp.stack([A * om[..., 0], A * om[..., 1], C * om[..., 2]], axis=-1)
    zero = jnp.zeros_like(A)
    mq = _qmul(_qmul(q0, jnp.concatenate([zero[..., None], Iom], axis=-1)), _conj(q0))
    mvec = mq[..., 1:]
    half = 0.5 * t / A[..., None]
    mn = _safe_norm(mvec)[..., None]
    ang = mn * half
    sinc = half * jnp.sinc(ang / jnp.pi)
    qm = jnp.concatenate([jnp.cos(ang)[..., None], sinc[..., None] * mvec[..., None, :]], axis=-1)
    b = om[..., 2] * (A - C) / A
    beta = 0.5 * b[..., None] * t
    z = jnp.zeros_like(beta)
    qb = jnp.stack([jnp.cos(beta), z, z, jnp.sin(beta)], axis=-1)
    q = _qmul(_qmul(qm, q0[..., None, :]), qb)
    cb, sb = jnp.cos(2.0 * beta), jnp.sin(2.0 * beta)
    o1 = om[..., None, 0] * cb + om[..., None, 1] * sb
    o2 = -om[..., None, 0] * sb + om[..., None, 1] * cb
    o3 = jnp.broadcast_to(om[..., None, 2], o1.shape)
    return q, jnp.stack([o1, o2, o3], axis=-1)


def _assemble(Z1, Z2, dZ1, dZ2):
    q = jnp.stack([Z1.real, Z2.real, Z2.imag, Z1.imag], axis=-1)
    qd = jnp.stack([dZ1.real, dZ2.real, dZ2.imag, dZ1.imag], axis=-1)
    w, v = q[..., 0:1], q[..., 1:]
    wd, vd = qd[..., 0:1], qd[..., 1:]
    om = 2.0 * (w * vd - wd * v - jnp.cross(v, vd))
    return q, om


def _expi(x):
    return jax.lax.complex(jnp.cos(x), jnp.sin(x))


def _cplx(re, im):
    return jax.lax.complex(re, im)


def _unit_phase(e):
    """``e / |e|``, 1 where ``e == 0``."""
    r2 = e.real * e.real + e.imag * e.imag
    ok = r2 > 0.0
    r = jnp.sqrt(jnp.where(ok, r2, 1.0))
    return jnp.where(ok, e / r.astype(e.dtype), jnp.ones_like(e))


def _per_time(c, tt):
    """Amplitudes ``cos(theta/2), sin(theta/2)``, their rates, the rates of the phases and the angle
    integrals at the elliptic arguments ``tt`` (..., T); the constants ``c`` (..., 1). One call of each special function: the Jacobi functions at
    ``tt`` and at its reduction ``tr`` stacked, the two angle integrals stacked, their complete
    integrals appended to the times of :math:`R_J` (the reference: ``_per_time``,
    ``_pi_periodic``, ``_pi_reduced``, ``_pi_complete`` of the NumPy module)."""
    K, m1 = c["K"], c["m1"]
    finite = jnp.isfinite(K)
    Ks = jnp.where(finite, K, 1.0)
    j = jax.lax.stop_gradient(jnp.where(finite, jnp.rint(tt / (2.0 * Ks)), 0.0))
    tr = tt - 2.0 * j * Ks
    u = jnp.stack([tt, tr])
    Pb = jacobi_params(jnp.broadcast_to(1.0 - m1, u.shape), jnp.broadcast_to(m1, u.shape))
    sn_, cn_, dn_, *_ = sncndn_dd(u, jnp.zeros_like(u), Pb)
    sn, cn, dn = sn_[0], cn_[0], dn_[0]
    snr, cnr, dnr = sn_[1], cn_[1], dn_[1]

    sd, d, nu, lam = c["sd"], c["d"], c["nu"], c["lam"]
    arg1 = 0.5 * (c["W1"] + d * sn * sn)
    arg2 = 0.5 * (c["W2"] + d * cn * cn)
    cc = jnp.where(c["s1"], sd * sn, safe_sqrt(jnp.where(c["s1"], 1.0, arg1)))
    ss = jnp.where(c["s2"], sd * cn, safe_sqrt(jnp.where(c["s2"], 1.0, arg2)))
    cdot = jnp.where(c["s1"], sd * nu * cn * dn, _safe_div(d * nu * sn * cn * dn, 2.0 * cc))
    sdot = jnp.where(c["s2"], -sd * nu * sn * dn, -_safe_div(d * nu * sn * cn * dn, 2.0 * ss))
    rate_c = lam * cc + jnp.where(c["zero1"], 0.0, _safe_div(c["kap_s"], 2.0 * cc))
    rate_s = -lam * ss + jnp.where(c["zero2"], 0.0, _safe_div(c["kap_d"], 2.0 * ss))

    # the angle integrals (sigma: maybe shifted by K, whose functions are even in tr; delta)
    shiftS = ~c["direct"]
    dns = jnp.where(dnr != 0.0, dnr, 1.0)
    sS = jnp.where(shiftS, cnr / dns, snr)
    c2S = jnp.where(shiftS, m1 * (snr / dns) ** 2, cnr * cnr)
    d2S = jnp.where(shiftS, m1 / (dns * dns), dnr * dnr)
    shape = tt.shape
    n = jnp.stack([jnp.broadcast_to(c["nS"], shape), jnp.broadcast_to(c["nD"], shape)])
    n1 = jnp.stack([jnp.broadcast_to(c["n1S"], shape), jnp.broadcast_to(c["n1D"], shape)])
    s = jnp.stack([sS, snr])
    c2 = jnp.stack([c2S, cnr * cnr])
    d2 = jnp.stack([d2S, dnr * dnr])
    both = (c2 == 0.0) & (d2 == 0.0)  # R_F, R_J take at most one zero (a stand-in, not selected)
    c2 = jnp.where(both, 1.0, c2)
    d2 = jnp.where(both, 1.0, d2)
    s2 = s * s
    p = jnp.where(n <= 0.0, 1.0 - n * s2, n1 + n * c2)
    # complete integrals Pi(n|m) = K + n/3 R_J(0, m1, 1, 1 - n), appended as a last time
    okc = m1 > 0.0
    m1s = jnp.where(okc, m1, 1.0)
    n_c = jnp.stack([c["nS"], c["nD"]])
    n1_c = jnp.stack([c["n1S"], c["n1D"]])
    ones = jnp.ones_like(p[..., :1])
    rjv = rj(
        jnp.concatenate([c2, 0.0 * ones], -1),
        jnp.concatenate([d2, m1s * ones], -1),
        jnp.concatenate([jnp.ones_like(p), ones], -1),
        jnp.concatenate([p, n1_c * ones], -1),
    )
    Pic = jnp.where(okc, K + n_c / 3.0 * rjv[..., -1:], jnp.inf)
    part = s * rf(c2, d2, jnp.ones_like(c2)) + (n / 3.0) * (s * s2) * rjv[..., :-1]
    Pis = jnp.where(finite, Pic, 0.0)
    shifted = jnp.stack([jnp.broadcast_to(shiftS, shape), jnp.zeros(shape, bool)])
    part = jnp.where(shifted, jnp.sign(tr) * (Pis - part), part)
    per = jnp.where(j == 0.0, part, 2.0 * j * Pis + part)
    return cc, ss, cdot, sdot, rate_c, rate_s, per[0], per[1]


def _heavy_top(A, C, P, q0, om, t):
    """Heavy top in the frame where up is ``e_z`` (scaled units): per body (...), ``t`` (..., T)."""
    dt = A.dtype
    w0, x0, y0, z0 = q0[..., 0], q0[..., 1], q0[..., 2], q0[..., 3]
    o1, o2, o3 = om[..., 0], om[..., 1], om[..., 2]
    g1 = 2.0 * (x0 * z0 - w0 * y0)
    g2 = 2.0 * (y0 * z0 + w0 * x0)
    om_u = 2.0 * (x0 * x0 + y0 * y0)  # 1 - u0
    op_u = 2.0 * (w0 * w0 + z0 * z0)  # 1 + u0
    u0 = 0.5 * (op_u - om_u)
    M3 = C * o3
    perp = A * (o1 * g1 + o2 * g2)
    Mz_m = perp - M3 * om_u
    Mz_p = perp + M3 * op_u
    udot0 = g1 * o2 - g2 * o1
    kin = 0.5 * A * (o1 * o1 + o2 * o2)
    r0 = g1 * g1 + g2 * g2

    c_u0 = _coeffs(u0, kin, r0, perp, A, P, M3)
    c_u0 = ((A * udot0) ** 2,) + c_u0[1:]
    c_p1 = _coeffs(1.0, kin - P * om_u, 0.0, Mz_m, A, P, M3)
    c_m1 = _coeffs(-1.0, kin + P * op_u, 0.0, Mz_p, A, P, M3)
    c_p1 = (-(Mz_m * Mz_m),) + c_p1[1:]
    c_m1 = (-(Mz_p * Mz_p),) + c_m1[1:]
    flip = (c_p1[0], -c_p1[1], c_p1[2], -c_p1[3])

    steady = (c_u0[0] == 0.0) & (c_u0[1] == 0.0)
    zeros = jnp.zeros_like(A)
    fmax = jnp.finfo(dt).max
    a3s = jax.lax.stop_gradient(c_p1[3])
    ratios = [jnp.abs(jax.lax.stop_gradient(c_p1[k]) / a3s) for k in range(3)]
    big = jnp.minimum(1.0 + jnp.maximum(jnp.maximum(ratios[0], ratios[1]), ratios[2]), fmax)
    big = jnp.where(jnp.isfinite(big), big, fmax)
    # five roots at once: v1 = u1 - u0, W1 = 1 + u1, v2 = u2 - u0, W2 = 1 - u2, h3 = u3 - 1
    shape = A.shape
    stack = lambda *xs: jnp.stack([jnp.broadcast_to(x, shape) for x in xs])  # noqa: E731
    coef = tuple(stack(c_u0[k], c_m1[k], c_u0[k], flip[k], c_p1[k]) for k in range(4))
    sgn = jnp.asarray([1.0, 1.0, -1.0, 1.0, 1.0], dt).reshape((5,) + (1,) * len(shape))
    roots = _bracket_roots(coef, stack(-op_u, zeros, zeros, zeros, zeros), stack(zeros, op_u, om_u, om_u, big), sgn)
    v1, W1, v2, W2, h3 = roots[0], roots[1], roots[2], roots[3], roots[4]
    near_m = W1 < -v1
    v1 = jnp.where(near_m, W1 - op_u, v1)
    W1 = jnp.where(near_m, W1, op_u + v1)
    near_p = W2 < v2
    v2 = jnp.where(near_p, om_u - W2, v2)
    W2 = jnp.where(near_p, W2, om_u - v2)
    at_m = Mz_p == 0.0
    v1 = jnp.where(at_m, -op_u, v1)
    W1 = jnp.where(at_m, 0.0, W1)
    at_p = Mz_m == 0.0
    u2_p = at_p & (c_p1[1] <= 0.0)
    v2 = jnp.where(u2_p, om_u, v2)
    W2 = jnp.where(u2_p, 0.0, W2)
    h3 = jnp.where(at_p & (c_p1[1] >= 0.0), 0.0, h3)

    d = v2 - v1
    steady = steady | (d <= 0.0)
    lam = 0.5 * M3 * (1.0 / C - 1.0 / A)
    kap_s = Mz_p / (2.0 * A)
    kap_d = Mz_m / (2.0 * A)
    Z10 = _cplx(w0, z0)
    Z20 = _cplx(x0, y0)

    # ---------------- steady motion (double root at u0) -------------------
    rs = jnp.where((Mz_p == 0.0) | (op_u == 0.0), lam, lam + _safe_div(kap_s, op_u))
    rd = jnp.where((Mz_m == 0.0) | (om_u == 0.0), -lam, -lam + _safe_div(kap_d, om_u))
    rs_t = rs[..., None] * t
    rd_t = rd[..., None] * t
    Z1 = Z10[..., None] * _expi(rs_t)
    Z2 = Z20[..., None] * _expi(rd_t)
    j1 = _cplx(jnp.zeros_like(rs), rs)[..., None]
    j2 = _cplx(jnp.zeros_like(rd), rd)[..., None]
    q_st, om_st = _assemble(Z1, Z2, j1 * Z1, j2 * Z2)

    # ---------------- nutating top (stand-in values where steady) ----------
    d = jnp.where(steady, 0.5, d)
    v1 = jnp.where(steady, -0.25, v1)
    v2 = jnp.where(steady, 0.25, v2)
    W1 = jnp.where(steady, 0.5, W1)
    W2 = jnp.where(steady, 0.5, W2)
    h3 = jnp.where(steady, 0.5, h3)
    udot0 = jnp.where(steady, 0.0, udot0)
    Pg = jnp.where(steady, 1.0, P)
    u3mu1 = h3 + W2 + d
    u3mu2 = h3 + W2
    m = d / u3mu1
    m1 = u3mu2 / u3mu1
    nu = jnp.sqrt(Pg * u3mu1 / (2.0 * A))
    K = ellipk_dd(m1)[0]
    sn2 = -v1 / d
    cn2 = v2 / d
    dn0 = safe_sqrt(jnp.where(m <= 0.5, 1.0 - m * sn2, m1 + m * cn2))
    use_cn = cn2 >= sn2
    cn_a = safe_sqrt(cn2)
    sn_a = _safe_div(udot0, 2.0 * d * nu * cn_a * dn0)
    sn_b = jnp.where(udot0 < 0.0, -1.0, 1.0) * safe_sqrt(sn2)  # copysign
    cn_b = _safe_div(jnp.abs(udot0), 2.0 * d * nu * jnp.abs(sn_b) * dn0)
    sn0 = jnp.where(use_cn, sn_a, sn_b)
    cn0 = jnp.where(use_cn, cn_a, cn_b)
    r2 = sn0 * sn0 + cn0 * cn0
    rpos = r2 > 0.0
    r = jnp.where(rpos, jnp.sqrt(jnp.where(rpos, r2, 1.0)), 1.0)
    s_, c_ = sn0 / r, cn0 / r
    c2_ = c_ * c_
    D2_ = jnp.where(m <= 0.5, 1.0 - m * s_ * s_, c2_ + m1 * s_ * s_)
    ok = (c2_ > 0.0) | (D2_ > 0.0)
    tau0 = jnp.where(ok, s_ * rf(jnp.where(ok, c2_, 1.0), jnp.where(ok, D2_, 1.0), jnp.ones_like(c2_)), 0.0)

    sd = jnp.sqrt(0.5 * d)
    zero1 = (W1 == 0.0) | (Mz_p == 0.0)
    zero2 = (W2 == 0.0) | (Mz_m == 0.0)
    s1 = W1 == 0.0
    s2 = W2 == 0.0
    W1s = jnp.where(zero1, 1.0, W1)
    direct = (W1s >= 0.5 * d) | (m1 == 0.0)
    nS = jnp.where(direct, -d / W1s, (W1s * m + d) / (W1s + d))
    n1S = jnp.where(direct, (W1s + d) / W1s, W1s * m1 / (W1s + d))
    linS = jnp.where(direct, 0.0, m / (W1s * m + d))
    coefS = jnp.where(direct, 1.0 / W1s, d * m1 / ((W1s + d) * (W1s * m + d)))
    cS_lin = lam + jnp.where(zero1, 0.0, kap_s * linS)
    cS_per = jnp.where(zero1, 0.0, kap_s * coefS / nu)
    W2s = jnp.where(zero2, 1.0, W2)
    nD = d / (W2s + d)
    n1D = W2s / (W2s + d)
    cD_per = jnp.where(zero2, 0.0, kap_d / ((W2s + d) * nu))
    cst = dict(
        m1=m1, K=K, sd=sd, d=d, nu=nu, W1=W1, W2=W2, s1=s1, s2=s2, zero1=zero1, zero2=zero2, lam=lam,
        kap_s=kap_s, kap_d=kap_d, nS=nS, n1S=n1S, direct=direct, nD=nD, n1D=n1D,
    )  # fmt: skip

    # ---------------- the elliptic functions at tau0 (initial phases) and at the times ----
    b = lambda x: x[..., None]  # noqa: E731
    tau = b(tau0) + b(nu) * t
    cT = {k: b(v) for k, v in cst.items()}
    outs = _per_time(cT, jnp.concatenate([b(tau0), tau], -1))
    cc0, ss0, cdot0, sdot0, rate_c0, rate_s0, perS0, perD0 = (x[..., 0] for x in outs)
    cc, ss, cdot, sdot, rate_c, rate_s, perS, perD = (x[..., 1:] for x in outs)

    # ---------------- initial phases e^{i sigma0}, e^{i delta0} ------------
    qd0 = 0.5 * _qmul(q0, jnp.concatenate([jnp.zeros_like(o1)[..., None], om], axis=-1))
    dZ10 = _cplx(qd0[..., 0], qd0[..., 3])
    dZ20 = _cplx(qd0[..., 1], qd0[..., 2])
    W2f = nu * nu + jnp.sum(om * om, axis=-1) + lam * lam
    gc = _cplx(cdot0, rate_c0)
    gs = _cplx(sdot0, rate_s0)
    e1 = _unit_phase(cc0 * Z10 + jnp.conj(gc) * dZ10 / W2f)
    e2 = _unit_phase(ss0 * Z20 + jnp.conj(gs) * dZ20 / W2f)

    dsig = b(cS_lin) * t + b(cS_per) * (perS - b(perS0))
    ddel = -b(lam) * t + b(cD_per) * (perD - b(perD0))
    ph1 = b(e1) * _expi(dsig)
    ph2 = b(e2) * _expi(ddel)
    Z1 = cc * ph1
    Z2 = ss * ph2
    dZ1 = _cplx(cdot, rate_c) * ph1
    dZ2 = _cplx(sdot, rate_s) * ph2
    q_gen, om_gen = _assemble(Z1, Z2, dZ1, dZ2)
    st = steady[..., None, None]
    return jnp.where(st, q_st, q_gen), jnp.where(st, om_st, om_gen)


def _check(cond, message):
    if not bool(jnp.all(cond)):
        raise InvalidInputError(message)


@float64_by_default
def lagrange_top_motion(A, C, mass, ell, g, q0, omega0, t, *, dtype=None):
    r"""Closed-form motion of a Lagrange top (heavy symmetric top), differentiable.

    The JAX twin of :func:`eulerpoisson.solvers.exact.lagrange.lagrange_top_motion` (same
    arguments, same results to a few ulp): a symmetric body ``diag(A, A, C)`` about a fixed point,
    its centre of mass at ``(0, 0, ell)`` in the body frame, in a uniform field ``g``.

    Parameters
    ----------
    A, C : array_like (...)
        Principal moments about the fixed point, ``0 < C <= 2 A``.
    mass : array_like (...)
        ``>= 0``.
    ell : array_like (...)
        Centre of mass on the symmetry axis (any sign, zero allowed).
    g : array_like (..., 3)
        Gravitational acceleration, space frame (any direction and magnitude, zero included).
    q0 : array_like (..., 4)
        Initial attitude, unit quaternion (tolerance ``1e-8``; normalized).
    omega0 : array_like (..., 3)
        Initial body angular velocity.
    t : array_like (T,)
        Output times, any order, negative allowed.
    dtype : None, jnp.float64 or jnp.float32, keyword-only
        Computing precision (None: float64).

    Returns
    -------
    q : jax.Array (..., T, 4)
        Attitudes (at ``t == 0`` the input ``q0``, with the derivative of the formula).
    omega : jax.Array (..., T, 3)
        Body angular velocities (at ``t == 0`` the input ``omega0``).

    Raises
    ------
    InvalidInputError
        Wrong trailing dimensions, ``t`` not 1-D, shapes that do not broadcast, non-numeric input;
        with concrete (not traced) values also ``A <= 0``, ``C <= 0``, ``C > 2 A``, ``mass < 0``,
        non-finite values or ``q0`` not of unit norm, and finite values whose gravity scale
        ``mass |g| |ell|`` or squared frequency overflows float64, or whose phase ``W |t|`` exceeds
        2^48 (as the NumPy :func:`eulerpoisson.solvers.exact.lagrange.lagrange_top_motion`).
    PrecisionError
        Traced in float64 with 64-bit floats off.

    Values are checked only when the inputs are concrete (an eager call). Under ``jit``, ``vmap``
    or ``grad`` (traced inputs) only the shapes are checked: a NaN or infinite input, a zero or
    non-unit ``q0``, ``A <= 0``, ``C <= 0``, ``C > 2 A`` or ``mass < 0`` then gives NaN (or
    meaningless) outputs without an error.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.lagrange import lagrange_top_motion
    >>> q, w = lagrange_top_motion(1.0, 0.5, 1.0, 0.3, [0, 0, -9.81], [1, 0, 0, 0], [0.1, 0.0, 20.0],
    ...                            np.linspace(0, 1, 5))
    >>> q.shape, w.shape
    ((5, 4), (5, 3))
    >>> print(np.round(np.asarray(w[-1]), 12) + 0.0)     # M3 = C Omega3 is conserved exactly
    [-0.06801549  0.08190035 20.        ]

    ``jax.jacfwd`` (or ``jax.grad`` of a scalar loss) differentiates it with respect to every
    argument; the derivatives take about a minute to compile.
    """
    dt = dtype
    names = ("A", "C", "mass", "ell", "g", "q0", "omega0", "t")
    A, C, mass, ell, g, q0, omega0, t = (as_float(x, dt, n) for x, n in zip((A, C, mass, ell, g, q0, omega0, t), names))
    for name, arr, k in (("g", g, 3), ("q0", q0, 4), ("omega0", omega0, 3)):
        if arr.ndim < 1 or arr.shape[-1] != k:
            raise InvalidInputError(f"{name} must have shape (..., {k}), got {arr.shape}")
    if t.ndim != 1:
        raise InvalidInputError(f"t must be one-dimensional (T,), got shape {t.shape}")
    try:
        shape = jnp.broadcast_shapes(
            A.shape, C.shape, mass.shape, ell.shape, g.shape[:-1], q0.shape[:-1], omega0.shape[:-1]
        )
    except ValueError as exc:
        raise InvalidInputError(
            "the shapes of A, C, mass, ell, g[..., :], q0[..., :], omega0[..., :] do not broadcast: "
            f"{A.shape}, {C.shape}, {mass.shape}, {ell.shape}, {g.shape}, {q0.shape}, {omega0.shape}"
        ) from exc
    args = (A, C, mass, ell, g, q0, omega0, t)
    if not any(isinstance(x, jax.core.Tracer) for x in args):
        for name, arr in zip(names, args):
            _check(jnp.isfinite(arr), f"{name} must be finite (no NaN or inf)")
        qn = jnp.linalg.norm(q0, axis=-1)
        _check(jnp.abs(qn - 1.0) <= _UNIT_TOL, f"q0 must be a unit quaternion (|q0| = 1 within {_UNIT_TOL})")
        _check(A > 0.0, "A must be > 0")
        _check(C > 0.0, "C must be > 0")
        _check(C <= 2.0 * A, "C must satisfy C <= 2 A (triangle inequality A + A >= C)")
        _check(mass >= 0.0, "mass must be >= 0")
        # finite values whose products leave float64: an error (as the NumPy twin), not a free top or NaN
        check_top_ranges(*(np.asarray(x, dtype=np.float64) for x in (A, mass, ell, g, omega0, t)))
    return _motion(A, C, mass, ell, g, q0, omega0, t, shape=shape)


@functools.partial(jax.jit, static_argnames=("shape",))
def _motion(A, C, mass, ell, g, q0, omega0, t, *, shape):
    """The motion (jit-compiled once per shape and dtype; see :func:`lagrange_top_motion`)."""
    A = jnp.broadcast_to(A, shape)
    C = jnp.broadcast_to(C, shape)
    mass = jnp.broadcast_to(mass, shape)
    ell = jnp.broadcast_to(ell, shape)
    g = jnp.broadcast_to(g, shape + (3,))
    q0_in = jnp.broadcast_to(q0, shape + (4,))
    om = jnp.broadcast_to(omega0, shape + (3,))
    qn = q0_in / jnp.sqrt(jnp.sum(q0_in * q0_in, axis=-1, keepdims=True))
    tt = jnp.broadcast_to(t, shape + t.shape)

    gn = _safe_norm(g)
    P = mass * gn * jnp.abs(ell)
    W2 = P / A + jnp.sum(om * om, axis=-1)
    posW = W2 > 0.0
    W2s = jnp.where(posW, W2, 1.0)
    Pn = jnp.where(posW, P / (A * W2s), 0.0)
    kW = jax.lax.stop_gradient(jnp.rint(0.5 * jnp.log2(W2s))).astype(jnp.int32)
    kS = jax.lax.stop_gradient(jnp.rint(jnp.log2(A))).astype(jnp.int32)
    heavy = (P > 0.0) & (Pn >= 2.0**-200) & jnp.isfinite(W2)

    q_free, om_free = _free_top(A, C, qn, om, tt)

    # the heavy top (a stand-in where the body is not heavy: its values unused)
    zhat = -jnp.sign(ell)[..., None] * g / jnp.where(heavy, gn, 1.0)[..., None]
    ez = jnp.zeros_like(zhat).at[..., 2].set(1.0)
    zhat = jnp.where(heavy[..., None], zhat, ez)
    qf = _frame_quaternion(zhat)
    q0f = _qmul(qf, qn)
    q0f = q0f / jnp.sqrt(jnp.sum(q0f * q0f, axis=-1, keepdims=True))
    W = jnp.ldexp(jnp.ones_like(A), kW)
    Ph = jnp.where(heavy, P * jnp.ldexp(jnp.ones_like(P), -kS - 2 * kW), 1.0)
    q_h, om_h = _heavy_top(
        A * jnp.ldexp(jnp.ones_like(A), -kS),
        C * jnp.ldexp(jnp.ones_like(C), -kS),
        Ph,
        q0f,
        om / W[..., None],
        W[..., None] * tt,
    )
    q_h = _qmul(_conj(qf)[..., None, :], q_h)
    om_h = om_h * W[..., None, None]

    hv = heavy[..., None, None]
    q = jnp.where(hv, q_h, q_free)
    o = jnp.where(hv, om_h, om_free)
    q = q / jnp.sqrt(jnp.sum(q * q, axis=-1, keepdims=True))
    o = o.at[..., 2].set(jnp.broadcast_to(om[..., None, 2], o.shape[:-1]))
    at0 = (t == 0.0)[:, None]
    q = jnp.where(at0, straight(jnp.broadcast_to(q0_in[..., None, :], q.shape), q), q)
    o = jnp.where(at0, straight(jnp.broadcast_to(om[..., None, :], o.shape), o), o)
    return q, o
