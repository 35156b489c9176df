r"""Elliptic functions and integrals in JAX: the special functions of the closed form.

The algorithms of the NumPy reference (:mod:`eulerpoisson.numerics.jacobi` and
:mod:`eulerpoisson.numerics.carlson`; their docstrings derive them), written with ``jax.numpy``
so that they trace, compile, vectorize and differentiate:

* the complete integral :math:`K(m)` by the arithmetic-geometric mean in double-double arithmetic
  (:func:`ellipk_dd`, public :func:`ellipk`);
* the Jacobi functions ``sn, cn, dn`` of a double-double argument reduced modulo :math:`K`
  exactly, by the descending Landen transformation (on :math:`m` for :math:`m \le 1/2`, on
  :math:`1-m` along the imaginary axis otherwise; :func:`sncndn_dd`, public
  :func:`jacobi_sncndn`);
* Carlson's :math:`R_F` and :math:`R_J` by the duplication theorem (:func:`rf`, :func:`rj`,
  public :func:`elliprf`, :func:`elliprj`).

Differences from the NumPy reference, needed by JAX:

* no loop stops on a traced value: the AGM, the Landen chain and Carlson's duplication run a
  fixed number of steps (enough for every argument, measured: 13 AGM steps at ``m1 = 5e-324``,
  4 Landen levels, 12 ``R_F`` and 16 ``R_J`` duplications), and an element that has converged
  keeps its value (the reference's element-by-element stop, so the values agree);
* a converged AGM step or an unneeded Landen level keeps its value but passes the derivative of
  the step on (:func:`~eulerpoisson.jax.doubledouble.straight`), so derivatives are right also
  where the reference stops at once (``m = 0`` exactly: a symmetric top);
* every branch is computed and selected by ``jnp.where``, with safe arguments in the branch that
  is not selected (no NaN or infinite derivative leaks into the selected one).

In float64 the results agree with the NumPy reference to an ulp or two (XLA's ``sinh``,
``atan``, ``log1p`` differ from the C library's by about an ulp); in float32 the same
algorithms run with float32 thresholds (float-float arithmetic).

References
----------
.. [1] B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer.
   Algorithms 10 (1995) 13-26.
.. [2] NIST Digital Library of Mathematical Functions, chapters 19 and 22,
   https://dlmf.nist.gov/ (19.36, 22.4, 22.6, 22.7).

Examples
--------
>>> import jax.numpy as jnp
>>> from eulerpoisson.jax.elliptic import ellipk, jacobi_sncndn
>>> round(float(ellipk(0.5)), 15)
1.854074677301372
>>> sn, cn, dn = jacobi_sncndn(jnp.array([0.0, 1.0]), 0.5)
>>> [round(float(x), 12) for x in sn]
[0.0, 0.803001824896]
"""

from __future__ import annotations

import functools
import math
import os
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ..errors import InvalidInputError
from .doubledouble import (
    dd_add,
    dd_div,
    dd_mul,
    dd_sqrt,
    exp2i,
    quick_two_sum,
    safe_sqrt,
    straight,
    two_prod,
    two_sum,
)
from .precision import as_float, float64_by_default

__all__ = [
    "Consts",
    "consts",
    "JacobiParams",
    "jacobi_params",
    "sncndn_dd",
    "ellipk_dd",
    "rf",
    "rj",
    "ellipk",
    "jacobi_sncndn",
    "elliprf",
    "elliprj",
]

#: duplication steps of the public elliprj: traced, then tried in turn on concrete arguments
_RJ_PUBLIC_STEPS = (40, 120, 480)

#: batches at least this large take the short R_J loop in the fused form (see :func:`rj`)
_SHORT_MIN = 1024

#: the number of Landen levels (at most 4 are used in float64, 3 in float32)
LANDEN_LEVELS = 4

_SIN_C = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(1, 9))
_COS_C = tuple((-1) ** k / math.factorial(2 * k) for k in range(2, 10))


def fused_loops() -> bool:
    """Whether the loops are unrolled and the batch-wide skips (``lax.cond``) replaced by masked steps.

    On a GPU one fused kernel per evaluation is much faster than a kernel per loop iteration (the
    state of every iteration would go through memory); on the CPU the rolled loops with skips compile
    faster and run as fast. The values are the same either way. Default: fused on any backend but
    the CPU; ``EULERPOISSON_JAX_FUSED=1`` or ``0`` forces the choice (read when a function is traced).

    Examples
    --------
    >>> from eulerpoisson.jax.elliptic import fused_loops
    >>> isinstance(fused_loops(), bool)
    True
    """
    forced = os.environ.get("EULERPOISSON_JAX_FUSED", "")
    if forced in ("0", "1"):
        return forced == "1"
    return jax.default_backend() != "cpu"


