r"""The paper's Lie series as an arbitrary-order Taylor integrator (``method="taylor"``).

The paper writes the general solution as the exponential of the Hamiltonian
vector field :math:`X = \{\cdot, H\}` (eq. 1.23.1),

.. math:: z(t) = e^{tL_X} z_0 = \sum_{k\ge0} \frac{t^k}{k!} L_X^k z\big|_{z_0},

a Lie series whose terms are the Taylor coefficients of the motion. This
module computes them to any order by *Taylor-mode automatic differentiation*:
the right-hand side of the paper's eq. 1.30 (the variables
:math:`(\mathbf n, \boldsymbol\Omega)`, related to the canonical
:math:`(\mathbf n, \boldsymbol\pi)` by eq. 1.26)

.. math::

    \dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega
      = \tfrac12\big(\boldsymbol\Omega + \mathbf n\times\boldsymbol\Omega + (\mathbf n\cdot\boldsymbol\Omega)\mathbf n\big),
    \qquad I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega,

is a polynomial, so with :math:`x(t)=\sum_k x_k t^k` every product is a
Cauchy product :math:`(xy)_k=\sum_{j\le k}x_jy_{k-j}` and
:math:`x_{k+1} = f_k/(k+1)`: order :math:`p` costs :math:`O(p^2)` per step.
:func:`lie_series_coefficients` does the same directly in
:math:`(\mathbf n, \boldsymbol\pi)` from Hamilton's equations of eq. 1.15.

The integrator (Jorba & Zou 2005) takes the order
:math:`p=\lceil-\tfrac12\ln\varepsilon+1\rceil` from the tolerance and the step
from the last two coefficients, :math:`h = e^{-0.7/(p-1)}\min_{k\in\{p-1,p\}}
(\varepsilon s/\lVert x_k\rVert_\infty)^{1/k}` taken over the groups
:math:`x=\mathbf n` (scale :math:`s=\max(1,\lVert\mathbf n_0\rVert_\infty)`,
Jorba-Zou's mixed absolute/relative rule) and :math:`x=\boldsymbol\Omega`
(scale :math:`s=\lVert\boldsymbol\Omega_0\rVert_\infty`, relative: the only
unit-free choice for a quantity with units, which keeps the step invariant
under a change of time unit). Output times inside a step are evaluated from
the step's Taylor polynomial (Horner), so they cost nothing extra.

Round-off. At ``tol`` near machine epsilon the error is round-off, so the
state is carried as an unevaluated sum :math:`x + \delta x` (the same for the
time): each step adds the increment :math:`\sum_{k\ge1}x_kh^k` (Horner
without the constant term) by an error-free two-sum (Knuth; Møller), and the
small part :math:`\delta\mathbf n` survives a chart change as the Gibbs
vector :math:`(\delta\mathbf n - \mathbf n\times\delta\mathbf n)/(1+n^2)`
of :math:`R(\mathbf n)^{-1}R(\mathbf n+\delta\mathbf n)` (first order).
This brought the attitude error at t = 100 for :math:`I=\mathrm{diag}(1,2,3)`,
:math:`\boldsymbol\Omega_0=(1,0.1,0.5)`, ``tol`` = eps from 2.1e-14 to
1.5e-15 rad, and the relative energy error at t = 1e5 from 6e-14 to 1.3e-15.
In ``mpmath``/``longdouble`` arithmetic every sum stays in that arithmetic
(the float64 steps enter exactly).

Charts through :math:`\alpha=\pi`. :math:`\mathbf n=\mathbf k\tan(\alpha/2)`
is infinite at :math:`\alpha=\pi`, which every tumbling body reaches. The free
body is left-invariant, so the motion continues in the chart
:math:`R=R_0R(\mathbf n)` with a reference attitude :math:`R_0` per body:
when :math:`|\mathbf n|` exceeds ``chart_threshold`` (default 0.5, i.e.
:math:`\alpha>53^\circ`) at the end of a step, :math:`R(\mathbf n)` is folded
into the reference, :math:`q_0\leftarrow q_0\otimes q(\mathbf n)`, and the
motion restarts at :math:`\mathbf n=0` with the same :math:`\boldsymbol\Omega`
(body-frame quantities do not change under the left translation; the
canonical momentum would become :math:`\boldsymbol\pi'=2I\boldsymbol\Omega`,
eq. 1.26 at :math:`\mathbf n'=0`). Every step then starts at
:math:`\alpha\le53^\circ`, so the pole of :math:`\mathbf n(t)` at
:math:`\alpha=\pi` is more than a third of a turn away on the real time axis;
a chart change costs one quaternion product (``chart_changes`` counts them).

That pole sets most steps, so the threshold trades steps against chart changes.
Measured (tol = eps): over 40 random bodies to t = 100 (against heyoka in
80-bit arithmetic) thresholds 1, 0.5, 0.25 and 0.1 took 11152, 9668, 8997 and
8479 steps in all with median attitude errors 2.2e-15, 2.1e-15, 2.1e-15 and
2.4e-15 rad; over 24 random bodies to t = 3e4 the median relative energy
errors were 5.6e-16, 8.9e-16 and 1.1e-15 at 1, 0.5 and 0.25 (means 1.2e-15,
1.2e-15, 1.3e-15). For :math:`I=\mathrm{diag}(1,2,3)`,
:math:`\boldsymbol\Omega_0=(1,0.1,0.5)` to t = 1e5: 287884, 252376 and 234561
steps, energy errors 5.3e-15, 4.1e-15 and 3.7e-14 (one sample each: the
rounding of a long run is a random walk with a long tail). 0.5 keeps the
accuracy of 1 with 13 % fewer steps; lower values are a speed option.

The motion is integrated in the principal frame :math:`P` of the inertia
tensor, :math:`R(t) = R_0\,P\,R_P(t)\,P^T` (left invariance again), so a full
symmetric tensor costs no more than a diagonal one.

References
----------
Paper eq. 1.15-1.16, 1.23.1, 1.26, 1.30. A. Jorba and M. Zou, "A software
package for the numerical integration of ODEs by means of high-order Taylor
methods", Exp. Math. 14 (2005) 99-117. D. E. Knuth, *The Art of Computer
Programming* vol. 2, 3rd ed. (1997), sec. 4.2.2 (two-sum). W. Gröbner, *Die Lie-Reihen und ihre
Anwendungen* (1960). A. Griewank and A. Walther, *Evaluating Derivatives*,
2nd ed., SIAM (2008), ch. 13 (Taylor-mode arithmetic).
"""

