r"""Taylor-mode recurrences and the stepping loop of the ``taylor`` method (private).

Two implementations of the same algorithm live here:

* compiled kernels (numba, ``@njit(cache=True)``): a scalar kernel, one body
  after the other in scalar loops over fixed-size arrays, and a *lane* kernel
  that advances ``LANES_TAYLOR`` (16) bodies in lockstep (SIMD), used for
  batches of ``LANES_MIN_BODIES`` (5) bodies or more. Every body has its own
  steps in both;
* a generic NumPy path, vectorized over the bodies, that only uses ``+ - * /``
  (dividing by integers), comparisons and one square root per chart change
  on the coefficient arrays, so that it runs unchanged with ``float64``,
  ``numpy.longdouble`` or ``object`` arrays of ``mpmath.mpf``. Step sizes are
  chosen in float64 in every arithmetic (a float64 step is exact in the
  others).

The compiled kernels are used when numba is installed and the environment
variable ``EULERPOISSON_NO_NUMBA`` is not ``"1"`` (:data:`USE_NUMBA`, decided
when eulerpoisson is imported, without importing numba: the kernels are made
and loaded from numba's cache on their first call, see
:mod:`eulerpoisson.util.jit`); otherwise the NumPy path runs. Both take the same steps and give the
same results to round-off: the compiled kernels let LLVM fuse multiply-adds
(``fastmath={"contract"}`` only, no reassociation) and sum the Cauchy
products in a different order.

Lane kernel
    A single body is a chain of dependent multiply-adds (the Cauchy sums of
    order 20 at tol = eps) that keeps one core at about 5e5 body-seconds per
    second. The lane kernel stores coefficient k of lane l at
    ``k*7*L + row*L + l`` (rows n, Omega and S = n.Omega, ``L = 16``) and runs
    the scalar kernel's operations lane by lane with the lane loop innermost,
    which LLVM turns into AVX2/AVX-512 code. Two details make that happen:
    the j-th Cauchy term is read through row *views* (``buf[j*7L:(j+1)*7L]``)
    so that every index is a non-negative constant plus the lane (numba's
    negative-index wrap-around otherwise turns the loads into gathers), and
    the running sums live in a stack buffer (:func:`~eulerpoisson.util.jit.stack_buffer`,
    an ``alloca``) that LLVM knows aliases no array, so no run-time overlap
    check is needed (for a 16-trip loop LLVM would not emit one and would not
    vectorize). Step sizes, dense output and chart changes are done lane by
    lane; a lane whose body is done takes the next body, so lanes stay busy
    until the queue is empty. Measured (2-core AMD EPYC, one thread, tol =
    eps, order 20): the series costs 150 ns per body and step against 620 ns
    for the scalar kernel; the whole integration makes 1.3e6 to 1.5e6
    body-seconds per second against 4.8e5 (heyoka's batch mode: 1.4e6).
    Since then (2-core Xeon, Cascade Lake, same run): one Cauchy loop per
    order with one fused multiply-add per product, the lanes' loop over j
    in halves of 8 (sums kept in registers) and the step size from one
    ``exp`` instead of two ``pow``: 965 -> 765 ns per step for one body,
    643 -> 436 ns per body and step in the lanes.
    The lane kernel takes the same steps as the scalar kernel; its results
    agree to round-off (measured: 1.5e-16 relative; plain Python runs of both
    agree bit for bit, which the tests check: zeros may differ in sign, the
    scalar kernel starts its sums with the term j = 0, the lanes from 0).

The recurrences (principal frame, :math:`a_1 = (I_2-I_3)/I_1` and cyclic) are
the Taylor coefficients of the solution of the paper's eq. 1.30,

.. math::

    \dot{\mathbf n} = \tfrac12\big(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega
                      + (\mathbf n\cdot\boldsymbol\Omega)\,\mathbf n\big), \qquad
    \dot\Omega_1 = a_1\Omega_2\Omega_3 \;(\text{cyclic}),

obtained with Cauchy products: with :math:`x(t) = \sum_k x_k t^k`,
:math:`(xy)_k = \sum_{j=0}^k x_j y_{k-j}` and :math:`x_{k+1} = f_k/(k+1)`,
so order :math:`p` costs :math:`O(p^2)` per step (15 fused multiply-adds per
term of the Cauchy sums).

State updates are compensated: the state and the time are pairs (value,
error) advanced by an error-free two-sum of the step's increment (Horner
without the constant term), in both implementations and every arithmetic.

References
----------
A. Jorba and M. Zou, "A software package for the numerical integration of
ODEs by means of high-order Taylor methods", Exp. Math. 14 (2005) 99-117.
Paper eq. 1.16, 1.23.1, 1.30.
"""

from __future__ import annotations

import math

import numpy as np

from ...model.free_body import euler_coefficients
from ...numerics.doubledouble import two_sum
from ...numerics.quaternion import qmul_components
from ...util.jit import (  # USE_NUMBA: numba importable, EULERPOISSON_NO_NUMBA not "1"
    USE_NUMBA,
    kernel_array,
    stack_buffer,
)

__all__ = [
    "USE_NUMBA",
    "STATUS_OK",
    "STATUS_MAX_STEPS",
    "STATUS_NONFINITE",
    "auto_order",
    "step_safety",
    "series_principal",
    "series_tensor",
    "series_canonical",
    "inverse3",
    "integrate_numpy",
    "integrate_numba",
    "coefficients_numba",
]

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_NONFINITE = 2


def auto_order(tol: float) -> int:
    r"""Taylor order for a tolerance (Jorba & Zou 2005): :math:`p = \lceil -\tfrac12\ln\varepsilon + 1\rceil`."""
    return int(math.ceil(-0.5 * math.log(tol) + 1.0))


def step_safety(order: int) -> float:
    r"""Jorba & Zou's step factor :math:`e^{-0.7/(p-1)}`."""
    return math.exp(-0.7 / (order - 1)) if order > 1 else 0.5


