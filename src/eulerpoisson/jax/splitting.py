r"""A fixed-step integrator in JAX under any torque: the exact free flow composed with torque kicks.

The Euler-Poisson equations :math:`I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega
+ \boldsymbol\tau(t, R, \boldsymbol\Omega)`, :math:`\dot R = R[\boldsymbol\Omega]_\times` split into

* the free rigid body, whose flow :math:`\varphi^{\text{free}}_h` is known in closed form
  (:func:`eulerpoisson.jax.exact.exact_motion`: Jacobi elliptic functions, to round-off), with the
  time advancing along it (:math:`\dot t = 1`);
* the *kick* :math:`\dot R = 0`, :math:`\dot t = 0`, :math:`\dot{\mathbf M} = \boldsymbol\tau(t, R,
  I^{-1}\mathbf M)` in the body frame (:math:`\mathbf M = I\boldsymbol\Omega`). When the torque depends
  on the time and the attitude only (gravity, gravity gradient, constant and magnetic torques) its
  right-hand side is constant along the kick and the kick is exact, :math:`\mathbf M \leftarrow \mathbf M
  + h\boldsymbol\tau`. When it depends on :math:`\boldsymbol\Omega` (a damping, a
  :class:`~eulerpoisson.jax.torques.FunctionTorque` by default) the kick is an ordinary differential
  equation in :math:`\mathbf M` alone (the attitude and the time frozen) and is integrated by one
  classical Runge-Kutta step of order 4: its local error :math:`O(h^5)` keeps the orders 2 and 4 of the
  compositions below (for a linear damping the kick is then exact up to :math:`O(h^5)`).

Treating the time as a coordinate that advances with the free flow only (the kicks use the current
time) makes both pieces autonomous flows of the extended phase space, so the compositions keep their
order for time-dependent torques. Strang's composition

.. math:: \Phi_h = \varphi^{\text{kick}}_{h/2}\circ\varphi^{\text{free}}_h\circ\varphi^{\text{kick}}_{h/2}

is of order 2 (symmetric); Yoshida's triple jump :math:`\Phi_{w_1h}\Phi_{w_0h}\Phi_{w_1h}`,
:math:`w_1 = 1/(2-2^{1/3})`, :math:`w_0 = 1-2w_1`, of order 4 (its middle flow runs backwards in
time). This is the scheme of ``eulerpoisson.solve(..., method="symplectic", scheme="exact_splitting")``
and ``"exact_splitting4"`` (:mod:`eulerpoisson.solvers.symplectic.exact_splitting`): for a potential
torque both flows are Hamiltonian, the method is symplectic and Poisson and the energy error stays
bounded, without drift. The inertia is diagonalized once, :math:`I = PDP^T` (``jnp.linalg.eigh``), and
the state is carried in the principal frame; given principal moments (..., 3) no diagonalization is
done (prefer them when differentiating with respect to the inertia of a symmetric body: the
eigenvectors of a repeated eigenvalue have no derivative).

Every step is a ``lax.scan`` iteration with a fixed number of operations: the integrator is
``jit``-compiled, ``vmap``-ped and differentiated (``grad``, ``jacfwd``) end to end, with respect to
the initial state, the inertia, the end time and the torque's parameters (a pytree).

References
----------
E. Celledoni, F. Fassò, N. Säfström and A. Zanna, "The exact computation of the free rigid body
motion and its use in splitting methods", SIAM J. Sci. Comput. 30 (2008) 2084-2112. H. Yoshida,
"Construction of higher order symplectic integrators", Phys. Lett. A 150 (1990) 262-268. E. Hairer,
C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd ed. (2006), II.5, III.3 and VII.5.
"""

from __future__ import annotations

import functools
import operator
from collections.abc import Callable
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import InvalidInputError
from ..model.torque_base import Torque, check_torque_scales
from .exact import check_inputs, check_phase, normalized
from .precision import as_float, float64_by_default
from .quaternion import qconj as _conj
from .quaternion import qmul as _qmul
from .torques import from_torque

__all__ = ["integrate", "SplittingResult", "composition", "ORDERS", "quaternion_from_matrix", "rk4_free_flow"]

#: orders of the compositions
ORDERS = (2, 4)