from __future__ import annotations

import functools
import math
import numbers
from contextlib import nullcontext as _nullcontext
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...attitude.core import quaternion_from_rotation_matrix
from ...errors import EulerPoissonError, InvalidInputError, require
from ...model.free_body import euler_coefficients
from ...numerics.quaternion import qmul
from ...util.validate import as_float_array, as_scalar
from ..problem import Problem
from ..registry import Method, MethodOptions, MethodResult, overrides, register_method
from . import kernels as _k

__all__ = [
    "Taylor",
    "taylor_coefficients",
    "lie_series_coefficients",
    "integrate_principal",
    "auto_order",
    "DEFAULT_FIXED_ORDER",
    "TAYLOR_CHART_THRESHOLD",
]

#: Taylor order used in fixed-step mode (``dt`` given) when ``order`` is None
DEFAULT_FIXED_ORDER = 4

#: taylor's default ``chart_threshold`` (rk and symplectic: charts.DEFAULT_CHART_THRESHOLD): the chart is re-centred when :math:`|\mathbf n|` exceeds it (the module notes)
TAYLOR_CHART_THRESHOLD = 0.5
#: largest accepted Taylor order
MAX_ORDER = 200

auto_order = _k.auto_order


# ---------------------------------------------------------------------------
# input helpers accepting float64, longdouble and object (mpmath) arrays
# ---------------------------------------------------------------------------
def _is_generic(a) -> bool:
    return isinstance(a, np.ndarray) and (a.dtype == object or a.dtype == np.longdouble) and a.dtype != np.float64


def _as_array(x, name, tail=()):
    """float64 array (validated), or an object/longdouble array kept as it is (shape checked)."""
    a = x if isinstance(x, np.ndarray) else None
    if a is None and isinstance(x, (list, tuple)):
        try:
            cand = np.asarray(x)
        except Exception:  # ragged input: let as_float_array report it
            cand = None
        if cand is not None and (cand.dtype == object or cand.dtype == np.longdouble):
            a = cand
    if a is not None and _is_generic(a):
        nt = len(tail)
        if nt and (a.ndim < nt or a.shape[a.ndim - nt :] != tuple(tail)):
            want = "(..., " + ", ".join(str(t) for t in tail) + ")"
            raise InvalidInputError(f"{name} must have shape {want}, got shape {a.shape}")
        return a
    return as_float_array(x, name, tail)


def _check_order(order, *, adaptive: bool) -> int:
    if isinstance(order, bool) or not isinstance(order, (numbers.Integral, np.integer)):
        raise TypeError(f"order must be an integer or None, got {type(order).__name__} {order!r}")
    lo = 2 if adaptive else 1
    if not lo <= int(order) <= MAX_ORDER:
        mode = "with adaptive steps" if adaptive else "with a fixed step dt"
        raise InvalidInputError(f"order must be between {lo} and {MAX_ORDER} {mode}, got {order!r}")
    return int(order)


def _check_tol(tol, dtype) -> float:
    tol = as_scalar(tol, "tol")
    eps = np.finfo(dtype).eps if dtype != np.dtype(object) else 0.0
    if not (tol >= eps and tol > 0 and tol < 1):
        lo = f"machine epsilon {float(eps):.3g}" if eps else "0 (exclusive)"
        raise InvalidInputError(f"tol must be in [{lo}, 1), got {tol!r}")
    return tol


def _inertia_parts(inertia):
    """Generic-arithmetic pieces of an inertia argument: ('diag', moments (3, ...)) or ('tensor', I, Iinv)."""
    I = _as_array(inertia, "inertia")
    if I.ndim >= 2 and I.shape[-2:] == (3, 3):
        It = np.moveaxis(I, (-2, -1), (0, 1))  # (3, 3, ...) with It[i, j] = I[..., i, j]
        return "tensor", It, _k.inverse3(It)
    if I.ndim >= 1 and I.shape[-1] == 3:
        return "diag", np.moveaxis(I, -1, 0)
    raise InvalidInputError(
        f"inertia must be three principal moments (..., 3) or a tensor (..., 3, 3); got shape {I.shape}"
    )


