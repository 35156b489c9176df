"""Independent high-precision reference for a rigid body under torque (no eulerpoisson code).

This module is "independent truth" for the package's tests.  It uses only
``mpmath``, ``numpy`` and the Python standard library, and shares no code with
``eulerpoisson``.

Conventions
-----------
* Quaternions are scalar-first ``(w, x, y, z)`` with the Hamilton product;
  ``x_space = R(q) x_body`` and ``q' = 1/2 q (x) (0, Omega)`` with ``Omega`` the
  BODY angular velocity.
* Euler--Poisson: ``I Omega' = (I Omega) x Omega + tau_body`` with ``I`` the
  symmetric positive-definite inertia tensor about the body origin, in the body
  frame (a (3,) diagonal or a full (3, 3) matrix).
* Torques (any combination, summed):

  - gravity ``(mass, c, g)``: ``tau = c x (mass R^T g)``; ``c`` = centre of mass
    in the body frame, ``g`` in the space frame; potential ``U = -mass g.(R c)``.
    Several terms may be given (list of tuples).
  - gravity gradient ``nu``: circular orbit in the space x-y plane, direction to
    the body ``r(t) = (cos nu t, sin nu t, 0)``;
    ``tau = 3 nu^2 r_b x (I r_b)`` with ``r_b = R^T r(t)``;
    potential ``V = +3/2 nu^2 r_b.I r_b`` (up to a constant).
  - body torque ``tau_b`` (constant in the body frame),
  - space torque ``tau_s`` (constant in the space frame, ``tau = R^T tau_s``).

Method
------
The equations are made polynomial (quadratic) in the state by carrying
body-frame images of space-fixed vectors as extra unknowns:

* ``V = R^T v`` for each space-fixed vector ``v`` (``mass g`` of a gravity term,
  ``tau_s``), with ``V' = V x Omega``;
* for the gravity gradient ``r_b = R^T r(t)`` and ``z_b = R^T e_z`` with
  ``r_b' = r_b x Omega + nu z_b x r_b`` and ``z_b' = z_b x Omega``.

The state (q, Omega, auxiliaries) is advanced by a Taylor-series method whose
coefficients come from Cauchy-product recurrences (``x_{k+1} = f_k / (k+1)``,
``f`` quadratic).  All arithmetic is binary fixed point on Python integers
(value = n / 2**P, ``P = ceil(dps log2 10) + 64`` bits) -- the technique mpmath
itself uses internally for its series -- because it is much faster than ``mpf``
objects in pure Python; inputs are converted exactly through mpmath and outputs
are given back as ``mpmath.mpf`` (or float64).  The order is fixed (``order``,
default ``max(20, round(1.1 dps))``) and the step is chosen from the decay of the
last two Taylor coefficients (Jorba & Zou 2005) so that the truncated tail of
every step is below ``10**-(dps+3)`` relative to the size of each group of
unknowns (q: 1; Omega: max(|Omega|, a rate sqrt(|torque| / I_min) built from the
torque parameters); auxiliaries: their constant norms).  A step too long for the
tolerance is shortened by rescaling its coefficients (``X_k -> X_k s^k``), so no
step is ever recomputed.  Outputs between step ends come from the step's Taylor
polynomial (dense output, as accurate as the step end).  The quaternion is never
renormalised: ``|q| = 1`` is conserved to the working precision, which is itself
a check.  ``q0`` is normalised in high precision before starting.

Accuracy and cost: with ``dps=40`` a run to ``t = 10`` with ``|Omega| ~ 1..5`` takes
~0.2-1 s (about 50-130 steps of order 44) and its error is ~1e-45 (runs at
``dps=40`` and ``dps=45`` differ by ~1e-47; ``dps=30`` vs ``dps=40`` by ~1e-37); the
conserved quantities below stay constant to ~1e-48.  ``tests/test_torque_reference.py``
checks all of this with margins (1e-25).

Conserved quantities
--------------------
Independent closed formulas (computed with mpmath from (q, Omega) through the
rotation matrix ``R(q)``, not from the solver's auxiliaries):

* :func:`energy` -- ``1/2 Omega.I Omega - sum mass g.(R c)`` (gravity only);
* :func:`vertical_momentum` -- ``g_hat.(R I Omega)`` (gravity, all g parallel);
* :func:`area_integral` -- ``(I Omega).gamma`` with ``gamma = R^T(-g_hat)`` (the
  same quantity with the opposite sign: ``vertical_momentum = -area_integral``);
* :func:`kovalevskaya_integral`, :func:`goryachev_chaplygin_integral` (see their
  docstrings for the exact normalisations, verified by differentiation);
* :func:`jacobi_integral` -- gravity gradient;
* :func:`lagrange_m3` -- ``I3 Omega3`` (symmetric top, centre of mass on the axis);
* :func:`space_angular_momentum` -- ``R I Omega`` (constant for a free body;
  ``L(t) = L(0) + tau_s t`` under a constant space torque alone).

Each returns an ``mpmath.mpf`` (a 3-list of them for the vector) for one state,
or a numpy object array of them when ``q`` is (T, 4) and ``omega`` (T, 3).

Pitfall: the returned ``mpf`` carry full precision, but mpmath rounds every
arithmetic result to the *current* precision (15 digits unless changed), so
compare or combine them inside ``with mpmath.workdps(60):``.
"""

