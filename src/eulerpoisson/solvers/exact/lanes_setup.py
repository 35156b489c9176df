r"""Per-body set-up of the lane kernel (private): ``LANES`` bodies at once.

:func:`setup_lanes` is ``scalar.body_setup`` of up to :data:`LANES` bodies in
the lanes ``0 .. nl - 1`` of the lane state ``CL`` (field ``k`` of lane ``l``
at ``CL[k * LANES + l]``, the fields named in
:mod:`eulerpoisson.solvers.exact.state`): ``scalar.setup_pre`` in vector code,
:func:`params_lanes` (the AGM, the Landen chain and the ``R_F`` of the
initial phase of all lanes in one loop, each lane with its own stopping rule),
then ``scalar.setup_post`` lane by lane.  Each lane performs exactly the
operations of the scalar code, so the constants are those of
``scalar.body_setup`` bit for bit.  Used by
:func:`eulerpoisson.solvers.exact.lanes.motion_lanes`; see
:mod:`eulerpoisson.solvers.exact.lanes` for what makes LLVM vectorize these
loops.
"""

from __future__ import annotations

import math

from ...util.jit import USE_NUMBA, stack_buffer
from .scalar import exponent_lane, perm3, pick3, pow2, pre_amplitude, pre_regime, setup_post, setup_pre
from .scalar_elliptic import (
    LANDEN_THRESHOLD,
    MAX_AGM,
    MAX_DUPLICATION,
    PI_HI,
    PI_LO,
    PIO2_HI,
    PIO2_LO,
    RF_QFAC,
    TWO200,
    TWOM100,
    TWOM104,
    dd_add,
    dd_div_f,
    dd_mul,
    dd_mul_f,
    dd_sqrt_f,
    fast_sqrt,
    rf_poly,
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
    C_NLEV,
    C_NU,
    C_NUD,
    C_OMNU,
    C_OMNUD,
    C_PCL,
    C_PCORR,
    C_PERM0,
    C_PERM1,
    C_PERM2,
    C_PH,
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
    C_SQM,
    C_T0H,
    C_T0L,
    C_THETA0,
    C_TSCALE,
    LANES,
    MAX_LANDEN,
    N_CONST,
    REGIME_A,
    REGIME_B,
    SEPARATRIX,
)

__all__ = ["params_lanes", "setup_lanes"]

_L = LANES
#: rows of the buffer of setup_lanes (stack_buffer needs module-level constants)
_PRE_SIZE = 34 * _L