class Consts(NamedTuple):
    """Precision-dependent constants (float64: those of the NumPy reference)."""

    pi_hi: float
    pi_lo: float
    pio2_hi: float
    pio2_lo: float
    landen: float  # a Landen level is needed while its parameter exceeds this
    agm_tol: float  # the AGM has converged when |a - b| <= agm_tol a
    agm_up: float  # sqrt(m1) is formed as sqrt(m1 agm_up) agm_down (tiny m1)
    agm_down: float
    agm_steps: int
    m1_sep: float  # orbits with 1 - k^2 below this are the separatrix
    rf_q: float  # Carlson's truncation factors
    rj_q: float
    rf_steps: int
    rj_steps: int
    rc_series: float  # R_C(1, 1 + e) by its series for |e| <= rc_series
    delta_tiny: float  # R_J's (p-x)(p-y)(p-z) is rescaled below this
    eps: float
    rj_closed: int  # the short R_J loop: steps with R_C's closed forms ...
    rj_short: int  # ... and steps in all (see rj)


def _split_const(x: float, dtype) -> tuple[float, float]:
    import numpy as np

    hi = float(np.asarray(x, dtype=dtype))
    return hi, float(np.asarray(x - hi, dtype=dtype))


def consts(dtype) -> Consts:
    """The constants for ``dtype`` (float64 or float32).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.elliptic import consts
    >>> consts(np.float64).agm_steps, consts(np.float32).agm_steps
    (16, 10)
    """
    import numpy as np

    if np.dtype(dtype) == np.float64:
        tol = 2.0**-53
        return Consts(
            3.141592653589793,
            1.2246467991473532e-16,
            1.5707963267948966,
            6.123233995736766e-17,
            2.0**-56,
            2.0**-104,
            2.0**200,
            2.0**-100,
            16,
            1e-200,
            (3.0 * tol) ** (-1.0 / 6.0),
            (0.25 * tol) ** (-1.0 / 6.0),
            14,
            18,
            2.0**-5,
            2.0**-960,
            2.0**-52,
            2,
            9,
        )
    tol = 2.0**-24
    # pi and pi/2 as float-float numbers (the low parts from the float64 value, enough in float32)
    pih, pil = _split_const(math.pi, np.float32)
    pio2h, pio2l = _split_const(0.5 * math.pi, np.float32)
    return Consts(
        pih,
        pil,
        pio2h,
        pio2l,
        2.0**-26,
        2.0**-46,
        2.0**64,
        2.0**-32,
        10,
        1e-30,
        (3.0 * tol) ** (-1.0 / 6.0),
        (0.25 * tol) ** (-1.0 / 6.0),
        10,
        12,
        2.0**-5,
        2.0**-100,
        2.0**-23,
        2,
        6,
    )


def _c(x) -> Consts:
    return consts(jnp.result_type(x))


# ---------------------------------------------------------------------------
# complete integral K by the AGM in double-double
# ---------------------------------------------------------------------------
def ellipk_dd(m1):
    """``K(m)`` as a double-double ``(K_hi, K_lo)`` from ``m1 = 1 - m`` (``m1 == 0``: ``inf, 0``)."""
    C = _c(m1)
    sep = m1 == 0.0
    m1s = jnp.where(sep, 1.0, m1)
    ah = jnp.ones_like(m1s)
    al = jnp.zeros_like(m1s)
    bh, bl = dd_sqrt(m1s * C.agm_up, jnp.zeros_like(m1s))
    bh, bl = bh * C.agm_down, bl * C.agm_down

    def step(_, st):
        ah, al, bh, bl = st
        dh, _dl = dd_add(ah, al, -bh, -bl)
        act = jnp.abs(dh) > C.agm_tol * ah
        sh, sl = dd_add(ah, al, bh, bl)
        ph, pl = dd_mul(ah, al, bh, bl)
        nbh, nbl = dd_sqrt(ph, pl)
        # converged: the value stays, the derivative follows the step (dK/dm at m = 0)
        return (
            jnp.where(act, 0.5 * sh, straight(ah, 0.5 * sh)),
            jnp.where(act, 0.5 * sl, straight(al, 0.5 * sl)),
            jnp.where(act, nbh, straight(bh, nbh)),
            jnp.where(act, nbl, straight(bl, nbl)),
        )

    ah, al, bh, bl = jax.lax.fori_loop(0, C.agm_steps, step, (ah, al, bh, bl))  # (per body: rolled in both forms)
    kh, kl = dd_div(jnp.full_like(ah, C.pi_hi), jnp.full_like(ah, C.pi_lo), ah, al)
    kh, kl = 0.5 * kh, 0.5 * kl
    return jnp.where(sep, jnp.inf, kh), jnp.where(sep, 0.0, kl)


# ---------------------------------------------------------------------------
# Jacobi elliptic functions
# ---------------------------------------------------------------------------
class JacobiParams(NamedTuple):
    """Parameter-only data of the Jacobi functions (see :class:`eulerpoisson.numerics.jacobi.JacobiParams`).

    ``sqm``, ``pcl``: stacks of :data:`LANDEN_LEVELS` arrays (the Landen levels ``sqrt(p_i)``,
    ``1 - p_i``; an unneeded level has ``sqrt(p_i) = 0`` and ``1 - p_i = 1`` in value).
    """

    m: jax.Array
    m1: jax.Array
    kp: jax.Array
    sep: jax.Array
    imag: jax.Array
    kh: jax.Array
    kl: jax.Array
    sqm: jax.Array
    pcl: jax.Array
    ph: jax.Array
    pcorr: jax.Array


