r"""Closed-form (elliptic-function) motion of the free rigid body.

The body angular momentum ``M(t)`` in the principal frame is given by Jacobi
elliptic functions and the attitude by a rotation about the constant spatial
angular momentum through an angle given by an elliptic integral of the third
kind (Jacobi 1849; Landau & Lifshitz, *Mechanics*, section 37; Celledoni,
Fassò, Säfström & Zanna 2008).  Everything is O(1) per output time and
vectorized over bodies and times; no time stepping.

Conventions (those of the package): ``x_space = R x_body``,
``dR/dt = R [Omega]x`` with the body angular velocity ``Omega = M / I``
(componentwise, principal frame), paper eqs. 1.4-1.5; ``R(0) = 1``;
quaternions scalar-first, Hamilton product, ``R(q)`` the active rotation.
The spatial angular momentum ``m = R(t) M(t)`` is constant and equals ``M0``.

Derivation (summary, sorted principal moments ``I1 <= I2 <= I3``)
-----------------------------------------------------------------
With ``M^2 = |M|^2`` and ``2E = sum M_i^2 / I_i`` define the non-negative,
cancellation-free combinations

.. math::

    a_1 = M^2 - 2EI_1 = M_2^2\frac{I_2-I_1}{I_2} + M_3^2\frac{I_3-I_1}{I_3},\qquad
    a_3 = 2EI_3 - M^2 = M_1^2\frac{I_3-I_1}{I_1} + M_2^2\frac{I_3-I_2}{I_2},

and the separatrix indicator ``D = M^2 - 2 E I2 = M3^2 (I3-I2)/I3 -
M1^2 (I2-I1)/I1``, evaluated in double-double arithmetic from the exact
inputs.

*Regime B* (``D > 0``, M circulates about the axis of the largest moment):

.. math::

    M_1 = A_1\,\mathrm{cn}\,\tau,\; M_2 = s A_2\,\mathrm{sn}\,\tau,\;
    M_3 = s A_3\,\mathrm{dn}\,\tau,\quad
    A_1^2 = \frac{a_3 I_1}{I_3-I_1},\; A_2^2 = \frac{a_3 I_2}{I_3-I_2},\;
    A_3^2 = \frac{a_1 I_3}{I_3-I_1},

``tau = lambda t + tau0``, ``lambda^2 = (I3-I2) a1 / (I1 I2 I3)``,
``m = k^2 = (I2-I1) a3 / ((I3-I2) a1)`` and, computed directly,
``1 - m = (I3-I1) D / ((I3-I2) a1)``; ``s = sign M3(0)``.

*Regime A* (``D < 0``, about the axis of the smallest moment): indices 1 and 3
exchange roles, ``M1 = s A1 dn``, ``M2 = s A2 sn``, ``M3 = A3 cn`` with
``A2^2 = a1 I2/(I2-I1)``, ``lambda^2 = (I2-I1) a3/(I1 I2 I3)``,
``m = (I3-I2) a1/((I2-I1) a3)``, ``1 - m = (I3-I1)(-D)/((I2-I1) a3)``.
*On the separatrix* (``D = 0``) ``m = 1``: ``sn = tanh``, ``cn = dn = sech``.
The initial phase ``tau0 = F(phi0|m)`` follows from the amplitude of
``M(0)``.

*Attitude.*  Let ``e`` be the (signed) axis circled by ``M`` (``s e_3`` in
regime B, ``s e_1`` in A) and ``Q(M)`` the minimal rotation taking ``M/|M|``
to ``e`` (quaternion ``(1 + z, Mhat x e)/sqrt(2(1+z))``, ``z = Mhat.e > 0``
never singular).  Then

.. math::

    R(t) = Q(M_0)^T\, R_e(\alpha(t))\, Q(M(t)),\qquad
    \alpha = \psi(t) - (\beta(t) - \beta(0)),

with ``beta`` the azimuth of ``M`` about ``e`` and ``psi`` the precession
angle about ``m``, ``psi' = 2E/|M| + (Mhat.e) beta'``.  Written without
cancellation,

.. math::

    \text{A:}\quad \psi' = \frac{|M|}{I_3} + \frac{|M|(I_3-I_2)}{I_2 I_3}
        \frac{M_2^2}{M_2^2+M_3^2}, \qquad
    \text{B:}\quad \psi' = \frac{|M|}{I_2} + \frac{|M|(I_2-I_1)}{I_1 I_2}
        \frac{M_1^2}{M_1^2+M_2^2},

so that, with ``J(nu; u) = int_0^u sn^2/(1 - nu sn^2)`` evaluated as
``s^3 R_J(c^2, d^2, 1, 1 - nu s^2)/3`` (a single positive term, the fourth
argument formed without cancellation),

* A: ``psi = |M| t/I3 + c_A/lambda [J(nu_A; tau) - J(nu_A; tau0)]``,
  ``nu_A = -N_A = -I1 (I3-I2) / (I3 (I2-I1)) <= 0``,
  ``c_A = |M| (I3-I2)(I3-I1) / (I3^2 (I2-I1))``;
* B: ``psi = |M| t/I2 + c_B/lambda [G(tau) - G(tau0)]`` with
  ``G(u) = int_0^u cn^2/(1 - n' cn^2)``, ``n' = I3 (I2-I1)/(I2 (I3-I1))``,
  ``c_B = |M| (I3-I2)(I2-I1) / (I2^2 (I3-I1))``.  ``G`` is evaluated either
  directly, ``G = g0 (u - g0 J(-N_B; u))`` (``N_B = n'/(1-n')``,
  ``g0 = 1 + N_B``) or, shifted by a quarter period (``cn^2(K+v)/(1 - n'
  cn^2(K+v)) = m1 sn^2 v/(1 - nu_B sn^2 v)``), as
  ``G = G(K) + m1 J(nu_B; u - K)`` with ``nu_B = m + n' m1 < 1`` and
  ``1 - nu_B = m1 I1 (I3-I2)/(I2 (I3-I1))``, whichever has no cancellation;
* separatrix: ``J = (tau - atan(sqrt(N) tanh tau)/sqrt(N))/(1+N)``.

*Increments without offsets.*  For ``|lambda t| <= K`` the increment
``J(tau) - J(tau0)`` is not formed as a difference (whose rounding error
``eps |J(tau0)|`` would correspond to the precession over up to a quarter
period of ``M``, huge for slow, nearly symmetric bodies) but by Jacobi's
addition theorem for the integral of the third kind (Whittaker & Watson
22.74) specialised to real characteristic ``nu = -N``:

.. math::

    J(\tau) - J(\tau_0) = J(\delta) - \frac{1}{C}\arctan\frac{C Y}{X},\quad
    \delta = \lambda t,\; P = \mathrm{sn}\,\tau\,\mathrm{sn}\,\tau_0,\;
    Y = -P\,\mathrm{sn}\,\delta,\;
    X = 1 + N\mathrm{sn}^2\delta + N P\,\mathrm{cn}\,\delta\,\mathrm{dn}\,\delta,

``C = sqrt(N (N + m)(1 + N))``; on ``|delta| <= K`` one has
``X >= (1 + N sn^2 delta)/2`` (checked numerically, ``>= 0.75``), so every
term is O(delta).  For regime B the same holds for ``G`` with
``G(tau) - G(tau0) = G(delta) - g0^2 (J-correction for -N_B)``.

*Long times.*  ``tau = lambda t + tau0`` is formed in double-double and
reduced modulo the quarter period ``K`` (itself a double-double) exactly, see
:mod:`eulerpoisson.numerics.elliptic`; ``J``, ``G`` and ``beta`` use the
quarter-period index (``J(tau) = n J_c + J_periodic``), so no digits are lost
as ``t`` grows beyond the unavoidable ``|Omega| t eps`` (``lambda`` itself
is a rounded number).  Inputs are rescaled by exact powers of two
(``M0 -> M0/2^a``, ``I -> I/2^b``, ``t -> t 2^(a-b)``) to keep all
intermediate quantities in range.

Degenerate cases: ``M0 = 0``, ``M0`` along a principal axis (of any
multiplicity, including the unstable middle axis and any axis of a sphere)
are relative equilibria (``M`` constant, uniform rotation about ``M0``);
symmetric tops are the limits ``m = 0`` (regime B for ``I1 = I2``, A for
``I2 = I3``), with ``K = pi/2`` and ``c = 0``.

*Implementation.*  The functions below are vectorized NumPy code (the
reference, and the fallback when numba is not installed or
``EULERPOISSON_NO_NUMBA=1``).  When numba is available :func:`exact_motion`
and :func:`exact_constants` run the compiled kernels of
:mod:`eulerpoisson.solvers.exact.kernels` instead (for :func:`exact_motion`
the lane kernel of :mod:`eulerpoisson.solvers.exact.lanes`, sixteen
evaluations in lockstep): the same floating-point operations in the same
order, with O(1) memory per body, bitwise equal to this module where both use
the C library's elementary functions (to a few ulp otherwise).
``solve(..., method="exact")`` runs this module's NumPy path for small
problems (about 2*10^4 evaluations or fewer: ``compiled=False``), which it
solves faster than numba is imported and the kernel loaded from its cache.

References
----------
.. [1] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., section 37.
.. [2] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation
   of the free rigid body motion and its use in splitting methods", SIAM J.
   Sci. Comput. 30 (2008) 2084-2112.
.. [3] B. C. Carlson, "Numerical computation of real or complex elliptic
   integrals", Numer. Algorithms 10 (1995) 13-26.
.. [4] DLMF chapters 19 and 22, https://dlmf.nist.gov/.
"""