from __future__ import annotations

import math
from operator import mul

import mpmath
import numpy as np

__all__ = [
    "reference_motion",
    "reference_motion_mp",
    "energy",
    "vertical_momentum",
    "area_integral",
    "kovalevskaya_integral",
    "goryachev_chaplygin_integral",
    "jacobi_integral",
    "lagrange_m3",
    "space_angular_momentum",
    "rotation_matrix",
]

_LOG2_10 = math.log2(10.0)
_LN2 = math.log(2.0)


# ----------------------------------------------------------------------------- conversions


def _mpf(x):
    """Exact mpf of a float / int / mpf / numpy scalar (at the current precision)."""
    if isinstance(x, mpmath.mpf):
        return x
    if isinstance(x, (np.floating, np.integer)):
        x = x.item()
    return mpmath.mpf(x)


def _inertia_mp(inertia):
    """3x3 list of mpf from a (3,) or (3, 3) inertia; checks symmetry."""
    arr = np.asarray(inertia, dtype=object)
    if arr.shape == (3,):
        m = [[_mpf(arr[i]) if i == j else mpmath.mpf(0) for j in range(3)] for i in range(3)]
    elif arr.shape == (3, 3):
        m = [[_mpf(arr[i, j]) for j in range(3)] for i in range(3)]
    else:
        raise ValueError(f"inertia must be (3,) or (3, 3), got shape {arr.shape}")
    for i in range(3):
        for j in range(i):
            if m[i][j] != m[j][i]:
                raise ValueError("inertia must be symmetric")
    return m


def _vec_mp(v, n=3, name="vector"):
    arr = np.asarray(v, dtype=object).reshape(-1)
    if arr.size != n:
        raise ValueError(f"{name} must have {n} components, got {arr.size}")
    return [_mpf(a) for a in arr]


def _to_fix(x, P):
    """Nearest integer to x * 2**P (x an mpf at enough precision)."""
    return int(mpmath.nint(mpmath.ldexp(x, P)))


def _from_fix(n, P):
    """mpf equal to n / 2**P exactly."""
    with mpmath.workprec(max(n.bit_length(), 1) + 8):
        return mpmath.ldexp(mpmath.mpf(n), -P)


# ----------------------------------------------------------------------------- rotations (mpmath)


def rotation_matrix(q):
    """R(q) (list of 3 rows of mpf) for a quaternion (w, x, y, z); q is normalised first."""
    w, x, y, z = (_mpf(a) for a in q)
    n2 = w * w + x * x + y * y + z * z
    s = 2 / n2
    return [
        [1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y)],
        [s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x)],
        [s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y)],
    ]


def _matvec(A, v):
    return [A[i][0] * v[0] + A[i][1] * v[1] + A[i][2] * v[2] for i in range(3)]


def _matTvec(A, v):
    return [A[0][i] * v[0] + A[1][i] * v[1] + A[2][i] * v[2] for i in range(3)]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _norm(v):
    return mpmath.sqrt(_dot(v, v))


# ----------------------------------------------------------------------------- the Taylor integrator


def _normalise_gravity(gravity):
    if gravity is None:
        return []
    if isinstance(gravity, tuple) and len(gravity) == 3 and not hasattr(gravity[0], "__len__"):
        gravity = [gravity]  # a single (mass, c, g) term
    out = []
    for term in gravity:
        mass, c, g = term
        out.append((_mpf(mass), _vec_mp(c, name="c"), _vec_mp(g, name="g")))
    return out


