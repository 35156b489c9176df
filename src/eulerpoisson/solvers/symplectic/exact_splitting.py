r"""Splitting with the exact free-body flow: ``scheme="exact_splitting"`` (order 2) and ``"exact_splitting4"``.

For a body under a torque that depends only on the time and the attitude,
:math:`\boldsymbol\tau(t, R)` (gravity, gravity gradient, constant torques),
the equations split into the free rigid body, whose flow
:math:`\varphi^{\text{free}}_h` is known in closed form
(:func:`eulerpoisson.solvers.exact.kernels.free_flow`: Jacobi elliptic
functions and Carlson's integral, to round-off), and the *kick*

.. math:: \dot R = 0, \qquad \dot{\mathbf M} = \boldsymbol\tau(t, R),

whose flow is :math:`\mathbf M \leftarrow \mathbf M + h\,\boldsymbol\tau(t, R)`
(exact: the right-hand side is constant along it). Strang's composition

.. math:: \Phi_h = \varphi^{\text{kick}}_{h/2}\circ\varphi^{\text{free}}_h\circ\varphi^{\text{kick}}_{h/2}

is of order 2; Yoshida's triple jump
:math:`\Phi_{w_1h}\Phi_{w_0h}\Phi_{w_1h}`, :math:`w_1 = 1/(2-2^{1/3})`,
:math:`w_0 = 1-2w_1`, of order 4. For a potential torque
(:math:`\boldsymbol\tau = -\partial U/\partial R` in the body frame: gravity,
gravity gradient) both flows are Hamiltonian and the compositions are
symplectic and Poisson maps: the energy error stays bounded over long times
(no drift), and :math:`\mathbf m\cdot\hat{\mathbf g}` is conserved to
round-off for gravity (both flows conserve it). For a time-dependent torque
the time advances with the free flow and the kick uses the current time. The
inertia is diagonalized once (:math:`I = PDP^T`); the kernel works in the
principal frame. The splitting error vanishes with the torque: without one the
method is the exact solution.

References
----------
E. Celledoni, F. Fassò, N. Säfström and A. Zanna, "The exact computation of
the free rigid body motion and its use in splitting methods", SIAM J. Sci.
Comput. 30 (2008) 2084-2112. H. Yoshida, "Construction of higher order
symplectic integrators", Phys. Lett. A 150 (1990) 262-268. E. Hairer, C.
Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed. (2006), II.5
and VII.5.
"""

from __future__ import annotations

import math

import numpy as np

from ...numerics.quaternion import qmul_components, rotate_inverse
from ...util.jit import USE_NUMBA, kernel_array
from ..exact import kernels as _ek

free_flow = _ek.free_flow

__all__ = ["composition", "run_exact_splitting", "ORDERS"]

#: orders of the compositions
ORDERS = (2, 4)


def composition(order: int) -> tuple[np.ndarray, np.ndarray]:
    r"""Kick and flow fractions ``(c, d)`` of the composition of order 2 or 4.

    The step is: kick :math:`c_0h`, flow :math:`d_0h`, kick :math:`c_1h`, ...,
    flow :math:`d_{s-1}h`, kick :math:`c_sh`; :math:`\sum c = \sum d = 1`.
    """
    if order == 2:
        return np.array([0.5, 0.5]), np.array([1.0])
    if order == 4:
        w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
        w0 = 1.0 - 2.0 * w1
        return np.array([0.5 * w1, 0.5 * (w1 + w0), 0.5 * (w0 + w1), 0.5 * w1]), np.array([w1, w0, w1])
    raise ValueError(f"exact splitting: order must be 2 or 4, got {order}")


def _torque(qw, qx, qy, qz, t, D, tau0, S, L, nu, kappa, out):
    """Principal-frame torque at attitude q (principal axes to space) and time t."""
    out[0] = tau0[0]
    out[1] = tau0[1]
    out[2] = tau0[2]
    for i in range(S.shape[0]):
        v0, v1, v2 = rotate_inverse(qw, qx, qy, qz, S[i, 0], S[i, 1], S[i, 2])
        out[0] += L[i, 0, 0] * v0 + L[i, 0, 1] * v1 + L[i, 0, 2] * v2
        out[1] += L[i, 1, 0] * v0 + L[i, 1, 1] * v1 + L[i, 1, 2] * v2
        out[2] += L[i, 2, 0] * v0 + L[i, 2, 1] * v1 + L[i, 2, 2] * v2
    if kappa != 0.0:
        ph = nu * t
        r0, r1, r2 = rotate_inverse(qw, qx, qy, qz, math.cos(ph), math.sin(ph), 0.0)
        i0 = D[0] * r0
        i1 = D[1] * r1
        i2 = D[2] * r2
        out[0] += kappa * (r1 * i2 - r2 * i1)
        out[1] += kappa * (r2 * i0 - r0 * i2)
        out[2] += kappa * (r0 * i1 - r1 * i0)