# ---------------------------------------------------------------------------
# generic recurrences (any dtype supporting + - * /): arrays (p+1, 3, *batch)
# ---------------------------------------------------------------------------
def series_principal(a, n0, w0, order):
    r"""Taylor coefficients of eq. 1.30 in the principal frame (generic arithmetic).

    Parameters
    ----------
    a : array, shape (3, *batch)
        Euler coefficients :math:`a_1 = (I_2-I_3)/I_1` and cyclic.
    n0, w0 : array, shape (3, *batch)
        Gibbs vector and body angular velocity (principal frame) at the
        expansion point.
    order : int

    Returns
    -------
    N, W : arrays, shape (order+1, 3, *batch)
        :math:`\mathbf n(t) = \sum_k N_k t^k`, :math:`\boldsymbol\Omega(t) = \sum_k W_k t^k`.
    """
    dtype = np.result_type(a, n0, w0)
    shape = (order + 1,) + np.shape(n0)
    N = np.zeros(shape, dtype=dtype)
    W = np.zeros(shape, dtype=dtype)
    S = np.zeros((order + 1,) + np.shape(n0)[1:], dtype=dtype)
    N[0] = n0
    W[0] = w0
    for k in range(order):
        Nk = N[: k + 1]
        Wr = W[k::-1]
        Wk = W[: k + 1]
        nx, ny, nz = Nk[:, 0], Nk[:, 1], Nk[:, 2]
        wx, wy, wz = Wr[:, 0], Wr[:, 1], Wr[:, 2]
        S[k] = (nx * wx + ny * wy + nz * wz).sum(0)
        cx = (ny * wz - nz * wy).sum(0)
        cy = (nz * wx - nx * wz).sum(0)
        cz = (nx * wy - ny * wx).sum(0)
        e0 = (Wk[:, 1] * wz).sum(0)
        e1 = (Wk[:, 2] * wx).sum(0)
        e2 = (Wk[:, 0] * wy).sum(0)
        Sr = S[: k + 1]
        Nr = N[k::-1]
        sx = (Sr * Nr[:, 0]).sum(0)
        sy = (Sr * Nr[:, 1]).sum(0)
        sz = (Sr * Nr[:, 2]).sum(0)
        # divide by integers so that the arithmetic stays exact in mpmath
        N[k + 1, 0] = (W[k, 0] + cx + sx) / (2 * (k + 1))
        N[k + 1, 1] = (W[k, 1] + cy + sy) / (2 * (k + 1))
        N[k + 1, 2] = (W[k, 2] + cz + sz) / (2 * (k + 1))
        W[k + 1, 0] = a[0] * e0 / (k + 1)
        W[k + 1, 1] = a[1] * e1 / (k + 1)
        W[k + 1, 2] = a[2] * e2 / (k + 1)
    return N, W


def _cross_series(x, y, k):
    """k-th coefficient of x(t) x y(t) for series arrays (p+1, 3, ...)."""
    xs = x[: k + 1]
    yr = y[k::-1]
    return np.stack(
        [
            (xs[:, 1] * yr[:, 2] - xs[:, 2] * yr[:, 1]).sum(0),
            (xs[:, 2] * yr[:, 0] - xs[:, 0] * yr[:, 2]).sum(0),
            (xs[:, 0] * yr[:, 1] - xs[:, 1] * yr[:, 0]).sum(0),
        ]
    )


def _dot_series(x, y, k):
    xs = x[: k + 1]
    yr = y[k::-1]
    return (xs[:, 0] * yr[:, 0] + xs[:, 1] * yr[:, 1] + xs[:, 2] * yr[:, 2]).sum(0)


def _scal_series(s, x, k):
    """k-th coefficient of s(t) x(t), s scalar series (p+1, ...), x (p+1, 3, ...)."""
    return (s[: k + 1, None] * x[k::-1]).sum(0)


def _matvec(A, v):
    """A (3, 3, ...) times v (3, ...), generic arithmetic."""
    return np.stack([A[i, 0] * v[0] + A[i, 1] * v[1] + A[i, 2] * v[2] for i in range(3)])


def inverse3(A):
    """Inverse of 3x3 matrices A (3, 3, ...) by the adjugate (generic arithmetic)."""
    c = np.empty_like(A)
    for i in range(3):
        for j in range(3):
            i1, i2 = (i + 1) % 3, (i + 2) % 3
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            c[j, i] = A[i1, j1] * A[i2, j2] - A[i1, j2] * A[i2, j1]
    det = A[0, 0] * c[0, 0] + A[0, 1] * c[1, 0] + A[0, 2] * c[2, 0]
    return c / det


def series_tensor(inertia, inertia_inv, n0, w0, order):
    r"""Taylor coefficients of eq. 1.30 for a full inertia tensor (generic arithmetic).

    :math:`I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega`,
    i.e. :math:`\boldsymbol\Omega_{k+1} = I^{-1}\sum_j \mathbf M_j\times\boldsymbol\Omega_{k-j}/(k+1)`
    with :math:`\mathbf M_j = I\boldsymbol\Omega_j`.

    Parameters
    ----------
    inertia, inertia_inv : arrays, shape (3, 3, *batch)
    n0, w0 : arrays, shape (3, *batch)
    order : int

    Returns
    -------
    N, W : arrays, shape (order+1, 3, *batch)
    """
    dtype = np.result_type(inertia, inertia_inv, n0, w0)
    shape = (order + 1,) + np.shape(n0)
    N = np.zeros(shape, dtype=dtype)
    W = np.zeros(shape, dtype=dtype)
    M = np.zeros(shape, dtype=dtype)
    S = np.zeros((order + 1,) + np.shape(n0)[1:], dtype=dtype)
    N[0] = n0
    W[0] = w0
    M[0] = _matvec(inertia, W[0])
    for k in range(order):
        S[k] = _dot_series(N, W, k)
        c = _cross_series(N, W, k)
        sn = _scal_series(S, N, k)
        N[k + 1] = (W[k] + c + sn) / (2 * (k + 1))
        W[k + 1] = _matvec(inertia_inv, _cross_series(M, W, k)) / (k + 1)
        M[k + 1] = _matvec(inertia, W[k + 1])
    return N, W


def series_canonical(inertia_inv, n0, pi0, order):
    r"""Taylor coefficients in the canonical variables :math:`(\mathbf n, \boldsymbol\pi)` (generic arithmetic).

    Hamilton's equations of :math:`H = \tfrac18(\tilde A\boldsymbol\pi)^T I^{-1}\tilde A\boldsymbol\pi`
    (paper eq. 1.15), with :math:`\mathbf u = \tilde A\boldsymbol\pi = \boldsymbol\pi + (\mathbf n\cdot\boldsymbol\pi)\mathbf n - \mathbf n\times\boldsymbol\pi`
    and :math:`\mathbf v = I^{-1}\mathbf u`:

    .. math::

        \dot{\mathbf n} = \tfrac14\tilde A^T\mathbf v = \tfrac14\big(\mathbf v + (\mathbf n\cdot\mathbf v)\mathbf n + \mathbf n\times\mathbf v\big),\qquad
        \dot{\boldsymbol\pi} = -\tfrac14\big((\mathbf n\cdot\boldsymbol\pi)\mathbf v + (\mathbf n\cdot\mathbf v)\boldsymbol\pi + \mathbf v\times\boldsymbol\pi\big).

    (The last term is :math:`-\tfrac14\epsilon_{ijk}\pi_k v_j`; the paper's
    eq. 1.16 prints :math:`\epsilon_{ijk}n_k` there, which is not
    :math:`-\partial H/\partial n_i`.)

    Parameters
    ----------
    inertia_inv : array, shape (3, 3, *batch)
    n0, pi0 : arrays, shape (3, *batch)
    order : int

    Returns
    -------
    N, PI : arrays, shape (order+1, 3, *batch)
    """
    dtype = np.result_type(inertia_inv, n0, pi0)
    shape = (order + 1,) + np.shape(n0)
    N = np.zeros(shape, dtype=dtype)
    P = np.zeros(shape, dtype=dtype)
    U = np.zeros(shape, dtype=dtype)
    V = np.zeros(shape, dtype=dtype)
    sa = np.zeros((order + 1,) + np.shape(n0)[1:], dtype=dtype)  # n.pi
    sb = np.zeros_like(sa)  # n.v
    N[0] = n0
    P[0] = pi0
    for k in range(order):
        sa[k] = _dot_series(N, P, k)
        U[k] = P[k] + _scal_series(sa, N, k) - _cross_series(N, P, k)
        V[k] = _matvec(inertia_inv, U[k])
        sb[k] = _dot_series(N, V, k)
        ndot = V[k] + _scal_series(sb, N, k) + _cross_series(N, V, k)
        pdot = _scal_series(sa, V, k) + _scal_series(sb, P, k) + _cross_series(V, P, k)
        N[k + 1] = ndot / (4 * (k + 1))
        P[k + 1] = -pdot / (4 * (k + 1))
    return N, P