class _System:
    """The quadratic ODE system, in fixed point with P fractional bits."""

    def __init__(self, inertia, q0, omega0, gravity, nu, body_torque, space_torque, P):
        self.P = P
        I = _inertia_mp(inertia)
        Iinv = mpmath.inverse(mpmath.matrix(I))
        Iinv = [[Iinv[i, j] for j in range(3)] for i in range(3)]
        self.I = [[_to_fix(I[i][j], P) for j in range(3)] for i in range(3)]
        self.Iinv = [[_to_fix(Iinv[i][j], P) for j in range(3)] for i in range(3)]

        q = _vec_mp(q0, 4, "q0")
        nq = mpmath.sqrt(sum(a * a for a in q))
        if nq == 0:
            raise ValueError("q0 must be non-zero")
        q = [a / nq for a in q]
        R = rotation_matrix(q)
        om = _vec_mp(omega0, name="omega0")

        self.q0 = [_to_fix(a, P) for a in q]
        self.w0 = [_to_fix(a, P) for a in om]

        # space-fixed vectors: gravity terms grouped by their (exact) g; torque A V, A = sum mass [c]x
        groups = {}
        for mass, c, g in _normalise_gravity(gravity):
            key = tuple(g)
            A = groups.setdefault(key, [[mpmath.mpf(0)] * 3 for _ in range(3)])
            cx = [[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]]
            for i in range(3):
                for j in range(3):
                    A[i][j] += mass * cx[i][j]
        self.aux = []  # list of (V0 fixed (3,), A fixed (3x3) or None for identity, scale float)
        torque_bound = mpmath.mpf(0)
        for key, A in groups.items():
            V = _matTvec(R, list(key))
            gn = _norm(list(key))
            self.aux.append(
                ([_to_fix(a, P) for a in V], [[_to_fix(A[i][j], P) for j in range(3)] for i in range(3)], float(gn))
            )
            torque_bound += mpmath.sqrt(sum(A[i][j] ** 2 for i in range(3) for j in range(3))) * gn
        if space_torque is not None:
            ts = _vec_mp(space_torque, name="space_torque")
            V = _matTvec(R, ts)
            tn = _norm(ts)
            if tn != 0:
                self.aux.append(([_to_fix(a, P) for a in V], None, float(tn)))
                torque_bound += tn
        self.tb = None
        if body_torque is not None:
            tb = _vec_mp(body_torque, name="body_torque")
            if any(a != 0 for a in tb):
                self.tb = [_to_fix(a, P) for a in tb]
                torque_bound += _norm(tb)
        self.gg = None
        if nu is not None and _mpf(nu) != 0:
            nu = _mpf(nu)
            r0 = [R[0][0], R[0][1], R[0][2]]  # R^T e_x
            z0 = [R[2][0], R[2][1], R[2][2]]  # R^T e_z
            self.gg = (
                _to_fix(nu, P),
                _to_fix(3 * nu * nu, P),
                [_to_fix(a, P) for a in r0],
                [_to_fix(a, P) for a in z0],
            )
            imax = max(abs(I[i][j]) for i in range(3) for j in range(3))
            torque_bound += 3 * nu * nu * imax
        # characteristic angular rate: sets the scale of Omega for the error control
        imin = min(mpmath.eig(mpmath.matrix(I))[0], key=lambda e: mpmath.re(e))
        imin = mpmath.re(imin)
        if imin <= 0:
            raise ValueError("inertia must be positive definite")
        rate = float(mpmath.sqrt(torque_bound / imin))
        if self.gg is not None:
            rate = max(rate, abs(float(nu)))
        self.rate = max(rate, max(abs(float(a)) for a in om))

    # -------------------------------------------------------------------------
    def series(self, state, h, N):
        """Taylor coefficients X_0..X_N (scaled by h^k) of every unknown at `state` with step h (fixed)."""
        P = self.P
        P2 = 2 * P
        I = self.I
        Iinv = self.Iinv
        qs, ws, auxs, ggs = state
        qw, qx, qy, qz = ([a] for a in qs)
        W0, W1, W2 = ([a] for a in ws)
        M0, M1, M2 = [], [], []
        aux = [([v[0]], [v[1]], [v[2]]) for v in auxs]
        auxA = [a[1] for a in self.aux]
        tb = self.tb
        gg = self.gg
        if gg is not None:
            nu, c3nu2 = gg[0], gg[1]
            r = [[a] for a in ggs[0]]
            zb = [[a] for a in ggs[1]]
            Ir = [[], [], []]
        I00, I01, I02 = I[0]
        I10, I11, I12 = I[1]
        I20, I21, I22 = I[2]
        J00, J01, J02 = Iinv[0]
        J10, J11, J12 = Iinv[1]
        J20, J21, J22 = Iinv[2]

        for k in range(N):
            hk = h // (k + 1)
            hk2 = h // (2 * (k + 1))
            a0, a1, a2 = W0[k], W1[k], W2[k]
            M0.append((I00 * a0 + I01 * a1 + I02 * a2) >> P)
            M1.append((I10 * a0 + I11 * a1 + I12 * a2) >> P)
            M2.append((I20 * a0 + I21 * a1 + I22 * a2) >> P)
            # quaternion: q' = 1/2 q (x) (0, W)
            rW0 = W0[::-1]
            rW1 = W1[::-1]
            rW2 = W2[::-1]
            dw = -(sum(map(mul, qx, rW0)) + sum(map(mul, qy, rW1)) + sum(map(mul, qz, rW2)))
            dx = sum(map(mul, qw, rW0)) + sum(map(mul, qy, rW2)) - sum(map(mul, qz, rW1))
            dy = sum(map(mul, qw, rW1)) - sum(map(mul, qx, rW2)) + sum(map(mul, qz, rW0))
            dz = sum(map(mul, qw, rW2)) + sum(map(mul, qx, rW1)) - sum(map(mul, qy, rW0))
            # Euler: M' = M x W + tau  (double scale)
            f0 = sum(map(mul, M1, rW2)) - sum(map(mul, M2, rW1))
            f1 = sum(map(mul, M2, rW0)) - sum(map(mul, M0, rW2))
            f2 = sum(map(mul, M0, rW1)) - sum(map(mul, M1, rW0))
            if tb is not None and k == 0:
                f0 += tb[0] << P
                f1 += tb[1] << P
                f2 += tb[2] << P
            new_aux = []
            for (V0, V1, V2), A in zip(aux, auxA):
                v0, v1, v2 = V0[k], V1[k], V2[k]
                if A is None:
                    f0 += v0 << P
                    f1 += v1 << P
                    f2 += v2 << P
                else:
                    f0 += A[0][0] * v0 + A[0][1] * v1 + A[0][2] * v2
                    f1 += A[1][0] * v0 + A[1][1] * v1 + A[1][2] * v2
                    f2 += A[2][0] * v0 + A[2][1] * v1 + A[2][2] * v2
                # V' = V x W
                new_aux.append(
                    (
                        sum(map(mul, V1, rW2)) - sum(map(mul, V2, rW1)),
                        sum(map(mul, V2, rW0)) - sum(map(mul, V0, rW2)),
                        sum(map(mul, V0, rW1)) - sum(map(mul, V1, rW0)),
                    )
                )
            if gg is not None:
                R0, R1, R2 = r
                Z0, Z1, Z2 = zb
                b0, b1, b2 = R0[k], R1[k], R2[k]
                Ir[0].append((I00 * b0 + I01 * b1 + I02 * b2) >> P)
                Ir[1].append((I10 * b0 + I11 * b1 + I12 * b2) >> P)
                Ir[2].append((I20 * b0 + I21 * b1 + I22 * b2) >> P)
                rI0, rI1, rI2 = Ir[0][::-1], Ir[1][::-1], Ir[2][::-1]
                # torque 3 nu^2 r x (I r)
                t0 = sum(map(mul, R1, rI2)) - sum(map(mul, R2, rI1))
                t1 = sum(map(mul, R2, rI0)) - sum(map(mul, R0, rI2))
                t2 = sum(map(mul, R0, rI1)) - sum(map(mul, R1, rI0))
                f0 += (c3nu2 * t0) >> P
                f1 += (c3nu2 * t1) >> P
                f2 += (c3nu2 * t2) >> P
                rR0, rR1, rR2 = R0[::-1], R1[::-1], R2[::-1]
                # r' = r x W + nu z x r ; z' = z x W
                zr0 = sum(map(mul, Z1, rR2)) - sum(map(mul, Z2, rR1))
                zr1 = sum(map(mul, Z2, rR0)) - sum(map(mul, Z0, rR2))
                zr2 = sum(map(mul, Z0, rR1)) - sum(map(mul, Z1, rR0))
                dr0 = sum(map(mul, R1, rW2)) - sum(map(mul, R2, rW1)) + ((nu * zr0) >> P)
                dr1 = sum(map(mul, R2, rW0)) - sum(map(mul, R0, rW2)) + ((nu * zr1) >> P)
                dr2 = sum(map(mul, R0, rW1)) - sum(map(mul, R1, rW0)) + ((nu * zr2) >> P)
                dz0 = sum(map(mul, Z1, rW2)) - sum(map(mul, Z2, rW1))
                dz1 = sum(map(mul, Z2, rW0)) - sum(map(mul, Z0, rW2))
                dz2 = sum(map(mul, Z0, rW1)) - sum(map(mul, Z1, rW0))
            # Omega' = I^-1 M'
            g0 = (J00 * f0 + J01 * f1 + J02 * f2) >> P2
            g1 = (J10 * f0 + J11 * f1 + J12 * f2) >> P2
            g2 = (J20 * f0 + J21 * f1 + J22 * f2) >> P2
            # append order k+1
            qw.append((hk2 * dw) >> P2)
            qx.append((hk2 * dx) >> P2)
            qy.append((hk2 * dy) >> P2)
            qz.append((hk2 * dz) >> P2)
            W0.append((hk * g0) >> P)
            W1.append((hk * g1) >> P)
            W2.append((hk * g2) >> P)
            for (V0, V1, V2), (d0, d1, d2) in zip(aux, new_aux):
                V0.append((hk * d0) >> P2)
                V1.append((hk * d1) >> P2)
                V2.append((hk * d2) >> P2)
            if gg is not None:
                R0.append((hk * dr0) >> P2)
                R1.append((hk * dr1) >> P2)
                R2.append((hk * dr2) >> P2)
                Z0.append((hk * dz0) >> P2)
                Z1.append((hk * dz1) >> P2)
                Z2.append((hk * dz2) >> P2)
        groups = [("q", [qw, qx, qy, qz]), ("w", [W0, W1, W2])]
        groups += [("aux", list(v)) for v in aux]
        if gg is not None:
            groups += [("r", r), ("z", zb)]
        return groups

    def scales(self, state):
        """Size of each group of unknowns for the relative error control (floats)."""
        P = self.P
        wmax = max(abs(a) for a in state[1])
        w = max(math.ldexp(float(wmax), -P), self.rate)
        out = [1.0, w] + [a[2] for a in self.aux]
        if self.gg is not None:
            out += [1.0, 1.0]
        return out


