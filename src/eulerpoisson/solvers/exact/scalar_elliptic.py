r"""Compiled scalar elliptic kernels of the exact method (private): double-double, Carlson, Jacobi.

The elliptic machinery of the scalar kernel :mod:`eulerpoisson.solvers.exact.scalar`,
shared with the lane kernel :mod:`eulerpoisson.solvers.exact.lanes` and the
Lagrange top (:mod:`eulerpoisson.solvers.exact.lagrange_kernels`): a scalar
transcription of :mod:`eulerpoisson.numerics.elliptic` (Jacobi elliptic
functions by a double-double reduction modulo the quarter period and the
descending Landen transformation, Carlson's ``R_F`` and ``R_J`` by
duplication; see that module for the mathematics and the references).  Every
floating-point operation is performed in the same order on the same operands
as there, only per element instead of per array.  Compiled with numba
(``error_model="numpy"`` so that IEEE semantics hold, no ``fastmath``: no
contraction into fused multiply-adds, which would break the error-free
transformations of the double-double arithmetic; the only explicit fused
multiply-add forms the exact error of a product inside the AGM, where it is
bitwise equal to Dekker's product, see ``_two_prod_f``).

Independent iterations run interleaved (their latency chains overlap): the
AGM for ``K``, the Landen chain and the ``R_F`` of the initial phase in one
loop (:func:`params`); the Jacobi functions at up to three arguments in one
Landen ascent (:func:`sncndn3`); up to three ``R_J`` in one duplication loop
(:func:`rj3`).  Each interleaved iteration keeps its own stopping rule, so
the results are those of the stand-alone algorithms, bit for bit.  The
``R_C`` terms of the ``R_J`` duplication use the series of ``atan(t)/t`` for
``|e| <= 2**-5`` (``elliptic.rc1_series``; all steps but the first one or two).

The small helpers are compiled with ``forceinline``: a call from one compiled
function to another is otherwise an indirect call, which LLVM can neither
inline nor vectorize; square roots are the ``llvm.sqrt`` intrinsic
(:func:`fast_sqrt`; numba's ``math.sqrt`` is a call to the C library's).
The functions are plain Python when numba is not used (correct, bitwise
equal, but slow). :func:`params` and :func:`sncndn3` read and write the
per-body state ``cst`` through the named offsets of
:mod:`eulerpoisson.solvers.exact.state`.

References
----------
.. [1] B. C. Carlson, "Numerical computation of real or complex elliptic
   integrals", Numer. Algorithms 10 (1995) 13-26.
.. [2] T. J. Dekker, "A floating-point technique for extending the available
   precision", Numer. Math. 18 (1971) 224-242.
.. [3] DLMF chapters 19 and 22, https://dlmf.nist.gov/.
"""

from __future__ import annotations

import math

import numpy as np

from ...numerics.doubledouble import dd_add as dd_add
from ...numerics.doubledouble import dd_mul as dd_mul
from ...numerics.doubledouble import quick_two_sum as quick_two_sum
from ...numerics.doubledouble import split as _split
from ...numerics.doubledouble import two_prod as two_prod
from ...numerics.doubledouble import two_sum as two_sum
from ...numerics.elliptic import RC_SERIES_MAX as RC_SERIES_MAX
from ...numerics.elliptic import SINCOS_POLY_MAX as SINCOS_POLY_MAX
from ...numerics.elliptic import cos_poly as cos_poly
from ...numerics.elliptic import rc1_series as rc1_series
from ...numerics.elliptic import sin_poly as sin_poly
from ...util.jit import USE_NUMBA  # numba importable and EULERPOISSON_NO_NUMBA not "1"
from .state import C_KH, C_KL, C_KP, C_M, C_M1, C_NLEV, C_PCL, C_PCORR, C_PH, C_SEP, C_SQM, MAX_LANDEN

__all__ = [
    "lib_hypot",
    "dd_add",
    "dd_mul",
    "quick_two_sum",
    "two_prod",
    "two_sum",
    "dd_mul_f",
    "dd_div_f",
    "dd_sqrt_f",
    "fast_sqrt",
    "rf_poly",
    "rc1",
    "rc1_series",
    "rj_init",
    "rj_finish",
    "rj3",
    "rj1",
    "params",
    "sech_real",
    "sin_poly",
    "cos_poly",
    "reduce",
    "real_level",
    "imag_level",
    "dn_from_sc",
    "quadrant",
    "sncndn3",
]

