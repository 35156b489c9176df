r"""Lane kernel of the closed-form free rigid body (private): ``LANES`` evaluations in lockstep.

The scalar kernel (:mod:`eulerpoisson.solvers.exact.scalar`) evaluates one (body, time) after the
other; every evaluation is a few long chains of dependent operations (the
double-double AGM of ``K``, the duplication of Carlson's ``R_F`` and ``R_J``,
the Landen chain), so one core runs them at the speed of their latencies.
Here :data:`LANES` (16) independent evaluations run side by side, with the
lane loop innermost over stack buffers (:func:`~eulerpoisson.util.jit.stack_buffer`),
which LLVM turns into AVX2/AVX-512 code (the technique of the taylor lane
kernel, see :mod:`eulerpoisson.solvers.taylor.kernels`):

* ``LANES`` times of one body (the body set up in lane 0 and copied), or
  ``LANES`` bodies set up together (:mod:`~eulerpoisson.solvers.exact.lanes_setup`:
  sorting, scaling and regime, then the AGM, the Landen chain and the ``R_F`` of
  the initial phase) and evaluated at each time together (the Monte-Carlo
  case: many bodies, one time each), whichever makes fewer blocks;
* the evaluation (:func:`_eval_lanes`): the Jacobi functions (reduction and
  Landen ascent, :func:`_jacobi_lanes`), every ``R_J`` the lanes need packed
  into one list of jobs (:func:`_rj_jobs`), the attitude
  (:func:`_attitude_lanes`).

Each lane performs exactly the operations of the scalar kernel, by calling
its helper functions (compiled inline); a lane that has converged (or takes
the other branch) keeps its values while the others go on, so the results
are those of :func:`~eulerpoisson.solvers.exact.scalar.body_setup` and
:func:`~eulerpoisson.solvers.exact.scalar.body_eval` bit for bit, in every
regime, the separatrix included (``tests/test_exact_lanes.py``).  The library
calls (``sin``, ``sinh``, ``atan2``, ``hypot``, ...), the rescaling where
``2**k`` is not a normal number, the closed-form ``R_C`` terms of ``R_J``
and the bodies whose set-up branches (relative equilibria) run lane by lane
in scalar loops; ``t = 0`` returns the initial condition exactly
(:func:`_initial`).

What makes LLVM vectorize the lane loops (found by trial, measured): the
helpers inlined (a call from one numba function to another is an indirect
call); no ``fmod`` and no call to the C library's ``sqrt`` in a loop; loops
over a run-time number of lanes (with a small constant trip count LLVM unrolls
a loop fully and then does not vectorize it); inputs copied into local
buffers first and results copied out last, with few distinct arrays written
per loop (each pair of an array written and an argument read needs a
run-time overlap check, and LLVM gives up beyond a few); whole vectors of
``R_J`` jobs (a scalar remainder loop runs the long Horner chain of the
``R_C`` series one job at a time).

The per-body constants of lane ``l`` live at ``CL[k * LANES + l]`` (``k`` a
field ``C_*`` of :mod:`~eulerpoisson.solvers.exact.state`), so that the
vector loops read them contiguously; the scalar helpers see a lane's
constants through the strided view ``CL[l::LANES]``.

Note for development: numba's on-disk cache of a function is keyed on the
source file that defines it only, and the compiled code of this module and of
:mod:`~eulerpoisson.solvers.exact.lanes_setup` contains the helpers of ``scalar.py`` and
``scalar_elliptic.py`` (and of ``numerics/elliptic.py``, ``numerics/doubledouble.py``); after editing those alone, delete the
``__pycache__/*.nbi``/``*.nbc`` files of this package (or touch this file).
The first call in a fresh environment compiles the lane kernel in about 18 s
(the scalar kernel alone took 7).
"""

from __future__ import annotations

import math

from ...util.jit import USE_NUMBA, stack_buffer
from .lanes_setup import setup_lanes
from .scalar import (
    equilibrium_eval,
    jsep,
    jtot_args,
    jtot_from,
    near_xadd,
    pick3,
    qmin,
    qmul,
    theta_v,
)
from .scalar_elliptic import (
    MAX_DUPLICATION,
    RC_SERIES_MAX,
    RDJ_QFAC,
    SINCOS_POLY_MAX,
    cos_poly,
    dd_add,
    dn_from_sc,
    fast_sqrt,
    imag_level,
    quadrant,
    rc1,
    rc1_series,
    real_level,
    reduce,
    rj_finish,
    rj_init,
    sech_real,
    sin_poly,
    two_prod,
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
    C_NLEV,
    C_NU,
    C_NUD,
    C_OMNU,
    C_OMNUD,
    C_PCL,
    C_PCORR,
    C_PERM0,
    C_PERM1,
    C_PH,
    C_Q0W,
    C_Q0X,
    C_Q0Y,
    C_Q0Z,
    C_RATE,
    C_SA,
    C_SC,
    C_SEP,
    C_SGN1,
    C_SN0,
    C_SQM,
    C_T0H,
    C_T0L,
    C_TAU0_C,
    C_TAU0_D,
    C_TAU0_N,
    C_TAU0_R,
    C_TAU0_S,
    C_TAU0V,
    C_THETA0,
    C_TSCALE,
    LANES,
    MAX_LANDEN,
    N_CONST,
    N_TAU0V,
)

__all__ = ["LANES", "motion_lanes"]

_L = LANES  # evaluations in lockstep (state.LANES)
_CL_SIZE = N_CONST * _L
#: R_J jobs of one evaluation of the lanes: at most 3 per lane and round
_NJOB = 3 * _L
#: Jacobi arguments of one evaluation: tau, tau0 (first evaluation), delta (near branch)
_NJAC = 3 * _L
# buffer sizes (stack_buffer needs module-level constants)
_L6 = 6 * _L
_L10 = 10 * _L
_L12 = 12 * _L
_L7 = 7 * _L
_NJAC8 = 8 * _NJAC
_ATT_IN = 17 * _L
_JAC_LC = 9 * _L
_JAC_LV = 2 * MAX_LANDEN * _L
_JAC_IN = 3 * _NJAC
_JAC_W = 10 * _NJAC

