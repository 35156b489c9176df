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

Modules
-------
The functions live in three modules, all re-exported here under their
names (the same objects, so the compiled kernels that import them from here
see the ones they always did):

* :mod:`eulerpoisson.numerics.jacobi`: the Jacobi functions and ``K``
  (double-double argument reduction modulo ``K``, the descending Landen
  transformation; its docstring describes the algorithms);
* :mod:`eulerpoisson.numerics.carlson`: Carlson's integrals (duplication);
* this module: the incomplete integrals in Legendre form, whose amplitude is
  reduced modulo ``pi`` in double-double;

and :mod:`eulerpoisson.numerics.elliptic_common` checks the arguments of all.

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

import numpy as np

from ..errors import InvalidInputError
from .carlson import RC_SERIES_MAX as RC_SERIES_MAX
from .carlson import elliprc as elliprc
from .carlson import elliprd as elliprd
from .carlson import elliprf as elliprf
from .carlson import elliprj as elliprj
from .carlson import rc1_series as rc1_series
from .carlson import rf_core as rf_core
from .carlson import rj_core as rj_core
from .doubledouble import two_prod as _two_prod
from .doubledouble import two_sum as _two_sum
from .elliptic_common import PI_HI as _PI_HI
from .elliptic_common import PI_LO as _PI_LO
from .elliptic_common import parameters as _parameters
from .elliptic_common import real_array as _as_float_array
from .elliptic_common import scalar_out as _out
from .jacobi import SINCOS_POLY_MAX as SINCOS_POLY_MAX
from .jacobi import JacobiParams as JacobiParams
from .jacobi import cos_poly as cos_poly
from .jacobi import ellipk as ellipk
from .jacobi import ellipk_dd as _ellipk_dd
from .jacobi import ellipkp as ellipkp
from .jacobi import jacobi_am as jacobi_am
from .jacobi import jacobi_params as jacobi_params
from .jacobi import jacobi_sncndn as jacobi_sncndn
from .jacobi import sin_poly as sin_poly
from .jacobi import sncndn_dd as sncndn_dd

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
