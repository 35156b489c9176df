r"""Chart changes and shared kernels of the integrators (private).

The global Gibbs vector :math:`\mathbf n = \mathbf k\tan(\alpha/2)` (paper
eq. 1.8) is infinite at :math:`\alpha = \pi`, which every tumbling body
reaches. The free body is *left invariant*: if :math:`R(t)` is a motion, so is
:math:`R_0R(t)` for a constant :math:`R_0`, with the same body angular
velocity. The integrators therefore write the attitude in a moving *chart*

.. math:: R = R_c\,R(\mathbf n),

integrate the paper's equations for the local :math:`\mathbf n`, and, when
:math:`|\mathbf n|` exceeds a threshold (1 by default, i.e. a rotation of
90° relative to the chart centre), fold :math:`R(\mathbf n)` into the centre,
:math:`R_c \leftarrow R_cR(\mathbf n)`, and restart at :math:`\mathbf n = 0`.

Why :math:`|\mathbf n| \le 1`
    The Hamiltonian vector field of eq. 1.15-1.16 is a polynomial in
    :math:`\mathbf n` whose Lipschitz constant grows like
    :math:`|\boldsymbol\Omega|(1+\mathbf n^2)`; on :math:`|\mathbf n|\le 1`
    it is at most about :math:`2|\boldsymbol\Omega|`, so the fixed-point
    iteration of the implicit methods contracts and the error constants stay
    uniform, while a chart still covers rotations up to 90° (a threshold of
    3, i.e. 143°, made the 4th-order Gauss method 7 times less accurate in
    the tests). A threshold of 0 re-centres the chart before every step.

Momenta under a chart change (cotangent lift)
    Let the new chart be centred at :math:`R_c' = R_cR(\mathbf n_c)`. A point
    with old coordinate :math:`\mathbf n` has new coordinate :math:`\mathbf n'`
    with :math:`R(\mathbf n) = R(\mathbf n_c)R(\mathbf n')`, i.e.
    :math:`\mathbf n = \mathbf n_c\circ\mathbf n'` (``gibbs_compose``). Since
    :math:`\mathbf n_c` is constant, both charts give the same body angular
    velocity, :math:`\boldsymbol\Omega = 2A^T(\mathbf n)\dot{\mathbf n} =
    2A^T(\mathbf n')\dot{\mathbf n}'` (eq. 1.11), so the Jacobian of the
    transition map is :math:`\partial\mathbf n/\partial\mathbf n' =
    \tilde A^T(\mathbf n)A^T(\mathbf n')` and the cotangent lift is

    .. math:: \boldsymbol\pi' = \Big(\frac{\partial\mathbf n}{\partial\mathbf n'}\Big)^T\boldsymbol\pi
              = A(\mathbf n')\tilde A(\mathbf n)\boldsymbol\pi .

    A cotangent lift is a canonical transformation (it preserves
    :math:`\boldsymbol\pi\cdot d\mathbf n`). At the restart point
    :math:`\mathbf n' = 0` this is :math:`\boldsymbol\pi' =
    \tilde A(\mathbf n)\boldsymbol\pi = 2I\boldsymbol\Omega` (eq. 1.26):
    the angular velocity is unchanged.

What survives a chart change (measured in ``tests/test_symplectic.py``)
    For a *fixed* transition (fixed :math:`\mathbf n_c`) the lift is
    canonical, so a map that is symplectic in one chart is symplectic in the
    other. But re-centring at the current point makes the new centre
    :math:`R_cR(\mathbf n)` depend on the state; the step across a chart
    change is then not exactly symplectic (defect :math:`O(h^{p+1})`, about
    1e-7 for a 4th-order step of 0.1 rad). And a symplectic method conserves
    a modified energy that depends on the coordinates, i.e. on the chart;
    since every chart is traversed outwards (from :math:`\mathbf n = 0` to
    the threshold), the energy error changes by a systematic
    :math:`O(h^p)` amount at every chart change and drifts linearly in
    time. Integrators that need long-time energy behaviour should not use
    charts (homogeneous quaternion variables, :func:`quaternion_field`, or
    a Lie-Poisson splitting); non-geometric integrators (Taylor,
    Runge-Kutta) drift anyway, at the level of their tolerance, and lose
    nothing measurable to the charts.

Layout
    The kernels here are written for speed in plain numpy (and to be easy to
    port to numba): vectors are *component first*, shape ``(3, ...)``,
    quaternions ``(4, ...)``, so each component is a contiguous array, and the
    inertia is diagonal (the integrators work in the principal frame, see
    :func:`principal_frame`). Every kernel is batched over the trailing axes
    and accepts complex input (used for complex-step Jacobians in the tests).

References
----------
Paper eqs. 1.8-1.17, 1.24-1.30. The printed :math:`\dot{\boldsymbol\pi}` of
eq. 1.16 has :math:`\epsilon_{ijk}n_k` where :math:`\epsilon_{ijk}\pi_k` is
meant; see :func:`canonical_field`.
E. Hairer, C. Lubich and G. Wanner, *Geometric Numerical Integration*, 2nd
ed., Springer (2006), sections VI.5 (cotangent lifts), VII.5 (the rigid body).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..attitude.core import quaternion_from_rotation_matrix
from ..errors import InvalidInputError
from ..numerics.quaternion import qmul_first as qmul

__all__ = [
    "DEFAULT_CHART_THRESHOLD",
    "dot",
    "cross",
    "apply_A",
    "apply_AT",
    "apply_At",
    "apply_AtT",
    "omega_from_pi",
    "pi_from_omega",
    "hamiltonian",
    "canonical_field",
    "spatial_momentum",
    "quaternion_field",
    "body_momentum_from_qp",
    "spatial_momentum_from_qp",
    "qp_from_body_momentum",
    "cotangent_lift",
    "qmul",
    "dot4",
    "quaternion_from_gibbs",
    "change_chart",
    "PrincipalFrame",
    "principal_frame",
    "run_fixed_step",
    "check_threshold",
]

#: default chart threshold: re-centre when |n| > 1 (rotation > 90 degrees from the centre)
DEFAULT_CHART_THRESHOLD = 1.0


# ---------------------------------------------------------------------------
# vector algebra, component first
# ---------------------------------------------------------------------------
def dot(a, b):
    """Dot product of component-first vectors ``(3, ...)`` -> ``(...)``."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    """Cross product of component-first vectors ``(3, ...)``, broadcast."""
    shape = np.broadcast_shapes(a.shape, b.shape)
    out = np.empty(shape, dtype=np.result_type(a, b))
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


def apply_A(n, v):
    r""":math:`A(\mathbf n)\mathbf v = (\mathbf v + \mathbf n\times\mathbf v)/(1+\mathbf n^2)` (eq. 1.12), shapes ``(3, ...)``."""
    return (v + cross(n, v)) / (1.0 + dot(n, n))


def apply_AT(n, v):
    r""":math:`A^T(\mathbf n)\mathbf v = (\mathbf v - \mathbf n\times\mathbf v)/(1+\mathbf n^2)` (eq. 1.11-1.12)."""
    return (v - cross(n, v)) / (1.0 + dot(n, n))


def apply_At(n, v):
    r""":math:`\tilde A(\mathbf n)\mathbf v = \mathbf v + (\mathbf n\cdot\mathbf v)\mathbf n - \mathbf n\times\mathbf v`.

    :math:`\tilde A = A^{-1} = \mathbf 1 + \mathbf n\mathbf n^T - [\mathbf n]_\times`
    (eq. 1.12 with its :math:`n_jn_j` read as :math:`n_in_j`).
    """
    return v + dot(n, v) * n - cross(n, v)


def apply_AtT(n, v):
    r""":math:`\tilde A^T(\mathbf n)\mathbf v = \mathbf v + (\mathbf n\cdot\mathbf v)\mathbf n + \mathbf n\times\mathbf v`."""
    return v + dot(n, v) * n + cross(n, v)


# ---------------------------------------------------------------------------
# the canonical formulation (n, pi), diagonal inertia
# ---------------------------------------------------------------------------
def omega_from_pi(n, pi, inv_moments):
    r"""Body angular velocity :math:`\boldsymbol\Omega = \tfrac12 I^{-1}\tilde A\boldsymbol\pi` (eq. 1.26).

    Parameters
    ----------
    n, pi : ndarray, shape (3, ...)
    inv_moments : ndarray, shape (3, ...)
        :math:`1/I_i` in the principal frame (broadcast).

    Returns
    -------
    ndarray, shape (3, ...)
    """
    return 0.5 * inv_moments * apply_At(n, pi)


def pi_from_omega(n, omega, moments):
    r"""Canonical momentum :math:`\boldsymbol\pi = 2AI\boldsymbol\Omega` (eq. 1.26), shapes ``(3, ...)``."""
    return 2.0 * apply_A(n, moments * omega)


def hamiltonian(n, pi, inv_moments):
    r"""Energy :math:`H = \tfrac18(\tilde A\boldsymbol\pi)^TI^{-1}(\tilde A\boldsymbol\pi)` (eq. 1.15), shape ``(...)``."""
    u = apply_At(n, pi)
    return 0.125 * dot(u, inv_moments * u)


def canonical_field(y, inv_moments):
    r"""Hamilton's equations of :math:`H(\mathbf n,\boldsymbol\pi)` (eq. 1.15), corrected eq. 1.16.

    With :math:`\boldsymbol\Omega = \tfrac12I^{-1}\tilde A\boldsymbol\pi`,

    .. math::
        \dot{\mathbf n} = \frac{\partial H}{\partial\boldsymbol\pi} = \tfrac12\tilde A^T\boldsymbol\Omega,
        \qquad
        \dot{\boldsymbol\pi} = -\frac{\partial H}{\partial\mathbf n}
          = -\tfrac12\left[(\mathbf n\cdot\boldsymbol\pi)\boldsymbol\Omega
          + (\mathbf n\cdot\boldsymbol\Omega)\boldsymbol\pi
          + \boldsymbol\Omega\times\boldsymbol\pi\right].

    In index form :math:`\dot\pi_i = -\tfrac12[\delta_{ij}(\mathbf n\cdot\boldsymbol\pi)
    + \pi_in_j + \epsilon_{ijk}\pi_k]\Omega_j`; the paper prints
    :math:`\epsilon_{ijk}n_k` in the last term, which is not
    :math:`-\partial H/\partial\mathbf n` (checked by finite differences in
    the tests). The first equation is eq. 1.30.

    Parameters
    ----------
    y : ndarray, shape (6, ...)
        :math:`(\mathbf n, \boldsymbol\pi)` stacked, component first.
    inv_moments : ndarray, shape (3, ...)
        Inverse principal moments, broadcast against ``y[:3]``.

    Returns
    -------
    ndarray, shape (6, ...)
        :math:`(\dot{\mathbf n}, \dot{\boldsymbol\pi})`.
    """
    n = y[:3]
    p = y[3:]
    npi = dot(n, p)
    W = 0.5 * inv_moments * (p + npi * n - cross(n, p))
    nW = dot(n, W)
    out = np.empty(np.broadcast_shapes(y.shape, (6,) + W.shape[1:]), dtype=np.result_type(y, W))
    out[:3] = 0.5 * (W + nW * n + cross(n, W))
    out[3:] = -0.5 * (npi * W + nW * p + cross(W, p))
    return out


def spatial_momentum(n, pi):
    r"""Angular momentum :math:`\mathbf m = \tfrac12\tilde A^T\boldsymbol\pi` (eq. 1.17) in the chart frame.

    The spatial angular momentum is :math:`R_c` times this; note that it is
    cubic in the canonical variables, not quadratic.
    """
    return 0.5 * apply_AtT(n, pi)


def cotangent_lift(n, pi, n_new):
    r"""Momentum in a new chart: :math:`\boldsymbol\pi' = A(\mathbf n')\tilde A(\mathbf n)\boldsymbol\pi`.

    The same phase-space point written in the chart whose coordinate of the
    attitude is ``n_new`` (see the module docstring for the derivation: the
    transpose of the Jacobian of :math:`\mathbf n = \mathbf n_c\circ\mathbf n'`).

    Parameters
    ----------
    n, pi : ndarray, shape (3, ...)
        Coordinates and momenta in the old chart.
    n_new : ndarray, shape (3, ...)
        Coordinates of the same attitude in the new chart.

    Returns
    -------
    ndarray, shape (3, ...)
    """
    return apply_A(n_new, apply_At(n, pi))


# ---------------------------------------------------------------------------
# homogeneous canonical variables (q, p) in T*R^4
# ---------------------------------------------------------------------------
def body_momentum_from_qp(q, p, normalize: bool = True):
    r"""Body angular momentum :math:`\mathbf M = \tfrac12\,\mathrm{vec}(\bar q\otimes p)/|q|^2`, shapes (4, ...) -> (3, ...).

    In components :math:`M_k = \tfrac12\,p\cdot(q\otimes\mathbf e_k)/|q|^2`;
    ``normalize=False`` leaves out the :math:`1/|q|^2` (the form used in the
    Hamiltonian of :func:`quaternion_field`, where :math:`|q| = 1` is an
    invariant).
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    p0, p1, p2, p3 = p[0], p[1], p[2], p[3]
    s = 0.5 / (w * w + x * x + y * y + z * z) if normalize else 0.5
    out = np.empty((3,) + np.broadcast_shapes(w.shape, p0.shape), dtype=np.result_type(q, p))
    out[0] = s * (w * p1 - x * p0 - y * p3 + z * p2)
    out[1] = s * (w * p2 + x * p3 - y * p0 - z * p1)
    out[2] = s * (w * p3 - x * p2 + y * p1 - z * p0)
    return out