# ---------------------------------------------------------------------------
# generic stepping loop (NumPy, vectorized over bodies)
# ---------------------------------------------------------------------------
def _sqrt(x):
    if x.dtype == object:
        return x**0.5
    return np.sqrt(x)


def _attitude_cols(qr, n):
    """Unit quaternion q_ref (x) (1, n)/|(1, n)| as (4, ...) columns."""
    one = np.ones_like(n[0])
    q = np.stack(qmul_components(qr[0], qr[1], qr[2], qr[3], one, n[0], n[1], n[2]))
    return q / _sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])


def _horner(X, theta):
    """Evaluate series X (p+1, 3, m) at theta (m,)."""
    acc = X[-1].copy()
    for k in range(X.shape[0] - 2, -1, -1):
        acc = acc * theta + X[k]
    return acc


def _horner_delta(X, theta):
    """X(theta) - X(0) for series X (p+1, 3, m) at theta (m,) (Horner without the constant term)."""
    acc = X[-1].copy()
    for k in range(X.shape[0] - 2, 0, -1):
        acc = acc * theta + X[k]
    return acc * theta


def _two_sum_into(hi, lo, d, sel):
    """hi[sel] + lo[sel] += d, compensated: hi the rounded sum, lo its exact error (two-sum)."""
    hi[..., sel], lo[..., sel] = two_sum(hi[..., sel], d + lo[..., sel])


def _to_float(x):
    return np.asarray(x).astype(np.float64)


def _step_sizes(N, W, order, tol, safety, scale_n, scale_w):
    """Jorba-Zou step from the last two coefficients (float64, one per body)."""
    rho = np.full(N.shape[-1], np.inf)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        for k in (order - 1, order):
            if k < 1:
                continue
            for X, sc in ((N, scale_n), (W, scale_w)):
                nrm = _to_float(np.abs(X[k]).max(axis=0))
                r = np.where(nrm > 0, (tol * sc / np.where(nrm > 0, nrm, 1.0)) ** (1.0 / k), np.inf)
                rho = np.minimum(rho, np.where(np.isnan(nrm), np.nan, r))
    return safety * rho


def integrate_numpy(moments, w0, qref0, t, *, tol, order, dt, max_steps, threshold):
    r"""Generic (NumPy) Taylor integration of bodies in their principal frames.

    Parameters
    ----------
    moments : array, shape (B, 3)
        Principal moments (float64, longdouble or object/mpmath).
    w0 : array, shape (B, 3)
        Initial body angular velocities, principal frame.
    qref0 : array, shape (B, 4)
        Initial reference quaternions (the attitude at t = 0).
    t : array, shape (T,)
        Output times, any order and sign.
    tol : float
        Tolerance (adaptive steps) — ignored when ``dt`` is given.
    order : int
        Taylor order.
    dt : float or None
        Fixed step size (> 0), or None for adaptive steps.
    max_steps : int
        Maximum number of steps per body (both directions together).
    threshold : float
        Chart change when :math:`|\mathbf n| >` threshold at the end of a step.

    Returns
    -------
    q : array (B, T, 4), w : array (B, T, 3), stats : int64 array (B, 3)
        stats columns: steps, chart changes, status (0 ok, 1 max_steps, 2 non-finite).
    """
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging state is reported in stats
        return _integrate_numpy(moments, w0, qref0, t, tol, order, dt, max_steps, threshold)


def _integrate_numpy(moments, w0, qref0, t, tol, order, dt, max_steps, threshold):
    moments = np.asarray(moments)
    w0 = np.asarray(w0)
    qref0 = np.asarray(qref0)
    t = np.asarray(t)
    dtype = np.result_type(moments, w0, qref0, t)
    B = moments.shape[0]
    T = t.shape[0]
    I1, I2, I3 = moments[:, 0], moments[:, 1], moments[:, 2]
    a = np.stack(euler_coefficients(I1, I2, I3)).astype(dtype)
    q_out = np.zeros((B, T, 4), dtype=dtype)
    w_out = np.zeros((B, T, 3), dtype=dtype)
    stats = np.zeros((B, 3), dtype=np.int64)
    tf = _to_float(t)
    safety = step_safety(order)
    thr2 = threshold * threshold
    w0c = np.ascontiguousarray(w0.T).astype(dtype)
    scale_w_all = _to_float(np.abs(w0c).max(axis=0))
    pos = np.flatnonzero(tf >= 0)
    pos = pos[np.argsort(tf[pos], kind="stable")]
    neg = np.flatnonzero(tf < 0)
    neg = neg[np.argsort(-tf[neg], kind="stable")]
    for sign, idx in ((1.0, pos), (-1.0, neg)):
        L = idx.size
        if L == 0:
            continue
        tlast = abs(tf[idx[-1]])
        tt = t[idx]
        # zeros of the working arithmetic (an int 0 in an object array would turn
        # the sums below into float64 ones: mpf(x) + float is mpf, 0 + float is float)
        zero = np.zeros(B, dtype=dtype) + moments[:, 0] * 0
        n = np.stack([zero, zero, zero])
        w = w0c.copy()
        nlo = n.copy()  # compensations: the state is (n + nlo, w + wlo)
        wlo = n.copy()
        qr = np.ascontiguousarray(qref0.T).astype(dtype)
        th = zero.copy()  # current time th + tc (two-sum of the steps)
        tc = zero.copy()
        ptr = np.zeros(B, dtype=np.int64)
        live = np.flatnonzero(stats[:, 2] == STATUS_OK)
        while live.size:
            N, W = series_principal(a[:, live], n[:, live], w[:, live], order)
            if dt is None:
                scale_n = np.maximum(1.0, _to_float(np.abs(n[:, live]).max(axis=0)))
                h = _step_sizes(N, W, order, tol, safety, scale_n, scale_w_all[live])
                rem = 2.0 * np.maximum(tlast - np.abs(_to_float(th[live])), 0.0) + 1.0
                h = np.where(np.isinf(h), rem, h)
            else:
                h = np.full(live.size, float(dt))
            stats[live, 0] += 1
            bad = ~np.isfinite(h) | ~(h > 0)
            # outputs inside this step: |t_out - t| <= h
            while True:
                pend = ptr[live] < L
                j = np.minimum(ptr[live], L - 1)
                theta = (tt[j] - th[live]) - tc[live]
                inside = pend & ~bad & (_to_float(sign * theta) <= h)
                if not inside.any():
                    break
                sel = live[inside]
                thi = theta[inside]
                nv = n[:, sel] + (_horner_delta(N[:, :, inside], thi) + nlo[:, sel])
                wv = w[:, sel] + (_horner_delta(W[:, :, inside], thi) + wlo[:, sel])
                cols = idx[ptr[sel]]
                q_out[sel, cols] = _attitude_cols(qr[:, sel], nv).T
                w_out[sel, cols] = wv.T
                ptr[sel] += 1
            finished = ptr[live] >= L
            adv = ~finished & ~bad
            hs = (sign * h).astype(np.float64)
            if adv.any():
                sl = live[adv]
                hv = hs[adv].astype(dtype)
                # compensated state update (two-sum) and time
                _two_sum_into(n, nlo, _horner_delta(N[:, :, adv], hv), sl)
                _two_sum_into(w, wlo, _horner_delta(W[:, :, adv], hv), sl)
                s, e = two_sum(th[sl], hv)
                tc[sl] = tc[sl] + e
                th[sl] = s
                nn = n[0, sl] * n[0, sl] + n[1, sl] * n[1, sl] + n[2, sl] * n[2, sl]
                nnf = _to_float(nn)
                chg = nnf > thr2
                if chg.any():
                    sc = sl[chg]
                    nc = n[:, sc]
                    qr[:, sc] = _attitude_cols(qr[:, sc], nc)
                    # R(n + nlo) = R(n) R(d), d = (nlo - n x nlo)/(1 + n.n) to first order
                    lo = nlo[:, sc]
                    den = 1 + nn[chg]
                    nlo[0, sc] = (lo[0] - (nc[1] * lo[2] - nc[2] * lo[1])) / den
                    nlo[1, sc] = (lo[1] - (nc[2] * lo[0] - nc[0] * lo[2])) / den
                    nlo[2, sc] = (lo[2] - (nc[0] * lo[1] - nc[1] * lo[0])) / den
                    n[:, sc] = zero[sc]
                    stats[sc, 1] += 1
                nonfinite = ~np.isfinite(nnf) | ~np.isfinite(_to_float(w[:, sl]).sum(0))
                stats[sl[nonfinite], 2] = STATUS_NONFINITE
            stats[live[bad], 2] = STATUS_NONFINITE
            over = adv & (stats[live, 0] >= max_steps) & (stats[live, 2] == STATUS_OK)
            stats[live[over], 2] = STATUS_MAX_STEPS
            live = live[adv & (stats[live, 2] == STATUS_OK)]
    return q_out, w_out, stats


