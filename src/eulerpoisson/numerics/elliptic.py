r"""Accurate, vectorized elliptic functions and integrals in float64.

This private module provides the special functions needed by the closed-form
solution of the free rigid body (:mod:`eulerpoisson.solvers.exact.motion`):

* Jacobi elliptic functions :func:`jacobi_sncndn` and the amplitude
  :func:`jacobi_am` of ``(u, m)``, accurate to a few ulp (relative) for every
  parameter ``0 <= m <= 1``, *including* ``m`` extremely close to 1.  The
  complementary parameter ``m1 = 1 - m`` is an input in its own right, so that
  ``1 - m = 1e-15`` (or ``1e-300``) is represented exactly;
* the complete integral of the first kind :func:`ellipk` (and
  :func:`ellipkp`, ``K'(m) = K(1 - m)``), internally also in double-double
  precision (used for the argument reduction);
* Carlson's symmetric integrals :func:`elliprf`, :func:`elliprd`,
  :func:`elliprj`, :func:`elliprc` by the duplication algorithm;
* the incomplete integrals :func:`ellipf` (first kind) and :func:`ellippi`
  (third kind) for any real amplitude, plus :func:`ellippi_complete`.

Notation follows DLMF chapter 19/22: parameter ``m = k**2``, complementary
parameter ``m1 = 1 - m = k'**2``.

Algorithms
----------
*Argument reduction.*  ``u`` is reduced to ``u = n K + r`` with
``|r| <= K/2`` (``n`` an integer, the quarter-period index).  ``K`` is
computed in double-double arithmetic by the arithmetic-geometric mean, and the
product ``n K`` is formed exactly (Dekker's two-product), so ``r`` carries an
error of about one ulp *of r*, independently of how large ``u`` is.

*Fundamental domain.*  On ``0 <= v <= K/2`` the functions come from the
descending Landen transformation (DLMF 22.7.1-22.7.3) applied "outwards"
from a bottom parameter ``p_N < 2**-56`` where ``sn = sin``:

.. math::

    \operatorname{sn}(u|p) = \frac{(1+\mu^{1/2})\,\operatorname{sn}(v|\mu)}
                                   {1+\mu^{1/2}\operatorname{sn}^2(v|\mu)},\qquad
    \operatorname{cn}(u|p) = \frac{\operatorname{cn}(v|\mu)\operatorname{dn}(v|\mu)}
                                   {1+\mu^{1/2}\operatorname{sn}^2(v|\mu)},

``sqrt(mu) = p/(1 + sqrt(1-p))**2``, ``1 - mu = 4 sqrt(1-p)/(1 + sqrt(1-p))**2``
(no cancellation), ``v = u/(1 + sqrt(mu))``.

* ``m <= 1/2``: the chain runs on ``p = m`` along the real axis; ``1 - cn``
  is carried next to ``cn`` while ``cn > 1/2`` (the rounding of ``cn ~ 1``
  would otherwise be amplified into a phase error), ``dn^2 = 1 - m sn^2``.
* ``m > 1/2``: Jacobi's imaginary transformation (DLMF 22.6.12),
  ``cn(u|m) = 1/cn(iu|m1)``, ``sn(u|m) = -i sn(iu|m1)/cn(iu|m1)``; the chain
  runs on ``p = m1 <= 1/2`` along the imaginary axis, starting from
  ``sinh``/``cosh``, every quantity positive.  The chain is short and its
  scale factor ~1, so ``cn, dn ~ sech`` keep full *relative* accuracy down
  to ``m1 = 1e-300``; ``dn^2 = cn^2 + m1 sn^2``.

The argument is scaled by the product ``prod (1 + sqrt(mu_i))`` of the
rounded chain (double-double), not by ``pi/(2K)``, and the low part of the
reduced argument enters by a first-order correction, so the phase is exact
to ~1 ulp.  The other quarter periods follow from ``sn(K + r) = cd r``,
``cn(K + r) = -k' sd r``, ``dn(K + r) = k' nd r`` (DLMF 22.4.3).
``m1 = 0`` uses ``tanh``/``sech`` (DLMF 22.5.4).

*Carlson integrals* use the duplication theorem with the truncation criteria
and the Taylor series of Carlson (1995) / DLMF 19.36.  In ``R_J`` the
argument ``1 + e_m`` of the ``R_C`` terms is formed as
``2 sqrt(p_m) (p_m + lambda_m) / d_m`` (an exact identity), which removes the
cancellation for ``p << x, y, z``; a term with ``|e_m| <= 2**-5`` (every step
but the first one or two: ``e_m`` falls by about 64 per step) is the
Maclaurin series of ``atan(t)/t`` in ``e = t**2`` (:func:`rc1_series`, eleven
terms, remainder below ``2**-59``) instead of ``atan`` or ``log1p``.
Converged elements leave the working set, so a result does not depend on the
batch it is computed in (bitwise).

The kernels are plain array operations in loops with a bounded number of
iterations (no Python objects in inner loops) so that a compiler could take
them over later.

References
----------
.. [1] B. C. Carlson, "Numerical computation of real or complex elliptic
   integrals", Numer. Algorithms 10 (1995) 13-26.
.. [2] NIST Digital Library of Mathematical Functions, chapters 19 and 22,
   https://dlmf.nist.gov/ (19.25, 19.36, 22.4, 22.5, 22.7).
.. [3] M. Abramowitz, I. A. Stegun, Handbook of Mathematical Functions,
   16.12 (descending Landen transformation), 17.6 (AGM).
.. [4] T. J. Dekker, "A floating-point technique for extending the available
   precision", Numer. Math. 18 (1971) 224-242 (double-double arithmetic).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InvalidInputError
from ..util.jit import jitable
from .doubledouble import dd_add as _dd_add
from .doubledouble import dd_div as _dd_div
from .doubledouble import dd_mul as _dd_mul
from .doubledouble import dd_sqrt as _dd_sqrt
from .doubledouble import quick_two_sum as _quick_two_sum
from .doubledouble import two_prod as _two_prod
from .doubledouble import two_sum as _two_sum

__all__ = [
    "jacobi_sncndn",
    "jacobi_am",
    "ellipk",
    "ellipkp",
    "elliprf",
    "elliprd",
    "elliprj",
    "elliprc",
    "ellipf",
    "ellippi",
    "ellippi_complete",
]

_EPS = np.finfo(np.float64).eps
# pi and pi/2 as double-double numbers
_PI_HI = 3.141592653589793
_PI_LO = 1.2246467991473532e-16
_PIO2_HI = 1.5707963267948966
_PIO2_LO = 6.123233995736766e-17
# Landen descent stops when m_N < 2**-56 (then sn(v|m_N) = sin v to < 1e-18)
_LANDEN_THRESHOLD = 2.0**-56
_MAX_LANDEN = 40
_MAX_AGM = 60
_MAX_DUPLICATION = 200
# Carlson's truncation tolerance r (Carlson 1995); with the degree-7 series of
# DLMF 19.36.1 the truncation error is far below one ulp.
_R_TOL = 2.0**-53
_RF_QFAC = (3.0 * _R_TOL) ** (-1.0 / 6.0)
_RDJ_QFAC = (0.25 * _R_TOL) ** (-1.0 / 6.0)
_RC_QFAC = (3.0 * _R_TOL) ** (-1.0 / 8.0)
#: the R_C terms of R_J use the series of atan(t)/t in e = t^2 for |e| <= 2**-5
RC_SERIES_MAX = 2.0**-5
#: the Landen ascent on the real axis starts from sin, cos of its argument by the polynomials
#: :func:`sin_poly`, :func:`cos_poly` up to this argument (the reduced argument is at most about pi/4)
SINCOS_POLY_MAX = 0.8
#: Maclaurin coefficients (-1)^k/(2k+1)! of sin for k = 1..8 and (-1)^k/(2k)! of cos for k = 2..9
#: (:func:`sin_poly`, :func:`cos_poly`), each the double nearest to the rational
_SIN_C = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(1, 9))
_COS_C = tuple((-1) ** k / math.factorial(2 * k) for k in range(2, 10))


# ---------------------------------------------------------------------------
# double-double primitives (Dekker 1971); all vectorized, error-free where noted
# ---------------------------------------------------------------------------
# ---------------------------------------------------------------------------
# input handling
# ---------------------------------------------------------------------------
def _as_float_array(x, name):
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be a real array_like, got {x!r}") from exc
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(f"{name} must be finite; got non-finite values (shape {arr.shape})")
    return arr


def _parameters(m, m1):
    """Validate ``m``/``m1`` and return both as float64 arrays.

    Exactly one of them may be ``None``; if both are given they must agree,
    ``|m + m1 - 1| <= 4 eps``.
    """
    if m is None and m1 is None:
        raise InvalidInputError("give the parameter m or its complement m1 (m1 = 1 - m)")
    if m is not None:
        m = _as_float_array(m, "m")
        if np.any((m < 0.0) | (m > 1.0)):
            bad = m[(m < 0.0) | (m > 1.0)].ravel()[0].item()
            raise InvalidInputError(f"parameter m must lie in [0, 1], got m={bad!r}")
    if m1 is not None:
        m1 = _as_float_array(m1, "m1")
        if np.any((m1 < 0.0) | (m1 > 1.0)):
            bad = m1[(m1 < 0.0) | (m1 > 1.0)].ravel()[0].item()
            raise InvalidInputError(f"complementary parameter m1 = 1 - m must lie in [0, 1], got m1={bad!r}")
    if m is None:
        m = 1.0 - m1
    elif m1 is None:
        m1 = 1.0 - m
    else:
        m, m1 = np.broadcast_arrays(m, m1)
        if np.any(np.abs((m - 1.0) + m1) > 4.0 * _EPS):
            raise InvalidInputError("m and m1 were both given but m + m1 != 1 (beyond 4 eps); pass only one of them")
    m, m1 = np.broadcast_arrays(m, m1)
    return np.array(m, dtype=np.float64), np.array(m1, dtype=np.float64)


def _out(x):
    """Return numpy scalars for 0-d results."""
    return x[()] if isinstance(x, np.ndarray) and x.ndim == 0 else x


# ---------------------------------------------------------------------------
# complete integral K by the AGM in double-double
# ---------------------------------------------------------------------------
def _ellipk_dd(m1):
    """``K(m)`` as a double-double ``(K_hi, K_lo)`` from ``m1 = 1 - m``.

    Also returns ``agm = pi / (2 K)`` (double).  ``m1 == 0`` gives
    ``K_hi = inf``, ``K_lo = 0``, ``agm = 0``.
    """
    m1 = np.asarray(m1, dtype=np.float64)
    sep = m1 == 0.0
    m1s = np.where(sep, 1.0, m1)
    ah = np.ones_like(m1s)
    al = np.zeros_like(m1s)
    # sqrt(m1) in double-double; scaled by 2**200 so that the low parts of
    # tiny m1 (down to the subnormal range) do not underflow
    bh, bl = _dd_sqrt(m1s * 2.0**200, np.zeros_like(m1s))
    bh, bl = bh * 2.0**-100, bl * 2.0**-100
    for _ in range(_MAX_AGM):
        dh, _dl = _dd_add(ah, al, -bh, -bl)
        act = np.abs(dh) > 2.0**-104 * ah
        if not np.any(act):
            break
        sh, sl = _dd_add(ah, al, bh, bl)
        ph, pl = _dd_mul(ah, al, bh, bl)
        nbh, nbl = _dd_sqrt(ph, pl)
        bh, bl = np.where(act, nbh, bh), np.where(act, nbl, bl)
        ah, al = np.where(act, 0.5 * sh, ah), np.where(act, 0.5 * sl, al)
    kh, kl = _dd_div(np.full_like(ah, _PI_HI), np.full_like(ah, _PI_LO), ah, al)
    kh, kl = 0.5 * kh, 0.5 * kl
    kh = np.where(sep, np.inf, kh)
    kl = np.where(sep, 0.0, kl)
    agm = np.where(sep, 0.0, ah)
    return kh, kl, agm


# ---------------------------------------------------------------------------
# Jacobi elliptic functions
# ---------------------------------------------------------------------------
class JacobiParams:
    """Precomputed, parameter-only data for the Jacobi kernels (plain arrays).

    Attributes (all broadcastable to the parameter shape)
    ----------
    m, m1 : parameter and complement
    kp : ``sqrt(m1)``
    sep : ``m1 == 0`` (``sn = tanh``, ``cn = dn = sech``; no reduction)
    imag : ``m > 1/2``: the Landen chain runs on the complementary parameter
        (Jacobi imaginary transformation), else on ``m``
    kh, kl : ``K`` as double-double, with ``pi/2`` substituted where ``sep``
    sqm, pcl : Landen levels ``sqrt(p_i)`` and ``1 - p_i``, arrays of shape
        ``(L,) + shape`` (``p_0 = m`` or ``m1``)
    ph, pcorr : ``prod(1 + sqrt(p_i))`` of the rounded chain as double-double
        ``ph * (1 + pcorr)``
    """

    __slots__ = ("m", "m1", "kp", "sep", "imag", "kh", "kl", "sqm", "pcl", "ph", "pcorr")
    m: np.ndarray
    m1: np.ndarray
    kp: np.ndarray
    sep: np.ndarray
    imag: np.ndarray
    kh: np.ndarray
    kl: np.ndarray
    sqm: np.ndarray
    pcl: np.ndarray
    ph: np.ndarray
    pcorr: np.ndarray

    def take(self, index):
        """Gather along the (flattened, 1-d) parameter axis."""
        new = JacobiParams()
        for name in ("m", "m1", "kp", "sep", "imag", "kh", "kl", "ph", "pcorr"):
            setattr(new, name, getattr(self, name)[index])
        new.sqm = self.sqm[:, index]
        new.pcl = self.pcl[:, index]
        return new


def jacobi_params(m, m1):
    m = np.asarray(m, dtype=np.float64)
    m1 = np.asarray(m1, dtype=np.float64)
    P = JacobiParams()
    P.m, P.m1 = m, m1
    P.kp = np.sqrt(m1)
    P.sep = m1 == 0.0
    P.imag = m > 0.5
    kh, kl, _ = _ellipk_dd(m1)
    P.kh = np.where(P.sep, _PIO2_HI, kh)
    P.kl = np.where(P.sep, _PIO2_LO, kl)
    # descending Landen chain on p = m (real path) or p = m1 (imaginary path):
    # sqrt(p_{i+1}) = p_i / (1 + sqrt(1-p_i))^2,  1 - p_{i+1} = 4 sqrt(1-p_i) / (1 + ...)^2
    pc = np.where(P.imag, m1, m)
    pc1 = np.where(P.imag, m, m1)
    # stop when the bottom parameter p_N makes sn = sin (sinh) exact: the
    # first-order term is ~ p_N/4 (real path, |v| <= pi/4) and
    # ~ p_N cosh^2(w)/4 <= p_N / (4 k') on the imaginary path (w <= K/2)
    thr = np.where(P.imag, 0.25 * _LANDEN_THRESHOLD * P.kp, _LANDEN_THRESHOLD)
    sq_levels, pc1_levels = [], []
    for _ in range(_MAX_LANDEN):
        active = pc > thr
        if not np.any(active):
            break
        kp = np.sqrt(pc1)
        den = (1.0 + kp) * (1.0 + kp)
        sq = np.where(active, pc / den, 0.0)
        pn1 = np.where(active, 4.0 * kp / den, 1.0)
        sq_levels.append(sq)
        pc1_levels.append(pn1)
        pc = sq * sq
        pc1 = pn1
    # prod (1 + sqrt(p_i)) of the *rounded* chain in double-double: scaling the
    # argument with the chain's own product keeps the phase exact
    ph = np.ones_like(m)
    pl = np.zeros_like(m)
    for sq in sq_levels:
        oh, ol = _two_sum(1.0, sq)
        ph, pl = _dd_mul(ph, pl, oh, ol)
    P.ph = ph
    P.pcorr = pl / ph
    if sq_levels:
        P.sqm = np.stack(sq_levels)
        P.pcl = np.stack(pc1_levels)
    else:
        P.sqm = np.zeros((0,) + m.shape)
        P.pcl = np.zeros((0,) + m.shape)
    return P


def _reduce_quarter(uh, ul, P):
    """Reduce ``u = uh + ul`` (double-double) to ``u = n K + r``, ``|r| <~ K/2``.

    Returns ``n`` (float64, integer valued) and ``r = rh + rl`` as a
    double-double.  Where ``P.sep`` (``K`` infinite) ``n = 0`` and
    ``r = uh + ul``.  ``n K`` is formed exactly (``uh - n K_hi`` is exact by
    Sterbenz' lemma), so ``r`` is accurate to ~``2**-100 |u|``.
    """
    n = np.rint(uh / P.kh)
    n = np.where(P.sep, 0.0, n)
    ph, pl = _two_prod(n, P.kh)
    t = uh - ph
    rh, rl = _two_sum(t, -pl)
    rl = rl + (ul - n * P.kl)
    rh, rl = _quick_two_sum(rh, rl)
    return n, rh, rl


def _sech(x):
    e = np.exp(-np.abs(x))
    return 2.0 * e / (1.0 + e * e)


def _sncndn_real(vn, dv, P):
    """Landen ascent on the real axis (used for ``m <= 1/2``).

    ``vn`` is the argument scaled to the bottom of the chain.  Returns sn, cn
    at the top.  ``y = 1 - cn`` is carried alongside ``cn``: while cn ~ 1 the
    value of cn holds too little information on the phase (its rounding
    error would be amplified by the ascent), ``y`` keeps it to full relative
    precision.
    """
    # sin, cos by polynomials (vn is at most about pi/4: the argument reduced modulo K, scaled to
    # the bottom of the chain), the C library beyond SINCOS_POLY_MAX
    if np.all(vn <= SINCOS_POLY_MAX):
        s0 = sin_poly(vn)
        c0 = cos_poly(vn)
        h = sin_poly(0.5 * vn)
    else:
        small = vn <= SINCOS_POLY_MAX
        s0 = np.where(small, sin_poly(vn), np.sin(vn))
        c0 = np.where(small, cos_poly(vn), np.cos(vn))
        h = np.where(small, sin_poly(0.5 * vn), np.sin(0.5 * vn))
    # first-order correction for the low part dv of the argument
    s = s0 + c0 * dv
    c = c0 - s0 * dv
    y = 2.0 * h * h + s0 * dv
    for i in range(P.sqm.shape[0] - 1, -1, -1):
        sq = P.sqm[i]
        s2 = s * s
        ce = np.where(y < 0.5, 1.0 - y, c)
        d = np.sqrt(ce * ce + P.pcl[i] * s2)
        den = 1.0 + sq * s2
        use = sq > 0.0
        s_new = (1.0 + sq) * s / den
        c_new = ce * d / den
        # 1 - c d / den = (y + c (1 - d) + sq s^2) / den,  1 - d = sq^2 s^2 / (1 + d)
        y_new = (y + ce * (sq * sq * s2) / (1.0 + d) + sq * s2) / den
        s = np.where(use, s_new, s)
        c = np.where(use, c_new, c)
        y = np.where(use, y_new, y)
    c = np.where(y < 0.5, 1.0 - y, c)
    return s, c


def _sncndn_imag(vn, dv, P):
    """Landen ascent on the imaginary axis for the complementary parameter.

    Jacobi's imaginary transformation (DLMF 22.6.12)
    ``cn(u|m) = 1 / cn(iu|m1)``, ``sn(u|m) = -i sn(iu|m1) / cn(iu|m1)``,
    ``dn(u|m) = dn(iu|m1) / cn(iu|m1)``; with ``sn(iw|mu) = i sigma`` the
    descending Landen ascent reads
    ``sigma' = (1 + sqrt(mu)) sigma / (1 - sqrt(mu) sigma^2)``,
    ``C' = C D / (1 - sqrt(mu) sigma^2)``, ``D = sqrt(1 + mu sigma^2)``,
    starting from ``sinh``, ``cosh``.  All quantities are positive, the chain
    on ``m1 <= 1/2`` is short and the scale factor is ~1, so no phase
    information is lost (used for ``m > 1/2``).  Returns ``sn(u|m)`` and
    ``cn(u|m)``.
    """
    sh = np.sinh(vn)
    ch = np.cosh(vn)
    sig = sh + ch * dv
    C = ch + sh * dv
    for i in range(P.sqm.shape[0] - 1, -1, -1):
        sq = P.sqm[i]
        s2 = sig * sig
        D = np.sqrt(1.0 + (sq * sq) * s2)
        den = 1.0 - sq * s2
        use = sq > 0.0
        sig_new = (1.0 + sq) * sig / den
        C_new = C * D / den
        sig = np.where(use, sig_new, sig)
        C = np.where(use, C_new, C)
    return sig / C, 1.0 / C


def _sncndn_core(r, rl, P):
    """sn, cn, dn of a reduced argument ``r + rl``, ``|r| <= ~K/2`` (sn signed)."""
    neg = r < 0.0
    v = np.abs(r)
    vl = np.where(neg, -rl, rl)
    vq = v / P.ph
    vn = vq - vq * P.pcorr
    dv = vl / P.ph
    with np.errstate(all="ignore"):
        if np.all(P.imag):
            s, c = _sncndn_imag(vn, dv, P)
        elif not np.any(P.imag):
            s, c = _sncndn_real(vn, dv, P)
        else:
            si, ci = _sncndn_imag(vn, dv, P)
            sr, cr = _sncndn_real(vn, dv, P)
            s = np.where(P.imag, si, sr)
            c = np.where(P.imag, ci, cr)
        s2 = s * s
        d = np.where(P.m <= 0.5, np.sqrt(1.0 - P.m * s2), np.sqrt(c * c + P.m1 * s2))
        # separatrix m = 1: tanh / sech of the unreduced argument
        if np.any(P.sep):
            s = np.where(P.sep, np.tanh(v), s)
            sech = _sech(v)
            c = np.where(P.sep, sech, c)
            d = np.where(P.sep, sech, d)
    s = np.where(neg, -s, s)
    return s, c, d


def _quadrant(n, s, c, d, kp):
    """Map reduced values at ``r`` to ``(sn, cn, dn)`` at ``n K + r``."""
    q = np.mod(n, 4.0)
    odd = (q == 1.0) | (q == 3.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        cd = c / d
        sd = kp * s / d
        nd = kp / d
    sn = np.where(odd, cd, s)
    cn = np.where(odd, -sd, c)
    dn = np.where(odd, nd, d)
    flip = q >= 2.0
    sn = np.where(flip, -sn, sn)
    cn = np.where(flip, -cn, cn)
    return sn, cn, dn


def sncndn_dd(uh, ul, P):
    """Internal entry point: ``u`` double-double, params precomputed.

    Returns ``(sn, cn, dn, n, r, s, c, d)``: the function values at ``u``, the
    quarter-period index ``n``, the reduced argument ``r`` and the values at
    ``r``.
    """
    n, r, rl = _reduce_quarter(uh, ul, P)
    s, c, d = _sncndn_core(r, rl, P)
    sn, cn, dn = _quadrant(n, s, c, d, P.kp)
    return sn, cn, dn, n, r, s, c, d


def jacobi_sncndn(u, m=None, m1=None):
    r"""Jacobi elliptic functions ``sn(u|m)``, ``cn(u|m)``, ``dn(u|m)``.

    Accurate to a few ulp (relative) for every ``0 <= m <= 1``, in particular
    for ``m`` close to 1 (where ``scipy.special.ellipj`` loses accuracy, scipy
    issue 8480): give the complementary parameter ``m1 = 1 - m`` directly.

    Parameters
    ----------
    u : array_like
        Real argument, any finite value (reduced modulo the quarter period
        ``K`` in double-double precision, so large ``|u|`` loses no digits
        beyond the representation of ``u`` itself).
    m : array_like, optional
        Parameter ``m = k**2`` in ``[0, 1]``.
    m1 : array_like, optional
        Complementary parameter ``1 - m`` in ``[0, 1]``.  Give ``m1`` (rather
        than ``m``) when ``m`` is close to 1.  If both are given they must
        satisfy ``|m + m1 - 1| <= 4 eps``.

    Returns
    -------
    sn, cn, dn : ndarray
        Broadcast shape of ``u``, ``m``/``m1``.

    Raises
    ------
    InvalidInputError
        If ``m``/``m1`` lie outside ``[0, 1]``, neither is given, they are
        inconsistent, or any input is not finite.

    Notes
    -----
    ``m = 1`` (``m1 = 0``) gives ``tanh u``, ``sech u``, ``sech u``
    (DLMF 22.5.4); ``m = 0`` gives ``sin``, ``cos``, 1.  See the module
    docstring for the algorithm (double-double reduction modulo ``K`` and
    the descending Landen transformation, DLMF 22.7).

    Examples
    --------
    >>> sn, cn, dn = jacobi_sncndn(1.0, m1=1e-15)
    """
    u = _as_float_array(u, "u")
    m, m1 = _parameters(m, m1)
    P = jacobi_params(m, m1)
    sn, cn, dn, *_ = sncndn_dd(u, np.zeros_like(u), P)
    shape = np.broadcast_shapes(u.shape, m.shape)
    return tuple(_out(np.broadcast_to(x, shape).copy()) for x in (sn, cn, dn))


def _am_from_reduced(n, r, s, c, P):
    """Amplitude ``am(nK + r)`` from the reduced values."""
    odd = np.mod(n, 2.0) == 1.0
    delta = np.where(odd, np.arctan2(P.kp * s, c), np.arctan2(s, c))
    return n * _PIO2_HI + (delta + n * _PIO2_LO)


def jacobi_am(u, m=None, m1=None):
    r"""Jacobi amplitude ``am(u|m)``, continuous and increasing in ``u``.

    ``sn = sin(am)``, ``cn = cos(am)``, ``am(u + 2K) = am(u) + pi``.

    Parameters
    ----------
    u : array_like
        Real argument.
    m, m1 : array_like, optional
        Parameter and/or its complement, as in :func:`jacobi_sncndn`.

    Returns
    -------
    ndarray
        ``am(u|m)``; for ``m = 1`` the Gudermannian ``gd(u)``.

    Raises
    ------
    InvalidInputError
        As :func:`jacobi_sncndn`.
    """
    u = _as_float_array(u, "u")
    m, m1 = _parameters(m, m1)
    P = jacobi_params(m, m1)
    _, _, _, n, r, s, c, _ = sncndn_dd(u, np.zeros_like(u), P)
    am = _am_from_reduced(n, r, s, c, P)
    shape = np.broadcast_shapes(u.shape, m.shape)
    return _out(np.broadcast_to(am, shape).copy())


def ellipk(m=None, m1=None):
    r"""Complete elliptic integral of the first kind ``K(m)``.

    .. math:: K(m) = \int_0^{\pi/2} \frac{d\theta}{\sqrt{1 - m\sin^2\theta}}
                   = \frac{\pi}{2\,\mathrm{AGM}(1, \sqrt{1-m})}.

    Computed by the arithmetic-geometric mean in double-double arithmetic from
    the complementary parameter, so ``K`` is accurate (to < 1 ulp) also for
    ``m1 -> 0`` where ``K ~ ln(4/sqrt(m1))``.

    Parameters
    ----------
    m, m1 : array_like, optional
        Parameter in ``[0, 1]`` and/or its complement ``1 - m``.

    Returns
    -------
    ndarray
        ``K``; ``inf`` where ``m1 == 0``.

    Raises
    ------
    InvalidInputError
        As :func:`jacobi_sncndn`.
    """
    m, m1 = _parameters(m, m1)
    kh, _, _ = _ellipk_dd(m1)
    return _out(kh)


def ellipkp(m=None, m1=None):
    r"""Complementary complete integral ``K'(m) = K(1 - m)``.

    Parameters
    ----------
    m, m1 : array_like, optional
        Parameter in ``[0, 1]`` and/or its complement ``1 - m``.

    Returns
    -------
    ndarray
        ``K'``; ``inf`` where ``m == 0``.

    Raises
    ------
    InvalidInputError
        As :func:`jacobi_sncndn`.
    """
    m, m1 = _parameters(m, m1)
    kh, _, _ = _ellipk_dd(m)
    return _out(kh)


# ---------------------------------------------------------------------------
# Carlson symmetric integrals (duplication algorithm)
# ---------------------------------------------------------------------------
def _duplicate(q, state, step):
    """Run a duplication iteration to convergence, element by element.

    ``state`` is a list of flat arrays whose first two entries are ``A_n``
    and ``4**-n``; an element is converged when ``4**-n q < |A_n|``
    (Carlson 1995).  Converged elements are removed from the working set
    (so the cost follows the active elements and results do not depend on
    the batch they are computed in); returns the final states.
    """
    final = [v.copy() for v in state]
    idx = np.arange(q.size)
    cur = list(state)
    qc = q
    for _ in range(_MAX_DUPLICATION):
        act = cur[1] * qc >= np.abs(cur[0])
        if not np.all(act):
            done = ~act
            di = idx[done]
            for f, c in zip(final, cur):
                f[di] = c[done]
            idx = idx[act]
            if idx.size == 0:
                return final
            qc = qc[act]
            cur = [c[act] for c in cur]
        cur = step(cur)
    for f, c in zip(final, cur):
        f[idx] = c
    return final


def _flat(*args):
    arrs = np.broadcast_arrays(*(np.asarray(a, np.float64) for a in args))
    shape = arrs[0].shape
    return shape, [np.array(a, dtype=np.float64).ravel() for a in arrs]


def _rf_step(st):
    a, fac, x, y, z = st
    sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
    lam = sx * sy + sy * sz + sz * sx
    return [0.25 * (a + lam), 0.25 * fac, 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)]


def rf_core(x, y, z):
    """R_F for non-negative arrays with at most one zero (no checks)."""
    shape, (x, y, z) = _flat(x, y, z)
    a0 = (x + y + z) / 3.0
    q = _RF_QFAC * np.maximum(np.maximum(np.abs(a0 - x), np.abs(a0 - y)), np.abs(a0 - z))
    a, fac, *_ = _duplicate(q, [a0, np.ones_like(a0), x, y, z], _rf_step)
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
    return (poly / np.sqrt(a)).reshape(shape)


def _rd_step(st):
    a, fac, x, y, z, acc = st
    sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
    lam = sx * sy + sy * sz + sz * sx
    return [
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        acc + fac / (sz * (z + lam)),
    ]


def _rd(x, y, z):
    """R_D for x, y >= 0 (at most one zero), z > 0 (no checks)."""
    shape, (x, y, z) = _flat(x, y, z)
    a0 = (x + y + 3.0 * z) / 5.0
    q = _RDJ_QFAC * np.maximum(np.maximum(np.abs(a0 - x), np.abs(a0 - y)), np.abs(a0 - z))
    st = [a0, np.ones_like(a0), x, y, z, np.zeros_like(a0)]
    a, fac, _, _, _, acc = _duplicate(q, st, _rd_step)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = -(X + Y) / 3.0
    xy = X * Y
    z2 = Z * Z
    e2 = xy - 6.0 * z2
    e3 = (3.0 * xy - 8.0 * z2) * Z
    e4 = 3.0 * (xy - z2) * z2
    e5 = xy * z2 * Z
    poly = (
        1.0
        - 3.0 * e2 / 14.0
        + e3 / 6.0
        + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
    )
    return (fac * poly / (a * np.sqrt(a)) + 3.0 * acc).reshape(shape)


@jitable
def sin_poly(x):
    r"""``sin(x)`` for ``|x| <= 0.8`` (:data:`SINCOS_POLY_MAX`) in plain arithmetic.

    .. math::
        \sin x = x + x z \sum_{k=1}^{8} \frac{(-1)^k z^{k-1}}{(2k+1)!}, \qquad z = x^2,

    the Maclaurin series to :math:`x^{17}` (the first term left out, :math:`x^{19}/19!`, is below
    :math:`2^{-62}` relative at :math:`x = 0.8`), the sum by Horner's rule in :math:`z` and the leading
    :math:`x` added last. Measured against 40-digit references: at most 0.71 ulp on ``[0, 0.8]``
    (``tests/test_elliptic.py``). Plain arithmetic, so the NumPy path and the compiled kernels (which
    inline it and run it in vector lanes, where the C library's ``sin`` is a call per element) agree
    bit for bit.
    """
    z = x * x
    p = _SIN_C[7]
    p = _SIN_C[6] + z * p
    p = _SIN_C[5] + z * p
    p = _SIN_C[4] + z * p
    p = _SIN_C[3] + z * p
    p = _SIN_C[2] + z * p
    p = _SIN_C[1] + z * p
    p = _SIN_C[0] + z * p
    return x + x * z * p


@jitable
def cos_poly(x):
    r"""``cos(x)`` for ``|x| <= 0.8`` (:data:`SINCOS_POLY_MAX`) in plain arithmetic.

    .. math::
        \cos x = \Big(1 - \frac z2\Big) + z^2 \sum_{k=2}^{9} \frac{(-1)^k z^{k-2}}{(2k)!}, \qquad z = x^2,

    the Maclaurin series to :math:`x^{18}`; ``w = 1 - z/2`` is rounded and its rounding error
    ``(1 - w) - z/2`` (exact: ``z/2 <= 0.32``) is added back with the tail, so the result is the
    rounded ``w`` plus a small correction. At most 0.71 ulp on ``[0, 0.8]`` (measured against 40-digit
    references); see :func:`sin_poly`.
    """
    z = x * x
    p = _COS_C[7]
    p = _COS_C[6] + z * p
    p = _COS_C[5] + z * p
    p = _COS_C[4] + z * p
    p = _COS_C[3] + z * p
    p = _COS_C[2] + z * p
    p = _COS_C[1] + z * p
    p = _COS_C[0] + z * p
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + z * z * p)


@jitable
def rc1_series(e):
    r"""``R_C(1, 1 + e)`` for ``|e| <= 2**-5`` by its Maclaurin series (DLMF 19.2.18-19).

    ``R_C(1, 1 + e) = atan(sqrt e)/sqrt e = atanh(sqrt(-e))/sqrt(-e) =
    sum_k (-e)^k/(2k + 1)``; eleven terms (Horner, degree 10): the remainder
    is below ``|e|^11/23 < 2**-59`` relative.  Plain arithmetic, so the NumPy
    path and the compiled kernels (which inline it) agree bit for bit; in the
    duplication of ``R_J`` all steps but the first one or two take this branch
    (``e`` falls by about 64 per step), which saves an ``atan`` (or ``log1p``),
    a square root and a division each.
    """
    return 1.0 + e * (
        -1.0 / 3.0
        + e
        * (
            1.0 / 5.0
            + e
            * (
                -1.0 / 7.0
                + e
                * (
                    1.0 / 9.0
                    + e
                    * (
                        -1.0 / 11.0
                        + e * (1.0 / 13.0 + e * (-1.0 / 15.0 + e * (1.0 / 17.0 + e * (-1.0 / 19.0 + e * (1.0 / 21.0)))))
                    )
                )
            )
        )
    )


def _rc1(e, y):
    """``R_C(1, y)`` with ``y = 1 + e``, both given accurately, ``y > 0``.

    ``|e| <= 2**-5``: the series :func:`rc1_series`.  Otherwise the closed
    forms (DLMF 19.2.18-19): ``atan(t)/t`` with ``t = sqrt(e)`` for
    ``e > 0``; ``atanh(t)/t = log1p(2 t (1 + t) / y) / (2 t)`` with
    ``t = sqrt(-e)`` for ``e < 0`` (``1 - t = y / (1 + t)``: no cancellation
    as ``y -> 0``).
    """
    small = np.abs(e) <= RC_SERIES_MAX
    ser = rc1_series(e)
    if np.all(small):
        return ser
    t = np.sqrt(np.abs(e))
    ts = np.where(t > 0.0, t, 1.0)
    pos = e > 0.0
    if np.all(pos | small):
        return np.where(small, ser, np.arctan(t) / ts)
    neg = 0.5 * np.log1p(2.0 * t * (1.0 + t) / y) / ts
    if not np.any(pos & ~small):
        return np.where(small, ser, np.where(e < 0.0, neg, 1.0))
    return np.where(small, ser, np.where(pos, np.arctan(t) / ts, np.where(e < 0.0, neg, 1.0)))


def _rj_delta(x, y, z, p):
    r"""``(delta, sc)``: :math:`\delta = (p-x)(p-y)(p-z)`, scaled against underflow.

    :math:`|p-x|\le(\sqrt p+\sqrt x)^2`, so :math:`|\delta|\le d^2` in every
    duplication step, and ``e = fac^3 delta / d^2`` is O(1) even when both
    underflow (``p``, ``x``, ``y`` of order 1e-162 and below: the regime-B
    integral ``R_J(0, m1, 1, m1 c)`` near the separatrix). Where
    :math:`|\delta| < 2^{-960}` the two small factors are scaled by powers of
    two into ``[1/2, 1)`` and ``sc`` is the square root of the total scale, so
    that ``e = fac^3 delta / (d sc)^2`` exactly as before; elsewhere ``sc = 1``
    and nothing changes (bit for bit).
    """
    f1, f2, f3 = p - x, p - y, p - z
    delta = f1 * f2 * f3
    sc = np.ones_like(delta)
    tiny = (np.abs(delta) < 2.0**-960) & (f1 != 0) & (f2 != 0) & (f3 != 0)
    if np.any(tiny):
        e1 = np.where(tiny & (np.abs(f1) < 0.5), -np.frexp(f1)[1], 0)
        e2 = np.where(tiny & (np.abs(f2) < 0.5), -np.frexp(f2)[1], 0)
        e1 = e1 + (e1 + e2) % 2  # an even total: sc is an exact power of two
        delta = np.where(tiny, np.ldexp(f1, e1) * np.ldexp(f2, e2) * f3, delta)
        sc = np.where(tiny, np.ldexp(1.0, (e1 + e2) // 2), sc)
    return delta, sc


def _rj_step(st):
    a, fac, x, y, z, p, acc, delta, sc = st
    sx, sy, sz, sp = np.sqrt(x), np.sqrt(y), np.sqrt(z), np.sqrt(p)
    lam = sx * sy + sy * sz + sz * sx
    d = (sp + sx) * (sp + sy) * (sp + sz)
    dd = d * sc
    with np.errstate(over="ignore"):  # (d sc)^2 = inf only where e underflows to 0 anyway
        e = (fac * fac * fac) * delta / (dd * dd)
    # 1 + e = 2 sqrt(p) (p + lambda) / d exactly (expand the products), which
    # avoids the cancellation in 1 + e for p << x, y, z
    y1 = 2.0 * sp * (p + lam) / d
    return [
        0.25 * (a + lam),
        0.25 * fac,
        0.25 * (x + lam),
        0.25 * (y + lam),
        0.25 * (z + lam),
        0.25 * (p + lam),
        acc + fac * _rc1(e, y1) / d,
        delta,
        sc,
    ]


def rj_core(x, y, z, p):
    """R_J for x, y, z >= 0 (at most one zero), p > 0 (no checks)."""
    shape, (x, y, z, p) = _flat(x, y, z, p)
    a0 = (x + y + z + 2.0 * p) / 5.0
    delta, sc = _rj_delta(x, y, z, p)
    q = _RDJ_QFAC * np.maximum(
        np.maximum(np.abs(a0 - x), np.abs(a0 - y)),
        np.maximum(np.abs(a0 - z), np.abs(a0 - p)),
    )
    st = [a0, np.ones_like(a0), x, y, z, p, np.zeros_like(a0), delta, sc]
    a, fac, _, _, _, _, acc, _, _ = _duplicate(q, st, _rj_step)
    X = (a0 - x) * fac / a
    Y = (a0 - y) * fac / a
    Z = (a0 - z) * fac / a
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
    return (fac * poly / (a * np.sqrt(a)) + 6.0 * acc).reshape(shape)


def _rc_step(st):
    a, fac, x, y = st
    lam = 2.0 * np.sqrt(x) * np.sqrt(y) + y
    return [0.25 * (a + lam), 0.25 * fac, 0.25 * (x + lam), 0.25 * (y + lam)]


def _rc(x, y):
    """R_C for x >= 0, y > 0 (no checks), by duplication (Carlson 1995)."""
    shape, (x, y) = _flat(x, y)
    a0 = (x + 2.0 * y) / 3.0
    q = _RC_QFAC * np.abs(a0 - x)
    a, fac, _, _ = _duplicate(q, [a0, np.ones_like(a0), x, y], _rc_step)
    s = (y - a0) * fac / a
    poly = 1.0 + s * s * (
        3.0 / 10.0 + s * (1.0 / 7.0 + s * (3.0 / 8.0 + s * (9.0 / 22.0 + s * (159.0 / 208.0 + s * 9.0 / 8.0))))
    )
    return (poly / np.sqrt(a)).reshape(shape)


def _check_nonneg(name, arr):
    if np.any(arr < 0.0):
        bad = arr[arr < 0.0].ravel()[0].item()
        raise InvalidInputError(f"{name} must be >= 0, got {name}={bad!r}")


def elliprf(x, y, z):
    r"""Carlson's symmetric integral of the first kind.

    .. math:: R_F(x,y,z) = \frac12\int_0^\infty
              \frac{dt}{\sqrt{(t+x)(t+y)(t+z)}}

    Duplication algorithm (Carlson 1995, DLMF 19.36.1), relative error of a
    few ulp.

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one of them zero (broadcast together).

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative or non-finite arguments or if two or more are zero.
    """
    x, y, z = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z")))
    for n, v in (("x", x), ("y", y), ("z", z)):
        _check_nonneg(n, v)
    zeros = (x == 0.0).astype(int) + (y == 0.0) + (z == 0.0)
    if np.any(zeros >= 2):
        raise InvalidInputError("elliprf: at most one of x, y, z may be zero (R_F diverges)")
    return _out(rf_core(x, y, z))


def elliprd(x, y, z):
    r"""Carlson's symmetric integral of the second kind.

    .. math:: R_D(x,y,z) = \frac32\int_0^\infty
              \frac{dt}{\sqrt{(t+x)(t+y)}\,(t+z)^{3/2}}

    Parameters
    ----------
    x, y : array_like
        Non-negative, not both zero.
    z : array_like
        Positive.

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite arguments, ``z <= 0`` or ``x = y = 0``.
    """
    x, y, z = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z")))
    _check_nonneg("x", x)
    _check_nonneg("y", y)
    if np.any(z <= 0.0):
        raise InvalidInputError(f"elliprd: z must be > 0, got z={z[z <= 0.0].ravel()[0].item()!r}")
    if np.any((x == 0.0) & (y == 0.0)):
        raise InvalidInputError("elliprd: x and y must not both be zero (R_D diverges)")
    return _out(_rd(x, y, z))


def elliprj(x, y, z, p):
    r"""Carlson's symmetric integral of the third kind.

    .. math:: R_J(x,y,z,p) = \frac32\int_0^\infty
              \frac{dt}{(t+p)\sqrt{(t+x)(t+y)(t+z)}}

    Duplication algorithm with the ``R_C`` correction terms (Carlson 1995,
    DLMF 19.36.ii).  Only ``p > 0`` (no Cauchy principal value).

    Parameters
    ----------
    x, y, z : array_like
        Non-negative, at most one zero.
    p : array_like
        Positive.

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite arguments, ``p <= 0`` or two zeros among
        ``x, y, z``.
    """
    x, y, z, p = (_as_float_array(v, n) for v, n in ((x, "x"), (y, "y"), (z, "z"), (p, "p")))
    for n, v in (("x", x), ("y", y), ("z", z)):
        _check_nonneg(n, v)
    if np.any(p <= 0.0):
        raise InvalidInputError(
            f"elliprj: p must be > 0 (principal values are not supported), got p={p[p <= 0.0].ravel()[0].item()!r}"
        )
    zeros = (x == 0.0).astype(int) + (y == 0.0) + (z == 0.0)
    if np.any(zeros >= 2):
        raise InvalidInputError("elliprj: at most one of x, y, z may be zero (R_J diverges)")
    return _out(rj_core(x, y, z, p))


def elliprc(x, y):
    r"""Carlson's degenerate integral ``R_C(x, y) = R_F(x, y, y)``.

    .. math:: R_C(x,y) = \frac12\int_0^\infty \frac{dt}{\sqrt{t+x}\,(t+y)}

    Duplication algorithm (no cancellation for ``x ~ y``).

    Parameters
    ----------
    x : array_like
        Non-negative.
    y : array_like
        Positive (no principal value).

    Returns
    -------
    ndarray

    Raises
    ------
    InvalidInputError
        On negative/non-finite ``x`` or ``y <= 0``.
    """
    x = _as_float_array(x, "x")
    y = _as_float_array(y, "y")
    _check_nonneg("x", x)
    if np.any(y <= 0.0):
        raise InvalidInputError(f"elliprc: y must be > 0, got y={y[y <= 0.0].ravel()[0].item()!r}")
    return _out(_rc(x, y))


# ---------------------------------------------------------------------------
# incomplete integrals in Legendre form
# ---------------------------------------------------------------------------
def _reduce_pi(phi):
    """``phi = j pi + (rh + rl)`` with ``|rh| <= pi/2``; returns sin, cos of
    the reduced amplitude (to a few ulp relative) and ``j``."""
    j = np.rint(phi / _PI_HI)
    ph, pl = _two_prod(j, _PI_HI)
    rh, rl = _two_sum(phi - ph, -pl - j * _PI_LO)
    s0, c0 = np.sin(rh), np.cos(rh)
    s = s0 + c0 * rl
    c = c0 - s0 * rl
    return j, s, c


def ellipf(phi, m=None, m1=None):
    r"""Incomplete elliptic integral of the first kind, any real amplitude.

    .. math:: F(\phi|m) = \int_0^\phi \frac{d\theta}{\sqrt{1-m\sin^2\theta}}
                        = 2jK(m) + \sin\phi_r\,
                          R_F(\cos^2\phi_r, 1 - m\sin^2\phi_r, 1),

    with ``phi = j pi + phi_r``, ``|phi_r| <= pi/2`` (reduction in
    double-double; DLMF 19.25.5, 19.2.10).

    Parameters
    ----------
    phi : array_like
        Amplitude (radians), any finite value.
    m, m1 : array_like, optional
        Parameter in ``[0, 1]`` and/or its complement.

    Returns
    -------
    ndarray
        ``F``; ``+-inf`` where ``m == 1`` and ``|phi| > pi/2``.

    Raises
    ------
    InvalidInputError
        As :func:`jacobi_sncndn`.
    """
    phi = _as_float_array(phi, "phi")
    m, m1 = _parameters(m, m1)
    kh, kl, _ = _ellipk_dd(m1)
    j, s, c = _reduce_pi(phi)
    s2 = s * s
    delta2 = np.where(m <= 0.5, 1.0 - m * s2, c * c + m1 * s2)
    f = s * rf_core(c * c, delta2, 1.0)
    with np.errstate(invalid="ignore"):
        out = np.where(j == 0.0, f, (2.0 * j * kh + f) + 2.0 * j * kl)
    return _out(out)


def ellippi_complete(n, m=None, m1=None):
    r"""Complete elliptic integral of the third kind for ``n < 1``.

    .. math:: \Pi(n|m) = \int_0^{\pi/2}
              \frac{d\theta}{(1-n\sin^2\theta)\sqrt{1-m\sin^2\theta}}
              = K(m) + \frac{n}{3} R_J(0, 1-m, 1, 1-n).

    Parameters
    ----------
    n : array_like
        Characteristic, ``n < 1``.
    m, m1 : array_like, optional
        Parameter in ``[0, 1]`` and/or its complement.

    Returns
    -------
    ndarray
        ``inf`` where ``m == 1``.

    Raises
    ------
    InvalidInputError
        If ``n >= 1`` or as :func:`jacobi_sncndn`.
    """
    n = _as_float_array(n, "n")
    if np.any(n >= 1.0):
        raise InvalidInputError(f"characteristic n must be < 1, got n={n[n >= 1.0].ravel()[0].item()!r}")
    m, m1 = _parameters(m, m1)
    kh, _, _ = _ellipk_dd(m1)
    sep = m1 == 0.0
    rj = rj_core(0.0, np.where(sep, 1.0, m1), 1.0, 1.0 - n)
    out = np.where(sep, np.inf, kh + n / 3.0 * rj)
    return _out(out)


def ellippi(n, phi, m=None, m1=None):
    r"""Incomplete elliptic integral of the third kind, ``n < 1``, any real ``phi``.

    .. math:: \Pi(n;\phi|m) = \int_0^\phi
              \frac{d\theta}{(1-n\sin^2\theta)\sqrt{1-m\sin^2\theta}}

    evaluated as ``2 j Pi(n|m) + s R_F(c^2, D^2, 1) + (n/3) s^3
    R_J(c^2, D^2, 1, 1 - n s^2)`` with ``phi = j pi + phi_r``, ``s, c`` the
    sine and cosine of ``phi_r`` and ``D^2 = 1 - m s^2`` (DLMF 19.25.14).

    Parameters
    ----------
    n : array_like
        Characteristic, ``n < 1`` (so that ``1 - n sin^2 > 0``).
    phi : array_like
        Amplitude (radians), any finite value.
    m, m1 : array_like, optional
        Parameter in ``[0, 1]`` and/or its complement.

    Returns
    -------
    ndarray
        ``+-inf`` where ``m == 1`` and ``|phi| > pi/2``.

    Raises
    ------
    InvalidInputError
        If ``n >= 1`` or as :func:`jacobi_sncndn`.

    Notes
    -----
    For ``n << -1`` the two terms cancel (relative error grows like
    ``1 - n``); the rigid-body kernel uses the third term alone (see
    :mod:`eulerpoisson.solvers.exact.motion`) and never needs this combination.
    """
    n = _as_float_array(n, "n")
    if np.any(n >= 1.0):
        raise InvalidInputError(f"characteristic n must be < 1, got n={n[n >= 1.0].ravel()[0].item()!r}")
    phi = _as_float_array(phi, "phi")
    m, m1 = _parameters(m, m1)
    kh, kl, _ = _ellipk_dd(m1)
    sep = m1 == 0.0
    j, s, c = _reduce_pi(phi)
    s2 = s * s
    c2 = c * c
    delta2 = np.where(m <= 0.5, 1.0 - m * s2, c2 + m1 * s2)
    p = np.where(n <= 0.0, 1.0 - n * s2, (1.0 - n) + n * c2)
    part = s * rf_core(c2, delta2, 1.0) + n / 3.0 * (s * s2) * rj_core(c2, delta2, 1.0, p)
    full = kh + n / 3.0 * rj_core(0.0, np.where(sep, 1.0, m1), 1.0, 1.0 - n)
    with np.errstate(invalid="ignore"):
        out = np.where(j == 0.0, part, 2.0 * j * full + part)
    return _out(out)
