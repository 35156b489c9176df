r"""Compiled scalar kernels of the closed-form free rigid body (private).

This module is a scalar transcription of the vectorized NumPy implementation
in :mod:`eulerpoisson.solvers.exact.motion` and :mod:`eulerpoisson.numerics.elliptic` (Jacobi
elliptic functions by a double-double reduction modulo the quarter period and
the descending Landen transformation, Carlson's ``R_F`` and ``R_J`` by
duplication, Jacobi's addition theorem for the integral of the third kind;
see those modules for the mathematics and the references).  The numerical
method is *the same*: every floating-point operation is performed in the same
order on the same operands, only per element instead of per array.  The
kernels are compiled with numba (``@njit(cache=True)``,
``error_model="numpy"`` so that IEEE semantics hold, no ``fastmath``: no
contraction into fused multiply-adds, which would break the error-free
transformations of the double-double arithmetic; the only explicit fused
multiply-add forms the exact error of a product inside the AGM, where it is
bitwise equal to Dekker's product, see :func:`_two_prod_f`).

Consequences:

* with the same elementary functions (``sin``, ``atan``, ``log1p``, ... from
  the C library) the compiled path reproduces the NumPy path *bitwise*; NumPy
  may use its own SIMD implementations of some of them (e.g. AVX-512 builds
  of ``exp``, ``tanh``, ``atan``), which differ by 1-3 ulp, so in general the
  two paths agree to a few ulp of the intermediate quantities;
* memory is O(1) per body: the per-body constants live in a small work array
  that is reused, so ``nb`` bodies times ``T`` times cost
  ``nb * (setup + T * evaluation)`` with no intermediate arrays.

Speed comes from doing only the work an output needs (the complete
integrals ``J_c``, the values at ``tau0`` and ``J(tau0)`` are computed on
first use, so a body evaluated once pays only for the branch it takes) and
from running independent iterations interleaved (their latency chains
overlap): the AGM for ``K``, the Landen chain and the ``R_F`` of the initial
phase in one loop (:func:`params`); the Jacobi functions at ``tau``,
``tau0`` and ``lambda t`` in one Landen ascent (:func:`sncndn3`); up to
three ``R_J`` (at ``tau``, at ``tau0`` and the complete one) in one
duplication loop (:func:`rj3`).  Each interleaved iteration keeps its own
stopping rule, so the results are those of the stand-alone algorithms, bit
for bit.  The ``R_C`` terms of the ``R_J`` duplication use the series of
``atan(t)/t`` for ``|e| <= 2**-5`` (``elliptic.rc1_series``; all steps but
the first one or two).

The small helpers are compiled with ``inline="always"``: a call from one
compiled function to another is otherwise an indirect call, which LLVM can
neither inline nor vectorize; square roots are the ``llvm.sqrt`` intrinsic
(:func:`fast_sqrt`; numba's ``math.sqrt`` is a call to the C library's) and the
power-of-two scaling reads and builds exponent bits (:func:`_exponent`,
:func:`pow2`) instead of calling numba's ``frexp``/``ldexp`` helpers; the
same numbers in every case.

Layout: :func:`body_setup` computes the per-body constants (sorting to
ascending moments by a proper signed permutation, exact power-of-two scaling,
regime, elliptic parameter, Landen chain, initial phase) into a float64 array
``cst`` (indices ``_C_*``, the Landen levels included);
:func:`body_eval` evaluates ``M`` and the attitude quaternion at one time;
:func:`motion_kernel` (which runs the lane kernel of
:mod:`eulerpoisson.solvers.exact.lanes`: sixteen evaluations in lockstep,
bitwise equal to :func:`motion_kernel_scalar`) and :func:`constants_kernel`
are the two compiled entry points (one signature each); :func:`free_flow` is
the kinetic step of the exact splitting methods.

The compiled kernels are used when numba is installed and the environment
variable ``EULERPOISSON_NO_NUMBA`` is not ``"1"`` (:data:`USE_NUMBA`, decided
when eulerpoisson is imported, without importing numba: the dispatchers and
intrinsics are made on the first call of a kernel and loaded from numba's
cache, :mod:`eulerpoisson.util.jit`; ``eulerpoisson warmup`` fills the cache);
otherwise :mod:`eulerpoisson.solvers.exact.motion` runs its NumPy path (the
reference), which ``solve`` also runs for small problems (no numba import).  The functions here are plain Python when numba
is not used (correct, bitwise equal, but slow; not used by the package then).

References
----------
.. [1] B. C. Carlson, "Numerical computation of real or complex elliptic
   integrals", Numer. Algorithms 10 (1995) 13-26.
.. [2] T. J. Dekker, "A floating-point technique for extending the available
   precision", Numer. Math. 18 (1971) 224-242.
.. [3] DLMF chapters 19 and 22, https://dlmf.nist.gov/.
.. [4] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation
   of the free rigid body motion and its use in splitting methods", SIAM J.
   Sci. Comput. 30 (2008) 2084-2112.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

__all__ = [
    "USE_NUMBA",
    "N_CONST",
    "MAX_LANDEN",
    "body_setup",
    "body_eval",
    "motion_kernel",
    "motion_kernel_scalar",
    "free_flow",
    "equilibrium_eval",
    "constants_kernel",
]


from ...numerics.doubledouble import dd_add as dd_add
from ...numerics.doubledouble import dd_mul as dd_mul
from ...numerics.doubledouble import quick_two_sum as _quick_two_sum
from ...numerics.doubledouble import split as _split
from ...numerics.doubledouble import two_prod as two_prod
from ...numerics.doubledouble import two_sum as two_sum
from ...numerics.elliptic import RC_SERIES_MAX as RC_SERIES_MAX
from ...numerics.elliptic import SINCOS_POLY_MAX as SINCOS_POLY_MAX
from ...numerics.elliptic import cos_poly as cos_poly
from ...numerics.elliptic import rc1_series as rc1_series
from ...numerics.elliptic import sin_poly as sin_poly
from ...numerics.quaternion import qmul_components as qmul
from ...util.jit import USE_NUMBA  # numba importable and EULERPOISSON_NO_NUMBA not "1"

# --- numerical constants: identical to those of numerics.elliptic / motion ----------
PI_HI = 3.141592653589793
PI_LO = 1.2246467991473532e-16
PIO2_HI = 1.5707963267948966
PIO2_LO = 6.123233995736766e-17
LANDEN_THRESHOLD = 2.0**-56
#: maximum number of Landen levels (as in numerics.elliptic; about 5 are ever used)
MAX_LANDEN = 40
MAX_AGM = 60
MAX_DUPLICATION = 200
_R_TOL = 2.0**-53
RF_QFAC: float = (3.0 * _R_TOL) ** (-1.0 / 6.0)
RDJ_QFAC: float = (0.25 * _R_TOL) ** (-1.0 / 6.0)
_M1_SEPARATRIX = 1e-200
TWO200 = 2.0**200
TWOM100 = 2.0**-100
TWOM104 = 2.0**-104
_HALF_PI = 0.5 * np.pi

# regime codes (as in motion)
_EQUILIBRIUM = 0
REGIME_A = 1
REGIME_B = 2
SEPARATRIX = 3

# --- layout of the per-body constants array ----------------------------------
C_REGIME = 0
C_CASEB = 1  # 1.0 regime B (circulation about the largest-moment axis)
C_SEP = 2  # 1.0 on the separatrix
C_M = 3
C_M1 = 4
C_KP = 5  # sqrt(m1)
C_KH = 6  # K (pi/2 on the separatrix), double-double
C_KL = 7
C_PH = 8  # prod(1 + sqrt(p_i)) of the Landen chain, ph * (1 + pcorr)
C_PCORR = 9
C_LAM = 10
C_T0H = 11  # tau0, double-double
C_T0L = 12
C_AC = 13
C_A2 = 14
C_AA = 15
C_SA = 16
C_SC = 17
C_RATE = 18
C_COEF = 19
C_NU = 20
C_OMNU = 21
C_JC = 22  # lazy
C_NADD = 23
C_CADD = 24
C_NUD = 25
C_OMNUD = 26
C_JCD = 27  # lazy
C_G0 = 28
C_TSCALE = 29  # 2**escale, or 0 where not a normal number (then ldexp)
C_SN0 = 30  # lazy (with the values at tau0)
C_JFAR0 = 31  # lazy
C_THETA0 = 32  # lazy (with the values at tau0)
C_KFULL = 33
C_Q0W = 34
C_Q0X = 35
C_Q0Y = 36
C_Q0Z = 37
C_PERM0 = 38  # perm[k] as float, k = 0, 1, 2
C_SGN0 = 41  # sgn[k]
C_EM = 44  # exponent of the M scaling
C_ESCALE = 45  # exponent of the time scaling
C_NLEV = 46  # number of Landen levels
C_M0S = 47  # sorted, signed, *unscaled* M0 (3 entries; exact output at t = 0)
C_MSCALE = 50  # 2**eM, or 0 where not a normal number
C_TAU0V = 53  # n, r, s, c, d of the reduced tau0 (5 entries; lazy)
C_HAVE_JC = 58  # flags of the lazily computed constants: 1.0 once computed
C_HAVE_JCD = 59
C_HAVE_JFAR0 = 60
C_HAVE_T0 = 61
C_SQM = 62  # Landen levels sqrt(p_i) (MAX_LANDEN entries)
C_PCL: int = C_SQM + MAX_LANDEN  # and 1 - p_i
#: length of the per-body constants array
N_CONST: int = C_PCL + MAX_LANDEN


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
    return _quick_two_sum(p, e)


def _dd_mul_d_f(ah, al, b):
    p, e = _two_prod_f(ah, b)
    e = e + al * b
    return _quick_two_sum(p, e)


def dd_div_f(ah, al, bh, bl):
    q1 = ah / bh
    ph, pl = _dd_mul_d_f(bh, bl, q1)
    rh, rl = dd_add(ah, al, -ph, -pl)
    q2 = rh / bh
    ph, pl = _dd_mul_d_f(bh, bl, q2)
    rh, rl = dd_add(rh, rl, -ph, -pl)
    q3 = rh / bh
    q1, q2 = _quick_two_sum(q1, q2)
    return dd_add(q1, q2, q3, 0.0 * q3)


def dd_sqrt_f(ah, al):
    x = fast_sqrt(ah)
    if x > 0.0:
        p, e = _two_prod_f(x, x)
        corr = ((ah - p) - e + al) / (2.0 * x)
    else:
        corr = 0.0
    return _quick_two_sum(x, corr)


def fast_sqrt(x):
    """Correctly rounded square root (compiled: the ``llvm.sqrt`` intrinsic, which vectorizes; numba's
    ``math.sqrt`` is a call to the C library's ``sqrt``, which LLVM does not always turn into one)."""
    return math.sqrt(x)


def pow2(k):
    """``2**k`` for ``-1022 <= k <= 1023`` (a normal number), else 0."""
    if -1022 <= k <= 1023:
        return math.ldexp(1.0, k)
    return 0.0


def _exponent(x):
    """``math.frexp(x)[1]`` for finite ``x != 0``."""
    return math.frexp(x)[1]


def exponent_lane(x):
    """``(math.frexp(x)[1], ok)`` for finite ``x != 0``; compiled without a call, ``ok`` false for a
    subnormal ``x`` (whose body the lane kernel then sets up with the scalar code)."""
    return math.frexp(x)[1], True


def _ldexp(x, f, k):
    """``ldexp(x, k)`` given ``f = pow2(k)``: one correctly rounded product."""
    if f != 0.0:
        return x * f
    return math.ldexp(x, k)


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
    r, _, _ = rj3(x, y, z, p, True, 0.0, 0.0, 0.0, 0.0, False, 0.0, 0.0, 0.0, 0.0, False)
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
    r, rl = _quick_two_sum(rh, rl)
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


def _mod2(n):
    """Python's ``n % 2.0`` for an integer-valued ``n``, exactly, without ``fmod`` (lane loops vectorize)."""
    return n - 2.0 * math.floor(0.5 * n)


def _mod4(n):
    """Python's ``n % 4.0`` for an integer-valued ``n`` (exact)."""
    return n - 4.0 * math.floor(0.25 * n)


def _mod8(n):
    """Python's ``n % 8.0`` for an integer-valued ``n`` (exact)."""
    return n - 8.0 * math.floor(0.125 * n)


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
# rigid-body pieces (see motion: _jtot, _theta, _jfar, jsep, _near, qmin)
# =============================================================================
def jtot_args(nu, omnu, n, s, c, d, kp):
    """Arguments of the ``R_J`` in ``J(nu; nK + r)``: ``(odd, S, S^2, C^2, D^2, p)``."""
    odd = _mod2(n) == 1.0
    sa_ = abs(s)
    if odd:
        S = _dv(c, d)
        C = _dv(kp * sa_, d)
        Dd = _dv(kp, d)
    else:
        S = sa_
        C = c
        Dd = d
    S2 = S * S
    C2 = C * C
    if nu <= 0.0:
        p = 1.0 - nu * S2
    else:
        p = omnu + nu * C2
    return odd, S, S2, C2, Dd * Dd, p


def jtot_from(odd, n, r, jc, S, S2, rj):
    """``J = n J_c + J_per`` from the ``R_J`` value (not used where ``S^2 = 0``)."""
    if S2 > 0.0:
        jq = S * S2 * rj / 3.0
    else:
        jq = 0.0
    if odd:
        sg = 1.0 if r > 0.0 else (-1.0 if r < 0.0 else 0.0)
        jper = sg * (jc - jq)
    else:
        jper = -jq if r < 0.0 else jq
    # n = +-0 is the only case in which a caller may pass a placeholder
    # jc > 0 (not computed yet): n * jc = n exactly there
    nj = n * jc if n != 0.0 else n
    return nj + jper


def _jtot(nu, omnu, jc, n, r, s, c, d, kp):
    """``J(nu; nK + r) = int_0^u sn^2/(1 - nu sn^2)`` from the values ``s, c, d``
    at ``r`` (``motion._jtot`` for one element, not on the separatrix)."""
    odd, S, S2, C2, D2, p = jtot_args(nu, omnu, n, s, c, d, kp)
    if S2 > 0.0:
        rj = rj1(C2, D2, 1.0, p)
    else:
        rj = 0.0
    return jtot_from(odd, n, r, jc, S, S2, rj)


def _get_jc(cst):
    """Complete ``J_c = R_J(0, m1, 1, 1 - nu) / 3`` (0 on the separatrix), on first use."""
    if cst[C_HAVE_JC] == 0.0:
        if cst[C_SEP] != 0.0:
            cst[C_JC] = 0.0
        else:
            rj = rj1(0.0, cst[C_M1], 1.0, cst[C_OMNU])
            cst[C_JC] = rj / 3.0
        cst[C_HAVE_JC] = 1.0
    return cst[C_JC]


def _get_jcd(cst):
    """Complete integral of the direct form of ``G`` (regime B; ``J_c`` in A), on first use."""
    if cst[C_CASEB] == 0.0:
        return _get_jc(cst)
    if cst[C_HAVE_JCD] == 0.0:
        rj = rj1(0.0, cst[C_M1], 1.0, cst[C_OMNUD])
        cst[C_JCD] = rj / 3.0
        cst[C_HAVE_JCD] = 1.0
    return cst[C_JCD]


def _theta(cst, n, s, c):
    """Unwrapped azimuth ``n pi/2 + dtheta`` of ``M`` about the circled axis (``motion._theta``)."""
    return theta_v(cst[C_AC], cst[C_KP], cst[C_A2], n, s, c)


def theta_v(ac, kp, a2, n, s, c):
    """:func:`_theta` from the constants ``A_c``, ``k'`` and ``A_2``."""
    if _mod2(n) == 1.0:
        dtheta = math.atan2(ac * kp * s, a2 * c)
    else:
        dtheta = math.atan2(a2 * s, ac * c)
    return _mod8(n) * _HALF_PI + dtheta


def jsep(N, tau):
    """Separatrix ``J = (tau - atan(sqrt(N) tanh tau)/sqrt(N)) / (1 + N)``."""
    rN = fast_sqrt(N)
    tt = math.tanh(tau)
    z = rN * tt
    if z != 0.0:
        at = math.atan(z) / z * tt
    else:
        at = 1.0 * tt
    return (tau - at) / (1.0 + N)


def near_xadd(N, cadd, Pp, snd, cnd, dnd):
    """The addition-theorem term ``-(1/C) atan(C Y/X)`` of :func:`_near` (``Pp = sn(tau) sn(tau0)``)."""
    X = 1.0 + N * snd * snd + N * Pp * cnd * dnd
    Y = -Pp * snd
    z = cadd * Y / X
    if z != 0.0:
        atanc = math.atan(z) / z
    else:
        atanc = 1.0
    return -(Y / X) * atanc


def _near(cst, dh, dl, sn_tau, snd, cnd, dnd, n, r, s, c, d):
    """Increment ``J(tau) - J(tau0)`` (A) or ``G(tau) - G(tau0)`` (B) for
    ``|lambda t| <= K`` by Jacobi's addition theorem (``motion._near``);
    ``snd ... d``: the Jacobi functions at ``delta = lambda t = dh + dl``."""
    N = cst[C_NADD]
    xadd = near_xadd(N, cst[C_CADD], sn_tau * cst[C_SN0], snd, cnd, dnd)
    dlt = dh + dl
    caseB = cst[C_CASEB] != 0.0
    g0 = cst[C_G0]
    use_sh = caseB and (abs(dlt) * g0 > cst[C_M1] * _get_jc(cst))
    if cst[C_SEP] != 0.0:
        jd = jsep(N, dlt)
    elif use_sh:
        nn = n - 1.0
        jc = 1.0 if nn == 0.0 else _get_jc(cst)
        jd = _jtot(cst[C_NU], cst[C_OMNU], jc, nn, r, s, c, d, cst[C_KP])
    else:
        jc = 1.0 if n == 0.0 else _get_jcd(cst)
        jd = _jtot(cst[C_NUD], cst[C_OMNUD], jc, n, r, s, c, d, cst[C_KP])
    if caseB:
        if use_sh:
            gdel = cst[C_M1] * _get_jc(cst) + cst[C_M1] * jd
        else:
            gdel = g0 * (dlt - g0 * jd)
        return gdel - g0 * g0 * xadd
    return jd + xadd


def _far(cst, n, r, s, c, d):
    """``J_far(tau) - J_far(tau0)`` for ``|lambda t| > K`` (``motion._jfar``;
    never on the separatrix, where ``K`` is infinite).

    ``J_far`` is ``J(nu_A; tau)`` (A) or ``m1 J(nu_B; tau - K)`` (B).  On the
    first far evaluation of a body ``J_c`` and ``J_far(tau0)`` may still be
    missing: their ``R_J`` run interleaved with the one at ``tau``.
    """
    caseB = cst[C_CASEB] != 0.0
    nu = cst[C_NU]
    omnu = cst[C_OMNU]
    kp = cst[C_KP]
    m1 = cst[C_M1]
    neff = n - 1.0 if caseB else n
    odd, S, S2, C2, D2, p = jtot_args(nu, omnu, neff, s, c, d, kp)
    do0 = cst[C_HAVE_JFAR0] == 0.0
    doc = cst[C_HAVE_JC] == 0.0
    k = C_TAU0V
    n0 = cst[k]
    r0 = cst[k + 1]
    neff0 = n0 - 1.0 if caseB else n0
    odd0, S0, S20, C20, D20, p0 = jtot_args(nu, omnu, neff0, cst[k + 2], cst[k + 3], cst[k + 4], kp)
    rjt, rj0, rjc = rj3(
        C2,
        D2,
        1.0,
        p,
        S2 > 0.0,
        C20,
        D20,
        1.0,
        p0,
        do0 and S20 > 0.0,
        0.0,
        m1,
        1.0,
        omnu,
        doc,
    )
    if doc:
        cst[C_JC] = rjc / 3.0
        cst[C_HAVE_JC] = 1.0
    jc = cst[C_JC]
    if do0:
        j0 = jtot_from(odd0, neff0, r0, jc, S0, S20, rj0)
        cst[C_JFAR0] = m1 * j0 if caseB else j0
        cst[C_HAVE_JFAR0] = 1.0
    j = jtot_from(odd, neff, r, jc, S, S2, rjt)
    if caseB:
        j = m1 * j
    return j - cst[C_JFAR0]


def qmin(M1, M2, M3, caseB, sa):
    """Quaternion of the minimal rotation taking ``M/|M|`` to ``sa e_3`` (B) / ``sa e_1`` (A)."""
    nrm = fast_sqrt(M1 * M1 + M2 * M2 + M3 * M3)
    x = M1 / nrm
    y = M2 / nrm
    z = M3 / nrm
    if caseB:
        ze = sa * z
        vx = sa * y
        vy = -sa * x
        vz = 0.0
    else:
        ze = sa * x
        vx = 0.0
        vy = sa * z
        vz = -sa * y
    w = 1.0 + ze
    f = 1.0 / fast_sqrt(2.0 * w)
    return w * f, vx * f, vy * f, vz * f


# =============================================================================
# per-body set-up
# =============================================================================
def body_setup(i0, i1, i2, m0, m1_, m2, cst):
    """Per-body constants of the closed-form solution into ``cst``.

    Scalar version of ``motion._prepare`` and ``motion._constants``.

    Parameters
    ----------
    i0, i1, i2 : float
        Principal moments (input axis order, all > 0, finite).
    m0, m1_, m2 : float
        Initial body angular momentum (input axis order, finite).
    cst : ndarray, shape (N_CONST,)
        Output: constants (indices ``_C_*``; the Landen levels ``sqrt(p_i)``
        and ``1 - p_i`` at ``C_SQM`` and ``C_PCL``).

    Returns
    -------
    bool
        True for a relative equilibrium (only the sorting data of ``cst`` is
        filled then).
    """
    eq, m, m1, rx, ry, do_rf, c0, s0, M1, M2, M3 = setup_pre(i0, i1, i2, m0, m1_, m2, cst)
    if eq:
        return True
    rf0 = params(m, m1, rx, ry, 1.0, do_rf, cst)
    setup_post(cst, rf0, c0, s0, M1, M2, M3)
    return False


def _dv(a, b):
    """``a / b`` with IEEE results for ``b = 0`` also in plain Python (compiled: the division itself).

    The branch-free set-up computes both regimes' quantities and selects; the one not taken may
    divide by zero (a symmetric top, a relative equilibrium)."""
    if b != 0.0:
        return a / b
    if a != a or a == 0.0 or b != b:
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def perm3(i0, i1, i2):
    """Proper signed permutation to ascending moments (a stable argsort, without branches):
    ``(p0, p1, p2, s1)`` with ``s1 = -1`` for an odd permutation (the middle axis changes sign)."""
    a0, a1, a2 = i0, i1, i2
    p0, p1, p2 = 0, 1, 2
    c = a1 < a0
    a0, a1 = (a1, a0) if c else (a0, a1)
    p0, p1 = (p1, p0) if c else (p0, p1)
    c2 = a2 < a1
    a1, a2 = (a2, a1) if c2 else (a1, a2)
    p1, p2 = (p2, p1) if c2 else (p1, p2)
    c3 = c2 and a1 < a0
    p0, p1 = (p1, p0) if c3 else (p0, p1)
    inv = (1 if p0 > p1 else 0) + (1 if p0 > p2 else 0) + (1 if p1 > p2 else 0)
    s1 = -1.0 if inv == 1 or inv == 3 else 1.0
    return p0, p1, p2, s1


def pick3(k, x0, x1, x2):
    """``(x0, x1, x2)[k]`` without indexing a tuple by a variable."""
    return x0 if k == 0 else (x1 if k == 1 else x2)


def pre_regime(M1, M2, M3, I1, I2, I3):
    """Regime, parameter and constants of a scaled, sorted body (``motion._constants``).

    Returns ``(eq, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0, x, y)``
    with ``(x, y)`` the (unnormalised) amplitude of ``M(0)``; the values are meaningless where ``eq``.
    """
    d21 = I2 - I1
    d32 = I3 - I2
    d31 = I3 - I1
    msq = M1 * M1 + M2 * M2 + M3 * M3
    a1 = M2 * M2 * d21 / I2 + M3 * M3 * d31 / I3
    a3 = M1 * M1 * d31 / I1 + M2 * M2 * d32 / I2
    # D = M^2 - 2 E I2 = (M3^2 (I3-I2) I1 - M1^2 (I2-I1) I3) / (I1 I3), double-double
    d32h, d32l = two_sum(I3, -I2)
    d21h, d21l = two_sum(I2, -I1)
    sh, sl = two_prod(M3, M3)
    ph, pl = dd_mul(sh, sl, d32h, d32l)
    p, e = two_prod(ph, I1)
    t3h, t3l = _quick_two_sum(p, e + pl * I1)
    sh, sl = two_prod(M1, M1)
    ph, pl = dd_mul(sh, sl, d21h, d21l)
    p, e = two_prod(ph, I3)
    t1h, t1l = _quick_two_sum(p, e + pl * I3)
    dh, _ = dd_add(t3h, t3l, -t1h, -t1l)
    D = dh / (I1 * I3)
    eq = (msq == 0.0) | (a1 == 0.0) | (a3 == 0.0) | ((dh == 0.0) & (M1 * M1 * d21 == 0.0) & (M3 * M3 * d32 == 0.0))
    mn = fast_sqrt(msq)
    m1B = _dv(d31 * D, d32 * a1)
    caseB = (D > 0.0) & (m1B >= _M1_SEPARATRIX)
    mB = _dv(d21 * a3, d32 * a1)
    mA = _dv(d32 * a1, d21 * a3)
    m1A = _dv(d31 * (-D), d21 * a3)
    m = mB if caseB else mA
    m1 = m1B if caseB else m1A
    sep = (not caseB) & (m1 < _M1_SEPARATRIX)
    # make m + m1 = 1 with the smaller of the two computed directly
    small_m = m <= m1
    m1r = 1.0 - m
    mr = 1.0 - m1
    m1 = m1r if small_m else m1
    m = m if small_m else mr
    # np.clip (NaN stays NaN); on the separatrix m = 1
    m = 0.0 if m < 0.0 else (1.0 if m > 1.0 else m)
    m1 = 0.0 if m1 < 0.0 else (1.0 if m1 > 1.0 else m1)
    m = 1.0 if sep else m
    m1 = 0.0 if sep else m1

    A1 = fast_sqrt(_dv(a3 * I1, d31))
    A3 = fast_sqrt(_dv(a1 * I3, d31))
    A2B = fast_sqrt(_dv(a3 * I2, d32))
    lamB = fast_sqrt(d32 * a1 / (I1 * I2 * I3))
    A2A = fast_sqrt(_dv(a1 * I2, d21))
    lamA = fast_sqrt(d21 * a3 / (I1 * I2 * I3))
    A2 = A2B if caseB else A2A
    lam = lamB if caseB else lamA
    Ac = A1 if caseB else A3
    Aa = A3 if caseB else A1
    Mc0 = M1 if caseB else M3
    Ma0 = M3 if caseB else M1
    sa = -1.0 if Ma0 < 0.0 else 1.0
    sc = -1.0 if (sep & (Mc0 < 0.0)) else 1.0

    # precession rates and characteristics
    rateB = mn / I2
    coefB = _dv(mn * d32 * d21, I2 * I2 * d31 * lam)
    nprime = _dv(I3 * d21, I2 * d31)
    omnprime = _dv(I1 * d32, I2 * d31)  # 1 - n'
    NaddB = _dv(nprime, omnprime)
    nuB = m + nprime * m1
    omnuB = m1 * omnprime
    rateA = mn / I3
    coefA = _dv(mn * d32 * d31, I3 * I3 * d21 * lam)
    NaddA = _dv(I1 * d32, I3 * d21)  # -nu_A
    nuA = -NaddA
    omnuA = _dv(I2 * d31, I3 * d21)
    rate = rateB if caseB else rateA
    coef = coefB if caseB else coefA
    Nadd = NaddB if caseB else NaddA
    nu = nuB if caseB else nuA
    omnu = omnuB if caseB else omnuA
    coef = coef if math.isfinite(coef) else 0.0
    nu = nu if math.isfinite(nu) else 0.0
    omnu = omnu if (math.isfinite(omnu) & (omnu > 0.0)) else 1.0
    Nadd = Nadd if math.isfinite(Nadd) else 0.0
    Cadd = fast_sqrt(Nadd * (Nadd + m) * (1.0 + Nadd))
    g0 = 1.0 + Nadd if caseB else 1.0

    # initial phase: amplitude (c0, s0) of (sc Mc/Ac, sa sc M2/A2)
    x = _dv(sc * Mc0, Ac)
    y = _dv(sa * sc * M2, A2)
    return eq, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0, x, y


def pre_amplitude(h, x, y, m, m1):
    """``(c0, s0, delta^2)`` of the initial phase from ``h = hypot(x, y)``."""
    c0 = _dv(x, h)
    s0 = _dv(y, h)
    s2 = s0 * s0
    delta2 = 1.0 - m * s2 if m <= 0.5 else c0 * c0 + m1 * s2
    return c0, s0, delta2


def setup_pre(i0, i1, i2, m0, m1_, m2, cst):
    """First part of :func:`body_setup`, up to :func:`params`.

    Returns ``(eq, m, m1, rx, ry, do_rf, c0, s0, M1, M2, M3)``: the
    equilibrium flag, the parameter, the first two arguments of the ``R_F`` of
    the initial phase and whether it is needed, the initial amplitude and the
    sorted, scaled ``M0`` (benign placeholders for an equilibrium).
    """
    # --- proper signed permutation to ascending moments (stable argsort) ---
    p0, p1, p2, s1 = perm3(i0, i1, i2)
    I1u = pick3(p0, i0, i1, i2)
    I2u = pick3(p1, i0, i1, i2)
    I3u = pick3(p2, i0, i1, i2)
    M1u = 1.0 * pick3(p0, m0, m1_, m2)
    M2u = s1 * pick3(p1, m0, m1_, m2)
    M3u = 1.0 * pick3(p2, m0, m1_, m2)
    cst[C_PERM0] = p0
    cst[C_PERM0 + 1] = p1
    cst[C_PERM0 + 2] = p2
    cst[C_SGN0] = 1.0
    cst[C_SGN0 + 1] = s1
    cst[C_SGN0 + 2] = 1.0
    cst[C_M0S] = M1u
    cst[C_M0S + 1] = M2u
    cst[C_M0S + 2] = M3u
    # --- exact power-of-two scaling: max |M| and max I in [0.5, 1) ---
    mmax = max(max(abs(M1u), abs(M2u)), abs(M3u))
    eM = 0 if mmax == 0.0 else _exponent(mmax)
    eI = _exponent(I3u)
    fM = pow2(-eM)
    fI = pow2(-eI)
    M1 = _ldexp(M1u, fM, -eM)
    M2 = _ldexp(M2u, fM, -eM)
    M3 = _ldexp(M3u, fM, -eM)
    I1 = _ldexp(I1u, fI, -eI)
    I2 = _ldexp(I2u, fI, -eI)
    I3 = _ldexp(I3u, fI, -eI)
    cst[C_EM] = eM
    cst[C_ESCALE] = eM - eI
    cst[C_MSCALE] = pow2(eM)
    cst[C_TSCALE] = pow2(eM - eI)
    eq, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0, x, y = pre_regime(
        M1, M2, M3, I1, I2, I3
    )
    if eq:
        cst[C_REGIME] = _EQUILIBRIUM
        return True, 0.5, 0.5, 1.0, 1.0, False, 1.0, 0.0, 0.0, 0.0, 0.0
    c0, s0, delta2 = pre_amplitude(math.hypot(x, y), x, y, m, m1)
    _pre_store(cst, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0)
    return False, m, m1, c0 * c0, delta2, not sep, c0, s0, M1, M2, M3


def _pre_store(cst, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0):
    """The constants of :func:`setup_pre` into ``cst`` (all but the sorting and scaling data)."""
    cst[C_REGIME] = SEPARATRIX if sep else (REGIME_B if caseB else REGIME_A)
    cst[C_CASEB] = 1.0 if caseB else 0.0
    cst[C_SEP] = 1.0 if sep else 0.0
    cst[C_M] = m
    cst[C_M1] = m1
    cst[C_NU] = nu
    cst[C_OMNU] = omnu
    cst[C_HAVE_JC] = 0.0
    cst[C_HAVE_JCD] = 0.0
    cst[C_HAVE_JFAR0] = 0.0
    cst[C_HAVE_T0] = 0.0
    cst[C_LAM] = lam
    cst[C_AC] = Ac
    cst[C_A2] = A2
    cst[C_AA] = Aa
    cst[C_SA] = sa
    cst[C_SC] = sc
    cst[C_RATE] = rate
    cst[C_COEF] = coef
    cst[C_NADD] = Nadd
    cst[C_CADD] = Cadd
    cst[C_G0] = g0
    cst[C_NUD] = -Nadd if caseB else nu
    cst[C_OMNUD] = 1.0 + Nadd if caseB else omnu


def setup_post(cst, rf0, c0, s0, M1, M2, M3):
    """Last part of :func:`body_setup`, after :func:`params`: ``tau0`` and the remaining constants."""
    sep = cst[C_SEP] != 0.0
    caseB = cst[C_CASEB] != 0.0
    sa = cst[C_SA]
    kh = cst[C_KH]
    kl = cst[C_KL]
    if sep:
        t0h = math.asinh(s0 / c0)
        t0l = 0.0
    else:
        F0 = s0 * rf0
        if c0 < 0.0:
            sg = -1.0 if s0 < 0.0 else 1.0
            th, tl = two_sum(sg * 2.0 * kh, -F0)
            tl = tl + sg * 2.0 * kl
            t0h, t0l = _quick_two_sum(th, tl)
        else:
            t0h = F0
            t0l = 0.0

    cst[C_T0H] = t0h
    cst[C_T0L] = t0l
    cst[C_KFULL] = math.inf if sep else kh
    qw, qx, qy, qz = qmin(M1, M2, M3, caseB, sa)
    cst[C_Q0W] = qw
    cst[C_Q0X] = qx
    cst[C_Q0Y] = qy
    cst[C_Q0Z] = qz
    return False


# =============================================================================
# per-(body, time) evaluation
# =============================================================================
def body_eval(cst, t):
    """``(M_0, M_1, M_2, q_w, q_x, q_y, q_z)`` at time ``t``, input frame.

    Scalar version of ``motion._generic_block`` plus the output mapping of
    ``motion.exact_motion``; ``cst`` from :func:`body_setup`
    (a non-equilibrium body).  The Jacobi functions at ``tau``, at
    ``delta = lambda t`` (near branch) and, on the first call, at ``tau0``
    are evaluated together.
    """
    p0 = int(cst[C_PERM0])
    p1 = int(cst[C_PERM0 + 1])
    s1 = cst[C_SGN0 + 1]
    if t == 0.0:
        # the initial condition is reproduced exactly
        Mk0 = cst[C_M0S]
        Mk1 = cst[C_M0S + 1]
        Mk2 = cst[C_M0S + 2]
        qw = 1.0
        qk0 = 0.0
        qk1 = 0.0
        qk2 = 0.0
    else:
        ts = _ldexp(t, cst[C_TSCALE], int(cst[C_ESCALE]))
        caseB = cst[C_CASEB] != 0.0
        dh, dl = two_prod(cst[C_LAM], ts)
        th, tl = dd_add(dh, dl, cst[C_T0H], cst[C_T0L])
        near = abs(dh) <= cst[C_KFULL]
        first = cst[C_HAVE_T0] == 0.0
        if first:
            k = 3 if near else 2
            u2h, u2l, u3h, u3l = cst[C_T0H], cst[C_T0L], dh, dl
        else:
            k = 2 if near else 1
            u2h, u2l, u3h, u3l = dh, dl, 0.0, 0.0
        (
            sn,
            cn,
            dn,
            n,
            r,
            s,
            c,
            d,
            a2,
            b2,
            e2,
            f2,
            g2,
            h2,
            i2,
            j2,
            a3,
            b3,
            e3,
            f3,
            g3,
            h3,
            i3,
            j3,
        ) = sncndn3(k, th, tl, u2h, u2l, u3h, u3l, cst)
        if first:
            # values at t = 0: sn(tau0), theta(tau0) and the reduced tau0
            cst[C_SN0] = a2
            cst[C_THETA0] = _theta(cst, f2, h2, i2)
            kk = C_TAU0V
            cst[kk] = f2
            cst[kk + 1] = g2
            cst[kk + 2] = h2
            cst[kk + 3] = i2
            cst[kk + 4] = j2
            cst[C_HAVE_T0] = 1.0
            snd, cnd, dnd, nd, rd, sd, cd, dd = a3, b3, e3, f3, g3, h3, i3, j3
        else:
            snd, cnd, dnd, nd, rd, sd, cd, dd = a2, b2, e2, f2, g2, h2, i2, j2
        theta = _theta(cst, n, s, c)
        if near:
            dj = _near(cst, dh, dl, sn, snd, cnd, dnd, nd, rd, sd, cd, dd)
        else:
            dj = _far(cst, n, r, s, c, d)
        sa = cst[C_SA]
        sc = cst[C_SC]
        Mc = sc * cst[C_AC] * cn
        M2 = sa * sc * cst[C_A2] * sn
        Ma = sa * cst[C_AA] * dn
        if caseB:
            M1 = Mc
            M3 = Ma
        else:
            M1 = Ma
            M3 = Mc
        psi = cst[C_RATE] * ts + cst[C_COEF] * dj
        sigma = 1.0 if caseB else -1.0
        alpha = psi - sigma * (theta - cst[C_THETA0])
        ca = math.cos(0.5 * alpha)
        sal = math.sin(0.5 * alpha)
        # q_e(alpha) with e = sa e_3 (B) or sa e_1 (A)
        if caseB:
            ex = 0.0
            ez = sa * sal
        else:
            ex = sa * sal
            ez = 0.0
        tw, tx, ty, tz = qmin(M1, M2, M3, caseB, sa)
        uw, ux, uy, uz = qmul(ca, ex, 0.0, ez, tw, tx, ty, tz)
        qw, qx, qy, qz = qmul(cst[C_Q0W], -cst[C_Q0X], -cst[C_Q0Y], -cst[C_Q0Z], uw, ux, uy, uz)
        nq = fast_sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        qw = qw / nq
        qk0 = qx / nq
        qk1 = qy / nq
        qk2 = qz / nq
        fM = cst[C_MSCALE]
        eM = int(cst[C_EM])
        Mk0 = _ldexp(M1, fM, eM)
        Mk1 = _ldexp(M2, fM, eM)
        Mk2 = _ldexp(M3, fM, eM)
    # back to the input frame: x[perm[k]] = sgn[k] x_sorted[k]
    Ms = (1.0 * Mk0, s1 * Mk1, 1.0 * Mk2)
    qs = (1.0 * qk0, s1 * qk1, 1.0 * qk2)
    # inverse permutation: input axis a holds sorted axis k with perm[k] = a
    i0 = 0 if p0 == 0 else (1 if p1 == 0 else 2)
    i1 = 0 if p0 == 1 else (1 if p1 == 1 else 2)
    i2 = 0 if p0 == 2 else (1 if p1 == 2 else 2)
    return Ms[i0], Ms[i1], Ms[i2], qw, qs[i0], qs[i1], qs[i2]


# =============================================================================
# entry points
# =============================================================================
def equilibrium_eval(i0, i1, i2, m0, m1, m2, t):
    """``(M_0, M_1, M_2, q_w, q_x, q_y, q_z)`` of a relative equilibrium (uniform rotation about Omega = M/I)."""
    o0 = m0 / i0
    o1 = m1 / i1
    o2 = m2 / i2
    w = fast_sqrt(o0 * o0 + o1 * o1 + o2 * o2)
    ws = w if w > 0.0 else 1.0
    half = 0.5 * w * t
    sh = math.sin(half)
    return m0, m1, m2, math.cos(half), sh * (o0 / ws), sh * (o1 / ws), sh * (o2 / ws)


def free_flow(i0, i1, i2, m0, m1, m2, t, cst):
    """The exact free-body flow over time ``t`` from body momentum ``(m0, m1, m2)`` (principal frame).

    Returns ``(M_0, M_1, M_2, q_w, q_x, q_y, q_z)``: the momentum at ``t`` and
    the rotation from the identity (``cst`` is scratch of length
    :data:`N_CONST`). Used as the kinetic step of splitting methods.
    """
    if body_setup(i0, i1, i2, m0, m1, m2, cst):
        return equilibrium_eval(i0, i1, i2, m0, m1, m2, t)
    return body_eval(cst, t)


def motion_kernel_scalar(inertia, M0, t, Mout, qout):
    """:func:`motion_kernel` one (body, time) after the other (the reference of the lane kernel).

    O(1) memory per body.
    """
    nb = inertia.shape[0]
    T = t.shape[0]
    cst = np.zeros(N_CONST)
    for b in range(nb):
        i0 = inertia[b, 0]
        i1 = inertia[b, 1]
        i2 = inertia[b, 2]
        m0 = M0[b, 0]
        m1 = M0[b, 1]
        m2 = M0[b, 2]
        if body_setup(i0, i1, i2, m0, m1, m2, cst):
            # relative equilibrium: M constant, uniform rotation about Omega = M0 / I
            for j in range(T):
                r0, r1, r2, r3, r4, r5, r6 = equilibrium_eval(i0, i1, i2, m0, m1, m2, t[j])
                Mout[b, j, 0] = r0
                Mout[b, j, 1] = r1
                Mout[b, j, 2] = r2
                qout[b, j, 0] = r3
                qout[b, j, 1] = r4
                qout[b, j, 2] = r5
                qout[b, j, 3] = r6
        else:
            for j in range(T):
                r0, r1, r2, r3, r4, r5, r6 = body_eval(cst, t[j])
                Mout[b, j, 0] = r0
                Mout[b, j, 1] = r1
                Mout[b, j, 2] = r2
                qout[b, j, 0] = r3
                qout[b, j, 1] = r4
                qout[b, j, 2] = r5
                qout[b, j, 3] = r6


def constants_kernel(inertia, M0, out):
    """Per-body ``(regime, m, m1, K, lam, tau0, period)`` into ``out`` (nb, 7)
    (``motion.exact_constants``)."""
    nb = inertia.shape[0]
    cst = np.zeros(N_CONST)
    for b in range(nb):
        if body_setup(inertia[b, 0], inertia[b, 1], inertia[b, 2], M0[b, 0], M0[b, 1], M0[b, 2], cst):
            out[b, 0] = _EQUILIBRIUM
            out[b, 1] = 0.0
            out[b, 2] = 1.0
            out[b, 3] = _HALF_PI
            out[b, 4] = 0.0
            out[b, 5] = 0.0
            out[b, 6] = math.inf
        else:
            K = math.inf if cst[C_SEP] != 0.0 else cst[C_KH]
            lam = math.ldexp(cst[C_LAM], int(cst[C_ESCALE]))
            out[b, 0] = cst[C_REGIME]
            out[b, 1] = cst[C_M]
            out[b, 2] = cst[C_M1]
            out[b, 3] = K
            out[b, 4] = lam
            out[b, 5] = cst[C_T0H] + cst[C_T0L]
            out[b, 6] = 4.0 * K / lam if lam > 0.0 else math.inf


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

    def _jiti(f):
        """Small helpers: inlined into their callers by numba (a call between compiled functions
        is otherwise an indirect call that LLVM can neither inline nor vectorize)."""
        return _njit(cache=True, nogil=True, error_model="numpy", forceinline=True)(f)

    @_intrinsic
    def _fma(typingctx, a, b, c):
        """``a * b + c`` rounded once (LLVM ``llvm.fma.f64``)."""
        sig = _types.float64(_types.float64, _types.float64, _types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.fma", [d], _ir.FunctionType(d, [d, d, d]))
            return builder.call(fn, args)

        return sig, codegen

    @_intrinsic
    def fast_sqrt(typingctx, x):  # noqa: F811 - the compiled version is the LLVM intrinsic
        """Correctly rounded ``sqrt(x)`` (``llvm.sqrt.f64``, bitwise equal to the C library's)."""
        sig = _types.float64(_types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.sqrt", [d], _ir.FunctionType(d, [d]))
            return builder.call(fn, args)

        return sig, codegen

    @_intrinsic
    def _bits(typingctx, x):
        """The bits of a float64 as an int64 (LLVM ``bitcast``)."""
        sig = _types.int64(_types.float64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.IntType(64))

        return sig, codegen

    @_intrinsic
    def _from_bits(typingctx, i):
        """The float64 with the bits of an int64 (LLVM ``bitcast``)."""
        sig = _types.float64(_types.int64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.DoubleType())

        return sig, codegen

    def pow2(k):  # noqa: F811 - compiled: built from its bits (numba's ldexp is a call into its helper library)
        if -1022 <= k <= 1023:
            return _from_bits((k + 1023) << 52)
        return 0.0

    def _exponent(x):  # noqa: F811 - compiled: read from the bits where x is normal (the same number)
        be = (_bits(x) >> 52) & 0x7FF
        if be != 0:
            return be - 1022
        return math.frexp(x)[1]

    def exponent_lane(x):  # noqa: F811 - compiled: the exponent bits, no call (vectorizes)
        be = (_bits(x) >> 52) & 0x7FF
        return be - 1022, be != 0

    def _two_prod_f(a, b):  # noqa: F811 - the compiled version uses the FMA
        p = a * b
        return p, _fma(a, b, -p)

    two_sum = _jiti(two_sum)
    _quick_two_sum = _jiti(_quick_two_sum)
    _split = _jiti(_split)
    two_prod = _jiti(two_prod)
    dd_add = _jiti(dd_add)
    dd_mul = _jiti(dd_mul)
    _two_prod_f = _jiti(_two_prod_f)
    dd_mul_f = _jiti(dd_mul_f)
    _dd_mul_d_f = _jiti(_dd_mul_d_f)
    dd_div_f = _jiti(dd_div_f)
    dd_sqrt_f = _jiti(dd_sqrt_f)
    pow2 = _jiti(pow2)
    _exponent = _jiti(_exponent)
    exponent_lane = _jiti(exponent_lane)
    _ldexp = _jiti(_ldexp)
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
    _mod2 = _jiti(_mod2)
    _mod4 = _jiti(_mod4)
    _mod8 = _jiti(_mod8)
    quadrant = _jiti(quadrant)
    _finish = _jiti(_finish)
    sncndn3 = _jit(sncndn3)
    jtot_args = _jiti(jtot_args)
    jtot_from = _jiti(jtot_from)
    _jtot = _jit(_jtot)
    _get_jc = _jit(_get_jc)
    _get_jcd = _jit(_get_jcd)
    theta_v = _jiti(theta_v)
    _theta = _jiti(_theta)
    jsep = _jiti(jsep)
    near_xadd = _jiti(near_xadd)
    _near = _jit(_near)
    _far = _jit(_far)
    qmin = _jiti(qmin)
    qmul = _jiti(qmul)

    def _dv(a, b):  # noqa: F811 - compiled: the IEEE division (error_model="numpy")
        return a / b

    _dv = _jiti(_dv)
    perm3 = _jiti(perm3)
    pick3 = _jiti(pick3)
    pre_regime = _jiti(pre_regime)
    pre_amplitude = _jiti(pre_amplitude)
    _pre_store = _jiti(_pre_store)
    setup_pre = _jit(setup_pre)
    setup_post = _jit(setup_post)
    body_setup = _jit(body_setup)
    body_eval = _jit(body_eval)
    equilibrium_eval = _jit(equilibrium_eval)
    free_flow = _jit(free_flow)
    motion_kernel_scalar = _jit(motion_kernel_scalar)
    constants_kernel = _jit(constants_kernel)

# the lane kernel (imported last: it reads this module's constants and compiled helpers).
# motion_kernel(inertia, M0, t, Mout, qout): fill Mout (nb, T, 3) and qout (nb, T, 4) for bodies
# (nb, 3) and times (T,), inputs validated by the caller (finite, moments > 0, C-contiguous
# float64): the lane kernel lanes.motion_lanes (sixteen evaluations in lockstep), whose results are
# those of motion_kernel_scalar bit for bit. (lanes sets it too, should it be imported first.)
motion_kernel: Callable[..., None]  # (declared for type checkers: lanes and this module import each other)
from . import lanes as _lanes  # noqa: E402

if hasattr(_lanes, "motion_lanes"):  # pragma: no branch
    motion_kernel = _lanes.motion_lanes