# =============================================================================
# per-body set-up of the lanes
# =============================================================================
def params_lanes(PM, PM1, PRX, PRY, PDO, CL, PRF, nl):
    """``scalar_elliptic.params`` of lanes ``l < nl`` at once: AGM, Landen chain, ``R_F`` (into ``CL``; ``R_F`` into ``PRF``)."""
    m_ = stack_buffer(_L)
    m1_ = stack_buffer(_L)
    rx_ = stack_buffer(_L)
    ry_ = stack_buffer(_L)
    do_ = stack_buffer(_L)
    AH = stack_buffer(_L)
    AL = stack_buffer(_L)
    BH = stack_buffer(_L)
    BL = stack_buffer(_L)
    AGM = stack_buffer(_L)
    PC = stack_buffer(_L)
    PC1 = stack_buffer(_L)
    THR = stack_buffer(_L)
    LAN = stack_buffer(_L)
    NLEV = stack_buffer(_L)
    RA0 = stack_buffer(_L)
    RQ = stack_buffer(_L)
    RA = stack_buffer(_L)
    RFAC = stack_buffer(_L)
    X = stack_buffer(_L)
    Y = stack_buffer(_L)
    Z = stack_buffer(_L)
    RFON = stack_buffer(_L)
    KH = stack_buffer(_L)
    KL = stack_buffer(_L)
    PPH = stack_buffer(_L)
    PPL = stack_buffer(_L)
    for l in range(nl):
        m_[l] = PM[l]
        m1_[l] = PM1[l]
        rx_[l] = PRX[l]
        ry_[l] = PRY[l]
        do_[l] = PDO[l]
    for l in range(nl):
        m = m_[l]
        m1 = m1_[l]
        kp = fast_sqrt(m1)
        sep = m1 == 0.0
        bh, bl = dd_sqrt_f(m1 * TWO200, 0.0)
        AH[l] = 1.0
        AL[l] = 0.0
        BH[l] = 0.0 if sep else bh * TWOM100
        BL[l] = 0.0 if sep else bl * TWOM100
        AGM[l] = 0.0 if sep else 1.0
        big = m > 0.5
        PC[l] = m1 if big else m
        PC1[l] = m if big else m1
        THR[l] = 0.25 * LANDEN_THRESHOLD * kp if big else LANDEN_THRESHOLD
        LAN[l] = 1.0
        NLEV[l] = 0.0
        rx = rx_[l]
        ry = ry_[l]
        rz = 1.0
        ra0 = (rx + ry + rz) / 3.0
        RA0[l] = ra0
        RQ[l] = RF_QFAC * max(max(abs(ra0 - rx), abs(ra0 - ry)), abs(ra0 - rz))
        RA[l] = ra0
        RFAC[l] = 1.0
        X[l] = rx
        Y[l] = ry
        Z[l] = rz
        RFON[l] = do_[l]
    for it in range(MAX_DUPLICATION):
        agm_it = it < MAX_AGM
        for l in range(nl):
            # AGM for K in double-double (scalar_elliptic.params)
            ah = AH[l]
            al = AL[l]
            bh = BH[l]
            bl = BL[l]
            dh, _dl = dd_add(ah, al, -bh, -bl)
            go = agm_it & (AGM[l] != 0.0) & (abs(dh) > TWOM104 * ah)
            sh, sl = dd_add(ah, al, bh, bl)
            ph, pl = dd_mul_f(ah, al, bh, bl)
            nbh, nbl = dd_sqrt_f(ph, pl)
            AH[l] = 0.5 * sh if go else ah
            AL[l] = 0.5 * sl if go else al
            BH[l] = nbh if go else bh
            BL[l] = nbl if go else bl
            AGM[l] = 1.0 if go else 0.0
            # R_F duplication
            ra = RA[l]
            rfac = RFAC[l]
            ron = (RFON[l] != 0.0) & (rfac * RQ[l] >= abs(ra))
            x = X[l]
            y = Y[l]
            z = Z[l]
            sx = fast_sqrt(x)
            sy = fast_sqrt(y)
            sz = fast_sqrt(z)
            lam = sx * sy + sy * sz + sz * sx
            RA[l] = 0.25 * (ra + lam) if ron else ra
            RFAC[l] = 0.25 * rfac if ron else rfac
            X[l] = 0.25 * (x + lam) if ron else x
            Y[l] = 0.25 * (y + lam) if ron else y
            Z[l] = 0.25 * (z + lam) if ron else z
            RFON[l] = 1.0 if ron else 0.0
        if it < MAX_LANDEN:
            sq_r = CL[(C_SQM + it) * _L : (C_SQM + it + 1) * _L]
            pcl_r = CL[(C_PCL + it) * _L : (C_PCL + it + 1) * _L]
            for l in range(nl):
                # descending Landen chain (level it: nlev == it while the chain runs)
                pc = PC[l]
                pc1 = PC1[l]
                lon = (LAN[l] != 0.0) & (pc > THR[l])
                kq = fast_sqrt(pc1)
                den = (1.0 + kq) * (1.0 + kq)
                sq = pc / den
                pn1 = 4.0 * kq / den
                sq_r[l] = sq if lon else sq_r[l]
                pcl_r[l] = pn1 if lon else pcl_r[l]
                NLEV[l] = NLEV[l] + 1.0 if lon else NLEV[l]
                PC[l] = sq * sq if lon else pc
                PC1[l] = pn1 if lon else pc1
                LAN[l] = 1.0 if lon else 0.0
        else:
            for l in range(nl):
                LAN[l] = 0.0
        busy = 0
        for l in range(nl):
            busy += 1 if (AGM[l] != 0.0) | (LAN[l] != 0.0) | (RFON[l] != 0.0) else 0
        if busy == 0:
            break
    maxlev = 0
    for l in range(nl):
        nlv = int(NLEV[l])
        if nlv > maxlev:
            maxlev = nlv
    for l in range(nl):
        sep = m1_[l] == 0.0
        kh, kl = dd_div_f(PI_HI, PI_LO, AH[l], AL[l])
        KH[l] = PIO2_HI if sep else 0.5 * kh
        KL[l] = PIO2_LO if sep else 0.5 * kl
        PPH[l] = 1.0
        PPL[l] = 0.0
    for i in range(maxlev):
        fi = 1.0 * i
        sq_r = CL[(C_SQM + i) * _L : (C_SQM + i + 1) * _L]
        for l in range(nl):
            ok = fi < NLEV[l]
            oh, ol = two_sum(1.0, sq_r[l])
            ph, pl = dd_mul(PPH[l], PPL[l], oh, ol)
            PPH[l] = ph if ok else PPH[l]
            PPL[l] = pl if ok else PPL[l]
    for l in range(nl):
        CL[C_KP * _L + l] = fast_sqrt(m1_[l])
        CL[C_KH * _L + l] = KH[l]
        CL[C_KL * _L + l] = KL[l]
        CL[C_PH * _L + l] = PPH[l]
        CL[C_PCORR * _L + l] = PPL[l] / PPH[l]
        CL[C_NLEV * _L + l] = NLEV[l]
        PRF[l] = rf_poly(RA0[l], rx_[l], ry_[l], RA[l], RFAC[l]) if do_[l] != 0.0 else 0.0


