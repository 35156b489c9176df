r"""Taylor integration of the Euler–Poisson equations under polynomial torques.

For a model with torques (:class:`~eulerpoisson.Model` whose torques have a
:meth:`~eulerpoisson.torques.Torque.polynomial` form: gravity, gravity
gradient, constant body and space torques), the state is the attitude
quaternion and the body angular velocity, :math:`(q, \boldsymbol\Omega)`,
and the torque is written with auxiliary body-frame vectors (the *Poisson
vectors*) :math:`\mathbf v_i = R^T\mathbf s_i`, :math:`\mathbf z = R^T\hat{\mathbf e}_z`,
:math:`\mathbf r = R^T\hat{\mathbf r}(t)`:

.. math::
    \dot q &= \tfrac12\,q\otimes(0, \boldsymbol\Omega), \\
    \dot{\boldsymbol\Omega} &= I^{-1}\Big((I\boldsymbol\Omega)\times\boldsymbol\Omega
        + \boldsymbol\tau_0 + \sum_i L_i\mathbf v_i + \kappa\,\mathbf r\times I\mathbf r\Big), \\
    \dot{\mathbf v}_i &= \mathbf v_i\times\boldsymbol\Omega, \qquad
    \dot{\mathbf z} = \mathbf z\times\boldsymbol\Omega, \qquad
    \dot{\mathbf r} = \mathbf r\times\boldsymbol\Omega + \nu\,\mathbf z\times\mathbf r .

Every right-hand side is a polynomial, so the Taylor coefficients of any
order follow from Cauchy products, :math:`x_{k+1} = f_k/(k+1)`, at
:math:`O(p^2)` per step (Taylor-mode automatic differentiation). The
auxiliary vectors are recomputed from :math:`q` at the start of every step
(the augmented system preserves :math:`\mathbf v_i = R(q)^T\mathbf s_i`
exactly, so this only removes round-off), which makes the method a one-step
map of :math:`(q, \boldsymbol\Omega)`. No chart is needed: the quaternion is
global; it is normalized only at output.

Order and step follow Jorba & Zou (2005) as for the free body: order
:math:`p = \lceil-\tfrac12\ln\varepsilon+1\rceil`, step
:math:`h = e^{-0.7/(p-1)}\min_{k\in\{p-1,p\}}(\varepsilon s/\lVert x_k\rVert_\infty)^{1/k}`
over the groups :math:`q` (scale 1) and :math:`\boldsymbol\Omega` (scale
:math:`s = \max(\lVert\boldsymbol\Omega\rVert_\infty, \lVert\dot{\boldsymbol\Omega}\rVert_\infty^{1/2})`,
a rate, so the step does not depend on the unit of time and stays finite for
a top released from rest). Outputs inside a step come from the step's
polynomial (Horner); the state and the time are carried with their rounding
errors (compensated two-sum updates).

References
----------
A. Jorba and M. Zou, Exp. Math. 14 (2005) 99-117. A. Griewank and A. Walther,
*Evaluating Derivatives*, 2nd ed. (2008), ch. 13. Leimanis (1965), ch. I (the
Poisson equations).
"""

from __future__ import annotations

import math

import numpy as np

from ...numerics.doubledouble import two_sum
from ...numerics.quaternion import rotate_inverse
from ...util.jit import USE_NUMBA, kernel_array

__all__ = ["integrate_polynomial", "BACKEND"]

#: which implementation runs: "numba" (compiled) or "python" (the same code, interpreted)
BACKEND = "numba" if USE_NUMBA else "python"