def _euler_coefficients(m):
    I1, I2, I3 = m[0], m[1], m[2]
    return np.stack(euler_coefficients(I1, I2, I3))


def _check_series_order(order) -> int:
    """Validate the order of a Taylor-coefficient request (0 to ``MAX_ORDER``)."""
    if isinstance(order, bool) or not isinstance(order, (numbers.Integral, np.integer)):
        raise TypeError(f"order must be an integer, got {type(order).__name__} {order!r}")
    if not 0 <= int(order) <= MAX_ORDER:
        raise InvalidInputError(f"order must be between 0 and {MAX_ORDER}, got {order!r}")
    return int(order)


def taylor_coefficients(n0, omega0, inertia, order):
    r"""Taylor coefficients of :math:`(\mathbf n(t), \boldsymbol\Omega(t))` through a state (eq. 1.30).

    The terms of the Lie series (eq. 1.23.1) in the variables
    :math:`(\mathbf n, \boldsymbol\Omega)`:
    :math:`\mathbf n(t) = \sum_{k=0}^{p} \mathbf n_k t^k + O(t^{p+1})` with
    :math:`\mathbf n_k = L_X^k\mathbf n/k!`, and the same for
    :math:`\boldsymbol\Omega`.

    Works with any arithmetic: float64 inputs, ``numpy.longdouble`` arrays, or
    object arrays of ``mpmath.mpf`` (the result has the same type).

    Parameters
    ----------
    n0 : array_like, shape (..., 3)
        Gibbs vector at the expansion point (``n0 = 0`` for the paper's
        trajectories through the identity).
    omega0 : array_like, shape (..., 3)
        Body angular velocity there.
    inertia : array_like, shape (..., 3) or (..., 3, 3)
        Principal moments (diagonal tensor) or a full symmetric tensor.
    order : int
        Highest power of t, 0 <= order <= 200.

    Returns
    -------
    n_k, omega_k : ndarray, shape (order+1, ..., 3)
        Coefficients of :math:`t^k`.

    Raises
    ------
    InvalidInputError
        Wrong shapes, NaN/inf, order out of range.
    TypeError
        Non-integer order.

    References
    ----------
    Paper eq. 1.23.1 and 1.30.

    Examples
    --------
    >>> nk, wk = taylor_coefficients([0, 0, 0], [1.0, 0, 0], [1.0, 2.0, 3.0], 3)
    >>> nk[:, 0].tolist()   # tan(t/2) = t/2 + t^3/24 + ...
    [0.0, 0.5, 0.0, 0.041666666666666664]
    """
    order = _check_series_order(order)
    n = np.moveaxis(_as_array(n0, "n0", (3,)), -1, 0)
    w = np.moveaxis(_as_array(omega0, "omega0", (3,)), -1, 0)
    parts = _inertia_parts(inertia)
    if parts[0] == "diag":
        m = parts[1]
        shape = np.broadcast_shapes(n.shape[1:], w.shape[1:], m.shape[1:])
        a = np.broadcast_to(_euler_coefficients(m), (3,) + shape)
        N, W = _k.series_principal(a, np.broadcast_to(n, (3,) + shape), np.broadcast_to(w, (3,) + shape), order)
    else:
        It, Iinv = parts[1], parts[2]
        shape = np.broadcast_shapes(n.shape[1:], w.shape[1:], It.shape[2:])
        N, W = _k.series_tensor(
            np.broadcast_to(It, (3, 3) + shape),
            np.broadcast_to(Iinv, (3, 3) + shape),
            np.broadcast_to(n, (3,) + shape),
            np.broadcast_to(w, (3,) + shape),
            order,
        )
    return np.moveaxis(N, 1, -1), np.moveaxis(W, 1, -1)


