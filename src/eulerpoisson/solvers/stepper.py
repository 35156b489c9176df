r"""Methods as steppers: a one-step map (:class:`Stepper`) and the fixed-step driver that owns the loop.

A *stepper* knows one thing: how to advance a batch of states by one step
:math:`h` from time :math:`t` (:meth:`Stepper.step`). Everything else — the
output times, their order, both time directions, the number of steps, the
step budget, the checks on the state — is the driver's,
:func:`run_fixed_step`, shared by every fixed-step method written this way.
The equations stay in the :class:`~eulerpoisson.model.equations.Model`
(:func:`batch_vector_field` gives its vector field on flat batches), so a
new method is a tableau, not a new loop.

The state (:class:`StepState`) is ``q`` ``(B, 4)`` and ``omega`` ``(B, 3)``,
the attitudes and body angular velocities of the ``B`` bodies of the
(flattened) batch, plus ``aux``, whatever the stepper needs (the vector
field, a previous derivative...).

How the driver steps (:func:`run_fixed_step`)
    From the initial state at ``t0`` (0 for a :class:`~.Problem`), the
    output times :math:`\ge t_0` are visited in increasing order, those
    below it in decreasing order (steps :math:`h < 0`), each branch from the
    initial state. From one output time :math:`a` to the next :math:`b` it
    takes full steps of ``dt`` and one final, shorter step that lands exactly
    on :math:`b` (an interval that is a multiple of ``dt`` up to a relative
    1e-12 gets exactly that many full steps), then continues from the state
    at :math:`b`. The steps between two outputs depend only on :math:`a`,
    :math:`b`, ``dt`` and the state at :math:`a`: the bits at an output do
    not depend on how the output times are chunked into calls, as long as
    the outputs before it are the same — solving ``t = [1, 2]`` and then,
    from the state at 2 with ``t0 = 2``, ``t = [3]`` gives at 3 the bits of
    one call with ``t = [1, 2, 3]``. (Adding an output time in between does
    change the later bits, by rounding: the step sequence changes.)

Examples
--------
A stepper is a small class: here the explicit Euler method (order 1) on
the model's equations.

>>> import numpy as np, eulerpoisson as ep
>>> from eulerpoisson.solvers import make_problem
>>> from eulerpoisson.solvers.stepper import Stepper, StepState, batch_vector_field, run_fixed_step
>>> class Euler(Stepper):
...     name, order, renormalize, evaluations_per_step = "euler", 1, True, 1
...     def init(self, problem):
...         return super().init(problem)._replace(aux=batch_vector_field(problem))
...     def step(self, state, t, h):
...         dq, dw = state.aux(t, state.q, state.omega)
...         return state._replace(q=state.q + h * dq, omega=state.omega + h * dw)
>>> p = make_problem([1.0, 2.0, 2.5], [0.0, 0.25, -1.0], omega0=[1.0, 0.1, 0.5])
>>> res = run_fixed_step(Euler(), p, dt=0.1, max_steps=100)
>>> res.q.shape, res.stats
((3, 4), {'dt': 0.1, 'steps': 13, 'evaluations': 13})
>>> print(np.round(res.omega[0], 12))                           # t = 0: the initial state
[1.  0.1 0.5]
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar, NamedTuple

import numpy as np

from ..errors import EulerPoissonError, InvalidInputError
from .problem import Problem
from .registry import MethodResult

__all__ = ["StepState", "Stepper", "batch_vector_field", "step_plan", "run_fixed_step"]

#: relative slack on |b - a| / dt: an interval that is a multiple of dt up to rounding gets that many full steps
_SLACK = 1e-12


class StepState(NamedTuple):
    """The state a :class:`Stepper` advances: a flat batch of ``B`` bodies.

    Attributes
    ----------
    q : ndarray, shape (B, 4)
        Attitude quaternions (scalar first).
    omega : ndarray, shape (B, 3)
        Body angular velocities.
    aux : object
        Whatever the stepper needs besides (the vector field, a cached
        derivative...); None when nothing.
    """

    q: np.ndarray
    omega: np.ndarray
    aux: Any = None


class Stepper:
    """Base class of a one-step method driven by :func:`run_fixed_step`.

    Subclasses implement :meth:`step` and usually extend :meth:`init` (to
    put the vector field in ``aux``). A stepper holds no state of its own:
    the same instance may drive several problems.

    Attributes
    ----------
    name : str
        Named by the driver's error messages (the method's name).
    order : int
        Order of convergence.
    renormalize : bool
        Whether the driver divides ``q`` by its norm after every step (a
        projection onto the unit quaternions, which keeps the order).
    evaluations_per_step : int
        Vector field evaluations per step (for ``stats["evaluations"]``).

    Examples
    --------
    >>> from eulerpoisson.solvers.stepper import Stepper
    >>> Stepper.order, Stepper.renormalize
    (0, False)
    """

    name: ClassVar[str] = "stepper"
    order: ClassVar[int] = 0
    renormalize: ClassVar[bool] = False
    evaluations_per_step: ClassVar[int] = 0

    def init(self, problem: Problem) -> StepState:
        """The state at the start: ``problem.q0`` and ``problem.omega0`` flattened to ``(B, 4)``, ``(B, 3)`` (copies)."""
        B = int(np.prod(problem.batch_shape, dtype=int))
        q = np.array(problem.q0, dtype=float).reshape(B, 4)
        w = np.array(problem.omega0, dtype=float).reshape(B, 3)
        return StepState(q=q, omega=w)

    def step(self, state: StepState, t: float, h: float) -> StepState:  # pragma: no cover - abstract
        """The state at ``t + h`` from the state at ``t`` (``h`` may be negative); a new state, inputs untouched."""
        raise NotImplementedError

    def interpolate(self, state: StepState, next_state: StepState, t: float, h: float, theta: float) -> StepState:
        """Optional dense output: the state at ``t + theta h`` within a step, ``0 <= theta <= 1``.

        Not needed by :func:`run_fixed_step`, which lands on every output
        time; the default raises :class:`NotImplementedError`.
        """
        raise NotImplementedError(f"{self.name}: no dense output (interpolate) for this stepper")


def batch_vector_field(problem: Problem) -> Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    r"""The model's vector field :math:`(\dot q, \dot{\boldsymbol\Omega})` on flat batches.

    ``f(t, q, omega)`` with ``q`` ``(B, 4)`` and ``omega`` ``(B, 3)``
    (:math:`B` the number of bodies of ``problem``) returns ``(qdot, omega_dot)``
    of the same shapes: :meth:`~eulerpoisson.model.equations.Model.rhs`, with
    the arrays seen in the problem's batch shape so that the model's
    parameters broadcast against them.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers import make_problem
    >>> from eulerpoisson.solvers.stepper import batch_vector_field
    >>> p = make_problem([1.0, 2.0, 2.5], [1.0], omega0=[[1.0, 0.0, 0.0], [0.0, 0.0, 2.0]])
    >>> qd, wd = batch_vector_field(p)(0.0, p.q0, p.omega0)
    >>> print(qd)                                                   # q' = q (0, Omega) / 2
    [[0.  0.5 0.  0. ]
     [0.  0.  0.  1. ]]
    """
    model = problem.model
    bshape = tuple(problem.batch_shape)
    q_shape, w_shape = bshape + (4,), bshape + (3,)

    def f(t: float, q: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        B = q.shape[0]
        qd, wd = model.rhs(t, q.reshape(q_shape), omega.reshape(w_shape))
        return np.reshape(qd, (B, 4)), np.reshape(wd, (B, 3))

    return f


def step_plan(t: np.ndarray, dt: float, t0: float = 0.0) -> tuple[list[list[int]], float]:
    """The order in which :func:`run_fixed_step` visits the output times, and the number of steps it takes.

    Returns
    -------
    branches : list of two lists of int
        Indices into ``t``: the times ``>= t0`` in increasing order, then
        those ``< t0`` in decreasing order (ties in the order of ``t``).
    steps : float
        Total number of steps over both branches (a float: it may be huge or
        infinite for absurd times).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers.stepper import step_plan
    >>> step_plan(np.array([0.3, -0.1, 0.0, 0.25]), 0.1)
    ([[2, 3, 0], [1]], 5.0)
    """
    t = np.asarray(t, dtype=float)
    order = np.argsort(t, kind="stable")
    pos = [int(i) for i in order if t[i] >= t0]
    neg = [int(i) for i in np.argsort(-t, kind="stable") if t[i] < t0]
    steps = 0.0
    for branch in (pos, neg):
        a = t0
        for i in branch:
            steps += _count(float(t[i]) - a, dt)
            a = float(t[i])
    return [pos, neg], steps


def _count(L: float, dt: float) -> float:
    """Steps from a to a + L: ceil(|L| / dt) up to the slack; 0 when L == 0."""
    if L == 0.0:
        return 0.0
    with np.errstate(over="ignore"):
        x = abs(L) / dt
    if not math.isfinite(x):
        return math.inf
    return float(max(1, math.ceil(x * (1.0 - _SLACK))))


def run_fixed_step(stepper: Stepper, problem: Problem, dt: float, max_steps: int, *, t0: float = 0.0) -> MethodResult:
    """Drive ``stepper`` through the output times of ``problem`` with fixed steps ``dt``.

    See the module docstring for the order of the steps (full steps of
    ``dt``, a final shorter step landing on each output time, then on from
    that state) and why it makes the results independent of how the output
    times are split into calls.

    Parameters
    ----------
    stepper : Stepper
    problem : Problem
        Its initial state is taken at time ``t0``; ``problem.t`` are the
        output times (any order, duplicates and times before ``t0`` allowed).
    dt : float
        The step, > 0.
    max_steps : int
        Most steps allowed, both time directions together (every body of the
        batch takes the same steps).
    t0 : float
        Time of the initial state (default 0): to continue a solution from
        its state at an output time.

    Returns
    -------
    MethodResult
        ``q`` ``(*batch_shape, T, 4)``, ``omega`` ``(*batch_shape, T, 3)``;
        ``stats``: ``dt``, ``steps``, ``evaluations`` (of the vector field,
        per body).

    Raises
    ------
    InvalidInputError
        ``dt`` not a finite number > 0, or the output times need more than
        ``max_steps`` steps (checked before the first step; an
        :class:`~eulerpoisson.errors.EulerPoissonError`).
    EulerPoissonError
        The state became non-finite (NaN or overflow).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers import make_problem
    >>> from eulerpoisson.solvers.rk4 import RK4Stepper
    >>> from eulerpoisson.solvers.stepper import run_fixed_step
    >>> p = make_problem([1.0, 2.0, 2.5], [1.0, 2.0], omega0=[1.0, 0.1, 0.5])
    >>> try:
    ...     run_fixed_step(RK4Stepper(), p, dt=0.01, max_steps=100)
    ... except ep.EulerPoissonError as err:
    ...     print(err)
    rk4: the output times need 200 steps of dt = 0.01, more than max_steps=100; raise max_steps or dt, or shorten the times
    """
    name = stepper.name
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating)):
        raise InvalidInputError(f"{name}: dt must be a positive number, got {dt!r}")
    dt = float(dt)
    if not (math.isfinite(dt) and dt > 0):
        raise InvalidInputError(f"{name}: dt must be a finite number > 0, got {dt!r}")
    t0 = float(t0)
    t = np.asarray(problem.t, dtype=float)
    branches, need = step_plan(t, dt, t0)
    if not need <= max_steps:
        raise InvalidInputError(
            f"{name}: the output times need {need:.6g} steps of dt = {dt:.6g}, more than max_steps={max_steps}; "
            f"raise max_steps or dt, or shorten the times"
        )
    bshape = tuple(problem.batch_shape)
    B = int(np.prod(bshape, dtype=int))
    T = t.shape[0]
    qout = np.empty((B, T, 4))
    wout = np.empty((B, T, 3))
    steps = 0
    if B:
        start = stepper.init(problem)
        for branch in branches:
            state, a = start, t0
            for i in branch:
                b = float(t[i])
                n = int(_count(b - a, dt))
                if n:
                    state = _advance(stepper, state, a, b, dt, n)
                    steps += n
                    a = b
                qout[:, i] = state.q
                wout[:, i] = state.omega
    stats = {"dt": dt, "steps": steps, "evaluations": steps * stepper.evaluations_per_step}
    return MethodResult(q=qout.reshape(bshape + (T, 4)), omega=wout.reshape(bshape + (T, 3)), stats=stats)


def _advance(stepper: Stepper, state: StepState, a: float, b: float, dt: float, n: int) -> StepState:
    """``n`` steps from ``a`` to ``b``: ``n - 1`` of ``+-dt`` (the step k starting at ``a + k h``), then the rest."""
    L = b - a
    h = math.copysign(dt, L)
    for k in range(n):
        hk = h if k < n - 1 else L - (n - 1) * h
        tk = a + k * h
        with np.errstate(over="ignore", invalid="ignore"):
            state = stepper.step(state, tk, hk)
            q = state.q
            if stepper.renormalize:
                nrm = np.sqrt(q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2] + q[:, 3] * q[:, 3])
                q = q / nrm[:, None]
                state = state._replace(q=q)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(state.omega))):
            raise EulerPoissonError(
                f"{stepper.name}: the state became non-finite at t = {tk + hk:.6g} (overflow: too large angular "
                f"velocity or torque for dt = {dt:.6g}); use a smaller dt"
            )
    return state