def spatial_momentum_from_qp(q, p):
    r"""Spatial angular momentum :math:`\mathbf m = \tfrac12\,\mathrm{vec}(p\otimes\bar q)` (bilinear), (4, ...) -> (3, ...).

    Equal to :math:`R(q)\mathbf M` when :math:`|q| = 1` and :math:`q\cdot p = 0`.
    """
    qc = q * np.array([1.0, -1.0, -1.0, -1.0]).reshape((4,) + (1,) * (q.ndim - 1))
    return 0.5 * qmul(p, qc)[1:]


def qp_from_body_momentum(q, M):
    r"""Momentum :math:`p = 2q\otimes(0, \mathbf M)`, the lift with :math:`q\cdot p = 0`, (4, ...), (3, ...) -> (4, ...)."""
    M4 = np.concatenate([np.zeros((1,) + M.shape[1:], dtype=M.dtype), M])
    return 2.0 * qmul(q, M4)


def quaternion_field(y, inv_moments):
    r"""Hamilton's equations of the free body in homogeneous canonical variables :math:`(q, p)\in T^*\mathbb R^4`.

    The paper's Gibbs vector is the central projection :math:`\mathbf n =
    \mathbf q/q_0` of the quaternion (footnote to eq. 1.9); its homogeneous
    canonical formulation has the Hamiltonian

    .. math:: H(q, p) = \tfrac12\sum_k M_k^2/I_k, \qquad
              M_k = \tfrac12\,p\cdot(q\otimes\mathbf e_k)

    (for :math:`|q| = 1`), whose equations are

    .. math:: \dot q = \tfrac12\,q\otimes(0,\boldsymbol\Omega), \qquad
              \dot p = \tfrac12\,p\otimes(0,\boldsymbol\Omega), \qquad
              \Omega_k = M_k/I_k .

    :math:`|q|^2`, :math:`q\cdot p` and :math:`\mathbf m = \tfrac12\,
    \mathrm{vec}(p\otimes\bar q)` are conserved, and all three are
    quadratic, so Gauss collocation conserves them exactly. There is no
    chart: left translations :math:`(q, p)\mapsto(g\otimes q, g\otimes p)`
    are linear.

    Parameters
    ----------
    y : ndarray, shape (8, ...)
        :math:`(q, p)` stacked, component first.
    inv_moments : ndarray, shape (3, ...)

    Returns
    -------
    ndarray, shape (8, ...)

    References
    ----------
    Paper eq. 1.9 (footnote), 1.24; Hairer-Lubich-Wanner VII.5.3 and IV.2 (quadratic invariants).
    """
    q = y[:4]
    p = y[4:]
    W = inv_moments * body_momentum_from_qp(q, p, normalize=False)
    a, b, c = W[0], W[1], W[2]
    out = np.empty(np.broadcast_shapes(y.shape, (8,) + a.shape), dtype=np.result_type(y, W))
    for off, v in ((0, q), (4, p)):
        w, x, yy, z = v[0], v[1], v[2], v[3]
        out[off + 0] = -0.5 * (x * a + yy * b + z * c)
        out[off + 1] = 0.5 * (w * a + yy * c - z * b)
        out[off + 2] = 0.5 * (w * b - x * c + z * a)
        out[off + 3] = 0.5 * (w * c + x * b - yy * a)
    return out