def _log_abs_max(col, P):
    m = max(abs(a) for a in col)
    return math.log(m) - P * _LN2 if m else -math.inf


def _pack(groups):
    """state tuple (q, w, aux, gg) from series groups, taking each unknown's coefficient list."""
    q = groups[0][1]
    w = groups[1][1]
    aux = [g[1] for g in groups if g[0] == "aux"]
    gg = [g[1] for g in groups if g[0] in ("r", "z")]
    return q, w, aux, gg


def _sum_series(coeffs):
    return sum(coeffs)


def _horner(coeffs, tau, P):
    val = coeffs[-1]
    for c in reversed(coeffs[:-1]):
        val = c + ((val * tau) >> P)
    return val


def _eval_state(groups, tau, P):
    """State (q, w, aux, gg) of fixed ints at tau in [0, 1] (tau fixed point, None for tau = 1)."""
    f = _sum_series if tau is None else (lambda c: _horner(c, tau, P))
    q, w, aux, gg = _pack(groups)
    return ([f(c) for c in q], [f(c) for c in w], [[f(c) for c in v] for v in aux], [[f(c) for c in v] for v in gg])


def _rescale(groups, s, P):
    """Coefficients for the step s*h from those for h (s fixed point, 0 < s <= 1)."""
    out = []
    for name, comps in groups:
        new = []
        for c in comps:
            pw = 1 << P
            nc = []
            for a in c:
                nc.append((a * pw) >> P)
                pw = (pw * s) >> P
            new.append(nc)
        out.append((name, new))
    return out