# ---------------------------------------------------------------------------
# compiled kernels
# ---------------------------------------------------------------------------
def _nb_mul(x, y):
    """x * y rounded once (compiled without ``contract``: never fused into a later add).

    The last product of a Horner increment is added to a compensation term;
    whether LLVM fuses that multiply-add would depend on how the kernel keeps
    its state (registers or memory), so the scalar and lane kernels round it
    explicitly and agree bit for bit.
    """
    return x * y


def _nb_series(a0, a1, a2, n0, w0, order, N, W, S):
    """Taylor coefficients 1..order of one body (rows of 3: N, W; S the coefficients of n.Omega).

    All the Cauchy sums of an order run in one loop over j (each row loaded
    once), and every product is added to its sum on its own (``c += a * b``
    then ``c -= d * e``), which ``contract`` fuses into one multiply-add
    each: 15 per term. n.Omega is summed per component (three chains of
    one multiply-add per term, which overlap); 1/(k+1) is multiplied, not
    divided.
    """
    N[0, 0] = n0[0]
    N[0, 1] = n0[1]
    N[0, 2] = n0[2]
    W[0, 0] = w0[0]
    W[0, 1] = w0[1]
    W[0, 2] = w0[2]
    for k in range(order):
        inv = 1.0 / (k + 1)
        hinv = 0.5 * inv
        f0 = a0 * inv
        f1 = a1 * inv
        f2 = a2 * inv
        # the term j = 0 starts the sums (that of (n.Omega) n needs S_k: added after the loop)
        nx = N[0, 0]
        ny = N[0, 1]
        nz = N[0, 2]
        wx = W[k, 0]
        wy = W[k, 1]
        wz = W[k, 2]
        px = nx * wx
        py = ny * wy
        pz = nz * wz
        cx = ny * wz
        cx -= nz * wy
        cy = nz * wx
        cy -= nx * wz
        cz = nx * wy
        cz -= ny * wx
        e0 = W[0, 1] * wz
        e1 = W[0, 2] * wx
        e2 = W[0, 0] * wy
        sx = 0.0
        sy = 0.0
        sz = 0.0
        for j in range(1, k + 1):
            m = k - j
            nx = N[j, 0]
            ny = N[j, 1]
            nz = N[j, 2]
            wx = W[m, 0]
            wy = W[m, 1]
            wz = W[m, 2]
            px += nx * wx
            py += ny * wy
            pz += nz * wz
            cx += ny * wz
            cx -= nz * wy
            cy += nz * wx
            cy -= nx * wz
            cz += nx * wy
            cz -= ny * wx
            e0 += W[j, 1] * wz
            e1 += W[j, 2] * wx
            e2 += W[j, 0] * wy
            sm = S[m]
            sx += sm * nx
            sy += sm * ny
            sz += sm * nz
        s = (px + py) + pz
        S[k] = s
        sx += s * N[0, 0]
        sy += s * N[0, 1]
        sz += s * N[0, 2]
        N[k + 1, 0] = ((W[k, 0] + cx) + sx) * hinv
        N[k + 1, 1] = ((W[k, 1] + cy) + sy) * hinv
        N[k + 1, 2] = ((W[k, 2] + cz) + sz) * hinv
        W[k + 1, 0] = f0 * e0
        W[k + 1, 1] = f1 * e1
        W[k + 1, 2] = f2 * e2


def _nb_coefficients(moments, n0, w0, order):
    B = moments.shape[0]
    N = np.zeros((B, order + 1, 3))
    W = np.zeros((B, order + 1, 3))
    S = np.zeros(order + 1)
    for b in range(B):
        I1 = moments[b, 0]
        I2 = moments[b, 1]
        I3 = moments[b, 2]
        a0, a1, a2 = euler_coefficients(I1, I2, I3)
        _nb_series(a0, a1, a2, n0[b], w0[b], order, N[b], W[b], S)
    return N, W


def _nb_quat_gibbs(pw, px, py, pz, nx, ny, nz):
    """Unit quaternion p (x) (1, n)/|(1, n)| (compiled without ``contract``, as :func:`_nb_chart`)."""
    q0, q1, q2, q3 = qmul_components(pw, px, py, pz, 1.0, nx, ny, nz)  # times 1.0: exact, the same bits
    r = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    return q0 / r, q1 / r, q2 / r, q3 / r


def _nb_chart(nx, ny, nz, lx, ly, lz):
    """Compensation carried into the new chart: d = (nlo - n x nlo)/(1 + n.n).

    R(n + nlo) = R(n) R(d) to first order in nlo. Compiled without
    ``contract``, like :func:`_nb_quat_gibbs`: the chart change is rare, and
    unfused it rounds the same in the scalar and the lane kernel.
    """
    den = 1.0 + (nx * nx + ny * ny + nz * nz)
    return (
        (lx - (ny * lz - nz * ly)) / den,
        (ly - (nz * lx - nx * lz)) / den,
        (lz - (nx * ly - ny * lx)) / den,
    )