# ---------------------------------------------------------------------------
# quaternions, component first
# ---------------------------------------------------------------------------
def quaternion_from_gibbs(n):
    r"""Unit quaternion :math:`(1, \mathbf n)/\sqrt{1+\mathbf n^2}`, component first ``(3, ...)`` -> ``(4, ...)``."""
    s = 1.0 / np.sqrt(1.0 + dot(n, n))
    out = np.empty((4,) + n.shape[1:], dtype=n.dtype)
    out[0] = s
    out[1:] = n * s
    return out


def change_chart(qc, n, pi, threshold):
    r"""Re-centre the charts of the bodies whose :math:`|\mathbf n|` exceeds ``threshold``.

    For those bodies :math:`q_c \leftarrow q_c\otimes q(\mathbf n)` (renormalized),
    :math:`\mathbf n\leftarrow 0` and :math:`\boldsymbol\pi \leftarrow
    \tilde A(\mathbf n)\boldsymbol\pi` (:func:`cotangent_lift` at
    :math:`\mathbf n' = 0`); the attitude, :math:`\boldsymbol\Omega`, the
    energy and :math:`\mathbf m` are unchanged up to round-off.

    Parameters
    ----------
    qc : ndarray, shape (4, B)
        Chart centres (unit quaternions).
    n, pi : ndarray, shape (3, B)
        Local canonical variables.
    threshold : float
        Re-centre where :math:`|\mathbf n| > ` threshold.

    Returns
    -------
    qc, n, pi : ndarrays
        Updated copies (the inputs are not modified).
    changed : ndarray of bool, shape (B,)
    """
    n2 = dot(n, n)
    changed = n2 > threshold * threshold
    if not np.any(changed):
        return qc, n, pi, changed
    qn = qmul(qc, quaternion_from_gibbs(n))
    qn = qn / np.sqrt(dot4(qn, qn))
    qc = np.where(changed, qn, qc)
    pi = np.where(changed, apply_At(n, pi), pi)
    n = np.where(changed, 0.0, n)
    return qc, n, pi, changed