def jacobi_params(m, m1) -> JacobiParams:
    """The :class:`JacobiParams` of ``m`` and ``m1 = 1 - m`` (both given, consistent)."""
    C = _c(m)
    kp = safe_sqrt(m1)
    sep = m1 == 0.0
    imag = m > 0.5
    kh, kl = ellipk_dd(m1)
    kh = jnp.where(sep, C.pio2_hi, kh)
    kl = jnp.where(sep, C.pio2_lo, kl)
    pc = jnp.where(imag, m1, m)
    pc1 = jnp.where(imag, m, m1)
    thr = jnp.where(imag, 0.25 * C.landen * kp, C.landen)
    sqs, pcls = [], []
    for _ in range(LANDEN_LEVELS):
        active = pc > thr
        k1 = jnp.sqrt(pc1)
        den = (1.0 + k1) * (1.0 + k1)
        sq_new = pc / den
        pn_new = 4.0 * k1 / den
        # an unneeded level: value 0 (1), the derivative of the level (m = 0 exactly)
        sq = jnp.where(active, sq_new, straight(0.0, sq_new))
        pn1 = jnp.where(active, pn_new, straight(1.0, pn_new))
        sqs.append(sq)
        pcls.append(pn1)
        pc = sq * sq
        pc1 = pn1
    ph = jnp.ones_like(m)
    pl = jnp.zeros_like(m)
    for sq in sqs:
        oh, ol = two_sum(1.0, sq)
        ph, pl = dd_mul(ph, pl, oh, ol)
    return JacobiParams(m, m1, kp, sep, imag, kh, kl, jnp.stack(sqs), jnp.stack(pcls), ph, pl / ph)


def _reduce_quarter(uh, ul, P: JacobiParams):
    """``u = n K + r`` exactly (double-double), ``|r| <~ K/2``; ``n = 0`` where ``P.sep``."""
    n = jnp.where(P.sep, 0.0, jnp.rint(uh / P.kh))
    ph, pl = two_prod(n, P.kh)
    t = uh - ph
    rh, rl = two_sum(t, -pl)
    rl = rl + (ul - n * P.kl)
    rh, rl = quick_two_sum(rh, rl)
    return n, rh, rl


def _sin_poly(x):
    z = x * x
    p = _SIN_C[7]
    for k in range(6, -1, -1):
        p = _SIN_C[k] + z * p
    return x + x * z * p


def _cos_poly(x):
    z = x * x
    p = _COS_C[7]
    for k in range(6, -1, -1):
        p = _COS_C[k] + z * p
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + z * z * p)


def _level(levels, i):
    """Level ``i`` (a Python int in the fused form, else a traced index) of a stack of Landen levels."""
    if isinstance(i, int):
        return levels[i]
    return jax.lax.dynamic_index_in_dim(levels, i, axis=0, keepdims=False)


def _loop(steps, body, state):
    """``lax.fori_loop(0, steps, body, state)``; in the fused form a Python loop (static indices)."""
    if fused_loops():
        for k in range(steps):
            state = body(k, state)
        return state
    return jax.lax.fori_loop(0, steps, body, state)


def _sncndn_ascent(vn, dv, sh, ch, dvi, P: JacobiParams):
    """The Landen ascents, real (``m <= 1/2``; ``vn <= pi/4``, the polynomials) and imaginary (``m > 1/2``, the
    complementary parameter, from ``sh, ch = sinh, cosh`` of the scaled argument), in one loop whose
    coefficients are selected per element: ``(s, c)`` of the level-0 amplitude.

    Real: ``s' = (1 + k) s/(1 + k s^2)``, ``c' = c sqrt(c^2 + k1^2 s^2)/(1 + k s^2)``, with ``y = 1 - c`` kept
    accurate near the real axis; imaginary: ``sigma' = (1 + k) sigma/(1 - k sigma^2)``, ``C' = C sqrt(1 + k^2
    sigma^2)/(1 - k sigma^2)`` (``sn = sigma/C``, ``cn = 1/C``). One square root and one reciprocal per level.
    """
    imag = P.imag
    s0 = _sin_poly(vn)
    c0 = _cos_poly(vn)
    h = _sin_poly(0.5 * vn)
    s = jnp.where(imag, sh + ch * dvi, s0 + c0 * dv)
    c = jnp.where(imag, ch + sh * dvi, c0 - s0 * dv)
    y = jnp.where(imag, 1.0, 2.0 * h * h + s0 * dv)
    sgn = jnp.where(imag, -1.0, 1.0)

    def level(k, st):
        s, c, y = st
        i = LANDEN_LEVELS - 1 - k
        sq = _level(P.sqm, i)
        s2 = s * s
        ry = (y < 0.5) & ~imag
        ce = jnp.where(ry, 1.0 - y, c)
        d = jnp.sqrt(jnp.where(imag, 1.0, ce * ce) + jnp.where(imag, sq * sq, _level(P.pcl, i)) * s2)
        den = 1.0 + sgn * (sq * s2)
        # one reciprocal for 1/den and 1/(1 + d)
        opd = 1.0 + d
        rr = 1.0 / (den * opd)
        r = rr * opd
        use = sq > 0.0
        s_new = (1.0 + sq) * s * r
        c_new = ce * d * r
        y_new = (y + ce * (sq * sq * s2) * (rr * den) + sq * s2) * r
        return (
            jnp.where(use, s_new, straight(s, s_new)),
            jnp.where(use, c_new, straight(c, c_new)),
            jnp.where(use & ~imag, y_new, straight(y, y_new)),
        )

    s, c, y = _loop(LANDEN_LEVELS, level, tuple(jnp.broadcast_arrays(s, c, y, P.m)[:3]))
    rc = 1.0 / jnp.where(imag, c, 1.0)
    return jnp.where(imag, s * rc, s), jnp.where(imag, rc, jnp.where(y < 0.5, 1.0 - y, c))