class SplittingResult(NamedTuple):
    """What :func:`integrate` returns (a tuple: ``t, quaternion, omega = integrate(...)``).

    Attributes
    ----------
    t : jax.Array, shape (..., K)
        The saved times (the batch shape of ``t0`` and ``t_end``).
    quaternion : jax.Array, shape (..., K, 4)
        Attitudes (scalar first), body to space.
    omega : jax.Array, shape (..., K, 3)
        Body angular velocities.

    Examples
    --------
    >>> from eulerpoisson.jax.splitting import SplittingResult
    >>> t, q, w = SplittingResult([0.0], [[1.0, 0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    >>> SplittingResult._fields
    ('t', 'quaternion', 'omega')
    """

    t: Any
    quaternion: Any
    omega: Any


def composition(order: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    r"""Kick and flow fractions ``(c, d)`` of the composition of order 2 (Strang) or 4 (Yoshida).

    A step of size :math:`h` is: kick :math:`c_0h`, flow :math:`d_0h`, kick :math:`c_1h`, ...,
    flow :math:`d_{s-1}h`, kick :math:`c_sh`; :math:`\sum c = \sum d = 1`.

    Raises
    ------
    InvalidInputError
        An order other than 2 or 4.

    Examples
    --------
    >>> from eulerpoisson.jax.splitting import composition
    >>> composition(2)
    ((0.5, 0.5), (1.0,))
    >>> c, d = composition(4)
    >>> round(sum(c), 15), round(sum(d), 15), len(d)
    (1.0, 1.0, 3)
    """
    if isinstance(order, bool) or order not in ORDERS:
        raise InvalidInputError(f"order must be 2 or 4, got {order!r}")
    if order == 2:
        return (0.5, 0.5), (1.0,)
    w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    w0 = 1.0 - 2.0 * w1
    return (0.5 * w1, 0.5 * (w1 + w0), 0.5 * (w0 + w1), 0.5 * w1), (w1, w0, w1)


def _normalize(q):
    return q / jnp.sqrt(jnp.sum(q * q, axis=-1, keepdims=True))


def quaternion_from_matrix(R):
    r"""Unit quaternions (..., 4) of rotation matrices (..., 3, 3), by Shepperd's method, branch free.

    The largest of :math:`1+\mathrm{tr}R` and :math:`1+2R_{ii}-\mathrm{tr}R` (:math:`4w^2`,
    :math:`4x_i^2`, at least 1) is the pivot; the four candidates are computed with their square roots
    guarded (:math:`\max(\cdot, 1)`, which leaves the pivot unchanged) and the pivot's is selected, so
    values and derivatives are finite. The sign is not normalized.

    Examples
    --------
    >>> import jax, numpy as np
    >>> from eulerpoisson.jax.splitting import quaternion_from_matrix
    >>> R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # 90 degrees about z
    >>> with jax.enable_x64(True):
    ...     print(np.round(np.asarray(quaternion_from_matrix(R)), 12) + 0.0)
    [0.70710678 0.         0.         0.70710678]
    """
    R = jnp.asarray(R)
    r00, r01, r02 = R[..., 0, 0], R[..., 0, 1], R[..., 0, 2]
    r10, r11, r12 = R[..., 1, 0], R[..., 1, 1], R[..., 1, 2]
    r20, r21, r22 = R[..., 2, 0], R[..., 2, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    args = jnp.stack([1.0 + tr, 1.0 + 2.0 * r00 - tr, 1.0 + 2.0 * r11 - tr, 1.0 + 2.0 * r22 - tr], -1)
    s = jnp.sqrt(jnp.maximum(args, 1.0))  # 2|w|, 2|x|, 2|y|, 2|z| at the pivot (its argument is >= 1)
    inv = 0.5 / s
    cands = jnp.stack(
        [
            jnp.stack(
                [0.5 * s[..., 0], (r21 - r12) * inv[..., 0], (r02 - r20) * inv[..., 0], (r10 - r01) * inv[..., 0]], -1
            ),
            jnp.stack(
                [(r21 - r12) * inv[..., 1], 0.5 * s[..., 1], (r01 + r10) * inv[..., 1], (r02 + r20) * inv[..., 1]], -1
            ),
            jnp.stack(
                [(r02 - r20) * inv[..., 2], (r01 + r10) * inv[..., 2], 0.5 * s[..., 2], (r12 + r21) * inv[..., 2]], -1
            ),
            jnp.stack(
                [(r10 - r01) * inv[..., 3], (r02 + r20) * inv[..., 3], (r12 + r21) * inv[..., 3], 0.5 * s[..., 3]], -1
            ),
        ],
        -2,
    )
    pivot = jnp.argmax(args, axis=-1)
    onehot = jax.nn.one_hot(pivot, 4, dtype=R.dtype)
    return jnp.sum(onehot[..., :, None] * cands, axis=-2)


def _euler_rhs(moments, q, M):
    w = M / moments
    dq = 0.5 * _qmul(q, jnp.concatenate([jnp.zeros_like(w[..., :1]), w], -1))
    return dq, jnp.cross(M, w)


def rk4_free_flow(moments, quaternion, omega, h, *, substeps: int = 32):
    r"""The free rigid body over a time ``h`` by ``substeps`` classical Runge-Kutta steps (a check).

    The principal-frame Euler equations :math:`\dot{\mathbf M} = \mathbf M\times\boldsymbol\Omega`,
    :math:`\dot q = \tfrac12 q\otimes(0, \boldsymbol\Omega)`; same signature as
    :func:`eulerpoisson.jax.exact.exact_motion` with principal moments. Of order 4 in ``h / substeps``:
    a stand-in for the exact flow in tests, not a substitute for it.

    Examples
    --------
    >>> import jax, numpy as np
    >>> from eulerpoisson.jax.splitting import rk4_free_flow
    >>> with jax.enable_x64(True):
    ...     q, w = rk4_free_flow(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), 0.5)
    ...     print(np.round(np.asarray(q), 12) + 0.0, np.asarray(w))
    [0.96891242 0.         0.         0.24740396] [0. 0. 1.]
    """
    dt = h / substeps
    dt_ = jnp.asarray(dt)[..., None]
    M = moments * omega

    def body(state, _):
        q, M = state
        k1q, k1m = _euler_rhs(moments, q, M)
        k2q, k2m = _euler_rhs(moments, q + 0.5 * dt_ * k1q, M + 0.5 * dt_ * k1m)
        k3q, k3m = _euler_rhs(moments, q + 0.5 * dt_ * k2q, M + 0.5 * dt_ * k2m)
        k4q, k4m = _euler_rhs(moments, q + dt_ * k3q, M + dt_ * k3m)
        q = q + dt_ / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q)
        M = M + dt_ / 6.0 * (k1m + 2.0 * k2m + 2.0 * k3m + k4m)
        return (q, M), None

    shape = jnp.broadcast_shapes(
        jnp.shape(moments)[:-1], jnp.shape(quaternion)[:-1], jnp.shape(omega)[:-1], jnp.shape(h)
    )
    q0 = jnp.broadcast_to(quaternion, shape + (4,))
    M0 = jnp.broadcast_to(M, shape + (3,))
    (q, M), _ = jax.lax.scan(body, (q0, M0), None, length=substeps)
    return q, M / moments


@functools.cache
def _exact_flow(dtype):
    """``exact_motion`` at ``dtype`` (one object per dtype: a static argument of the compiled run)."""
    from .exact import exact_motion

    return functools.partial(exact_motion, dtype=dtype)


def _count(x, name: str, minimum: int = 1) -> int:
    try:
        n = operator.index(x)
    except TypeError:
        raise InvalidInputError(
            f"{name} must be a Python int >= {minimum} (static: it sets the loop), got {x!r}"
        ) from None
    if isinstance(x, bool) or n < minimum:
        raise InvalidInputError(f"{name} must be an int >= {minimum}, got {x!r}")
    return n


@float64_by_default
def integrate(
    inertia,
    quaternion0,
    omega0,
    t_end,
    n_steps: int,
    torque=None,
    *,
    order: int = 2,
    t0=0.0,
    save_every: int = 1,
    dtype=None,
    _free_flow: Callable[..., Any] | None = None,
) -> SplittingResult:
    r"""Integrate a rigid body under a torque with ``n_steps`` fixed steps of the exact-flow splitting.

    Parameters
    ----------
    inertia : array_like, shape (..., 3) or (..., 3, 3)
        Principal moments (the body frame is the principal frame) or the symmetric positive-definite
        inertia tensor (body frame, diagonalized once).
    quaternion0 : array_like, shape (..., 4)
        Initial attitudes, scalar first, body to space (normalized here, after an exact scaling:
        any finite non-zero magnitude).
    omega0 : array_like, shape (..., 3)
        Initial body angular velocities.
    t_end : float or array_like, shape (...)
        End time; the step is :math:`h = (t_\text{end} - t_0)/n_\text{steps}` (negative: backwards).
    n_steps : int
        Number of steps (a Python int: it fixes the loop).
    torque : JaxTorque, eulerpoisson.torques.Torque, list of them, or None
        A torque of :mod:`eulerpoisson.jax.torques` (a pytree: its parameters are differentiated and
        mapped over) or of :mod:`eulerpoisson.torques` (converted by
        :func:`~eulerpoisson.jax.torques.from_torque`); None: the free body (exact, up to round-off).
    order : {2, 4}, keyword-only
        Strang (2) or Yoshida's triple jump (4).
    t0 : float or array_like, shape (...), keyword-only
        Start time (for time-dependent torques), default 0.
    save_every : int, keyword-only
        Save every ``save_every``-th step (it must divide ``n_steps``); the initial state is saved too.
    dtype : None, jnp.float64 or jnp.float32, keyword-only
        Computing precision (:func:`~eulerpoisson.jax.precision.float64_by_default`).

    Returns
    -------
    SplittingResult
        ``(t, quaternion, omega)``: times (..., K), attitudes (..., K, 4) and body angular velocities
        (..., K, 3) with ``K = n_steps // save_every + 1`` (the batch axes first, broadcast from all
        inputs and the torque's parameters).

    Raises
    ------
    InvalidInputError
        Wrong shapes, batch shapes that do not broadcast, non-numeric input, ``n_steps`` or
        ``save_every`` not a positive int (or ``save_every`` not dividing ``n_steps``), an order other
        than 2 or 4, or a torque that is not a torque; with concrete values also a torque whose
        parameters, or whose value at the initial state, are not finite, non-finite
        ``quaternion0``, ``omega0``, ``t_end`` or ``t0`` (or, with ``dtype=jnp.float32``, finite values
        that overflow float32), a zero ``quaternion0``, an ``omega0`` whose square or angular momentum
        overflows, ``t_end - t0`` that overflows, or :math:`|\Omega_0|\,|h| > 2^{48}` for a flow of
        the first step (:func:`eulerpoisson.jax.exact.check_phase`).
    InvalidInertiaError
        With concrete values: ``inertia`` non-finite, not symmetric or not positive definite (the
        checks of :func:`~eulerpoisson.jax.exact.exact_motion`; the triangle inequalities are not
        required).
    UnsupportedModelError
        A torque of :mod:`eulerpoisson.torques` without a JAX twin (a NumPy function).
    PrecisionError
        Traced in float64 with 64-bit floats off.

    Values are checked only when the inputs are concrete (an eager call). Under ``jit``, ``vmap``
    or ``grad`` (traced inputs) only the shapes are checked: a NaN or infinite input, a zero
    ``quaternion0`` or an inertia that is not positive definite then gives NaN outputs without an
    error. Torques of :mod:`eulerpoisson.torques` whose parameters overflow float64 together are
    refused (``eulerpoisson.model.torque_base.check_torque_scales``); a torque built in
    :mod:`eulerpoisson.jax.torques` with concrete parameters is refused when a parameter, or its value
    at the initial state, is not finite.

    Notes
    -----
    Every step is differentiable: ``jax.grad`` of a loss of the result with respect to ``omega0``,
    ``inertia``, ``t_end``, ``t0`` or the torque's parameters (a :mod:`eulerpoisson.jax.torques`
    pytree). One configuration (shapes, ``n_steps``, ``order``, ``save_every``, the torque's
    structure, ``dtype``) is compiled once: the exact flow takes tens of seconds to compile, its
    derivatives minutes.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.jax.splitting import integrate
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])
    >>> t, q, w = integrate([1.0, 1.0, 0.5], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 20.0], 0.5, 50, top, order=4)
    >>> t.shape, q.shape, w.shape
    ((51,), (51, 4), (51, 3))
    >>> print(np.round(np.asarray(w[-1]), 9) + 0.0)      # a sleeping top stays asleep
    [ 0.  0. 20.]
    """
    dt = dtype
    composition(order)  # checks the order
    n_steps = _count(n_steps, "n_steps")
    save_every = _count(save_every, "save_every")
    if n_steps % save_every:
        raise InvalidInputError(f"save_every ({save_every}) must divide n_steps ({n_steps})")
    tq = from_torque(torque)
    if tq is not None:
        tq = jax.tree_util.tree_map(lambda x: as_float(x, dt, "torque parameter"), tq)
    flow = _free_flow if _free_flow is not None else _exact_flow(dt)
    I = as_float(inertia, dt, "inertia")
    given = [x for x in (torque if isinstance(torque, (list, tuple)) else [torque]) if isinstance(x, Torque)]
    if given and not isinstance(I, jax.core.Tracer):
        # parameters of eulerpoisson.torques that overflow together: an error, as eulerpoisson.solve gives
        check_torque_scales(given, float(np.max(np.abs(np.asarray(I, dtype=np.float64)), initial=0.0)))
    q0 = as_float(quaternion0, dt, "quaternion0")
    w0 = as_float(omega0, dt, "omega0")
    te = as_float(t_end, dt, "t_end")
    ts = as_float(t0, dt, "t0")
    tensor = I.ndim >= 2 and I.shape[-2:] == (3, 3)
    if not tensor and (I.ndim == 0 or I.shape[-1] != 3):
        raise InvalidInputError(f"inertia must have shape (..., 3) (moments) or (..., 3, 3) (a tensor), got {I.shape}")
    if q0.ndim == 0 or q0.shape[-1] != 4:
        raise InvalidInputError(f"quaternion0 must have shape (..., 4), got {q0.shape}")
    if w0.ndim == 0 or w0.shape[-1] != 3:
        raise InvalidInputError(f"omega0 must have shape (..., 3), got {w0.shape}")
    bI = I.shape[:-2] if tensor else I.shape[:-1]
    try:
        jnp.broadcast_shapes(bI, q0.shape[:-1], w0.shape[:-1], te.shape, ts.shape)
    except ValueError as exc:
        raise InvalidInputError(
            f"the batch shapes of inertia {bI}, quaternion0 {q0.shape[:-1]}, omega0 {w0.shape[:-1]}, t_end "
            f"{te.shape} and t0 {ts.shape} do not broadcast"
        ) from exc
    raw = {"inertia": inertia, "quaternion0": quaternion0, "omega0": omega0, "t_end": t_end, "t0": t0}
    check_inputs(I, q0, w0, [("t_end", te), ("t0", ts)], tensor=tensor, raw=raw)
    if not isinstance(te, jax.core.Tracer) and not isinstance(ts, jax.core.Tracer):
        with np.errstate(over="ignore", invalid="ignore"):
            span = np.asarray(te, np.float64) - np.asarray(ts, np.float64)
            fits = np.all(np.isfinite(span)) and np.all(np.isfinite(np.asarray(span, dt)))
        if not fits:
            raise InvalidInputError(f"t_end - t0 overflows {np.dtype(dt)}; use a shorter time span")
        try:
            check_phase(w0, span / n_steps, "h", max(abs(x) for x in composition(order)[1]))
        except InvalidInputError as exc:
            raise InvalidInputError(f"the free flow over a step h = (t_end - t0) / n_steps: {exc}") from None
    if tq is not None and not any(
        isinstance(x, jax.core.Tracer) for x in jax.tree_util.tree_leaves((tq, I, q0, w0, ts))
    ):
        _check_torque_values(tq, I, q0, w0, ts)
    return _run(I, q0, w0, te, ts, tq, n_steps=n_steps, order=order, save_every=save_every, flow=flow, dtype=dt)


def _check_torque_values(tq, I, q0, w0, ts) -> None:
    """A JAX torque (concrete) whose parameters, or whose value at the initial state, are not finite: an error.

    Covers the torques built in :mod:`eulerpoisson.jax.torques` (those of :mod:`eulerpoisson.torques` are
    checked by ``check_torque_scales`` too): parameters that overflow together give an infinite or NaN
    torque, which would otherwise give NaN outputs without an error.

    Raises
    ------
    InvalidInputError
        Naming the torque and what is not finite.
    """
    name = type(tq).__name__
    for leaf in jax.tree_util.tree_leaves(tq):
        if not np.all(np.isfinite(np.asarray(leaf))):
            raise InvalidInputError(f"torque {name}: a parameter is not finite (NaN or infinite); give finite values")
    with np.errstate(all="ignore"):
        tau = np.asarray(tq.evaluate(ts, normalized(q0), w0, I))
    if not np.all(np.isfinite(tau)):
        raise InvalidInputError(
            f"torque {name}: its value at the initial state is not finite (its parameters overflow together, "
            f"e.g. a mass times a lever arm times g beyond float range); give parameters of a physical scale"
        )


@functools.partial(jax.jit, static_argnames=("n_steps", "order", "save_every", "flow", "dtype"))
def _run(I, q0, w0, te, ts, tq, *, n_steps, order, save_every, flow, dtype):
    """The integration proper (jit-compiled once per configuration; see :func:`integrate`)."""
    dt = dtype
    c, d = composition(order)
    tensor = I.ndim >= 2 and I.shape[-2:] == (3, 3)
    q0 = normalized(q0)
    if tensor:
        D, P = jnp.linalg.eigh(I)
        sign = jnp.sign(jnp.linalg.det(P))
        P = P.at[..., :, 2].multiply(sign[..., None])  # a proper rotation
        qP = quaternion_from_matrix(P)
        qp0 = _qmul(q0, qP)
        Mp0 = D * jnp.einsum("...ji,...j->...i", P, w0)
    else:
        D, P, qP = I, None, None
        qp0 = q0
        Mp0 = D * w0
    span = te - ts
    h = span / n_steps

    def to_body(qp, Mp):
        if P is None:
            return qp, Mp / D
        return _qmul(qp, _conj(qP)), jnp.einsum("...ij,...j->...i", P, Mp / D)

    def torque_p(t, qp, Mp):
        assert tq is not None
        qb, wb = to_body(qp, Mp)
        tau = tq.evaluate(t, qb, wb, I)
        return tau if P is None else jnp.einsum("...ji,...j->...i", P, tau)

    shape = jnp.broadcast_shapes(D.shape[:-1], qp0.shape[:-1], Mp0.shape[:-1], h.shape, ts.shape)
    if tq is not None:
        probe = jax.eval_shape(torque_p, jnp.zeros(shape, dt), jnp.zeros(shape + (4,), dt), jnp.ones(shape + (3,), dt))
        shape = jnp.broadcast_shapes(shape, probe.shape[:-1])
    D_b = jnp.broadcast_to(D, shape + (3,))
    h_b = jnp.broadcast_to(h, shape)
    hv = h_b[..., None]

    def kick(t, qp, Mp, frac):
        if tq is None:
            return Mp
        if not tq.depends_on_omega:
            return Mp + (frac * hv) * torque_p(t, qp, Mp)
        k = frac * hv
        k1 = torque_p(t, qp, Mp)
        k2 = torque_p(t, qp, Mp + 0.5 * k * k1)
        k3 = torque_p(t, qp, Mp + 0.5 * k * k2)
        k4 = torque_p(t, qp, Mp + k * k3)
        return Mp + k / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    def step(state, _):
        qp, Mp, tcur = state
        tt = tcur
        for s in range(len(d) + 1):
            Mp = kick(tt, qp, Mp, c[s])
            if s == len(d):
                break
            dh = d[s] * h_b
            qn, wn = flow(D_b, qp, Mp / D_b, dh)
            qp, Mp = _normalize(qn), D_b * wn
            tt = tt + dh
        return (qp, Mp, tcur + h_b), None

    def save(state, _):
        state, _ = jax.lax.scan(step, state, None, length=save_every)
        return state, state[:2]

    state0 = (jnp.broadcast_to(qp0, shape + (4,)), jnp.broadcast_to(Mp0, shape + (3,)), jnp.broadcast_to(ts, shape))
    _, (qs, Ms) = jax.lax.scan(save, state0, None, length=n_steps // save_every)
    qs = jnp.concatenate([state0[0][None], qs], 0)
    Ms = jnp.concatenate([state0[1][None], Ms], 0)
    qb, wb = to_body(qs, Ms)
    K = n_steps // save_every + 1
    frac = jnp.arange(K, dtype=dt) * (save_every / n_steps)
    times = ts[..., None] + span[..., None] * frac
    return SplittingResult(times, jnp.moveaxis(qb, 0, -2), jnp.moveaxis(wb, 0, -2))