def dot4(a, b):
    """Dot product of component-first quaternions ``(4, ...)``."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]


# ---------------------------------------------------------------------------
# principal frame
# ---------------------------------------------------------------------------
class PrincipalFrame:
    r"""Map a batch of problems to the principal frame and back.

    With :math:`I = PDP^T` (:math:`\det P = 1`) and :math:`R' = RP`, the free
    body obeys the same equations with the diagonal inertia :math:`D` and
    :math:`\boldsymbol\Omega' = P^T\boldsymbol\Omega`. Integrators run in
    the principal frame (cheap diagonal :math:`I^{-1}`); for the Gibbs-vector
    methods the map is linear (:math:`\mathbf n' = P^T\mathbf n`), and
    Runge-Kutta methods are equivariant under linear changes of variables,
    so this changes nothing but round-off.

    Attributes
    ----------
    moments : ndarray, shape (3, B)
        Principal moments, component first.
    diagonal : bool
        True when :math:`P = 1` for every body (nothing to transform).
    qP : ndarray, shape (4, B)
        Quaternions of :math:`P`.
    P : ndarray, shape (B, 3, 3)
    """

    def __init__(self, principal_moments, principal_axes, diagonal: bool):
        self.moments = np.ascontiguousarray(principal_moments.reshape(-1, 3).T)
        self.diagonal = bool(diagonal)
        self.P = principal_axes.reshape(-1, 3, 3)
        self.qP = np.ascontiguousarray(quaternion_from_rotation_matrix(self.P).T)

    def to_principal(self, q, omega):
        """``(q, Omega)`` body frame, shapes (4, B), (3, B) -> principal frame."""
        if self.diagonal:
            return q, omega
        return qmul(q, self.qP), np.einsum("bji,jb->ib", self.P, omega)

    def from_principal(self, q, omega):
        """Inverse of :meth:`to_principal`; works on (4, B, ...) and (3, B, ...)."""
        if self.diagonal:
            return q, omega
        extra = q.ndim - 2
        qPc = self.qP * np.array([1.0, -1.0, -1.0, -1.0])[:, None]
        qPc = qPc.reshape(qPc.shape + (1,) * extra)
        w = np.einsum("bij,jb...->ib...", self.P, omega)
        return qmul(q, qPc), w


def principal_frame(problem) -> PrincipalFrame:
    """:class:`PrincipalFrame` of a :class:`~eulerpoisson.solvers.problem.Problem`'s (flattened) batch."""
    return PrincipalFrame(problem.principal_moments, problem.principal_axes, problem.body.is_diagonal)