def _nb_horner(N, W, order, theta, n, w):
    """n(theta), Omega(theta) from the series; the six Horner chains interleaved."""
    a0 = N[order, 0]
    a1 = N[order, 1]
    a2 = N[order, 2]
    b0 = W[order, 0]
    b1 = W[order, 1]
    b2 = W[order, 2]
    for k in range(order - 1, -1, -1):
        a0 = a0 * theta + N[k, 0]
        a1 = a1 * theta + N[k, 1]
        a2 = a2 * theta + N[k, 2]
        b0 = b0 * theta + W[k, 0]
        b1 = b1 * theta + W[k, 1]
        b2 = b2 * theta + W[k, 2]
    n[0] = a0
    n[1] = a1
    n[2] = a2
    w[0] = b0
    w[1] = b1
    w[2] = b2


def _nb_horner_delta(N, W, order, theta, n, w):
    """Increments n(theta) - n(0), Omega(theta) - Omega(0) (Horner without the constant term)."""
    a0 = N[order, 0]
    a1 = N[order, 1]
    a2 = N[order, 2]
    b0 = W[order, 0]
    b1 = W[order, 1]
    b2 = W[order, 2]
    for k in range(order - 1, 0, -1):
        a0 = a0 * theta + N[k, 0]
        a1 = a1 * theta + N[k, 1]
        a2 = a2 * theta + N[k, 2]
        b0 = b0 * theta + W[k, 0]
        b1 = b1 * theta + W[k, 1]
        b2 = b2 * theta + W[k, 2]
    n[0] = _nb_mul(a0, theta)
    n[1] = _nb_mul(a1, theta)
    n[2] = _nb_mul(a2, theta)
    w[0] = _nb_mul(b0, theta)
    w[1] = _nb_mul(b1, theta)
    w[2] = _nb_mul(b2, theta)


def nb_integrate(moments, w0, qref0, t, idx_pos, idx_neg, tol, order, dt, max_steps, threshold, q_out, w_out, stats):
    B = moments.shape[0]
    N = np.zeros((order + 1, 3))
    W = np.zeros((order + 1, 3))
    S = np.zeros(order + 1)
    n = np.zeros(3)
    w = np.zeros(3)
    nlo = np.zeros(3)  # compensations: the state is (n + nlo, w + wlo)
    wlo = np.zeros(3)
    dn = np.zeros(3)
    dw = np.zeros(3)
    qr = np.zeros(4)
    nv = np.zeros(3)
    wv = np.zeros(3)
    if order > 1:
        safety = math.exp(-0.7 / (order - 1))
    else:
        safety = 0.5
    thr2 = threshold * threshold
    for b in range(B):
        I1 = moments[b, 0]
        I2 = moments[b, 1]
        I3 = moments[b, 2]
        a0, a1, a2 = euler_coefficients(I1, I2, I3)
        scale_w = max(abs(w0[b, 0]), abs(w0[b, 1]), abs(w0[b, 2]))
        steps = 0
        charts = 0
        status = 0
        for d in range(2):
            if d == 0:
                idx = idx_pos
                sign = 1.0
            else:
                idx = idx_neg
                sign = -1.0
            L = idx.shape[0]
            if L == 0 or status != 0:
                continue
            tlast = abs(t[idx[L - 1]])
            n[0] = 0.0
            n[1] = 0.0
            n[2] = 0.0
            w[0] = w0[b, 0]
            w[1] = w0[b, 1]
            w[2] = w0[b, 2]
            for c in range(3):
                nlo[c] = 0.0
                wlo[c] = 0.0
            for c in range(4):
                qr[c] = qref0[b, c]
            th = 0.0
            tc = 0.0
            ptr = 0
            while True:
                _nb_series(a0, a1, a2, n, w, order, N, W, S)
                if dt > 0.0:
                    h = dt
                else:
                    scale_n = max(1.0, abs(n[0]), abs(n[1]), abs(n[2]))
                    lrho = math.inf  # min over k of log(x_k)/k: the step is exp(lrho) (one exp, no pow)
                    nanflag = False
                    for k in range(order - 1, order + 1):
                        if k < 1:
                            continue
                        x = math.inf
                        nrm = max(abs(N[k, 0]), abs(N[k, 1]), abs(N[k, 2]))
                        if nrm != nrm:
                            nanflag = True
                        elif nrm > 0.0:
                            x = tol * scale_n / nrm
                        nrm = max(abs(W[k, 0]), abs(W[k, 1]), abs(W[k, 2]))
                        if nrm != nrm:
                            nanflag = True
                        elif nrm > 0.0:
                            x = min(x, tol * scale_w / nrm)
                        if x < math.inf:
                            r = math.log(x) / k
                            if r < lrho:
                                lrho = r
                    h = safety * math.exp(lrho)
                    if nanflag:
                        h = math.nan
                    elif math.isinf(h):
                        h = 2.0 * max(tlast - abs(th), 0.0) + 1.0
                steps += 1
                if not (h > 0.0) or math.isinf(h):
                    status = 2
                    break
                # dense output inside the step
                while ptr < L:
                    j = idx[ptr]
                    theta = (t[j] - th) - tc
                    if sign * theta > h:
                        break
                    _nb_horner_delta(N, W, order, theta, dn, dw)
                    for c in range(3):
                        nv[c] = n[c] + (dn[c] + nlo[c])
                        wv[c] = w[c] + (dw[c] + wlo[c])
                    q0, q1, q2, q3 = _nb_quat_gibbs(qr[0], qr[1], qr[2], qr[3], nv[0], nv[1], nv[2])
                    q_out[b, j, 0] = q0
                    q_out[b, j, 1] = q1
                    q_out[b, j, 2] = q2
                    q_out[b, j, 3] = q3
                    for c in range(3):
                        w_out[b, j, c] = wv[c]
                    ptr += 1
                if ptr >= L:
                    break
                hs = sign * h
                # compensated update x <- x + dx (two-sum: x + xlo is the state)
                _nb_horner_delta(N, W, order, hs, dn, dw)
                for c in range(3):
                    n[c], nlo[c] = two_sum(n[c], dn[c] + nlo[c])
                    w[c], wlo[c] = two_sum(w[c], dw[c] + wlo[c])
                # time: two-sum, t = th + tc
                th, e = two_sum(th, hs)
                tc += e
                nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
                if nn > thr2:
                    q0, q1, q2, q3 = _nb_quat_gibbs(qr[0], qr[1], qr[2], qr[3], n[0], n[1], n[2])
                    qr[0] = q0
                    qr[1] = q1
                    qr[2] = q2
                    qr[3] = q3
                    d0, d1, d2 = _nb_chart(n[0], n[1], n[2], nlo[0], nlo[1], nlo[2])
                    nlo[0] = d0
                    nlo[1] = d1
                    nlo[2] = d2
                    n[0] = 0.0
                    n[1] = 0.0
                    n[2] = 0.0
                    charts += 1
                if not (math.isfinite(nn) and math.isfinite(w[0] + w[1] + w[2])):
                    status = 2
                    break
                if steps >= max_steps:
                    status = 1
                    break
        stats[b, 0] = steps
        stats[b, 1] = charts
        stats[b, 2] = status