def _integrate(system, t_fix, N, log_eps, safety=0.85, stats=None):
    """Advance from t=0; return states (fixed) at the sorted fixed-point times t_fix (>= 0)."""
    P = system.P
    state = (
        system.q0,
        system.w0,
        [a[0] for a in system.aux],
        [system.gg[2], system.gg[3]] if system.gg is not None else [],
    )
    t = 0
    results = []
    idx = 0
    while idx < len(t_fix) and t_fix[idx] == 0:
        results.append(state)
        idx += 1
    if idx == len(t_fix):
        return results
    # initial trial step: a tenth of the characteristic time, grown or shrunk by the controller
    h_try = 0.2 / (system.rate + 1e-300) if system.rate > 0 else float(math.ldexp(t_fix[-1], -P))
    nsteps = 0
    while idx < len(t_fix):
        remaining = t_fix[-1] - t
        h = min(int(math.ldexp(h_try, P)), remaining)
        h = max(h, 1)
        groups = system.series(state, h, N)
        scales = system.scales(state)
        # largest admissible step from the last two coefficients (in units of h)
        lrho = math.inf
        for (_name, comps), sc in zip(groups, scales):
            for k in (N - 1, N):
                la = _log_abs_max([c[k] for c in comps], P)
                if la == -math.inf:
                    continue
                lrho = min(lrho, (log_eps + math.log(sc) - la) / k)
        rho = math.exp(lrho) * safety if lrho < math.inf else math.inf
        if rho < 1.0:
            s = int(math.ldexp(rho, P))
            groups = _rescale(groups, s, P)
            h = (h * s) >> P
            h_next = math.ldexp(h, -P) * 1.15
        else:
            h_next = math.ldexp(h, -P) * min(rho, 3.0)
        h_try = h_next
        t_new = t + h
        while idx < len(t_fix) and t_fix[idx] <= t_new:
            if t_fix[idx] == t_new:
                results.append(_eval_state(groups, None, P))
            else:
                tau = ((t_fix[idx] - t) << P) // h
                results.append(_eval_state(groups, tau, P))
            idx += 1
        state = _eval_state(groups, None, P)
        t = t_new
        nsteps += 1
    if stats is not None:
        stats["steps"] = nsteps
    return results


