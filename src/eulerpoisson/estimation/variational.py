r"""The free motion and its sensitivities: Taylor series of the variational equations.

For a body with inertia tensor :math:`I` (any symmetric positive-definite
matrix, in the frame of the observations) started from the identity attitude
with body angular velocity :math:`\boldsymbol\Omega_0`, this module
integrates together

.. math::

    I\dot{\boldsymbol\Omega} &= (I\boldsymbol\Omega)\times\boldsymbol\Omega,
    \qquad \dot q = \tfrac12\, q\otimes(0, \boldsymbol\Omega),\\
    I\,\delta\dot{\boldsymbol\Omega}_j &= -\,\partial_jI\,\dot{\boldsymbol\Omega}
       + (\partial_jI\,\boldsymbol\Omega + I\,\delta\boldsymbol\Omega_j)\times\boldsymbol\Omega
       + (I\boldsymbol\Omega)\times\delta\boldsymbol\Omega_j,\\
    \dot{\boldsymbol\eta}_j &= \delta\boldsymbol\Omega_j + \boldsymbol\eta_j\times\boldsymbol\Omega,

the derivatives :math:`\delta\boldsymbol\Omega_j = \partial\boldsymbol\Omega/\partial p_j`
and the body-frame rotation sensitivities :math:`\boldsymbol\eta_j`, defined by
:math:`R(t; p + \mathrm dp) = R(t; p)\,(1 + [\boldsymbol\eta_j\,\mathrm dp_j]_\times)`, for
the parameters :math:`p = (\boldsymbol\Omega_0, \text{inertia parameters})`
(:math:`\delta\boldsymbol\Omega_j(0) = \mathbf e_j` for the three components of
:math:`\boldsymbol\Omega_0`, zero for the inertia parameters;
:math:`\boldsymbol\eta_j(0) = 0`). The equation for :math:`\boldsymbol\eta` follows
from :math:`\dot R = R[\boldsymbol\Omega]_\times` (paper eq. 1.4):
:math:`[\dot{\boldsymbol\eta}]_\times = [\delta\boldsymbol\Omega]_\times + [\boldsymbol\eta]_\times[\boldsymbol\Omega]_\times - [\boldsymbol\Omega]_\times[\boldsymbol\eta]_\times`.

Every right-hand side is a polynomial (quadratic) in the unknowns, so the
Taylor coefficients follow from Cauchy products exactly as in the ``taylor``
method (Jorba & Zou 2005): order :math:`p` costs :math:`O(p^2)` per step and
per parameter. Steps are chosen on the motion (:math:`\boldsymbol\Omega`,
:math:`q`); the variational equations share its analytic continuation, so the
same steps integrate them to the same relative accuracy. The observation
times are evaluated inside the steps by Horner's rule (dense output).

Two implementations give the same results: a compiled kernel (numba, when
:data:`~eulerpoisson.util.jit.USE_NUMBA`) and a NumPy twin that vectorizes the
Cauchy sums.

References
----------
A. Jorba and M. Zou, "A software package for the numerical integration of
ODEs by means of high-order Taylor methods", Exp. Math. 14 (2005) 99-117.
Paper eq. 1.4 (kinematics), 1.6 (Euler's equations).
"""

from __future__ import annotations

import math

import numpy as np

from ..util.jit import USE_NUMBA, kernel_array

__all__ = ["propagate", "Sensitivities"]

#: taken steps are capped at this many per integration (a body spinning 10^5 turns)
MAX_STEPS = 5_000_000


class Sensitivities:
    """The motion and its derivatives at the requested times (from :func:`propagate`).

    Attributes
    ----------
    quaternion : ndarray, shape (K, 4)
        Attitude relative to the initial one, :math:`q(0) = 1`.
    omega : ndarray, shape (K, 3)
        Body angular velocity.
    eta : ndarray, shape (K, P, 3)
        Body-frame rotation sensitivities, one row per parameter.
    domega : ndarray, shape (K, P, 3)
        :math:`\\partial\\boldsymbol\\Omega/\\partial p_j`.
    steps : int
        Taylor steps taken.
    """

    __slots__ = ("quaternion", "omega", "eta", "domega", "steps")

    def __init__(self, quaternion, omega, eta, domega, steps):
        self.quaternion = quaternion
        self.omega = omega
        self.eta = eta
        self.domega = domega
        self.steps = int(steps)