# ---------------------------------------------------------------------------
# compiled kernel in lanes: LANES_TAYLOR bodies advanced together (SIMD)
# ---------------------------------------------------------------------------
LANES_TAYLOR = 16
#: fewest bodies for which integrate_numba runs the lane kernel by default
LANES_MIN_BODIES = 5
_TL = LANES_TAYLOR
# one Taylor coefficient of all lanes: rows n_x n_y n_z, W_x W_y W_z, S (= n.Omega), L each
_TR = 7 * _TL
_CN, _CW, _CS = 0, 3 * _TL, 6 * _TL
# Cauchy-sum accumulators of the series kernel: n.W (3 components), n x W (3), W x W terms (3), S n (3)
_ACC = 12 * _TL
#: lanes per pass of the series kernel's loop over j (its sums for 8 lanes fit in registers)
_HB = 8
# lane state (rows of L): n, Omega, their compensations, reference quaternion,
# time (hi, lo), signed step, Horner increments of n and Omega
_XN, _XW, _XNL, _XWL = 0, 3 * _TL, 6 * _TL, 9 * _TL
_XQ = 12 * _TL
_XTH, _XTC, _XH = 16 * _TL, 17 * _TL, 18 * _TL
_XDN, _XDW = 19 * _TL, 22 * _TL
_XSIZE = 25 * _TL


def _nb_series_lanes(a, buf, order):
    """Taylor coefficients 1..order of all lanes from coefficient 0 (lane layout).

    ``buf`` holds coefficient k of lane l at ``k*_TR + row*_TL + l``; ``a`` the
    Euler coefficients (3 rows of L). The same operations in the same order
    as :func:`_nb_series`, lane by lane: the j-th Cauchy term is read through
    two row views (non-negative constant offsets, contiguous in the lanes)
    and summed into a stack buffer, so LLVM vectorizes the lane loops. The
    loop over j runs once per ``_HB`` (8) lanes: the 12 sums of 8 lanes (24
    AVX2 registers) stay in registers through it, those of 16 lanes were
    spilled to the stack (measured: 270 against 450 ns per body and step).
    """
    acc = stack_buffer(_ACC)
    for k in range(order):
        inv = 1.0 / (k + 1)
        hinv = 0.5 * inv
        ok = k * _TR
        ck = buf[ok : ok + _TR]
        for i in range(_ACC):
            acc[i] = 0.0
        for l in range(_TL):
            ck[_CS + l] = 0.0  # S_k, the sum being made: its term j = 0 is added after the loop
        # the lanes in halves: a half's 12 sums stay in vector registers through the loop over j
        for hb in range(0, _TL, _HB):
            ac = acc[hb:]
            for j in range(k + 1):
                oj = j * _TR + hb
                om = (k - j) * _TR + hb
                cj = buf[oj : oj + _TR]
                cm = buf[om : om + _TR]
                for l in range(_HB):
                    nx = cj[_CN + l]
                    ny = cj[_CN + _TL + l]
                    nz = cj[_CN + 2 * _TL + l]
                    wx = cm[_CW + l]
                    wy = cm[_CW + _TL + l]
                    wz = cm[_CW + 2 * _TL + l]
                    ac[l] += nx * wx
                    ac[_TL + l] += ny * wy
                    ac[2 * _TL + l] += nz * wz
                    ac[3 * _TL + l] += ny * wz
                    ac[3 * _TL + l] -= nz * wy
                    ac[4 * _TL + l] += nz * wx
                    ac[4 * _TL + l] -= nx * wz
                    ac[5 * _TL + l] += nx * wy
                    ac[5 * _TL + l] -= ny * wx
                    ac[6 * _TL + l] += cj[_CW + _TL + l] * wz
                    ac[7 * _TL + l] += cj[_CW + 2 * _TL + l] * wx
                    ac[8 * _TL + l] += cj[_CW + l] * wy
                    sm = cm[_CS + l]
                    ac[9 * _TL + l] += sm * nx
                    ac[10 * _TL + l] += sm * ny
                    ac[11 * _TL + l] += sm * nz
        o1 = ok + _TR
        c1 = buf[o1 : o1 + _TR]
        for l in range(_TL):
            s = (acc[l] + acc[_TL + l]) + acc[2 * _TL + l]
            ck[_CS + l] = s
            sx = acc[9 * _TL + l] + s * buf[_CN + l]
            sy = acc[10 * _TL + l] + s * buf[_CN + _TL + l]
            sz = acc[11 * _TL + l] + s * buf[_CN + 2 * _TL + l]
            c1[_CN + l] = ((ck[_CW + l] + acc[3 * _TL + l]) + sx) * hinv
            c1[_CN + _TL + l] = ((ck[_CW + _TL + l] + acc[4 * _TL + l]) + sy) * hinv
            c1[_CN + 2 * _TL + l] = ((ck[_CW + 2 * _TL + l] + acc[5 * _TL + l]) + sz) * hinv
            c1[_CW + l] = (a[l] * inv) * acc[6 * _TL + l]
            c1[_CW + _TL + l] = (a[_TL + l] * inv) * acc[7 * _TL + l]
            c1[_CW + 2 * _TL + l] = (a[2 * _TL + l] * inv) * acc[8 * _TL + l]


def _nb_lane_horner_delta(buf, l, order, theta):
    """Increments n(theta) - n(0), Omega(theta) - Omega(0) of lane l (as :func:`_nb_horner_delta`)."""
    o = order * _TR + l
    a0 = buf[o]
    a1 = buf[o + _TL]
    a2 = buf[o + 2 * _TL]
    b0 = buf[o + 3 * _TL]
    b1 = buf[o + 4 * _TL]
    b2 = buf[o + 5 * _TL]
    for k in range(order - 1, 0, -1):
        o = k * _TR + l
        a0 = a0 * theta + buf[o]
        a1 = a1 * theta + buf[o + _TL]
        a2 = a2 * theta + buf[o + 2 * _TL]
        b0 = b0 * theta + buf[o + 3 * _TL]
        b1 = b1 * theta + buf[o + 4 * _TL]
        b2 = b2 * theta + buf[o + 5 * _TL]
    return (
        _nb_mul(a0, theta),
        _nb_mul(a1, theta),
        _nb_mul(a2, theta),
        _nb_mul(b0, theta),
        _nb_mul(b1, theta),
        _nb_mul(b2, theta),
    )