def reference_motion_mp(
    inertia,
    q0,
    omega0,
    t,
    *,
    gravity=None,
    gravity_gradient=None,
    body_torque=None,
    space_torque=None,
    dps=40,
    order=None,
    stats=None,
):
    """Like :func:`reference_motion` but returns lists of mpmath numbers at full working precision.

    Returns ``(q, omega)``: ``q[i]`` a list of 4 ``mpf`` and ``omega[i]`` a list of 3, for each
    requested time, in the order given.  ``order`` overrides the Taylor order (default
    ``max(20, round(1.1 dps))``); ``stats`` (a dict) receives the number of steps.
    """
    dps = int(dps)
    if dps < 15:
        raise ValueError("dps must be >= 15")
    P = int(math.ceil(dps * _LOG2_10)) + 64
    N = int(order) if order is not None else max(20, round(1.1 * dps))
    if N < 8:
        raise ValueError("order must be >= 8")
    log_eps = -(dps + 3) * math.log(10.0)
    tt = np.atleast_1d(np.asarray(t, dtype=float))
    if tt.ndim != 1:
        raise ValueError("t must be a scalar or a 1-D array")
    if not np.all(np.isfinite(tt)) or np.any(tt < 0):
        raise ValueError("times must be finite and >= 0")
    with mpmath.workprec(P + 64):
        system = _System(inertia, q0, omega0, gravity, gravity_gradient, body_torque, space_torque, P)
        t_fix_all = [_to_fix(mpmath.mpf(float(a)), P) for a in tt]
    uniq = sorted(set(t_fix_all))
    states = _integrate(system, uniq, N, log_eps, stats=stats)
    by_t = dict(zip(uniq, states))
    q_out, w_out = [], []
    for tf in t_fix_all:
        st = by_t[tf]
        q_out.append([_from_fix(a, P) for a in st[0]])
        w_out.append([_from_fix(a, P) for a in st[1]])
    return q_out, w_out


def reference_motion(
    inertia, q0, omega0, t, *, gravity=None, gravity_gradient=None, body_torque=None, space_torque=None, dps=40
):
    """High-precision motion of a rigid body under torque.

    Parameters
    ----------
    inertia : (3,) or (3, 3)
        Inertia tensor about the body origin, body frame (symmetric positive definite).
    q0 : (4,)
        Initial attitude, scalar-first (w, x, y, z); normalised in high precision.
    omega0 : (3,)
        Initial BODY angular velocity.
    t : float or 1-D array
        Output times >= 0, in any order (repeats allowed).
    gravity : None, (mass, c, g) or list of such tuples
        Uniform gravity terms, summed: ``tau = c x (mass R^T g)``.
    gravity_gradient : None or float
        Orbital rate ``nu`` of the circular orbit in the space x-y plane.
    body_torque, space_torque : None or (3,)
        Constant torque in the body frame / in the space frame.
    dps : int
        Decimal digits of the computation (local tolerance ``10**-(dps+3)``).

    Returns
    -------
    q : (T, 4) float64, omega : (T, 3) float64
        Attitude quaternions and body angular velocities, correctly rounded from the
        high-precision values (``q`` has unit norm to the working precision).
    """
    q, w = reference_motion_mp(
        inertia,
        q0,
        omega0,
        t,
        gravity=gravity,
        gravity_gradient=gravity_gradient,
        body_torque=body_torque,
        space_torque=space_torque,
        dps=dps,
    )
    qa = np.array([[float(a) for a in row] for row in q], dtype=float).reshape(-1, 4)
    wa = np.array([[float(a) for a in row] for row in w], dtype=float).reshape(-1, 3)
    return qa, wa