# ---------------------------------------------------------------------------
# the kernel (plain Python on scalars and small arrays: compiled by numba when available)
# ---------------------------------------------------------------------------
def _coefficients(order, Q, W, V, Z, Rr, MI, I, Iinv, tau0, L, nv, nu, kappa, orbit):
    """Fill the Taylor coefficients 1..order of q (Q), Omega (W) and the Poisson vectors; row 0 is set."""
    for k in range(order):
        # M_k = I W_k
        for a in range(3):
            MI[k, a] = I[a, 0] * W[k, 0] + I[a, 1] * W[k, 1] + I[a, 2] * W[k, 2]
        qd0 = 0.0
        qd1 = 0.0
        qd2 = 0.0
        qd3 = 0.0
        e0 = 0.0
        e1 = 0.0
        e2 = 0.0
        for j in range(k + 1):
            wj0 = W[k - j, 0]
            wj1 = W[k - j, 1]
            wj2 = W[k - j, 2]
            pw = Q[j, 0]
            px = Q[j, 1]
            py = Q[j, 2]
            pz = Q[j, 3]
            qd0 += -px * wj0 - py * wj1 - pz * wj2
            qd1 += pw * wj0 + py * wj2 - pz * wj1
            qd2 += pw * wj1 - px * wj2 + pz * wj0
            qd3 += pw * wj2 + px * wj1 - py * wj0
            m0 = MI[j, 0]
            m1 = MI[j, 1]
            m2 = MI[j, 2]
            e0 += m1 * wj2 - m2 * wj1
            e1 += m2 * wj0 - m0 * wj2
            e2 += m0 * wj1 - m1 * wj0
        if k == 0:
            e0 += tau0[0]
            e1 += tau0[1]
            e2 += tau0[2]
        for i in range(nv):
            v0 = V[k, i, 0]
            v1 = V[k, i, 1]
            v2 = V[k, i, 2]
            e0 += L[i, 0, 0] * v0 + L[i, 0, 1] * v1 + L[i, 0, 2] * v2
            e1 += L[i, 1, 0] * v0 + L[i, 1, 1] * v1 + L[i, 1, 2] * v2
            e2 += L[i, 2, 0] * v0 + L[i, 2, 1] * v1 + L[i, 2, 2] * v2
        if orbit:
            g0 = 0.0
            g1 = 0.0
            g2 = 0.0
            for j in range(k + 1):
                r0 = Rr[j, 0]
                r1 = Rr[j, 1]
                r2 = Rr[j, 2]
                s0 = Rr[k - j, 0]
                s1 = Rr[k - j, 1]
                s2 = Rr[k - j, 2]
                i0 = I[0, 0] * s0 + I[0, 1] * s1 + I[0, 2] * s2
                i1 = I[1, 0] * s0 + I[1, 1] * s1 + I[1, 2] * s2
                i2 = I[2, 0] * s0 + I[2, 1] * s1 + I[2, 2] * s2
                g0 += r1 * i2 - r2 * i1
                g1 += r2 * i0 - r0 * i2
                g2 += r0 * i1 - r1 * i0
            e0 += kappa * g0
            e1 += kappa * g1
            e2 += kappa * g2
        inv = 1.0 / (k + 1)
        Q[k + 1, 0] = 0.5 * qd0 * inv
        Q[k + 1, 1] = 0.5 * qd1 * inv
        Q[k + 1, 2] = 0.5 * qd2 * inv
        Q[k + 1, 3] = 0.5 * qd3 * inv
        for a in range(3):
            W[k + 1, a] = (Iinv[a, 0] * e0 + Iinv[a, 1] * e1 + Iinv[a, 2] * e2) * inv
        # Poisson vectors: v' = v x Omega
        for i in range(nv):
            c0 = 0.0
            c1 = 0.0
            c2 = 0.0
            for j in range(k + 1):
                v0 = V[j, i, 0]
                v1 = V[j, i, 1]
                v2 = V[j, i, 2]
                w0 = W[k - j, 0]
                w1 = W[k - j, 1]
                w2 = W[k - j, 2]
                c0 += v1 * w2 - v2 * w1
                c1 += v2 * w0 - v0 * w2
                c2 += v0 * w1 - v1 * w0
            V[k + 1, i, 0] = c0 * inv
            V[k + 1, i, 1] = c1 * inv
            V[k + 1, i, 2] = c2 * inv
        if orbit:
            c0 = 0.0
            c1 = 0.0
            c2 = 0.0
            d0 = 0.0
            d1 = 0.0
            d2 = 0.0
            for j in range(k + 1):
                w0 = W[k - j, 0]
                w1 = W[k - j, 1]
                w2 = W[k - j, 2]
                z0 = Z[j, 0]
                z1 = Z[j, 1]
                z2 = Z[j, 2]
                c0 += z1 * w2 - z2 * w1
                c1 += z2 * w0 - z0 * w2
                c2 += z0 * w1 - z1 * w0
                r0 = Rr[j, 0]
                r1 = Rr[j, 1]
                r2 = Rr[j, 2]
                d0 += r1 * w2 - r2 * w1
                d1 += r2 * w0 - r0 * w2
                d2 += r0 * w1 - r1 * w0
                s0 = Rr[k - j, 0]
                s1 = Rr[k - j, 1]
                s2 = Rr[k - j, 2]
                d0 += nu * (z1 * s2 - z2 * s1)
                d1 += nu * (z2 * s0 - z0 * s2)
                d2 += nu * (z0 * s1 - z1 * s0)
            Z[k + 1, 0] = c0 * inv
            Z[k + 1, 1] = c1 * inv
            Z[k + 1, 2] = c2 * inv
            Rr[k + 1, 0] = d0 * inv
            Rr[k + 1, 1] = d1 * inv
            Rr[k + 1, 2] = d2 * inv


