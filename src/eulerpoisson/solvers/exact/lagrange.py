r"""The Lagrange top (heavy symmetric top) in closed form.

A symmetric rigid body with principal moments of inertia ``diag(A, A, C)``
about a fixed point (the body origin), its centre of mass on the symmetry
axis at ``c = (0, 0, ell)``, in a uniform gravitational field ``g``.  This
module gives the motion as explicit functions of time: Jacobi elliptic
functions for the nutation and incomplete elliptic integrals of the third
kind (Carlson's :math:`R_F`, :math:`R_J`) for the two rotation angles.  The
cost per output time is O(1) (no time stepping) and large times keep full
accuracy (the angle integrals are reduced by periods: the secular part is the
number of half-periods times a complete integral).

Conventions
-----------
Quaternions are scalar-first ``(w, x, y, z)`` with the Hamilton product,
``x_space = R(q) x_body``, :math:`\dot q = \tfrac12 q\otimes(0,\Omega)` with
:math:`\Omega` the *body* angular velocity, and the Euler--Poisson equations

.. math::

    I\dot\Omega = (I\Omega)\times\Omega + c\times(\mathrm{mass}\,R^{T}g),
    \qquad I = \operatorname{diag}(A, A, C).

Conserved: :math:`E = \tfrac12\Omega\cdot I\Omega - \mathrm{mass}\,g\cdot Rc`,
:math:`M_z = (R I\Omega)\cdot\hat z` and :math:`M_3 = C\Omega_3`.

Method
------
Let :math:`\hat z = -\operatorname{sign}(\ell)\,\hat g` ("up" for a top whose
centre of mass lies above the pivot, "down" for a pendulum-like body), so that
the potential is :math:`P u` with :math:`P = \mathrm{mass}\,|g|\,|\ell|\ge 0`
and :math:`u = \cos\theta = \hat z\cdot R e_3`.  The problem is solved in a
space frame whose third axis is :math:`\hat z` and rotated back at the end.
With :math:`E' = E - M_3^2/(2C)`, the nutation obeys

.. math::

    A^2\dot u^2 = p(u) = 2A(E' - P u)(1-u^2) - (M_z - M_3 u)^2
                = 2AP\,(u-u_1)(u-u_2)(u-u_3),

:math:`-1\le u_1\le u_2\le 1\le u_3`, solved by

.. math::

    u = u_1 + (u_2-u_1)\,\operatorname{sn}^2(\tau|m),\quad
    \tau = \tau_0 + \nu t,\quad
    m = \frac{u_2-u_1}{u_3-u_1},\quad
    \nu = \sqrt{\frac{P(u_3-u_1)}{2A}}.

The attitude is written with the Euler angles ``z-x-z``
(:math:`q = q_z(\phi)q_x(\theta)q_z(\psi)`) but only through the smooth
complex combinations

.. math::

    w + iz = \cos\tfrac\theta2\,e^{i\sigma},\qquad
    x + iy = \sin\tfrac\theta2\,e^{i\delta},\qquad
    \sigma = \tfrac{\phi+\psi}2,\ \delta = \tfrac{\phi-\psi}2,

whose rates

.. math::

    \dot\sigma = \frac{M_3}2\Big(\frac1C-\frac1A\Big)
                 + \frac{M_z+M_3}{2A(1+u)},\qquad
    \dot\delta = -\frac{M_3}2\Big(\frac1C-\frac1A\Big)
                 + \frac{M_z-M_3}{2A(1-u)}

are singular only where the corresponding amplitude vanishes (``u = -1``
needs :math:`M_z = -M_3`, ``u = 1`` needs :math:`M_z = M_3`).  With
:math:`d = u_2-u_1`, :math:`w_1 = 1+u_1`, :math:`w_2 = 1-u_2`,

.. math::

    \int\frac{dt}{1-u} = \frac{\Pi(n;\operatorname{am}\tau|m)}{\nu(w_2+d)},
    \qquad n = \frac{d}{w_2+d},

and :math:`\int dt/(1+u)` is :math:`\Pi(-d/w_1;\cdot|m)/(\nu w_1)` for
:math:`w_1\ge d/2` or, after the shift :math:`\tau\to\tau-K`
(:math:`\operatorname{sn}\to\operatorname{cd}`),

.. math::

    \int\frac{d\tau}{w_1 + d\,\operatorname{cd}^2\tau}
    = \frac{m\tau + \frac{d\,m_1}{w_1+d}\,\Pi(N;\operatorname{am}\tau|m)}
           {w_1 m + d},\qquad N = \frac{w_1 m + d}{w_1 + d},

so that every characteristic lies in ``[-2, 1)`` and, for ``n, N > 0``, all
Carlson terms (DLMF 19.25.14, with :math:`1-n` formed exactly) are positive:
the near-passage through the vertical (a narrow spike of the rate, a jump of
nearly :math:`\pi` of the angle) is computed without cancellation.  The
shifted integral is reduced about its peak (``tau = 2jK + tau_r``, and
:math:`\operatorname{sn}(K-x) = \operatorname{cd}x` etc. instead of
subtracting ``K``), so the peak is resolved to the relative accuracy of
``tau_r``.  Large times: ``2 j Pi(n|m)`` (number of half-periods times the
complete integral) plus the integral over the reduced argument.  The exact
passage (:math:`w = 0`) uses the *signed* amplitudes
:math:`\cos\tfrac\theta2 = \sqrt{d/2}\,\operatorname{sn}\tau` or
:math:`\sin\tfrac\theta2 = \sqrt{d/2}\,\operatorname{cn}\tau`.  The initial
phases of ``w + iz`` and ``x + iy`` come from a least-squares combination of
the initial values and their initial rates (so that a tiny amplitude at
``t = 0`` does not make the phase ill-determined).

*Implementation.*  The set-up of a top (the roots, the parameter, the
initial phases) is NumPy code, vectorized over the tops; the evaluation at
the output times is NumPy code too (:func:`_per_time`, the reference) or,
when numba is used, the compiled kernel of
:mod:`eulerpoisson.solvers.exact.lagrange_kernels` (the same formulas, one
(top, time) after the other with the scalar elliptic kernels; the two agree
to a few ulp, ``tests/test_exact_lanes.py``): about 0.5 microseconds per
(top, time) with the attitude against 2 for NumPy.

The problem is first rescaled by powers of two (exact) to a frequency scale
:math:`\sqrt{P/A + |\Omega_0|^2}` and inertia scale ``A``.

The roots are found by a safeguarded Newton--bisection on the cubic expanded
about the nearest of :math:`u_0` and :math:`\pm1` (coefficients formed
directly from the initial data, e.g. :math:`p(u_0) = A^2\dot u_0^2`,
:math:`p(\pm1) = -(M_z\mp M_3)^2`), so that the distances :math:`u_0-u_1`,
:math:`u_2-u_0`, :math:`1-u_2`, :math:`1+u_1`, :math:`u_3-1` have full
accuracy.  The initial phase :math:`\tau_0` uses both :math:`u_0` and
:math:`\dot u_0`.  Special regimes: ``P = 0`` (``g = 0``, ``ell = 0`` or
``mass = 0``) is the free symmetric top, uniform precession about the angular
momentum; a double root at :math:`u_0` (sleeping top, equilibria, steady
precession) is uniform rotation.

References
----------
.. [1] E. T. Whittaker, *A Treatise on the Analytical Dynamics of Particles
   and Rigid Bodies*, 4th ed., Cambridge (1937), sections 71-72.
.. [2] L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed., section 35.
.. [3] H. Goldstein, C. Poole, J. Safko, *Classical Mechanics*, 3rd ed.,
   section 5.7.
.. [4] R. H. Cushman, L. M. Bates, *Global Aspects of Classical Integrable
   Systems*, 2nd ed., Birkhaeuser (2015), chapter V (the Lagrange top).
.. [5] B. C. Carlson, "Numerical computation of real or complex elliptic
   integrals", Numer. Algorithms 10 (1995) 13-26; DLMF 19.25.14, 19.7.
"""