def nb_integrate_lanes(
    moments,
    w0,
    qref0,
    t,
    idx_pos,
    idx_neg,
    tol,
    order,
    dt,
    max_steps,
    threshold,
    q_out,
    w_out,
    stats,
    buf,
    lane_a,
    lane_i,
    lane_f,
):
    """:func:`nb_integrate` with ``_TL`` bodies in lockstep, one per lane.

    Every lane runs the scalar kernel's algorithm on its own body (its own
    steps, outputs and chart changes); when a body is done the lane takes
    the next one, so the lanes stay busy until the last bodies. The Taylor
    coefficients and the state update are computed for all lanes at once
    (vector code); step sizes, dense output and chart changes lane by lane.
    ``buf`` ((order+1)*_TR), ``lane_a`` (3*_TL), ``lane_i`` (10*_TL int64) and
    ``lane_f`` (3*_TL) are work arrays from the caller.
    """
    B = moments.shape[0]
    x = stack_buffer(_XSIZE)
    for i in range(_XSIZE):
        x[i] = 0.0
    for i in range(buf.shape[0]):
        buf[i] = 0.0
    # int state per lane: body (-1 none), direction, output pointer, outputs of
    # the direction, steps, charts, status, needs a task, active, advanced
    body = lane_i[0:_TL]
    dirn = lane_i[_TL : 2 * _TL]
    ptr = lane_i[2 * _TL : 3 * _TL]
    nout = lane_i[3 * _TL : 4 * _TL]
    steps = lane_i[4 * _TL : 5 * _TL]
    charts = lane_i[5 * _TL : 6 * _TL]
    status = lane_i[6 * _TL : 7 * _TL]
    need = lane_i[7 * _TL : 8 * _TL]
    active = lane_i[8 * _TL : 9 * _TL]
    adv = lane_i[9 * _TL : 10 * _TL]
    scale_w = lane_f[0:_TL]
    tlast = lane_f[_TL : 2 * _TL]
    sgn = lane_f[2 * _TL : 3 * _TL]
    for l in range(_TL):
        body[l] = -1
        need[l] = 1
        active[l] = 0
        lane_a[l] = 0.0
        lane_a[_TL + l] = 0.0
        lane_a[2 * _TL + l] = 0.0
    if order > 1:
        safety = math.exp(-0.7 / (order - 1))
    else:
        safety = 0.5
    thr2 = threshold * threshold
    next_body = 0
    n_pos = idx_pos.shape[0]
    n_neg = idx_neg.shape[0]
    while True:
        # tasks: the next direction of the lane's body, else the next body
        n_active = 0
        for l in range(_TL):
            while need[l] != 0:
                b = body[l]
                if b >= 0:
                    d = dirn[l] + 1
                    started = False
                    while d < 2 and status[l] == 0:
                        cnt = n_pos if d == 0 else n_neg
                        if cnt > 0:
                            started = True
                            break
                        d += 1
                    if started:
                        dirn[l] = d
                        if d == 0:
                            sgn[l] = 1.0
                            tlast[l] = abs(t[idx_pos[n_pos - 1]])
                            nout[l] = n_pos
                        else:
                            sgn[l] = -1.0
                            tlast[l] = abs(t[idx_neg[n_neg - 1]])
                            nout[l] = n_neg
                        for c in range(3):
                            x[_XN + c * _TL + l] = 0.0
                            x[_XW + c * _TL + l] = w0[b, c]
                            x[_XNL + c * _TL + l] = 0.0
                            x[_XWL + c * _TL + l] = 0.0
                        for c in range(4):
                            x[_XQ + c * _TL + l] = qref0[b, c]
                        x[_XTH + l] = 0.0
                        x[_XTC + l] = 0.0
                        ptr[l] = 0
                        need[l] = 0
                        active[l] = 1
                        break
                    stats[b, 0] = steps[l]
                    stats[b, 1] = charts[l]
                    stats[b, 2] = status[l]
                    body[l] = -1
                    active[l] = 0
                if next_body < B:
                    b = next_body
                    next_body += 1
                    body[l] = b
                    dirn[l] = -1
                    steps[l] = 0
                    charts[l] = 0
                    status[l] = 0
                    I1 = moments[b, 0]
                    I2 = moments[b, 1]
                    I3 = moments[b, 2]
                    lane_a[l], lane_a[_TL + l], lane_a[2 * _TL + l] = euler_coefficients(I1, I2, I3)
                    scale_w[l] = max(abs(w0[b, 0]), abs(w0[b, 1]), abs(w0[b, 2]))
                else:
                    need[l] = 0
                    active[l] = 0
                    # an idle lane integrates a body at rest (no NaN, no cost to the others)
                    for c in range(3):
                        x[_XN + c * _TL + l] = 0.0
                        x[_XW + c * _TL + l] = 0.0
            n_active += active[l]
        if n_active == 0:
            break
        # Taylor coefficients of all lanes
        for c in range(3):
            for l in range(_TL):
                buf[_CN + c * _TL + l] = x[_XN + c * _TL + l]
                buf[_CW + c * _TL + l] = x[_XW + c * _TL + l]
        _nb_series_lanes(lane_a, buf, order)
        # step sizes and dense output, lane by lane
        for l in range(_TL):
            x[_XH + l] = 0.0
            adv[l] = 0
            if active[l] == 0:
                continue
            if dt > 0.0:
                h = dt
            else:
                scale_n = max(1.0, abs(x[_XN + l]), abs(x[_XN + _TL + l]), abs(x[_XN + 2 * _TL + l]))
                lrho = math.inf  # as in nb_integrate: the step is exp(min log(x_k)/k)
                nanflag = False
                for k in range(order - 1, order + 1):
                    if k < 1:
                        continue
                    o = k * _TR + l
                    xx = math.inf
                    nrm = max(abs(buf[o]), abs(buf[o + _TL]), abs(buf[o + 2 * _TL]))
                    if nrm != nrm:
                        nanflag = True
                    elif nrm > 0.0:
                        xx = tol * scale_n / nrm
                    nrm = max(abs(buf[o + 3 * _TL]), abs(buf[o + 4 * _TL]), abs(buf[o + 5 * _TL]))
                    if nrm != nrm:
                        nanflag = True
                    elif nrm > 0.0:
                        xx = min(xx, tol * scale_w[l] / nrm)
                    if xx < math.inf:
                        r = math.log(xx) / k
                        if r < lrho:
                            lrho = r
                h = safety * math.exp(lrho)
                if nanflag:
                    h = math.nan
                elif math.isinf(h):
                    h = 2.0 * max(tlast[l] - abs(x[_XTH + l]), 0.0) + 1.0
            steps[l] += 1
            if not (h > 0.0) or math.isinf(h):
                status[l] = STATUS_NONFINITE
                need[l] = 1
                continue
            b = body[l]
            sign = sgn[l]
            L = nout[l]
            while ptr[l] < L:
                if dirn[l] == 0:
                    j = idx_pos[ptr[l]]
                else:
                    j = idx_neg[ptr[l]]
                theta = (t[j] - x[_XTH + l]) - x[_XTC + l]
                if sign * theta > h:
                    break
                d0, d1, d2, e0, e1, e2 = _nb_lane_horner_delta(buf, l, order, theta)
                nx = x[_XN + l] + (d0 + x[_XNL + l])
                ny = x[_XN + _TL + l] + (d1 + x[_XNL + _TL + l])
                nz = x[_XN + 2 * _TL + l] + (d2 + x[_XNL + 2 * _TL + l])
                q0, q1, q2, q3 = _nb_quat_gibbs(
                    x[_XQ + l], x[_XQ + _TL + l], x[_XQ + 2 * _TL + l], x[_XQ + 3 * _TL + l], nx, ny, nz
                )
                q_out[b, j, 0] = q0
                q_out[b, j, 1] = q1
                q_out[b, j, 2] = q2
                q_out[b, j, 3] = q3
                w_out[b, j, 0] = x[_XW + l] + (e0 + x[_XWL + l])
                w_out[b, j, 1] = x[_XW + _TL + l] + (e1 + x[_XWL + _TL + l])
                w_out[b, j, 2] = x[_XW + 2 * _TL + l] + (e2 + x[_XWL + 2 * _TL + l])
                ptr[l] += 1
            if ptr[l] >= L:
                need[l] = 1
                continue
            x[_XH + l] = sign * h
            adv[l] = 1
        # compensated update of all lanes; a lane that does not advance (h = 0) is idle (at
        # rest, state zero) or done with its task (its state is reloaded before it is used)
        oo = order * _TR
        for c in range(3):
            for l in range(_TL):
                x[_XDN + c * _TL + l] = buf[oo + _CN + c * _TL + l]
                x[_XDW + c * _TL + l] = buf[oo + _CW + c * _TL + l]
        for k in range(order - 1, 0, -1):
            ok = k * _TR
            ck = buf[ok : ok + _TR]
            for l in range(_TL):
                hl = x[_XH + l]
                x[_XDN + l] = x[_XDN + l] * hl + ck[_CN + l]
                x[_XDN + _TL + l] = x[_XDN + _TL + l] * hl + ck[_CN + _TL + l]
                x[_XDN + 2 * _TL + l] = x[_XDN + 2 * _TL + l] * hl + ck[_CN + 2 * _TL + l]
                x[_XDW + l] = x[_XDW + l] * hl + ck[_CW + l]
                x[_XDW + _TL + l] = x[_XDW + _TL + l] * hl + ck[_CW + _TL + l]
                x[_XDW + 2 * _TL + l] = x[_XDW + 2 * _TL + l] * hl + ck[_CW + 2 * _TL + l]
        for c in range(3):
            for l in range(_TL):
                hl = x[_XH + l]
                cur = x[_XN + c * _TL + l]
                # two-sum written out (numerics.doubledouble.two_sum): this loop over the lanes must vectorize
                y = _nb_mul(x[_XDN + c * _TL + l], hl) + x[_XNL + c * _TL + l]
                s = cur + y
                z = s - cur
                x[_XNL + c * _TL + l] = (cur - (s - z)) + (y - z)
                x[_XN + c * _TL + l] = s
                cur = x[_XW + c * _TL + l]
                y = _nb_mul(x[_XDW + c * _TL + l], hl) + x[_XWL + c * _TL + l]
                s = cur + y
                z = s - cur
                x[_XWL + c * _TL + l] = (cur - (s - z)) + (y - z)
                x[_XW + c * _TL + l] = s
        # time, chart changes and checks, lane by lane
        for l in range(_TL):
            if adv[l] == 0:
                continue
            hs = x[_XH + l]
            s, e = two_sum(x[_XTH + l], hs)
            x[_XTC + l] += e
            x[_XTH + l] = s
            n0 = x[_XN + l]
            n1 = x[_XN + _TL + l]
            n2 = x[_XN + 2 * _TL + l]
            nn = n0 * n0 + n1 * n1 + n2 * n2
            if nn > thr2:
                q0, q1, q2, q3 = _nb_quat_gibbs(
                    x[_XQ + l], x[_XQ + _TL + l], x[_XQ + 2 * _TL + l], x[_XQ + 3 * _TL + l], n0, n1, n2
                )
                x[_XQ + l] = q0
                x[_XQ + _TL + l] = q1
                x[_XQ + 2 * _TL + l] = q2
                x[_XQ + 3 * _TL + l] = q3
                d0, d1, d2 = _nb_chart(n0, n1, n2, x[_XNL + l], x[_XNL + _TL + l], x[_XNL + 2 * _TL + l])
                x[_XNL + l] = d0
                x[_XNL + _TL + l] = d1
                x[_XNL + 2 * _TL + l] = d2
                x[_XN + l] = 0.0
                x[_XN + _TL + l] = 0.0
                x[_XN + 2 * _TL + l] = 0.0
                charts[l] += 1
            wsum = x[_XW + l] + x[_XW + _TL + l] + x[_XW + 2 * _TL + l]
            if not (math.isfinite(nn) and math.isfinite(wsum)):
                status[l] = STATUS_NONFINITE
                need[l] = 1
            elif steps[l] >= max_steps:
                status[l] = STATUS_MAX_STEPS
                need[l] = 1