def _sncndn_core(r, rl, P: JacobiParams):
    """sn, cn, dn of a reduced argument ``r + rl`` (sn signed)."""
    neg = r < 0.0
    # (not jnp.abs: its derivative at r = 0 is 0)
    v = jnp.where(neg, -r, r)
    vl = jnp.where(neg, -rl, rl)
    rph = 1.0 / P.ph
    vq = v * rph
    vn = vq - vq * P.pcorr
    dv = vl * rph
    # each path with safe arguments where the other one (or the separatrix) is used
    vr = jnp.where(P.imag, 0.5, vn)
    vi = jnp.where(P.imag & ~P.sep, vn, 0.5)
    # one expm1 per element for the imaginary path (sinh, cosh of vi <~ 120) and the separatrix (tanh, sech
    # of the unreduced v, any size): with g = exp(-x) - 1, e = exp(-x),
    # sinh x = -g (2 + g)/(2 e), cosh x = (1 + e^2)/(2 e), tanh x = -g (2 + g)/(1 + e^2), sech x = 2 e/(1 + e^2)
    g = jnp.expm1(-jnp.where(P.sep, v, vi))
    gi = jnp.where(P.sep, -0.5, g)  # (safe: e = 1/2)
    ei = 1.0 + gi
    e = 1.0 + g
    ope2 = 1.0 + e * e
    # one reciprocal for 1/(2 ei) and 1/(1 + e^2) (ei >= exp(-120) and e <= 1: no overflow)
    rr = 1.0 / (ei * ope2)
    hi = 0.5 * (rr * ope2)
    s, c = _sncndn_ascent(
        vr,
        jnp.where(P.imag, 0.0, dv),
        -gi * (2.0 + gi) * hi,
        (1.0 + ei * ei) * hi,
        jnp.where(P.imag & ~P.sep, dv, 0.0),
        P,
    )
    s2 = s * s
    d = jnp.sqrt(jnp.where(P.m <= 0.5, 1.0 - P.m * s2, c * c + P.m1 * s2))
    # separatrix m = 1: tanh / sech of the unreduced argument
    den = rr * ei
    sech = 2.0 * e * den
    s = jnp.where(P.sep, -g * (2.0 + g) * den, s)
    c = jnp.where(P.sep, sech, c)
    d = jnp.where(P.sep, sech, d)
    return jnp.where(neg, -s, s), c, d


def _quadrant(n, s, c, d, kp):
    q = jnp.mod(n, 4.0)
    odd = (q == 1.0) | (q == 3.0)
    rd = 1.0 / d
    sn = jnp.where(odd, c * rd, s)
    cn = jnp.where(odd, -(kp * s * rd), c)
    dn = jnp.where(odd, kp * rd, d)
    flip = q >= 2.0
    return jnp.where(flip, -sn, sn), jnp.where(flip, -cn, cn), dn


def sncndn_dd(uh, ul, P: JacobiParams):
    """``(sn, cn, dn, n, r, s, c, d)`` at the double-double argument ``uh + ul``.

    ``n``: the quarter-period index, ``r`` the reduced argument, ``s, c, d`` the values at ``r``.
    """
    n, r, rl = _reduce_quarter(uh, ul, P)
    s, c, d = _sncndn_core(r, rl, P)
    sn, cn, dn = _quadrant(n, s, c, d, P.kp)
    return sn, cn, dn, n, r, s, c, d


# ---------------------------------------------------------------------------
# Carlson's integrals (duplication, a fixed number of steps)
# ---------------------------------------------------------------------------
def _rc1_series(e):
    p = 1.0 / 21.0
    for k in range(9, -1, -1):
        p = (-1.0) ** k / (2 * k + 1) + e * p
    return p