from __future__ import annotations

import numpy as np

from ...errors import InvalidInputError
from ...numerics.elliptic import ellipk, elliprf, elliprj, jacobi_sncndn
from ...numerics.quaternion import CONJUGATE, qmul
from ...util.validate import MAX_PHASE, scaled_norms

__all__ = ["lagrange_top_motion", "check_top_ranges"]

_UNIT_TOL = 1e-8
_BRACKET_ITERS = 200
#: a rejected Newton step within this many ulp of the iterate: the bracket is closed beside it (_bracket_root)
_NEWTON_ULPS = 4.0
_EPS = float(np.finfo(np.float64).eps)


# ---------------------------------------------------------------------------
# quaternion helpers (scalar first)
# ---------------------------------------------------------------------------
def _conj(q):
    return q * CONJUGATE


def _frame_quaternion(a):
    """Unit quaternion ``q_f`` with ``R(q_f) a = e_z`` for unit vectors ``a`` (N, 3)."""
    ax, ay, az = a[:, 0], a[:, 1], a[:, 2]
    up = az >= 0.0
    # rotation about x by pi maps (ax, ay, az) -> (ax, -ay, -az)
    by = np.where(up, ay, -ay)
    bz = np.where(up, az, -az)
    # half-way quaternion taking b to e_z: (1 + b.e_z, b x e_z) normalised
    h = np.stack([1.0 + bz, by, -ax, np.zeros_like(ax)], axis=-1)
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    flip = np.where(up[:, None], np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0, 0.0]))
    return qmul(h, flip)


# ---------------------------------------------------------------------------
# input validation
# ---------------------------------------------------------------------------
def _array(x, name):
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be a real array, got {x!r}") from exc
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(f"{name} must be finite (no NaN or inf)")
    return arr


def _validate(A, C, mass, ell, g, q0, omega0, t):
    A = _array(A, "A")
    C = _array(C, "C")
    mass = _array(mass, "mass")
    ell = _array(ell, "ell")
    g = _array(g, "g")
    q0 = _array(q0, "q0")
    omega0 = _array(omega0, "omega0")
    t = _array(t, "t")
    for name, arr, k in (("g", g, 3), ("q0", q0, 4), ("omega0", omega0, 3)):
        if arr.ndim < 1 or arr.shape[-1] != k:
            raise InvalidInputError(f"{name} must have shape (..., {k}), got {arr.shape}")
    if t.ndim != 1:
        raise InvalidInputError(f"t must be one-dimensional (T,), got shape {t.shape}")
    qn = np.linalg.norm(q0, axis=-1)
    if np.any(np.abs(qn - 1.0) > _UNIT_TOL):
        raise InvalidInputError(
            f"q0 must be a unit quaternion (|q0| = 1 within {_UNIT_TOL}), got |q0| = "
            f"{qn[np.abs(qn - 1.0) > _UNIT_TOL].ravel()[0]!r}"
        )
    try:
        shape = np.broadcast_shapes(
            A.shape, C.shape, mass.shape, ell.shape, g.shape[:-1], q0.shape[:-1], omega0.shape[:-1]
        )
    except ValueError as exc:
        raise InvalidInputError(
            "the shapes of A, C, mass, ell, g[..., :], q0[..., :], omega0[..., :] do not broadcast: "
            f"{A.shape}, {C.shape}, {mass.shape}, {ell.shape}, {g.shape}, {q0.shape}, {omega0.shape}"
        ) from exc
    if np.any(A <= 0.0):
        raise InvalidInputError("A must be > 0")
    if np.any(C <= 0.0):
        raise InvalidInputError("C must be > 0")
    if np.any(C > 2.0 * A):
        raise InvalidInputError("C must satisfy C <= 2 A (triangle inequality A + A >= C)")
    if np.any(mass < 0.0):
        raise InvalidInputError("mass must be >= 0")
    return A, C, mass, ell, g, q0, omega0, t, shape


# ---------------------------------------------------------------------------
# cubic roots
# ---------------------------------------------------------------------------
def _coeffs(uc, ec, rc, muc, A, P, M3):
    r"""Taylor coefficients of :math:`p(u_c + h)`.

    With :math:`e_c = E' - P u_c`, :math:`r_c = 1 - u_c^2`,
    :math:`\mu_c = M_z - M_3 u_c` (all formed accurately by the caller).
    """
    a0 = 2.0 * A * ec * rc - muc * muc
    a1 = 2.0 * A * (-2.0 * uc * ec - P * rc) + 2.0 * muc * M3
    a2 = 2.0 * A * (2.0 * P * uc - ec) - M3 * M3
    a3 = 2.0 * A * P
    return a0, a1, a2, a3