def split_body(D, q0, M0, tau0, S, L, nu, kappa, times, dt, c, d, qout, Mout, cst, tau):
    """Advance one body (principal frame) through the output times (one sign, sorted by |t|); returns steps."""
    qw, qx, qy, qz = q0[0], q0[1], q0[2], q0[3]
    m0, m1, m2 = M0[0], M0[1], M0[2]
    tcur = 0.0
    steps = 0
    ns = d.shape[0]
    for j in range(times.shape[0]):
        Lint = times[j] - tcur
        if Lint != 0.0:
            if math.isfinite(dt):
                N = max(1, int(math.ceil(abs(Lint) / dt * (1.0 - 1e-12))))
            else:
                N = 1
            h = Lint / N
            for _ in range(N):
                tt = tcur
                for s in range(ns + 1):
                    _torque(qw, qx, qy, qz, tt, D, tau0, S, L, nu, kappa, tau)
                    ch = c[s] * h
                    m0 += ch * tau[0]
                    m1 += ch * tau[1]
                    m2 += ch * tau[2]
                    if s == ns:
                        break
                    dh = d[s] * h
                    r0, r1, r2, rw, rx, ry, rz = free_flow(D[0], D[1], D[2], m0, m1, m2, dh, cst)
                    m0, m1, m2 = r0, r1, r2
                    qw, qx, qy, qz = qmul_components(qw, qx, qy, qz, rw, rx, ry, rz)
                    nrm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
                    qw /= nrm
                    qx /= nrm
                    qy /= nrm
                    qz /= nrm
                    tt = tt + dh
                tcur = tcur + h
                steps += 1
            tcur = times[j]
        qout[j, 0] = qw
        qout[j, 1] = qx
        qout[j, 2] = qy
        qout[j, 3] = qz
        Mout[j, 0] = m0
        Mout[j, 1] = m1
        Mout[j, 2] = m2
    return steps


if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    _torque = _njit(cache=True, nogil=True)(_torque)
    split_body = _njit(cache=True, nogil=True)(split_body)


def run_exact_splitting(moments, qp0, Mp0, data, t, dt, order):
    """Integrate a batch in the principal frame.

    Parameters
    ----------
    moments : ndarray (B, 3)
    qp0 : ndarray (B, 4)
        Attitudes of the principal axes.
    Mp0 : ndarray (B, 3)
        Principal-frame body angular momenta.
    data : FlatPolynomialTorque
        The torque in the principal frame (:meth:`~eulerpoisson.torques.PolynomialTorque.flatten`, ``in_frame``).
    t : ndarray (T,)
    dt : float
    order : int (2 or 4)

    Returns
    -------
    q (B, T, 4), M (B, T, 3), steps (int, total)
    """
    c, d = composition(order)
    # C-contiguous writeable float64 (a copy only where needed: the moments of one body are a read-only broadcast
    # view): one signature of split_body, the one the warm-up compiles
    moments, qp0, Mp0, tau0, S, L = (kernel_array(x) for x in (moments, qp0, Mp0, data.tau0, data.S, data.L))
    B = qp0.shape[0]
    T = t.shape[0]
    qout = np.empty((B, T, 4))
    Mout = np.empty((B, T, 3))
    cst = np.zeros(_ek.N_CONST)
    tau = np.zeros(3)
    steps = 0
    pos = np.flatnonzero(t >= 0)
    neg = np.flatnonzero(t < 0)
    for b in range(B):
        for idx in (pos, neg):
            if not idx.size:
                continue
            oi = idx[np.argsort(np.abs(t[idx]), kind="stable")]
            ts = kernel_array(t[oi])
            qo = np.empty((ts.shape[0], 4))
            Mo = np.empty((ts.shape[0], 3))
            steps += split_body(
                moments[b],
                qp0[b],
                Mp0[b],
                tau0[b],
                S[b],
                L[b],
                float(data.nu[b]),
                float(data.kappa[b]),
                ts,
                float(dt),
                c,
                d,
                qo,
                Mo,
                cst,
                tau,
            )
            qout[b, oi] = qo
            Mout[b, oi] = Mo
    return qout, Mout, steps