def _rc1(e, y, C: Consts):
    """``R_C(1, y)``, ``y = 1 + e`` (the series for ``|e| <= 2**-5``, else atan / log1p)."""
    small = jnp.abs(e) <= C.rc_series
    pos = (e > 0.0) & ~small
    neg = (e < 0.0) & ~small
    tp = safe_sqrt(jnp.where(pos, e, 1.0))
    tn = safe_sqrt(jnp.where(neg, -e, 1.0))
    yn = jnp.where(neg, y, 1.0)
    vpos = jnp.arctan(tp) / tp
    vneg = 0.5 * jnp.log1p(2.0 * tn * (1.0 + tn) / yn) / tn
    return jnp.where(small, _rc1_series(e), jnp.where(pos, vpos, jnp.where(neg, vneg, 1.0)))


#: the short R_J loop's closed steps: halvings of R_C's argument in each (see _rc1_halved)
_RC_HALVINGS = (3, 2)


def _rc1_halved(e, y, halvings, C: Consts):
    """``(R_C(1, y), ok)``, ``y = 1 + e``, without a transcendental: ``halvings`` times the duplication
    ``g(e) = 2/(1 + s) g(e/(1 + s)^2)``, ``s = sqrt(y)`` (``g(e) = R_C(1, 1 + e)``; ``atan t = 2 atan(t/(1 +
    sqrt(1 + t^2)))`` and the same for ``atanh``), with ``y' = 2 s/(1 + s)`` kept accurate, then the series.
    ``ok``: the argument reached the series' range (elsewhere the value is wrong). Three halvings take
    ``-0.79 <= e <= 3`` (at least) there (the closed forms of :func:`_rc1` cost an ``atan`` and a ``log1p``).
    """
    fac = jnp.ones_like(e)
    for _ in range(halvings):
        s = jnp.sqrt(y)
        r = 1.0 / (1.0 + s)
        fac = fac * (2.0 * r)
        e = e * (r * r)
        y = 2.0 * s * r
    return fac * _rc1_series(e), jnp.abs(e) <= C.rc_series


def rf(x, y, z):
    """Carlson's ``R_F`` for non-negative arguments, at most one zero (no checks)."""
    C = _c(x)
    x, y, z = jnp.broadcast_arrays(x, y, z)
    a0 = (x + y + z) / 3.0
    q = C.rf_q * jnp.maximum(jnp.maximum(jnp.abs(a0 - x), jnp.abs(a0 - y)), jnp.abs(a0 - z))
    q = jax.lax.stop_gradient(q)

    def step(_, st):
        a, fac, x, y, z = st
        act = fac * q >= jnp.abs(a)
        sx, sy, sz = safe_sqrt(x), safe_sqrt(y), safe_sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        new = (0.25 * (a + lam), 0.25 * fac, 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam))
        return tuple(jnp.where(act, nv, ov) for nv, ov in zip(new, st))

    a, fac, *_ = jax.lax.fori_loop(0, C.rf_steps, step, (a0, jnp.ones_like(a0), x, y, z))  # (per body: rolled)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = -(X + Y)
    e2 = X * Y - Z * Z
    e3 = X * Y * Z
    poly = (
        1.0
        - e2 / 10.0
        + e3 / 14.0
        + e2 * e2 / 24.0
        - 3.0 * e2 * e3 / 44.0
        - 5.0 * e2 * e2 * e2 / 208.0
        + 3.0 * e3 * e3 / 104.0
        + e2 * e2 * e3 / 16.0
    )
    return poly / jnp.sqrt(a)


def _frexp_exp(x):
    return jnp.frexp(x)[1]


def _rj_delta(x, y, z, p, C: Consts):
    """``(delta, sc)``: ``(p-x)(p-y)(p-z)`` rescaled by powers of two against underflow (``sc``: the reciprocal
    of the square root of the scaling, a power of two)."""
    f1, f2, f3 = p - x, p - y, p - z
    delta = f1 * f2 * f3
    tiny = (jnp.abs(delta) < C.delta_tiny) & (f1 != 0) & (f2 != 0) & (f3 != 0)
    e1 = jnp.where(tiny & (jnp.abs(f1) < 0.5), -_frexp_exp(f1), 0)
    e2 = jnp.where(tiny & (jnp.abs(f2) < 0.5), -_frexp_exp(f2), 0)
    e1 = e1 + jnp.mod(e1 + e2, 2)
    # (exact scalings by powers of two: jnp.ldexp would be a pow)
    delta = jnp.where(tiny, (f1 * exp2i(e1, f1.dtype)) * (f2 * exp2i(e2, f2.dtype)) * f3, delta)
    sc = jnp.where(tiny, exp2i(-jnp.floor_divide(e1 + e2, 2), delta.dtype), 1.0)
    return delta, sc


def _keep(act, st):
    return st