# ---------------------------------------------------------------------------
# options and the fixed-step driver
# ---------------------------------------------------------------------------
def check_threshold(value) -> float:
    """Validate the ``chart_threshold`` option (a finite float >= 0).

    Raises
    ------
    InvalidInputError
        Negative, non-finite or non-numeric.
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"chart_threshold must be a number >= 0, got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(v) or v < 0:
        raise InvalidInputError(f"chart_threshold must be a finite number >= 0, got {value!r}")
    return v


def check_step_budget(method: str, t, steps_per_unit_time: float, max_steps: int, hint: str) -> None:
    r"""Refuse a run that needs more than ``max_steps`` steps before it starts.

    The number of steps is estimated as ``steps_per_unit_time`` times the time
    to cover, :math:`\max(t, 0) + \max(-t, 0)` (both branches start at
    0). A non-finite estimate (an overflowing rate or time) is refused too.

    Raises
    ------
    InvalidInputError
        Naming the method, the estimate, ``max_steps`` and ``hint``.
    """
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        return
    span = max(float(np.max(t)), 0.0) + max(-float(np.min(t)), 0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        need = span * float(steps_per_unit_time)
    if span > 0 and not (need <= max_steps):  # also catches inf and nan
        raise InvalidInputError(
            f"{method}: reaching |t| = {span:.6g} needs about {need:.3g} steps, more than max_steps={max_steps}; {hint}"
        )


def check_count(method: str, key: str, value) -> int:
    """A counting option (``max_steps``, ``max_iter``): an integer >= 1, not a bool."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidInputError(f"{method}: {key} must be an integer >= 1, got {value!r}")
    return int(value)