# --- numerical constants: identical to those of numerics.elliptic / motion ----------
PI_HI = 3.141592653589793
PI_LO = 1.2246467991473532e-16
PIO2_HI = 1.5707963267948966
PIO2_LO = 6.123233995736766e-17
LANDEN_THRESHOLD = 2.0**-56
MAX_AGM = 60
MAX_DUPLICATION = 200
_R_TOL = 2.0**-53
RF_QFAC: float = (3.0 * _R_TOL) ** (-1.0 / 6.0)
RDJ_QFAC: float = (0.25 * _R_TOL) ** (-1.0 / 6.0)
TWO200 = 2.0**200
TWOM100 = 2.0**-100
TWOM104 = 2.0**-104


# =============================================================================
# double-double primitives (Dekker 1971), scalar
# =============================================================================
# Variants with the exact product ``a*b - fl(a*b)`` formed by a fused
# multiply-add when compiled.  Without underflow of the error term Dekker's
# product is exact as well, so both give the same bits; they are used only
# in the AGM, whose operands are >= 1e-100 (m1 >= 1e-200 and the 2**200
# scaling), where that holds.  The plain-Python version is Dekker's.
def _two_prod_f(a, b):
    return two_prod(a, b)


def dd_mul_f(ah, al, bh, bl):
    p, e = _two_prod_f(ah, bh)
    e = e + (ah * bl + al * bh)
    return quick_two_sum(p, e)


def _dd_mul_d_f(ah, al, b):
    p, e = _two_prod_f(ah, b)
    e = e + al * b
    return quick_two_sum(p, e)


def dd_div_f(ah, al, bh, bl):
    q1 = ah / bh
    ph, pl = _dd_mul_d_f(bh, bl, q1)
    rh, rl = dd_add(ah, al, -ph, -pl)
    q2 = rh / bh
    ph, pl = _dd_mul_d_f(bh, bl, q2)
    rh, rl = dd_add(rh, rl, -ph, -pl)
    q3 = rh / bh
    q1, q2 = quick_two_sum(q1, q2)
    return dd_add(q1, q2, q3, 0.0 * q3)


def dd_sqrt_f(ah, al):
    x = fast_sqrt(ah)
    if x > 0.0:
        p, e = _two_prod_f(x, x)
        corr = ((ah - p) - e + al) / (2.0 * x)
    else:
        corr = 0.0
    return quick_two_sum(x, corr)


def lib_hypot(x, y):
    """The C library's ``hypot(x, y)`` (compiled: numba's ``math.hypot`` calls it; in Python, NumPy's scalar
    ``hypot`` calls it, while Python's ``math.hypot`` has an algorithm of its own that can differ by an ulp)."""
    return float(np.hypot(x, y))


def fast_sqrt(x):
    """Correctly rounded square root (compiled: the ``llvm.sqrt`` intrinsic, which vectorizes; numba's
    ``math.sqrt`` is a call to the C library's ``sqrt``, which LLVM does not always turn into one)."""
    return math.sqrt(x)


# =============================================================================
# Carlson integrals (duplication; same truncation as _elliptic)
# =============================================================================
def rf_poly(a0, x0, y0, a, fac):
    """Truncated series of ``R_F`` after the duplication (DLMF 19.36.1)."""
    X = (a0 - x0) * fac / a
    Y = (a0 - y0) * fac / a
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
    return poly / fast_sqrt(a)


def rc1(e, sp, p, lam, d):
    """``R_C(1, 1 + e)`` (``elliptic.rc1``): the series for ``|e| <= 2**-5``,
    else the closed forms; ``1 + e = 2 sqrt(p) (p + lam) / d`` is formed only
    where it is used (``e < 0``)."""
    if abs(e) <= RC_SERIES_MAX:
        return rc1_series(e)
    t = fast_sqrt(abs(e))
    if e > 0.0:
        return math.atan(t) / t
    y = 2.0 * sp * (p + lam) / d
    return 0.5 * math.log1p(2.0 * t * (1.0 + t) / y) / t