def _coefficients_top(order, Q, W, V, MI, I, Iinv, ML, tau0):
    r"""The Taylor coefficients 1..order for one Poisson vector and no orbit (gravity: the heavy top).

    :math:`\dot{\boldsymbol\Omega} = I^{-1}\big((I\boldsymbol\Omega)\times\boldsymbol\Omega
    + \boldsymbol\tau_0\big) + M\mathbf v` with :math:`M = I^{-1}L` (made once per body),
    :math:`\dot{\mathbf v} = \mathbf v\times\boldsymbol\Omega`,
    :math:`\dot q = \frac12 q\otimes(0, \boldsymbol\Omega)`: :func:`_coefficients` without its
    branches and its loops over Poisson vectors. The three Cauchy sums of an order run in one loop
    over j (each row of W loaded once), and every product is added to its sum on its own
    (``g += a * b`` then ``g -= c * d``), which ``contract`` fuses into one multiply-add each: 24
    fused operations per term instead of 34 (a product, a fused product and an addition per
    two-term component); 1/(k + 1) is multiplied, not divided. Each sum starts from its term
    j = 0 (W_k, the newest row, with row 0) and ends with the term j = k (row 0 of W with the
    newest rows of q, v and I Omega) outside the loop over 1..k-1: no additions to zero, and the
    loop reads only rows made before the previous order ended (measured: 7 to 8 % less per step).
    Row 0 of Q, W and V (one vector: shape (order + 1, 3)) is set.
    """
    for k in range(order):
        # M_k = I W_k
        x0 = W[k, 0]
        x1 = W[k, 1]
        x2 = W[k, 2]
        MI[k, 0] = I[0, 0] * x0 + I[0, 1] * x1 + I[0, 2] * x2
        MI[k, 1] = I[1, 0] * x0 + I[1, 1] * x1 + I[1, 2] * x2
        MI[k, 2] = I[2, 0] * x0 + I[2, 1] * x1 + I[2, 2] * x2
        # (I Omega) x Omega, v x Omega and q (x) (0, Omega): the term j = 0 starts the sums
        w0 = W[k, 0]
        w1 = W[k, 1]
        w2 = W[k, 2]
        m0 = MI[0, 0]
        m1 = MI[0, 1]
        m2 = MI[0, 2]
        g0 = m1 * w2
        g0 -= m2 * w1
        g1 = m2 * w0
        g1 -= m0 * w2
        g2 = m0 * w1
        g2 -= m1 * w0
        v0 = V[0, 0]
        v1 = V[0, 1]
        v2 = V[0, 2]
        c0 = v1 * w2
        c0 -= v2 * w1
        c1 = v2 * w0
        c1 -= v0 * w2
        c2 = v0 * w1
        c2 -= v1 * w0
        pw = Q[0, 0]
        px = Q[0, 1]
        py = Q[0, 2]
        pz = Q[0, 3]
        s0 = -px * w0
        s0 -= py * w1
        s0 -= pz * w2
        s1 = pw * w0
        s1 += py * w2
        s1 -= pz * w1
        s2 = pw * w1
        s2 -= px * w2
        s2 += pz * w0
        s3 = pw * w2
        s3 += px * w1
        s3 -= py * w0
        if k > 0:
            for j in range(1, k):
                m = k - j
                w0 = W[m, 0]
                w1 = W[m, 1]
                w2 = W[m, 2]
                m0 = MI[j, 0]
                m1 = MI[j, 1]
                m2 = MI[j, 2]
                g0 += m1 * w2
                g0 -= m2 * w1
                g1 += m2 * w0
                g1 -= m0 * w2
                g2 += m0 * w1
                g2 -= m1 * w0
                v0 = V[j, 0]
                v1 = V[j, 1]
                v2 = V[j, 2]
                c0 += v1 * w2
                c0 -= v2 * w1
                c1 += v2 * w0
                c1 -= v0 * w2
                c2 += v0 * w1
                c2 -= v1 * w0
                pw = Q[j, 0]
                px = Q[j, 1]
                py = Q[j, 2]
                pz = Q[j, 3]
                s0 -= px * w0
                s0 -= py * w1
                s0 -= pz * w2
                s1 += pw * w0
                s1 += py * w2
                s1 -= pz * w1
                s2 += pw * w1
                s2 -= px * w2
                s2 += pz * w0
                s3 += pw * w2
                s3 += px * w1
                s3 -= py * w0
            # the term j = k (the newest rows of q, v and I Omega) last
            w0 = W[0, 0]
            w1 = W[0, 1]
            w2 = W[0, 2]
            m0 = MI[k, 0]
            m1 = MI[k, 1]
            m2 = MI[k, 2]
            g0 += m1 * w2
            g0 -= m2 * w1
            g1 += m2 * w0
            g1 -= m0 * w2
            g2 += m0 * w1
            g2 -= m1 * w0
            v0 = V[k, 0]
            v1 = V[k, 1]
            v2 = V[k, 2]
            c0 += v1 * w2
            c0 -= v2 * w1
            c1 += v2 * w0
            c1 -= v0 * w2
            c2 += v0 * w1
            c2 -= v1 * w0
            pw = Q[k, 0]
            px = Q[k, 1]
            py = Q[k, 2]
            pz = Q[k, 3]
            s0 -= px * w0
            s0 -= py * w1
            s0 -= pz * w2
            s1 += pw * w0
            s1 += py * w2
            s1 -= pz * w1
            s2 += pw * w1
            s2 -= px * w2
            s2 += pz * w0
            s3 += pw * w2
            s3 += px * w1
            s3 -= py * w0
        if k == 0:
            g0 += tau0[0]
            g1 += tau0[1]
            g2 += tau0[2]
        inv = 1.0 / (k + 1)
        v0 = V[k, 0]
        v1 = V[k, 1]
        v2 = V[k, 2]
        for a in range(3):
            W[k + 1, a] = (
                (Iinv[a, 0] * g0 + Iinv[a, 1] * g1 + Iinv[a, 2] * g2) + (ML[a, 0] * v0 + ML[a, 1] * v1 + ML[a, 2] * v2)
            ) * inv
        V[k + 1, 0] = c0 * inv
        V[k + 1, 1] = c1 * inv
        V[k + 1, 2] = c2 * inv
        hinv = 0.5 * inv
        Q[k + 1, 0] = s0 * hinv
        Q[k + 1, 1] = s1 * hinv
        Q[k + 1, 2] = s2 * hinv
        Q[k + 1, 3] = s3 * hinv