def _poly(a, h):
    a0, a1, a2, a3 = a
    return a0 + h * (a1 + h * (a2 + h * a3)), a1 + h * (2.0 * a2 + h * 3.0 * a3)


def _bracket_root(a, lo, hi, increasing):
    """Root of the cubic ``sum a_k h^k`` in ``[lo, hi]`` by safeguarded Newton.

    ``increasing``: the cubic is ``<= 0`` left of the root and ``>= 0`` right of
    it (else the opposite).  Iterates until the bracket stops shrinking.
    """
    lo = lo.copy()
    hi = hi.copy()
    x = 0.5 * (lo + hi)
    sgn = np.where(increasing, 1.0, -1.0)
    for _ in range(_BRACKET_ITERS):
        with np.errstate(over="ignore", invalid="ignore"):  # huge brackets (tiny P)
            f, df = _poly(a, x)
        f = sgn * f
        df = sgn * df
        right = ~(f < 0.0)  # root at or left of x (NaN from inf - inf: far right)
        hi = np.where(right, x, hi)
        lo = np.where(right, lo, x)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            xn = x - f / df
        bad = ~np.isfinite(xn) | (xn <= lo) | (xn >= hi)
        # a Newton step onto the bracket's end (x itself: converged from one side) closes the bracket with the
        # neighbouring float on the root's side, not by bisecting the far end down (45-60 iterations)
        near = bad & np.isfinite(xn) & (np.abs(xn - x) <= _NEWTON_ULPS * _EPS * np.abs(x))
        mid = 0.5 * (lo + hi)
        xn = np.where(bad, np.where(near, np.nextafter(x, np.where(f < 0.0, hi, lo)), mid), xn)
        done = (xn == x) | (mid == lo) | (mid == hi) | (f == 0.0)
        x = np.where(done, x, xn)
        if np.all(done):
            break
    return x


# ---------------------------------------------------------------------------
# elliptic integrals of the third kind with period reduction
# ---------------------------------------------------------------------------
def _pi_reduced(n, n1, s, c2, d2):
    r""":math:`\int_0^{\tau_r} d\tau/(1-n\,\mathrm{sn}^2\tau)` for :math:`|\tau_r|\le K`.

    ``s = sn``, ``c2 = cn**2``, ``d2 = dn**2`` of :math:`\tau_r`; ``n1 = 1 - n``
    (given accurately), ``n < 1``.  DLMF 19.25.14 with ``p`` formed without
    cancellation.
    """
    s2 = s * s
    p = np.where(n <= 0.0, 1.0 - n * s2, n1 + n * c2)
    one = np.ones_like(c2)
    return s * elliprf(c2, d2, one) + (n / 3.0) * (s * s2) * elliprj(c2, d2, one, p)