def _rj_step(act, st, C: Consts, delta, sc, closed=True):
    """One duplication step of ``R_J`` on the elements ``act`` (and ``e``, the argument of its ``R_C``).

    ``closed=False``: ``R_C`` by its series alone (right where ``|e| <= 2**-5``; see :func:`rj`); an int:
    by that many halvings and the series (:func:`_rc1_halved`). Returns the new state and ``e`` (with halvings:
    0 where they sufficed, 1 where not).
    """
    a, fac, x, y, z, p, acc = st
    sx, sy, sz, sp = safe_sqrt(x), safe_sqrt(y), safe_sqrt(z), safe_sqrt(p)
    lam = sx * sy + sy * sz + sz * sx
    d = (sp + sx) * (sp + sy) * (sp + sz)
    rd = 1.0 / d
    rdd = rd * sc
    e = (fac * fac * fac) * delta * (rdd * rdd)
    y1 = 2.0 * sp * (p + lam) * rd
    # the closed forms (atan, log1p: the costly part) only when an element needs them
    if closed is not True and closed:
        rc, ok = _rc1_halved(e, y1, closed, C)
        e = jnp.where(ok, 0.0, 1.0)
    elif not closed:
        rc = _rc1_series(e)
    elif fused_loops():
        rc = _rc1(e, y1, C=C)
    else:
        big = jnp.any(act & (jnp.abs(e) > C.rc_series))
        rc = jax.lax.cond(big, functools.partial(_rc1, C=C), lambda e, y1: _rc1_series(e), e, y1)
    new = (
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        0.25 * (p + lam),
        acc + fac * rc * rd,
    )
    return tuple(jnp.where(act, nv, ov) for nv, ov in zip(new, st)), e


def _rj_start(x, y, z, p, C: Consts):
    a0 = _rj_a0(x, y, z, p)
    delta, sc = _rj_delta(x, y, z, p, C)
    q = C.rj_q * jnp.maximum(
        jnp.maximum(jnp.abs(a0 - x), jnp.abs(a0 - y)),
        jnp.maximum(jnp.abs(a0 - z), jnp.abs(a0 - p)),
    )
    q = jax.lax.stop_gradient(q)
    return (a0, jnp.ones_like(a0), x, y, z, p, jnp.zeros_like(a0)), delta, sc, q


def _rj_end(x, y, z, a0, st):
    a, fac, _, _, _, _, acc = st
    sqa = jnp.sqrt(a)
    ra = 1.0 / (a * sqa)
    fa = fac * (ra * sqa)
    X = (a0 - x) * fa
    Y = (a0 - y) * fa
    Z = (a0 - z) * fa
    Pp = -0.5 * (X + Y + Z)
    xyz = X * Y * Z
    p2 = Pp * Pp
    e2 = X * Y + X * Z + Y * Z - 3.0 * p2
    e3 = xyz + 2.0 * e2 * Pp + 4.0 * p2 * Pp
    e4 = (2.0 * xyz + e2 * Pp + 3.0 * p2 * Pp) * Pp
    e5 = xyz * p2
    # (constant coefficients: multiplications, not divisions)
    poly = (
        1.0
        - (3.0 / 14.0) * e2
        + (1.0 / 6.0) * e3
        + (9.0 / 88.0) * (e2 * e2)
        - (3.0 / 22.0) * e4
        - (9.0 / 52.0) * (e2 * e3)
        + (3.0 / 26.0) * e5
    )
    return fac * poly * ra + 6.0 * acc


def _rj_all(x, y, z, p, C: Consts, steps=None, converged=False):
    """``R_J`` by the full loop: ``C.rj_steps`` (or ``steps``) steps, each with the closed forms of ``R_C`` where
    needed; with ``converged``, also whether the steps sufficed (enough for the closed form's arguments, not for
    every argument: ``p`` far above ``x, y, z`` falls only 4-fold per step)."""
    st, delta, sc, q = _rj_start(x, y, z, p, C)

    def body(_, st):
        # a step that no element needs is skipped (a branch on the whole batch: the values are those
        # of the elementwise stop; under vmap both branches run, with the same values)
        act = st[1] * q >= jnp.abs(st[0])
        if fused_loops():
            return _rj_step(act, st, C=C, delta=delta, sc=sc)[0]
        step = functools.partial(_rj_step, C=C, delta=delta, sc=sc)
        return jax.lax.cond(jnp.any(act), lambda act, st: step(act, st)[0], _keep, act, st)

    # rolled in both forms: in the fused one it serves the per-body constants and the few elements the short
    # loop leaves (unrolled, its 18 steps with their closed forms, twice, took a quarter of the compilation)
    st = jax.lax.fori_loop(0, C.rj_steps if steps is None else steps, body, st)
    value = _rj_end(x, y, z, _rj_a0(x, y, z, p), st)
    if converged:
        return value, st[1] * q < jnp.abs(st[0])
    return value


def _rj_a0(x, y, z, p):
    return (x + y + z + 2.0 * p) * 0.2


