r"""Quantities of the motion in closed form: elliptic modulus, periods, flips; stability of tops and satellites.

Free body: the elliptic parameters, periods and the tennis-racket flips; the
two fundamental periods of a tumbling body (:func:`tumbling_periods`) and the
spin states consistent with two observed periods (:func:`spin_states_from_periods`).
Under torque: the sleeping top's stability threshold and its small-oscillation
frequencies (:func:`sleeping_top`), and the small oscillations of a satellite
about its gravity-gradient equilibrium (:func:`gravity_gradient_frequencies`).

For principal moments :math:`I_1<I_2<I_3`, body angular momentum
:math:`\mathbf M`, :math:`L^2 = |\mathbf M|^2` and :math:`2E = \mathbf M\cdot I^{-1}\mathbf M`,
the body momentum moves on the polhode with the Jacobi parameter and rate

.. math::
    k^2 = \frac{(I_3-I_2)(L^2-2EI_1)}{(I_2-I_1)(2EI_3-L^2)},\quad
    \lambda = \sqrt{\frac{(I_2-I_1)(2EI_3-L^2)}{I_1I_2I_3}}
    \qquad (L^2 < 2EI_2),

and the same with :math:`1\leftrightarrow3` when :math:`L^2 > 2EI_2`
(Landau-Lifshitz §37). The period of :math:`\mathbf M(t)` is
:math:`4K(k)/\lambda`; the component that changes sign (the tennis-racket
flips) does so every :math:`2K(k)/\lambda`. Differences such as
:math:`2EI_2 - L^2 = \sum_i M_i^2(I_2/I_i - 1)` and
:math:`1-k^2 = (I_3-I_1)(2EI_2-L^2)/((I_2-I_1)(2EI_3-L^2))` are formed
without cancellation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import InvalidInputError
from .model.body import check_moments
from .util.validate import as_bool, as_float_array, as_scalar, check_broadcast

if TYPE_CHECKING:
    from .trajectory import Trajectory

__all__ = [
    "elliptic_parameters",
    "momentum_period",
    "tennis_racket_half_period",
    "flip_times",
    "tumbling_periods",
    "spin_states_from_periods",
    "sleeping_top",
    "gravity_gradient_frequencies",
]


def elliptic_parameters(inertia: ArrayLike, M0: ArrayLike) -> dict:
    r"""Jacobi parameter :math:`k^2`, its complement :math:`1-k^2` and the rate :math:`\lambda`.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments, distinct, positive and normal floats (checked as
        :class:`~eulerpoisson.RigidBody` checks them; the triangle inequality
        is not required, so the often-quoted (3, 5, 9) is accepted).
    M0 : array_like, shape (3,)
        Body angular momentum in the principal frame, finite.

    Returns
    -------
    dict
        ``k2``, ``k2c`` (:math:`1-k^2`, accurate near the separatrix),
        ``lam``, ``axis`` (index, in the given order, of the principal axis
        the momentum circulates about: the smallest or the largest moment),
        ``order`` (the permutation sorting the moments).

    Raises
    ------
    InvalidInertiaError
        A moment that is not > 0, or below the smallest normal float64.
    InvalidInputError
        Wrong shapes, NaN or infinite values; two equal moments (a
        symmetric body has no elliptic modulus: the motion is a uniform
        precession); a momentum exactly on the separatrix or zero; or a
        rate :math:`\lambda` (or moments spanning a range) beyond float64.

    Notes
    -----
    :math:`k^2` is homogeneous of degree 0 in :math:`\mathbf M` and in
    :math:`I`, and :math:`\lambda` scales as :math:`|\mathbf M|/I`. Both are
    computed with the moments and the momentum scaled by powers of two (to
    about 1, exactly: ordinary inputs give the same bits as without scaling)
    and :math:`\lambda` is scaled back, so momenta such as :math:`10^{200}`
    or :math:`10^{-200}` neither overflow nor underflow.
    """
    I = as_float_array(inertia, "inertia", (3,))
    M = as_float_array(M0, "M0", (3,))
    if I.ndim != 1 or M.ndim != 1:
        raise InvalidInputError(
            f"elliptic_parameters takes one body: inertia and M0 of shape (3,), got shapes {I.shape} and {M.shape}"
        )
    check_moments(I, "inertia", triangle=False)
    order = np.argsort(I)
    if not (I[order[0]] < I[order[1]] < I[order[2]]):
        raise InvalidInputError(f"elliptic_parameters needs three distinct principal moments, got {I.tolist()}")
    if not np.any(M != 0):
        raise InvalidInputError("M0 is zero: the body is at rest")
    # exact power-of-two scaling: I -> I 2**-eI, M -> M 2**-eM (lam is scaled back below)
    eI = int(np.frexp(np.max(I))[1])
    eM = int(np.frexp(np.max(np.abs(M)))[1])
    with np.errstate(under="ignore"):
        I1, I2, I3 = np.ldexp(I[order], -eI)
        M = np.ldexp(M[order], -eM)
    I_ = np.array([I1, I2, I3])
    with np.errstate(over="ignore", divide="ignore", invalid="ignore", under="ignore"):
        d2 = float(np.sum(M**2 * (I2 / I_ - 1.0)))  # 2 E I2 - L^2
        d1 = float(np.sum(M**2 * (1.0 - I1 / I_)))  # L^2 - 2 E I1 >= 0
        d3 = float(np.sum(M**2 * (I3 / I_ - 1.0)))  # 2 E I3 - L^2 >= 0
        if d2 == 0:
            raise InvalidInputError("M0 lies on the separatrix (L^2 = 2 E I2): the period is infinite")
        if d2 > 0:  # circulation about the axis of smallest moment
            k2 = (I3 - I2) * d1 / ((I2 - I1) * d3)
            k2c = (I3 - I1) * d2 / ((I2 - I1) * d3)
            lam = np.sqrt((I2 - I1) * d3 / (I1 * I2 * I3))
            axis = int(order[0])
        else:
            k2 = (I2 - I1) * d3 / ((I3 - I2) * d1)
            k2c = (I3 - I1) * (-d2) / ((I3 - I2) * d1)
            lam = np.sqrt((I3 - I2) * d1 / (I1 * I2 * I3))
            axis = int(order[2])
        lam = np.ldexp(lam, eM - eI)  # lambda is homogeneous of degree 1 in M and -1 in I
    # a subnormal lambda has lost its relative precision: refused like an infinite one
    if not (np.isfinite(k2) and np.isfinite(k2c) and np.isfinite(lam) and lam >= np.finfo(float).tiny):
        raise InvalidInputError(
            f"elliptic_parameters: k^2 = {k2!r}, 1 - k^2 = {k2c!r}, lambda = {float(lam)!r} are not representable "
            f"in float64 for inertia {I.tolist()} and M0 {np.asarray(M0, float).tolist()} (moments spanning too "
            "wide a range, or |M0|/I out of range); rescale the units"
        )
    return {"k2": k2, "k2c": k2c, "lam": float(lam), "axis": axis, "order": order}


def momentum_period(inertia: ArrayLike, M0: ArrayLike) -> float:
    r"""Period :math:`4K(k)/\lambda` of the body angular momentum :math:`\mathbf M(t)`.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments (see :func:`elliptic_parameters`).
    M0 : array_like, shape (3,)
        Body angular momentum in the principal frame.

    Returns
    -------
    float

    Raises
    ------
    InvalidInertiaError, InvalidInputError
        See :func:`elliptic_parameters`; also a period that overflows float64.
    """
    from scipy.special import ellipkm1

    p = elliptic_parameters(inertia, M0)
    with np.errstate(over="ignore"):
        T = float(4.0 * ellipkm1(p["k2c"]) / p["lam"])
    if not np.isfinite(T):
        raise InvalidInputError(
            f"the period 4 K(k)/lambda overflows float64 (lambda = {p['lam']!r}, 1 - k^2 = {p['k2c']!r}); "
            "rescale the units"
        )
    return T


def tennis_racket_half_period(inertia: ArrayLike, M0: ArrayLike) -> float:
    r"""Time :math:`2K(k)/\lambda` between consecutive flips (sign changes) of the momentum components that change sign."""
    return 0.5 * momentum_period(inertia, M0)


def flip_times(traj: Trajectory, component: int = 1, *, refine: bool = True) -> NDArray[np.float64]:
    r"""Times at which :math:`\Omega_\mathrm{component}(t)` changes sign.

    Sign changes between samples are located by linear interpolation and,
    for a single body with ``refine=True``, polished by a few secant steps on
    the closed-form solution (so they are accurate to round-off, not to the
    sampling step).

    Exact zeros: a flip is a change of sign between consecutive *nonzero*
    samples. When exactly-zero samples lie between two samples of opposite
    sign, that is one flip, placed at the zero sample (at the middle of a
    run of several zeros) before refinement. Zeros before the first or
    after the last nonzero sample, and zeros between samples of the same
    sign (a touch), are not flips.

    Parameters
    ----------
    traj : Trajectory
        A single-body trajectory with increasing times.
    component : int
        Index 0, 1 or 2 of the body-frame component (an ``int`` or numpy
        integer; not a bool or a float).
    refine : bool
        Polish with the exact solution.

    Returns
    -------
    ndarray, shape (F,)

    Raises
    ------
    TypeError
        ``traj`` not a :class:`~eulerpoisson.Trajectory`, ``component`` not an
        integer, ``refine`` not a bool.
    InvalidInputError
        A batch trajectory, or ``component`` not 0, 1 or 2.
    """
    from .trajectory import Trajectory

    if not isinstance(traj, Trajectory):
        raise TypeError(f"flip_times takes a Trajectory (the result of solve), got {type(traj).__name__} {traj!r}")
    if isinstance(component, (bool, np.bool_)) or not isinstance(component, (int, np.integer)):
        raise TypeError(f"component must be an integer 0, 1 or 2, got {type(component).__name__} {component!r}")
    refine = as_bool(refine, "refine")
    if traj.batch_shape:
        raise InvalidInputError(f"flip_times takes a single-body trajectory, got batch shape {traj.batch_shape}")
    if component not in (0, 1, 2):
        raise InvalidInputError(f"component must be 0, 1 or 2, got {component!r}")
    component = int(component)
    order = np.argsort(traj.t)
    t = traj.t[order]
    w = traj.omega[order, component]
    # consecutive nonzero samples of opposite sign (exact zeros in between are skipped)
    nz = np.nonzero(w != 0)[0]
    i, j = nz[:-1], nz[1:]
    keep = np.sign(w[i]) != np.sign(w[j])
    i, j = i[keep], j[keep]
    t0, t1, w0, w1 = t[i], t[j], w[i], w[j]
    adjacent = j == i + 1
    roots = np.where(
        adjacent,
        t0 - w0 * (t1 - t0) / np.where(adjacent, w1 - w0, 1.0),
        0.5 * (t[np.minimum(i + 1, t.size - 1)] + t[np.maximum(j - 1, 0)]),  # the zero sample(s)
    )
    if not refine or roots.size == 0:
        return roots
    from .solvers import solve

    q0 = traj.quaternion[order[0]]
    om0 = traj.omega[order[0]]
    tstart = t[0]

    def f(tt):
        tr = solve(traj.body, tt - tstart, omega0=om0, attitude0=q0, method="exact")
        return tr.omega[:, component]

    a, b = t0.copy(), t1.copy()
    fa, fb = w0.copy(), w1.copy()
    x = roots.copy()
    for _ in range(60):  # Illinois-type false position, bracketing kept
        fx = f(x)
        left = np.sign(fx) == np.sign(fa)
        a = np.where(left, x, a)
        fa = np.where(left, fx, fa * 0.5)
        b = np.where(left, b, x)
        fb = np.where(left, fb * 0.5, fx)
        xn = a - fa * (b - a) / (fb - fa)
        done = np.all(np.abs(xn - x) <= 4 * np.finfo(float).eps * np.abs(xn))
        x = xn
        if done:
            break
    return x


# --- tumbling (non-principal-axis) rotation: the two fundamental periods and their inverse ---------------------------

_MODES = ("LAM", "SAM")


def _precession_factor(N, c, kc, sam):
    r"""Mean precession rate of the circulation axis in units of :math:`L/I_3`, and :math:`K(k)`.

    ``N`` is minus the characteristic of :math:`\Pi`, ``c`` is :math:`(I_3-I_1)/I_1` and ``kc``
    is :math:`1-k^2`; vectorized. With :math:`Q = 1-\Pi(-N,k)/K(k) = (N/3)R_J(0,k'^2,1,1+N)/R_F(0,k'^2,1)`
    (formed without cancellation), the factor is :math:`1 + c(1-Q)` for SAM and :math:`1 + cQ` for LAM;
    the subtraction :math:`1-Q` costs the SAM rate at most about :math:`\epsilon I_2/I_1` (relative).
    """
    from scipy.special import elliprf, elliprj

    K = elliprf(0.0, kc, 1.0)
    Q = (N / 3.0) * elliprj(0.0, kc, 1.0, 1.0 + N) / K
    return 1.0 + c * np.where(sam, 1.0 - Q, Q), K


def _tumbling_one(I, V, name, is_omega):
    from scipy.special import ellipkm1

    I = np.asarray(I, float)
    check_moments(I, "inertia", triangle=False)
    order = np.argsort(I, kind="stable")
    if not (I[order[0]] < I[order[1]] < I[order[2]]):
        raise InvalidInputError(
            f"inertia must be three distinct principal moments (a body with two equal moments precesses "
            f"uniformly and has no tumbling periods), got {I.tolist()}"
        )
    with np.errstate(over="ignore"):
        M = I * V if is_omega else np.asarray(V, float)
    if not np.all(np.isfinite(M)):
        raise InvalidInputError(
            f"the angular momentum I*omega0 overflows float64 for inertia {I.tolist()} and omega0 {V.tolist()}; "
            "rescale the units"
        )
    if not np.any(M != 0):
        raise InvalidInputError(f"{name} must be a nonzero vector (the body is at rest: no periods), got {V.tolist()}")
    # exact power-of-two scaling as in elliptic_parameters (so that the separatrix test agrees with it bit for bit)
    eI = int(np.frexp(np.max(I))[1])
    eM = int(np.frexp(np.max(np.abs(M)))[1])
    with np.errstate(under="ignore"):
        Is = np.ldexp(I[order], -eI)
        Ms = np.ldexp(M[order], -eM)
    I1, I2, I3 = Is
    with np.errstate(over="ignore", divide="ignore", invalid="ignore", under="ignore"):
        d2 = float(np.sum(Ms**2 * (I2 / Is - 1.0)))  # 2 E I2 - L^2
        d3 = float(np.sum(Ms**2 * (I3 / Is - 1.0)))  # 2 E I3 - L^2 >= 0
        L2s = float(np.sum(Ms**2))
    if d2 == 0:
        raise InvalidInputError(
            f"{name} lies exactly on the separatrix L^2 = 2 E I2 (the motion tends to the intermediate axis): "
            f"the periods are infinite and the mode is neither LAM nor SAM; got {name} = {V.tolist()}"
        )
    p = elliptic_parameters(I, M)  # k^2, 1 - k^2, lambda (and its own range checks)
    sam = d2 < 0
    with np.errstate(over="ignore", divide="ignore", invalid="ignore", under="ignore"):
        if sam:  # circulation about the axis of largest moment
            N = I3 * (I2 - I1) / (I1 * (I3 - I2))
        else:  # about the axis of smallest moment
            N = I1 * (I3 - I2) / (I3 * (I2 - I1))
        c = (I3 - I1) / I1
        factor, _ = _precession_factor(N, c, p["k2c"], sam)
        L_over_I3 = float(np.ldexp(np.sqrt(L2s) / I3, eM - eI))
        nu_phi = L_over_I3 * float(factor)
        P_omega = float(4.0 * ellipkm1(p["k2c"]) / p["lam"])
        P_phi = 2.0 * np.pi / nu_phi
        nu_psi = 2.0 * np.pi / P_omega
        # the two axes normal to the circulation axis turn about m at nu_phi + nu_psi (LAM), nu_phi - nu_psi (SAM)
        P_perp = 2.0 * np.pi / (nu_phi - nu_psi if sam else nu_phi + nu_psi)
        energy = float(np.ldexp(0.5 * np.sum(Ms**2 / Is), 2 * eM - eI))
        L2 = float(np.ldexp(L2s, 2 * eM))
        E_over_E0 = 1.0 + d3 / L2s
    if not all(np.isfinite(x) and x > 0 for x in (P_omega, P_phi, P_perp, nu_phi)):
        raise InvalidInputError(
            f"tumbling_periods: the periods P_omega = {P_omega!r}, P_phi = {P_phi!r} are not representable in "
            f"float64 for inertia {I.tolist()} and {name} {V.tolist()} (|M|/I out of range); rescale the units"
        )
    axis = int(order[2] if sam else order[0])
    P_axes = np.full(3, P_perp)
    P_axes[axis] = P_phi
    return {
        "mode": "SAM" if sam else "LAM",
        "P_omega": P_omega,
        "P_psi": P_omega,
        "P_phi": P_phi,
        "P_theta": 0.5 * P_omega,
        "P_long": float(P_axes[order[0]]),
        "P_axes": P_axes,
        "k2": float(p["k2"]),
        "k2c": float(p["k2c"]),
        "lam": p["lam"],
        "axis": axis,
        "energy": energy,
        "L2": L2,
        "E_over_E0": float(E_over_E0),
        "L_over_I3": L_over_I3,
        "I1_I3": float(I1 / I3),
        "I2_I3": float(I2 / I3),
    }


def tumbling_periods(inertia: ArrayLike, M0: ArrayLike | None = None, *, omega0: ArrayLike | None = None) -> dict:
    r"""The two fundamental periods of a tumbling (torque-free, non-principal-axis) body.

    With :math:`I_1<I_2<I_3` the principal moments sorted, :math:`L^2=|\mathbf M|^2`
    and :math:`2E=\mathbf M\cdot I^{-1}\mathbf M`, the body is in a *long-axis
    mode* (LAM) when :math:`L^2<2EI_2`: the momentum circulates in the body
    about the axis of least moment (the long axis of an ellipsoid), and in a
    *short-axis mode* (SAM) when :math:`L^2>2EI_2`: about the axis of largest
    moment (the short axis). Call that axis the *circulation axis* :math:`c`
    and put the Euler angles :math:`(\phi,\theta,\psi)` (z-x-z) with the
    spatial momentum :math:`\mathbf m` as polar axis and :math:`c` as body z-axis
    (Landau & Lifshitz §37; Samarasinha & A'Hearn 1991; Kaasalainen 2001).
    Then :math:`\cos\theta = M_c/L` and :math:`\psi` (the azimuth of
    :math:`\mathbf M` about :math:`c` in the body) are periodic with the period
    of the polhode, and the precession :math:`\phi` is a uniform rotation plus a
    periodic term:

    .. math::
        P_\psi = P_\omega = \frac{4K(k)}{\lambda},\qquad P_\theta = \frac{P_\psi}{2},\qquad
        \frac{2\pi}{P_\phi} = \langle\dot\phi\rangle
        = \frac{L}{I_3} + \frac{L(I_3-I_1)}{I_1I_3}
          \begin{cases}\Pi(-N,k)/K(k), & N = \dfrac{I_3(I_2-I_1)}{I_1(I_3-I_2)}\ \text{(SAM)}\\[2ex]
          1-\Pi(-N,k)/K(k), & N = \dfrac{I_1(I_3-I_2)}{I_3(I_2-I_1)}\ \text{(LAM)}\end{cases}

    from :math:`\dot\phi = L(2E - M_c^2/I_c)/(L^2 - M_c^2)` averaged over the
    polhode (:math:`M_c^2 \propto \mathrm{dn}^2`), with :math:`k,\lambda` of
    :func:`elliptic_parameters` and :math:`\Pi(n,k)=\int_0^{\pi/2}
    d\vartheta/((1-n\sin^2\vartheta)\sqrt{1-k^2\sin^2\vartheta})`, evaluated as
    :math:`1-\Pi(-N,k)/K = (N/3)R_J(0,k'^2,1,1+N)/R_F(0,k'^2,1)` (Carlson). This
    is the period :math:`T'` of Landau & Lifshitz, whose :math:`\phi` is a
    periodic function plus :math:`2\pi t/T'`. The limits: :math:`2\pi/P_\phi \to
    L/I_2` at the separatrix; at the relaxed rotation (:math:`k\to0`),
    :math:`2\pi/P_\phi - 2\pi/P_\psi \to L/I_3` (SAM) and
    :math:`2\pi/P_\phi + 2\pi/P_\psi \to L/I_1` (LAM).

    **What** :math:`P_\psi` **and** :math:`P_\phi` **mean.** :math:`\psi` makes full
    turns in both modes (with right-handed body axes :math:`\langle\dot\psi\rangle`
    is :math:`+2\pi/P_\psi` in LAM and :math:`-2\pi/P_\psi` in SAM), so
    :math:`P_\psi` is a rotation period, equal to :math:`P_\omega`, in both:
    about the long axis in LAM, about the short axis in SAM (it stays
    :math:`P_\omega` for the convention that keeps the short axis as body z in LAM,
    where :math:`\psi` librates instead). :math:`P_\phi` is the mean precession
    period of the circulation axis about :math:`\mathbf m`: the long axis in LAM, the
    short axis in SAM. These are the :math:`P_\psi, P_\phi` of Kaasalainen (2001)
    and Pravec et al. (2005) (LAM: (4179) Toutatis, :math:`P_\psi` = 5.4 d
    rotation about the long axis, :math:`P_\phi` = 7.35 d precession of it;
    SAM: (99942) Apophis, :math:`P_\phi` = 27.38 h, :math:`P_\psi` = 263 h). The
    two principal axes normal to :math:`c` turn about :math:`\mathbf m` at the
    mean rate

    .. math:: \frac{2\pi}{P_\perp} = \frac{2\pi}{P_\phi} + \frac{2\pi}{P_\psi}\ \text{(LAM)},\qquad
              \frac{2\pi}{P_\perp} = \frac{2\pi}{P_\phi} - \frac{2\pi}{P_\psi}\ \text{(SAM)},

    so the mean precession period of the **long** axis (``P_long``) is
    :math:`P_\phi` in LAM but :math:`(1/P_\phi - 1/P_\psi)^{-1}` in SAM (30.56 h
    for Apophis, its strongest lightcurve period).

    Parameters
    ----------
    inertia : array_like, shape (..., 3)
        Principal moments, in any order, distinct, positive and normal floats
        (the triangle inequality is not required).
    M0 : array_like, shape (..., 3), optional
        Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega` in the
        principal frame (components in the order of ``inertia``), finite.
    omega0 : array_like, shape (..., 3), keyword-only, optional
        Body angular velocity :math:`\boldsymbol\Omega` instead of ``M0``.
        Exactly one of ``M0`` and ``omega0``. The batch shapes of ``inertia``
        and the vector broadcast; each body is computed in turn.

    Returns
    -------
    dict
        Floats for one body, arrays of the batch shape for a batch:
        ``mode`` (``"LAM"`` or ``"SAM"``), ``P_omega`` (period of
        :math:`\boldsymbol\Omega(t)` and :math:`\mathbf M(t)`), ``P_psi``
        (:math:`=P_\omega`), ``P_phi`` (mean precession period of the
        circulation axis), ``P_theta`` (:math:`P_\omega/2`, nutation), ``P_long``
        (mean precession period of the axis of least moment about :math:`\mathbf m`),
        ``P_axes`` (shape (..., 3): mean precession period of each principal
        axis about :math:`\mathbf m`, in the order of ``inertia``), ``k2``,
        ``k2c`` (:math:`1-k^2`), ``lam``, ``axis`` (index of the circulation
        axis in the order of ``inertia``), ``energy`` (:math:`E`), ``L2``
        (:math:`L^2`; these two overflow to inf, or underflow to 0, for momenta
        beyond about :math:`10^{\pm154}`; the periods are computed scaled), ``E_over_E0``
        (:math:`2EI_3/L^2 = E/E_0`, :math:`E_0 = L^2/2I_3` the energy of the
        relaxed spin with the same momentum: 1 for the relaxed spin,
        :math:`I_3/I_2` at the separatrix, :math:`I_3/I_1` for a pure long-axis
        spin; SAM below :math:`I_3/I_2`, LAM above), ``L_over_I3``
        (:math:`L/I_3`, the relaxed spin rate), ``I1_I3``, ``I2_I3`` (the sorted
        moments over the largest: with ``P_psi``, ``P_phi``, ``mode`` they are the
        arguments of :func:`spin_states_from_periods`).

    Raises
    ------
    TypeError
        Neither or both of ``M0`` and ``omega0``; non-numeric input.
    InvalidInertiaError
        A moment that is not > 0, or below the smallest normal float64.
    InvalidInputError
        Wrong shapes (not (..., 3)) or batch shapes that do not broadcast;
        NaN or infinite values; two equal moments (a symmetric body precesses
        uniformly: no tumbling periods); a zero vector (a body at rest); a
        momentum exactly on the separatrix :math:`L^2 = 2EI_2` (infinite
        periods); periods beyond float64.

    See Also
    --------
    spin_states_from_periods : the inverse: the states consistent with two periods.
    momentum_period : :math:`P_\omega` alone.

    Notes
    -----
    The rates are accurate to a few units of round-off (the separatrix
    included, through :math:`1-k^2` formed without cancellation as in
    :func:`elliptic_parameters`), except :math:`P_\phi` of a SAM with
    :math:`I_1 \ll I_2`, which can lose about :math:`\epsilon I_2/I_1`
    (relative). Moments and momenta are scaled by powers of two, so that
    extreme units neither overflow nor underflow.

    References
    ----------
    L. D. Landau and E. M. Lifshitz, *Mechanics*, 3rd ed. (1976), §37.
    N. H. Samarasinha and M. F. A'Hearn, "Observational and dynamical constraints
    on the rotation of comet P/Halley", Icarus 93, 194 (1991).
    M. Kaasalainen, "Interpretation of lightcurves of precessing asteroids",
    A&A 376, 302 (2001).
    P. Pravec et al., "Tumbling asteroids", Icarus 173, 108 (2005); P. Pravec et al.,
    "The tumbling spin state of (99942) Apophis", Icarus 233, 48 (2014).
    B. C. Carlson, "Numerical computation of real or complex elliptic
    integrals", Numer. Algorithms 10, 13 (1995).

    Examples
    --------
    >>> from eulerpoisson.analysis import tumbling_periods
    >>> p = tumbling_periods([1.0, 2.0, 2.5], [0.2, 0.3, 1.0])
    >>> p["mode"], round(p["P_psi"], 6), round(p["P_phi"], 6), round(p["P_long"], 6)
    ('SAM', 26.600363, 9.271334, 14.231661)
    """
    if (M0 is None) == (omega0 is None):
        raise TypeError(
            "tumbling_periods takes exactly one of M0 (body angular momentum) and omega0 (body angular velocity)"
        )
    is_omega = omega0 is not None
    name = "omega0" if is_omega else "M0"
    I = as_float_array(inertia, "inertia", (3,))
    V = as_float_array(omega0 if is_omega else M0, name, (3,))
    batch = check_broadcast(inertia=I, **{name: V})
    if batch == ():
        return _tumbling_one(I, V, name, is_omega)
    Ib = np.broadcast_to(I, batch + (3,))
    Vb = np.broadcast_to(V, batch + (3,))
    rows = []
    for idx in np.ndindex(*batch):
        try:
            rows.append(_tumbling_one(Ib[idx], Vb[idx], name, is_omega))
        except InvalidInputError as exc:
            raise type(exc)(f"body {idx}: {exc}") from None
    return {key: np.array([r[key] for r in rows]).reshape(batch + np.shape(rows[0][key])) for key in rows[0]}


def _family_rates(a, b, y, sam):
    """Period ratio and rates (units L/I3) of the state with moments (a, b, 1) and k^2 = 1/(1 + e^y)."""
    from scipy.special import expit

    k2, kc = expit(-y), expit(y)  # k^2 and 1 - k^2, each to full relative precision
    if sam:
        den = (b - a) + a * k2 * (1.0 - b)
        lam = np.sqrt((1.0 - b) * (b - a) * (1.0 - a) / (den * a * b))
        N = (b - a) / (a * (1.0 - b))
    else:
        den = a * (1.0 - b) + k2 * (b - a)
        lam = np.sqrt((b - a) * (1.0 - b) * (1.0 - a) / (den * a * b))
        N = a * (1.0 - b) / (b - a)
    factor, K = _precession_factor(N, (1.0 - a) / a, kc, sam)
    nu_psi = 0.5 * np.pi * lam / K
    return nu_psi, factor, k2, den


def spin_states_from_periods(
    P_psi: ArrayLike, P_phi: ArrayLike, mode: str, *, I1_I3: ArrayLike, I2_I3: ArrayLike
) -> dict:
    r"""Spin states of a torque-free body with the periods :math:`P_\psi, P_\phi` in a given mode.

    The inverse of :func:`tumbling_periods`. A torque-free state is fixed, up
    to its orientation and the phase on the polhode, by four numbers: the
    inertia ratios :math:`a = I_1/I_3`, :math:`b = I_2/I_3`, the energy ratio
    :math:`E/E_0 = 2EI_3/L^2` and the rate :math:`L/I_3` (a common factor of
    :math:`I` and :math:`L` changes nothing). The periods scale as
    :math:`I_3/L`, so only their ratio :math:`P_\phi/P_\psi` constrains
    :math:`(a, b, E/E_0)`, and :math:`P_\psi` then fixes :math:`L/I_3`: **two
    periods and the mode determine a two-parameter family** (Kaasalainen 2001,
    §2: the periods alone do not give the inertia ratios). Here the family is
    parametrized by the inertia ratios: at each given :math:`(a, b)` the
    energy is the one root, found by :func:`scipy.optimize.brentq`, of

    .. math:: \frac{P_\phi}{P_\psi} = \frac{\langle\dot\phi\rangle}{2\pi/P_\psi}\Big|^{-1}
              = \frac{\pi\hat\lambda/(2K(k))}{\langle\dot\phi\rangle/(L/I_3)},

    in the variable :math:`y = \ln(k'^2/k^2)` (so that both :math:`k^2` and
    :math:`k'^2` keep full precision), and :math:`L/I_3 = 2\pi/(P_\psi\,\hat\nu_\psi)`.
    The ratio falls monotonically (checked numerically over the whole range of
    inertia ratios) from its value at the relaxed rotation (:math:`k\to0`),

    .. math:: R_0 = \frac{s}{1+s},\ s = \sqrt{\frac{(1-a)(1-b)}{ab}}\ \text{(SAM)},\qquad
              R_0 = \frac{s}{1-s},\ s = \sqrt{\frac{(1-a)(b-a)}{b}}\ \text{(LAM)},

    to 0 at the separatrix; a member exists iff :math:`P_\phi/P_\psi < R_0(a,b)`
    (in SAM always :math:`P_\phi < P_\psi`), and, once the ratio is below what
    :math:`k'^2 \ge 10^{-304}` reaches (about :math:`R_0/300`), the state is
    indistinguishable from the separatrix in float64 and is reported invalid.
    A one-parameter family is a curve through the inertia ratios, e.g. a fixed
    ``I2_I3`` and an array ``I1_I3``.

    The periods are those of :func:`tumbling_periods` (Kaasalainen's):
    ``P_psi`` the period of :math:`\psi` (= of :math:`\boldsymbol\Omega(t)`),
    ``P_phi`` the mean precession period of the circulation axis (the long axis
    in LAM, the short axis in SAM). A SAM lightcurve's dominant period belongs
    to the long axis, :math:`P_\mathrm{long} = (1/P_\phi - 1/P_\psi)^{-1}`: convert
    with :math:`1/P_\phi = 1/P_\mathrm{long} + 1/P_\psi`.

    Parameters
    ----------
    P_psi, P_phi : float
        The two periods, > 0, in any unit of time (``L_over_I3`` comes in
        radians per that unit).
    mode : {"LAM", "SAM"}
        Long-axis or short-axis mode (case-insensitive).
    I1_I3, I2_I3 : array_like, keyword-only
        The family members: smallest and intermediate moments over the largest,
        :math:`0 < a < b < 1`, broadcast together (their common shape is the
        shape of every output).

    Returns
    -------
    dict
        Arrays of the broadcast shape of ``I1_I3`` and ``I2_I3``:
        ``I1_I3``, ``I2_I3`` (broadcast copies), ``E_over_E0``
        (:math:`2EI_3/L^2`), ``k2``, ``k2c`` (:math:`1-k^2`, to full relative
        precision next to the separatrix), ``L_over_I3`` (:math:`L/I_3`), ``M0``
        (shape (..., 3): a body angular momentum of the member for the
        moments ``(I1_I3, I2_I3, 1)``, at the instant where :math:`M_2` is
        largest and :math:`M_1 = 0` (SAM) or :math:`M_3 = 0` (LAM), components
        :math:`\ge 0`, so that ``tumbling_periods((I1_I3, I2_I3, 1), M0)``
        gives back the periods; multiply by :math:`I_3` for other units), and
        ``valid`` (bool: the member exists; elsewhere the others are NaN).

    Raises
    ------
    TypeError
        ``mode`` not a string; non-numeric input.
    InvalidInputError
        A period that is not a finite number > 0; ``mode`` not ``"LAM"`` or
        ``"SAM"``; ``I1_I3`` and ``I2_I3`` not finite, not broadcastable, or
        not :math:`0 < I1\_I3 < I2\_I3 < 1`.

    See Also
    --------
    tumbling_periods : the periods of a given state.

    References
    ----------
    M. Kaasalainen, "Interpretation of lightcurves of precessing asteroids",
    A&A 376, 302 (2001), §2. P. Pravec et al., "Tumbling asteroids",
    Icarus 173, 108 (2005). L. D. Landau and E. M. Lifshitz, *Mechanics*,
    3rd ed. (1976), §37.

    Examples
    --------
    >>> from eulerpoisson.analysis import spin_states_from_periods, tumbling_periods
    >>> p = tumbling_periods([1.0, 2.0, 2.5], [0.2, 0.3, 1.0])
    >>> p["I1_I3"], p["I2_I3"], round(p["E_over_E0"], 9)
    (0.4, 0.8, 1.07300885)
    >>> fam = spin_states_from_periods(p["P_psi"], p["P_phi"], p["mode"], I1_I3=0.4, I2_I3=[0.7, 0.8, 0.9])
    >>> fam["valid"]
    array([ True,  True, False])
    >>> round(float(fam["E_over_E0"][1]), 9)  # the member with the true ratios
    1.07300885
    """
    from scipy.optimize import brentq
    from scipy.special import expit

    P_psi = as_scalar(P_psi, "P_psi", positive=True)
    P_phi = as_scalar(P_phi, "P_phi", positive=True)
    if not isinstance(mode, str):
        raise TypeError(f'mode must be the string "LAM" or "SAM", got {type(mode).__name__} {mode!r}')
    if mode.upper() not in _MODES:
        raise InvalidInputError(f'mode must be "LAM" (long-axis mode) or "SAM" (short-axis mode), got {mode!r}')
    sam = mode.upper() == "SAM"
    a = as_float_array(I1_I3, "I1_I3")
    b = as_float_array(I2_I3, "I2_I3")
    try:
        a, b = np.broadcast_arrays(a, b)
    except ValueError:
        raise InvalidInputError(
            f"I1_I3 and I2_I3 must broadcast together, got shapes {np.shape(a)} and {np.shape(b)}"
        ) from None
    ok = (a > 0) & (a < b) & (b < 1)
    if not np.all(ok):
        i = tuple(int(j) for j in np.argwhere(~ok)[0])
        raise InvalidInputError(
            f"I1_I3 and I2_I3 must satisfy 0 < I1_I3 < I2_I3 < 1 (the smallest and intermediate principal moments "
            f"over the largest, all distinct), got I1_I3 = {a[i]!r}, I2_I3 = {b[i]!r}"
            + (f" at index {i}" if a.ndim else "")
        )
    target = np.log(P_phi / P_psi)
    shape = a.shape
    out = {key: np.full(shape, np.nan) for key in ("E_over_E0", "k2", "k2c", "L_over_I3")}
    M0 = np.full(shape + (3,), np.nan)
    valid = np.zeros(shape, bool)
    y_lo, y_hi = -700.0, 700.0  # 1 - k^2 = e^-700 (the separatrix in float64) ... k^2 = e^-700 (the relaxed spin)
    for idx in np.ndindex(*shape):
        ai, bi = float(a[idx]), float(b[idx])

        def g(y, ai=ai, bi=bi):
            nu_psi, factor, _, _ = _family_rates(ai, bi, y, sam)
            return float(np.log(nu_psi / factor)) - target

        with np.errstate(over="ignore", under="ignore"):
            glo, ghi = g(y_lo), g(y_hi)
            if not (np.isfinite(glo) and np.isfinite(ghi) and glo < 0 < ghi):
                continue
            y = brentq(g, y_lo, y_hi, xtol=1e-13, rtol=4 * np.finfo(float).eps, maxiter=400)
            nu_psi, _, k2, den = _family_rates(ai, bi, y, sam)
        rate = 2.0 * np.pi / (P_psi * float(nu_psi))
        kc = float(expit(y))
        # M0 where the component normal to both the circulation and the intermediate axis vanishes: there
        # L^2 - 2 E I2 and 2 E I3 - L^2 (SAM), 2 E I1 - L^2 (LAM) are single terms, so that the state
        # (k^2, 1 - k^2) is represented without cancellation, even next to the separatrix
        m2 = bi * k2 * (1.0 - ai) / den
        if sam:
            e = 1.0 + k2 * (1.0 - bi) * (1.0 - ai) / den
            m = (0.0, m2, (bi - ai) * kc / den)
        else:
            e = 1.0 + (1.0 - bi) * (1.0 - ai) / den
            m = (ai * (1.0 - bi) * kc / den, m2, 0.0)
        out["E_over_E0"][idx] = e
        out["k2"][idx] = k2
        out["k2c"][idx] = kc
        out["L_over_I3"][idx] = rate
        M0[idx] = rate * np.sqrt(m)
        valid[idx] = True
    res = {"I1_I3": a.copy(), "I2_I3": b.copy()}
    res.update(out)
    res["M0"] = M0
    res["valid"] = valid
    return res


def _positive(x, name):
    v = as_float_array(x, name)
    if v.ndim or not v > 0:
        raise InvalidInputError(f"{name} must be a number > 0, got {x!r}")
    return float(v)


def sleeping_top(I1: float, I3: float, mass: float, ell: float, spin: float, g: float = 9.81) -> dict:
    r"""Stability of a sleeping top (Maxwell–Routh) and its small oscillations.

    A symmetric top (moments :math:`I_1 = I_2`, :math:`I_3` about the fixed
    point) spins with :math:`\Omega_3` = ``spin`` about its symmetry axis held
    vertical, the centre of mass at height :math:`\ell` above the fixed point
    (:math:`\ell < 0`: below it, a hanging top). Linearizing the Euler–Poisson
    equations about this motion, the axis tip :math:`x + iy` moves as
    :math:`ae^{i\omega_+t} + be^{i\omega_-t}` with

    .. math:: \omega_\pm = \frac{I_3\Omega_3 \pm \sqrt{I_3^2\Omega_3^2 - 4\mu g\ell I_1}}{2I_1},

    so the top is stable while :math:`I_3^2\Omega_3^2 > 4\mu g\ell I_1`
    (Maxwell–Routh; always for :math:`\ell \le 0`), and the tilt of a
    slightly disturbed top nutates with the frequency :math:`\omega_+ - \omega_-`.

    Parameters
    ----------
    I1, I3 : float
        Transverse and axial moments about the fixed point, > 0.
    mass : float
        > 0.
    ell : float
        Height of the centre of mass above the fixed point along the axis (any sign).
    spin : float
        :math:`\Omega_3`, any sign.
    g : float
        Magnitude of gravity, > 0 (default 9.81).

    Returns
    -------
    dict
        ``stable`` (bool), ``critical_spin`` (the smallest
        :math:`|\Omega_3|` for stability, :math:`2\sqrt{\mu g\ell I_1}/I_3`,
        0 for :math:`\ell \le 0`), ``omega_plus``, ``omega_minus`` (the fast
        and slow precession rates, NaN when unstable), ``nutation_frequency``
        (:math:`\omega_+ - \omega_-`, NaN when unstable), ``growth_rate``
        (:math:`\sqrt{4\mu g\ell I_1 - I_3^2\Omega_3^2}/(2I_1)` when
        unstable, else 0), ``fall_angle`` (unstable: the largest tilt a
        slightly disturbed top reaches, :math:`\arccos(I_3^2\Omega_3^2/(2\mu g\ell I_1) - 1)`,
        from the energy and the two momenta of the Lagrange top; 0 when stable).

    Raises
    ------
    InvalidInputError
        Non-positive moments, mass or g; non-finite values.

    References
    ----------
    J. C. Maxwell (1857); E. J. Routh, *Advanced Rigid Dynamics* (1905), §207;
    A. Sommerfeld and F. Klein, *Über die Theorie des Kreisels* (1897); H.
    Goldstein, *Classical Mechanics*, 3rd ed., §5.7 (the "fast top").
    """
    I1 = _positive(I1, "I1")
    I3 = _positive(I3, "I3")
    mass = _positive(mass, "mass")
    g = _positive(g, "g")
    ell = float(as_float_array(ell, "ell"))
    spin = float(as_float_array(spin, "spin"))
    a = I3 * spin
    disc = a * a - 4.0 * mass * g * ell * I1
    crit = 2.0 * np.sqrt(mass * g * ell * I1) / I3 if ell > 0 else 0.0
    if disc > 0 or (ell <= 0 and disc >= 0):
        r = np.sqrt(disc)
        return {
            "stable": True,
            "critical_spin": crit,
            "omega_plus": (a + r) / (2 * I1),
            "omega_minus": (a - r) / (2 * I1),
            "nutation_frequency": r / I1,
            "growth_rate": 0.0,
            "fall_angle": 0.0,
        }
    return {
        "stable": False,
        "critical_spin": crit,
        "omega_plus": np.nan,
        "omega_minus": np.nan,
        "nutation_frequency": np.nan,
        "growth_rate": float(np.sqrt(-disc) / (2 * I1)),
        "fall_angle": float(np.arccos(a * a / (2.0 * mass * g * ell * I1) - 1.0)),
    }


def gravity_gradient_frequencies(moments: ArrayLike, mean_motion: float) -> dict:
    r"""Small oscillations of a satellite about its gravity-gradient equilibrium on a circular orbit.

    The principal axes of the satellite are aligned with the orbit frame:
    ``moments = (I_roll, I_pitch, I_yaw)`` about the along-track direction,
    the orbit normal and the local vertical (the direction to the body,
    :math:`\hat{\mathbf r}` of :class:`~eulerpoisson.torques.GravityGradient`);
    the satellite turns once per orbit about the orbit normal. With
    :math:`k_1 = (I_p - I_y)/I_r` and :math:`k_3 = (I_p - I_r)/I_y`, the
    pitch oscillation decouples,

    .. math:: \omega_p^2 = 3\nu^2\,\frac{I_r - I_y}{I_p},

    and roll and yaw are coupled, with :math:`\omega^2` the roots of

    .. math:: \omega^4 - \nu^2(1 + 3k_1 + k_1k_3)\,\omega^2 + 4k_1k_3\nu^4 = 0 .

    The equilibrium is stable (linearly) when all three :math:`\omega^2` are
    real and positive, e.g. in the Lagrange region :math:`I_p > I_r > I_y`.

    Parameters
    ----------
    moments : array_like, shape (3,)
        :math:`(I_r, I_p, I_y)`, > 0.
    mean_motion : float
        :math:`\nu` > 0.

    Returns
    -------
    dict
        ``pitch`` (:math:`\omega_p`), ``roll_yaw`` (the two roll-yaw
        frequencies, largest first), ``stable`` (bool); frequencies are NaN
        where the corresponding :math:`\omega^2` is not a positive real.

    Raises
    ------
    InvalidInputError
        Non-positive moments or mean motion, wrong shape.

    References
    ----------
    P. C. Hughes, *Spacecraft Attitude Dynamics* (1986), §9.2; V. V. Beletsky,
    *Motion of an Artificial Satellite about its Center of Mass* (1966), ch. 2.
    """
    Im = as_float_array(moments, "moments", (3,))
    if Im.ndim != 1 or np.any(Im <= 0):
        raise InvalidInputError(f"moments must be three numbers > 0 (I_roll, I_pitch, I_yaw), got {moments!r}")
    nu = _positive(mean_motion, "mean_motion")
    Ir, Ip, Iy = Im
    wp2 = 3.0 * nu * nu * (Ir - Iy) / Ip
    k1 = (Ip - Iy) / Ir
    k3 = (Ip - Ir) / Iy
    b = 1.0 + 3.0 * k1 + k1 * k3
    c = 4.0 * k1 * k3
    disc = b * b - 4.0 * c
    roots = []
    if disc >= 0:
        r = np.sqrt(disc)
        roots = [0.5 * nu * nu * (b + r), 0.5 * nu * nu * (b - r)]
    freqs = [float(np.sqrt(x)) if x > 0 else np.nan for x in roots] or [np.nan, np.nan]
    stable = wp2 > 0 and disc >= 0 and all(x > 0 for x in roots)
    return {"pitch": float(np.sqrt(wp2)) if wp2 > 0 else np.nan, "roll_yaw": tuple(freqs), "stable": bool(stable)}