from __future__ import annotations

from types import ModuleType
from typing import NamedTuple

import numpy as np

from ...errors import InvalidInertiaError, InvalidInputError
from ...numerics import elliptic as _el
from ...numerics.doubledouble import dd_add, dd_mul, dd_mul_d, quick_two_sum, two_prod, two_sum
from ...numerics.quaternion import qmul_components
from ...util import jit as _jit
from ...util.validate import check_phase

__all__ = [
    "ExactMotion",
    "ExactConstants",
    "exact_motion",
    "exact_motion_unchecked",
    "one_body_motion",
    "exact_constants",
    "EQUILIBRIUM",
    "REGIME_A",
    "REGIME_B",
    "SEPARATRIX",
]

# regime codes
EQUILIBRIUM = 0
REGIME_A = 1  # M circulates about the axis of the smallest moment (D < 0)
REGIME_B = 2  # M circulates about the axis of the largest moment (D > 0)
SEPARATRIX = 3  # D = 0, m = 1 (hyperbolic functions)

# below this complementary parameter the orbit is treated as the separatrix
# (K > 230: indistinguishable in double precision for lambda t < ~200)
_M1_SEPARATRIX = 1e-200
_DEFAULT_CHUNK = 1 << 15


class ExactMotion(NamedTuple):
    """Result of :func:`exact_motion`.

    Attributes
    ----------
    M : ndarray, shape (..., T, 3)
        Body angular momentum in the principal frame (input axis order).
    q : ndarray, shape (..., T, 4)
        Attitude quaternion (scalar first) of ``R(t)``, ``R(0) = 1``,
        continuous in ``t``.
    """

    M: np.ndarray
    q: np.ndarray


class ExactConstants(NamedTuple):
    """Per-body constants of the closed-form solution (see :func:`exact_constants`).

    All arrays have the broadcast batch shape of ``inertia`` and ``M0``.

    Attributes
    ----------
    regime : ndarray of int
        0 relative equilibrium, 1 regime A (about the smallest-moment axis),
        2 regime B (about the largest-moment axis), 3 separatrix.
    m, m1 : ndarray
        Elliptic parameter ``k^2`` and its complement ``1 - k^2`` (computed
        directly).  Equilibria report ``m = 0``, ``m1 = 1``.
    K : ndarray
        Quarter period ``K(m)`` (``inf`` on the separatrix, ``pi/2`` for
        equilibria).
    lam : ndarray
        Rate ``lambda`` of the elliptic argument ``tau = lambda t + tau0``
        (physical time units; 0 for equilibria).
    tau0 : ndarray
        Initial elliptic argument (0 for equilibria).
    period : ndarray
        Period ``4K/lambda`` of ``M(t)`` (``inf`` on the separatrix and for
        equilibria).
    """

    regime: np.ndarray
    m: np.ndarray
    m1: np.ndarray
    K: np.ndarray
    lam: np.ndarray
    tau0: np.ndarray
    period: np.ndarray


