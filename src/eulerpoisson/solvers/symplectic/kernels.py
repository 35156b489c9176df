r"""Compiled step loops of the ``symplectic`` method (private).

Two kernels, each advancing a batch of bodies through a schedule of
fixed-step segments (:func:`schedule`, the same steps as
:func:`~eulerpoisson.solvers.charts.run_fixed_step`) and writing the
state at every output time:

* :func:`run_splitting`: the Lie-Poisson splitting (``"splitting"``,
  ``"splitting4"``), a sequence of exact rotations about principal axes;
* :func:`run_gauss_quaternion`: Gauss-Legendre collocation with 1, 2 or 3
  stages in the homogeneous canonical variables :math:`(q, p)`, fixed-point
  iteration with the stopping rule of
  :func:`~eulerpoisson.solvers.symplectic.method.gauss_step`.

Design
    The bodies are independent, but one body alone is a chain of dependent
    operations (a ``sincos`` per rotation, the field of the previous
    iterate) whose latency leaves most of a core idle: written as one body
    at a time in local scalars, the splitting made about 1e7 body-steps/s
    and ``gauss4`` 5e6. The kernels therefore advance *lanes* of ``L``
    bodies in lockstep (16 for the splitting, 8 for Gauss), with the loop
    over the lanes innermost, the lane state in one flat local buffer
    (row ``r`` of lane ``l`` at ``r*L + l``) addressed at compile-time
    offsets, and no call left after inlining, no conditional load and no
    NaN-propagating select in the lane loops, so that LLVM turns every
    lane loop into AVX2/AVX-512 code (8 to 10 times the throughput). The
    loops, outermost first: chunks of ``L`` bodies, output segments, steps,
    sub-flows or fixed-point iterations, lanes. A short last chunk is
    padded with copies of its first body.

    Gauss in lockstep: a lane whose stage iteration has converged is
    frozen (its stage increments and derivatives no longer change) while
    the other lanes iterate, as the NumPy path freezes the converged bodies
    of a batch, so every body gets the iterates it would get alone. The
    tableau is passed as tuples (``b`` of length s, ``A`` and ``E`` of
    length s*s): the number of stages is then a compile-time constant, one
    specialization per s, compiled on first use.

    The rotations need :math:`\sin` and :math:`\cos`; a call to libm
    would stop the vectorization, so both paths evaluate
    :func:`sincos_numpy` (or its compiled twin): Cody-Waite reduction by
    :math:`\pi/2` and the Taylor polynomials of degree 17/16 on
    :math:`|r|\le\pi/4`, error below 1.5 ulp of :math:`\max(|\sin x|, \tfrac12)`
    (measured against mpmath in the tests); only for :math:`|x| > 2^{19}`
    are the libm functions called, in a separate loop.

Same results as NumPy
    The compiled kernels perform the same floating-point operations in the
    same order as the NumPy path of :mod:`~eulerpoisson.solvers.symplectic.method`
    (no ``fastmath``: no contraction to fused multiply-adds, no
    reassociation; the Runge-Kutta sums are written out in the same order
    in both), so the results agree bit for bit on the same machine (tested
    with ``EULERPOISSON_NO_NUMBA=1`` in a subprocess).

The kernels are used when numba is installed and the environment variable
``EULERPOISSON_NO_NUMBA`` is not ``"1"`` (decided when eulerpoisson is
imported, without importing numba: the kernels are made on their first call,
:mod:`eulerpoisson.util.jit`, as for the ``taylor`` kernels); :data:`USE_NUMBA`
says which.

References
----------
W. J. Cody and W. Waite, *Software Manual for the Elementary Functions*,
Prentice-Hall (1980), ch. 8 (argument reduction for sin and cos).
E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd
ed. (2006), VIII.6 (fixed-point iteration of implicit Runge-Kutta methods).
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np

__all__ = [
    "USE_NUMBA",
    "LANES_SPLITTING",
    "LANES_GAUSS",
    "sincos_numpy",
    "sincos_compiled",
    "schedule",
    "run_splitting",
    "run_gauss_quaternion",
    "STATUS_OK",
    "STATUS_NONFINITE",
    "STATUS_DIVERGED",
    "STATUS_MAX_ITER",
]


from ...util.jit import USE_NUMBA, kernel_array  # numba importable and EULERPOISSON_NO_NUMBA not "1"

#: bodies advanced in lockstep by the splitting kernel and by the Gauss kernel
LANES_SPLITTING = 16
LANES_GAUSS = 8

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_DIVERGED = 2
STATUS_MAX_ITER = 3

_EPS = float(np.finfo(float).eps)

# ---------------------------------------------------------------------------
# sin and cos without a library call
# ---------------------------------------------------------------------------
# pi/2 = _PIO2_HI + _PIO2_LO: the high part has 33 significant bits, so k*_PIO2_HI is exact for |k| < 2**20
_PIO2_HI = math.ldexp(math.floor(math.ldexp(math.pi / 2, 32)), -32)
with localcontext() as _ctx:
    _ctx.prec = 60
    _PIO2_LO = float(Decimal("1.570796326794896619231321691639751442098584699687552910487") - Decimal(_PIO2_HI))
_TWO_OVER_PI = 2.0 / math.pi
#: |x| above which the libm functions are used (k*_PIO2_HI stays exact)
_SINCOS_MAX = 2.0**19
# Taylor coefficients (-1)^k/(2k+1)! (k = 1..8) and (-1)^k/(2k)! (k = 2..8)
_S1, _S2, _S3, _S4, _S5, _S6, _S7, _S8 = [(-1.0) ** k / math.factorial(2 * k + 1) for k in range(1, 9)]
_C2, _C3, _C4, _C5, _C6, _C7, _C8 = [(-1.0) ** k / math.factorial(2 * k) for k in range(2, 9)]


def sincos_numpy(x):
    r""":math:`(\sin x, \cos x)`, elementwise, the same operations as the compiled kernels.

    :math:`x = k\pi/2 + r` with :math:`k = \lfloor 2x/\pi + \tfrac12\rfloor`
    and :math:`r = (x - k\,p_1) - k\,p_2` (:math:`p_1 + p_2 = \pi/2`,
    :math:`p_1` with 33 significant bits, so :math:`k p_1` is exact), then
    :math:`\sin r = r + r^3P(r^2)`, :math:`\cos r = 1 - r^2/2 + r^4Q(r^2)`
    with the Taylor polynomials up to :math:`r^{17}`, :math:`r^{16}`
    (remainders below :math:`10^{-17}` on :math:`|r|\le\pi/4`), and the
    quadrant :math:`k \bmod 4`. Error below 1.5 ulp of :math:`\max(|\sin x|, \tfrac12)`
    (resp. cos), i.e. an absolute error below :math:`1.7\cdot10^{-16}`, and
    below 1.5 ulp of the value for :math:`|x|\le\pi/4`; :math:`|x| > 2^{19}`
    and complex input use ``np.sin``/``np.cos``. Up to four values are
    evaluated with Python floats (the same operations, less overhead).

    Parameters
    ----------
    x : ndarray
        Real (float64) or complex (for complex-step derivatives).

    Returns
    -------
    s, c : ndarrays, shape of ``x``

    References
    ----------
    Cody and Waite (1980), ch. 8.
    """
    if np.iscomplexobj(x):
        return np.sin(x), np.cos(x)
    x = np.asarray(x, dtype=np.float64)
    if x.size <= 4:  # a few values: Python floats (the same IEEE operations) cost less than 30 ufunc calls
        sc = [_sincos_scalar(float(v)) for v in x.ravel()]
        return (np.array([a for a, _ in sc]).reshape(x.shape), np.array([b for _, b in sc]).reshape(x.shape))
    with np.errstate(invalid="ignore", over="ignore"):  # non-finite x: NaN, quietly (as np.sin)
        kq = np.floor(x * _TWO_OVER_PI + 0.5)
        r = (x - kq * _PIO2_HI) - kq * _PIO2_LO
        z = r * r
        sr = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * (_S6 + z * (_S7 + z * _S8)))))))
        cr = 1.0 - 0.5 * z + z * z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * (_C6 + z * (_C7 + z * _C8))))))
        hq = kq * 0.5
        odd = hq != np.floor(hq)
        q4 = kq * 0.25
        hi = (q4 - np.floor(q4)) >= 0.5
        s = np.where(odd, cr, sr)
        c = np.where(odd, sr, cr)
        s = np.where(hi, -s, s)
        c = np.where(hi != odd, -c, c)
        big = np.abs(x) > _SINCOS_MAX
        if np.any(big):
            s = np.where(big, np.sin(x), s)
            c = np.where(big, np.cos(x), c)
    return s, c


def _sincos_scalar(x):
    # the operations of sincos_numpy on one Python float
    if abs(x) > _SINCOS_MAX or x != x:
        return math.sin(x) if math.isfinite(x) else math.nan, math.cos(x) if math.isfinite(x) else math.nan
    kq = float(math.floor(x * _TWO_OVER_PI + 0.5))
    r = (x - kq * _PIO2_HI) - kq * _PIO2_LO
    z = r * r
    sr = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * (_S6 + z * (_S7 + z * _S8)))))))
    cr = 1.0 - 0.5 * z + z * z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * (_C6 + z * (_C7 + z * _C8))))))
    hq = kq * 0.5
    odd = hq != math.floor(hq)
    q4 = kq * 0.25
    hi = (q4 - math.floor(q4)) >= 0.5
    s = cr if odd else sr
    c = sr if odd else cr
    s = -s if hi else s
    c = -c if hi != odd else c
    return s, c


def _nb_sincos(x):
    # the operations of sincos_numpy, in the same order (without the |x| > _SINCOS_MAX case)
    kq = np.floor(x * _TWO_OVER_PI + 0.5)
    r = (x - kq * _PIO2_HI) - kq * _PIO2_LO
    z = r * r
    sr = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * (_S6 + z * (_S7 + z * _S8)))))))
    cr = 1.0 - 0.5 * z + z * z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * (_C6 + z * (_C7 + z * _C8))))))
    hq = kq * 0.5
    odd = hq != np.floor(hq)
    q4 = kq * 0.25
    hi = (q4 - np.floor(q4)) >= 0.5
    s = cr if odd else sr
    c = sr if odd else cr
    s = -s if hi else s
    c = -c if hi != odd else c
    return s, c


def _nb_sincos_array(x, s, c):
    n = x.shape[0]
    for i in range(n):
        si, ci = _nb_sincos(x[i])
        s[i] = si
        c[i] = ci
    for i in range(n):
        if abs(x[i]) > _SINCOS_MAX:
            s[i] = math.sin(x[i])
            c[i] = math.cos(x[i])


# ---------------------------------------------------------------------------
# the schedule of steps
# ---------------------------------------------------------------------------
def schedule(t, dt):
    r"""The steps of :func:`~eulerpoisson.solvers.charts.run_fixed_step` as flat arrays.

    Segment ``k`` restarts from the initial state if ``restart[k]`` (the
    first segment of the forward and of the backward branch), then takes
    ``nsteps[k]`` steps of size ``h[k]`` (possibly none: a repeated output
    time) and writes the state to output ``out[k]``.

    Parameters
    ----------
    t : ndarray, shape (T,)
        Output times, any order, negative allowed.
    dt : float
        Largest step (> 0, may be ``inf``).

    Returns
    -------
    h : ndarray of float64, shape (T,)
    nsteps : ndarray of int64, shape (T,)
    out : ndarray of int64, shape (T,)
    restart : ndarray of int64, shape (T,)
    total : int
        Total number of steps.
    """
    t = np.asarray(t, dtype=float)
    order = np.argsort(t, kind="stable")
    pos = [int(i) for i in order if t[i] >= 0]
    neg = [int(i) for i in order[::-1] if t[i] < 0]
    hs, ns, outs, rs = [], [], [], []
    total = 0
    for branch in (pos, neg):
        tcur = 0.0
        first = True
        for i in branch:
            L = float(t[i]) - tcur
            h, N = 0.0, 0
            if L != 0.0:
                N = max(1, int(math.ceil(abs(L) / dt * (1.0 - 1e-12)))) if math.isfinite(dt) else 1
                h = L / N
                total += N
                tcur = float(t[i])
            hs.append(h)
            ns.append(N)
            outs.append(i)
            rs.append(1 if first else 0)
            first = False
    return (
        np.array(hs, dtype=np.float64),
        np.array(ns, dtype=np.int64),
        np.array(outs, dtype=np.int64),
        np.array(rs, dtype=np.int64),
        total,
    )


# ---------------------------------------------------------------------------
# splitting kernel: rows of the lane buffer (times L = LANES_SPLITTING)
# ---------------------------------------------------------------------------
_LS = LANES_SPLITTING
_SW, _SX, _SY, _SZ = 0, _LS, 2 * _LS, 3 * _LS  # attitude quaternion
_SM0, _SM1, _SM2 = 4 * _LS, 5 * _LS, 6 * _LS  # body angular momentum
_SI0, _SI1, _SI2 = 7 * _LS, 8 * _LS, 9 * _LS  # inverse moments
_SSH, _SCH, _SXA = 10 * _LS, 11 * _LS, 12 * _LS  # sin, cos of half the angle, half the angle
_SROWS = 13


def _nb_rotate(buf, tau, mi, mj, mk, ii, vi, vj, vk):
    """Exact flow of M_i^2/(2 I_i) for time tau on all lanes (buffer offsets are constants)."""
    big = 0
    for l in range(_LS):
        x = 0.5 * (tau * (buf[mi + l] * buf[ii + l]))
        s, c = _nb_sincos(x)
        buf[_SSH + l] = s
        buf[_SCH + l] = c
        buf[_SXA + l] = x
        big += 1 if abs(x) > _SINCOS_MAX else 0
    if big:
        for l in range(_LS):
            x = buf[_SXA + l]
            if abs(x) > _SINCOS_MAX:
                buf[_SSH + l] = math.sin(x)
                buf[_SCH + l] = math.cos(x)
    for l in range(_LS):
        sh = buf[_SSH + l]
        ch = buf[_SCH + l]
        s = 2.0 * sh * ch
        c = 1.0 - 2.0 * sh * sh
        a = buf[mj + l]
        b = buf[mk + l]
        buf[mj + l] = c * a + s * b
        buf[mk + l] = c * b - s * a
        w = buf[_SW + l]
        a = buf[vi + l]
        b = buf[vj + l]
        d = buf[vk + l]
        buf[_SW + l] = w * ch - a * sh
        buf[vi + l] = w * sh + a * ch
        buf[vj + l] = b * ch + d * sh
        buf[vk + l] = d * ch - b * sh


def _nb_rotate_axis(buf, axis, tau):
    if axis == 0:
        _nb_rotate(buf, tau, _SM0, _SM1, _SM2, _SI0, _SX, _SY, _SZ)
    elif axis == 1:
        _nb_rotate(buf, tau, _SM1, _SM2, _SM0, _SI1, _SY, _SZ, _SX)
    else:
        _nb_rotate(buf, tau, _SM2, _SM0, _SM1, _SI2, _SZ, _SX, _SY)


def nb_splitting(q0, M0, inv_m, axes, fracs, seg_h, seg_n, seg_out, seg_restart, q_out, w_out):
    B = q0.shape[1]
    K = axes.shape[0]
    nseg = seg_h.shape[0]
    buf = np.zeros(_SROWS * _LS)
    f_first = fracs[0]
    f_last = fracs[K - 1]
    f_join = f_first + f_last
    a_first = axes[0]
    a_last = axes[K - 1]
    for b0 in range(0, B, _LS):
        nl = min(_LS, B - b0)
        for kseg in range(nseg):
            if seg_restart[kseg] != 0:
                for l in range(_LS):
                    bb = b0 + l if l < nl else b0
                    for c in range(4):
                        buf[c * _LS + l] = q0[c, bb]
                    for c in range(3):
                        buf[_SM0 + c * _LS + l] = M0[c, bb]
                        buf[_SI0 + c * _LS + l] = inv_m[c, bb]
            h = seg_h[kseg]
            N = seg_n[kseg]
            # the sub-flows of N steps, the last of a step merged with the first of the next:
            # sub-flow m is sequence[m mod (K-1)], except the very last one, sequence[K-1]
            for m in range(N * (K - 1) + 1 if N > 0 else 0):
                kk = m % (K - 1)
                if m == N * (K - 1):
                    axis = a_last
                    tau = f_last * h
                elif m == 0:
                    axis = a_first
                    tau = f_first * h
                elif kk == 0:
                    axis = a_first
                    tau = f_join * h
                else:
                    axis = axes[kk]
                    tau = fracs[kk] * h
                _nb_rotate_axis(buf, axis, tau)
            j = seg_out[kseg]
            for l in range(nl):
                for c in range(4):
                    q_out[b0 + l, j, c] = buf[c * _LS + l]
                for c in range(3):
                    w_out[b0 + l, j, c] = buf[_SM0 + c * _LS + l] * buf[_SI0 + c * _LS + l]


# ---------------------------------------------------------------------------
# Gauss kernel in (q, p): rows of the lane buffer (times L = LANES_GAUSS)
# ---------------------------------------------------------------------------
_LG = LANES_GAUSS
_GY = 0  # y0 of the step, 8 rows
_GZ = 8 * _LG  # stage increments, Z[i, d] at row 8 i + d, 24 rows
_GF = 32 * _LG  # stage derivatives, F[i, d] at row 8 i + d, 24 rows
_GI = 56 * _LG  # inverse moments, 3 rows
_GACT = 59 * _LG  # 1.0 while the lane iterates
_GDPREV = 60 * _LG  # increment of the previous iteration
_GSCALE = 61 * _LG  # size of y0 + Z, fixed for the step
_GCNT = 62 * _LG  # iterations of this step
_GTOT = 63 * _LG  # iterations, total
_GMAX = 64 * _LG  # iterations, most in one step
_GYMAX = 65 * _LG  # max |y0|
_GROWS = 66
# In the lane loops every load is unconditional (a conditional expression reads only one of
# its operands, and a conditional load stops the vectorization), and the maxima are plain
# max() with NaN tracked by a sum (NaN-propagating selects are not if-converted).
# The tableau comes as tuples (b of length s, A and E of length s*s), so that the number of
# stages is a compile-time constant (one specialization per s): the loops over stages and
# components inside the lane loops unroll, every row is then at a compile-time offset, and
# LLVM vectorizes the lane loops.


def _nb_field(q0, q1, q2, q3, p0, p1, p2, p3, i0, i1, i2):
    """quaternion_field of charts, the same operations in the same order."""
    a = i0 * (0.5 * (q0 * p1 - q1 * p0 - q2 * p3 + q3 * p2))
    b = i1 * (0.5 * (q0 * p2 + q1 * p3 - q2 * p0 - q3 * p1))
    c = i2 * (0.5 * (q0 * p3 - q1 * p2 + q2 * p1 - q3 * p0))
    return (
        -0.5 * (q1 * a + q2 * b + q3 * c),
        0.5 * (q0 * a + q2 * c - q3 * b),
        0.5 * (q0 * b - q1 * c + q3 * a),
        0.5 * (q0 * c + q1 * b - q2 * a),
        -0.5 * (p1 * a + p2 * b + p3 * c),
        0.5 * (p0 * a + p2 * c - p3 * b),
        0.5 * (p0 * b - p1 * c + p3 * a),
        0.5 * (p0 * c + p1 * b - p2 * a),
    )


def _nb_gauss_fields(buf, b):
    """F_i = field(y0 + Z_i), i = 1..s, on the lanes that iterate; the other lanes keep their F."""
    L = _LG
    S = len(b)
    for i in range(S):
        z = _GZ + 8 * L * i
        for l in range(L):
            keep = buf[_GACT + l] == 0.0
            f = _nb_field(
                buf[_GY + l] + buf[z + l],
                buf[_GY + L + l] + buf[z + L + l],
                buf[_GY + 2 * L + l] + buf[z + 2 * L + l],
                buf[_GY + 3 * L + l] + buf[z + 3 * L + l],
                buf[_GY + 4 * L + l] + buf[z + 4 * L + l],
                buf[_GY + 5 * L + l] + buf[z + 5 * L + l],
                buf[_GY + 6 * L + l] + buf[z + 6 * L + l],
                buf[_GY + 7 * L + l] + buf[z + 7 * L + l],
                buf[_GI + l],
                buf[_GI + L + l],
                buf[_GI + 2 * L + l],
            )
            for d in range(8):
                r = _GF + (8 * i + d) * L + l
                old = buf[r]
                buf[r] = old if keep else f[d]


def _nb_gauss_start(buf, first, E, b):
    """Start a step: Z = 0 (first step of a segment) or Z = E Z, and F = field(y0 + Z)."""
    L = _LG
    S = len(b)
    for l in range(L):
        buf[_GACT + l] = 1.0
        buf[_GDPREV + l] = math.inf
        buf[_GCNT + l] = 0.0
        ymax = 0.0
        nan = 0.0
        for d in range(8):
            ay = abs(buf[_GY + d * L + l])
            ymax = max(ymax, ay)
            nan += ay * 0.0
        buf[_GYMAX + l] = ymax + nan
    if first:
        for l in range(L):
            for i in range(S):
                for d in range(8):
                    buf[_GZ + (8 * i + d) * L + l] = 0.0
    else:
        for l in range(L):
            for d in range(8):
                z0 = buf[_GZ + d * L + l]
                z1 = buf[_GZ + (8 + d) * L + l]
                z2 = buf[_GZ + (16 + d) * L + l]
                if S == 1:
                    buf[_GZ + d * L + l] = E[0] * z0
                elif S == 2:
                    buf[_GZ + d * L + l] = E[0] * z0 + E[1] * z1
                    buf[_GZ + (8 + d) * L + l] = E[2] * z0 + E[3] * z1
                else:
                    buf[_GZ + d * L + l] = E[0] * z0 + E[1] * z1 + E[2] * z2
                    buf[_GZ + (8 + d) * L + l] = E[3] * z0 + E[4] * z1 + E[5] * z2
                    buf[_GZ + (16 + d) * L + l] = E[6] * z0 + E[7] * z1 + E[8] * z2
    _nb_gauss_fields(buf, b)


def _nb_gauss_iterate(buf, h, k, A, b):
    """One fixed-point iteration on all lanes; returns (lanes still iterating, status)."""
    L = _LG
    S = len(b)
    nactive = 0
    nonfinite = 0
    diverged = 0
    for l in range(L):
        active = buf[_GACT + l] != 0.0
        delta = 0.0
        zmax = 0.0
        nan = 0.0
        for i in range(S):
            for d in range(8):
                f0 = buf[_GF + d * L + l]
                f1 = buf[_GF + (8 + d) * L + l]
                f2 = buf[_GF + (16 + d) * L + l]
                if S == 1:
                    zn = h * (A[0] * f0)
                elif S == 2:
                    zn = h * (A[2 * i] * f0 + A[2 * i + 1] * f1)
                else:
                    zn = h * (A[3 * i] * f0 + A[3 * i + 1] * f1 + A[3 * i + 2] * f2)
                r = _GZ + (8 * i + d) * L + l
                z = buf[r]
                dz = abs(zn - z)
                az = abs(zn)
                delta = max(delta, dz)
                zmax = max(zmax, az)
                nan += dz * 0.0 + az * 0.0
                buf[r] = zn if active else z
        delta += nan  # NaN if an increment is not finite (as numpy's max, which propagates NaN)
        zmax += nan
        # the scale is fixed at the first iteration (no branch here: it would stop the vectorization)
        scale_new = buf[_GYMAX + l] + zmax
        scale_old = buf[_GSCALE + l]
        scale = scale_new if k == 1 else scale_old
        buf[_GSCALE + l] = scale
        nonfinite += 0 if abs(scale) < math.inf else 1
        diverged += 0 if delta <= 1e3 * (scale + 1.0) else 1
        dprev = buf[_GDPREV + l]
        done = (delta <= _EPS * scale) | ((delta >= dprev) & (delta <= 64 * _EPS * scale))
        cnt = buf[_GCNT + l]
        buf[_GCNT + l] = k if (active & done) else cnt
        still = active & (not done)
        buf[_GACT + l] = 1.0 if still else 0.0
        buf[_GDPREV + l] = delta
        nactive += 1 if still else 0
    if nonfinite > 0:
        return nactive, STATUS_NONFINITE
    if diverged > 0:
        return nactive, STATUS_DIVERGED
    if nactive > 0:
        _nb_gauss_fields(buf, b)
    return nactive, STATUS_OK


def _nb_gauss_finish(buf, h, b):
    """y1 = y0 + h (b_1 F_1 + ... + b_s F_s); iteration counters."""
    L = _LG
    S = len(b)
    for l in range(L):
        for d in range(8):
            f0 = buf[_GF + d * L + l]
            f1 = buf[_GF + (8 + d) * L + l]
            f2 = buf[_GF + (16 + d) * L + l]
            if S == 1:
                s = b[0] * f0
            elif S == 2:
                s = b[0] * f0 + b[1] * f1
            else:
                s = b[0] * f0 + b[1] * f1 + b[2] * f2
            buf[_GY + d * L + l] = buf[_GY + d * L + l] + h * s
        cnt = buf[_GCNT + l]
        buf[_GTOT + l] += cnt
        buf[_GMAX + l] = max(buf[_GMAX + l], cnt)


def _nb_gauss_advance(buf, h, N, A, b, E, max_iter, status):
    """N steps of size h on all lanes; False (and status filled) on failure."""
    L = _LG
    for step in range(N):
        _nb_gauss_start(buf, step == 0, E, b)
        converged = False
        for k in range(1, max_iter + 1):
            nactive, fail = _nb_gauss_iterate(buf, h, k, A, b)
            if fail != STATUS_OK:
                status[0] = fail
                status[1] = h
                return False
            if nactive == 0:
                converged = True
                break
        if not converged:
            bad = 0.0
            for l in range(L):
                if buf[_GACT + l] != 0.0:
                    bad = max(bad, buf[_GDPREV + l] / buf[_GSCALE + l])
            status[0] = STATUS_MAX_ITER
            status[1] = h
            status[2] = bad
            return False
        _nb_gauss_finish(buf, h, b)
    return True


def nb_gauss(y0, inv_m, A, b, E, max_iter, seg_h, seg_n, seg_out, seg_restart, q_out, w_out, iters, status):
    B = y0.shape[1]
    L = _LG
    nseg = seg_h.shape[0]
    buf = np.zeros(_GROWS * L)
    for b0 in range(0, B, L):
        nl = min(L, B - b0)
        for l in range(L):
            bb = b0 + l if l < nl else b0
            for c in range(3):
                buf[_GI + c * L + l] = inv_m[c, bb]
            buf[_GTOT + l] = 0.0
            buf[_GMAX + l] = 0.0
        for kseg in range(nseg):
            if seg_restart[kseg] != 0:
                for l in range(L):
                    bb = b0 + l if l < nl else b0
                    for c in range(8):
                        buf[_GY + c * L + l] = y0[c, bb]
            h = seg_h[kseg]
            N = seg_n[kseg]
            if N > 0:
                if not _nb_gauss_advance(buf, h, N, A, b, E, max_iter, status):
                    status[3] = b0
                    return
            j = seg_out[kseg]
            for l in range(nl):
                w = buf[_GY + l]
                x = buf[_GY + L + l]
                y = buf[_GY + 2 * L + l]
                z = buf[_GY + 3 * L + l]
                p0 = buf[_GY + 4 * L + l]
                p1 = buf[_GY + 5 * L + l]
                p2 = buf[_GY + 6 * L + l]
                p3 = buf[_GY + 7 * L + l]
                nq = math.sqrt(w * w + x * x + y * y + z * z)
                q_out[b0 + l, j, 0] = w / nq
                q_out[b0 + l, j, 1] = x / nq
                q_out[b0 + l, j, 2] = y / nq
                q_out[b0 + l, j, 3] = z / nq
                s = 0.5 / (w * w + x * x + y * y + z * z)
                w_out[b0 + l, j, 0] = buf[_GI + l] * (s * (w * p1 - x * p0 - y * p3 + z * p2))
                w_out[b0 + l, j, 1] = buf[_GI + L + l] * (s * (w * p2 + x * p3 - y * p0 - z * p1))
                w_out[b0 + l, j, 2] = buf[_GI + 2 * L + l] * (s * (w * p3 - x * p2 + y * p1 - z * p0))
        for l in range(nl):
            iters[b0 + l, 0] = int(buf[_GTOT + l])
            iters[b0 + l, 1] = int(buf[_GMAX + l])


if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    _inline = _njit(inline="always", cache=True, nogil=True)
    _plain = _njit(cache=True, nogil=True)
    _nb_sincos = _plain(_nb_sincos)
    _nb_rotate = _inline(_nb_rotate)
    _nb_rotate_axis = _plain(_nb_rotate_axis)
    _nb_field = _inline(_nb_field)
    _nb_gauss_fields = _plain(_nb_gauss_fields)
    _nb_gauss_start = _plain(_nb_gauss_start)
    _nb_gauss_iterate = _plain(_nb_gauss_iterate)
    _nb_gauss_finish = _plain(_nb_gauss_finish)
    _nb_gauss_advance = _plain(_nb_gauss_advance)
    _nb_sincos_array = _njit(cache=True, nogil=True)(_nb_sincos_array)
    nb_splitting = _njit(cache=True, nogil=True)(nb_splitting)
    nb_gauss = _njit(cache=True, nogil=True)(nb_gauss)


# ---------------------------------------------------------------------------
# entry points
# ---------------------------------------------------------------------------


def sincos_compiled(x):
    """:math:`(\\sin x, \\cos x)` by the compiled kernel (float64, 1-D); for tests."""
    x = kernel_array(np.ravel(x))
    s = np.empty_like(x)
    c = np.empty_like(x)
    _nb_sincos_array(x, s, c)
    return s, c


def run_splitting(q0, M0, inv_m, sequence, t, dt):
    r"""Lie-Poisson splitting of a batch of bodies at the output times.

    Parameters
    ----------
    q0 : ndarray, shape (4, B)
        Initial attitudes in the principal frame.
    M0 : ndarray, shape (3, B)
        Initial body angular momenta in the principal frame.
    inv_m : ndarray, shape (3, B)
        Inverse principal moments.
    sequence : list of (axis, fraction)
        From :func:`~eulerpoisson.solvers.symplectic.method.splitting_sequence`.
    t : ndarray, shape (T,)
    dt : float

    Returns
    -------
    q : ndarray, shape (B, T, 4)
    omega : ndarray, shape (B, T, 3)
        Body angular velocity in the principal frame.
    nsteps : int
    """
    h, n, out, restart, total = schedule(t, dt)
    B, T = q0.shape[1], t.shape[0]
    axes = np.array([a for a, _ in sequence], dtype=np.int64)
    fracs = np.array([f for _, f in sequence], dtype=np.float64)
    q_out = np.empty((B, T, 4))
    w_out = np.empty((B, T, 3))
    nb_splitting(
        kernel_array(q0),
        kernel_array(M0),
        kernel_array(inv_m),
        axes,
        fracs,
        h,
        n,
        out,
        restart,
        q_out,
        w_out,
    )
    return q_out, w_out, total


def run_gauss_quaternion(y0, inv_m, tableau, t, dt, max_iter):
    r"""Gauss collocation in :math:`(q, p)` of a batch of bodies at the output times.

    Parameters
    ----------
    y0 : ndarray, shape (8, B)
        Initial :math:`(q, p)`, principal frame.
    inv_m : ndarray, shape (3, B)
    tableau : GaussTableau
    t : ndarray, shape (T,)
    dt : float
    max_iter : int

    Returns
    -------
    q : ndarray, shape (B, T, 4)
        :math:`q/|q|`.
    omega : ndarray, shape (B, T, 3)
    iters : ndarray of int64, shape (B, 2)
        Per body: fixed-point iterations in total and the most in one step.
    nsteps : int
    status : ndarray, shape (4,)
        ``(code, h, value, chunk start)``; code :data:`STATUS_OK` or the failure
        (:data:`STATUS_NONFINITE`, :data:`STATUS_DIVERGED`, :data:`STATUS_MAX_ITER`,
        ``value`` the relative increment).
    """
    h, n, out, restart, total = schedule(t, dt)
    B, T = y0.shape[1], t.shape[0]
    A = tuple(float(x) for x in tableau.A.ravel())
    b = tuple(float(x) for x in tableau.b)
    E = tuple(float(x) for x in tableau.extrapolation.ravel())
    q_out = np.empty((B, T, 4))
    w_out = np.empty((B, T, 3))
    iters = np.zeros((B, 2), dtype=np.int64)
    status = np.zeros(4)
    nb_gauss(
        kernel_array(y0),
        kernel_array(inv_m),
        A,
        b,
        E,
        int(max_iter),
        h,
        n,
        out,
        restart,
        q_out,
        w_out,
        iters,
        status,
    )
    return q_out, w_out, iters, total, status