def rj_init(x0, y0, z0, p0):
    """``(A_0, delta, sc, Q)`` of the ``R_J`` duplication (``delta, sc`` as ``elliptic._rj_delta``)."""
    a0 = (x0 + y0 + z0 + 2.0 * p0) / 5.0
    f1 = p0 - x0
    f2 = p0 - y0
    f3 = p0 - z0
    delta = f1 * f2 * f3
    sc = 1.0
    if abs(delta) < 2.0**-960 and f1 != 0.0 and f2 != 0.0 and f3 != 0.0:
        e1 = -math.frexp(f1)[1] if abs(f1) < 0.5 else 0
        e2 = -math.frexp(f2)[1] if abs(f2) < 0.5 else 0
        e1 = e1 + (e1 + e2) % 2
        delta = math.ldexp(f1, e1) * math.ldexp(f2, e2) * f3
        sc = math.ldexp(1.0, (e1 + e2) // 2)
    q = RDJ_QFAC * max(max(abs(a0 - x0), abs(a0 - y0)), max(abs(a0 - z0), abs(a0 - p0)))
    return a0, delta, sc, q


def _rj_step(a, fac, x, y, z, p, acc, delta, sc):
    """One duplication step of ``R_J`` with its ``R_C`` term (``elliptic._rj_step``)."""
    sx = fast_sqrt(x)
    sy = fast_sqrt(y)
    sz = fast_sqrt(z)
    sp = fast_sqrt(p)
    lam = sx * sy + sy * sz + sz * sx
    d = (sp + sx) * (sp + sy) * (sp + sz)
    dd = d * sc
    e = (fac * fac * fac) * delta / (dd * dd)
    acc = acc + fac * rc1(e, sp, p, lam, d) / d
    return (
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        0.25 * (p + lam),
        acc,
    )


def rj_finish(a0, x0, y0, z0, a, fac, acc):
    """Truncated series after the duplication (DLMF 19.36.ii)."""
    X = (a0 - x0) * fac / a
    Y = (a0 - y0) * fac / a
    Z = (a0 - z0) * fac / a
    P = -(X + Y + Z) / 2.0
    xyz = X * Y * Z
    p2 = P * P
    e2 = X * Y + X * Z + Y * Z - 3.0 * p2
    e3 = xyz + 2.0 * e2 * P + 4.0 * p2 * P
    e4 = (2.0 * xyz + e2 * P + 3.0 * p2 * P) * P
    e5 = xyz * p2
    poly = (
        1.0
        - 3.0 * e2 / 14.0
        + e3 / 6.0
        + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
    )
    return fac * poly / (a * fast_sqrt(a)) + 6.0 * acc


def rj3(xa, ya, za, pa, on_a, xb, yb, zb, pb, on_b, xc, yc, zc, pc, on_c):
    """Up to three independent ``R_J`` values (lanes ``on_*``), duplications interleaved.

    Every lane performs exactly the operations of ``elliptic.rj_core`` and stops
    by its own criterion.  Lanes that are off return 0.
    """
    a0a, dla, sca, qa = rj_init(xa, ya, za, pa)
    a0b, dlb, scb, qb = rj_init(xb, yb, zb, pb)
    a0c, dlc, scc, qc = rj_init(xc, yc, zc, pc)
    A_a, fa, x_a, y_a, z_a, p_a, ca = a0a, 1.0, xa, ya, za, pa, 0.0
    A_b, fb, x_b, y_b, z_b, p_b, cb = a0b, 1.0, xb, yb, zb, pb, 0.0
    A_c, fc, x_c, y_c, z_c, p_c, cc = a0c, 1.0, xc, yc, zc, pc, 0.0
    run_a = on_a
    run_b = on_b
    run_c = on_c
    for _ in range(MAX_DUPLICATION):
        if run_a:
            if fa * qa >= abs(A_a):
                A_a, fa, x_a, y_a, z_a, p_a, ca = _rj_step(A_a, fa, x_a, y_a, z_a, p_a, ca, dla, sca)
            else:
                run_a = False
        if run_b:
            if fb * qb >= abs(A_b):
                A_b, fb, x_b, y_b, z_b, p_b, cb = _rj_step(A_b, fb, x_b, y_b, z_b, p_b, cb, dlb, scb)
            else:
                run_b = False
        if run_c:
            if fc * qc >= abs(A_c):
                A_c, fc, x_c, y_c, z_c, p_c, cc = _rj_step(A_c, fc, x_c, y_c, z_c, p_c, cc, dlc, scc)
            else:
                run_c = False
        if not (run_a or run_b or run_c):
            break
    ra = rj_finish(a0a, xa, ya, za, A_a, fa, ca) if on_a else 0.0
    rb = rj_finish(a0b, xb, yb, zb, A_b, fb, cb) if on_b else 0.0
    rc = rj_finish(a0c, xc, yc, zc, A_c, fc, cc) if on_c else 0.0
    return ra, rb, rc


# =============================================================================
# parameter set-up: K (AGM in double-double), Landen chain and the R_F of the
# initial phase, interleaved
# =============================================================================


def rj1(x, y, z, p):
    """One ``R_J(x, y, z, p)`` by :func:`rj3` (its other two jobs off): the same operations as a job of three."""
    # computed flags (x < x is False, NaN included): literal True/False would compile rj3 once more per pattern
    off = x < x
    r, _, _ = rj3(x, y, z, p, not off, 0.0, 0.0, 0.0, 0.0, off, 0.0, 0.0, 0.0, 0.0, off)
    return r


def params(m, m1, rx, ry, rz, do_rf, cst):
    """Parameter data of the Jacobi kernels into ``cst``; returns ``R_F(rx, ry, rz)``.

    Three independent iterations run interleaved in one loop, each with its
    own stopping rule and iteration limit, so that their latency chains
    overlap; each performs exactly the operations of its stand-alone version:
    the AGM for ``K`` in double-double (``elliptic._ellipk_dd``), the
    descending Landen chain (``elliptic.jacobi_params``) and the duplication
    of ``R_F`` (if ``do_rf``).  Returns the ``R_F`` value (0 if not
    ``do_rf``).
    """
    kp = fast_sqrt(m1)
    sep = m1 == 0.0
    # AGM state: a = 1, b = sqrt(m1) (double-double, scaled against underflow)
    agm_on = not sep
    ah = 1.0
    al = 0.0
    bh = 0.0
    bl = 0.0
    if agm_on:
        bh, bl = dd_sqrt_f(m1 * TWO200, 0.0)
        bh, bl = bh * TWOM100, bl * TWOM100
    # Landen chain on p = m (real path) or p = m1 (imaginary path, m > 1/2)
    if m > 0.5:
        pc = m1
        pc1 = m
        thr = 0.25 * LANDEN_THRESHOLD * kp
    else:
        pc = m
        pc1 = m1
        thr = LANDEN_THRESHOLD
    lan_on = True
    nlev = 0
    # R_F duplication
    rf_on = do_rf
    ra0 = (rx + ry + rz) / 3.0
    rq = RF_QFAC * max(max(abs(ra0 - rx), abs(ra0 - ry)), abs(ra0 - rz))
    ra = ra0
    rfac = 1.0
    x = rx
    y = ry
    z = rz
    for it in range(MAX_DUPLICATION):
        if agm_on:
            if it < MAX_AGM:
                dh, _dl = dd_add(ah, al, -bh, -bl)
                if abs(dh) > TWOM104 * ah:
                    sh, sl = dd_add(ah, al, bh, bl)
                    ph, pl = dd_mul_f(ah, al, bh, bl)
                    bh, bl = dd_sqrt_f(ph, pl)
                    ah, al = 0.5 * sh, 0.5 * sl
                else:
                    agm_on = False
            else:
                agm_on = False
        if lan_on:
            if it < MAX_LANDEN and pc > thr:
                kq = fast_sqrt(pc1)
                den = (1.0 + kq) * (1.0 + kq)
                sq = pc / den
                pn1 = 4.0 * kq / den
                cst[C_SQM + nlev] = sq
                cst[C_PCL + nlev] = pn1
                nlev += 1
                pc = sq * sq
                pc1 = pn1
            else:
                lan_on = False
        if rf_on:
            if rfac * rq >= abs(ra):
                sx = fast_sqrt(x)
                sy = fast_sqrt(y)
                sz = fast_sqrt(z)
                lam = sx * sy + sy * sz + sz * sx
                ra = 0.25 * (ra + lam)
                rfac = 0.25 * rfac
                x = 0.25 * (x + lam)
                y = 0.25 * (y + lam)
                z = 0.25 * (z + lam)
            else:
                rf_on = False
        if not (agm_on or lan_on or rf_on):
            break
    if sep:
        kh = PIO2_HI
        kl = PIO2_LO
    else:
        kh, kl = dd_div_f(PI_HI, PI_LO, ah, al)
        kh = 0.5 * kh
        kl = 0.5 * kl
    ph = 1.0
    pl = 0.0
    for i in range(nlev):
        oh, ol = two_sum(1.0, cst[C_SQM + i])
        ph, pl = dd_mul(ph, pl, oh, ol)
    cst[C_KP] = kp
    cst[C_KH] = kh
    cst[C_KL] = kl
    cst[C_PH] = ph
    cst[C_PCORR] = pl / ph
    cst[C_NLEV] = nlev
    if do_rf:
        return rf_poly(ra0, rx, ry, ra, rfac)
    return 0.0


# =============================================================================
# Jacobi elliptic functions of double-double arguments, up to three at once
# (``elliptic.sncndn_dd``: reduction modulo K, Landen ascent, quarter map)
# =============================================================================
def sech_real(x):
    e = math.exp(-abs(x))
    return 2.0 * e / (1.0 + e * e)


def reduce(uh, ul, sep, kh, kl, ph, pcorr):
    """``u = n K + r``; returns ``n, r, neg, v = |r|, vn, dv`` (argument at the chain's bottom)."""
    n = 0.0 if sep else np.rint(uh / kh)
    p, pe = two_prod(n, kh)
    t = uh - p
    rh, rl = two_sum(t, -pe)
    rl = rl + (ul - n * kl)
    r, rl = quick_two_sum(rh, rl)
    neg = r < 0.0
    v = abs(r)
    vl = -rl if neg else rl
    vq = v / ph
    vn = vq - vq * pcorr
    dv = vl / ph
    return n, r, neg, v, vn, dv


def _real_start(vn, dv):
    if vn <= SINCOS_POLY_MAX:
        # (the reduced argument is at most about pi/4: always, but for safety)
        s0 = sin_poly(vn)
        c0 = cos_poly(vn)
        h = sin_poly(0.5 * vn)
    else:
        s0 = math.sin(vn)
        c0 = math.cos(vn)
        h = math.sin(0.5 * vn)
    return s0 + c0 * dv, c0 - s0 * dv, 2.0 * h * h + s0 * dv


def real_level(s, c, y, sq, pc):
    """One Landen step up on the real axis, carrying ``y = 1 - cn``."""
    s2 = s * s
    ce = 1.0 - y if y < 0.5 else c
    d = fast_sqrt(ce * ce + pc * s2)
    den = 1.0 + sq * s2
    s_new = (1.0 + sq) * s / den
    c_new = ce * d / den
    y_new = (y + ce * (sq * sq * s2) / (1.0 + d) + sq * s2) / den
    return s_new, c_new, y_new


def _imag_start(vn, dv):
    sh = math.sinh(vn)
    ch = math.cosh(vn)
    return sh + ch * dv, ch + sh * dv


def imag_level(sig, C, sq):
    """One Landen step up on the imaginary axis (Jacobi's imaginary transformation)."""
    s2 = sig * sig
    D = fast_sqrt(1.0 + (sq * sq) * s2)
    den = 1.0 - sq * s2
    return (1.0 + sq) * sig / den, C * D / den


def dn_from_sc(s, c, m, m1):
    """``dn`` at the chain's top from ``s = sn``, ``c = cn`` (no cancellation)."""
    s2 = s * s
    if m <= 0.5:
        return fast_sqrt(1.0 - m * s2)
    return fast_sqrt(c * c + m1 * s2)


def _mod4(n):
    """Python's ``n % 4.0`` for an integer-valued ``n`` (exact)."""
    return n - 4.0 * math.floor(0.25 * n)


def quadrant(n, r, neg, s, c, d, kp):
    """Sign and quarter-period map of the values ``s, c, d`` at ``|r|``: ``(sn, cn, dn, n, r, s, c, d)``."""
    if neg:
        s = -s
    q = _mod4(n)
    if q == 1.0 or q == 3.0:
        sn = c / d
        cn = -(kp * s / d)
        dn = kp / d
    else:
        sn = s
        cn = c
        dn = d
    if q >= 2.0:
        sn = -sn
        cn = -cn
    return sn, cn, dn, n, r, s, c, d


def _finish(n, r, neg, v, s, c, sep, m, m1, kp):
    """``dn``, sign, separatrix and quarter-period map: ``(sn, cn, dn, n, r, s, c, d)``."""
    if sep:
        s = math.tanh(v)
        c = sech_real(v)
        d = c
    else:
        d = dn_from_sc(s, c, m, m1)
    return quadrant(n, r, neg, s, c, d, kp)


def sncndn3(k, u1h, u1l, u2h, u2l, u3h, u3l, cst):
    """Jacobi functions at ``k`` (1 to 3) double-double arguments, ascents interleaved.

    Returns ``(sn, cn, dn, n, r, s, c, d)`` of each of the three lanes (a
    24-tuple; lanes beyond ``k`` are zeros): the values at ``u``, the
    quarter-period index ``n``, the reduced argument ``r`` and the values at
    ``r``, exactly as ``elliptic.sncndn_dd``.
    """
    sep = cst[C_SEP] != 0.0
    kh = cst[C_KH]
    kl = cst[C_KL]
    ph = cst[C_PH]
    pcorr = cst[C_PCORR]
    m = cst[C_M]
    m1 = cst[C_M1]
    kp = cst[C_KP]
    nlev = int(cst[C_NLEV])
    two = k >= 2
    three = k >= 3
    n1, r1, ng1, v1, vn1, dv1 = reduce(u1h, u1l, sep, kh, kl, ph, pcorr)
    n2 = r2 = v2 = vn2 = dv2 = 0.0
    n3 = r3 = v3 = vn3 = dv3 = 0.0
    ng2 = ng3 = False
    if two:
        n2, r2, ng2, v2, vn2, dv2 = reduce(u2h, u2l, sep, kh, kl, ph, pcorr)
    if three:
        n3, r3, ng3, v3, vn3, dv3 = reduce(u3h, u3l, sep, kh, kl, ph, pcorr)
    s1 = c1 = s2 = c2 = s3 = c3 = 0.0
    if not sep:
        if m > 0.5:
            g1, C1 = _imag_start(vn1, dv1)
            g2 = C2 = g3 = C3 = 1.0
            if two:
                g2, C2 = _imag_start(vn2, dv2)
            if three:
                g3, C3 = _imag_start(vn3, dv3)
            for i in range(nlev - 1, -1, -1):
                sq = cst[C_SQM + i]
                if sq > 0.0:
                    g1, C1 = imag_level(g1, C1, sq)
                    if two:
                        g2, C2 = imag_level(g2, C2, sq)
                    if three:
                        g3, C3 = imag_level(g3, C3, sq)
            s1, c1 = g1 / C1, 1.0 / C1
            if two:
                s2, c2 = g2 / C2, 1.0 / C2
            if three:
                s3, c3 = g3 / C3, 1.0 / C3
        else:
            s1, c1, y1 = _real_start(vn1, dv1)
            y2 = y3 = 0.0
            if two:
                s2, c2, y2 = _real_start(vn2, dv2)
            if three:
                s3, c3, y3 = _real_start(vn3, dv3)
            for i in range(nlev - 1, -1, -1):
                sq = cst[C_SQM + i]
                if sq > 0.0:
                    pc = cst[C_PCL + i]
                    s1, c1, y1 = real_level(s1, c1, y1, sq, pc)
                    if two:
                        s2, c2, y2 = real_level(s2, c2, y2, sq, pc)
                    if three:
                        s3, c3, y3 = real_level(s3, c3, y3, sq, pc)
            if y1 < 0.5:
                c1 = 1.0 - y1
            if two and y2 < 0.5:
                c2 = 1.0 - y2
            if three and y3 < 0.5:
                c3 = 1.0 - y3
    a1, b1, e1, f1, g1_, h1, i1, j1 = _finish(n1, r1, ng1, v1, s1, c1, sep, m, m1, kp)
    a2 = b2 = e2 = f2 = g2_ = h2 = i2 = j2 = 0.0
    a3 = b3 = e3 = f3 = g3_ = h3 = i3 = j3 = 0.0
    if two:
        a2, b2, e2, f2, g2_, h2, i2, j2 = _finish(n2, r2, ng2, v2, s2, c2, sep, m, m1, kp)
    if three:
        a3, b3, e3, f3, g3_, h3, i3, j3 = _finish(n3, r3, ng3, v3, s3, c3, sep, m, m1, kp)
    return (
        a1,
        b1,
        e1,
        f1,
        g1_,
        h1,
        i1,
        j1,
        a2,
        b2,
        e2,
        f2,
        g2_,
        h2,
        i2,
        j2,
        a3,
        b3,
        e3,
        f3,
        g3_,
        h3,
        i3,
        j3,
    )


# =============================================================================
# compilation
# =============================================================================
if USE_NUMBA:  # pragma: no branch
    # made when numba is first used, not at import (util.jit: lazy_njit, activate)
    from ...util.jit import lazy_intrinsic as _intrinsic
    from ...util.jit import lazy_module as _lazy_module
    from ...util.jit import lazy_njit as _njit

    _ir = _lazy_module("llvmlite.ir")
    _types = _lazy_module("numba.core.types")

    def _jit(f):
        return _njit(cache=True, nogil=True, error_model="numpy")(f)

    def _jiti(f, python=None):
        """Small helpers: inlined into their callers by numba (a call between compiled functions
        is otherwise an indirect call that LLVM can neither inline nor vectorize). ``python``: the
        plain-Python twin of a function written for the compiler (util.jit.python_twins)."""
        return _njit(cache=True, nogil=True, error_model="numpy", forceinline=True, python=python)(f)

    # the plain-Python forms of the functions written for the compiler below (the same numbers)
    _py_fast_sqrt, _py_two_prod_f = fast_sqrt, _two_prod_f

    @_intrinsic
    def _fma(typingctx, a, b, c):
        """``a * b + c`` rounded once (LLVM ``llvm.fma.f64``)."""
        sig = _types.float64(_types.float64, _types.float64, _types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.fma", [d], _ir.FunctionType(d, [d, d, d]))
            return builder.call(fn, args)

        return sig, codegen

    @_intrinsic(python=_py_fast_sqrt)
    def fast_sqrt(typingctx, x):  # noqa: F811 - the compiled version is the LLVM intrinsic
        """Correctly rounded ``sqrt(x)`` (``llvm.sqrt.f64``, bitwise equal to the C library's)."""
        sig = _types.float64(_types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.sqrt", [d], _ir.FunctionType(d, [d]))
            return builder.call(fn, args)

        return sig, codegen

    def _two_prod_f(a, b):  # noqa: F811 - the compiled version uses the FMA
        p = a * b
        return p, _fma(a, b, -p)

    two_sum = _jiti(two_sum)
    quick_two_sum = _jiti(quick_two_sum)
    _split = _jiti(_split)
    two_prod = _jiti(two_prod)
    dd_add = _jiti(dd_add)
    dd_mul = _jiti(dd_mul)
    _two_prod_f = _jiti(_two_prod_f, _py_two_prod_f)
    lib_hypot = _jiti(lib_hypot)
    dd_mul_f = _jiti(dd_mul_f)
    _dd_mul_d_f = _jiti(_dd_mul_d_f)
    dd_div_f = _jiti(dd_div_f)
    dd_sqrt_f = _jiti(dd_sqrt_f)
    rf_poly = _jiti(rf_poly)
    rc1_series = _jiti(rc1_series)
    sin_poly = _jiti(sin_poly)
    cos_poly = _jiti(cos_poly)
    rc1 = _jiti(rc1)
    rj_init = _jiti(rj_init)
    _rj_step = _jiti(_rj_step)
    rj_finish = _jiti(rj_finish)
    rj3 = _jit(rj3)
    rj1 = _jiti(rj1)
    params = _jit(params)
    sech_real = _jiti(sech_real)
    reduce = _jiti(reduce)
    _real_start = _jiti(_real_start)
    real_level = _jiti(real_level)
    _imag_start = _jiti(_imag_start)
    imag_level = _jiti(imag_level)
    dn_from_sc = _jiti(dn_from_sc)
    _mod4 = _jiti(_mod4)
    quadrant = _jiti(quadrant)
    _finish = _jiti(_finish)
    sncndn3 = _jit(sncndn3)
