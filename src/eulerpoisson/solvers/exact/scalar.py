r"""Compiled scalar kernel of the closed-form free rigid body (private).

This module is a scalar transcription of the vectorized NumPy implementation
in :mod:`eulerpoisson.solvers.exact.motion` (with the elliptic functions of
:mod:`eulerpoisson.solvers.exact.scalar_elliptic`, the scalar twins of
:mod:`eulerpoisson.numerics.elliptic`; Jacobi's addition theorem for the
integral of the third kind).  The numerical method is *the same*: every
floating-point operation is performed in the same order on the same
operands, only per element instead of per array.  The kernels are compiled
with numba (``cache=True``, ``error_model="numpy"`` so that IEEE semantics
hold, no ``fastmath``).

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
from running independent iterations interleaved (:func:`params
<eulerpoisson.solvers.exact.scalar_elliptic.params>`, ``sncndn3``, ``rj3``:
the Jacobi functions at ``tau``, ``tau0`` and ``lambda t`` in one Landen
ascent; up to three ``R_J`` in one duplication loop).  The power-of-two
scaling reads and builds exponent bits (``_exponent``, :func:`pow2`) instead
of calling numba's ``frexp``/``ldexp`` helpers; the same numbers in every case.

Layout: :func:`body_setup` computes the per-body constants (sorting to
ascending moments by a proper signed permutation, exact power-of-two scaling,
regime, elliptic parameter, Landen chain, initial phase) into a float64 array
``cst`` whose fields are named in :mod:`eulerpoisson.solvers.exact.state`
(``C_*``, the Landen levels included); :func:`body_eval` evaluates ``M`` and
the attitude quaternion at one time; :func:`motion_kernel_scalar` (the
reference of the lane kernel :mod:`eulerpoisson.solvers.exact.lanes`) and
:func:`constants_kernel` are compiled entry points (one signature each);
:func:`free_flow` is the kinetic step of the exact splitting methods.
:mod:`eulerpoisson.solvers.exact.kernels` is the entry point the package
calls.  The functions here are plain Python when numba is not used (correct,
bitwise equal, but slow; not used by the package then).

References
----------
.. [1] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation
   of the free rigid body motion and its use in splitting methods", SIAM J.
   Sci. Comput. 30 (2008) 2084-2112.
"""

from __future__ import annotations

import math

import numpy as np

from ...numerics.quaternion import qmul_components as qmul
from ...util.jit import USE_NUMBA  # numba importable and EULERPOISSON_NO_NUMBA not "1"
from .scalar_elliptic import (
    dd_add,
    dd_mul,
    fast_sqrt,
    lib_hypot,
    params,
    quick_two_sum,
    rj1,
    rj3,
    sncndn3,
    two_prod,
    two_sum,
)
from .state import (
    C_A2,
    C_AA,
    C_AC,
    C_CADD,
    C_CASEB,
    C_COEF,
    C_EM,
    C_ESCALE,
    C_G0,
    C_HAVE_JC,
    C_HAVE_JCD,
    C_HAVE_JFAR0,
    C_HAVE_T0,
    C_JC,
    C_JCD,
    C_JFAR0,
    C_KFULL,
    C_KH,
    C_KL,
    C_KP,
    C_LAM,
    C_M,
    C_M0S,
    C_M0S1,
    C_M0S2,
    C_M1,
    C_MSCALE,
    C_NADD,
    C_NU,
    C_NUD,
    C_OMNU,
    C_OMNUD,
    C_PERM0,
    C_PERM1,
    C_PERM2,
    C_Q0W,
    C_Q0X,
    C_Q0Y,
    C_Q0Z,
    C_RATE,
    C_REGIME,
    C_SA,
    C_SC,
    C_SEP,
    C_SGN0,
    C_SGN1,
    C_SGN2,
    C_SN0,
    C_T0H,
    C_T0L,
    C_TAU0_C,
    C_TAU0_D,
    C_TAU0_N,
    C_TAU0_R,
    C_TAU0_S,
    C_THETA0,
    C_TSCALE,
    EQUILIBRIUM,
    N_CONST,
    REGIME_A,
    REGIME_B,
    SEPARATRIX,
)

__all__ = [
    "pow2",
    "exponent_lane",
    "jtot_args",
    "jtot_from",
    "theta_v",
    "jsep",
    "near_xadd",
    "qmin",
    "qmul",
    "body_setup",
    "perm3",
    "pick3",
    "pre_regime",
    "pre_amplitude",
    "setup_pre",
    "setup_post",
    "body_eval",
    "equilibrium_eval",
    "free_flow",
    "motion_kernel_scalar",
    "constants_kernel",
]