def _coefficients_top_principal(order, Q, W, V, E, ML, tau0i):
    r""":func:`_coefficients_top` in a principal frame of the body (a diagonal inertia tensor).

    :math:`I^{-1}\big((I\boldsymbol\Omega)\times\boldsymbol\Omega\big)_a = e_a\,\Omega_b\Omega_c` with
    :math:`e_a = (I_b - I_c)/I_a`, :math:`(a, b, c)` cyclic: the angular-velocity equation takes three
    Cauchy products of the rows of W (``E`` the three :math:`e_a`) instead of the six of
    :math:`(I\boldsymbol\Omega)\times\boldsymbol\Omega` with the matrix products around them, 21 fused
    operations per term instead of 24 (the free body's kernel has 15). ``tau0i`` is
    :math:`I^{-1}\boldsymbol\tau_0`, ``ML`` :math:`I^{-1}L`. Row 0 of Q, W and V is set.
    """
    e0 = E[0]
    e1 = E[1]
    e2 = E[2]
    for k in range(order):
        # the term j = 0 starts the sums: row 0 of the left factors with the newest row k of W
        w0 = W[k, 0]
        w1 = W[k, 1]
        w2 = W[k, 2]
        u0 = W[0, 0]
        u1 = W[0, 1]
        u2 = W[0, 2]
        p0 = u1 * w2
        p1 = u2 * w0
        p2 = u0 * w1
        v0 = V[0, 0]
        v1 = V[0, 1]
        v2 = V[0, 2]
        c0 = v1 * w2
        c0 -= v2 * w1
        c1 = v2 * w0
        c1 -= v0 * w2
        c2 = v0 * w1
        c2 -= v1 * w0
        pw = Q[0, 0]
        px = Q[0, 1]
        py = Q[0, 2]
        pz = Q[0, 3]
        s0 = -px * w0
        r0 = -py * w1
        r0 -= pz * w2
        s1 = pw * w0
        r1 = py * w2
        r1 -= pz * w1
        s2 = pw * w1
        r2 = pz * w0
        r2 -= px * w2
        s3 = pw * w2
        r3 = px * w1
        r3 -= py * w0
        if k > 0:
            for j in range(1, k):
                m = k - j
                w0 = W[m, 0]
                w1 = W[m, 1]
                w2 = W[m, 2]
                u0 = W[j, 0]
                u1 = W[j, 1]
                u2 = W[j, 2]
                p0 += u1 * w2
                p1 += u2 * w0
                p2 += u0 * w1
                v0 = V[j, 0]
                v1 = V[j, 1]
                v2 = V[j, 2]
                c0 += v1 * w2
                c0 -= v2 * w1
                c1 += v2 * w0
                c1 -= v0 * w2
                c2 += v0 * w1
                c2 -= v1 * w0
                pw = Q[j, 0]
                px = Q[j, 1]
                py = Q[j, 2]
                pz = Q[j, 3]
                s0 -= px * w0
                r0 -= py * w1
                r0 -= pz * w2
                s1 += pw * w0
                r1 += py * w2
                r1 -= pz * w1
                s2 += pw * w1
                r2 += pz * w0
                r2 -= px * w2
                s3 += pw * w2
                r3 += px * w1
                r3 -= py * w0
            # the term j = k (the newest rows of W, v and q with row 0 of W) last
            w0 = W[0, 0]
            w1 = W[0, 1]
            w2 = W[0, 2]
            u0 = W[k, 0]
            u1 = W[k, 1]
            u2 = W[k, 2]
            p0 += u1 * w2
            p1 += u2 * w0
            p2 += u0 * w1
            v0 = V[k, 0]
            v1 = V[k, 1]
            v2 = V[k, 2]
            c0 += v1 * w2
            c0 -= v2 * w1
            c1 += v2 * w0
            c1 -= v0 * w2
            c2 += v0 * w1
            c2 -= v1 * w0
            pw = Q[k, 0]
            px = Q[k, 1]
            py = Q[k, 2]
            pz = Q[k, 3]
            s0 -= px * w0
            r0 -= py * w1
            r0 -= pz * w2
            s1 += pw * w0
            r1 += py * w2
            r1 -= pz * w1
            s2 += pw * w1
            r2 += pz * w0
            r2 -= px * w2
            s3 += pw * w2
            r3 += px * w1
            r3 -= py * w0
        inv = 1.0 / (k + 1)
        v0 = V[k, 0]
        v1 = V[k, 1]
        v2 = V[k, 2]
        f0 = e0 * p0 + (ML[0, 0] * v0 + ML[0, 1] * v1 + ML[0, 2] * v2)
        f1 = e1 * p1 + (ML[1, 0] * v0 + ML[1, 1] * v1 + ML[1, 2] * v2)
        f2 = e2 * p2 + (ML[2, 0] * v0 + ML[2, 1] * v1 + ML[2, 2] * v2)
        if k == 0:
            f0 += tau0i[0]
            f1 += tau0i[1]
            f2 += tau0i[2]
        W[k + 1, 0] = f0 * inv
        W[k + 1, 1] = f1 * inv
        W[k + 1, 2] = f2 * inv
        V[k + 1, 0] = c0 * inv
        V[k + 1, 1] = c1 * inv
        V[k + 1, 2] = c2 * inv
        hinv = 0.5 * inv
        Q[k + 1, 0] = (s0 + r0) * hinv
        Q[k + 1, 1] = (s1 + r1) * hinv
        Q[k + 1, 2] = (s2 + r2) * hinv
        Q[k + 1, 3] = (s3 + r3) * hinv