def lie_series_coefficients(n0, pi0, inertia, order):
    r"""Terms of the paper's Lie series in the canonical variables :math:`(\mathbf n, \boldsymbol\pi)` (eq. 1.23.1).

    :math:`z(t) = \sum_k z_k t^k` with :math:`z_k = L_X^k z/k!` for
    :math:`z = (\mathbf n, \boldsymbol\pi)`, computed by Taylor-mode
    recurrences on Hamilton's equations of :math:`H` (eq. 1.15),

    .. math::

        \dot{\mathbf n} = \tfrac14\tilde A^T I^{-1}\tilde A\boldsymbol\pi, \qquad
        \dot{\boldsymbol\pi} = -\tfrac14\big[(\mathbf n\cdot\boldsymbol\pi)\mathbf v
            + (\mathbf n\cdot\mathbf v)\boldsymbol\pi + \mathbf v\times\boldsymbol\pi\big],
        \quad \mathbf v = I^{-1}\tilde A\boldsymbol\pi

    (eq. 1.16; its printed :math:`\epsilon_{ijk}n_k` must read
    :math:`\epsilon_{ijk}\pi_k` to equal :math:`-\partial H/\partial n_i`).
    Independent of :func:`taylor_coefficients` (a different recurrence on a
    different system); the two agree through :math:`\boldsymbol\pi = 2AI\boldsymbol\Omega`
    (eq. 1.26). Any arithmetic, as in :func:`taylor_coefficients`.

    Parameters
    ----------
    n0, pi0 : array_like, shape (..., 3)
        Canonical coordinates and momenta at the expansion point
        (:math:`\boldsymbol\pi_0 = 2I\boldsymbol\Omega_0` at :math:`\mathbf n_0 = 0`).
    inertia : array_like, shape (..., 3) or (..., 3, 3)
    order : int

    Returns
    -------
    n_k, pi_k : ndarray, shape (order+1, ..., 3)

    Raises
    ------
    InvalidInputError, TypeError
        As :func:`taylor_coefficients`.

    References
    ----------
    Paper eq. 1.15, 1.16, 1.23.1, 1.26.
    """
    order = _check_series_order(order)
    n = np.moveaxis(_as_array(n0, "n0", (3,)), -1, 0)
    p = np.moveaxis(_as_array(pi0, "pi0", (3,)), -1, 0)
    parts = _inertia_parts(inertia)
    if parts[0] == "diag":
        m = parts[1]
        inv = 1 / m if m.dtype == object else np.reciprocal(m)
        zero = inv[0] * 0
        Iinv = np.stack(
            [np.stack([inv[0], zero, zero]), np.stack([zero, inv[1], zero]), np.stack([zero, zero, inv[2]])]
        )
    else:
        Iinv = parts[2]
    shape = np.broadcast_shapes(n.shape[1:], p.shape[1:], Iinv.shape[2:])
    N, P = _k.series_canonical(
        np.broadcast_to(Iinv, (3, 3) + shape),
        np.broadcast_to(n, (3,) + shape),
        np.broadcast_to(p, (3,) + shape),
        order,
    )
    return np.moveaxis(N, 1, -1), np.moveaxis(P, 1, -1)


# ---------------------------------------------------------------------------
# integration
# ---------------------------------------------------------------------------
def integrate_principal(
    moments,
    omega0,
    t,
    *,
    q0=None,
    tol=1e-15,
    order=None,
    dt=None,
    max_steps=1_000_000,
    chart_threshold=TAYLOR_CHART_THRESHOLD,
    backend="auto",
    lanes=None,
):
    r"""Taylor integration of bodies given in their principal frames.

    The engine behind ``solve(..., method="taylor")``; usable directly with
    any arithmetic (``backend="numpy"`` with ``numpy.longdouble`` or
    ``mpmath.mpf`` object arrays, e.g. ``tol=1e-30`` at ``mp.dps = 35``).

    Parameters
    ----------
    moments : array_like, shape (B, 3) or (3,)
        Principal moments :math:`I_1, I_2, I_3`.
    omega0 : array_like, shape (B, 3) or (3,)
        Initial body angular velocities (principal frame).
    t : array_like, shape (T,)
        Output times, any order; negative ones are reached by integrating
        backwards from 0.
    q0 : array_like, shape (B, 4) or (4,), optional
        Initial attitudes (unit quaternions); identity by default.
    tol : float
        Tolerance, at least the machine epsilon of the arithmetic (ignored
        when ``dt`` is given).
    order : int, optional
        Taylor order; default :func:`auto_order` (tol) with adaptive steps,
        :data:`DEFAULT_FIXED_ORDER` with ``dt``.
    dt : float, optional
        Fixed step (> 0) instead of adaptive steps.
    max_steps : int
        Maximum number of steps per body (both time directions together).
    chart_threshold : float
        Chart change when :math:`|\mathbf n|` exceeds it at the end of a step (>= 0; default
        :data:`TAYLOR_CHART_THRESHOLD`).
    backend : {"auto", "numba", "numpy"}
        ``"auto"``: compiled kernels for float64 when numba is in use
        (see :data:`~eulerpoisson.solvers.taylor.kernels.USE_NUMBA`),
        else the vectorized NumPy path (the only one for other arithmetic).
    lanes : bool or None
        Compiled backend: True runs the SIMD-lane kernel (16 bodies in
        lockstep), False the one-body kernel; None (default) the lane kernel
        for batches of ``LANES_MIN_BODIES`` (5) bodies or more. The two agree
        to round-off; :meth:`Taylor.for_batch` fixes the choice for a whole
        batch so that its chunks, solved in threads, give the same bits.

    Returns
    -------
    q : ndarray, shape (B, T, 4) (or (T, 4) for one body)
        Attitudes (unit quaternions).
    omega : ndarray, shape (B, T, 3) (or (T, 3))
        Body angular velocities.
    stats : dict
        ``steps`` (total), ``steps_max`` (largest per body), ``chart_changes``
        (total), ``max_order`` (the order used), ``backend``.

    Raises
    ------
    InvalidInputError
        Bad shapes, NaN/inf, option values out of range.
    TypeError
        Non-numeric options.
    EulerPoissonError
        ``max_steps`` exhausted, or a non-finite state (a diverging series).
    """
    m = _as_array(moments, "moments", (3,))
    w = _as_array(omega0, "omega0", (3,))
    ta = _as_array(t, "t")
    if ta.ndim > 1:
        raise InvalidInputError(f"t must be a scalar or a 1-D array of output times, got shape {ta.shape}")
    ta = np.atleast_1d(ta)
    single = m.ndim == 1 and w.ndim == 1 and (q0 is None or np.ndim(q0) == 1)
    if q0 is None:
        qa = np.array([1.0, 0.0, 0.0, 0.0])
    else:
        qa = _as_array(q0, "q0", (4,))
    if m.ndim > 2 or w.ndim > 2 or qa.ndim > 2:
        raise InvalidInputError("moments, omega0 and q0 must be 1-D (one body) or 2-D (B bodies)")
    B = max(np.atleast_2d(m).shape[0], np.atleast_2d(w).shape[0], np.atleast_2d(qa).shape[0])
    try:
        m2, w2, q2 = (
            a2 if a2.shape == shape else np.broadcast_to(a2, shape)
            for a2, shape in ((np.atleast_2d(m), (B, 3)), (np.atleast_2d(w), (B, 3)), (np.atleast_2d(qa), (B, 4)))
        )
    except ValueError as exc:
        raise InvalidInputError(
            f"moments {m.shape}, omega0 {w.shape} and q0 {qa.shape} do not broadcast to one batch"
        ) from exc
    dtype = np.result_type(m2, w2, q2, ta)
    generic = dtype != np.float64
    if generic and dtype != np.dtype(object) and dtype != np.longdouble:
        dtype = np.dtype(np.float64)
        generic = False
    if backend not in ("auto", "numba", "numpy"):
        raise InvalidInputError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
    if backend == "numba" and (generic or not _k.USE_NUMBA):
        why = "the arithmetic is not float64" if generic else "numba is not in use"
        raise InvalidInputError(f"backend='numba' is not available: {why}")
    use_numba = not generic and _k.USE_NUMBA and backend != "numpy"
    if dt is not None:
        dt = as_scalar(dt, "dt", positive=True)
    if order is None:
        tol = _check_tol(tol, dtype)
        order = auto_order(tol) if dt is None else DEFAULT_FIXED_ORDER
    else:
        order = _check_order(order, adaptive=dt is None)
        tol = _check_tol(tol, dtype)
    max_steps = as_scalar(max_steps, "max_steps", positive=True, integer=True)
    chart_threshold = as_scalar(chart_threshold, "chart_threshold", nonnegative=True)
    if not generic:
        if np.any(m2 <= 0):
            raise InvalidInputError(f"moments must be > 0, got {m.tolist()}")
    q, om, stats = _integrate_checked(m2, w2, q2, ta, tol, order, dt, max_steps, chart_threshold, use_numba, lanes)
    if single:
        return q[0], om[0], stats
    return q, om, stats