def _order(tol):
    return int(math.ceil(-0.5 * math.log(tol) + 1.0))


def propagate(inertia, omega0, dinertia, tau, *, tol: float = 2.0**-52) -> Sensitivities:
    r"""Integrate the motion and its variational equations to the times ``tau``.

    Parameters
    ----------
    inertia : ndarray, shape (3, 3)
        Symmetric positive-definite inertia tensor (no check here).
    omega0 : ndarray, shape (3,)
        Body angular velocity at :math:`\tau = 0`.
    dinertia : ndarray, shape (Q, 3, 3)
        :math:`\partial I/\partial p_j` of the inertia parameters (``Q`` may be 0).
    tau : ndarray, shape (K,)
        Non-negative, non-decreasing times from the start.
    tol : float
        Relative tolerance of the Taylor steps (order and step from Jorba & Zou).

    Returns
    -------
    Sensitivities
        ``P = 3 + Q`` parameters: the components of ``omega0``, then the inertia parameters.

    Raises
    ------
    FloatingPointError
        The motion became non-finite or needed more than ``MAX_STEPS`` steps.
    """
    inertia = kernel_array(inertia)
    jinv = kernel_array(np.linalg.inv(inertia))
    omega0 = kernel_array(omega0)
    dinertia = kernel_array(np.asarray(dinertia, dtype=np.float64).reshape(-1, 3, 3))
    tau = kernel_array(tau)
    order = _order(tol)
    safety = math.exp(-0.7 / (order - 1))
    K = tau.shape[0]
    P = 3 + dinertia.shape[0]
    q = np.zeros((K, 4))
    w = np.zeros((K, 3))
    eta = np.zeros((K, P, 3))
    dw = np.zeros((K, P, 3))
    kernel = propagate_numba if USE_NUMBA else _propagate_numpy
    status, steps = kernel(inertia, jinv, dinertia, omega0, tau, order, tol, safety, MAX_STEPS, q, w, eta, dw)
    if status == 1:
        raise FloatingPointError(f"the motion needed more than {MAX_STEPS} Taylor steps")
    if status == 2:
        raise FloatingPointError("the motion became non-finite (an inertia tensor near singular?)")
    return Sensitivities(q, w, eta, dw, steps)


# ---------------------------------------------------------------------------
# NumPy twin: Cauchy sums vectorized
# ---------------------------------------------------------------------------
def _series_numpy(I, J, dI, W0, Q0, E0, D0, order):
    """Taylor coefficients (order+1, ...) of Omega, q, eta, dOmega from their values at the step start."""
    P = E0.shape[0]
    Qn = dI.shape[0]
    W = np.zeros((order + 1, 3))
    L = np.zeros((order + 1, 3))
    Q = np.zeros((order + 1, 4))
    E = np.zeros((order + 1, P, 3))
    D = np.zeros((order + 1, P, 3))
    DL = np.zeros((order + 1, P, 3))  # variation of L = I Omega: dI_j Omega + I dOmega_j
    W[0], Q[0], E[0], D[0] = W0, Q0, E0, D0
    for k in range(order):
        L[k] = I @ W[k]
        DL[k] = D[k] @ I.T
        if Qn:
            DL[k, 3:] += dI @ W[k]
        rev = W[k::-1]  # Omega[k-i], i = 0..k
        c = np.cross(L[: k + 1], rev).sum(axis=0)
        wdot = J @ c
        W[k + 1] = wdot / (k + 1)
        # variational: J[-dI wdot + sum(DL[i] x W[k-i]) + sum(L[i] x D[k-i])]
        s = np.cross(DL[: k + 1], rev[:, None, :]).sum(axis=0)
        s += np.cross(L[: k + 1, None, :], D[k::-1]).sum(axis=0)
        if Qn:
            s[3:] -= dI @ wdot
        D[k + 1] = (s @ J.T) / (k + 1)
        E[k + 1] = (D[k] + np.cross(E[: k + 1], rev[:, None, :]).sum(axis=0)) / (k + 1)
        qw, qx, qy, qz = Q[: k + 1].T
        ox, oy, oz = rev.T
        Q[k + 1, 0] = -(qx * ox + qy * oy + qz * oz).sum() / (2 * (k + 1))
        Q[k + 1, 1] = (qw * ox + qy * oz - qz * oy).sum() / (2 * (k + 1))
        Q[k + 1, 2] = (qw * oy - qx * oz + qz * ox).sum() / (2 * (k + 1))
        Q[k + 1, 3] = (qw * oz + qx * oy - qy * ox).sum() / (2 * (k + 1))
    return W, Q, E, D