if USE_NUMBA:  # pragma: no branch
    from ...util.jit import lazy_njit as _njit  # made when numba is first used, not at import

    _nb_mul = _njit(cache=True, nogil=True)(_nb_mul)  # no fastmath flags: never contracted
    _nb_series = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_series)
    _nb_quat_gibbs = _njit(cache=True, nogil=True)(_nb_quat_gibbs)  # no contract, see its docstring
    _nb_chart = _njit(cache=True, nogil=True)(_nb_chart)
    _nb_horner = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_horner)
    _nb_horner_delta = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_horner_delta)
    _nb_coefficients = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_coefficients)
    nb_integrate = _njit(cache=True, nogil=True, fastmath={"contract"})(nb_integrate)
    _nb_series_lanes = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_series_lanes)
    _nb_lane_horner_delta = _njit(cache=True, nogil=True, fastmath={"contract"})(_nb_lane_horner_delta)
    nb_integrate_lanes = _njit(cache=True, nogil=True, fastmath={"contract"})(nb_integrate_lanes)


def coefficients_numba(moments, n0, w0, order):
    """Taylor coefficients by the compiled kernel, (B, order+1, 3) each (float64).

    Runs the plain-Python version of the same code when numba is not used.
    """
    return _nb_coefficients(kernel_array(moments), kernel_array(n0), kernel_array(w0), int(order))


def integrate_numba(moments, w0, qref0, t, *, tol, order, dt, max_steps, threshold, lanes=None):
    """Compiled Taylor integration; same arguments and results as :func:`integrate_numpy` (float64 only).

    ``lanes``: None (default) runs the lane kernel (``LANES_TAYLOR`` bodies
    in lockstep, SIMD) when there are at least ``LANES_MIN_BODIES`` bodies,
    else one body after the other; True or False forces one of the two.
    Both take the same steps and give the same results (to round-off; bit
    for bit when LLVM contracts the same multiply-adds in both).

    Runs the plain-Python version of the same code when numba is not used
    (slow; :func:`integrate_numpy` is the fallback actually used then).
    """
    # (one signature per kernel)
    moments, w0, qref0, t = kernel_array(moments), kernel_array(w0), kernel_array(qref0), kernel_array(t)
    B, T = moments.shape[0], t.shape[0]
    if T == 1:  # one output time: the orderings below without the sorting
        one, none = np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64)
        pos, neg = (one, none) if t.item() >= 0 else (none, one)
    else:
        pos = np.flatnonzero(t >= 0)
        pos = np.ascontiguousarray(pos[np.argsort(t[pos], kind="stable")], dtype=np.int64)
        neg = np.flatnonzero(t < 0)
        neg = np.ascontiguousarray(neg[np.argsort(-t[neg], kind="stable")], dtype=np.int64)
    q_out = np.zeros((B, T, 4))
    w_out = np.zeros((B, T, 3))
    stats = np.zeros((B, 3), dtype=np.int64)
    args = (
        moments,
        w0,
        qref0,
        t,
        pos,
        neg,
        float(tol),
        int(order),
        float(dt) if dt is not None else -1.0,
        int(max_steps),
        float(threshold),
        q_out,
        w_out,
        stats,
    )
    if lanes is None:
        lanes = USE_NUMBA and B >= LANES_MIN_BODIES
    if lanes:
        nb_integrate_lanes(
            *args,
            np.zeros((int(order) + 1) * _TR),
            np.zeros(3 * _TL),
            np.zeros(10 * _TL, dtype=np.int64),
            np.zeros(3 * _TL),
        )
    else:
        nb_integrate(*args)
    return q_out, w_out, stats