def _integrate_checked(m2, w2, q2, ta, tol, order, dt, max_steps, chart_threshold, use_numba, lanes):
    """:func:`integrate_principal` after its checks: ``(q, omega, stats)`` of the batch (B bodies).

    The arrays are (B, 3), (B, 3), (B, 4) and (T,); the options normalized (``order`` an int, ``tol``,
    ``dt`` (or None) and ``chart_threshold`` floats, ``max_steps`` an int).

    Raises
    ------
    EulerPoissonError
        ``max_steps`` exhausted, or a non-finite state (a diverging series).
    """
    kw = dict(tol=tol, order=order, dt=dt, max_steps=max_steps, threshold=chart_threshold)
    B = m2.shape[0]
    if use_numba:
        q, om, st = _k.integrate_numba(m2, w2, q2, ta, lanes=lanes, **kw)
    else:
        q, om, st = _k.integrate_numpy(m2, w2, q2, ta, **kw)
    if B == 1:  # one body: its counters as plain ints (the same numbers, fewer array reductions)
        steps, charts, failed = st[0].tolist()
        most = steps
    else:
        steps, charts = int(st[:, 0].sum()), int(st[:, 1].sum())
        most = int(st[:, 0].max()) if B else 0
        failed = st[:, 2].any()
    if failed:  # a body failed (rare): name the first
        status = st[:, 2]
        if np.any(status == _k.STATUS_MAX_STEPS):
            b = int(np.flatnonzero(status == _k.STATUS_MAX_STEPS)[0])
            raise EulerPoissonError(
                f"taylor: max_steps={max_steps} exhausted (body {b}) before the last output time "
                f"{float(np.max(np.abs(ta.astype(float)))):.6g}; raise max_steps (or tol, or dt)"
            )
        if np.any(status == _k.STATUS_NONFINITE):
            b = int(np.flatnonzero(status == _k.STATUS_NONFINITE)[0])
            raise EulerPoissonError(f"taylor: the state of body {b} became non-finite (diverging Taylor series)")
    stats = {
        "steps": steps,
        "steps_max": most,
        "chart_changes": charts,
        "max_order": int(order),
        "backend": "numba" if use_numba else "numpy",
    }
    return q, om, stats