def _rj_short(x, y, z, p, C: Consts):
    """The common case in fewer operations: ``(value, redo)``.

    ``C.rj_closed`` steps with ``R_C`` by halvings of its argument and its series (:data:`_RC_HALVINGS`;
    no transcendental), then series-only steps up to ``C.rj_short`` in all. Where neither sufficed
    (``redo``: an argument out of reach of the halvings, a later step with ``|e| > 2**-5``, or not
    converged), the value is wrong and the element must be recomputed by :func:`_rj_all`; elsewhere it
    is the value of :func:`_rj_all` to an ulp or two (the same steps, ``R_C`` computed otherwise).
    """
    st, delta, sc, q = _rj_start(x, y, z, p, C)
    redo = jnp.zeros(x.shape, bool)
    for k in range(C.rj_short):
        act = st[1] * q >= jnp.abs(st[0])
        closed = _RC_HALVINGS[min(k, len(_RC_HALVINGS) - 1)] if k < C.rj_closed else False
        st, e = _rj_step(act, st, C=C, delta=delta, sc=sc, closed=closed)
        redo = redo | (act & (jnp.abs(e) > C.rc_series))
    redo = redo | (st[1] * q >= jnp.abs(st[0]))
    return _rj_end(x, y, z, _rj_a0(x, y, z, p), st), redo


