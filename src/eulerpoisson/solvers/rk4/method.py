r"""The classical Runge-Kutta method of order 4 with a fixed step (``method="rk4"``): a plain reference.

On :math:`y = (q, \boldsymbol\Omega)` with the model's own vector field
(:meth:`~eulerpoisson.model.equations.Model.rhs`, the one ``rk`` integrates
under torque),

.. math:: \dot q = \tfrac12\,q\otimes(0, \boldsymbol\Omega), \qquad
          I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega + \boldsymbol\tau,

one step of size :math:`h` from :math:`(t, y)` is the classical tableau

.. math:: k_1 = f(t, y),\quad k_2 = f(t + \tfrac h2, y + \tfrac h2 k_1),\quad
          k_3 = f(t + \tfrac h2, y + \tfrac h2 k_2),\quad k_4 = f(t + h, y + hk_3),

.. math:: y_1 = y + \tfrac h6 (k_1 + 2k_2 + 2k_3 + k_4),

followed by the projection :math:`q_1 \leftarrow q_1/|q_1|` (the exact flow
keeps :math:`|q| = 1`; the projection changes the state by
:math:`O(h^5)` per step, so the order stays 4). The loop over the output
times is the shared fixed-step driver,
:func:`~eulerpoisson.solvers.stepper.run_fixed_step`: full steps of ``dt``
and one shorter step landing on each output time, both time directions.

Every model runs, the free body and any torque (Python callables
included, vectorized over the batch: the whole batch is advanced at once,
every body with the same steps); nothing is conserved exactly.

References
----------
W. Kutta, "Beitrag zur näherungsweisen Integration totaler
Differentialgleichungen", Z. Math. Phys. 46 (1901) 435. E. Hairer,
S. P. Nørsett and G. Wanner, *Solving Ordinary Differential Equations I*,
2nd ed. (1993), II.1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...errors import InvalidInputError
from .. import charts as ch
from ..problem import Problem
from ..registry import Method, MethodOptions, MethodResult, register_method
from ..stepper import Stepper, StepState, batch_vector_field, run_fixed_step

__all__ = ["RK4", "RK4Options", "RK4Stepper"]


class RK4Stepper(Stepper):
    """One step of the classical Runge-Kutta 4 tableau on ``(q, omega)``; ``q`` renormalized by the driver.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers import make_problem
    >>> from eulerpoisson.solvers.rk4 import RK4Stepper
    >>> p = make_problem([1.0, 2.0, 2.5], [1.0], omega0=[0.0, 0.0, 2.0])    # steady spin about e3
    >>> st = RK4Stepper()
    >>> s1 = st.step(st.init(p), 0.0, 0.5)
    >>> print(np.round(s1.q, 6), s1.omega)                          # cos(0.5) = 0.877583
    [[0.877604 0.       0.       0.479167]] [[0. 0. 2.]]
    """

    name = "rk4"
    order = 4
    renormalize = True
    evaluations_per_step = 4

    def init(self, problem: Problem) -> StepState:
        """The initial state with the model's vector field (:func:`~..stepper.batch_vector_field`) in ``aux``."""
        return super().init(problem)._replace(aux=batch_vector_field(problem))

    def step(self, state: StepState, t: float, h: float) -> StepState:
        f = state.aux
        q, w = state.q, state.omega
        h2 = 0.5 * h
        q1, w1 = f(t, q, w)
        q2, w2 = f(t + h2, q + h2 * q1, w + h2 * w1)
        q3, w3 = f(t + h2, q + h2 * q2, w + h2 * w2)
        q4, w4 = f(t + h, q + h * q3, w + h * w3)
        h6 = h / 6.0
        return state._replace(
            q=q + h6 * (q1 + 2.0 * q2 + 2.0 * q3 + q4),
            omega=w + h6 * (w1 + 2.0 * w2 + 2.0 * w3 + w4),
        )


@dataclass(frozen=True)
class RK4Options(MethodOptions):
    """Options of ``method="rk4"``; see :class:`RK4` for their meaning.

    Examples
    --------
    >>> from eulerpoisson.solvers.rk4 import RK4Options
    >>> RK4Options(dt=0.02).dt, RK4Options().dt, RK4Options().max_steps
    (0.02, 0.005, 10000000)
    >>> try:
    ...     RK4Options(dt=0.0)
    ... except ValueError as err:
    ...     print(err)
    rk4: dt must be a finite number > 0, got 0.0
    """

    method: ClassVar[str] = "rk4"

    dt: float = 0.005
    max_steps: int = 10_000_000

    def check(self) -> None:
        cfg = self.to_dict()
        dt = cfg["dt"]
        if isinstance(dt, (bool, np.bool_)) or not isinstance(dt, (int, float, np.integer, np.floating)):
            raise InvalidInputError(f"rk4: dt must be a positive number, got {dt!r}")
        if not (math.isfinite(float(dt)) and float(dt) > 0):
            raise InvalidInputError(f"rk4: dt must be a finite number > 0, got {dt!r}")
        cfg["dt"] = float(dt)
        cfg["max_steps"] = ch.check_count("rk4", "max_steps", cfg["max_steps"])
        self._update(cfg)


@register_method
class RK4(Method):
    r"""The classical Runge-Kutta method of order 4, fixed step, on the model's equations.

    Parameters
    ----------
    dt : float
        The step (default 0.005), > 0: full steps of ``dt`` and one shorter
        step to land on each output time. The error at a fixed time scales
        as :math:`(|\boldsymbol\Omega|\,dt)^4`: about 1e-10 after one time
        unit at :math:`|\boldsymbol\Omega| = 3` with the default.
    max_steps : int
        Most steps (default 10^7), both time directions together; every body
        of a batch takes the same steps. Refused before the first step when
        the output times need more
        (:class:`~eulerpoisson.errors.InvalidInputError`, an
        :class:`~eulerpoisson.errors.EulerPoissonError`).

    One thread: the whole batch is advanced by NumPy array operations driven
    from Python (``threads = False``).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0, -1.0], omega0=[1.0, 0.1, 0.5], method="rk4", dt=0.01)
    >>> ref = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0, -1.0], omega0=[1.0, 0.1, 0.5])
    >>> bool(np.max(np.abs(tr.omega - ref.omega)) < 1e-9), tr.stats["steps"]
    (True, 200)
    """

    name = "rk4"
    Options = RK4Options
    order = 4
    refine = "dt"
    negative_times = True
    description = "classical Runge-Kutta 4, fixed step dt, on (q, Omega) with the model's vector field (any torque)"
    threads = False
    additive_stats = ()

    @classmethod
    def supports(cls, model) -> str | None:
        bad = [t for t in model.torques if t.kind == "unrecorded"]
        if bad:
            return f"the torque {bad[0].description} was not recorded (a Python function read back from a file)"
        return None

    def run(self, problem: Problem) -> MethodResult:
        return run_fixed_step(RK4Stepper(), problem, self.config["dt"], self.config["max_steps"])
