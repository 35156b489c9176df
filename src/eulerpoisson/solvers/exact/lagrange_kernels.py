r"""Compiled evaluation of the Lagrange top at its output times (private).

:mod:`eulerpoisson.solvers.exact.lagrange` sets every top up with NumPy
(the roots of the cubic, the parameter, the initial phases: work per body)
and evaluates the motion at the output times either with NumPy or, when numba
is used, with :func:`heavy_top_kernel` here: one (body, time) after the
other, with the scalar elliptic kernels of
:mod:`eulerpoisson.solvers.exact.kernels` (Jacobi functions by the
double-double reduction and the Landen ascent, the three arguments of a time
in one interleaved ascent; Carlson's ``R_F`` and ``R_J`` by duplication, the
two integrals of a time interleaved).  The formulas are those of
``lagrange._heavy_top``, operation for operation; the results agree with the
NumPy path to a few ulp (NumPy's complex ``exp`` and its SIMD elementary
functions round differently from the C library's).

The per-body constants are the columns ``_L_*`` of an array ``C``
(:func:`lagrange._heavy_constants` fills it).
"""

from __future__ import annotations

import math

import numpy as np

from ...util.jit import USE_NUMBA
from . import kernels as _K

__all__ = ["N_LAG", "heavy_top_kernel"]

# per-body constants (columns of C)
L_M1 = 0  # 1 - m of the nutation
L_M = 1  # 1 - m1 (the parameter as jacobi_sncndn forms it)
L_K = 2  # K(m) (inf on the separatrix)
L_NU = 3
L_TAU0 = 4
L_SD = 5  # sqrt(d/2)
L_D = 6
L_W1 = 7
L_W2 = 8
L_S1 = 9  # 1.0 where W1 == 0 (signed amplitude cos(theta/2) = sd sn)
L_S2 = 10
L_Z1 = 11  # 1.0 where the rate of sigma has no 1/(1+u) term
L_Z2 = 12
L_LAM = 13
L_KAPS = 14
L_KAPD = 15
L_NS = 16
L_N1S = 17
L_PICS = 18
L_SHS = 19  # 1.0: the sigma integral in its shifted form
L_ND = 20
L_N1D = 21
L_PICD = 22
L_CSLIN = 23  # dsig = CSLIN ts + CSPER (perS - perS0)
L_CSPER = 24
L_CDPER = 25  # ddel = -lam ts + CDPER (perD - perD0)
L_PERS0 = 26
L_PERD0 = 27
L_E1R = 28
L_E1I = 29
L_E2R = 30
L_E2I = 31
L_SDNU = 32  # sd nu
L_DNU = 33  # d nu
L_W = 34  # time scale (power of two)
#: number of per-body constants
N_LAG = 35

_RF_QFAC = _K.RF_QFAC
_MAX_DUPLICATION = _K.MAX_DUPLICATION


def _rf2(xa, ya, za, xb, yb, zb):
    """Two independent ``R_F`` (``elliptic.rf_core``), duplications interleaved, each with its own stopping rule."""
    a0a = (xa + ya + za) / 3.0
    qa = _RF_QFAC * max(max(abs(a0a - xa), abs(a0a - ya)), abs(a0a - za))
    a0b = (xb + yb + zb) / 3.0
    qb = _RF_QFAC * max(max(abs(a0b - xb), abs(a0b - yb)), abs(a0b - zb))
    A_a, fa, x_a, y_a, z_a = a0a, 1.0, xa, ya, za
    A_b, fb, x_b, y_b, z_b = a0b, 1.0, xb, yb, zb
    run_a = True
    run_b = True
    for _ in range(_MAX_DUPLICATION):
        if run_a:
            if fa * qa >= abs(A_a):
                sx = _K.fast_sqrt(x_a)
                sy = _K.fast_sqrt(y_a)
                sz = _K.fast_sqrt(z_a)
                lam = sx * sy + sy * sz + sz * sx
                A_a = 0.25 * (A_a + lam)
                fa = 0.25 * fa
                x_a = 0.25 * (x_a + lam)
                y_a = 0.25 * (y_a + lam)
                z_a = 0.25 * (z_a + lam)
            else:
                run_a = False
        if run_b:
            if fb * qb >= abs(A_b):
                sx = _K.fast_sqrt(x_b)
                sy = _K.fast_sqrt(y_b)
                sz = _K.fast_sqrt(z_b)
                lam = sx * sy + sy * sz + sz * sx
                A_b = 0.25 * (A_b + lam)
                fb = 0.25 * fb
                x_b = 0.25 * (x_b + lam)
                y_b = 0.25 * (y_b + lam)
                z_b = 0.25 * (z_b + lam)
            else:
                run_b = False
        if not (run_a or run_b):
            break
    return _K.rf_poly(a0a, xa, ya, A_a, fa), _K.rf_poly(a0b, xb, yb, A_b, fb)