def rj(x, y, z, p):
    """Carlson's ``R_J`` for ``x, y, z >= 0`` (at most one zero), ``p > 0`` (no checks).

    In the fused form (GPUs) a large batch takes the short loop of :func:`_rj_short` (``R_J``'s
    duplication shrinks the argument ``e`` of its ``R_C`` terms 64-fold per step: the closed forms
    matter in the first steps only, where halvings of ``e`` and the series replace them, and 8 steps
    suffice for almost every argument) and recomputes the
    few elements that need more with the full loop (gathered into a buffer of 1/16 of the batch; the
    whole batch again if they do not fit). Which loop gives an element's value depends on that
    element alone, never on the rest of the batch (the two agree to an ulp or two: XLA contracts
    multiply-adds by context).
    """
    C = _c(x)
    x, y, z, p = jnp.broadcast_arrays(x, y, z, p)
    n = math.prod(x.shape)
    if not fused_loops() or n < _SHORT_MIN:
        return _rj_all(x, y, z, p, C)
    val, redo = _rj_short(x, y, z, p, C)
    shape = x.shape
    flat = [a.reshape(-1) for a in (x, y, z, p, val)]
    redo = redo.reshape(-1)
    nbuf = max(_SHORT_MIN // 16, n // 16)
    (idx,) = jnp.nonzero(redo, size=nbuf, fill_value=n)
    xs, ys, zs, ps = (a.at[idx].get(mode="clip") for a in flat[:4])
    patched = flat[4].at[idx].set(_rj_all(xs, ys, zs, ps, C), mode="drop")
    count = jnp.sum(redo)
    xf, yf, zf, pf = flat[:4]
    res = jax.lax.cond(count > nbuf, lambda: jnp.where(redo, _rj_all(xf, yf, zf, pf, C), flat[4]), lambda: patched)
    return res.reshape(shape)


# ---------------------------------------------------------------------------
# public functions (checked arguments)
# ---------------------------------------------------------------------------
def _concrete(*xs) -> bool:
    return not any(isinstance(x, jax.core.Tracer) for x in xs)


def _check(cond, message):
    if not bool(jnp.all(cond)):
        raise InvalidInputError(message)


def _param(m, dtype):
    m = as_float(m, dtype, "m")
    if _concrete(m):
        _check(jnp.isfinite(m) & (m >= 0.0) & (m <= 1.0), f"parameter m must lie in [0, 1], got {m}")
    return m


@float64_by_default
def ellipk(m, *, dtype=None):
    r"""Complete elliptic integral of the first kind :math:`K(m)` (differentiable).

    .. math:: K(m) = \int_0^{\pi/2} \frac{d\theta}{\sqrt{1 - m\sin^2\theta}}
                   = \frac{\pi}{2\,\mathrm{AGM}(1, \sqrt{1-m})}

    Parameters
    ----------
    m : array_like
        Parameter in ``[0, 1]``, any shape.
    dtype : None, jnp.float64 or jnp.float32
        Computing precision (None: float64).

    Returns
    -------
    jax.Array
        ``K`` (``inf`` at ``m = 1``), shape of ``m``.

    Raises
    ------
    InvalidInputError
        If a (concrete) ``m`` lies outside ``[0, 1]`` or is not finite.

    Examples
    --------
    >>> import jax
    >>> from eulerpoisson.jax.elliptic import ellipk
    >>> with jax.enable_x64(True):  # (traced: 64-bit floats must be on)
    ...     dk = jax.grad(ellipk)(0.0)
    >>> round(float(dk), 15)  # pi/8
    0.392699081698724
    """
    m = _param(m, dtype)
    kh, _ = ellipk_dd(1.0 - m)
    return kh


@float64_by_default
def jacobi_sncndn(u, m, *, dtype=None):
    r"""Jacobi elliptic functions :math:`\mathrm{sn}(u|m), \mathrm{cn}(u|m), \mathrm{dn}(u|m)`.

    The argument is reduced modulo :math:`K` in double-double arithmetic and the functions come
    from the descending Landen transformation (DLMF 22.7); a few ulp for every ``0 <= m <= 1``.

    Parameters
    ----------
    u : array_like
        Real argument.
    m : array_like
        Parameter in ``[0, 1]`` (broadcasts with ``u``).
    dtype : None, jnp.float64 or jnp.float32
        Computing precision (None: float64).

    Returns
    -------
    sn, cn, dn : jax.Array
        Broadcast shape of ``u`` and ``m``.

    Raises
    ------
    InvalidInputError
        If a (concrete) ``m`` lies outside ``[0, 1]`` or an input is not finite.

    Examples
    --------
    >>> from eulerpoisson.jax.elliptic import jacobi_sncndn
    >>> [round(float(x), 12) for x in jacobi_sncndn(1.0, 0.0)]
    [0.841470984808, 0.540302305868, 1.0]
    """
    u = as_float(u, dtype, "u")
    if _concrete(u):
        _check(jnp.isfinite(u), "u must be finite")
    m = _param(m, dtype)
    u, m = jnp.broadcast_arrays(u, m)
    P = jacobi_params(m, 1.0 - m)
    sn, cn, dn, *_ = sncndn_dd(u, jnp.zeros_like(u), P)
    return sn, cn, dn


def _carlson_args(names, values, dtype):
    out = [as_float(v, dtype, n) for n, v in zip(names, values)]
    if _concrete(*out):
        for n, v in zip(names, out):
            _check(jnp.isfinite(v) & (v >= 0.0), f"{n} must be finite and >= 0, got {v}")
        zeros = sum((v == 0.0).astype(int) for v in out[:3])
        _check(zeros <= 1, f"at most one of {', '.join(names[:3])} may be zero")
    return out


@float64_by_default
def elliprf(x, y, z, *, dtype=None):
    r"""Carlson's symmetric integral of the first kind (duplication, a few ulp).

    .. math:: R_F(x,y,z) = \frac12\int_0^\infty \frac{dt}{\sqrt{(t+x)(t+y)(t+z)}}

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one of them zero (broadcast together).
    dtype : None, jnp.float64 or jnp.float32
        Computing precision (None: float64).

    Returns
    -------
    jax.Array

    Raises
    ------
    InvalidInputError
        On negative or non-finite (concrete) arguments, or two zeros.

    Examples
    --------
    >>> from eulerpoisson.jax.elliptic import elliprf
    >>> round(float(elliprf(0.0, 0.5, 1.0)), 15)  # K(1/2)
    1.854074677301372
    """
    x, y, z = _carlson_args(("x", "y", "z"), (x, y, z), dtype)
    return rf(x, y, z)


@float64_by_default
def elliprj(x, y, z, p, *, dtype=None):
    r"""Carlson's symmetric integral of the third kind, ``p > 0`` (duplication, a few ulp).

    .. math:: R_J(x,y,z,p) = \frac32\int_0^\infty \frac{dt}{(t+p)\sqrt{(t+x)(t+y)(t+z)}}

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one zero.
    p : array_like
        Positive.
    dtype : None, jnp.float64 or jnp.float32
        Computing precision (None: float64).

    Returns
    -------
    jax.Array
        ``R_J``. Concrete arguments take as many duplication steps as they need (up to 480); traced
        ones (under ``jit``/``grad``) a fixed 40, enough unless ``p`` exceeds ``max(x, y, z)`` by about
        ``1e16``: NaN there, never a wrong number.

    Raises
    ------
    InvalidInputError
        On negative or non-finite (concrete) arguments, ``p <= 0`` or two zeros among ``x, y, z``; when
        480 steps do not converge (``p`` above ``max(x, y, z)`` by more than about ``1e280``).

    Examples
    --------
    >>> from eulerpoisson.jax.elliptic import elliprj
    >>> round(float(elliprj(1.0, 1.0, 1.0, 1.0)), 15)
    1.0
    """
    x, y, z, p = _carlson_args(("x", "y", "z", "p"), (x, y, z, p), dtype)
    x, y, z, p = jnp.broadcast_arrays(x, y, z, p)
    C = _c(x)
    if not _concrete(x, y, z, p):
        # traced: a fixed number of steps; NaN where they do not suffice (p above x, y, z by more than ~1e6)
        value, ok = _rj_all(x, y, z, p, C, steps=_RJ_PUBLIC_STEPS[0], converged=True)
        return jnp.where(ok, value, jnp.nan)
    _check(p > 0.0, f"p must be > 0 (no principal values), got {p}")
    for steps in _RJ_PUBLIC_STEPS:
        value, ok = _rj_all(x, y, z, p, C, steps=steps, converged=True)
        if bool(jnp.all(ok)):
            return value
    raise InvalidInputError(
        "elliprj: the arguments are too far apart for the duplication to converge "
        f"(p / max(x, y, z) up to {float(jnp.max(p / jnp.maximum(jnp.maximum(x, y), z))):.3g}; "
        f"{_RJ_PUBLIC_STEPS[-1]} steps)"
    )