def _norm_inf(X, k, n):
    m = 0.0
    for a in range(n):
        v = abs(X[k, a])
        if v > m:
            m = v
    return m


def _horner(Q, W, order, theta, dq, dw):
    """dq[a] = sum_{k>=1} Q[k, a] theta^k and dw from W (the increments, without the constant terms).

    The seven Horner chains run interleaved (independent: their latencies overlap).
    """
    a0 = Q[order, 0]
    a1 = Q[order, 1]
    a2 = Q[order, 2]
    a3 = Q[order, 3]
    b0 = W[order, 0]
    b1 = W[order, 1]
    b2 = W[order, 2]
    for k in range(order - 1, 0, -1):
        a0 = a0 * theta + Q[k, 0]
        a1 = a1 * theta + Q[k, 1]
        a2 = a2 * theta + Q[k, 2]
        a3 = a3 * theta + Q[k, 3]
        b0 = b0 * theta + W[k, 0]
        b1 = b1 * theta + W[k, 1]
        b2 = b2 * theta + W[k, 2]
    dq[0] = a0 * theta
    dq[1] = a1 * theta
    dq[2] = a2 * theta
    dq[3] = a3 * theta
    dw[0] = b0 * theta
    dw[1] = b1 * theta
    dw[2] = b2 * theta