def setup_lanes(inertia, M0, b0, nl, CL, EQ):
    """``scalar.body_setup`` of bodies ``b0 .. b0 + nl - 1`` into lanes ``0 .. nl - 1`` (``EQ[l]``: relative equilibrium).

    ``scalar.setup_pre`` in vector code (sorting, scaling, regime and constants of all lanes at
    once; ``hypot`` lane by lane), :func:`params_lanes`, then ``scalar.setup_post`` lane by lane.
    Relative equilibria and bodies whose scale factors are not normal numbers are set up by the
    scalar code (the same values).  Lanes ``nl ..`` get a copy of lane 0.
    """
    PRE = stack_buffer(_PRE_SIZE)
    PM = stack_buffer(_L)
    PM1 = stack_buffer(_L)
    PRX = stack_buffer(_L)
    PRY = stack_buffer(_L)
    PDO = stack_buffer(_L)
    PC0 = stack_buffer(_L)
    PS0 = stack_buffer(_L)
    PMa = stack_buffer(_L)
    PMb = stack_buffer(_L)
    PMc = stack_buffer(_L)
    PRF = stack_buffer(_L)
    H = stack_buffer(_L)
    for l in range(nl):
        b = b0 + l
        i0 = inertia[b, 0]
        i1 = inertia[b, 1]
        i2 = inertia[b, 2]
        m0 = M0[b, 0]
        m1_ = M0[b, 1]
        m2 = M0[b, 2]
        p0, p1, p2, s1 = perm3(i0, i1, i2)
        I1u = pick3(p0, i0, i1, i2)
        I2u = pick3(p1, i0, i1, i2)
        I3u = pick3(p2, i0, i1, i2)
        M1u = 1.0 * pick3(p0, m0, m1_, m2)
        M2u = s1 * pick3(p1, m0, m1_, m2)
        M3u = 1.0 * pick3(p2, m0, m1_, m2)
        mmax = max(max(abs(M1u), abs(M2u)), abs(M3u))
        eMx, okM = exponent_lane(mmax)
        eI, okI = exponent_lane(I3u)
        eM = 0 if mmax == 0.0 else eMx
        fM = pow2(-eM)
        fI = pow2(-eI)
        M1 = M1u * fM
        M2 = M2u * fM
        M3 = M3u * fM
        eq, m, m1, sep, caseB, Ac, A2, Aa, lam, sa, sc, rate, coef, Nadd, nu, omnu, Cadd, g0, x, y = pre_regime(
            M1, M2, M3, I1u * fI, I2u * fI, I3u * fI
        )
        scalar = eq | ((mmax != 0.0) & (not okM)) | (not okI) | (fM == 0.0) | (fI == 0.0)
        PRE[l] = 1.0 if scalar else 0.0
        PRE[_L + l] = p0
        PRE[2 * _L + l] = p1
        PRE[3 * _L + l] = p2
        PRE[4 * _L + l] = s1
        PRE[5 * _L + l] = M1u
        PRE[6 * _L + l] = M2u
        PRE[7 * _L + l] = M3u
        PRE[8 * _L + l] = eM
        PRE[9 * _L + l] = eM - eI
        PRE[10 * _L + l] = pow2(eM)
        PRE[11 * _L + l] = pow2(eM - eI)
        PRE[12 * _L + l] = M1
        PRE[13 * _L + l] = M2
        PRE[14 * _L + l] = M3
        PRE[15 * _L + l] = m
        PRE[16 * _L + l] = m1
        PRE[17 * _L + l] = 1.0 if sep else 0.0
        PRE[18 * _L + l] = 1.0 if caseB else 0.0
        PRE[19 * _L + l] = Ac
        PRE[20 * _L + l] = A2
        PRE[21 * _L + l] = Aa
        PRE[22 * _L + l] = lam
        PRE[23 * _L + l] = sa
        PRE[24 * _L + l] = sc
        PRE[25 * _L + l] = rate
        PRE[26 * _L + l] = coef
        PRE[27 * _L + l] = Nadd
        PRE[28 * _L + l] = nu
        PRE[29 * _L + l] = omnu
        PRE[30 * _L + l] = Cadd
        PRE[31 * _L + l] = g0
        PRE[32 * _L + l] = x
        PRE[33 * _L + l] = y
    for l in range(nl):
        # the library's hypot, lane by lane (lanes set up by the scalar code are skipped)
        H[l] = 1.0 if PRE[l] != 0.0 else math.hypot(PRE[32 * _L + l], PRE[33 * _L + l])
    for l in range(nl):
        m = PRE[15 * _L + l]
        m1 = PRE[16 * _L + l]
        c0, s0, delta2 = pre_amplitude(H[l], PRE[32 * _L + l], PRE[33 * _L + l], m, m1)
        EQ[l] = 0.0
        PM[l] = m
        PM1[l] = m1
        PRX[l] = c0 * c0
        PRY[l] = delta2
        PDO[l] = 0.0 if PRE[17 * _L + l] != 0.0 else 1.0
        PC0[l] = c0
        PS0[l] = s0
        PMa[l] = PRE[12 * _L + l]
        PMb[l] = PRE[13 * _L + l]
        PMc[l] = PRE[14 * _L + l]
    for l in range(nl):
        # scalar.setup_pre's stores (scalar._pre_store), all lanes
        sep = PRE[17 * _L + l] != 0.0
        caseB = PRE[18 * _L + l] != 0.0
        CL[C_PERM0 * _L + l] = PRE[_L + l]
        CL[C_PERM1 * _L + l] = PRE[2 * _L + l]
        CL[C_PERM2 * _L + l] = PRE[3 * _L + l]
        CL[C_SGN0 * _L + l] = 1.0
        CL[C_SGN1 * _L + l] = PRE[4 * _L + l]
        CL[C_SGN2 * _L + l] = 1.0
        CL[C_M0S * _L + l] = PRE[5 * _L + l]
        CL[C_M0S1 * _L + l] = PRE[6 * _L + l]
        CL[C_M0S2 * _L + l] = PRE[7 * _L + l]
        CL[C_EM * _L + l] = PRE[8 * _L + l]
        CL[C_ESCALE * _L + l] = PRE[9 * _L + l]
        CL[C_MSCALE * _L + l] = PRE[10 * _L + l]
        CL[C_TSCALE * _L + l] = PRE[11 * _L + l]
        CL[C_REGIME * _L + l] = SEPARATRIX if sep else (REGIME_B if caseB else REGIME_A)
        CL[C_CASEB * _L + l] = 1.0 if caseB else 0.0
        CL[C_SEP * _L + l] = 1.0 if sep else 0.0
        CL[C_M * _L + l] = PRE[15 * _L + l]
        CL[C_M1 * _L + l] = PRE[16 * _L + l]
        CL[C_NU * _L + l] = PRE[28 * _L + l]
        CL[C_OMNU * _L + l] = PRE[29 * _L + l]
        CL[C_HAVE_JC * _L + l] = 0.0
        CL[C_HAVE_JCD * _L + l] = 0.0
        CL[C_HAVE_JFAR0 * _L + l] = 0.0
        CL[C_HAVE_T0 * _L + l] = 0.0
        CL[C_LAM * _L + l] = PRE[22 * _L + l]
        CL[C_AC * _L + l] = PRE[19 * _L + l]
        CL[C_A2 * _L + l] = PRE[20 * _L + l]
        CL[C_AA * _L + l] = PRE[21 * _L + l]
        CL[C_SA * _L + l] = PRE[23 * _L + l]
        CL[C_SC * _L + l] = PRE[24 * _L + l]
        CL[C_RATE * _L + l] = PRE[25 * _L + l]
        CL[C_COEF * _L + l] = PRE[26 * _L + l]
        Nadd = PRE[27 * _L + l]
        CL[C_NADD * _L + l] = Nadd
        CL[C_CADD * _L + l] = PRE[30 * _L + l]
        CL[C_G0 * _L + l] = PRE[31 * _L + l]
        CL[C_NUD * _L + l] = -Nadd if caseB else PRE[28 * _L + l]
        CL[C_OMNUD * _L + l] = 1.0 + Nadd if caseB else PRE[29 * _L + l]
    for l in range(nl):
        if PRE[l] != 0.0:
            # relative equilibria, scale factors that are not normal numbers: the scalar code
            b = b0 + l
            eq, m, m1, rx, ry, do_rf, c0, s0, M1, M2, M3 = setup_pre(
                inertia[b, 0], inertia[b, 1], inertia[b, 2], M0[b, 0], M0[b, 1], M0[b, 2], CL[l::_L]
            )
            EQ[l] = 1.0 if eq else 0.0
            PM[l] = m
            PM1[l] = m1
            PRX[l] = rx
            PRY[l] = ry
            PDO[l] = 1.0 if do_rf else 0.0
            PC0[l] = c0
            PS0[l] = s0
            PMa[l] = M1
            PMb[l] = M2
            PMc[l] = M3
    for l in range(nl, _L):
        # lanes beyond nl compute along (vector loops over all lanes) with lane 0's inputs
        EQ[l] = 0.0
        PM[l] = PM[0]
        PM1[l] = PM1[0]
        PRX[l] = PRX[0]
        PRY[l] = PRY[0]
        PDO[l] = PDO[0]
    params_lanes(PM, PM1, PRX, PRY, PDO, CL, PRF, nl)
    for l in range(nl):
        if EQ[l] == 0.0:
            setup_post(CL[l::_L], PRF[l], PC0[l], PS0[l], PMa[l], PMb[l], PMc[l])
        else:
            # a relative equilibrium is evaluated by the caller; its lane computes along with neutral values
            for k in (C_AC, C_A2, C_AA, C_SA, C_SC, C_Q0W, C_MSCALE, C_TSCALE, C_LAM, C_KFULL, C_M, C_M1):
                CL[k * _L + l] = 1.0
            for k in (C_Q0X, C_Q0Y, C_Q0Z, C_CASEB, C_SEP, C_T0H, C_T0L, C_RATE, C_COEF, C_THETA0):
                CL[k * _L + l] = 0.0
    if nl < _L:
        for k in range(N_CONST):
            v = CL[k * _L]
            for l in range(nl, _L):
                CL[k * _L + l] = v


# =============================================================================
# compilation
# =============================================================================
if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    def _jit(f):
        return _njit(cache=True, nogil=True, error_model="numpy")(f)

    params_lanes = _jit(params_lanes)
    setup_lanes = _jit(setup_lanes)