#: arithmetic of the free-body Taylor integration (``precision=``)
PRECISIONS = ("float64", "longdouble", "mpmath")


@dataclass(frozen=True)
class TaylorOptions(MethodOptions):
    """Options of ``method="taylor"``; see :class:`Taylor` for their meaning.

    Examples
    --------
    >>> from eulerpoisson.solvers import TaylorOptions
    >>> opts = TaylorOptions(tol=1e-12)
    >>> opts.method, opts.tol, opts.precision
    ('taylor', 1e-12, 'float64')
    >>> try:
    ...     TaylorOptions(tol=-1.0)
    ... except ValueError as err:
    ...     print(err)
    tol must be in [machine epsilon 2.22e-16, 1), got -1.0
    """

    method: ClassVar[str] = "taylor"

    tol: float = 1e-15
    order: int | None = None
    dt: float | None = None
    max_steps: int = 1_000_000
    chart_threshold: float = TAYLOR_CHART_THRESHOLD
    precision: str = "float64"
    dps: int = 30

    def check(self) -> None:
        c = cfg = self.to_dict()
        if c["precision"] not in PRECISIONS:
            raise InvalidInputError(f"precision must be one of {', '.join(PRECISIONS)}, got {c['precision']!r}")
        if isinstance(c["dps"], bool) or not isinstance(c["dps"], (int, np.integer)) or not 16 <= c["dps"] <= 1000:
            raise InvalidInputError(f"dps (mpmath decimal digits) must be an integer in [16, 1000], got {c['dps']!r}")
        if c["dt"] is not None:
            as_scalar(c["dt"], "dt", positive=True)
        if c["order"] is not None:
            _check_order(c["order"], adaptive=c["dt"] is None)
        _check_tol(c["tol"], {"float64": np.float64, "longdouble": np.longdouble, "mpmath": object}[c["precision"]])
        as_scalar(c["max_steps"], "max_steps", positive=True, integer=True)
        as_scalar(c["chart_threshold"], "chart_threshold", nonnegative=True)
        self._update(cfg)