def run_fixed_step(t, dt, state0, advance, output):
    r"""Drive a one-step map through the output times with fixed steps.

    The output times are sorted; times :math:`\ge 0` are reached forwards
    from the initial state at :math:`t = 0`, negative ones backwards. Each
    interval between consecutive output times of length :math:`L` is split
    into :math:`N = \lceil |L|/dt\rceil` equal steps :math:`h = L/N`, so the
    outputs land exactly on the output times and :math:`|h|\le dt` (up to a
    relative 1e-12, so that an interval that is a multiple of ``dt`` up to
    rounding gets exactly that many steps).

    Parameters
    ----------
    t : ndarray, shape (T,)
        Output times, any order, duplicates allowed.
    dt : float
        Largest step (> 0, may be ``inf``: one step per interval).
    state0 : object
        Initial state at t = 0, passed to ``advance`` and ``output``.
    advance : callable
        ``advance(state, h, nsteps) -> state``: ``nsteps`` steps of size ``h``
        (negative ``h`` runs backwards).
    output : callable
        ``output(state) -> tuple of ndarrays``, each of shape (C, B).

    Returns
    -------
    tuple of ndarrays
        Each of shape (C, B, T), the outputs in the order of ``t``.
    int
        Total number of steps taken.
    """
    t = np.asarray(t, dtype=float)
    T = t.shape[0]
    results: list[Any] = [None] * T
    nsteps_total = 0
    order = np.argsort(t, kind="stable")
    pos = [int(i) for i in order if t[i] >= 0]
    neg = [int(i) for i in order[::-1] if t[i] < 0]
    for branch in (pos, neg):
        state = state0
        tcur = 0.0
        for i in branch:
            L = float(t[i]) - tcur
            if L != 0.0:
                # the slack keeps N = L/dt when L is a multiple of dt up to rounding
                N = max(1, int(math.ceil(abs(L) / dt * (1.0 - 1e-12)))) if math.isfinite(dt) else 1
                state = advance(state, L / N, N)
                nsteps_total += N
                tcur = float(t[i])
            results[i] = output(state)
    outs = tuple(np.stack([r[k] for r in results], axis=-1) for k in range(len(results[0])))
    return outs, nsteps_total