def _horner(X, h):
    out = X[-1].copy()
    for k in range(X.shape[0] - 2, -1, -1):
        out = out * h + X[k]
    return out


def _step_size(W, Q, order, tol, safety, scale):
    h = math.inf
    for k in (order - 1, order):
        nrm = max(np.abs(W[k]).max() / scale, np.abs(Q[k]).max())
        if nrm > 0:
            h = min(h, (tol / nrm) ** (1.0 / k))
    return safety * h if math.isfinite(h) else 1.0


def _propagate_numpy(I, J, dI, omega0, tau, order, tol, safety, max_steps, q, w, eta, dw):
    P = eta.shape[1]
    W0 = omega0.copy()
    Q0 = np.array([1.0, 0.0, 0.0, 0.0])
    E0 = np.zeros((P, 3))
    D0 = np.zeros((P, 3))
    D0[0, 0] = D0[1, 1] = D0[2, 2] = 1.0
    scale = max(np.abs(omega0).max(), 1e-300)
    t = 0.0
    i = 0
    K = tau.shape[0]
    steps = 0
    while i < K and tau[i] <= 0.0:
        q[i], w[i], eta[i], dw[i] = Q0, W0, E0, D0
        i += 1
    while i < K:
        if steps >= max_steps:
            return 1, steps
        W, Q, E, D = _series_numpy(I, J, dI, W0, Q0, E0, D0, order)
        h = _step_size(W, Q, order, tol, safety, scale)
        if not (h > 0 and math.isfinite(h)) or not np.all(np.isfinite(W)):
            return 2, steps
        last = t + h >= tau[K - 1]
        if last:
            h = tau[K - 1] - t
        while i < K and (tau[i] <= t + h or last):
            s = tau[i] - t
            q[i] = _horner(Q, s)
            w[i] = _horner(W, s)
            eta[i] = _horner(E, s)
            dw[i] = _horner(D, s)
            i += 1
        W0, Q0, E0, D0 = _horner(W, h), _horner(Q, h), _horner(E, h), _horner(D, h)
        Q0 = Q0 / math.sqrt(Q0 @ Q0)
        t = t + h
        steps += 1
    return 0, steps