# ----------------------------------------------------------------------------- conserved quantities


def _batched(fn):
    """Let fn(inertia, q, omega, ...) take one state or a batch (T, 4) / (T, 3)."""

    def wrapper(inertia, q, omega, *args, **kwargs):
        qa = np.asarray(q, dtype=object)
        if qa.ndim == 2:
            wa = np.asarray(omega, dtype=object)
            return np.array([fn(inertia, qa[i], wa[i], *args, **kwargs) for i in range(qa.shape[0])], dtype=object)
        return fn(inertia, q, omega, *args, **kwargs)

    wrapper.__name__ = fn.__name__
    wrapper.__qualname__ = fn.__qualname__
    wrapper.__doc__ = fn.__doc__
    return wrapper


def _common(inertia, q, omega):
    I = _inertia_mp(inertia)
    qv = _vec_mp(q, 4, "q")
    w = _vec_mp(omega, name="omega")
    return I, rotation_matrix(qv), w


@_batched
def energy(inertia, q, omega, gravity=None, *, dps=50):
    """``1/2 Omega.I Omega + sum_k U_k`` with ``U_k = -mass_k g_k.(R c_k)`` (gravity terms).

    Conserved under any combination of gravity terms (not under the gravity gradient or a
    constant torque).  Computed in mpmath at ``dps`` digits from R(q).
    """
    with mpmath.workdps(dps):
        I, R, w = _common(inertia, q, omega)
        e = _dot(w, _matvec(I, w)) / 2
        for mass, c, g in _normalise_gravity(gravity):
            e -= mass * _dot(g, _matvec(R, c))
        return +e


@_batched
def space_angular_momentum(inertia, q, omega, *, dps=50):
    """Angular momentum in the space frame ``L = R I Omega`` (list of 3 mpf).

    Constant for a free body; ``dL/dt = tau_space`` in general, so ``L(t) = L(0) + tau_s t``
    under a constant space torque alone.
    """
    with mpmath.workdps(dps):
        I, R, w = _common(inertia, q, omega)
        return [+a for a in _matvec(R, _matvec(I, w))]


@_batched
def vertical_momentum(inertia, q, omega, g, *, dps=50):
    """``g_hat.(R I Omega)``: the component of the space angular momentum along gravity.

    Conserved under gravity (any number of terms sharing the direction of ``g``).
    Equal to ``-area_integral``.
    """
    with mpmath.workdps(dps):
        I, R, w = _common(inertia, q, omega)
        gv = _vec_mp(g, name="g")
        gh = [a / _norm(gv) for a in gv]
        return +_dot(gh, _matvec(R, _matvec(I, w)))


@_batched
def area_integral(inertia, q, omega, g, *, dps=50):
    """``(I Omega).gamma`` with ``gamma = R^T(-g_hat)`` the unit "up" vector in the body frame."""
    with mpmath.workdps(dps):
        I, R, w = _common(inertia, q, omega)
        gv = _vec_mp(g, name="g")
        gam = [-a / _norm(gv) for a in _matTvec(R, gv)]
        return +_dot(_matvec(I, w), gam)


def _gamma_mu(inertia, q, omega, mass, c, g):
    I, R, w = _common(inertia, q, omega)
    gv = _vec_mp(g, name="g")
    gn = _norm(gv)
    gam = [-a / gn for a in _matTvec(R, gv)]
    cv = _vec_mp(c, name="c")
    I3 = I[2][2]
    k = _mpf(mass) * gn / I3
    return I, w, gam, cv, k


@_batched
def kovalevskaya_integral(inertia, q, omega, mass, c, g, *, dps=50):
    """Kovalevskaya's integral for ``I = diag(2, 2, 1) I3``, centre of mass ``c = (x0, y0, 0)``.

    With ``omega = Omega`` (body), ``gamma = R^T(-g_hat)`` (unit up vector, body frame),
    ``z = omega1 + i omega2``, ``xi = gamma1 + i gamma2`` and ``kappa = mass |g| / I3``::

        K = | z**2 - kappa (x0 + i y0) xi |**2

    which for ``c = (x0, 0, 0)`` is, with ``mu = mass |g| x0 / I3``::

        K = (omega1**2 - omega2**2 - mu gamma1)**2 + (2 omega1 omega2 - mu gamma2)**2.

    Derivation (torque ``tau = mass |g| gamma x c``): ``2 z' = -i omega3 z + i mu gamma3``,
    ``xi' = -i omega3 xi + i gamma3 z``, so ``(z**2 - mu xi)' = -i omega3 (z**2 - mu xi)``.
    The inertia must be proportional to diag(2, 2, 1) for K to be conserved (not checked).
    """
    with mpmath.workdps(dps):
        I, w, gam, cv, kap = _gamma_mu(inertia, q, omega, mass, c, g)
        z = mpmath.mpc(w[0], w[1])
        xi = mpmath.mpc(gam[0], gam[1])
        val = z * z - kap * mpmath.mpc(cv[0], cv[1]) * xi
        return +(val.real**2 + val.imag**2)