_TINY_DELTA = 2.0**-960
#: rows of CL copied by _jacobi_lanes
_JAC_ROWS = (C_SEP, C_KH, C_KL, C_PH, C_PCORR, C_M, C_M1, C_KP, C_NLEV)


# =============================================================================
# Carlson's R_J for a list of jobs
# =============================================================================
def _rj_jobs(X, Y, Z, P, R, n):
    """``R[j] = R_J(X[j], Y[j], Z[j], P[j])`` for ``j < n`` (``scalar_elliptic.rj3``, one job per slot).

    The slots run the duplication in lockstep, each with its own stopping
    rule; the ``R_C`` term of a step is the series (vector code) unless
    ``|e| > 2**-5``, where the closed form is called for that slot alone.
    """
    X0 = stack_buffer(_NJOB)
    Y0 = stack_buffer(_NJOB)
    Z0 = stack_buffer(_NJOB)
    A0 = stack_buffer(_NJOB)
    A = stack_buffer(_NJOB)
    F = stack_buffer(_NJOB)
    x = stack_buffer(_NJOB)
    y = stack_buffer(_NJOB)
    z = stack_buffer(_NJOB)
    p = stack_buffer(_NJOB)
    acc = stack_buffer(_NJOB)
    dl = stack_buffer(_NJOB)
    sc = stack_buffer(_NJOB)
    q = stack_buffer(_NJOB)
    E = stack_buffer(_NJOB)
    D = stack_buffer(_NJOB)
    SP = stack_buffer(_NJOB)
    LM = stack_buffer(_NJOB)
    RC = stack_buffer(_NJOB)
    RUN = stack_buffer(_NJOB)
    # whole vectors only (a scalar remainder loop would run the long latency chains one job at a time):
    # padding jobs R_J(1, 1, 1, 1) stop at once
    m = n
    for j in range(n, ((n + _L - 1) // _L) * _L):
        X[j] = 1.0
        Y[j] = 1.0
        Z[j] = 1.0
        P[j] = 1.0
        m += 1
    n = m
    for j in range(n):
        x0 = X[j]
        y0 = Y[j]
        z0 = Z[j]
        p0 = P[j]
        X0[j] = x0
        Y0[j] = y0
        Z0[j] = z0
        x[j] = x0
        y[j] = y0
        z[j] = z0
        p[j] = p0
        # scalar_elliptic.rj_init without the rescaling of a tiny delta (below)
        a0 = (x0 + y0 + z0 + 2.0 * p0) / 5.0
        A0[j] = a0
        A[j] = a0
        F[j] = 1.0
        acc[j] = 0.0
        dl[j] = (p0 - x0) * (p0 - y0) * (p0 - z0)
        sc[j] = 1.0
        q[j] = RDJ_QFAC * max(max(abs(a0 - x0), abs(a0 - y0)), max(abs(a0 - z0), abs(a0 - p0)))
    for j in range(n):
        if abs(dl[j]) < _TINY_DELTA:
            a0, delta, s_, q_ = rj_init(X0[j], Y0[j], Z0[j], p[j])
            dl[j] = delta
            sc[j] = s_
    for _ in range(MAX_DUPLICATION):
        for j in range(n):
            f = F[j]
            RUN[j] = 1.0 if f * q[j] >= abs(A[j]) else 0.0
            sx = fast_sqrt(x[j])
            sy = fast_sqrt(y[j])
            sz = fast_sqrt(z[j])
            sp = fast_sqrt(p[j])
            lam = sx * sy + sy * sz + sz * sx
            d = (sp + sx) * (sp + sy) * (sp + sz)
            dd = d * sc[j]
            e = (f * f * f) * dl[j] / (dd * dd)
            E[j] = e
            D[j] = d
            SP[j] = sp
            LM[j] = lam
            RC[j] = rc1_series(e)
        # integer counts (vector code): running slots, and those whose R_C term needs the closed form
        nrun = 0
        nbig = 0
        for j in range(n):
            r = RUN[j] != 0.0
            nrun += 1 if r else 0
            nbig += 1 if (r and not (abs(E[j]) <= RC_SERIES_MAX)) else 0
        if nrun == 0:
            break
        if nbig > 0:
            for j in range(n):
                if RUN[j] != 0.0 and not (abs(E[j]) <= RC_SERIES_MAX):
                    RC[j] = rc1(E[j], SP[j], p[j], LM[j], D[j])
        for j in range(n):
            r = RUN[j] != 0.0
            lam = LM[j]
            f = F[j]
            acc[j] = acc[j] + f * RC[j] / D[j] if r else acc[j]
            A[j] = 0.25 * (A[j] + lam) if r else A[j]
            F[j] = 0.25 * f if r else f
            x[j] = 0.25 * (x[j] + lam) if r else x[j]
            y[j] = 0.25 * (y[j] + lam) if r else y[j]
            z[j] = 0.25 * (z[j] + lam) if r else z[j]
            p[j] = 0.25 * (p[j] + lam) if r else p[j]
    for j in range(n):
        E[j] = rj_finish(A0[j], X0[j], Y0[j], Z0[j], A[j], F[j], acc[j])
    for j in range(n):
        R[j] = E[j]


# =============================================================================
# Jacobi elliptic functions, one argument per lane and group
# =============================================================================
def _jacobi_lanes(CL, UH, UL, ON, ng, nl, O):
    """Jacobi functions of the double-double arguments ``UH + UL`` (``scalar_elliptic.sncndn3``).

    Slot ``j = g * LANES + l`` (group ``g < ng``, lane ``l < nl``) holds an
    argument of lane ``l``, whose constants are in ``CL``;
    ``O[k * _NJAC + j]`` receives ``(sn, cn, dn, n, r, s, c, d)[k]`` for the
    slots ``ON`` (benign values ``sn = 0``, ``cn = dn = 1`` for the others).
    The reduction, the Landen ascent, ``dn`` and the quarter-period map are
    vector code over the lanes; the starting values (``sin``/``cos`` or
    ``sinh``/``cosh``) are library calls slot by slot.  The inputs are copied
    into local buffers first and the results out at the end (see
    :func:`_attitude_lanes`).
    """
    LC = stack_buffer(_JAC_LC)  # lane constants: sep, kh, kl, ph, pcorr, m, m1, kp, nlev
    LV = stack_buffer(_JAC_LV)  # Landen levels: sqrt(p_i) at i * LANES, 1 - p_i at (MAX_LANDEN + i) * LANES
    IN = stack_buffer(_JAC_IN)  # uh, ul, on of the slots
    W = stack_buffer(
        _JAC_W
    )  # n, r, neg, vn, dv, im, s, c, y, v of the slots (im: 1 imaginary path, 0 real, 2 separatrix, -1 off)
    OL = stack_buffer(_NJAC8)
    maxlev = 0
    for l in range(nl):
        for k in range(9):
            LC[k * _L + l] = CL[_JAC_ROWS[k] * _L + l]
        nlv = int(CL[C_NLEV * _L + l])
        if nlv > maxlev:
            maxlev = nlv
    for i in range(maxlev):
        for l in range(nl):
            LV[i * _L + l] = CL[(C_SQM + i) * _L + l]
            LV[(MAX_LANDEN + i) * _L + l] = CL[(C_PCL + i) * _L + l]
    nj = ng * _L
    for j in range(nj):
        IN[j] = UH[j]
        IN[_NJAC + j] = UL[j]
        IN[2 * _NJAC + j] = ON[j]
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            sep = LC[l] != 0.0
            n, r, neg, v, vn, dv = reduce(
                IN[j], IN[_NJAC + j], sep, LC[_L + l], LC[2 * _L + l], LC[3 * _L + l], LC[4 * _L + l]
            )
            W[j] = n
            W[_NJAC + j] = r
            W[2 * _NJAC + j] = 1.0 if neg else 0.0
            W[3 * _NJAC + j] = vn
            W[4 * _NJAC + j] = dv
            W[9 * _NJAC + j] = v
            W[5 * _NJAC + j] = (
                -1.0 if IN[2 * _NJAC + j] == 0.0 else (2.0 if sep else (1.0 if LC[5 * _L + l] > 0.5 else 0.0))
            )
    any_real = False
    any_imag = False
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            # the real path's starting values by the polynomials (scalar_elliptic._real_start), vector code
            # for every slot; the other paths overwrite them below
            vn = W[3 * _NJAC + j]
            W[6 * _NJAC + j] = sin_poly(vn)
            W[7 * _NJAC + j] = cos_poly(vn)
            W[8 * _NJAC + j] = sin_poly(0.5 * vn)
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            im = W[5 * _NJAC + j]
            vn = W[3 * _NJAC + j]
            # starting values at the bottom of the chain (library calls)
            if im == 1.0:
                W[6 * _NJAC + j] = math.sinh(vn)
                W[7 * _NJAC + j] = math.cosh(vn)
                any_imag = True
            elif im == 0.0:
                if not (vn <= SINCOS_POLY_MAX):
                    W[6 * _NJAC + j] = math.sin(vn)
                    W[7 * _NJAC + j] = math.cos(vn)
                    W[8 * _NJAC + j] = math.sin(0.5 * vn)
                any_real = True
            elif im == 2.0:
                # the separatrix (scalar_elliptic._finish): tanh, sech of |r|
                v = W[9 * _NJAC + j]
                W[6 * _NJAC + j] = math.tanh(v)
                W[7 * _NJAC + j] = sech_real(v)
                W[8 * _NJAC + j] = 0.0
            else:
                W[6 * _NJAC + j] = 0.0
                W[7 * _NJAC + j] = 1.0
                W[8 * _NJAC + j] = 0.0
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            # scalar_elliptic._imag_start / scalar_elliptic._real_start: first-order correction for the low part
            dv = W[4 * _NJAC + j]
            im = W[5 * _NJAC + j]
            s0 = W[6 * _NJAC + j]
            c0 = W[7 * _NJAC + j]
            h = W[8 * _NJAC + j]
            W[6 * _NJAC + j] = s0 + c0 * dv if (im == 0.0) | (im == 1.0) else s0
            W[7 * _NJAC + j] = (c0 + s0 * dv) if im == 1.0 else ((c0 - s0 * dv) if im == 0.0 else c0)
            W[8 * _NJAC + j] = (2.0 * h * h + s0 * dv) if im == 0.0 else 0.0
    for k in range(maxlev):
        i = maxlev - 1 - k
        fi = 1.0 * i
        if any_imag:
            for g in range(ng):
                o = g * _L
                for l in range(nl):
                    j = o + l
                    sq = LV[i * _L + l]
                    ok = (W[5 * _NJAC + j] == 1.0) & (fi < LC[8 * _L + l]) & (sq > 0.0)
                    s0 = W[6 * _NJAC + j]
                    c0 = W[7 * _NJAC + j]
                    s1, c1 = imag_level(s0, c0, sq)
                    W[6 * _NJAC + j] = s1 if ok else s0
                    W[7 * _NJAC + j] = c1 if ok else c0
        if any_real:
            for g in range(ng):
                o = g * _L
                for l in range(nl):
                    j = o + l
                    sq = LV[i * _L + l]
                    ok = (W[5 * _NJAC + j] == 0.0) & (fi < LC[8 * _L + l]) & (sq > 0.0)
                    s0 = W[6 * _NJAC + j]
                    c0 = W[7 * _NJAC + j]
                    y0 = W[8 * _NJAC + j]
                    s1, c1, y1 = real_level(s0, c0, y0, sq, LV[(MAX_LANDEN + i) * _L + l])
                    W[6 * _NJAC + j] = s1 if ok else s0
                    W[7 * _NJAC + j] = c1 if ok else c0
                    W[8 * _NJAC + j] = y1 if ok else y0
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            im = W[5 * _NJAC + j] == 1.0
            sp = W[5 * _NJAC + j] == 2.0
            S0 = W[6 * _NJAC + j]
            C0 = W[7 * _NJAC + j]
            Y0 = W[8 * _NJAC + j]
            sv = S0 / C0 if im else S0
            cv = 1.0 / C0 if im else (C0 if sp else (1.0 - Y0 if Y0 < 0.5 else C0))
            dn_ = dn_from_sc(sv, cv, LC[5 * _L + l], LC[6 * _L + l])
            dv = cv if sp else dn_
            a, b, e, f, h, kk, u, w = quadrant(W[j], W[_NJAC + j], W[2 * _NJAC + j] != 0.0, sv, cv, dv, LC[7 * _L + l])
            OL[j] = a
            OL[_NJAC + j] = b
            OL[2 * _NJAC + j] = e
            OL[3 * _NJAC + j] = f
            OL[4 * _NJAC + j] = h
            OL[5 * _NJAC + j] = kk
            OL[6 * _NJAC + j] = u
            OL[7 * _NJAC + j] = w
    for g in range(ng):
        o = g * _L
        for l in range(nl):
            j = o + l
            for k in range(8):
                O[k * _NJAC + j] = OL[k * _NJAC + j]


# =============================================================================
# evaluation of the lanes at their times
# =============================================================================
def _eval_lanes(CL, TT, ON, OUT, nl):
    """``OUT[k * LANES + l]`` = ``(M_0, M_1, M_2, q_w, q_x, q_y, q_z)[k]`` of lane ``l < nl`` at time ``TT[l]``.

    Only the lanes ``ON`` (generic: not on the separatrix, ``t != 0``, normal
    scale factors) are evaluated; the result is that of ``scalar.body_eval``
    bit for bit, including the constants computed on first use (stored in the
    lane's column of ``CL``).
    """
    TS = stack_buffer(_L)
    DH = stack_buffer(_L)
    DLo = stack_buffer(_L)
    UH = stack_buffer(_NJAC)
    UL = stack_buffer(_NJAC)
    JON = stack_buffer(_NJAC)
    O = stack_buffer(_NJAC8)
    GF = stack_buffer(_L)  # slot of the tau0 argument of a lane (-1: none)
    GN = stack_buffer(_L)  # slot of the delta argument
    NEAR = stack_buffer(_L)
    THETA = stack_buffer(_L)
    DJ = stack_buffer(_L)
    XADD = stack_buffer(_L)
    JX = stack_buffer(_NJOB)
    JY = stack_buffer(_NJOB)
    JZ = stack_buffer(_NJOB)
    JP = stack_buffer(_NJOB)
    JR = stack_buffer(_NJOB)
    IT = stack_buffer(_L)  # job of R_J(tau) (far) or of the delta integral (near), -1: none
    I0 = stack_buffer(_L)  # job of R_J(tau0) (far)
    IC = stack_buffer(_L)  # job of the complete integral (J_c, or J_cd in round two)
    AUX = stack_buffer(_L12)  # odd, S, S2, C2, D2, p of tau, then of tau0 (far); of delta (near)
    RT = stack_buffer(_L)
    R0 = stack_buffer(_L)
    USH = stack_buffer(_L)
    ALPHA = stack_buffer(_L)
    CA = stack_buffer(_L)
    SAL = stack_buffer(_L)
    lam_r = CL[C_LAM * _L : (C_LAM + 1) * _L]
    tsc_r = CL[C_TSCALE * _L : (C_TSCALE + 1) * _L]
    t0h_r = CL[C_T0H * _L : (C_T0H + 1) * _L]
    t0l_r = CL[C_T0L * _L : (C_T0L + 1) * _L]
    kfull_r = CL[C_KFULL * _L : (C_KFULL + 1) * _L]
    # --- arguments: tau = lambda t + tau0 (double-double), near/far, first evaluation
    for l in range(nl):
        TS[l] = TT[l] * tsc_r[l]
    for l in range(nl):
        if tsc_r[l] == 0.0:
            # 2**escale is not a normal number (scalar._ldexp)
            TS[l] = math.ldexp(TT[l], int(CL[C_ESCALE * _L + l]))
    for l in range(nl):
        ts = TS[l]
        dh, dl = two_prod(lam_r[l], ts)
        th, tl = dd_add(dh, dl, t0h_r[l], t0l_r[l])
        DH[l] = dh
        DLo[l] = dl
        UH[l] = th
        UL[l] = tl
        JON[l] = ON[l]
        NEAR[l] = 1.0 if abs(dh) <= kfull_r[l] else 0.0
    any_first = False
    any_near = False
    for l in range(nl):
        GF[l] = -1.0
        GN[l] = -1.0
        if ON[l] != 0.0:
            if CL[C_HAVE_T0 * _L + l] == 0.0:
                any_first = True
            if NEAR[l] != 0.0:
                any_near = True
    ng = 1
    if any_first:
        o = ng * _L
        for l in range(nl):
            first = ON[l] != 0.0 and CL[C_HAVE_T0 * _L + l] == 0.0
            UH[o + l] = t0h_r[l]
            UL[o + l] = t0l_r[l]
            JON[o + l] = 1.0 if first else 0.0
            GF[l] = 1.0 * (o + l) if first else -1.0
        ng += 1
    if any_near:
        o = ng * _L
        for l in range(nl):
            near = ON[l] != 0.0 and NEAR[l] != 0.0
            UH[o + l] = DH[l]
            UL[o + l] = DLo[l]
            JON[o + l] = 1.0 if near else 0.0
            GN[l] = 1.0 * (o + l) if near else -1.0
        ng += 1
    _jacobi_lanes(CL, UH, UL, JON, ng, nl, O)
    # --- values at tau0 on the first evaluation (SN0, THETA0, the reduced tau0), theta at tau
    for l in range(nl):
        if ON[l] == 0.0:
            continue
        ac = CL[C_AC * _L + l]
        kp = CL[C_KP * _L + l]
        a2 = CL[C_A2 * _L + l]
        if GF[l] >= 0.0:
            j = int(GF[l])
            CL[C_SN0 * _L + l] = O[j]
            CL[C_THETA0 * _L + l] = theta_v(ac, kp, a2, O[3 * _NJAC + j], O[5 * _NJAC + j], O[6 * _NJAC + j])
            for k in range(N_TAU0V):
                CL[(C_TAU0V + k) * _L + l] = O[(3 + k) * _NJAC + j]
            CL[C_HAVE_T0 * _L + l] = 1.0
        THETA[l] = theta_v(ac, kp, a2, O[3 * _NJAC + l], O[5 * _NJAC + l], O[6 * _NJAC + l])
    # --- round one of R_J: far lanes (tau, tau0 on the first far evaluation, J_c), J_c of near lanes.
    # The arguments of scalar._far for every lane in vector code (AUX rows: odd, S, S2, C2, D2, p at
    # tau, then at tau0), the list of jobs lane by lane, the integrals from the R_J in vector code.
    for l in range(nl):
        caseB = CL[C_CASEB * _L + l] != 0.0
        nu = CL[C_NU * _L + l]
        omnu = CL[C_OMNU * _L + l]
        kp = CL[C_KP * _L + l]
        n = O[3 * _NJAC + l]
        neff = n - 1.0 if caseB else n
        odd, S, S2, C2, D2, p = jtot_args(nu, omnu, neff, O[5 * _NJAC + l], O[6 * _NJAC + l], O[7 * _NJAC + l], kp)
        n0 = CL[C_TAU0_N * _L + l]
        neff0 = n0 - 1.0 if caseB else n0
        odd0, S0, S20, C20, D20, p0 = jtot_args(
            nu, omnu, neff0, CL[C_TAU0_S * _L + l], CL[C_TAU0_C * _L + l], CL[C_TAU0_D * _L + l], kp
        )
        AUX[l] = 1.0 if odd else 0.0
        AUX[_L + l] = S
        AUX[2 * _L + l] = S2
        AUX[3 * _L + l] = C2
        AUX[4 * _L + l] = D2
        AUX[5 * _L + l] = p
        AUX[6 * _L + l] = 1.0 if odd0 else 0.0
        AUX[7 * _L + l] = S0
        AUX[8 * _L + l] = S20
        AUX[9 * _L + l] = C20
        AUX[10 * _L + l] = D20
        AUX[11 * _L + l] = p0
    nj = 0
    for l in range(nl):
        IT[l] = -1.0
        I0[l] = -1.0
        IC[l] = -1.0
        if ON[l] == 0.0:
            continue
        need_jc = False
        if NEAR[l] == 0.0:
            if AUX[2 * _L + l] > 0.0:
                JX[nj] = AUX[3 * _L + l]
                JY[nj] = AUX[4 * _L + l]
                JZ[nj] = 1.0
                JP[nj] = AUX[5 * _L + l]
                IT[l] = 1.0 * nj
                nj += 1
            if CL[C_HAVE_JFAR0 * _L + l] == 0.0 and AUX[8 * _L + l] > 0.0:
                JX[nj] = AUX[9 * _L + l]
                JY[nj] = AUX[10 * _L + l]
                JZ[nj] = 1.0
                JP[nj] = AUX[11 * _L + l]
                I0[l] = 1.0 * nj
                nj += 1
            need_jc = True
        else:
            nd = O[3 * _NJAC + int(GN[l])]
            need_jc = CL[C_CASEB * _L + l] != 0.0 or nd != 0.0
        if need_jc and CL[C_HAVE_JC * _L + l] == 0.0:
            JX[nj] = 0.0
            JY[nj] = CL[C_M1 * _L + l]
            JZ[nj] = 1.0
            JP[nj] = CL[C_OMNU * _L + l]
            IC[l] = 1.0 * nj
            nj += 1
    if nj > 0:
        _rj_jobs(JX, JY, JZ, JP, JR, nj + 0)  # (+ 0: an int64, never a literal 0 typed apart)
    for l in range(nl):
        RT[l] = JR[int(IT[l])] if IT[l] >= 0.0 else 0.0
        R0[l] = JR[int(I0[l])] if I0[l] >= 0.0 else 0.0
        if ON[l] != 0.0 and IC[l] >= 0.0:
            CL[C_JC * _L + l] = JR[int(IC[l])] / 3.0
            CL[C_HAVE_JC * _L + l] = 1.0
    for l in range(nl):
        # scalar._far after its R_J (J_far(tau0) stored below where it is new)
        caseB = CL[C_CASEB * _L + l] != 0.0
        m1 = CL[C_M1 * _L + l]
        jc = CL[C_JC * _L + l]
        n0 = CL[C_TAU0_N * _L + l]
        neff0 = n0 - 1.0 if caseB else n0
        j0 = jtot_from(
            AUX[6 * _L + l] != 0.0, neff0, CL[C_TAU0_R * _L + l], jc, AUX[7 * _L + l], AUX[8 * _L + l], R0[l]
        )
        n = O[3 * _NJAC + l]
        neff = n - 1.0 if caseB else n
        jj = jtot_from(AUX[l] != 0.0, neff, O[4 * _NJAC + l], jc, AUX[_L + l], AUX[2 * _L + l], RT[l])
        R0[l] = m1 * j0 if caseB else j0
        RT[l] = m1 * jj if caseB else jj
    for l in range(nl):
        if ON[l] == 0.0 or NEAR[l] != 0.0:
            continue
        if CL[C_HAVE_JFAR0 * _L + l] == 0.0:
            CL[C_JFAR0 * _L + l] = R0[l]
            CL[C_HAVE_JFAR0 * _L + l] = 1.0
        DJ[l] = RT[l] - CL[C_JFAR0 * _L + l]
    # --- near lanes: addition theorem (scalar._near), round two of R_J
    if any_near:
        nj = 0
        for l in range(nl):
            IT[l] = -1.0
            IC[l] = -1.0
            if ON[l] == 0.0 or NEAR[l] == 0.0:
                continue
            j = int(GN[l])
            N = CL[C_NADD * _L + l]
            XADD[l] = near_xadd(N, CL[C_CADD * _L + l], O[l] * CL[C_SN0 * _L + l], O[j], O[_NJAC + j], O[2 * _NJAC + j])
            dlt = DH[l] + DLo[l]
            caseB = CL[C_CASEB * _L + l] != 0.0
            g0 = CL[C_G0 * _L + l]
            m1 = CL[C_M1 * _L + l]
            use_sh = caseB and (abs(dlt) * g0 > m1 * CL[C_JC * _L + l])
            USH[l] = 1.0 if use_sh else 0.0
            n = O[3 * _NJAC + j]
            if use_sh:
                nu = CL[C_NU * _L + l]
                omnu = CL[C_OMNU * _L + l]
                nx = n - 1.0
            else:
                nu = CL[C_NUD * _L + l]
                omnu = CL[C_OMNUD * _L + l]
                nx = n
            odd, S, S2, C2, D2, p = jtot_args(
                nu, omnu, nx, O[5 * _NJAC + j], O[6 * _NJAC + j], O[7 * _NJAC + j], CL[C_KP * _L + l]
            )
            AUX[l] = 1.0 if odd else 0.0
            AUX[_L + l] = S
            AUX[2 * _L + l] = S2
            if S2 > 0.0 and CL[C_SEP * _L + l] == 0.0:
                JX[nj] = C2
                JY[nj] = D2
                JZ[nj] = 1.0
                JP[nj] = p
                IT[l] = 1.0 * nj
                nj += 1
            if caseB and not use_sh and n != 0.0 and CL[C_HAVE_JCD * _L + l] == 0.0:
                JX[nj] = 0.0
                JY[nj] = m1
                JZ[nj] = 1.0
                JP[nj] = CL[C_OMNUD * _L + l]
                IC[l] = 1.0 * nj
                nj += 1
        if nj > 0:
            _rj_jobs(JX, JY, JZ, JP, JR, nj + 0)  # (+ 0: an int64, never a literal 0 typed apart)
        for l in range(nl):
            if ON[l] == 0.0 or NEAR[l] == 0.0:
                continue
            if IC[l] >= 0.0:
                CL[C_JCD * _L + l] = JR[int(IC[l])] / 3.0
                CL[C_HAVE_JCD * _L + l] = 1.0
            j = int(GN[l])
            n = O[3 * _NJAC + j]
            caseB = CL[C_CASEB * _L + l] != 0.0
            use_sh = USH[l] != 0.0
            m1 = CL[C_M1 * _L + l]
            if use_sh:
                nx = n - 1.0
                jc = 1.0 if nx == 0.0 else CL[C_JC * _L + l]
            else:
                nx = n
                if n == 0.0:
                    jc = 1.0
                elif caseB:
                    jc = CL[C_JCD * _L + l]
                else:
                    jc = CL[C_JC * _L + l]
            rj = JR[int(IT[l])] if IT[l] >= 0.0 else 0.0
            jd = jtot_from(AUX[l] != 0.0, nx, O[4 * _NJAC + j], jc, AUX[_L + l], AUX[2 * _L + l], rj)
            dlt = DH[l] + DLo[l]
            if CL[C_SEP * _L + l] != 0.0:
                jd = jsep(CL[C_NADD * _L + l], dlt)
            g0 = CL[C_G0 * _L + l]
            if caseB:
                if use_sh:
                    gdel = m1 * CL[C_JC * _L + l] + m1 * jd
                else:
                    gdel = g0 * (dlt - g0 * jd)
                DJ[l] = gdel - g0 * g0 * XADD[l]
            else:
                DJ[l] = jd + XADD[l]
    # --- attitude (scalar.body_eval)
    caseb_r = CL[C_CASEB * _L : (C_CASEB + 1) * _L]
    rate_r = CL[C_RATE * _L : (C_RATE + 1) * _L]
    coef_r = CL[C_COEF * _L : (C_COEF + 1) * _L]
    th0_r = CL[C_THETA0 * _L : (C_THETA0 + 1) * _L]
    for l in range(nl):
        caseB = caseb_r[l] != 0.0
        psi = rate_r[l] * TS[l] + coef_r[l] * DJ[l]
        sigma = 1.0 if caseB else -1.0
        ALPHA[l] = psi - sigma * (THETA[l] - th0_r[l])
    for l in range(nl):
        if ON[l] != 0.0:
            CA[l] = math.cos(0.5 * ALPHA[l])
            SAL[l] = math.sin(0.5 * ALPHA[l])
        else:
            CA[l] = 1.0
            SAL[l] = 0.0
    _attitude_lanes(CL, O, ON, CA, SAL, OUT, nl)


def _attitude_lanes(CL, O, ON, CA, SAL, OUT, nl):
    """The attitude and the outputs of lanes ``l < nl`` (``scalar.body_eval``) from the Jacobi functions in ``O``
    and ``cos, sin`` of half the angle.

    Layout for LLVM's loop vectorizer: the inputs are first copied into one local buffer, the vector loop
    reads and writes local buffers only (no run-time overlap checks against the argument arrays, which
    LLVM otherwise needs for each pair and gives up beyond a few), the results are copied out at the end.
    Lanes that are off hold benign values (sn = 0, cn = dn = 1 from :func:`_jacobi_lanes`, the constants of
    a body: :func:`~eulerpoisson.solvers.exact.lanes_setup.setup_lanes` gives relative equilibria neutral ones), so that no division by zero
    occurs, also in plain Python.
    """
    IN = stack_buffer(_ATT_IN)
    OO = stack_buffer(_L10)
    for l in range(nl):
        IN[l] = CL[C_CASEB * _L + l]
        IN[_L + l] = CL[C_SA * _L + l]
        IN[2 * _L + l] = CL[C_SC * _L + l]
        IN[3 * _L + l] = CL[C_AC * _L + l]
        IN[4 * _L + l] = CL[C_A2 * _L + l]
        IN[5 * _L + l] = CL[C_AA * _L + l]
        IN[6 * _L + l] = CL[C_Q0W * _L + l]
        IN[7 * _L + l] = CL[C_Q0X * _L + l]
        IN[8 * _L + l] = CL[C_Q0Y * _L + l]
        IN[9 * _L + l] = CL[C_Q0Z * _L + l]
        IN[10 * _L + l] = CL[C_MSCALE * _L + l]
        IN[11 * _L + l] = CL[C_SGN1 * _L + l]
        IN[12 * _L + l] = O[l]
        IN[13 * _L + l] = O[_NJAC + l]
        IN[14 * _L + l] = O[2 * _NJAC + l]
        IN[15 * _L + l] = CA[l]
        IN[16 * _L + l] = SAL[l]
    for l in range(nl):
        caseB = IN[l] != 0.0
        sa = IN[_L + l]
        sc = IN[2 * _L + l]
        sn = IN[12 * _L + l]
        cn = IN[13 * _L + l]
        dn = IN[14 * _L + l]
        Mc = sc * IN[3 * _L + l] * cn
        M2 = sa * sc * IN[4 * _L + l] * sn
        Ma = sa * IN[5 * _L + l] * dn
        M1 = Mc if caseB else Ma
        M3 = Ma if caseB else Mc
        sal = IN[16 * _L + l]
        ex = 0.0 if caseB else sa * sal
        ez = sa * sal if caseB else 0.0
        tw, tx, ty, tz = qmin(M1, M2, M3, caseB, sa)
        uw, ux, uy, uz = qmul(IN[15 * _L + l], ex, 0.0, ez, tw, tx, ty, tz)
        qw, qx, qy, qz = qmul(IN[6 * _L + l], -IN[7 * _L + l], -IN[8 * _L + l], -IN[9 * _L + l], uw, ux, uy, uz)
        nq = fast_sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        fM = IN[10 * _L + l]
        s1 = IN[11 * _L + l]
        # sorted frame, with the sign of the permutation on the middle axis (1.0 * x keeps the bits)
        OO[l] = 1.0 * (M1 * fM)
        OO[_L + l] = s1 * (M2 * fM)
        OO[2 * _L + l] = 1.0 * (M3 * fM)
        OO[7 * _L + l] = M1
        OO[8 * _L + l] = M2
        OO[9 * _L + l] = M3
        OO[3 * _L + l] = qw / nq
        OO[4 * _L + l] = 1.0 * (qx / nq)
        OO[5 * _L + l] = s1 * (qy / nq)
        OO[6 * _L + l] = 1.0 * (qz / nq)
    for l in range(nl):
        if CL[C_MSCALE * _L + l] == 0.0:
            # 2**eM is not a normal number (scalar._ldexp)
            eM = int(CL[C_EM * _L + l])
            s1 = CL[C_SGN1 * _L + l]
            OO[l] = 1.0 * math.ldexp(OO[7 * _L + l], eM)
            OO[_L + l] = s1 * math.ldexp(OO[8 * _L + l], eM)
            OO[2 * _L + l] = 1.0 * math.ldexp(OO[9 * _L + l], eM)
    for l in range(nl):
        # back to the input frame: x[perm[k]] = sgn[k] x_sorted[k]; input axis a holds sorted axis k with perm[k] = a
        p0 = CL[C_PERM0 * _L + l]
        p1 = CL[C_PERM1 * _L + l]
        a0 = 0 if p0 == 0.0 else (1 if p1 == 0.0 else 2)
        a1 = 0 if p0 == 1.0 else (1 if p1 == 1.0 else 2)
        a2 = 0 if p0 == 2.0 else (1 if p1 == 2.0 else 2)
        OUT[l] = OO[a0 * _L + l]
        OUT[_L + l] = OO[a1 * _L + l]
        OUT[2 * _L + l] = OO[a2 * _L + l]
        OUT[3 * _L + l] = OO[3 * _L + l]
        OUT[4 * _L + l] = OO[(4 + a0) * _L + l]
        OUT[5 * _L + l] = OO[(4 + a1) * _L + l]
        OUT[6 * _L + l] = OO[(4 + a2) * _L + l]


def _initial(CL, l, OUT):
    """The exact initial condition of lane ``l`` (``t == 0``, ``scalar.body_eval``) into ``OUT``."""
    s1 = CL[C_SGN1 * _L + l]
    Ms0 = 1.0 * CL[C_M0S * _L + l]
    Ms1 = s1 * CL[C_M0S1 * _L + l]
    Ms2 = 1.0 * CL[C_M0S2 * _L + l]
    qs0 = 1.0 * 0.0
    qs1 = s1 * 0.0
    qs2 = 1.0 * 0.0
    p0 = CL[C_PERM0 * _L + l]
    p1 = CL[C_PERM1 * _L + l]
    a0 = 0 if p0 == 0.0 else (1 if p1 == 0.0 else 2)
    a1 = 0 if p0 == 1.0 else (1 if p1 == 1.0 else 2)
    a2 = 0 if p0 == 2.0 else (1 if p1 == 2.0 else 2)
    OUT[l] = pick3(a0, Ms0, Ms1, Ms2)
    OUT[_L + l] = pick3(a1, Ms0, Ms1, Ms2)
    OUT[2 * _L + l] = pick3(a2, Ms0, Ms1, Ms2)
    OUT[3 * _L + l] = 1.0
    OUT[4 * _L + l] = pick3(a0, qs0, qs1, qs2)
    OUT[5 * _L + l] = pick3(a1, qs0, qs1, qs2)
    OUT[6 * _L + l] = pick3(a2, qs0, qs1, qs2)


# =============================================================================
# entry point
# =============================================================================
def motion_lanes(inertia, M0, t, Mout, qout):
    """Fill ``Mout`` (nb, T, 3) and ``qout`` (nb, T, 4) for bodies (nb, 3) and times (T,).

    The results of ``scalar.motion_kernel_scalar`` bit for bit. Either each
    body is set up once (in lane 0, copied to the others) and its times run
    in blocks of ``LANES``, or ``LANES`` bodies are set up at once and run
    together at each time,
    whichever makes fewer blocks (one body at many times, many bodies at
    one time: the Monte-Carlo case). Inputs are validated by the caller
    (finite, moments > 0, C-contiguous float64).
    """
    nb = inertia.shape[0]
    T = t.shape[0]
    CL = stack_buffer(_CL_SIZE)
    for i in range(_CL_SIZE):
        CL[i] = 0.0
    TT = stack_buffer(_L)
    ON = stack_buffer(_L)
    EQ = stack_buffer(_L)
    OUT = stack_buffer(_L7)
    for l in range(_L):
        EQ[l] = 0.0
    # blocks of LANES times of one body, or of one time of LANES bodies: the fewer blocks
    if nb * ((T + _L - 1) // _L) <= ((nb + _L - 1) // _L) * T:
        one = min(nb, 1)
        for b in range(nb):
            i0 = inertia[b, 0]
            i1 = inertia[b, 1]
            i2 = inertia[b, 2]
            m0 = M0[b, 0]
            m1 = M0[b, 1]
            m2 = M0[b, 2]
            # lane 0, copied to the other lanes (a computed 1: a literal 1 would compile setup_lanes a second time)
            setup_lanes(inertia, M0, b, one, CL, EQ)
            if EQ[0] != 0.0:
                EQ[0] = 0.0
                for j in range(T):
                    r0, r1, r2, r3, r4, r5, r6 = equilibrium_eval(i0, i1, i2, m0, m1, m2, t[j])
                    Mout[b, j, 0] = r0
                    Mout[b, j, 1] = r1
                    Mout[b, j, 2] = r2
                    qout[b, j, 0] = r3
                    qout[b, j, 1] = r4
                    qout[b, j, 2] = r5
                    qout[b, j, 3] = r6
                continue
            for j0 in range(0, T, _L):
                nl = min(_L, T - j0)
                _run_block(CL, TT, ON, OUT, EQ, t, j0, nl, b, 0, 1, Mout, qout)
    else:
        for b0 in range(0, nb, _L):
            nl = min(_L, nb - b0)
            setup_lanes(inertia, M0, b0, nl, CL, EQ)
            for j in range(T):
                for l in range(nl):
                    if EQ[l] != 0.0:
                        b = b0 + l
                        r0, r1, r2, r3, r4, r5, r6 = equilibrium_eval(
                            inertia[b, 0], inertia[b, 1], inertia[b, 2], M0[b, 0], M0[b, 1], M0[b, 2], t[j]
                        )
                        Mout[b, j, 0] = r0
                        Mout[b, j, 1] = r1
                        Mout[b, j, 2] = r2
                        qout[b, j, 0] = r3
                        qout[b, j, 1] = r4
                        qout[b, j, 2] = r5
                        qout[b, j, 3] = r6
                _run_block(CL, TT, ON, OUT, EQ, t, j, nl, b0, 1, 0, Mout, qout)


def _run_block(CL, TT, ON, OUT, EQ, t, j0, nl, b0, db, dj, Mout, qout):
    """Evaluate ``nl`` lanes: lane ``l`` is body ``b0 + l*db`` at time index ``j0 + l*dj``.

    Lanes at ``t = 0`` return the initial condition exactly (:func:`_initial`), the others run in
    :func:`_eval_lanes`; lanes marked in ``EQ`` (relative equilibria) are skipped: the caller evaluates them.
    """
    n_on = 0
    for l in range(nl):
        TT[l] = t[j0 + l * dj]
        on = EQ[l] == 0.0 and TT[l] != 0.0
        ON[l] = 1.0 if on else 0.0
        if on:
            n_on += 1
    for l in range(nl, _L):
        TT[l] = TT[0]
        ON[l] = 0.0
    if n_on > 0:
        _eval_lanes(CL, TT, ON, OUT, nl)
    for l in range(nl):
        if EQ[l] != 0.0:
            continue
        b = b0 + l * db
        j = j0 + l * dj
        if ON[l] == 0.0:
            _initial(CL, l, OUT)
        Mout[b, j, 0] = OUT[l]
        Mout[b, j, 1] = OUT[_L + l]
        Mout[b, j, 2] = OUT[2 * _L + l]
        qout[b, j, 0] = OUT[3 * _L + l]
        qout[b, j, 1] = OUT[4 * _L + l]
        qout[b, j, 2] = OUT[5 * _L + l]
        qout[b, j, 3] = OUT[6 * _L + l]


# =============================================================================
# compilation
# =============================================================================
if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    def _jit(f):
        return _njit(cache=True, nogil=True, error_model="numpy")(f)

    def _jit_inline(f):
        # numba-level inlining of a small function: no library of its own (numba compiles every
        # called function into a library that links, and optimizes again, the libraries of its
        # callees, so each level of the call tree costs compile time again)
        return _njit(cache=True, nogil=True, error_model="numpy", inline="always")(f)

    _rj_jobs = _jit(_rj_jobs)
    _jacobi_lanes = _jit(_jacobi_lanes)
    _attitude_lanes = _jit(_attitude_lanes)
    _eval_lanes = _jit(_eval_lanes)
    _initial = _jit(_initial)
    _run_block = _jit_inline(_run_block)
    motion_lanes = _jit(motion_lanes)