def integrate_body(q0, w0, I, Iinv, tau0, S, L, nu, kappa, times, tol, order, dt, max_steps, qout, wout):
    """Integrate one body from t = 0 to the output times (all of one sign, sorted by |t| ascending).

    Returns ``(steps, status)``: status 0 ok, 1 ``max_steps`` exhausted, 2 non-finite state.

    One Poisson vector and no orbit term (gravity, or a space torque, with or without a constant
    body torque) take :func:`_coefficients_top`, or :func:`_coefficients_top_principal` when the
    tensor is diagonal (a body given by its principal moments). A full tensor is not turned into
    its principal frame: the rotated initial state, tensor and torque carry a few ulp of rounding
    that the motion of a top amplifies (measured: 10-20 times the error at t = 10).
    """
    nv = S.shape[0]
    orbit = kappa != 0.0
    top = nv == 1 and not orbit
    Vt = np.zeros((order + 1, 3))
    Q = np.zeros((order + 1, 4))
    W = np.zeros((order + 1, 3))
    MI = np.zeros((order + 1, 3))
    V = np.zeros((order + 1, max(nv, 1), 3))
    Z = np.zeros((order + 1, 3))
    Rr = np.zeros((order + 1, 3))
    dq = np.zeros(4)
    dw = np.zeros(3)
    q = q0.copy()
    w = w0.copy()
    qlo = np.zeros(4)
    wlo = np.zeros(3)
    th = 0.0
    tl = 0.0
    T = times.shape[0]
    j = 0
    # outputs at t = 0
    while j < T and times[j] == 0.0:
        for a in range(4):
            qout[j, a] = q0[a]
        for a in range(3):
            wout[j, a] = w0[a]
        j += 1
    if j >= T:
        return 0, 0
    # the specialized kernels: ML = I^-1 L; in a principal frame (a diagonal tensor) the Euler
    # coefficients E and I^-1 tau0
    ML = np.zeros((3, 3))
    E = np.zeros(3)
    tau0i = np.zeros(3)
    principal = I[0, 1] == 0.0 and I[0, 2] == 0.0 and I[1, 0] == 0.0 and I[1, 2] == 0.0
    principal = principal and I[2, 0] == 0.0 and I[2, 1] == 0.0
    if top:
        for a in range(3):
            for c in range(3):
                ML[a, c] = Iinv[a, 0] * L[0, 0, c] + Iinv[a, 1] * L[0, 1, c] + Iinv[a, 2] * L[0, 2, c]
        if principal:
            E[0] = (I[1, 1] - I[2, 2]) / I[0, 0]
            E[1] = (I[2, 2] - I[0, 0]) / I[1, 1]
            E[2] = (I[0, 0] - I[1, 1]) / I[2, 2]
            for a in range(3):
                tau0i[a] = tau0[a] / I[a, a]
    sgn = 1.0 if times[T - 1] > 0 else -1.0
    safety = math.exp(-0.7 / (order - 1)) if order > 1 else 0.5
    steps = 0
    while j < T:
        if steps >= max_steps:
            return steps, 1
        for a in range(4):
            Q[0, a] = q[a]
        for a in range(3):
            W[0, a] = w[a]
        nq = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        uw = q[0] / nq
        ux = q[1] / nq
        uy = q[2] / nq
        uz = q[3] / nq
        if top:
            a0, a1, a2 = rotate_inverse(uw, ux, uy, uz, S[0, 0], S[0, 1], S[0, 2])
            Vt[0, 0] = a0
            Vt[0, 1] = a1
            Vt[0, 2] = a2
        else:
            for i in range(nv):
                a0, a1, a2 = rotate_inverse(uw, ux, uy, uz, S[i, 0], S[i, 1], S[i, 2])
                V[0, i, 0] = a0
                V[0, i, 1] = a1
                V[0, i, 2] = a2
        if orbit:
            a0, a1, a2 = rotate_inverse(uw, ux, uy, uz, 0.0, 0.0, 1.0)
            Z[0, 0] = a0
            Z[0, 1] = a1
            Z[0, 2] = a2
            ph = nu * th + nu * tl
            a0, a1, a2 = rotate_inverse(uw, ux, uy, uz, math.cos(ph), math.sin(ph), 0.0)
            Rr[0, 0] = a0
            Rr[0, 1] = a1
            Rr[0, 2] = a2
        if top and principal:
            _coefficients_top_principal(order, Q, W, Vt, E, ML, tau0i)
        elif top:
            _coefficients_top(order, Q, W, Vt, MI, I, Iinv, ML, tau0)
        else:
            _coefficients(order, Q, W, V, Z, Rr, MI, I, Iinv, tau0, L, nv, nu, kappa, orbit)
        if dt > 0.0:
            h = dt
        else:
            # (the row and width as computed int64: literal constants would compile _norm_inf once per value)
            sw = max(_norm_inf(W, order - order, W.shape[1]), math.sqrt(_norm_inf(W, order - order + 1, W.shape[1])))
            h = math.inf
            for k in (order - 1, order):
                if k < 1:
                    continue
                x = math.inf  # the smaller bound of the two groups, then one root
                nqk = _norm_inf(Q, k, Q.shape[1])
                if nqk > 0.0:
                    x = tol / nqk
                nwk = _norm_inf(W, k, W.shape[1])
                if nwk > 0.0 and sw > 0.0:
                    x = min(x, tol * sw / nwk)
                if x < math.inf:
                    h = min(h, x ** (1.0 / k))
            h = safety * h
            if not (h < math.inf):
                # no motion at all (at rest, no torque): jump to the last output
                h = abs(times[T - 1] - th) + 1.0
        h = sgn * h
        # outputs inside [t, t + h]
        while j < T:
            theta = (times[j] - th) - tl
            if sgn * theta > sgn * h:
                break
            _horner(Q, W, order, theta, dq, dw)
            nrm = 0.0
            for a in range(4):
                qa = q[a] + (dq[a] + qlo[a])
                qout[j, a] = qa
                nrm += qa * qa
            nrm = math.sqrt(nrm)
            for a in range(4):
                qout[j, a] /= nrm
            for a in range(3):
                wout[j, a] = w[a] + (dw[a] + wlo[a])
            j += 1
        if j >= T:
            steps += 1
            break
        _horner(Q, W, order, h, dq, dw)
        for a in range(4):
            s, e = two_sum(q[a], dq[a] + qlo[a])
            q[a] = s
            qlo[a] = e
        for a in range(3):
            s, e = two_sum(w[a], dw[a] + wlo[a])
            w[a] = s
            wlo[a] = e
        th, e = two_sum(th, h + tl)
        tl = e
        steps += 1
        ok = True
        for a in range(4):
            if not math.isfinite(q[a]):
                ok = False
        for a in range(3):
            if not math.isfinite(w[a]):
                ok = False
        if not ok:
            return steps, 2
    return steps, 0