_M1_SEPARATRIX = 1e-200
_HALF_PI = 0.5 * np.pi


# =============================================================================
# exact power-of-two scaling, integer-valued remainders
# =============================================================================
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


def _mod2(n):
    """Python's ``n % 2.0`` for an integer-valued ``n``, exactly, without ``fmod`` (lane loops vectorize)."""
    return n - 2.0 * math.floor(0.5 * n)


def _mod8(n):
    """Python's ``n % 8.0`` for an integer-valued ``n`` (exact)."""
    return n - 8.0 * math.floor(0.125 * n)


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
    n0 = cst[C_TAU0_N]
    r0 = cst[C_TAU0_R]
    neff0 = n0 - 1.0 if caseB else n0
    odd0, S0, S20, C20, D20, p0 = jtot_args(nu, omnu, neff0, cst[C_TAU0_S], cst[C_TAU0_C], cst[C_TAU0_D], kp)
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
        Output: constants (fields ``C_*`` of :mod:`eulerpoisson.solvers.exact.state`; the Landen levels
        ``sqrt(p_i)`` and ``1 - p_i`` at ``C_SQM`` and ``C_PCL``).

    Returns
    -------
    bool
        True for a relative equilibrium (only the sorting data of ``cst`` is
        filled then).
    """
    # a view of any layout ('A'), as the lane kernel passes its strided rows: one compilation of setup_pre and
    # setup_post serves both (the same memory, the same operations)
    csa = cst[0::1]
    eq, m, m1, rx, ry, do_rf, c0, s0, M1, M2, M3 = setup_pre(i0, i1, i2, m0, m1_, m2, csa)
    if eq:
        return True
    rf0 = params(m, m1, rx, ry, 1.0, do_rf, cst)
    setup_post(csa, rf0, c0, s0, M1, M2, M3)
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
    t3h, t3l = quick_two_sum(p, e + pl * I1)
    sh, sl = two_prod(M1, M1)
    ph, pl = dd_mul(sh, sl, d21h, d21l)
    p, e = two_prod(ph, I3)
    t1h, t1l = quick_two_sum(p, e + pl * I3)
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
    cst[C_PERM1] = p1
    cst[C_PERM2] = p2
    cst[C_SGN0] = 1.0
    cst[C_SGN1] = s1
    cst[C_SGN2] = 1.0
    cst[C_M0S] = M1u
    cst[C_M0S1] = M2u
    cst[C_M0S2] = M3u
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
        cst[C_REGIME] = EQUILIBRIUM
        return True, 0.5, 0.5, 1.0, 1.0, False, 1.0, 0.0, 0.0, 0.0, 0.0
    c0, s0, delta2 = pre_amplitude(lib_hypot(x, y), x, y, m, m1)
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
            t0h, t0l = quick_two_sum(th, tl)
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
    p1 = int(cst[C_PERM1])
    s1 = cst[C_SGN1]
    if t == 0.0:
        # the initial condition is reproduced exactly
        Mk0 = cst[C_M0S]
        Mk1 = cst[C_M0S1]
        Mk2 = cst[C_M0S2]
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
            cst[C_TAU0_N] = f2
            cst[C_TAU0_R] = g2
            cst[C_TAU0_S] = h2
            cst[C_TAU0_C] = i2
            cst[C_TAU0_D] = j2
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
            out[b, 0] = EQUILIBRIUM
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

    def _jiti(f, python=None):
        """Small helpers: inlined into their callers by numba (a call between compiled functions
        is otherwise an indirect call that LLVM can neither inline nor vectorize). ``python``: the
        plain-Python twin of a function written for the compiler (util.jit.python_twins)."""
        return _njit(cache=True, nogil=True, error_model="numpy", forceinline=True, python=python)(f)

    # the plain-Python forms of the functions written differently for the compiler below (the same numbers)
    _py_pow2, _py_exponent, _py_exponent_lane, _py_dv = pow2, _exponent, exponent_lane, _dv

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

    pow2 = _jiti(pow2, _py_pow2)
    _exponent = _jiti(_exponent, _py_exponent)
    exponent_lane = _jiti(exponent_lane, _py_exponent_lane)
    _ldexp = _jiti(_ldexp)
    _mod2 = _jiti(_mod2)
    _mod8 = _jiti(_mod8)
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

    _dv = _jiti(_dv, _py_dv)
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