def _reduced_args(n, n1, shifted, sn, cn, dn, m1):
    """``s, c2, d2, p`` of ``lagrange._pi_periodic`` / ``_pi_reduced`` from the Jacobi functions at ``x``."""
    if shifted:
        s = cn / dn
        q = sn / dn
        c2 = m1 * (q * q)
        d2 = m1 / (dn * dn)
    else:
        s = sn
        c2 = cn * cn
        d2 = dn * dn
    s2 = s * s
    if n <= 0.0:
        p = 1.0 - n * s2
    else:
        p = n1 + n * c2
    return s, s2, c2, d2, p


def _periodic(n, s, s2, rf, rj, tr, j, finite, pic, shifted):
    """``lagrange._pi_periodic`` after its ``R_F`` and ``R_J``."""
    part = s * rf + (n / 3.0) * (s * s2) * rj
    pis = pic if finite else 0.0
    if shifted:
        sg = 1.0 if tr > 0.0 else (-1.0 if tr < 0.0 else 0.0)
        part = sg * (pis - part)
    if j == 0.0:
        return part
    return 2.0 * j * pis + part


def heavy_top_kernel(C, t, QF, Q0, OM0, qout, wout):
    """Attitude ``qout`` (n, T, 4) and body angular velocity ``wout`` (n, T, 3) of heavy tops.

    ``lagrange._heavy_top`` and the last steps of ``lagrange.lagrange_top_motion``:
    ``C`` (n, N_LAG) holds the constants of the bodies, ``t`` (T,) the times
    (each body scales them by its ``L_W``); the motion in the frame whose
    third axis is up is turned back by ``QF`` (n, 4), normalised, ``Omega_3``
    is the conserved input value ``OM0[:, 2]`` and ``t = 0`` returns the
    inputs ``Q0`` (n, 4) and ``OM0`` (n, 3) exactly.  Returns the number of
    non-finite outputs (the caller then lets the NumPy evaluation say why).
    """
    bad = 0
    n_b = C.shape[0]
    T = t.shape[0]
    cst = np.zeros(_K.N_CONST)
    for b in range(n_b):
        m1 = C[b, L_M1]
        m = C[b, L_M]
        cst[_K.C_SEP] = 1.0 if m1 == 0.0 else 0.0
        cst[_K.C_M] = m
        cst[_K.C_M1] = m1
        _K.params(m, m1, 1.0, 1.0, 1.0, m < m, cst)  # (m < m: a computed False; a literal compiles params twice)
        K = C[b, L_K]
        finite = math.isfinite(K)
        Ks = K if finite else 1.0
        nu = C[b, L_NU]
        tau0 = C[b, L_TAU0]
        sd = C[b, L_SD]
        d = C[b, L_D]
        W1 = C[b, L_W1]
        W2 = C[b, L_W2]
        s1 = C[b, L_S1] != 0.0
        s2 = C[b, L_S2] != 0.0
        z1 = C[b, L_Z1] != 0.0
        z2 = C[b, L_Z2] != 0.0
        lam = C[b, L_LAM]
        kaps = C[b, L_KAPS]
        kapd = C[b, L_KAPD]
        nS = C[b, L_NS]
        n1S = C[b, L_N1S]
        picS = C[b, L_PICS]
        shS = C[b, L_SHS] != 0.0
        nD = C[b, L_ND]
        n1D = C[b, L_N1D]
        picD = C[b, L_PICD]
        cslin = C[b, L_CSLIN]
        csper = C[b, L_CSPER]
        cdper = C[b, L_CDPER]
        perS0 = C[b, L_PERS0]
        perD0 = C[b, L_PERD0]
        e1r = C[b, L_E1R]
        e1i = C[b, L_E1I]
        e2r = C[b, L_E2R]
        e2i = C[b, L_E2I]
        sdnu = C[b, L_SDNU]
        dnu = C[b, L_DNU]
        W = C[b, L_W]
        for jt in range(T):
            ts = W * t[jt]
            tau = tau0 + nu * ts
            # reduction by half periods for the angle integrals
            jj = np.rint(tau / (2.0 * Ks)) if finite else 0.0
            tr = tau - 2.0 * jj * Ks
            k = 3 if shS else 2
            (
                sn,
                cn,
                dn,
                _a,
                _b,
                _c,
                _d,
                _e,
                snD,
                cnD,
                dnD,
                _f,
                _g,
                _h,
                _i,
                _j,
                snS,
                cnS,
                dnS,
                _k,
                _l,
                _m,
                _n,
                _o,
            ) = _K.sncndn3(k, tau, 0.0, tr, 0.0, abs(tr), 0.0, cst)
            if not shS:
                snS, cnS, dnS = snD, cnD, dnD
            # amplitudes cos(theta/2), sin(theta/2) and their rates
            if s1:
                cc = sd * sn
                cdot = sdnu * cn * dn
            else:
                cc = _K.fast_sqrt(0.5 * (W1 + d * sn * sn))
                cdot = dnu * sn * cn * dn / (2.0 * cc)
            if s2:
                ss = sd * cn
                sdot = -sdnu * sn * dn
            else:
                ss = _K.fast_sqrt(0.5 * (W2 + d * cn * cn))
                sdot = -dnu * sn * cn * dn / (2.0 * ss)
            if not math.isfinite(cdot):
                cdot = 0.0
            if not math.isfinite(sdot):
                sdot = 0.0
            rate_c = lam * cc + (0.0 if z1 else kaps / (2.0 * cc))
            rate_s = -lam * ss + (0.0 if z2 else kapd / (2.0 * ss))
            # the angle integrals
            # (no shift for delta: a computed False, as a literal False would compile the helpers a second time)
            no_shift = shS and not shS
            sS, s2S, c2S, d2S, pS = _reduced_args(nS, n1S, shS, snS, cnS, dnS, m1)
            sD, s2D, c2D, d2D, pD = _reduced_args(nD, n1D, no_shift, snD, cnD, dnD, m1)
            rfS, rfD = _rf2(c2S, d2S, 1.0, c2D, d2D, 1.0)
            rjS, rjD, _r = _K.rj3(
                c2S, d2S, 1.0, pS, not no_shift, c2D, d2D, 1.0, pD, not no_shift, 0.0, 0.0, 0.0, 0.0, no_shift
            )
            perS = _periodic(nS, sS, s2S, rfS, rjS, tr, jj, finite, picS, shS)
            perD = _periodic(nD, sD, s2D, rfD, rjD, tr, jj, finite, picD, no_shift)
            dsig = cslin * ts + csper * (perS - perS0)
            ddel = -lam * ts + cdper * (perD - perD0)
            c1 = math.cos(dsig)
            si1 = math.sin(dsig)
            c2 = math.cos(ddel)
            si2 = math.sin(ddel)
            # e^{i sigma}, e^{i delta}
            p1r = e1r * c1 - e1i * si1
            p1i = e1r * si1 + e1i * c1
            p2r = e2r * c2 - e2i * si2
            p2i = e2r * si2 + e2i * c2
            # q = (Re Z1, Re Z2, Im Z2, Im Z1), Z1 = cc ph1, Z2 = ss ph2, and the rates dZ = (xdot + i rate) ph
            w = cc * p1r
            z = cc * p1i
            x = ss * p2r
            y = ss * p2i
            wd = cdot * p1r - rate_c * p1i
            zd = cdot * p1i + rate_c * p1r
            xd = sdot * p2r - rate_s * p2i
            yd = sdot * p2i + rate_s * p2r
            # Omega = 2 (w vd - wd v - v x vd)
            o1 = 2.0 * (w * xd - wd * x - (y * zd - z * yd))
            o2 = 2.0 * (w * yd - wd * y - (z * xd - x * zd))
            if t[jt] == 0.0:
                qout[b, jt, 0] = Q0[b, 0]
                qout[b, jt, 1] = Q0[b, 1]
                qout[b, jt, 2] = Q0[b, 2]
                qout[b, jt, 3] = Q0[b, 3]
                wout[b, jt, 0] = OM0[b, 0]
                wout[b, jt, 1] = OM0[b, 1]
                wout[b, jt, 2] = OM0[b, 2]
                continue
            # back to the frame of the input: conj(q_f) q, then normalised
            qw, qx, qy, qz = _K.qmul(QF[b, 0], -QF[b, 1], -QF[b, 2], -QF[b, 3], w, x, y, z)
            nq = _K.fast_sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
            qout[b, jt, 0] = qw / nq
            qout[b, jt, 1] = qx / nq
            qout[b, jt, 2] = qy / nq
            qout[b, jt, 3] = qz / nq
            wout[b, jt, 0] = o1 * W
            wout[b, jt, 1] = o2 * W
            wout[b, jt, 2] = OM0[b, 2]
            if not (math.isfinite(nq) and math.isfinite(o1) and math.isfinite(o2)):
                bad += 1
    return bad


if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    def _jit(f):
        return _njit(cache=True, nogil=True, error_model="numpy")(f)

    def _jiti(f):
        return _njit(cache=True, nogil=True, error_model="numpy", forceinline=True)(f)

    _rf2 = _jit(_rf2)
    _reduced_args = _jiti(_reduced_args)
    _periodic = _jiti(_periodic)
    heavy_top_kernel = _jit(heavy_top_kernel)