def _pi_periodic(n, n1, tau, K, m1, Pic, shifted):
    r"""Periodic-plus-secular form of the third-kind integrals.

    ``tau = 2 j K + tau_r`` with ``|tau_r| <= K``.  Unshifted:
    :math:`\int_0^\tau d\tau/(1-n\,\mathrm{sn}^2) = 2j\Pi(n|m) + \Pi(n;\mathrm{am}\,\tau_r|m)`.
    Shifted (the integrand :math:`1/(1-n\,\mathrm{cd}^2)` evaluated at ``tau - K``, whose
    narrow peak sits at ``tau_r = 0``):
    ``2 j Pi(n|m) + sign(tau_r) (Pi(n|m) - Pi(n; am(K - |tau_r|)|m))`` with
    ``sn(K - x) = cd x``, ``cn(K - x) = k' sd x``, ``dn(K - x) = k' nd x`` (no
    subtraction of ``K`` from the argument, so the peak is resolved to the
    relative accuracy of ``tau_r``).  ``K = inf`` (``m1 = 0``): no reduction.
    """
    finite = np.isfinite(K)
    Ks = np.where(finite, K, 1.0)
    j = np.where(finite, np.rint(tau / (2.0 * Ks)), 0.0)
    tr = tau - 2.0 * j * Ks
    x = np.where(shifted, np.abs(tr), tr)
    sn, cn, dn = jacobi_sncndn(x, m1=m1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(shifted, cn / dn, sn)
        c2 = np.where(shifted, m1 * (sn / dn) ** 2, cn * cn)
        d2 = np.where(shifted, m1 / (dn * dn), dn * dn)
    part = _pi_reduced(n, n1, s, c2, d2)
    Pis = np.where(finite, Pic, 0.0)
    part = np.where(shifted, np.sign(tr) * (Pis - part), part)
    return np.where(j == 0.0, part, 2.0 * j * Pis + part)


def _pi_complete(n, n1, K, m1):
    """Complete ``Pi(n|m) = K + n/3 R_J(0, m1, 1, 1 - n)`` (``m1 > 0``)."""
    ok = m1 > 0.0
    m1s = np.where(ok, m1, 1.0)
    rj = elliprj(np.zeros_like(m1s), m1s, np.ones_like(m1s), n1)
    return np.where(ok, K + n / 3.0 * rj, np.inf)


# ---------------------------------------------------------------------------
# the regimes
# ---------------------------------------------------------------------------
def _free_top(A, C, q0, om, t):
    """Free symmetric top: ``q(t) = q_m(|m| t/A) q0 q_e3(b t)``, ``b = Omega3 (A - C)/A``."""
    Iom = np.stack([A * om[:, 0], A * om[:, 1], C * om[:, 2]], axis=-1)
    # spatial angular momentum m = R(q0) I Omega  (as q0 (0, I Omega) q0^*)
    zero = np.zeros_like(A)
    mq = qmul(qmul(q0, np.concatenate([zero[:, None], Iom], axis=-1)), _conj(q0))
    mvec = mq[:, 1:]
    half = 0.5 * t[None, :] / A[:, None]  # (N, T)
    mn = np.linalg.norm(mvec, axis=-1)[:, None]
    ang = mn * half
    sinc = half * np.sinc(ang / np.pi)  # sin(|m| t / 2A) / |m|
    qm = np.concatenate([np.cos(ang)[..., None], sinc[..., None] * mvec[:, None, :]], axis=-1)
    b = om[:, 2] * (A - C) / A
    beta = 0.5 * b[:, None] * t[None, :]
    z = np.zeros_like(beta)
    qb = np.stack([np.cos(beta), z, z, np.sin(beta)], axis=-1)
    q = qmul(qmul(qm, q0[:, None, :]), qb)
    cb, sb = np.cos(2.0 * beta), np.sin(2.0 * beta)
    o1 = om[:, None, 0] * cb + om[:, None, 1] * sb
    o2 = -om[:, None, 0] * sb + om[:, None, 1] * cb
    o3 = np.broadcast_to(om[:, None, 2], o1.shape)
    return q, np.stack([o1, o2, o3], axis=-1)


def _assemble(Z1, Z2, dZ1, dZ2):
    """Quaternion and body angular velocity from ``w+iz``, ``x+iy`` and their rates."""
    q = np.stack([Z1.real, Z2.real, Z2.imag, Z1.imag], axis=-1)
    qd = np.stack([dZ1.real, dZ2.real, dZ2.imag, dZ1.imag], axis=-1)
    w, v = q[..., 0:1], q[..., 1:]
    wd, vd = qd[..., 0:1], qd[..., 1:]
    om = 2.0 * (w * vd - wd * v - np.cross(v, vd))
    return q, om


def _heavy_top(A, C, P, q0, om, t, t_scale=None, t_times=None, post=None, compiled=None):
    """Heavy top, ``P > 0``, in the frame where up is ``e_z``.

    All arrays are per body, ``(N, ...)``; ``t`` is ``(N, T)`` (scaled times).
    With ``t_scale`` (N,) and ``t_times`` (T,) given (``t = t_scale t_times``)
    and numba in use (and ``compiled`` not False), the motion at the output times is evaluated by the
    compiled kernel (:mod:`.lagrange_kernels`), which also does the last
    steps of :func:`lagrange_top_motion` (``post = (q_f, q0_in, omega0_in)``,
    per body): the returned boolean array marks those bodies. The set-up is
    NumPy either way.
    """
    N = A.shape[0]
    T = t.shape[-1]
    w0, x0, y0, z0 = q0[:, 0], q0[:, 1], q0[:, 2], q0[:, 3]
    o1, o2, o3 = om[:, 0], om[:, 1], om[:, 2]
    # up direction in the body frame, gamma = R^T e_z
    g1 = 2.0 * (x0 * z0 - w0 * y0)
    g2 = 2.0 * (y0 * z0 + w0 * x0)
    om_u = 2.0 * (x0 * x0 + y0 * y0)  # 1 - u0
    op_u = 2.0 * (w0 * w0 + z0 * z0)  # 1 + u0
    u0 = 0.5 * (op_u - om_u)
    M3 = C * o3
    perp = A * (o1 * g1 + o2 * g2)  # Mz - M3 u0
    Mz_m = perp - M3 * om_u  # Mz - M3
    Mz_p = perp + M3 * op_u  # Mz + M3
    udot0 = g1 * o2 - g2 * o1
    kin = 0.5 * A * (o1 * o1 + o2 * o2)  # E' - P u0
    r0 = g1 * g1 + g2 * g2  # 1 - u0^2

    c_u0 = _coeffs(u0, kin, r0, perp, A, P, M3)
    c_u0 = ((A * udot0) ** 2,) + c_u0[1:]
    c_p1 = _coeffs(1.0, kin - P * om_u, 0.0, Mz_m, A, P, M3)  # about u = +1
    c_m1 = _coeffs(-1.0, kin + P * op_u, 0.0, Mz_p, A, P, M3)  # about u = -1
    c_p1 = (-(Mz_m * Mz_m),) + c_p1[1:]
    c_m1 = (-(Mz_p * Mz_p),) + c_m1[1:]
    flip = lambda a: (a[0], -a[1], a[2], -a[3])  # noqa: E731  p(1 - w) in w

    steady = (c_u0[0] == 0.0) & (c_u0[1] == 0.0)
    zeros = np.zeros(N)
    # lower root: v1 = u1 - u0 in [-(1+u0), 0], W1 = 1 + u1 in [0, 1 + u0]
    v1 = _bracket_root(c_u0, -op_u, zeros, np.ones(N, bool))
    W1 = _bracket_root(c_m1, zeros, op_u, np.ones(N, bool))
    near_m = W1 < -v1
    v1 = np.where(near_m, W1 - op_u, v1)
    W1 = np.where(near_m, W1, op_u + v1)
    # upper root: v2 = u2 - u0 in [0, 1 - u0], W2 = 1 - u2 in [0, 1 - u0]
    v2 = _bracket_root(c_u0, zeros, om_u, np.zeros(N, bool))
    W2 = _bracket_root(flip(c_p1), zeros, om_u, np.ones(N, bool))
    near_p = W2 < v2
    v2 = np.where(near_p, om_u - W2, v2)
    W2 = np.where(near_p, W2, om_u - v2)
    # third root: h3 = u3 - 1 >= 0
    with np.errstate(over="ignore"):
        big = 1.0 + np.maximum.reduce([np.abs(c_p1[k] / c_p1[3]) for k in range(3)])
    big = np.minimum(big, np.finfo(float).max)
    h3 = _bracket_root(c_p1, zeros, big, np.ones(N, bool))
    # exact roots at the poles: p(-1) = 0 <=> u1 = -1; p(1) = 0 <=> u2 = 1
    # (p'(1) <= 0) and/or u3 = 1 (p'(1) >= 0)
    at_m = Mz_p == 0.0
    v1 = np.where(at_m, -op_u, v1)
    W1 = np.where(at_m, 0.0, W1)
    at_p = Mz_m == 0.0
    u2_p = at_p & (c_p1[1] <= 0.0)
    v2 = np.where(u2_p, om_u, v2)
    W2 = np.where(u2_p, 0.0, W2)
    h3 = np.where(at_p & (c_p1[1] >= 0.0), 0.0, h3)

    d = v2 - v1
    steady = steady | (d <= 0.0)
    u3mu1 = h3 + W2 + d  # u3 - u1 = (u3 - 1) + (1 - u2) + (u2 - u1)
    u3mu2 = h3 + W2
    # ---------------- steady motion (double root at u0) -------------------
    lam = 0.5 * M3 * (1.0 / C - 1.0 / A)
    kap_s = Mz_p / (2.0 * A)
    kap_d = Mz_m / (2.0 * A)
    Z10 = w0 + 1j * z0
    Z20 = x0 + 1j * y0
    q_out = np.empty((N, T, 4))
    om_out = np.empty((N, T, 3))
    final = np.zeros(N, dtype=bool)
    if np.any(steady):
        i = np.flatnonzero(steady)
        with np.errstate(divide="ignore", invalid="ignore"):
            rs = lam[i] + np.where(Mz_p[i] == 0.0, 0.0, kap_s[i] / op_u[i])
            rd = -lam[i] + np.where(Mz_m[i] == 0.0, 0.0, kap_d[i] / om_u[i])
        rs = np.where(np.isfinite(rs), rs, lam[i])
        rd = np.where(np.isfinite(rd), rd, -lam[i])
        es = np.exp(1j * rs[:, None] * t[i])
        ed = np.exp(1j * rd[:, None] * t[i])
        Z1 = Z10[i, None] * es
        Z2 = Z20[i, None] * ed
        q, o = _assemble(Z1, Z2, 1j * rs[:, None] * Z1, 1j * rd[:, None] * Z2)
        q_out[i] = q
        om_out[i] = o
    gen = ~steady
    if not np.any(gen):
        return q_out, om_out, final
    i = np.flatnonzero(gen)
    A, C, P, M3, lam, kap_s, kap_d = A[i], C[i], P[i], M3[i], lam[i], kap_s[i], kap_d[i]
    d, v1, v2, W1, W2 = d[i], v1[i], v2[i], W1[i], W2[i]
    u3mu1, u3mu2, udot0 = u3mu1[i], u3mu2[i], udot0[i]
    Z10, Z20, Mz_p, Mz_m = Z10[i], Z20[i], Mz_p[i], Mz_m[i]
    om_i = om[i]
    q0_i = q0[i]
    t = t[i]

    m = d / u3mu1
    m1 = u3mu2 / u3mu1
    nu = np.sqrt(P * u3mu1 / (2.0 * A))
    K = ellipk(m1=m1)
    # ---------------- initial phase tau0 in [-K, K] ------------------------
    sn2 = -v1 / d
    cn2 = v2 / d
    dn0 = np.sqrt(np.where(m <= 0.5, 1.0 - m * sn2, m1 + m * cn2))  # no cancellation
    use_cn = cn2 >= sn2
    with np.errstate(divide="ignore", invalid="ignore"):
        cn_a = np.sqrt(cn2)
        sn_a = udot0 / (2.0 * d * nu * cn_a * dn0)
        sn_b = np.copysign(np.sqrt(sn2), udot0)
        cn_b = np.abs(udot0) / (2.0 * d * nu * np.abs(sn_b) * dn0)
    sn0 = np.where(use_cn, sn_a, sn_b)
    cn0 = np.where(use_cn, cn_a, cn_b)
    sn0 = np.where(np.isfinite(sn0), sn0, 0.0)
    cn0 = np.where(np.isfinite(cn0), cn0, 0.0)
    # tau0 = F(am0|m) from sn0, cn0 directly (DLMF 19.25.5): going through the
    # amplitude am0 = atan2(sn0, cn0) would lose the relative accuracy of a small
    # cn0 (near the turning point u2, where dF/d(am) = 1/dn can be large)
    r = np.hypot(sn0, cn0)
    r = np.where(r > 0.0, r, 1.0)
    s_, c_ = sn0 / r, cn0 / r
    c2_ = c_ * c_
    D2_ = np.where(m <= 0.5, 1.0 - m * s_ * s_, c2_ + m1 * s_ * s_)
    ok = (c2_ > 0.0) | (D2_ > 0.0)
    tau0 = np.where(ok, s_ * elliprf(np.where(ok, c2_, 1.0), np.where(ok, D2_, 1.0), 1.0), 0.0)

    # ---------------- amplitudes, rates and angle integrals: constants ------
    sd = np.sqrt(0.5 * d)
    zero1 = (W1 == 0.0) | (Mz_p == 0.0)
    zero2 = (W2 == 0.0) | (Mz_m == 0.0)
    s1 = W1 == 0.0
    s2 = W2 == 0.0
    # sigma: int dtau / (W1 + d sn^2)
    W1s = np.where(zero1, 1.0, W1)
    direct = (W1s >= 0.5 * d) | (m1 == 0.0)
    n_dir = -d / W1s
    n1_dir = (W1s + d) / W1s
    N_sh = (W1s * m + d) / (W1s + d)
    N1_sh = W1s * m1 / (W1s + d)
    nS = np.where(direct, n_dir, N_sh)
    n1S = np.where(direct, n1_dir, N1_sh)
    PicS = _pi_complete(nS, n1S, K, m1)
    # G1 = lin * tau + coef * per
    linS = np.where(direct, 0.0, m / (W1s * m + d))
    coefS = np.where(direct, 1.0 / W1s, d * m1 / ((W1s + d) * (W1s * m + d)))
    cS_lin = lam + np.where(zero1, 0.0, kap_s * linS)
    cS_per = np.where(zero1, 0.0, kap_s * coefS / nu)
    # delta: int dtau / (W2 + d cn^2) = Pi(n2)/(W2 + d), n2 = d/(W2 + d)
    W2s = np.where(zero2, 1.0, W2)
    nD = d / (W2s + d)
    n1D = W2s / (W2s + d)
    PicD = _pi_complete(nD, n1D, K, m1)
    cD_per = np.where(zero2, 0.0, kap_d / ((W2s + d) * nu))
    cst = dict(
        m1=m1,
        K=K,
        sd=sd,
        d=d,
        nu=nu,
        W1=W1,
        W2=W2,
        s1=s1,
        s2=s2,
        zero1=zero1,
        zero2=zero2,
        lam=lam,
        kap_s=kap_s,
        kap_d=kap_d,
        nS=nS,
        n1S=n1S,
        PicS=PicS,
        direct=direct,
        nD=nD,
        n1D=n1D,
        PicD=PicD,
    )

    # ---------------- initial phases e^{i sigma0}, e^{i delta0} ------------
    cc0, ss0, cdot0, sdot0, rate_c0, rate_s0, perS0, perD0 = _per_time(cst, tau0[:, None])
    # qdot(0) = q0 (0, Omega0) / 2
    qd0 = 0.5 * qmul(q0_i, np.concatenate([np.zeros((len(i), 1)), om_i], axis=-1))
    dZ10 = qd0[:, 0] + 1j * qd0[:, 3]
    dZ20 = qd0[:, 1] + 1j * qd0[:, 2]
    W2f = nu * nu + np.sum(om_i * om_i, axis=-1) + lam * lam
    gc = cdot0[:, 0] + 1j * rate_c0[:, 0]
    gs = sdot0[:, 0] + 1j * rate_s0[:, 0]
    e1 = cc0[:, 0] * Z10 + np.conj(gc) * dZ10 / W2f
    e2 = ss0[:, 0] * Z20 + np.conj(gs) * dZ20 / W2f
    with np.errstate(divide="ignore", invalid="ignore"):
        e1 = e1 / np.abs(e1)
        e2 = e2 / np.abs(e2)
    e1 = np.where(np.isfinite(e1), e1, 1.0)
    e2 = np.where(np.isfinite(e2), e2, 1.0)

    if t_scale is not None and post is not None and compiled is not False and _use_kernel():
        from . import lagrange_kernels as _LK

        Cb = np.empty((len(i), _LK.N_LAG))
        for col, val in (
            (_LK.L_M1, m1),
            (_LK.L_M, 1.0 - m1),
            (_LK.L_K, K),
            (_LK.L_NU, nu),
            (_LK.L_TAU0, tau0),
            (_LK.L_SD, sd),
            (_LK.L_D, d),
            (_LK.L_W1, W1),
            (_LK.L_W2, W2),
            (_LK.L_S1, s1),
            (_LK.L_S2, s2),
            (_LK.L_Z1, zero1),
            (_LK.L_Z2, zero2),
            (_LK.L_LAM, lam),
            (_LK.L_KAPS, kap_s),
            (_LK.L_KAPD, kap_d),
            (_LK.L_NS, nS),
            (_LK.L_N1S, n1S),
            (_LK.L_PICS, PicS),
            (_LK.L_SHS, ~direct),
            (_LK.L_ND, nD),
            (_LK.L_N1D, n1D),
            (_LK.L_PICD, PicD),
            (_LK.L_CSLIN, cS_lin),
            (_LK.L_CSPER, cS_per),
            (_LK.L_CDPER, cD_per),
            (_LK.L_PERS0, perS0[:, 0]),
            (_LK.L_PERD0, perD0[:, 0]),
            (_LK.L_E1R, e1.real),
            (_LK.L_E1I, e1.imag),
            (_LK.L_E2R, e2.real),
            (_LK.L_E2I, e2.imag),
            (_LK.L_SDNU, sd * nu),
            (_LK.L_DNU, d * nu),
            (_LK.L_W, t_scale[i]),
        ):
            Cb[:, col] = val
        every = len(i) == N  # no steady body: the kernel writes the outputs themselves
        q = q_out if every else np.empty((len(i), T, 4))
        o = om_out if every else np.empty((len(i), T, 3))
        qf, q0_in, om_in = (np.ascontiguousarray(x[i], dtype=np.float64) for x in post)
        bad = 0
        if T:
            # (writeable: the times may be a read-only array, another signature of the kernel; a copy then only)
            tk = np.require(t_times, dtype=np.float64, requirements=("C", "A", "W", "E"))
            bad = _LK.heavy_top_kernel(Cb, tk, qf, q0_in, om_in, q, o)
        if bad == 0:
            if not every:
                q_out[i] = q
                om_out[i] = o
            final[i] = True
            return q_out, om_out, final
        # not representable (e.g. the separatrix so late that sech underflows): the NumPy path says why

    b = lambda x: x[:, None]  # noqa: E731
    tau = tau0[:, None] + nu[:, None] * t  # (n, T)
    cc, ss, cdot, sdot, rate_c, rate_s, perS, perD = _per_time(cst, tau)
    dsig = b(cS_lin) * t + b(cS_per) * (perS - perS0)
    ddel = -b(lam) * t + b(cD_per) * (perD - perD0)
    ph1 = b(e1) * np.exp(1j * dsig)
    ph2 = b(e2) * np.exp(1j * ddel)
    Z1 = cc * ph1
    Z2 = ss * ph2
    dZ1 = (cdot + 1j * rate_c) * ph1
    dZ2 = (sdot + 1j * rate_s) * ph2
    q, o = _assemble(Z1, Z2, dZ1, dZ2)
    q_out[i] = q
    om_out[i] = o
    return q_out, om_out, final


def _use_kernel():
    """Whether the compiled evaluation (:mod:`.lagrange_kernels`) runs: numba is used."""
    from ...util.jit import USE_NUMBA

    return USE_NUMBA


def _per_time(c, tt):
    """Amplitudes ``cos(theta/2), sin(theta/2)``, their rates, the rates of the phases and the angle
    integrals at the elliptic arguments ``tt`` (n, k) (NumPy; the compiled twin is
    :func:`.lagrange_kernels.heavy_top_kernel`)."""
    b = lambda x: x[:, None]  # noqa: E731
    sn, cn, dn = jacobi_sncndn(tt, m1=b(c["m1"]))
    sd, d, nu, lam = c["sd"], c["d"], c["nu"], c["lam"]
    cc = np.where(b(c["s1"]), b(sd) * sn, np.sqrt(0.5 * (b(c["W1"]) + b(d) * sn * sn)))
    ss = np.where(b(c["s2"]), b(sd) * cn, np.sqrt(0.5 * (b(c["W2"]) + b(d) * cn * cn)))
    with np.errstate(divide="ignore", invalid="ignore"):
        cdot = np.where(b(c["s1"]), b(sd * nu) * cn * dn, b(d * nu) * sn * cn * dn / (2.0 * cc))
        sdot = np.where(b(c["s2"]), -b(sd * nu) * sn * dn, -b(d * nu) * sn * cn * dn / (2.0 * ss))
        rate_c = b(lam) * cc + np.where(b(c["zero1"]), 0.0, b(c["kap_s"]) / (2.0 * cc))
        rate_s = -b(lam) * ss + np.where(b(c["zero2"]), 0.0, b(c["kap_d"]) / (2.0 * ss))
    cdot = np.where(np.isfinite(cdot), cdot, 0.0)
    sdot = np.where(np.isfinite(sdot), sdot, 0.0)
    K, m1 = c["K"], c["m1"]
    perS = _pi_periodic(b(c["nS"]), b(c["n1S"]), tt, b(K), b(m1), b(c["PicS"]), b(~c["direct"]))
    perD = _pi_periodic(b(c["nD"]), b(c["n1D"]), tt, b(K), b(m1), b(c["PicD"]), False)
    return cc, ss, cdot, sdot, rate_c, rate_s, perS, perD


def check_top_ranges(A, mass, ell, g, omega0, t) -> None:
    r"""Refuse finite inputs of a Lagrange top whose gravity scale, frequency or phase leaves float64.

    ``A``, ``mass``, ``ell`` (...), ``g`` and ``omega0`` (..., 3), broadcasting; ``t`` (T,). Without
    this, an overflowing gravity scale ``P = mass |g| |ell|`` made the top free (a silent wrong answer) and
    an overflowing frequency or phase gave NaN (in :func:`lagrange_top_motion` and its JAX twin).

    Raises
    ------
    InvalidInputError
        ``P`` or the squared frequency :math:`W^2 = P/A + |\Omega_0|^2` overflows, or :math:`W|t| > 2^{48}`.

    Examples
    --------
    >>> import numpy as np
    >>> check_top_ranges(np.ones(1), np.ones(1), np.ones(1), np.array([[0, 0, -9.81]]), np.zeros((1, 3)), np.ones(2))
    >>> check_top_ranges(np.ones(1), np.ones(1), np.ones(1), np.array([[0, 0, -1e300]]), np.zeros((1, 3)), np.ones(2))
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: W |t| = 1e+150 (body 0 of the flattened batch, ...
    """
    A, mass, ell = (np.asarray(x, dtype=float) for x in (A, mass, ell))
    omega0 = np.asarray(omega0, dtype=float)
    g = np.asarray(g, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        P = mass * scaled_norms(g) * np.abs(ell)
    bad = ~np.isfinite(P)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(
            f"mass * |g| * |ell| overflows float64 (body {i} of the flattened batch): rescale the units "
            "(the motion depends on mass * |g| * |ell| / A and omega0 only)"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        W2 = P / A + scaled_norms(omega0) ** 2
        tmax = float(np.max(np.abs(t), initial=0.0))
        phase = np.sqrt(W2) * tmax
    bad = ~np.isfinite(W2)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(
            f"the squared frequency mass |g| |ell| / A + |omega0|^2 overflows float64 (body {i} of the flattened "
            "batch): rescale the units of time"
        )
    bad = ~(phase <= MAX_PHASE)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError(
            f"W |t| = {np.ravel(phase)[i]:.3g} (body {i} of the flattened batch, W the top's frequency "
            f"sqrt(mass |g| |ell| / A + |omega0|^2), |t| = {tmax:.6g}) exceeds 2^48 = {MAX_PHASE:.3g} rad: "
            "float64 no longer determines the phase of the motion there"
        )


def lagrange_top_motion(A, C, mass, ell, g, q0, omega0, t, *, compiled=None):
    r"""Closed-form motion of a Lagrange top (heavy symmetric top).

    Parameters
    ----------
    A, C : array_like (...)
        Principal moments of inertia about the fixed point, ``diag(A, A, C)``;
        ``0 < C <= 2 A``.  ``A == C`` (spherical body with offset centre of
        mass) is allowed.
    mass : array_like (...)
        Mass, ``>= 0``.
    ell : array_like (...)
        Position of the centre of mass on the symmetry axis, ``c = (0, 0,
        ell)`` in the body frame; any sign, zero allowed.
    g : array_like (..., 3)
        Gravitational acceleration in the space frame (any direction, any
        magnitude including zero).
    q0 : array_like (..., 4)
        Initial attitude, unit quaternion ``(w, x, y, z)`` (tolerance
        ``1e-8``; it is normalised).
    omega0 : array_like (..., 3)
        Initial body angular velocity.
    t : array_like (T,)
        Output times, any order, negative allowed.
    compiled : bool or None, optional
        None (default): the compiled evaluation at the output times when
        numba is in use; False: NumPy (``solve`` passes it for small
        problems, see :func:`eulerpoisson.util.jit.use_compiled`).

    Returns
    -------
    q : ndarray (..., T, 4)
        Attitude at the times ``t`` (unit quaternions; at ``t == 0`` the input
        ``q0`` is returned unchanged).
    omega : ndarray (..., T, 3)
        Body angular velocity (at ``t == 0`` the input ``omega0``).

    Raises
    ------
    InvalidInputError
        (a ``ValueError``) naming the argument: ``A <= 0``, ``C <= 0``,
        ``C > 2 A``, ``mass < 0``, non-finite values, ``q0`` not of unit norm,
        wrong trailing dimensions, ``t`` not 1-D, shapes that do not
        broadcast; finite values whose gravity scale
        :math:`\mathrm{mass}\,|g|\,|\ell|` or squared frequency
        :math:`W^2 = \mathrm{mass}\,|g|\,|\ell|/A + |\Omega_0|^2`
        overflows float64, and times with :math:`W|t| > 2^{48}` (beyond
        it float64 no longer determines the phase: the exact method's
        limit).

    Notes
    -----
    With :math:`\hat z = -\operatorname{sign}(\ell)\hat g`,
    :math:`P = \mathrm{mass}\,|g|\,|\ell|`, :math:`u = \hat z\cdot R e_3`:

    .. math::

        A^2\dot u^2 = 2A(E' - Pu)(1-u^2) - (M_z - M_3u)^2
                    = 2AP(u-u_1)(u-u_2)(u-u_3),\qquad
        u = u_1 + (u_2-u_1)\operatorname{sn}^2(\tau_0 + \nu t\,|\,m),

    and the attitude follows from the elliptic integrals of the third kind
    for :math:`\sigma = (\phi+\psi)/2` and :math:`\delta = (\phi-\psi)/2`
    (see the module docstring).  Regimes: nutation between two latitudes,
    looping and cusped motion, passage through (or arbitrarily close to) the
    vertical, the separatrix ``m = 1``, the sleeping top and the equilibria
    (uniform rotation), steady precession, and ``P = 0`` (free symmetric
    top: :math:`q(t) = q_{\hat m}(|m|t/A)\,q_0\,q_{e_3}(\Omega_3(A-C)t/A)`).

    References
    ----------
    .. [1] E. T. Whittaker, *Analytical Dynamics*, section 71.
    .. [2] L. D. Landau, E. M. Lifshitz, *Mechanics*, section 35.
    .. [3] H. Goldstein, *Classical Mechanics*, section 5.7.
    .. [4] R. H. Cushman, L. M. Bates, *Global Aspects of Classical Integrable
       Systems*, chapter V.

    Examples
    --------
    >>> import numpy as np
    >>> q, w = lagrange_top_motion(1.0, 0.5, 1.0, 0.3, [0, 0, -9.81],
    ...                            [1, 0, 0, 0], [0.1, 0.0, 20.0], np.linspace(0, 1, 5))
    >>> q.shape, w.shape
    ((5, 4), (5, 3))
    """
    A, C, mass, ell, g, q0, omega0, t, shape = _validate(A, C, mass, ell, g, q0, omega0, t)
    T = t.shape[0]
    Nb = int(np.prod(shape))
    A_ = np.broadcast_to(A, shape).reshape(Nb)
    C_ = np.broadcast_to(C, shape).reshape(Nb)
    mass_ = np.broadcast_to(mass, shape).reshape(Nb)
    ell_ = np.broadcast_to(ell, shape).reshape(Nb)
    g_ = np.broadcast_to(g, shape + (3,)).reshape(Nb, 3)
    q0_in = np.broadcast_to(q0, shape + (4,)).reshape(Nb, 4)
    om_ = np.broadcast_to(omega0, shape + (3,)).reshape(Nb, 3)
    qn = q0_in / np.linalg.norm(q0_in, axis=-1, keepdims=True)

    with np.errstate(over="ignore"):
        gn = np.linalg.norm(g_, axis=-1)
    if not np.all(np.isfinite(gn)):
        gn = np.where(np.isfinite(gn), gn, scaled_norms(g_))  # the plain norm overflows from |g| ~ 1e154 on
    with np.errstate(over="ignore"):
        P = mass_ * gn * np.abs(ell_)
    check_top_ranges(A_, mass_, ell_, g_, om_, t)
    # scales: frequency W ~ sqrt(P/A + |Omega0|^2) and inertia S ~ A, both
    # powers of two (the rescaling is exact); in the units t' = W t,
    # Omega' = Omega/W, A' = A/S, P' = P/(S W^2) the problem is O(1).  A gravity
    # term P/(A W^2) < 2**-200 is dropped (free top): its effect ~ P' t'^2 is
    # below round-off for |t'| < 1e50.
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        W2 = P / A_ + np.sum(om_ * om_, axis=-1)
        Pn = np.where(W2 > 0.0, P / (A_ * np.where(W2 > 0.0, W2, 1.0)), 0.0)
        kW = np.rint(0.5 * np.log2(np.where(W2 > 0.0, W2, 1.0)))
        kS = np.rint(np.log2(A_))
    heavy = (P > 0.0) & (Pn >= 2.0**-200) & np.isfinite(W2)
    q_out = np.empty((Nb, T, 4))
    om_out = np.empty((Nb, T, 3))
    if np.any(~heavy):
        i = np.flatnonzero(~heavy)
        q, o = _free_top(A_[i], C_[i], qn[i], om_[i], t)
        q_out[i] = q
        om_out[i] = o
    if np.all(heavy):
        q_out = om_out = None  # type: ignore[assignment]  # the heavy-top evaluation allocates them (the compiled one fills them directly)
    if np.any(heavy):
        i = np.flatnonzero(heavy)
        zhat = -np.sign(ell_[i])[:, None] * g_[i] / gn[i, None]
        qf = _frame_quaternion(zhat)
        q0f = qmul(qf, qn[i])
        q0f = q0f / np.linalg.norm(q0f, axis=-1, keepdims=True)
        kw, ks = kW[i], kS[i]
        W = np.ldexp(1.0, kw.astype(int))
        q, o, final = _heavy_top(
            np.ldexp(A_[i], -ks.astype(int)),
            np.ldexp(C_[i], -ks.astype(int)),
            np.ldexp(P[i], (-ks - 2 * kw).astype(int)),
            q0f,
            om_[i] / W[:, None],
            W[:, None] * t[None, :],
            W,
            t,
            (qf, q0_in[i], om_[i]),
            compiled,
        )
        done = np.zeros(Nb, dtype=bool)
        # the compiled kernel did the last steps below for the bodies marked final
        done[i[final]] = True
        if q_out is None:
            q_out, om_out = q, o  # every body heavy: the rows not final are turned back below, in place
        else:
            q_out[i[final]] = q[final]
            om_out[i[final]] = o[final]
        if not np.all(final):
            k = ~final
            q_out[i[k]] = qmul(_conj(qf[k])[:, None, :], q[k])
            om_out[i[k]] = o[k] * W[k][:, None, None]
    else:
        done = np.zeros(Nb, dtype=bool)
    if np.all(done):
        return q_out.reshape(shape + (T, 4)), om_out.reshape(shape + (T, 3))
    rest = slice(None) if not np.any(done) else np.flatnonzero(~done)
    qr = q_out[rest]
    qr /= np.linalg.norm(qr, axis=-1, keepdims=True)
    omr = om_out[rest]
    omr[..., 2] = om_[rest, None, 2]
    at0 = t == 0.0
    if np.any(at0):
        qr[:, at0] = q0_in[rest, None, :]
        omr[:, at0] = om_[rest, None, :]
    q_out[rest] = qr
    om_out[rest] = omr
    return q_out.reshape(shape + (T, 4)), om_out.reshape(shape + (T, 3))