# ---------------------------------------------------------------------------
# compiled kernel: the same recurrences in scalar loops
# ---------------------------------------------------------------------------
def _propagate_loops(I, J, dI, omega0, tau, order, tol, safety, max_steps, q, w, eta, dw):
    P = eta.shape[1]
    K = tau.shape[0]
    n1 = order + 1
    W = np.zeros((n1, 3))
    L = np.zeros((n1, 3))
    Q = np.zeros((n1, 4))
    E = np.zeros((n1, P, 3))
    D = np.zeros((n1, P, 3))
    DL = np.zeros((n1, P, 3))
    for a in range(3):
        W[0, a] = omega0[a]
    Q[0, 0] = 1.0
    for a in range(3):
        D[0, a, a] = 1.0
    scale = max(abs(omega0[0]), abs(omega0[1]), abs(omega0[2]), 1e-300)
    t = 0.0
    i = 0
    steps = 0
    while i < K and tau[i] <= 0.0:
        for a in range(4):
            q[i, a] = Q[0, a]
        for a in range(3):
            w[i, a] = W[0, a]
            for j in range(P):
                eta[i, j, a] = E[0, j, a]
                dw[i, j, a] = D[0, j, a]
        i += 1
    while i < K:
        if steps >= max_steps:
            return 1, steps
        for k in range(order):
            for a in range(3):
                L[k, a] = I[a, 0] * W[k, 0] + I[a, 1] * W[k, 1] + I[a, 2] * W[k, 2]
            for j in range(P):
                for a in range(3):
                    v = I[a, 0] * D[k, j, 0] + I[a, 1] * D[k, j, 1] + I[a, 2] * D[k, j, 2]
                    if j >= 3:
                        g = j - 3
                        v += dI[g, a, 0] * W[k, 0] + dI[g, a, 1] * W[k, 1] + dI[g, a, 2] * W[k, 2]
                    DL[k, j, a] = v
            c0 = 0.0
            c1 = 0.0
            c2 = 0.0
            for m in range(k + 1):
                r = k - m
                c0 += L[m, 1] * W[r, 2] - L[m, 2] * W[r, 1]
                c1 += L[m, 2] * W[r, 0] - L[m, 0] * W[r, 2]
                c2 += L[m, 0] * W[r, 1] - L[m, 1] * W[r, 0]
            wd0 = J[0, 0] * c0 + J[0, 1] * c1 + J[0, 2] * c2
            wd1 = J[1, 0] * c0 + J[1, 1] * c1 + J[1, 2] * c2
            wd2 = J[2, 0] * c0 + J[2, 1] * c1 + J[2, 2] * c2
            inv = 1.0 / (k + 1)
            W[k + 1, 0] = wd0 * inv
            W[k + 1, 1] = wd1 * inv
            W[k + 1, 2] = wd2 * inv
            for j in range(P):
                s0 = 0.0
                s1 = 0.0
                s2 = 0.0
                e0 = 0.0
                e1 = 0.0
                e2 = 0.0
                for m in range(k + 1):
                    r = k - m
                    s0 += DL[m, j, 1] * W[r, 2] - DL[m, j, 2] * W[r, 1] + L[m, 1] * D[r, j, 2] - L[m, 2] * D[r, j, 1]
                    s1 += DL[m, j, 2] * W[r, 0] - DL[m, j, 0] * W[r, 2] + L[m, 2] * D[r, j, 0] - L[m, 0] * D[r, j, 2]
                    s2 += DL[m, j, 0] * W[r, 1] - DL[m, j, 1] * W[r, 0] + L[m, 0] * D[r, j, 1] - L[m, 1] * D[r, j, 0]
                    e0 += E[m, j, 1] * W[r, 2] - E[m, j, 2] * W[r, 1]
                    e1 += E[m, j, 2] * W[r, 0] - E[m, j, 0] * W[r, 2]
                    e2 += E[m, j, 0] * W[r, 1] - E[m, j, 1] * W[r, 0]
                if j >= 3:
                    g = j - 3
                    s0 -= dI[g, 0, 0] * wd0 + dI[g, 0, 1] * wd1 + dI[g, 0, 2] * wd2
                    s1 -= dI[g, 1, 0] * wd0 + dI[g, 1, 1] * wd1 + dI[g, 1, 2] * wd2
                    s2 -= dI[g, 2, 0] * wd0 + dI[g, 2, 1] * wd1 + dI[g, 2, 2] * wd2
                D[k + 1, j, 0] = (J[0, 0] * s0 + J[0, 1] * s1 + J[0, 2] * s2) * inv
                D[k + 1, j, 1] = (J[1, 0] * s0 + J[1, 1] * s1 + J[1, 2] * s2) * inv
                D[k + 1, j, 2] = (J[2, 0] * s0 + J[2, 1] * s1 + J[2, 2] * s2) * inv
                E[k + 1, j, 0] = (D[k, j, 0] + e0) * inv
                E[k + 1, j, 1] = (D[k, j, 1] + e1) * inv
                E[k + 1, j, 2] = (D[k, j, 2] + e2) * inv
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            for m in range(k + 1):
                r = k - m
                a0 -= Q[m, 1] * W[r, 0] + Q[m, 2] * W[r, 1] + Q[m, 3] * W[r, 2]
                a1 += Q[m, 0] * W[r, 0] + Q[m, 2] * W[r, 2] - Q[m, 3] * W[r, 1]
                a2 += Q[m, 0] * W[r, 1] - Q[m, 1] * W[r, 2] + Q[m, 3] * W[r, 0]
                a3 += Q[m, 0] * W[r, 2] + Q[m, 1] * W[r, 1] - Q[m, 2] * W[r, 0]
            half = 0.5 * inv
            Q[k + 1, 0] = a0 * half
            Q[k + 1, 1] = a1 * half
            Q[k + 1, 2] = a2 * half
            Q[k + 1, 3] = a3 * half
        h = math.inf
        for k in (order - 1, order):
            nrm = 0.0
            for a in range(3):
                nrm = max(nrm, abs(W[k, a]) / scale)
            for a in range(4):
                nrm = max(nrm, abs(Q[k, a]))
            if nrm > 0:
                h = min(h, (tol / nrm) ** (1.0 / k))
        h = safety * h if h < math.inf else 1.0
        if not (h > 0.0 and h < math.inf):
            return 2, steps
        for a in range(3):
            if not math.isfinite(W[order, a]):
                return 2, steps
        last = t + h >= tau[K - 1]
        if last:
            h = tau[K - 1] - t
        while i < K and (tau[i] <= t + h or last):
            s = tau[i] - t
            for a in range(4):
                acc = Q[order, a]
                for k in range(order - 1, -1, -1):
                    acc = acc * s + Q[k, a]
                q[i, a] = acc
            for a in range(3):
                acc = W[order, a]
                for k in range(order - 1, -1, -1):
                    acc = acc * s + W[k, a]
                w[i, a] = acc
                for j in range(P):
                    acc = E[order, j, a]
                    acd = D[order, j, a]
                    for k in range(order - 1, -1, -1):
                        acc = acc * s + E[k, j, a]
                        acd = acd * s + D[k, j, a]
                    eta[i, j, a] = acc
                    dw[i, j, a] = acd
            i += 1
        # advance the state to t + h
        for a in range(4):
            acc = Q[order, a]
            for k in range(order - 1, -1, -1):
                acc = acc * h + Q[k, a]
            Q[0, a] = acc
        nq = math.sqrt(Q[0, 0] ** 2 + Q[0, 1] ** 2 + Q[0, 2] ** 2 + Q[0, 3] ** 2)
        for a in range(4):
            Q[0, a] /= nq
        for a in range(3):
            acc = W[order, a]
            for k in range(order - 1, -1, -1):
                acc = acc * h + W[k, a]
            W[0, a] = acc
            for j in range(P):
                acc = E[order, j, a]
                acd = D[order, j, a]
                for k in range(order - 1, -1, -1):
                    acc = acc * h + E[k, j, a]
                    acd = acd * h + D[k, j, a]
                E[0, j, a] = acc
                D[0, j, a] = acd
        t = t + h
        steps += 1
    return 0, steps


if USE_NUMBA:
    from ..util.jit import lazy_njit as njit  # made when numba is first used, not at import

    propagate_numba = njit(cache=True, fastmath={"contract"})(_propagate_loops)
else:  # pragma: no cover - depends on environment
    propagate_numba = _propagate_loops
