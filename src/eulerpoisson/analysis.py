r"""Quantities of the motion in closed form: elliptic modulus, periods, flips; stability of tops and satellites.

Free body: the elliptic parameters, periods and the tennis-racket flips.
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

import numpy as np

from .util.validate import as_bool, as_float_array
from .model.body import check_moments
from .errors import InvalidInputError

__all__ = [
    "elliptic_parameters",
    "momentum_period",
    "tennis_racket_half_period",
    "flip_times",
    "sleeping_top",
    "gravity_gradient_frequencies",
]


def elliptic_parameters(inertia, M0) -> dict:
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


def momentum_period(inertia, M0) -> float:
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


def tennis_racket_half_period(inertia, M0) -> float:
    r"""Time :math:`2K(k)/\lambda` between consecutive flips (sign changes) of the momentum components that change sign."""
    return 0.5 * momentum_period(inertia, M0)


def flip_times(traj, component: int = 1, *, refine: bool = True) -> np.ndarray:
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


def _positive(x, name):
    v = as_float_array(x, name)
    if v.ndim or not v > 0:
        raise InvalidInputError(f"{name} must be a number > 0, got {x!r}")
    return float(v)


def sleeping_top(I1, I3, mass, ell, spin, g=9.81) -> dict:
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
        return {"stable": True, "critical_spin": crit, "omega_plus": (a + r) / (2 * I1),
                "omega_minus": (a - r) / (2 * I1), "nutation_frequency": r / I1, "growth_rate": 0.0, "fall_angle": 0.0}
    return {"stable": False, "critical_spin": crit, "omega_plus": np.nan, "omega_minus": np.nan,
            "nutation_frequency": np.nan, "growth_rate": float(np.sqrt(-disc) / (2 * I1)),
            "fall_angle": float(np.arccos(a * a / (2.0 * mass * g * ell * I1) - 1.0))}


def gravity_gradient_frequencies(moments, mean_motion) -> dict:
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
