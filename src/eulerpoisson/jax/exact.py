r"""The exact free rigid-body motion in JAX: jit-compiled, vectorized and differentiable.

A transcription of the NumPy reference :mod:`eulerpoisson.solvers.exact.motion` (its module
docstring derives every formula: the regimes A and B, the separatrix, the relative equilibria,
the double-double phase reduced modulo :math:`K`, the addition theorem for :math:`|\lambda t|\le
K`, the integrals of the third kind as single :math:`R_J` terms) into ``jax.numpy``, with

* no Python control flow on values: every branch is computed and selected by ``jnp.where`` (one
  compiled function serves a batch that mixes regimes, equilibria and symmetric tops), with safe
  arguments in the branch that is not selected, so that no NaN or infinity reaches a derivative;
* loops of a fixed length (``lax.fori_loop`` and short unrolled loops; no ``while_loop``), so
  that forward and reverse differentiation both work;
* the near (addition theorem) and far (quarter-period) increments of the precession computed
  with one :math:`R_J` per evaluation (the arguments are selected before the call).

The public function is :func:`exact_motion`.

References
----------
.. [1] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., section 37.
.. [2] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the free rigid
   body motion and its use in splitting methods", SIAM J. Sci. Comput. 30 (2008) 2084-2112.
.. [3] B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer.
   Algorithms 10 (1995) 13-26.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import InvalidInertiaError, InvalidInputError
from ..util.validate import MAX_PHASE, scaled_norms
from .doubledouble import (
    dd_add,
    dd_mul,
    dd_mul_d,
    exp2i,
    quick_two_sum,
    safe_sqrt,
    straight,
    two_prod,
    two_sum,
)
from .elliptic import JacobiParams, consts, fused_loops, jacobi_params, rf, rj, sncndn_dd
from .precision import as_float, float64_by_default
from .quaternion import qmul_components as _qmul

__all__ = ["exact_motion", "check_inputs", "check_phase", "normalized", "MAX_PHASE"]


# ---------------------------------------------------------------------------
# quaternions (components)
# ---------------------------------------------------------------------------


def _qmin(M1, M2, M3, caseB, sa):
    """Quaternion of the minimal rotation taking ``M/|M|`` to ``e = sa e_a`` (components)."""
    rn = jax.lax.rsqrt(M1 * M1 + M2 * M2 + M3 * M3)
    x, y, z = M1 * rn, M2 * rn, M3 * rn
    ze = jnp.where(caseB, sa * z, sa * x)
    vx = jnp.where(caseB, sa * y, 0.0)
    vy = jnp.where(caseB, -sa * x, sa * z)
    vz = jnp.where(caseB, 0.0, -sa * y)
    w = 1.0 + ze
    f = jax.lax.rsqrt(2.0 * w)
    return (w * f, vx * f, vy * f, vz * f)


# ---------------------------------------------------------------------------
# per-body constants
# ---------------------------------------------------------------------------
class _Body(NamedTuple):
    caseB: jax.Array
    sep: jax.Array
    m1: jax.Array
    lam: jax.Array
    t0h: jax.Array
    t0l: jax.Array
    Ac: jax.Array
    A2: jax.Array
    Aa: jax.Array
    sa: jax.Array
    sc: jax.Array
    rate: jax.Array
    coef: jax.Array
    nu: jax.Array
    omnu: jax.Array
    Jc: jax.Array
    Nadd: jax.Array
    Cadd: jax.Array
    nud: jax.Array
    omnud: jax.Array
    Jcd: jax.Array
    g0: jax.Array
    Gc: jax.Array
    sn0: jax.Array
    theta0: jax.Array
    Jfar0: jax.Array
    kfull: jax.Array
    q0: tuple


def _dd_square_times(x, dh, dl, y):
    sh, sl = two_prod(x, x)
    ph, pl = dd_mul(sh, sl, dh, dl)
    return dd_mul_d(ph, pl, y)


def _nz(x, use):
    """``x`` where ``use``, else 1 (a safe denominator for a branch that is not selected)."""
    return jnp.where(use, x, 1.0)


def _differences(Is, Ms):
    """``(d21, d32, d31, |M|^2, a1, a3)``: the moment differences and the two sums the regimes are read from."""
    I1, I2, I3 = Is
    M1, M2, M3 = Ms
    d21 = I2 - I1
    d32 = I3 - I2
    d31 = I3 - I1
    msq = M1 * M1 + M2 * M2 + M3 * M3
    a1 = M2 * M2 * d21 / I2 + M3 * M3 * d31 / I3
    a3 = M1 * M1 * d31 / I1 + M2 * M2 * d32 / I2
    return d21, d32, d31, msq, a1, a3


def _equilibrium(Is, Ms):
    """Relative equilibria (``M0 = 0`` or along a principal axis) in the sorted, scaled frame."""
    M1, _, M3 = Ms
    d21, d32, _, msq, a1, a3 = _differences(Is, Ms)
    dh = _dd_D(Is, Ms)
    return (msq == 0.0) | (a1 == 0.0) | (a3 == 0.0) | ((dh == 0.0) & (M1 * M1 * d21 == 0.0) & (M3 * M3 * d32 == 0.0))


def _dd_D(Is, Ms):
    """High part of ``(M3^2 (I3-I2) I1 - M1^2 (I2-I1) I3)`` in double-double."""
    I1, I2, I3 = Is
    M1, _, M3 = Ms
    d32h, d32l = two_sum(I3, -I2)
    d21h, d21l = two_sum(I2, -I1)
    t3h, t3l = _dd_square_times(M3, d32h, d32l, I1)
    t1h, t1l = _dd_square_times(M1, d21h, d21l, I3)
    dh, _ = dd_add(t3h, t3l, -t1h, -t1l)
    return dh


def _constants(Is, Ms, C) -> tuple[_Body, JacobiParams]:
    """Constants of generic (non-equilibrium) bodies in the sorted, scaled frame (components)."""
    I1, I2, I3 = Is
    M1, M2, M3 = Ms
    d21, d32, d31, msq, a1, a3 = _differences(Is, Ms)
    D = _dd_D(Is, Ms) / (I1 * I3)
    mn = jnp.sqrt(msq)

    caseB0 = D > 0.0
    m1B = d31 * D / (_nz(d32, caseB0) * a1)
    caseB = caseB0 & (m1B >= C.m1_sep)
    d32B = _nz(d32, caseB)  # > 0 in regime B
    d21A = _nz(d21, ~caseB)  # > 0 in regime A
    mB = d21 * a3 / (d32B * a1)
    m1A = d31 * (-D) / (d21A * a3)
    mA = d32 * a1 / (d21A * a3)
    m = jnp.where(caseB, mB, mA)
    m1 = jnp.where(caseB, m1B, m1A)
    sep = (~caseB) & (m1 < C.m1_sep)
    small_m = m <= m1
    m, m1 = jnp.where(small_m, m, 1.0 - m1), jnp.where(small_m, 1.0 - m, m1)
    # (jnp.clip would halve the derivative at m = 0: a tie in max)
    m = jnp.where(sep, 1.0, jnp.where(m < 0.0, 0.0, jnp.where(m > 1.0, 1.0, m)))
    m1 = jnp.where(sep, 0.0, jnp.where(m1 < 0.0, 0.0, jnp.where(m1 > 1.0, 1.0, m1)))

    A1 = jnp.sqrt(a3 * I1 / d31)
    A2 = jnp.sqrt(jnp.where(caseB, a3 * I2 / d32B, a1 * I2 / d21A))
    A3 = jnp.sqrt(a1 * I3 / d31)
    lam = jnp.sqrt(jnp.where(caseB, d32 * a1, d21 * a3) / (I1 * I2 * I3))
    Ac = jnp.where(caseB, A1, A3)
    Aa = jnp.where(caseB, A3, A1)
    Mc0 = jnp.where(caseB, M1, M3)
    Ma0 = jnp.where(caseB, M3, M1)
    sa = jnp.where(Ma0 < 0.0, -1.0, 1.0)
    sc = jnp.where(sep & (Mc0 < 0.0), -1.0, 1.0)

    rate = jnp.where(caseB, mn / I2, mn / I3)
    coefA = mn * d32 * d31 / (I3 * I3 * d21A * lam)
    coefB = mn * d32 * d21 / (I2 * I2 * d31 * lam)
    coef = jnp.where(caseB, coefB, coefA)
    NA = I1 * d32 / (I3 * d21A)
    omnuA = I2 * d31 / (I3 * d21A)
    nprime = I3 * d21 / (I2 * d31)
    omnprime = I1 * d32 / (I2 * d31)
    NB = nprime / _nz(omnprime, caseB)
    nuB = m + nprime * m1
    omnuB = m1 * omnprime
    nu = jnp.where(caseB, nuB, -NA)
    omnu = jnp.where(caseB, omnuB, omnuA)
    Nadd = jnp.where(caseB, NB, NA)
    coef = jnp.where(jnp.isfinite(coef), coef, 0.0)
    nu = jnp.where(jnp.isfinite(nu), nu, 0.0)
    omnu = jnp.where(jnp.isfinite(omnu) & (omnu > 0.0), omnu, 1.0)
    Nadd = jnp.where(jnp.isfinite(Nadd), Nadd, 0.0)
    Cadd = safe_sqrt(Nadd * (Nadd + m) * (1.0 + Nadd))
    g0 = jnp.where(caseB, 1.0 + Nadd, 1.0)

    # initial phase: amplitude (c0, s0) of (sc Mc/Ac, sa sc M2/A2)
    x = sc * Mc0 / Ac
    y = sa * sc * M2 / A2
    h = jnp.hypot(x, y)
    c0 = x / h
    s0 = y / h
    P = jacobi_params(m, m1)
    s2 = s0 * s0
    delta2 = jnp.where(m <= 0.5, 1.0 - m * s2, c0 * c0 + m1 * s2)
    F0 = s0 * rf(c0 * c0, jnp.where(sep, 1.0, delta2), jnp.ones_like(s0))
    tsep = jnp.arcsinh(s0 / _nz(c0, sep & (c0 != 0.0)))
    sg = jnp.where(s0 < 0.0, -1.0, 1.0)
    th, tl = two_sum(sg * 2.0 * P.kh, -F0)
    tl = tl + sg * 2.0 * P.kl
    th, tl = quick_two_sum(th, tl)
    neg = c0 < 0.0
    t0h = jnp.where(sep, tsep, jnp.where(neg, th, F0))
    t0l = jnp.where(sep | ~neg, 0.0, tl)
    # The derivative of tau0 at a turning point of M (Mc = 0, c0 = 0: a common initial state, e.g. a zero
    # component of omega0). F0 = s0 R_F(c0^2, ...) depends on c0 through c0^2, whose derivative vanishes
    # there, while dtau0/dc0 = -s0/dn does not. The complementary form tau0 = sg (K - u'),
    # u' = (c0/dn) R_F(m1 s0^2/dn^2, m1/dn^2, 1) (sn(K - u') = cd u', cn(K - u') = sqrt(m1) sd u'),
    # is linear in c0: its derivative is taken where |c0| < |s0|; the value stays the reference's.
    comp = (jnp.abs(c0) < jnp.abs(s0)) & ~sep
    dn2 = jnp.where(comp, delta2, 1.0)
    dn0 = jnp.sqrt(dn2)
    m1c = jnp.where(comp, m1, 1.0)
    g = sg * (P.kh - (c0 / dn0) * rf(m1c * s2 / dn2, m1c / dn2, jnp.ones_like(s0)))
    t0h = jnp.where(comp, jax.lax.stop_gradient(t0h) + (g - jax.lax.stop_gradient(g)), t0h)

    nud = jnp.where(caseB, -Nadd, nu)
    omnud = jnp.where(caseB, 1.0 + Nadd, omnu)
    kfull = jnp.where(sep, jnp.inf, P.kh)
    q0 = _qmin(M1, M2, M3, caseB, sa)
    zero = jnp.zeros_like(m)
    B = _Body(
        caseB, sep, m1, lam, t0h, t0l, Ac, A2, Aa, sa, sc, rate, coef, nu, omnu, zero, Nadd, Cadd, nud, omnud,
        zero, g0, zero, zero, zero, zero, kfull, q0,
    )  # fmt: skip
    # values at t = 0
    sn, _, _, n, r, s, c, d = sncndn_dd(t0h, t0l, P)
    theta0 = _theta(B, P, n, s, c)
    # three R_J in one call: J_c = R_J(0, m1, 1, 1 - nu)/3 for nu and nu_d, and J of the far branch at t = 0
    neff = jnp.where(caseB, n - 1.0, n)
    jx, jy, jp, ok, S, S2, odd = _jtot_args(nu, omnu, neff, s, c, d, P.kp, sep)
    m1s = jnp.where(sep, 1.0, m1)
    one = jnp.ones_like(m)
    rjv = rj(
        jnp.stack([zero, zero, jx]), jnp.stack([m1s, m1s, jy]), jnp.stack([one, one, one]), jnp.stack([omnu, omnud, jp])
    )
    Jc = jnp.where(sep, 0.0, rjv[0] / 3.0)
    Jcd = jnp.where(caseB, jnp.where(sep, 0.0, rjv[1] / 3.0), Jc)
    j = _jtot_end(rjv[2], ok, S, S2, odd, r, Jc, neff, sep, omnu)
    Jfar0 = jnp.where(caseB, m1 * j, j)
    Gc = jnp.where(caseB, m1 * Jc, 0.0)
    return B._replace(Jc=Jc, Jcd=Jcd, Gc=Gc, sn0=sn, theta0=theta0, Jfar0=Jfar0), P


def _keep(tree):
    """``tree`` materialized in the rolled (CPU) form: passed through a conditional on a runtime predicate,
    across which XLA does not fuse.

    XLA's CPU fusion otherwise copies a shared intermediate (the Jacobi functions, the precession
    increment) into every consumer, recomputing it several times per element: measured, a third more
    time and a slower compilation. The values are unchanged (both branches return ``tree``; under ``vmap``
    the conditional becomes a select). In the fused form an optimization barrier instead (no conditional,
    no split of the kernel's loops; measured on an H100: 18 % faster than without).
    """
    if fused_loops():
        return jax.lax.optimization_barrier(tree)
    x = jax.tree_util.tree_leaves(tree)[0].reshape(-1)[0]

    def other(t):
        return jax.tree_util.tree_map(lambda a: a + jnp.zeros((), a.dtype), t)

    return jax.lax.cond(x == x, lambda t: t, other, tree)


def _jtot_args(nu, omnu, n, s, c, d, kp, sep):
    """Arguments of the ``R_J`` of ``J(nu; u)`` (``u = n K + r``, values ``s, c, d`` at ``r``).

    ``J = n J_c + J_per`` with ``J_per = S^3 R_J(C^2, D^2, 1, 1 - nu S^2)/3`` (the values at ``r``,
    or at ``K - |r|`` for odd ``n``); the fourth argument without cancellation.
    """
    odd = jnp.mod(n, 2.0) == 1.0
    sa_ = jnp.abs(s)
    rd = 1.0 / d
    S = jnp.where(odd, c * rd, sa_)
    Cc = jnp.where(odd, kp * sa_ * rd, c)
    Dd = jnp.where(odd, kp * rd, d)
    S2 = S * S
    C2 = Cc * Cc
    p = jnp.where(nu <= 0.0, 1.0 - nu * S2, omnu + nu * C2)
    ok = ~sep & (S2 > 0.0)
    return jnp.where(ok, C2, 1.0), jnp.where(ok, Dd * Dd, 1.0), jnp.where(ok, p, 1.0), ok, S, S2, odd


def _jtot_end(rjv, ok, S, S2, odd, r, jc, n, sep, omnu):
    """``J(nu; u)`` from the value of its ``R_J`` (see :func:`_jtot_args`; 0 on the separatrix).

    For odd ``n`` the periodic part ``sign(r) (J_c - J(K - |r|))`` is smooth in ``r`` but written
    with ``sign`` and ``|r|``, whose derivatives vanish at ``r = 0`` exactly (``u`` an odd multiple of
    ``K``: a turning point of ``M``, e.g. an initial state with a zero component): there the
    derivative ``dJ/du = sn^2/(1 - nu sn^2) = 1/(1 - nu)`` is added explicitly (value unchanged).
    """
    jq = jnp.where(ok, S * S2 * rjv * (1.0 / 3.0), 0.0)
    jper = jnp.where(odd, jnp.sign(r) * (jc - jq), jnp.where(r < 0.0, -jq, jq))
    kink = odd & (r == 0.0)
    jper = jper + jnp.where(kink, (r - jax.lax.stop_gradient(r)) / jnp.where(kink, omnu, 1.0), 0.0)
    return jnp.where(sep, 0.0, n * jc + jper)


def _theta(B: _Body, P: JacobiParams, n, s, c):
    """Unwrapped azimuth ``atan2(A2 sn, Ac cn) = n pi/2 + dtheta`` (``n`` modulo 8)."""
    odd = jnp.mod(n, 2.0) == 1.0
    C = consts(jnp.result_type(s))
    # one atan2 of the selected arguments (the select commutes with it: the same values)
    dtheta = jnp.arctan2(jnp.where(odd, B.Ac * P.kp * s, B.A2 * s), jnp.where(odd, B.A2 * c, B.Ac * c))
    return jnp.mod(n, 8.0) * C.pio2_hi + dtheta


# ---------------------------------------------------------------------------
# the motion at given (scaled) times
# ---------------------------------------------------------------------------
def _generic(B: _Body, P: JacobiParams, ts, eq, eq_angle):
    """``M`` (sorted, scaled frame) and ``q`` (components) of generic bodies at scaled times ``ts``, and
    ``(cos, sin)`` of half the angle: ``alpha`` (below), or ``eq_angle`` where ``eq`` (a relative equilibrium's
    uniform rotation; one sine and cosine per element serve both)."""
    dh, dl = two_prod(B.lam, ts)
    th, tl = dd_add(dh, dl, B.t0h, B.t0l)
    # increment of the precession integral: the addition theorem (near) or the reduction (far)
    near = jnp.abs(dh) <= B.kfull
    dh = jnp.where(near, dh, 0.0)
    dl = jnp.where(near, dl, 0.0)
    # sn, cn, dn of tau and of delta = lambda t in one call
    th, dh, tl, dl = jnp.broadcast_arrays(th, dh, tl, dl)
    vals = _keep(sncndn_dd(jnp.stack([th, dh]), jnp.stack([tl, dl]), P))
    sn, cn, dn, n, r, s, c, d = (v[0] for v in vals)
    snd, cnd, dnd, nd, rd, sd, cd, ddd = (v[1] for v in vals)
    theta = _theta(B, P, n, s, c)
    N = B.Nadd
    Pp = sn * B.sn0
    X = 1.0 + N * snd * snd + N * Pp * cnd * dnd
    Y = -Pp * snd
    YX = Y / X
    z = B.Cadd * YX
    # On the separatrix the near increment is J(delta) + xadd with J(delta) = (delta - atan(a)/sqrt(N))/(1 + N),
    # a = sqrt(N) tanh(delta) (tanh(delta) = snd there: n = 0) and xadd = -atan(z)/(sqrt(N) (1 + N))
    # (Cadd = sqrt(N) (1 + N) at m = 1): atan(a) + atan(z) = atan2(a + z, 1 - a z) (for every real a, z), one
    # atan2 shared with the generic atan(z) = atan2(z, 1). With w = a + z = sqrt(N) wq, the quotient
    # F = atan2(w, v)/w keeps the limit N -> 0: near value (delta - F wq)/(1 + N).
    sN = safe_sqrt(N)
    wq = snd + (1.0 + N) * YX
    a_s = sN * snd
    w_s = sN * wq
    v_s = 1.0 - a_s * (sN * (1.0 + N) * YX)
    nzz = z != 0.0
    zs = jnp.where(nzz, z, 1.0)
    nzw = w_s != 0.0
    ws = jnp.where(nzw, w_s, 1.0)
    num = jnp.where(B.sep, ws, zs)
    at = jnp.arctan2(num, jnp.where(B.sep, v_s, 1.0))
    # (one quotient: at / zs off the separatrix, where xadd is used; at / ws on it, where fsep is)
    aq = at / num
    xadd = -YX * jnp.where(nzz, aq, 1.0)
    fsep = jnp.where(nzw, aq, 1.0 / jnp.where(B.sep, v_s, 1.0))
    dlt = dh + dl
    use_sh = B.caseB & (jnp.abs(dlt) * B.g0 > B.Gc)
    # one R_J: the arguments of the near branch (J of delta, direct or shifted) or the far one
    nu_j = jnp.where(near, jnp.where(use_sh, B.nu, B.nud), B.nu)
    omnu_j = jnp.where(near, jnp.where(use_sh, B.omnu, B.omnud), B.omnu)
    jc_j = jnp.where(near, jnp.where(use_sh, B.Jc, B.Jcd), B.Jc)
    n_j = jnp.where(near, jnp.where(use_sh, nd - 1.0, nd), jnp.where(B.caseB, n - 1.0, n))
    r_j = jnp.where(near, rd, r)
    jx, jy, jp, ok, S, S2, odd = _jtot_args(
        nu_j, omnu_j, n_j, jnp.where(near, sd, s), jnp.where(near, cd, c), jnp.where(near, ddd, d), P.kp, B.sep
    )
    j = _jtot_end(rj(jx, jy, jnp.ones_like(jx), jp), ok, S, S2, odd, r_j, jc_j, n_j, B.sep, omnu_j)
    gdel = jnp.where(use_sh, B.Gc + B.m1 * j, B.g0 * (dlt - B.g0 * j))
    near_sep = (dlt - fsep * wq) / (1.0 + N)
    near_val = jnp.where(B.caseB, gdel - B.g0 * B.g0 * xadd, jnp.where(B.sep, near_sep, j + xadd))
    far_val = jnp.where(B.caseB, B.m1 * j, j) - B.Jfar0
    dj = _keep(jnp.where(near, near_val, far_val))

    Mc = B.sc * B.Ac * cn
    M2 = B.sa * B.sc * B.A2 * sn
    Ma = B.sa * B.Aa * dn
    M1 = jnp.where(B.caseB, Mc, Ma)
    M3 = jnp.where(B.caseB, Ma, Mc)
    psi = B.rate * ts + B.coef * dj
    sigma = jnp.where(B.caseB, 1.0, -1.0)
    alpha = jnp.where(eq, eq_angle, psi - sigma * (theta - B.theta0))
    ca = jnp.cos(0.5 * alpha)
    sal = jnp.sin(0.5 * alpha)
    zero = jnp.zeros_like(sal)
    qe = (ca, jnp.where(B.caseB, 0.0, B.sa * sal), zero, jnp.where(B.caseB, B.sa * sal, 0.0))
    qt = _qmin(M1, M2, M3, B.caseB, B.sa)
    q = _qmul(*qe, *qt)
    q0 = B.q0
    q = _qmul(q0[0], -q0[1], -q0[2], -q0[3], *q)
    return _keep(((M1, M2, M3), q, (ca, sal)))


def _assemble(components, shape):
    """The components as one array ``shape + (k,)``, each computed once.

    (``jnp.stack`` is compiled by XLA on the CPU into one kernel that evaluates the expression of
    every component for every output element, which repeats the whole closed form for each
    component: ten times slower. Setting the components one by one materializes them.)
    """
    dtype = jnp.result_type(*components)
    out = jnp.zeros(shape + (len(components),), dtype)
    for k, comp in enumerate(components):
        out = out.at[..., k].set(jnp.broadcast_to(comp, shape))
    return out


def _sorting(inertia):
    """Proper signed permutation to ascending moments: ``x_sorted[k] = sgn[k] x[perm[k]]``."""
    perm = jnp.argsort(inertia, axis=-1, stable=True)
    inv = (
        (perm[..., 0] > perm[..., 1]).astype(jnp.int32) + (perm[..., 0] > perm[..., 2]) + (perm[..., 1] > perm[..., 2])
    )
    one = jnp.ones(inertia.shape[:-1], inertia.dtype)
    sgn = jnp.stack([one, jnp.where(inv % 2 == 1, -1.0, 1.0).astype(inertia.dtype), one], axis=-1)
    return perm, sgn


def _pow2(x, e):
    """``2**e`` in the dtype of ``x`` (exact). Scaling by a product with it, not ``jnp.ldexp(x, e)``:
    JAX's ``ldexp`` passes the tangent of ``x = 0`` through unscaled, a wrong derivative there; and it is a
    ``pow``, costly on a GPU)."""
    return exp2i(e, x.dtype)


def _principal_motion(inertia, M0, t):
    """The motion in the principal frame from ``R(0) = 1``: ``M(t)`` (..., 3) and ``q_rel`` (..., 4).

    ``inertia`` and ``M0`` (batch shape ``Bb``, last axis 3, principal moments any order) and
    ``t`` (shape ``Tt``) broadcast elementwise: results of shape ``broadcast(Bb, Tt) + (3,)``, ``(4,)``.
    """
    C = consts(inertia.dtype)
    perm, sgn = _sorting(inertia)
    Is = jnp.take_along_axis(inertia, perm, axis=-1)
    Ms = sgn * jnp.take_along_axis(M0, perm, axis=-1)
    # exact power-of-two scaling: max |M| and max I in [0.5, 1)
    amax = jax.lax.stop_gradient(jnp.max(jnp.abs(Ms), axis=-1))
    eM = jnp.where(amax == 0.0, 0, jnp.frexp(amax)[1])
    eI = jnp.frexp(jax.lax.stop_gradient(Is[..., 2]))[1]
    Ms = Ms * _pow2(Ms, -eM[..., None])
    Is = Is * _pow2(Is, -eI[..., None])
    escale = eM - eI
    Isc = (Is[..., 0], Is[..., 1], Is[..., 2])
    Msc = (Ms[..., 0], Ms[..., 1], Ms[..., 2])
    eq = _equilibrium(Isc, Msc)
    # generic bodies; an equilibrium gets a generic stand-in (its values and derivatives unused)
    dummy_I = (0.5, 0.625, 0.875)
    Isg = tuple(jnp.where(eq, di, x) for di, x in zip(dummy_I, Isc))
    Msg = tuple(jnp.where(eq, 0.5, x) for x in Msc)
    B, P = _constants(Isg, Msg, C)
    # the per-body constants are computed once per body (XLA would otherwise fuse their arithmetic
    # into the per-time kernels and repeat it for every time)
    scale_t = _pow2(Ms, escale)
    scale_m = _pow2(Ms, eM)
    # relative equilibria: M constant, uniform rotation about Omega = M0 / I (per body here)
    om = M0 / inertia
    w2 = jnp.sum(om * om, axis=-1)
    pos = w2 > 0.0
    w = jnp.sqrt(jnp.where(pos, w2, 1.0))
    axis = om / w[..., None]
    B, P, scale_t, scale_m, w, axis = jax.lax.optimization_barrier((B, P, scale_t, scale_m, w, axis))
    ts = t * scale_t
    # (the half angle w t / 2 of the uniform rotation: its cosine and sine come with the generic ones)
    (M1, M2, M3), q, (ceq, seq) = _generic(B, P, ts, eq, w * t)
    shape = jnp.broadcast_shapes(eq.shape, t.shape)
    Mg = _assemble((M1, M2, M3), shape)
    Mg = Mg * jnp.broadcast_to(scale_m, shape)[..., None]
    qg = _assemble(q, shape)
    qg = qg * jax.lax.rsqrt(jnp.sum(qg * qg, axis=-1, keepdims=True))
    # t == 0: the initial condition exactly (with the derivative of the formula)
    at0 = (t == 0.0)[..., None]
    M0s = sgn * jnp.take_along_axis(M0, perm, axis=-1)
    Mg = jnp.where(at0, straight(jnp.broadcast_to(M0s, Mg.shape), Mg), Mg)
    ident = jnp.asarray([1.0, 0.0, 0.0, 0.0], qg.dtype)
    qg = jnp.where(at0, straight(jnp.broadcast_to(ident, qg.shape), qg), qg)
    # back to the input frame: x[perm[k]] = sgn[k] x_sorted[k]
    inv = jnp.broadcast_to(jnp.argsort(perm, axis=-1), shape + (3,))
    sgb = jnp.broadcast_to(sgn, shape + (3,))
    Mo = jnp.take_along_axis(sgb * Mg, inv, axis=-1)
    vo = jnp.take_along_axis(sgb * qg[..., 1:], inv, axis=-1)
    qo = jnp.concatenate([qg[..., :1], vo], axis=-1)

    # relative equilibria (see above)
    qv = jnp.where(pos[..., None], seq[..., None] * axis, 0.5 * t[..., None] * om)
    qeq = jnp.concatenate([jnp.where(pos, ceq, 1.0)[..., None], qv], axis=-1)
    Meq = jnp.broadcast_to(M0, shape + (3,))
    eqb = eq[..., None]
    return jnp.where(eqb, Meq, Mo), jnp.where(eqb, jnp.broadcast_to(qeq, shape + (4,)), qo)


# ---------------------------------------------------------------------------
# full inertia tensors: the principal frame
# ---------------------------------------------------------------------------
@jax.custom_jvp
def _eigh(a):
    """``jnp.linalg.eigh`` whose derivative is finite at repeated eigenvalues (see :func:`exact_motion`)."""
    w, v = jnp.linalg.eigh(a, symmetrize_input=False)
    return w, v  # a plain pair (the JVP rule returns one; eigh's own result type differs across jax versions)


@_eigh.defjvp
def _eigh_jvp(primals, tangents):
    (a,), (da,) = primals, tangents
    w, v = _eigh(a)
    vt = jnp.swapaxes(v, -1, -2)
    b = vt @ (0.5 * (da + jnp.swapaxes(da, -1, -2))) @ v
    dw = jnp.diagonal(b, axis1=-2, axis2=-1)
    gap = w[..., None, :] - w[..., :, None]  # [i, j] = w_j - w_i
    tol = 64.0 * jnp.finfo(w.dtype).eps * jnp.max(jnp.abs(w), axis=-1)[..., None, None]
    ok = jnp.abs(gap) > tol
    F = jnp.where(ok, 1.0 / jnp.where(ok, gap, 1.0), 0.0)
    return (w, v), (dw, v @ (F * b))


def _quat_from_rotation(R):
    """Unit quaternion (components) of a rotation matrix (Shepperd's method, safe square roots)."""
    r00, r01, r02 = R[..., 0, 0], R[..., 0, 1], R[..., 0, 2]
    r10, r11, r12 = R[..., 1, 0], R[..., 1, 1], R[..., 1, 2]
    r20, r21, r22 = R[..., 2, 0], R[..., 2, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    cand = jnp.stack([tr, r00, r11, r22], axis=-1)
    k = jnp.argmax(cand, axis=-1)
    args = (1.0 + tr, 1.0 + r00 - r11 - r22, 1.0 - r00 + r11 - r22, 1.0 - r00 - r11 + r22)
    h = [0.5 * jnp.sqrt(jnp.where(k == i, a, 1.0)) for i, a in enumerate(args)]
    f = [0.25 / hi for hi in h]
    quats = (
        (h[0], (r21 - r12) * f[0], (r02 - r20) * f[0], (r10 - r01) * f[0]),
        ((r21 - r12) * f[1], h[1], (r01 + r10) * f[1], (r02 + r20) * f[1]),
        ((r02 - r20) * f[2], (r01 + r10) * f[2], h[2], (r12 + r21) * f[2]),
        ((r10 - r01) * f[3], (r02 + r20) * f[3], (r12 + r21) * f[3], h[3]),
    )
    return tuple(
        jnp.where(k == 0, quats[0][c], jnp.where(k == 1, quats[1][c], jnp.where(k == 2, quats[2][c], quats[3][c])))
        for c in range(4)
    )


# ---------------------------------------------------------------------------
# the public function
# ---------------------------------------------------------------------------
def _is_tracer(x) -> bool:
    return isinstance(x, jax.core.Tracer)


def normalized(q):
    """``q / |q|`` along the last axis, computed after an exact power-of-two scaling of each quaternion (its
    largest component in [0.5, 1)): no overflow or underflow of ``|q|^2`` for huge or tiny quaternions, and
    the same bits as the unscaled quotient where that one neither overflows nor underflows.

    Examples
    --------
    >>> import jax, numpy as np
    >>> from eulerpoisson.jax.exact import normalized
    >>> with jax.enable_x64(True):
    ...     print(np.asarray(normalized(np.array([1e300, 1e300, 0.0, 0.0]))))
    [0.70710678 0.70710678 0.         0.        ]
    """
    q = jnp.asarray(q)
    big = jax.lax.stop_gradient(jnp.max(jnp.abs(q), axis=-1, keepdims=True))
    e = jnp.where(big > 0.0, jnp.frexp(big)[1], 0)
    q = q * exp2i(-e, q.dtype)
    return q / jnp.sqrt(jnp.sum(q * q, axis=-1, keepdims=True))


def _not_finite(name: str, x, raw) -> InvalidInputError | None:
    """The error for a non-finite concrete ``x`` (``raw``: the input before its cast to the computing dtype)."""
    if np.all(np.isfinite(np.asarray(x))):
        return None
    if raw is not None and np.asarray(x).dtype == np.float32 and not _is_tracer(raw):
        try:
            r = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError):
            r = None
        if r is not None and np.all(np.isfinite(r)):
            return InvalidInputError(
                f"{name} overflows float32 (dtype=jnp.float32): its largest |value| {float(np.max(np.abs(r))):.3g} "
                f"exceeds {float(np.finfo(np.float32).max):.3g}; rescale the problem or compute in float64"
            )
    return InvalidInputError(f"{name} must be finite, got non-finite values (shape {np.shape(x)})")


def check_inputs(inertia, quaternion0, omega0, times, *, tensor: bool, raw=None) -> None:
    """The value checks of :func:`exact_motion` (and :func:`eulerpoisson.jax.integrate`) on concrete inputs.

    A traced input (under ``jit``, ``vmap`` or ``grad``) is not checked: its values are unknown.

    Parameters
    ----------
    inertia, quaternion0, omega0 : arrays
        As given to :func:`exact_motion`, cast to the computing dtype (``inertia`` a tensor when ``tensor``).
    times : sequence of (str, array)
        The time arguments and their names (``t``; ``t_end`` and ``t0``).
    tensor : bool
        Whether ``inertia`` is a (..., 3, 3) tensor.
    raw : mapping of str to array_like, optional
        The inputs before the cast, by name: a finite value that overflows float32 on the cast is then
        reported as such.

    Raises
    ------
    InvalidInertiaError
        ``inertia`` non-finite, not symmetric or not positive definite.
    InvalidInputError
        Non-finite ``quaternion0``, ``omega0`` or times, a zero (or subnormal) ``quaternion0``, an ``omega0`` whose square
        overflows, or an angular momentum ``inertia @ omega0`` that overflows the computing dtype.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.exact import check_inputs
    >>> check_inputs(np.ones(3), np.array([1.0, 0, 0, 0]), np.array([0.0, 0, 1]), [("t", np.zeros(2))], tensor=False)
    >>> check_inputs(np.ones(3), np.zeros(4), np.array([0.0, 0, 1]), [("t", np.zeros(2))], tensor=False)
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: quaternion0 must be a non-zero quaternion (w, x, y, z), got a zero one
    """
    raw = raw or {}
    if not _is_tracer(inertia):
        I = np.asarray(inertia)
        err = _not_finite("inertia", I, raw.get("inertia"))
        if err is not None:
            raise InvalidInertiaError(str(err))
        if tensor:
            scale = np.max(np.abs(I), axis=(-1, -2), keepdims=True)
            asym = np.max(np.abs(I - np.swapaxes(I, -1, -2)) / np.where(scale > 0, scale, 1.0), initial=0.0)
            if asym > 1e-12 * (1e5 if I.dtype == np.float32 else 1.0):
                raise InvalidInertiaError(
                    f"inertia (a tensor of shape {I.shape}) is not symmetric: max |I - I^T| / max |I| = {asym:.3g}"
                )
            ev = np.linalg.eigvalsh(0.5 * (I + np.swapaxes(I, -1, -2)))
        else:
            ev = I
        if np.any(ev <= 0.0):
            bad = ev[np.any(ev <= 0.0, axis=-1)][0]
            what = "principal moments (eigenvalues)" if tensor else "principal moments"
            raise InvalidInertiaError(
                f"inertia must be positive definite: {what} {bad.tolist()}, every one must be > 0"
            )
    for name, x in (("quaternion0", quaternion0), ("omega0", omega0), *times):
        if not _is_tracer(x):
            err = _not_finite(name, x, raw.get(name))
            if err is not None:
                raise err
    if not _is_tracer(quaternion0):
        q = np.asarray(quaternion0)
        if np.any(np.all(q == 0.0, axis=-1)):
            raise InvalidInputError("quaternion0 must be a non-zero quaternion (w, x, y, z), got a zero one")
        if np.any(np.all(np.abs(q) < np.finfo(q.dtype).tiny, axis=-1)):
            raise InvalidInputError(
                "quaternion0 must be a non-zero quaternion (w, x, y, z), got a subnormal one (XLA flushes subnormal "
                "numbers to zero); scale it up"
            )
    if not _is_tracer(omega0):
        w = np.asarray(omega0)
        big = float(np.sqrt(np.finfo(w.dtype).max)) / 4.0
        speed = float(np.max(_speed(w), initial=0.0))
        if speed > big:
            raise InvalidInputError(
                f"omega0 is too large: |omega0| = {speed:.3g} exceeds {big:.3g} (its square must stay finite in "
                f"{w.dtype}); rescale the problem (time unit)"
            )
        if not _is_tracer(inertia):
            I = np.asarray(inertia)
            imax = np.max(np.abs(I), axis=(-1, -2) if tensor else -1)
            with np.errstate(over="ignore"):
                mom = float(np.max(3.0 * imax * _speed(w) if imax.size and w.size else 0.0, initial=0.0))
            if not mom <= float(np.finfo(w.dtype).max):
                raise InvalidInputError(
                    f"the angular momentum inertia @ omega0 overflows {w.dtype} (|I| |omega0| up to {mom / 3.0:.3g}); "
                    "rescale the problem (units)"
                )


def _speed(w):
    """``|w|`` along the last axis (NumPy, concrete), without overflow of the squares."""
    return scaled_norms(np.asarray(w, dtype=np.float64))


def check_phase(omega0, t, what: str = "t", factor: float = 1.0) -> None:
    r"""Refuse :math:`|\Omega_0|\,|t|` beyond ``2^48`` (:data:`MAX_PHASE`), as ``ep.solve(..., method="exact")``.

    ``omega0`` (..., 3) and ``t`` broadcast elementwise (batch shapes); ``factor`` multiplies ``|t|`` (the
    largest fraction of a step a composition flows over). Concrete values only: nothing is checked when
    either is traced.

    Raises
    ------
    InvalidInputError
        When some :math:`|\Omega_0|\,|t|` exceeds ``2^48`` (or overflows).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.exact import check_phase
    >>> check_phase(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0e3]))
    >>> check_phase(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0e15]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: |omega0| |t| = 1e+15 exceeds 2^48 = 2.81e+14 rad: ...
    """
    if _is_tracer(omega0) or _is_tracer(t):
        return
    speed = _speed(omega0)
    tt = np.abs(np.asarray(t, dtype=np.float64)) * factor
    if speed.size == 0 or tt.size == 0:
        return
    with np.errstate(over="ignore", invalid="ignore"):
        phase = np.where(speed == 0.0, 0.0, np.broadcast_to(speed, np.broadcast_shapes(speed.shape, tt.shape)) * tt)
    worst = float(np.max(phase))
    if not worst <= MAX_PHASE:
        raise InvalidInputError(
            f"|omega0| |{what}| = {worst:.3g} exceeds 2^48 = {MAX_PHASE:.3g} rad: the rounding of the frequencies "
            "(a few ulp) already shifts the phase of the motion by more than 0.1 rad, so float64 cannot say where "
            "on its orbit the body is; use shorter times"
        )


@float64_by_default
def exact_motion(inertia, quaternion0, omega0, t, *, dtype=None):
    r"""The exact motion of a free rigid body, in JAX: attitude and body angular velocity at times ``t``.

    The closed form of :mod:`eulerpoisson.solvers.exact.motion` (Jacobi elliptic functions and an
    elliptic integral of the third kind; O(1) per output time, no time stepping) as a pure JAX
    function: it compiles with ``jax.jit``, vectorizes with ``jax.vmap`` and broadcasting, and is
    differentiable (``jax.jacfwd``, ``jax.jacrev``, ``jax.grad``) with respect to every input. With

    .. math::

        \mathbf x_\mathrm{space} = R\,\mathbf x_\mathrm{body},\qquad
        \dot R = R\,[\boldsymbol\Omega]_\times,\qquad
        I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,

    the attitude is :math:`q(t) = q_0 \otimes q_\mathrm{rel}(t)` (Hamilton product, scalar first;
    :math:`q_\mathrm{rel}(0) = 1`), continuous in ``t``. For a full tensor the motion is computed
    in its principal frame :math:`P` (``jnp.linalg.eigh``, made a rotation) and mapped back,
    :math:`R(t) = R_0 P R_P(t) P^T`, :math:`\boldsymbol\Omega = P\boldsymbol\Omega_P`, as
    ``ep.solve(..., method="exact")`` does.

    Parameters
    ----------
    inertia : array_like, shape (..., 3) or (..., 3, 3)
        Principal moments (the body axes are principal axes; any order, all ``> 0``, equal ones
        allowed) or a symmetric positive-definite inertia tensor in the body frame. An array whose
        last two axes are (3, 3) is a tensor.
    quaternion0 : array_like, shape (..., 4)
        Attitude at ``t = 0``, scalar first (normalized here, after an exact scaling: any finite
        non-zero magnitude).
    omega0 : array_like, shape (..., 3)
        Body angular velocity at ``t = 0``.
    t : array_like, any shape
        Times (any sign; empty: empty results). ``t`` has no component axis: the batch shapes of the three other inputs
        and the shape of ``t`` broadcast elementwise (one body at many times: ``t`` of shape
        ``(T,)``; bodies ``(N, 1, 3)`` at times ``(T,)``: results ``(N, T, ...)``).
    dtype : None, jnp.float64 or jnp.float32
        Computing precision (None: float64, see :mod:`eulerpoisson.jax.precision`).

    Returns
    -------
    quaternion : jax.Array, shape broadcast + (4,)
        Unit attitude quaternions (w, x, y, z), body to space.
    omega : jax.Array, shape broadcast + (3,)
        Body angular velocities.

    Raises
    ------
    InvalidInputError
        Wrong shapes (the last axis of ``quaternion0`` not 4, of ``omega0`` not 3), batch shapes
        that do not broadcast, non-numeric input; with concrete values also non-finite
        ``quaternion0``, ``omega0`` or ``t`` (or, with ``dtype=jnp.float32``, finite values that
        overflow float32), a zero ``quaternion0``, an ``omega0`` whose square or angular momentum
        overflows, or :math:`|\Omega_0|\,|t| > 2^{48}` (as ``ep.solve(..., method="exact")``:
        float64 no longer determines the phase of the motion).
    InvalidInertiaError
        ``inertia`` not of shape (..., 3) or (..., 3, 3); with concrete values also non-finite,
        not symmetric or not positive definite (a moment ``<= 0``). The triangle inequalities
        :math:`I_i + I_j \ge I_k` of a physical body are not required (as
        ``ep.solve(..., allow_unphysical=True)``).
    PrecisionError
        When traced with 64-bit floats off and ``dtype`` not float32.

    Values are checked only when the inputs are concrete (an eager call). Under ``jit``, ``vmap``
    or ``grad`` (traced inputs) only the shapes are checked: a NaN or infinite input, a zero
    ``quaternion0``, an inertia that is not positive definite or a phase beyond :math:`2^{48}`
    then gives NaN (or meaningless) outputs without an error. Check the inputs before tracing
    (or call eagerly once) when they may be invalid.

    Notes
    -----
    *Accuracy* (float64): the NumPy reference's, a few ulp times :math:`|\Omega| t` (the
    conditioning of the phase). Measured against ``ep.solve(..., method="exact")`` on the
    reference cases and random bodies (near and on the separatrix, symmetric tops, spheres,
    equilibria, full tensors, negative times): below 1e-14 rad and 1e-14 relative in
    :math:`\Omega` for :math:`|\Omega t| \lesssim 30`, and about :math:`4\varepsilon|\Omega||t|`
    beyond (3.6e-12 rad at :math:`|\Omega| t = 3\cdot10^4`), where the two differ by XLA's and
    the C library's elementary functions (an ulp) amplified by the number of quarter periods.

    *float32* (``dtype=jnp.float32``, the same algorithms in float-float arithmetic): attitude
    errors against float64 on the reference cases at most 1.6e-5 rad at ``t = 10`` and 4.9e-4 rad
    at ``t = 100`` (``fast_spin``, :math:`|\Omega| t = 10^3, 10^4`: the conditioning
    :math:`|\Omega| t\,\varepsilon_{32}`), below 1e-6 and 8e-6 rad on the other cases.

    *Derivatives* are those of the closed form and agree with central differences of the NumPy
    path (to their accuracy, 1e-6 relative) on generic bodies, near the separatrix on both sides and for
    symmetric bodies given as moments; :math:`\partial/\partial t` satisfies the equations of
    motion to round-off. Where the closed form is singular they are finite, not the derivatives
    of the motion: exactly on the separatrix (the derivative with respect to the elliptic
    parameter is not taken: the motion is not differentiable across it at long times), at exact
    relative equilibria (``omega0 = 0`` or along a principal axis, a sphere: the derivative of the
    uniform rotation, which misses the linearized motion transverse to the equilibrium) and for a
    full tensor with repeated eigenvalues (the rotation of the principal axes within the
    degenerate eigenspace is left out).

    *Cost*: each (body, time) costs two Jacobi evaluations and one :math:`R_J`; per body one
    AGM, one :math:`R_F` and three :math:`R_J`. Loops have a fixed length; a duplication step of
    :math:`R_J` that no element of the batch needs is skipped by ``lax.cond`` (inside ``vmap``
    both branches run). Measured on a shared 2-core x86-64 machine (float64, ``jax.jit``):
    compilation about 11 s; 2.7 s for 1000 bodies at 1000 times (the numba kernel of
    ``motion.exact_motion(..., compiled=True)``: 0.4 s) and 10 s for 10^6 bodies at one time
    each (numba: 1.3 s). Compile once and reuse.

    References
    ----------
    .. [1] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., section 37.
    .. [2] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the free rigid
       body motion and its use in splitting methods", SIAM J. Sci. Comput. 30 (2008) 2084-2112.
    .. [3] B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer.
       Algorithms 10 (1995) 13-26.

    Examples
    --------
    >>> import jax, jax.numpy as jnp, numpy as np
    >>> from eulerpoisson.jax.exact import exact_motion
    >>> I = np.array([3.0, 5.0, 8.0])
    >>> q, w = exact_motion(I, [1.0, 0.0, 0.0, 0.0], [0.004, 0.4, 0.0], np.linspace(0.0, 100.0, 5))
    >>> q.shape, w.shape
    ((5, 4), (5, 3))
    >>> E = 0.5 * np.sum(I * np.asarray(w) ** 2, axis=-1)  # conserved
    >>> bool(np.allclose(E, E[0], rtol=1e-14, atol=0))
    True
    >>> with jax.enable_x64(True):  # (traced: 64-bit floats must be on)
    ...     dw = jax.jacfwd(lambda w0: exact_motion(I, [1.0, 0, 0, 0], w0, 1.0)[1])(jnp.array([0.004, 0.4, 0.0]))
    >>> dw.shape
    (3, 3)
    """
    raw = {"inertia": inertia, "quaternion0": quaternion0, "omega0": omega0, "t": t}
    inertia = as_float(inertia, dtype, "inertia")
    q0 = as_float(quaternion0, dtype, "quaternion0")
    w0 = as_float(omega0, dtype, "omega0")
    t = as_float(t, dtype, "t")
    tensor = inertia.ndim >= 2 and inertia.shape[-2:] == (3, 3)
    if inertia.ndim < 1 or (inertia.shape[-1] != 3):
        raise InvalidInertiaError(
            f"inertia must have shape (..., 3) (principal moments) or (..., 3, 3) (a tensor), got shape {inertia.shape}"
        )
    if q0.ndim < 1 or q0.shape[-1] != 4:
        raise InvalidInputError(f"quaternion0 must have shape (..., 4) (w, x, y, z), got shape {q0.shape}")
    if w0.ndim < 1 or w0.shape[-1] != 3:
        raise InvalidInputError(f"omega0 must have shape (..., 3), got shape {w0.shape}")
    bI = inertia.shape[:-2] if tensor else inertia.shape[:-1]
    try:
        shape = jnp.broadcast_shapes(bI, q0.shape[:-1], w0.shape[:-1], t.shape)
    except ValueError as exc:
        raise InvalidInputError(
            f"the batch shapes of inertia {bI}, quaternion0 {q0.shape[:-1]}, omega0 {w0.shape[:-1]} and the shape "
            f"of t {t.shape} do not broadcast"
        ) from exc
    check_inputs(inertia, q0, w0, [("t", t)], tensor=tensor, raw=raw)
    check_phase(w0, t)
    if math.prod(shape) == 0:  # nothing to compute (an empty t or batch)
        return jnp.zeros(tuple(shape) + (4,), dtype), jnp.zeros(tuple(shape) + (3,), dtype)
    return _motion(inertia, q0, w0, t, tensor=tensor, shape=tuple(shape))


@functools.partial(jax.jit, static_argnames=("tensor", "shape"))
def _motion(inertia, q0, w0, t, *, tensor, shape):
    """The computation of :func:`exact_motion` after the checks, compiled once per shape and dtype (an eager
    call then costs one dispatch, not one per operation; inside a user's ``jit`` it is inlined)."""
    q0 = normalized(q0)
    if tensor:
        A = 0.5 * (inertia + jnp.swapaxes(inertia, -1, -2))
        ev, P = _eigh(A)
        c0, c1, c2 = P[..., :, 0], P[..., :, 1], P[..., :, 2]
        det = jnp.sum(c0 * jnp.cross(c1, c2), axis=-1)
        sign = jax.lax.stop_gradient(jnp.where(det < 0.0, -1.0, 1.0))
        P = jnp.concatenate([P[..., :, :2], (sign[..., None] * c2)[..., None]], axis=-1)
        M0 = jnp.einsum("...ij,...j->...i", A, w0)
        Mp0 = jnp.einsum("...ji,...j->...i", P, M0)
        Mp, qr = _keep(_principal_motion(ev, Mp0, t))
        om = jnp.einsum("...ij,...j->...i", P, Mp / ev)
        pw, px, py, pz = _quat_from_rotation(P)
        a = _qmul(pw, px, py, pz, qr[..., 0], qr[..., 1], qr[..., 2], qr[..., 3])
        qr = _qmul(a[0], a[1], a[2], a[3], pw, -px, -py, -pz)
    else:
        Mp, qr4 = _keep(_principal_motion(inertia, inertia * w0, t))
        om = Mp / inertia
        qr = (qr4[..., 0], qr4[..., 1], qr4[..., 2], qr4[..., 3])
    q = _qmul(q0[..., 0], q0[..., 1], q0[..., 2], q0[..., 3], *qr)
    q = _assemble(q, shape)
    return q, jnp.broadcast_to(om, shape + (3,))