# ---------------------------------------------------------------------------
# input handling and frame permutation
# ---------------------------------------------------------------------------
def _validate(inertia, M0):
    try:
        inertia = np.asarray(inertia, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInertiaError(f"inertia must be a real array of shape (..., 3), got {inertia!r}") from exc
    try:
        M0 = np.asarray(M0, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"M0 must be a real array of shape (..., 3), got {M0!r}") from exc
    if inertia.ndim < 1 or inertia.shape[-1] != 3:
        raise InvalidInertiaError(f"inertia must have shape (..., 3) (principal moments), got shape {inertia.shape}")
    if M0.ndim < 1 or M0.shape[-1] != 3:
        raise InvalidInputError(f"M0 must have shape (..., 3), got shape {M0.shape}")
    if not np.isfinite(inertia).all():
        raise InvalidInertiaError("inertia must be finite; got non-finite principal moments")
    if (inertia <= 0.0).any():
        bad = inertia[inertia <= 0.0].ravel()[0].item()
        raise InvalidInertiaError(f"principal moments of inertia must be > 0, got {bad!r}")
    if not np.isfinite(M0).all():
        raise InvalidInputError("M0 must be finite; got non-finite angular momentum")
    if inertia.shape == M0.shape:  # common case, no broadcasting needed
        batch = inertia.shape[:-1]
        return inertia.reshape(-1, 3), M0.reshape(-1, 3), batch
    try:
        batch = np.broadcast_shapes(inertia.shape[:-1], M0.shape[:-1])
    except ValueError as exc:
        raise InvalidInputError(
            f"inertia batch shape {inertia.shape[:-1]} and M0 batch shape {M0.shape[:-1]} do not broadcast"
        ) from exc
    inertia = np.broadcast_to(inertia, batch + (3,)).reshape(-1, 3)
    M0 = np.broadcast_to(M0, batch + (3,)).reshape(-1, 3)
    return inertia, M0, batch


def _validate_t(t):
    try:
        t = np.asarray(t, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"t must be a real 1-d array of times, got {t!r}") from exc
    if t.ndim != 1:
        raise InvalidInputError(f"t must be a 1-d array of shape (T,), got shape {t.shape}")
    if not np.isfinite(t).all():
        raise InvalidInputError("t must be finite; got non-finite times")
    return t


def _sorting(inertia):
    """Proper signed permutation to ascending moments.

    Returns ``perm`` (nb, 3) and ``sgn`` (nb, 3) with
    ``x_sorted[k] = sgn[k] * x[perm[k]]``; ``det = +1``.
    """
    perm = np.argsort(inertia, axis=-1, kind="stable")
    # parity of the permutation: number of inversions
    inv = (perm[:, 0] > perm[:, 1]).astype(int) + (perm[:, 0] > perm[:, 2]) + (perm[:, 1] > perm[:, 2])
    sgn = np.ones(perm.shape)
    sgn[:, 1] = np.where(inv % 2 == 1, -1.0, 1.0)
    return perm, sgn


def _to_sorted(x, perm, sgn):
    return sgn * np.take_along_axis(x, perm, axis=-1)


# ---------------------------------------------------------------------------
# per-body constants
# ---------------------------------------------------------------------------
class _Body:
    """Per-body constants of the generic (non-equilibrium) solution, plain arrays.

    Regime A: ``psi = rate t + coef [J(nu_A; tau) - J(nu_A; tau0)]``.
    Regime B: ``psi = rate t + coef [G(tau) - G(tau0)]`` with
    ``G(tau) = int_0^tau cn^2/(1 - n' cn^2) = g0 (tau - g0 J(-N_B; tau))
    = Gc + m1 J(nu_B; tau - K)``, ``g0 = 1/(1-n') = 1 + N_B``.
    """

    __slots__ = (
        "regime",
        "m",
        "m1",
        "lam",
        "t0h",
        "t0l",
        "Ac",
        "A2",
        "Aa",
        "sa",
        "sc",
        "rate",
        "coef",
        "nu",
        "omnu",
        "Jc",
        "Nadd",
        "Cadd",
        "nud",
        "omnud",
        "Jcd",
        "g0",
        "Gc",
        "sn0",
        "sep",
        "caseB",
        "Jfar0",
        "theta0",
        "kfull",
        "P",
        "q0",
    )
    regime: np.ndarray
    m: np.ndarray
    m1: np.ndarray
    lam: np.ndarray
    t0h: np.ndarray
    t0l: np.ndarray
    Ac: np.ndarray
    A2: np.ndarray
    Aa: np.ndarray
    sa: np.ndarray
    sc: np.ndarray
    rate: np.ndarray
    coef: np.ndarray
    nu: np.ndarray
    omnu: np.ndarray
    Jc: np.ndarray
    Nadd: np.ndarray
    Cadd: np.ndarray
    nud: np.ndarray
    omnud: np.ndarray
    Jcd: np.ndarray
    g0: np.ndarray
    Gc: np.ndarray
    sn0: np.ndarray
    sep: np.ndarray
    caseB: np.ndarray
    Jfar0: np.ndarray
    theta0: np.ndarray
    kfull: np.ndarray
    P: _el.JacobiParams
    q0: tuple[np.ndarray, ...]  # the quaternion's components


def _dd_square_times(x, dh, dl, y):
    """``x^2 * (dh + dl) * y`` as double-double."""
    sh, sl = two_prod(x, x)
    ph, pl = dd_mul(sh, sl, dh, dl)
    return dd_mul_d(ph, pl, y)


def _jc(nu_om, m1, sep):
    """Complete ``J_c = R_J(0, m1, 1, 1 - nu) / 3`` (0 on the separatrix)."""
    with np.errstate(all="ignore"):
        jc = _el.rj_core(0.0, np.where(sep, 1.0, m1), 1.0, nu_om) / 3.0
    return np.where(sep, 0.0, jc)


def _constants(Is, Ms):
    """Constants for bodies in the sorted, scaled frame (arrays (nb, 3)).

    Returns ``(eq, body)`` with ``eq`` the equilibrium mask over all bodies and
    ``body`` a :class:`_Body` for the non-equilibrium ones (in order).
    """
    I1, I2, I3 = Is[:, 0], Is[:, 1], Is[:, 2]
    M1, M2, M3 = Ms[:, 0], Ms[:, 1], Ms[:, 2]
    d21 = I2 - I1
    d32 = I3 - I2
    d31 = I3 - I1
    msq = M1 * M1 + M2 * M2 + M3 * M3
    a1 = M2 * M2 * d21 / I2 + M3 * M3 * d31 / I3
    a3 = M1 * M1 * d31 / I1 + M2 * M2 * d32 / I2
    # D = M^2 - 2 E I2 = (M3^2 (I3-I2) I1 - M1^2 (I2-I1) I3) / (I1 I3), double-double
    d32h, d32l = two_sum(I3, -I2)
    d21h, d21l = two_sum(I2, -I1)
    t3h, t3l = _dd_square_times(M3, d32h, d32l, I1)
    t1h, t1l = _dd_square_times(M1, d21h, d21l, I3)
    dh, _ = dd_add(t3h, t3l, -t1h, -t1l)
    D = dh / (I1 * I3)
    eq = (msq == 0.0) | (a1 == 0.0) | (a3 == 0.0) | ((dh == 0.0) & (M1 * M1 * d21 == 0.0) & (M3 * M3 * d32 == 0.0))
    g = ~eq
    I1, I2, I3, M1, M2, M3 = I1[g], I2[g], I3[g], M1[g], M2[g], M3[g]
    d21, d32, d31, msq, a1, a3, D = d21[g], d32[g], d31[g], msq[g], a1[g], a3[g], D[g]
    mn = np.sqrt(msq)

    B = _Body()
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        caseB = D > 0.0
        m1B = d31 * D / (d32 * a1)
        caseB = caseB & (m1B >= _M1_SEPARATRIX)
        mB = d21 * a3 / (d32 * a1)
        m1A = d31 * (-D) / (d21 * a3)
        mA = d32 * a1 / (d21 * a3)
        m = np.where(caseB, mB, mA)
        m1 = np.where(caseB, m1B, m1A)
        sep = (~caseB) & (m1 < _M1_SEPARATRIX)
        # make m + m1 = 1 with the smaller of the two computed directly
        small_m = m <= m1
        m, m1 = np.where(small_m, m, 1.0 - m1), np.where(small_m, 1.0 - m, m1)
        m = np.where(sep, 1.0, np.clip(m, 0.0, 1.0))
        m1 = np.where(sep, 0.0, np.clip(m1, 0.0, 1.0))

        A1 = np.sqrt(a3 * I1 / d31)
        A2 = np.where(caseB, np.sqrt(a3 * I2 / d32), np.sqrt(a1 * I2 / d21))
        A3 = np.sqrt(a1 * I3 / d31)
        lam = np.where(caseB, np.sqrt(d32 * a1 / (I1 * I2 * I3)), np.sqrt(d21 * a3 / (I1 * I2 * I3)))
        # c-axis (cn) and a-axis (dn)
        Ac = np.where(caseB, A1, A3)
        Aa = np.where(caseB, A3, A1)
        Mc0 = np.where(caseB, M1, M3)
        Ma0 = np.where(caseB, M3, M1)
        sa = np.where(Ma0 < 0.0, -1.0, 1.0)
        sc = np.where(sep & (Mc0 < 0.0), -1.0, 1.0)

        # precession rates and characteristics (see the module docstring)
        rate = np.where(caseB, mn / I2, mn / I3)
        coefA = mn * d32 * d31 / (I3 * I3 * d21 * lam)
        coefB = mn * d32 * d21 / (I2 * I2 * d31 * lam)
        coef = np.where(caseB, coefB, coefA)
        NA = I1 * d32 / (I3 * d21)  # -nu_A
        omnuA = I2 * d31 / (I3 * d21)  # 1 - nu_A
        nprime = I3 * d21 / (I2 * d31)
        omnprime = I1 * d32 / (I2 * d31)  # 1 - n'
        NB = nprime / omnprime
        nuB = m + nprime * m1
        omnuB = m1 * omnprime  # 1 - nu_B
        nu = np.where(caseB, nuB, -NA)
        omnu = np.where(caseB, omnuB, omnuA)
        Nadd = np.where(caseB, NB, NA)
        coef = np.where(np.isfinite(coef), coef, 0.0)
        nu = np.where(np.isfinite(nu), nu, 0.0)
        omnu = np.where(np.isfinite(omnu) & (omnu > 0.0), omnu, 1.0)
        Nadd = np.where(np.isfinite(Nadd), Nadd, 0.0)
        Cadd = np.sqrt(Nadd * (Nadd + m) * (1.0 + Nadd))
        g0 = np.where(caseB, 1.0 + Nadd, 1.0)

        # initial phase: amplitude (c0, s0) of (sc Mc/Ac, sa sc M2/A2)
        x = sc * Mc0 / Ac
        y = sa * sc * M2 / A2
        h = np.hypot(x, y)
        c0 = x / h
        s0 = y / h
    P = _el.jacobi_params(m, m1)
    kh, kl = P.kh, P.kl
    s2 = s0 * s0
    delta2 = np.where(m <= 0.5, 1.0 - m * s2, c0 * c0 + m1 * s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        F0 = s0 * _el.rf_core(c0 * c0, np.where(sep, 1.0, delta2), 1.0)
        tsep = np.arcsinh(s0 / c0)
    sg = np.where(s0 < 0.0, -1.0, 1.0)
    th, tl = two_sum(sg * 2.0 * kh, -F0)
    tl = tl + sg * 2.0 * kl
    th, tl = quick_two_sum(th, tl)
    neg = c0 < 0.0
    t0h = np.where(sep, tsep, np.where(neg, th, F0))
    t0l = np.where(sep | ~neg, 0.0, tl)

    B.regime = np.where(sep, SEPARATRIX, np.where(caseB, REGIME_B, REGIME_A))
    B.m, B.m1, B.lam, B.t0h, B.t0l = m, m1, lam, t0h, t0l
    B.Ac, B.A2, B.Aa, B.sa, B.sc = Ac, A2, Aa, sa, sc
    B.rate, B.coef, B.nu, B.omnu = rate, coef, nu, omnu
    B.Jc = _jc(omnu, m1, sep)
    B.Nadd, B.Cadd, B.g0 = Nadd, Cadd, g0
    # near-branch G(delta) of regime B, direct form: characteristic -N_B
    B.nud = np.where(caseB, -Nadd, nu)
    B.omnud = np.where(caseB, 1.0 + Nadd, omnu)
    B.Jcd = np.where(caseB, _jc(B.omnud, m1, sep), B.Jc)
    B.Gc = np.where(caseB, m1 * B.Jc, 0.0)
    B.sep, B.caseB, B.P = sep, caseB, P
    B.kfull = np.where(sep, np.inf, kh)
    # values at t = 0
    sn, _, _, n, r, s, c, d = _el.sncndn_dd(t0h, t0l, P)
    B.sn0 = sn
    B.theta0 = _theta(B, P, n, s, c)
    B.Jfar0 = _jfar(B, P, n, r, s, c, d)
    return eq, B


def _jtot(nu, omnu, jc, n, r, s, c, d, kp, sep):
    """``J(nu; u) = int_0^u sn^2 / (1 - nu sn^2)`` from the reduced values.

    ``u = n K + r`` (``|r| <= K/2``), ``s, c, d`` = sn, cn, dn of ``r``.
    ``J = n J_c + J_per`` with ``J_per = s^3 R_J(c^2, d^2, 1, 1 - nu s^2)/3``
    for even ``n`` and ``sign(r) (J_c - J(am(K - |r|)))`` for odd ``n``
    (values at ``K - |r|`` from ``cd``, ``k' sd``, ``k' nd``); the fourth
    argument of ``R_J`` is formed without cancellation.  Not for ``sep``.
    """
    odd = np.mod(n, 2.0) == 1.0
    sa_ = np.abs(s)
    S = np.where(odd, c / d, sa_)
    C = np.where(odd, kp * sa_ / d, c)
    Dd = np.where(odd, kp / d, d)
    S2 = S * S
    C2 = C * C
    p = np.where(nu <= 0.0, 1.0 - nu * S2, omnu + nu * C2)
    ok = ~sep & (S2 > 0.0)
    rj = _el.rj_core(np.where(ok, C2, 1.0), np.where(ok, Dd * Dd, 1.0), 1.0, np.where(ok, p, 1.0))
    jq = np.where(ok, S * S2 * rj / 3.0, 0.0)
    jper = np.where(odd, np.sign(r) * (jc - jq), np.where(r < 0.0, -jq, jq))
    return np.where(sep, 0.0, n * jc + jper)


def _theta(B, P, n, s, c):
    """Unwrapped azimuth ``atan2(A2 sn tau, Ac cn tau) = n pi/2 + dtheta``
    (``n`` reduced modulo 8: only ``theta`` modulo ``4 pi`` is used)."""
    odd = np.mod(n, 2.0) == 1.0
    dtheta = np.where(odd, np.arctan2(B.Ac * P.kp * s, B.A2 * c), np.arctan2(B.A2 * s, B.Ac * c))
    return np.mod(n, 8.0) * (0.5 * np.pi) + dtheta


def _jfar(B, P, n, r, s, c, d):
    """``J`` of the far branch: ``J(nu_A; tau)`` (A) or ``m1 J(nu_B; tau - K)`` (B)."""
    neff = np.where(B.caseB, n - 1.0, n)
    j = _jtot(B.nu, B.omnu, B.Jc, neff, r, s, c, d, P.kp, B.sep)
    return np.where(B.caseB, B.m1 * j, j)


def _jsep(N, tau):
    """Separatrix ``J = (tau - atan(sqrt(N) tanh tau)/sqrt(N)) / (1 + N)``."""
    rN = np.sqrt(N)
    tt = np.tanh(tau)
    z = rN * tt
    at = np.where(z != 0.0, np.arctan(z) / np.where(z != 0.0, z, 1.0), 1.0) * tt
    return (tau - at) / (1.0 + N)


def _near(B, P, dh, dl, sn_tau):
    """Increment ``J(tau) - J(tau0)`` (A) or ``G(tau) - G(tau0)`` (B) for
    ``|delta| <= K`` by the addition theorem, ``delta = lambda t = dh + dl``.

    With ``N = -nu >= 0``, ``P = sn tau sn tau0``:
    ``J(tau) - J(tau0) - J(delta) = -atan(C Y / X) / C``,
    ``Y = -P sn delta``, ``X = 1 + N sn^2 delta + N P cn delta dn delta > 0``,
    ``C = sqrt(N (N + m) (1 + N))`` (Jacobi's addition theorem for the
    integral of the third kind, Whittaker & Watson 22.74, specialized to real
    characteristic).  Every term is O(delta): no offset from ``tau0``.
    """
    snd, cnd, dnd, n, r, s, c, d = _el.sncndn_dd(dh, dl, P)
    N = B.Nadd
    Pp = sn_tau * B.sn0
    X = 1.0 + N * snd * snd + N * Pp * cnd * dnd
    Y = -Pp * snd
    z = B.Cadd * Y / X
    atanc = np.where(z != 0.0, np.arctan(z) / np.where(z != 0.0, z, 1.0), 1.0)
    xadd = -(Y / X) * atanc
    # J(nu_d; delta): regime A uses nu_A.  Regime B needs
    # G(delta) = g0 (delta - g0 J(-N_B; delta)) (direct, accurate while
    # |delta| g0 <= Gc) or Gc + m1 J(nu_B; delta - K) (shifted): one R_J.
    dlt = dh + dl
    use_sh = B.caseB & (np.abs(dlt) * B.g0 > B.Gc)
    jd = _jtot(
        np.where(use_sh, B.nu, B.nud),
        np.where(use_sh, B.omnu, B.omnud),
        np.where(use_sh, B.Jc, B.Jcd),
        np.where(use_sh, n - 1.0, n),
        r,
        s,
        c,
        d,
        P.kp,
        B.sep,
    )
    if np.any(B.sep):
        jd = np.where(B.sep, _jsep(N, dlt), jd)
    if np.any(B.caseB):
        gdel = np.where(use_sh, B.Gc + B.m1 * jd, B.g0 * (dlt - B.g0 * jd))
        return np.where(B.caseB, gdel - B.g0 * B.g0 * xadd, jd + xadd)
    return jd + xadd


def _qmin(M1, M2, M3, caseB, sa):
    """Quaternion of the minimal rotation taking ``M/|M|`` to ``e = sa e_a``."""
    nrm = np.sqrt(M1 * M1 + M2 * M2 + M3 * M3)
    x, y, z = M1 / nrm, M2 / nrm, M3 / nrm
    # z_e = Mhat . e > 0 ; Mhat x e
    ze = np.where(caseB, sa * z, sa * x)
    vx = np.where(caseB, sa * y, 0.0)
    vy = np.where(caseB, -sa * x, sa * z)
    vz = np.where(caseB, 0.0, -sa * y)
    w = 1.0 + ze
    f = 1.0 / np.sqrt(2.0 * w)
    return (w * f, vx * f, vy * f, vz * f)


def _subset(B, mask):
    """Elements ``mask`` (block shape) of the per-body data, as flat arrays."""
    shape = mask.shape
    sub = _Body()
    for name in _Body.__slots__:
        if name in ("P", "q0"):
            continue
        setattr(sub, name, np.broadcast_to(getattr(B, name), shape)[mask])
    P = B.P
    P2 = _el.JacobiParams()
    for name in ("m", "m1", "kp", "sep", "imag", "kh", "kl", "ph", "pcorr"):
        setattr(P2, name, np.broadcast_to(getattr(P, name), shape)[mask])
    L = P.sqm.shape[0]
    P2.sqm = np.broadcast_to(P.sqm, (L,) + shape)[:, mask]
    P2.pcl = np.broadcast_to(P.pcl, (L,) + shape)[:, mask]
    sub.P = P2
    return sub


def _increment(B, dh, dl, sn, n, r, s, c, d):
    """``J(tau) - J(tau0)`` (A) or ``G(tau) - G(tau0)`` (B) for a block.

    ``|lambda t| <= K``: addition theorem (:func:`_near`); otherwise the
    quarter-period reduction of ``tau`` (far branch).  Each branch is
    evaluated only on its own elements.
    """
    P = B.P
    near = np.abs(dh) <= B.kfull
    if np.all(near):
        return _near(B, P, dh, dl, sn)
    if not np.any(near):
        return _jfar(B, P, n, r, s, c, d) - B.Jfar0
    shape = near.shape
    out = np.empty(shape)
    far = ~near
    for mask, is_near in ((near, True), (far, False)):
        sub = _subset(B, mask)
        if is_near:
            out[mask] = _near(sub, sub.P, dh[mask], dl[mask], sn[mask])
        else:
            out[mask] = _jfar(sub, sub.P, n[mask], r[mask], s[mask], c[mask], d[mask]) - sub.Jfar0
    return out


def _generic_block(B, ts):
    """M (sorted frame) and q for bodies ``B`` (arrays (nb, 1)) at scaled times ``ts``."""
    P = B.P
    dh, dl = two_prod(B.lam, ts)
    th, tl = dd_add(dh, dl, B.t0h, B.t0l)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        sn, cn, dn, n, r, s, c, d = _el.sncndn_dd(th, tl, P)
        shape = sn.shape
        dh = np.broadcast_to(dh, shape)
        dl = np.broadcast_to(dl, shape)
        theta = _theta(B, P, n, s, c)
        dj = _increment(B, dh, dl, sn, n, r, s, c, d)
    Mc = B.sc * B.Ac * cn
    M2 = B.sa * B.sc * B.A2 * sn
    Ma = B.sa * B.Aa * dn
    M1 = np.where(B.caseB, Mc, Ma)
    M3 = np.where(B.caseB, Ma, Mc)
    psi = B.rate * ts + B.coef * dj
    sigma = np.where(B.caseB, 1.0, -1.0)
    alpha = psi - sigma * (theta - B.theta0)
    ca = np.cos(0.5 * alpha)
    sal = np.sin(0.5 * alpha)
    # q_e(alpha) with e = sa e_3 (B) or sa e_1 (A)
    qe = (
        ca,
        np.where(B.caseB, 0.0, B.sa * sal),
        np.zeros_like(sal),
        np.where(B.caseB, B.sa * sal, 0.0),
    )
    qt = _qmin(M1, M2, M3, B.caseB, B.sa)
    q = qmul_components(*qe, *qt)
    q0 = B.q0
    q = qmul_components(q0[0], -q0[1], -q0[2], -q0[3], *q)
    return (M1, M2, M3), q


def _take_body(B, idx):
    """Gather bodies ``idx`` and append a trailing axis for broadcasting over times."""
    new = _Body()
    for name in _Body.__slots__:
        if name in ("P", "q0"):
            continue
        val = getattr(B, name)
        setattr(new, name, val[idx][:, None])
    P = B.P.take(idx)
    P2 = _el.JacobiParams()
    for name in ("m", "m1", "kp", "sep", "imag", "kh", "kl", "ph", "pcorr"):
        setattr(P2, name, getattr(P, name)[:, None])
    P2.sqm = P.sqm[:, :, None]
    P2.pcl = P.pcl[:, :, None]
    new.P = P2
    new.q0 = tuple(c[idx][:, None] for c in B.q0)
    return new


def _prepare(inertia, M0):
    """Validation, sorting, scaling and constants shared by the public functions."""
    inertia, M0, batch = _validate(inertia, M0)
    perm, sgn = _sorting(inertia)
    Is = np.take_along_axis(inertia, perm, axis=-1)
    Ms = _to_sorted(M0, perm, sgn)
    # exact power-of-two scaling: max |M| and max I in [0.5, 1)
    _, eM = np.frexp(np.max(np.abs(Ms), axis=-1))
    _, eI = np.frexp(Is[:, 2])
    eM = np.where(np.max(np.abs(Ms), axis=-1) == 0.0, 0, eM)
    Ms = np.ldexp(Ms, -eM[:, None])
    Is = np.ldexp(Is, -eI[:, None])
    escale = (eM - eI).astype(np.int64)
    eM = eM.astype(np.int64)
    eq, B = _constants(Is, Ms)
    if B.lam.size:
        gidx = np.nonzero(~eq)[0]
        Mg = Ms[gidx]
        B.q0 = _qmin(Mg[:, 0], Mg[:, 1], Mg[:, 2], B.caseB, B.sa)
    else:
        B.q0 = tuple(np.zeros(0) for _ in range(4))
    return inertia, M0, batch, perm, sgn, eM, escale, eq, B


def exact_motion(inertia, M0, t, *, chunk_size=_DEFAULT_CHUNK, compiled=None):
    r"""Closed-form free rigid-body motion in the principal frame.

    Evaluates, for every body of the batch and every time, the exact solution
    of Euler's equations ``dM/dt = M x Omega`` and of the kinematics
    ``dR/dt = R [Omega]x`` (``Omega = M / I`` componentwise, paper
    eqs. 1.4-1.5) with ``M(0) = M0`` and ``R(0) = 1``, by Jacobi elliptic
    functions and an elliptic integral of the third kind (see the module
    docstring for the formulas).  Cost O(1) per (body, time); no time
    stepping.

    Parameters
    ----------
    inertia : array_like, shape (..., 3)
        Principal moments of inertia, any order, all ``> 0``; two or three
        may be equal (symmetric tops, sphere).  Triangle inequalities are
        not required by the formulas.
    M0 : array_like, shape (..., 3)
        Body angular momentum at ``t = 0`` in the principal frame (same axis
        order as ``inertia``); any finite value including 0, exact principal
        axes and exact separatrix data.  Batch shapes of ``inertia`` and
        ``M0`` broadcast.
    t : array_like, shape (T,)
        Times, any order and sign.
    chunk_size : int, optional
        Number of (body, time) pairs evaluated at once (memory bound only).
    compiled : bool, "python" or None, optional
        None (default): the compiled kernel when numba is in use, else
        NumPy; False: the NumPy path; True: the compiled kernel where numba
        is in use (NumPy otherwise); ``"python"``: the scalar kernel run as
        plain Python (:func:`eulerpoisson.util.jit.python_twins`: the
        compiled kernel's numbers bit for bit, no numba start; about 0.1 ms
        per body and per (body, time), for a few evaluations).
        ``solve(..., method="exact")`` passes ``"python"`` for a few
        evaluations and False for other small problems, which NumPy solves
        faster than numba is imported (:func:`eulerpoisson.util.jit.use_compiled`).

    Returns
    -------
    ExactMotion
        Named tuple ``(M, q)``: ``M`` of shape ``batch + (T, 3)``, the body
        angular momentum; ``q`` of shape ``batch + (T, 4)``, the unit
        quaternion ``(w, x, y, z)`` of ``R(t)`` (``x_space = R x_body``),
        continuous in ``t`` with ``q(0) = (1, 0, 0, 0)``.  The spatial
        angular momentum ``R(t) M(t)`` equals ``M0`` for all ``t``.

    Raises
    ------
    InvalidInertiaError
        If ``inertia`` does not have shape (..., 3), is not finite or has a
        non-positive moment.
    InvalidInputError
        If ``M0`` does not have shape (..., 3) or is not finite, if the batch
        shapes do not broadcast, if ``t`` is not a finite 1-d array, or if
        :math:`\Omega_0 = M_0/I` overflows or :math:`|\Omega_0||t| > 2^{48}`
        for some body (float64 cannot place the body on its orbit then).

    Notes
    -----
    Accuracy (measured against 30-50 digit references, see
    ``tests/test_exact_kernel.py``): ``M`` and ``q`` to ~1e-15 (a few ulp)
    for ``|Omega t| <~ 10`` in every regime, including nearly symmetric
    bodies and ``1 - k^2`` down to 1e-15 and the separatrix itself; for long
    times the error grows like the conditioning ``~ |Omega| t eps`` (about
    1e3 ulp at ``|Omega| t = 1e4``).  ``M`` returns to ``M0`` after one
    period ``4K/lambda`` within a few ulp (a few tens of ulp at
    ``1 - k^2 ~ 1e-12``).  Invariants hold to round-off at all times:
    ``E`` and ``|M|`` to a few ulp, ``R(t) M(t) = M0`` to ~1e-15 relative.
    ``t == 0`` returns ``M0`` and the identity exactly.  Orbits with
    ``1 - k^2 < 1e-200`` (only reachable with extreme magnitude ratios in
    ``M0``) are evaluated as the separatrix.

    Cost (one x86-64 core, CPU time): with numba (the default when it is
    installed) the compiled lane kernel of
    :mod:`eulerpoisson.solvers.exact.lanes` runs (sixteen evaluations in
    lockstep, SIMD; the results of the scalar kernels of
    :mod:`eulerpoisson.solvers.exact.kernels` bit for bit): about 0.15
    microseconds per (body, time) including the attitude, and 0.6
    microseconds for a body evaluated at a single time (set-up included;
    benchmarks/bench_exact.py); memory O(1) per body (``chunk_size`` is then
    irrelevant).  The first call in a fresh environment compiles the kernels
    (about 20 s, cached on disk: ``eulerpoisson warmup``); the first call in
    a process imports numba and loads them from the cache (about 0.5 s).
    Without numba, or with the environment
    variable ``EULERPOISSON_NO_NUMBA=1``, the vectorized NumPy path runs (the
    reference; about 1 microsecond per (body, time) plus ~4 microseconds per
    body, and ~2 ms of overhead per call).  Both paths perform the same
    floating-point operations in the same order: they agree bitwise when NumPy
    uses the C library's elementary functions, and to a few ulp of the
    intermediate quantities otherwise (NumPy's SIMD ``exp``, ``tanh``,
    ``atan``, ... differ by 1-3 ulp).

    Examples
    --------
    >>> M, q = exact_motion([3.0, 5.0, 9.0], [0.0, 2.0, 0.01], np.linspace(0, 100, 5))
    >>> M.shape, q.shape
    ((5, 3), (5, 4))
    """
    t = _validate_t(t)
    chunk_size = int(chunk_size)
    if chunk_size < 1:
        raise InvalidInputError(f"chunk_size must be a positive integer, got {chunk_size}")
    if isinstance(compiled, str) and compiled != "python":
        raise InvalidInputError(f"compiled must be True, False, None or 'python', got {compiled!r}")
    _check_range(inertia, M0, t)
    if isinstance(compiled, str):
        return _exact_motion_compiled(inertia, M0, t, python=True)
    if _jit.USE_NUMBA and compiled is not False:
        return _exact_motion_compiled(inertia, M0, t)
    return _exact_motion_numpy(inertia, M0, t, chunk_size)


def _check_range(inertia, M0, t) -> None:
    r"""Refuse what float64 cannot evaluate: :math:`\Omega_0 = M_0/I` overflowing, or
    :math:`|\boldsymbol\Omega_0||t| > 2^{48}` (:func:`~eulerpoisson.util.validate.check_phase`, as
    ``solve(..., method="exact")`` refuses).

    Raises
    ------
    InvalidInertiaError, InvalidInputError
        As :func:`exact_motion`'s checks; the range, naming the body.
    """
    I2, M2, batch = _validate(inertia, M0)
    with np.errstate(over="ignore"):
        w = (M2 / I2).reshape(batch + (3,))
    check_phase(t, w, who="exact_motion", what="|Omega0| |t|", rate="Omega0 = M0 / I")


def _kernels():
    """The kernels module (imported on first use: the NumPy path never needs it)."""
    global _KERNELS
    if _KERNELS is None:
        from . import kernels

        _KERNELS = kernels
    return _KERNELS


_KERNELS: ModuleType | None = None


def exact_motion_unchecked(inertia, M0, t, *, compiled):
    """:func:`exact_motion` for inputs checked already (by ``solve``): no conversion, no validation.

    ``inertia`` and ``M0`` float64 arrays of one shape ``(..., 3)`` (moments > 0, everything finite),
    ``t`` a finite float64 array of shape (T,); ``compiled`` as for :func:`exact_motion`. The same
    numbers as :func:`exact_motion` (the same kernels), without its checks (some microseconds per call,
    most of a small call).

    Examples
    --------
    >>> import numpy as np
    >>> I, M0, t = np.array([3.0, 5.0, 9.0]), np.array([0.0, 2.0, 0.01]), np.array([0.0, 1.0])
    >>> a, b = exact_motion_unchecked(I, M0, t, compiled=False), exact_motion(I, M0, t, compiled=False)
    >>> bool(np.array_equal(a.q, b.q) and np.array_equal(a.M, b.M))
    True
    """
    if isinstance(compiled, str) or (compiled is not False and _jit.USE_NUMBA):
        batch = inertia.shape[:-1]
        I2, M2 = _jit.kernel_array(inertia.reshape(-1, 3)), _jit.kernel_array(M0.reshape(-1, 3))
        return _run_kernel(I2, M2, _jit.kernel_array(t), batch, python=isinstance(compiled, str))
    return _exact_motion_numpy(inertia, M0, t)


def one_body_motion(inertia, M0, t, *, compiled):
    """:func:`exact_motion_unchecked` for one body: ``inertia`` and ``M0`` float64 arrays of shape (3,), ``t`` a
    C-contiguous float64 array (T,) made by the caller; the same numbers, with less around the kernel (the
    quick lane of ``solve``).

    Examples
    --------
    >>> import numpy as np
    >>> I, M0, t = np.array([3.0, 5.0, 9.0]), np.array([0.0, 2.0, 0.01]), np.array([0.0, 1.0])
    >>> a, b = one_body_motion(I, M0, t, compiled="python"), exact_motion_unchecked(I, M0, t, compiled="python")
    >>> bool(np.array_equal(a.q, b.q) and np.array_equal(a.M, b.M))
    True
    """
    python = isinstance(compiled, str)
    if not (python or (compiled is not False and _jit.USE_NUMBA)):
        return _exact_motion_numpy(inertia, M0, t)
    T = t.shape[0]
    Mout = np.empty((1, T, 3))
    qout = np.empty((1, T, 4))
    if T:
        _K = _KERNELS if _KERNELS is not None else _kernels()
        I2 = _jit.kernel_array(inertia).reshape(1, 3)
        M2 = _jit.kernel_array(M0).reshape(1, 3)
        if python:
            with _jit.python_twins():
                _K.motion_kernel_scalar(I2, M2, t, Mout, qout)
        else:
            _K.motion_kernel(I2, M2, t, Mout, qout)
    return ExactMotion(Mout[0], qout[0])


def _exact_motion_compiled(inertia, M0, t, python=False):
    """Compiled path of :func:`exact_motion` (``t`` already validated); ``python``: the scalar kernel as plain
    Python (the same numbers: the lane kernel and the scalar one agree bit for bit, and so do their twins)."""
    inertia, M0, batch = _validate(inertia, M0)
    return _run_kernel(_jit.kernel_array(inertia), _jit.kernel_array(M0), _jit.kernel_array(t), batch, python)


def _run_kernel(inertia, M0, t, batch, python):
    """The compiled kernel (or its plain-Python twin) on kernel arrays ``(nb, 3)``, ``(nb, 3)``, ``(T,)``."""
    _K = _kernels()
    nb = inertia.shape[0]
    T = t.shape[0]
    Mout = np.empty((nb, T, 3))
    qout = np.empty((nb, T, 4))
    if nb and T:
        if python:
            with _jit.python_twins():
                _K.motion_kernel_scalar(inertia, M0, t, Mout, qout)
        else:
            _K.motion_kernel(inertia, M0, t, Mout, qout)
    return ExactMotion(Mout.reshape(batch + (T, 3)), qout.reshape(batch + (T, 4)))


def _exact_motion_numpy(inertia, M0, t, chunk_size=_DEFAULT_CHUNK):
    """Vectorized NumPy path of :func:`exact_motion` (the reference; ``t`` validated)."""
    inertia, M0, batch, perm, sgn, eM, escale, eq, B = _prepare(inertia, M0)
    nb = inertia.shape[0]
    T = t.shape[0]
    Mout = np.empty((nb, T, 3))
    qout = np.empty((nb, T, 4))

    # relative equilibria: M constant, uniform rotation about Omega = M0 / I
    if np.any(eq):
        ei = np.nonzero(eq)[0]
        om = M0[ei] / inertia[ei]
        w = np.sqrt(np.sum(om * om, axis=-1))
        axis = om / np.where(w > 0.0, w, 1.0)[:, None]
        half = 0.5 * w[:, None] * t[None, :]
        Mout[ei] = M0[ei][:, None, :]
        qout[ei, :, 0] = np.cos(half)
        qout[ei, :, 1:] = np.sin(half)[:, :, None] * axis[:, None, :]

    gidx = np.nonzero(~eq)[0]
    if gidx.size and T:
        nbb = max(1, chunk_size // T)
        tb = min(T, chunk_size)
        for b0 in range(0, gidx.size, nbb):
            sel = np.arange(b0, min(b0 + nbb, gidx.size))
            Bb = _take_body(B, sel)
            bodies = gidx[sel]
            es = escale[bodies][:, None]
            for j0 in range(0, T, tb):
                tt = t[j0 : j0 + tb]
                ts = np.ldexp(tt[None, :], es)
                (M1, M2, M3), q = _generic_block(Bb, ts)
                Ms = np.stack(np.broadcast_arrays(M1, M2, M3), axis=-1)
                # back to the input frame and scale: x[perm[k]] = sgn[k] x_sorted[k]
                Ms = np.ldexp(Ms, eM[bodies][:, None, None])
                qs = np.stack(np.broadcast_arrays(*q), axis=-1)
                qs = qs / np.sqrt(np.sum(qs * qs, axis=-1, keepdims=True))
                # the initial condition is reproduced exactly
                at0 = tt == 0.0
                if np.any(at0):
                    Ms[:, at0, :] = _to_sorted(M0[bodies], perm[bodies], sgn[bodies])[:, None, :]
                    qs[:, at0, :] = (1.0, 0.0, 0.0, 0.0)
                pb = perm[bodies][:, None, :]
                sb = sgn[bodies][:, None, :]
                Mo = np.empty_like(Ms)
                np.put_along_axis(Mo, pb, sb * Ms, axis=-1)
                vo = np.empty_like(qs[..., 1:])
                np.put_along_axis(vo, pb, sb * qs[..., 1:], axis=-1)
                Mout[bodies, j0 : j0 + tb] = Mo
                qout[bodies, j0 : j0 + tb, 0] = qs[..., 0]
                qout[bodies, j0 : j0 + tb, 1:] = vo
    return ExactMotion(Mout.reshape(batch + (T, 3)), qout.reshape(batch + (T, 4)))


def exact_constants(inertia, M0):
    r"""Per-body constants of the closed-form solution.

    Parameters
    ----------
    inertia : array_like, shape (..., 3)
        Principal moments (any order, > 0).
    M0 : array_like, shape (..., 3)
        Initial body angular momentum in the principal frame.

    Returns
    -------
    ExactConstants
        Regime code, ``m = k^2``, ``m1 = 1 - k^2`` (computed without
        cancellation), ``K(m)``, the rate ``lambda`` of the elliptic argument
        (physical time units), ``tau0`` and the period ``4K/lambda`` of
        ``M(t)``; arrays of the broadcast batch shape.  The sign changes of
        the middle-axis component happen every ``2K/lambda``.

    Raises
    ------
    InvalidInertiaError, InvalidInputError
        As :func:`exact_motion`.
    """
    from . import kernels as _K

    if _K.USE_NUMBA:
        return _exact_constants_compiled(inertia, M0)
    return _exact_constants_numpy(inertia, M0)


def _exact_constants_compiled(inertia, M0):
    """Compiled path of :func:`exact_constants`."""
    from . import kernels as _K

    inertia, M0, batch = _validate(inertia, M0)
    inertia, M0 = _jit.kernel_array(inertia), _jit.kernel_array(M0)
    out = np.empty((inertia.shape[0], 7))
    if inertia.shape[0]:
        _K.constants_kernel(inertia, M0, out)
    shp = lambda x: x.reshape(batch)  # noqa: E731
    regime = out[:, 0].astype(np.int64)
    return ExactConstants(shp(regime), *(shp(out[:, k].copy()) for k in range(1, 7)))


def _exact_constants_numpy(inertia, M0):
    """Vectorized NumPy path of :func:`exact_constants` (the reference)."""
    inertia, M0, batch, perm, sgn, eM, escale, eq, B = _prepare(inertia, M0)
    nb = inertia.shape[0]
    regime = np.full(nb, EQUILIBRIUM, dtype=np.int64)
    m = np.zeros(nb)
    m1 = np.ones(nb)
    K = np.full(nb, 0.5 * np.pi)
    lam = np.zeros(nb)
    tau0 = np.zeros(nb)
    g = np.nonzero(~eq)[0]
    regime[g] = B.regime
    m[g] = B.m
    m1[g] = B.m1
    K[g] = np.where(B.sep, np.inf, B.P.kh)
    lam[g] = np.ldexp(B.lam, escale[g])
    tau0[g] = B.t0h + B.t0l
    with np.errstate(divide="ignore"):
        period = np.where(lam > 0.0, 4.0 * K / np.where(lam > 0.0, lam, 1.0), np.inf)
    shp = lambda x: x.reshape(batch)  # noqa: E731
    return ExactConstants(shp(regime), shp(m), shp(m1), shp(K), shp(lam), shp(tau0), shp(period))