@register_method
class Taylor(Method):
    r"""The Lie series (paper eq. 1.23.1) as an arbitrary-order Taylor integrator.

    Taylor coefficients of the motion in :math:`(\mathbf n, \boldsymbol\Omega)`
    (eq. 1.30) by Cauchy-product recurrences, order and step from the
    tolerance (Jorba & Zou 2005), dense output from each step's polynomial,
    chart changes :math:`R = R_0R(\mathbf n)` through :math:`\alpha=\pi`,
    every body of a batch with its own steps. Compiled with numba when
    available (``EULERPOISSON_NO_NUMBA=1`` forces the NumPy path, same
    results to round-off); batches of 5 bodies or more run 16 bodies in
    lockstep in SIMD lanes (about 3x the throughput of one body after the
    other, 1.3e6 body-seconds per second per core at tol = eps). Large
    batches are split over threads by ``solve(..., workers=)`` (compiled
    float64 kernels only: long double, mpmath and the NumPy fallback run on
    one thread), with the kernel chosen once for the whole batch
    (:meth:`for_batch`), so the results do not depend on the number of
    threads. See the module docstring for the algorithm.

    Parameters
    ----------
    tol : float, default 1e-15
        Tolerance, from machine epsilon (2.2e-16) to 1 (exclusive); sets the
        order and the steps in adaptive mode, unused with ``dt``.
    order : int or None, default None
        Taylor order: 2..200 with adaptive steps (None: :func:`auto_order`,
        19 at 1e-15, 20 at machine epsilon), 1..200 with ``dt`` (None:
        :data:`DEFAULT_FIXED_ORDER` = 4).
    dt : float or None, default None
        Fixed step (> 0); None for adaptive steps.
    max_steps : int, default 1_000_000
        Maximum number of steps per body (both time directions together).
    chart_threshold : float, default 0.5
        The chart is re-centred when :math:`|\mathbf n|` exceeds it at the end
        of a step (>= 0; 1 means :math:`\alpha > 90^\circ`, 0 re-centres at
        every step; see the module notes for the default).

    Raises
    ------
    TypeError
        Unknown or non-numeric option.
    InvalidInputError
        Option value out of range.
    EulerPoissonError
        (from :func:`~eulerpoisson.solve`) ``max_steps`` exhausted or a
        diverging (non-finite) state.

    Notes
    -----
    Two modes, selected by ``dt``:

    * **adaptive** (default). The global error is proportional to ``tol``
      (the number of steps grows only like :math:`\varepsilon^{-1/p}`):
      about 1-5 ``tol`` at t = 100 for :math:`I = \mathrm{diag}(1,2,3)`,
      :math:`\boldsymbol\Omega_0 = (1, 0.1, 0.5)`, down to about
      :math:`10^{-15}` per radian turned at ``tol`` = 1e-15 or below
      (round-off).
    * **fixed step** (``dt`` given): steps of exactly ``dt`` at order
      ``order``; the global error is :math:`O(\Delta t^p)`. This is what the
      registry's convergence test refines (``refine = "dt"``, nominal
      ``order = 4``).

    ``stats``: ``steps`` (total over bodies), ``steps_max`` (largest per
    body), ``chart_changes`` (total), ``max_order`` (the order used),
    ``backend`` (``"numba"`` or ``"numpy"``).

    References
    ----------
    Paper eq. 1.23.1, 1.26, 1.30. A. Jorba and M. Zou, Exp. Math. 14 (2005) 99-117.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers.taylor import Taylor
    >>> Taylor.name, Taylor.refine
    ('taylor', 'dt')
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], method="taylor", tol=1e-12)
    >>> ref = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
    >>> bool(np.max(np.abs(tr.quaternion - ref.quaternion)) < 1e-10)
    True
    """

    name = "taylor"
    Options = TaylorOptions
    order = DEFAULT_FIXED_ORDER
    refine = "dt"
    negative_times = True
    description = "Lie series (eq. 1.23.1) as an adaptive high-order Taylor integrator"
    additive_stats = ("steps", "chart_changes")
    #: the kernel chosen for a whole batch by :meth:`for_batch` (None: by the size of the batch run)
    _lanes: bool | None = None

    @property
    def threads(self) -> bool:  # type: ignore[override]  # read on instances only (parallel.solve_batch)
        """Batches are solved in threads by the compiled (numba) kernels in float64.

        Not in long double or mpmath, nor by the NumPy fallback: it holds
        the GIL most of the time, and its Cauchy sums round differently when
        a single body is left to step (NumPy sums a lone column pairwise), so
        a body's last bits would depend on the chunk it is in.
        """
        return self.config["precision"] == "float64" and bool(_k.USE_NUMBA)

    def for_batch(self, problem: Problem) -> Taylor:
        """This method with the free-body kernel (SIMD lanes or one body at a time) chosen for the whole batch."""
        import copy

        planned = copy.copy(self)
        planned._lanes = math.prod(problem.batch_shape) >= _k.LANES_MIN_BODIES
        return planned

    def work_estimate(self, problem: Problem) -> float:
        """Rough seconds on one core: steps from the rotation angle (about 0.4 rad per step at tol = eps)."""
        c = self.config
        B = int(np.prod(problem.batch_shape, dtype=int))
        T = problem.t.shape[0]
        tmax = float(np.max(np.abs(problem.t))) if T else 0.0
        if c["dt"] is not None:
            steps = B * (1.0 + tmax / float(c["dt"]))
        else:
            with np.errstate(over="ignore"):
                rate = np.sqrt(np.sum(problem.omega0 * problem.omega0, axis=-1))
                steps = float(np.sum(1.0 + 2.5 * rate * tmax))
        free = problem.model.is_free
        return B * (1e-6 if free else 1e-5) + steps * (0.4e-6 if free else 1.5e-6) + 1e-7 * B * T

    @classmethod
    def supports(cls, model) -> str | None:
        if model.is_free or model.polynomial() is not None:
            return None
        return (
            "taylor expands polynomial torques (Gravity, GravityGradient, BodyTorque, SpaceTorque) in Taylor "
            f"series, and the model has {model.describe()}, which is not one"
        )

    def run_one(self, body, q0, omega0, t) -> MethodResult | None:
        """One free body in float64 with a diagonal tensor (the quick lane, :meth:`Method.run_one`): what
        :meth:`run` computes for it, without the problem (one body: never the lane kernel, one thread)."""
        c = self.config
        if (
            c["precision"] != "float64"
            or not body.is_diagonal
            or overrides(self, Taylor, ("run", "for_batch", "_integrate"))
        ):
            return None  # (a subclass that runs otherwise: the general route, through its own methods)
        q, om, stats = self._integrate(
            body.principal_moments.reshape(1, 3), omega0[None], q0[None], t, 1 >= _k.LANES_MIN_BODIES
        )
        T = t.shape[0]
        return MethodResult(q=q.reshape(T, 4), omega=om.reshape(T, 3), stats={**stats, "threads": 1})

    def _integrate(self, moments, w0, q0, t, lanes):
        """The float64 free-body integration of :meth:`run` in the principal frame: ``(q, omega, stats)``."""
        # the options were checked with the method, the arrays with the problem (integrate_principal's checks)
        tol, order, dt, max_steps, threshold = self._kernel_options
        return _integrate_checked(moments, w0, q0, t, tol, order, dt, max_steps, threshold, bool(_k.USE_NUMBA), lanes)

    @functools.cached_property
    def _kernel_options(self) -> tuple[float, int, float | None, int, float]:
        """``(tol, order, dt, max_steps, chart_threshold)`` as the kernels take them (normalized once: a configured
        method's options do not change)."""
        c = self.config
        dt = c["dt"]
        tol = float(c["tol"])
        order = c["order"] if c["order"] is not None else (auto_order(tol) if dt is None else DEFAULT_FIXED_ORDER)
        return tol, int(order), None if dt is None else float(dt), int(c["max_steps"]), float(c["chart_threshold"])

    def run(self, problem: Problem) -> MethodResult:
        if not problem.model.is_free:
            return self._run_torque(problem)
        c = self.config
        bshape = problem.batch_shape
        B = math.prod(bshape)
        moments = np.ascontiguousarray(problem.principal_moments).reshape(B, 3)
        P = np.ascontiguousarray(problem.principal_axes).reshape(B, 3, 3)
        w0 = problem.extended.get("omega0", problem.omega0).reshape(B, 3)
        q0 = problem.extended.get("q0", problem.q0).reshape(B, 4)
        diagonal = problem.body.is_diagonal
        if c["precision"] != "float64":
            return self._run_extended(problem, moments, P, w0, q0, diagonal)
        if diagonal:
            w0p, qref0 = w0, q0
        else:
            w0p = np.einsum("bji,bj->bi", P, w0)
            qP = quaternion_from_rotation_matrix(P)
            qref0 = qmul(q0, qP)
        q, om, stats = self._integrate(moments, w0p, qref0, problem.t, self._lanes)
        if not diagonal:
            qPc = qP * np.array([1.0, -1.0, -1.0, -1.0])
            q = qmul(q, qPc[:, None, :])
            om = np.einsum("bij,btj->bti", P, om)
        T = problem.t.shape[0]
        return MethodResult(q=q.reshape(bshape + (T, 4)), omega=om.reshape(bshape + (T, 3)), stats=stats)

    def _run_extended(self, problem, moments, P, w0, q0, diagonal) -> MethodResult:
        """The free body in long double or mpmath (``precision=``): the NumPy kernels in that arithmetic,
        rounded to float64 once, at the end."""
        c = self.config
        if c["precision"] == "longdouble":
            conv = lambda a: np.asarray(a, dtype=np.longdouble)  # noqa: E731
            ctx = _nullcontext()
        else:
            mpmath = require("mpmath", "symbolic")
            ctx = mpmath.workdps(int(c["dps"]))

            def conv(a):
                a = np.asarray(a)
                out = np.empty(a.shape, dtype=object)
                for i, v in np.ndenumerate(a):
                    out[i] = mpmath.mpf(v) if not isinstance(v, mpmath.mpf) else v
                return out

        with ctx:
            m, w, q, Pg = conv(moments), conv(w0), conv(q0), conv(P)
            if not diagonal:
                w = np.einsum("bji,bj->bi", Pg, w)
                q = qmul(q, conv(quaternion_from_rotation_matrix(P)))
            qo, om, stats = integrate_principal(
                m,
                w,
                conv(problem.t),
                q0=q,
                tol=c["tol"],
                order=c["order"],
                dt=c["dt"],
                max_steps=c["max_steps"],
                chart_threshold=c["chart_threshold"],
                backend="numpy",
            )
            if qo.ndim == 2:
                qo, om = qo[None], om[None]
            if not diagonal:
                qPc = conv(quaternion_from_rotation_matrix(P) * np.array([1.0, -1.0, -1.0, -1.0]))
                qo = qmul(qo, qPc[:, None, :])
                om = np.einsum("bij,btj->bti", Pg, om)
            qf = np.asarray(qo.astype(float) if qo.dtype != object else np.vectorize(float)(qo), dtype=float)
            wf = np.asarray(om.astype(float) if om.dtype != object else np.vectorize(float)(om), dtype=float)
        stats = {**stats, "precision": c["precision"]}
        bshape = problem.batch_shape
        T = problem.t.shape[0]
        return MethodResult(q=qf.reshape(bshape + (T, 4)), omega=wf.reshape(bshape + (T, 3)), stats=stats)

    def _run_torque(self, problem: Problem) -> MethodResult:
        """Bodies under polynomial torques: (q, Omega) with Poisson vectors (:mod:`.torque`)."""
        from .torque import integrate_polynomial

        c = self.config
        if c["precision"] != "float64":
            raise InvalidInputError(
                f"taylor: precision={c['precision']!r} is for the free body; under torque "
                f"the integration runs in float64 (precision='float64')"
            )
        bshape = problem.batch_shape
        B = int(np.prod(bshape, dtype=int))
        poly = problem.model.polynomial()
        assert poly is not None  # supports() admits polynomial torques only
        data = poly.flatten(bshape)
        inertia = np.ascontiguousarray(problem.inertia.reshape(B, 3, 3))
        order = (
            c["order"]
            if c["order"] is not None
            else (DEFAULT_FIXED_ORDER if c["dt"] is not None else auto_order(float(c["tol"])))
        )
        q, om, stats, status = integrate_polynomial(
            inertia,
            problem.q0.reshape(B, 4),
            problem.omega0.reshape(B, 3),
            data,
            problem.t,
            tol=float(c["tol"]),
            order=int(order),
            dt=c["dt"],
            max_steps=int(c["max_steps"]),
        )
        if np.any(status == 1):
            b = int(np.flatnonzero(status == 1)[0])
            raise EulerPoissonError(
                f"taylor: max_steps={c['max_steps']} exhausted for body {b}; raise max_steps or tol, or shorten the times"
            )
        if np.any(status == 2):
            b = int(np.flatnonzero(status == 2)[0])
            raise EulerPoissonError(f"taylor: the state of body {b} became non-finite (the motion diverges)")
        T = problem.t.shape[0]
        return MethodResult(q=q.reshape(bshape + (T, 4)), omega=om.reshape(bshape + (T, 3)), stats=stats)