if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    # fastmath={"contract"} only (multiply-adds fused, no reassociation), as the free body's kernels: the
    # Cauchy sums issue half the instructions (the compensated updates are two_sum, additions only, which
    # contraction leaves exact); the interpreted twin agrees to round-off, not bit for bit
    _coefficients = _njit(cache=True, nogil=True, fastmath={"contract"})(_coefficients)
    _coefficients_top = _njit(cache=True, nogil=True, fastmath={"contract"})(_coefficients_top)
    _coefficients_top_principal = _njit(cache=True, nogil=True, fastmath={"contract"})(_coefficients_top_principal)
    _norm_inf = _njit(cache=True, nogil=True)(_norm_inf)
    _horner = _njit(cache=True, nogil=True, fastmath={"contract"})(_horner)
    integrate_body = _njit(cache=True, nogil=True, fastmath={"contract"})(integrate_body)


def integrate_polynomial(inertia, q0, w0, data, t, *, tol, order, dt, max_steps):
    """Integrate a batch of bodies under polynomial torques.

    Parameters
    ----------
    inertia : ndarray, shape (B, 3, 3)
    q0 : ndarray, shape (B, 4)
    w0 : ndarray, shape (B, 3)
    data : FlatPolynomialTorque
        :meth:`~eulerpoisson.torques.PolynomialTorque.flatten`.
    t : ndarray, shape (T,)
        Output times, any order and sign.
    tol : float
    order : int
    dt : float or None
        Fixed step (None: adaptive).
    max_steps : int
        Per body, both directions together.

    Returns
    -------
    q : ndarray (B, T, 4)
    omega : ndarray (B, T, 3)
    stats : dict
    status : ndarray (B,) of int
        0 ok, 1 ``max_steps`` exhausted, 2 non-finite state.
    """
    # C-contiguous writeable float64 (a copy only where needed: the inertia is a broadcast view, read-only,
    # and so may be the torque's arrays): one signature of integrate_body, the one the warm-up compiles
    inertia, q0, w0, tau0, S, L = (kernel_array(x) for x in (inertia, q0, w0, data.tau0, data.S, data.L))
    B = q0.shape[0]
    T = t.shape[0]
    qout = np.empty((B, T, 4))
    wout = np.empty((B, T, 3))
    status = np.zeros(B, dtype=np.int64)
    steps_total = 0
    steps_max = 0
    Iinv = kernel_array(np.linalg.inv(inertia)) if B else inertia
    pos = np.flatnonzero(t >= 0)
    neg = np.flatnonzero(t < 0)
    branches = []
    for idx in (pos, neg):
        if idx.size:
            order_idx = idx[np.argsort(np.abs(t[idx]), kind="stable")]
            branches.append((order_idx, kernel_array(t[order_idx])))
    fixed = float(dt) if dt is not None else 0.0
    for b in range(B):
        used = 0
        for order_idx, ts in branches:
            qo = np.empty((ts.shape[0], 4))
            wo = np.empty((ts.shape[0], 3))
            steps, st = integrate_body(
                q0[b],
                w0[b],
                inertia[b],
                Iinv[b],
                tau0[b],
                S[b],
                L[b],
                float(data.nu[b]),
                float(data.kappa[b]),
                ts,
                float(tol),
                int(order),
                fixed,
                int(max_steps - used),
                qo,
                wo,
            )
            used += steps
            qout[b, order_idx] = qo
            wout[b, order_idx] = wo
            if st:
                status[b] = st
                break
        steps_total += used
        steps_max = max(steps_max, used)
    stats = {
        "steps": steps_total,
        "steps_max": steps_max,
        "max_order": int(order),
        "backend": BACKEND,
        "chart_changes": 0,
    }
    return qout, wout, stats, status