@_batched
def goryachev_chaplygin_integral(inertia, q, omega, mass, c, g, *, dps=50):
    """Goryachev--Chaplygin integral for ``I = diag(4, 4, 1) I3``, centre of mass ``(x0, y0, 0)``.

    With ``gamma = R^T(-g_hat)`` and ``kappa = mass |g| / I3``::

        G = omega3 (omega1**2 + omega2**2) - kappa gamma3 (x0 omega1 + y0 omega2)

    i.e. for ``c = (x0, 0, 0)``, ``G = omega3 (omega1**2 + omega2**2) - mu omega1 gamma3`` with
    ``mu = mass |g| x0 / I3`` (note the MINUS sign with gamma the up vector).  Along the motion
    ``dG/dt = -(kappa / (4 I3)) (x0 omega2 - y0 omega1) (I Omega).gamma``, so G is conserved only on
    the level ``area_integral = (I Omega).gamma = 0``.
    """
    with mpmath.workdps(dps):
        I, w, gam, cv, kap = _gamma_mu(inertia, q, omega, mass, c, g)
        return +(w[2] * (w[0] ** 2 + w[1] ** 2) - kap * gam[2] * (cv[0] * w[0] + cv[1] * w[1]))


def _jacobi(inertia, q, omega, nu, t, *, dps=50):
    with mpmath.workdps(dps):
        I, R, w = _common(inertia, q, omega)
        nu = _mpf(nu)
        t = _mpf(t)
        rhat = [mpmath.cos(nu * t), mpmath.sin(nu * t), mpmath.mpf(0)]
        rb = _matTvec(R, rhat)
        Iw = _matvec(I, w)
        L = _matvec(R, Iw)
        return +(_dot(w, Iw) / 2 - nu * L[2] + 3 * nu * nu * _dot(rb, _matvec(I, rb)) / 2)


def jacobi_integral(inertia, q, omega, nu, t, *, dps=50):
    """Jacobi integral of the gravity-gradient problem (orbit rate ``nu`` about space z) at time ``t``::

        J = 1/2 Omega.I Omega - nu e_z.(R I Omega) + 3/2 nu**2 r_b.I r_b,   r_b = R^T r_hat(t),

    ``r_hat(t) = (cos nu t, sin nu t, 0)``.  ``3/2 nu**2 r_b.I r_b`` is the gravity-gradient
    potential (its torque is ``-dV/dtheta = 3 nu**2 r_b x I r_b``) and ``-nu e_z.L`` comes from
    going over to the frame rotating with the orbit.  dJ/dt = 0 exactly: the torque's power
    ``Omega.tau`` cancels the change of the potential through ``r_b x Omega``, and what remains,
    ``3 nu**3 z_b.(r_b x I r_b)`` from ``nu z_b x r_b``, cancels ``-nu e_z.tau_space``.

    One state: q (4,), omega (3,), t scalar; or a batch q (T, 4), omega (T, 3), t (T,).
    """
    qa = np.asarray(q, dtype=object)
    if qa.ndim == 2:
        wa = np.asarray(omega, dtype=object)
        ta = np.broadcast_to(np.asarray(t, dtype=object), (qa.shape[0],))
        return np.array([_jacobi(inertia, qa[i], wa[i], nu, ta[i], dps=dps) for i in range(qa.shape[0])], dtype=object)
    return _jacobi(inertia, q, omega, nu, t, dps=dps)


def lagrange_m3(inertia, omega, *, dps=50):
    """``I3 Omega3`` (uses ``inertia[2, 2]``): conserved for a symmetric top (I1 = I2, no products
    of inertia with the axis) whose torques are about axes perpendicular to body z, e.g. gravity with
    the centre of mass on the body z axis (Lagrange top)."""
    with mpmath.workdps(dps):
        I = _inertia_mp(inertia)
        wa = np.asarray(omega, dtype=object)
        if wa.ndim == 2:
            return np.array([+(I[2][2] * _mpf(row[2])) for row in wa], dtype=object)
        w = _vec_mp(omega, name="omega")
        return +(I[2][2] * w[2])
