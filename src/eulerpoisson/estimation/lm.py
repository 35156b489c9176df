r"""Levenberg–Marquardt on the fit's manifold (attitude on SO(3), the rest in a vector space).

Each iteration solves :math:`(J^\mathsf TJ + \lambda\,\mathrm{diag}(J^\mathsf TJ))\,\delta = -J^\mathsf T\mathbf r`
(Marquardt's scaling, with a floor on the diagonal), moves the attitude by
:math:`q_0 \leftarrow q_0\otimes\exp(\delta_\theta/2)` and the other unknowns
by addition, and keeps the step when :math:`\chi^2` decreases (then
:math:`\lambda` shrinks) or rejects it (then :math:`\lambda` grows). A step to
an inertia that is not physical (not positive definite, or breaking a
triangle inequality) is rejected like a step that increases :math:`\chi^2`.

References
----------
D. W. Marquardt, "An algorithm for least-squares estimation of nonlinear
parameters", J. SIAM 11 (1963) 431-441. H. B. Nielsen, "Damping parameter in
Marquardt's method", IMM-REP-1999-05 (the update of :math:`\lambda`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics.quaternion import qmul
from .residuals import Evaluation, FitState, Layout, evaluate, exp_quaternion, inertia_matrix, inertia_valid

__all__ = ["LMOutcome", "levenberg_marquardt", "retract"]


@dataclass
class LMOutcome:
    """Where the search ended: the state, its evaluation, iterations and whether it converged."""

    state: FitState
    evaluation: Evaluation
    iterations: int
    converged: bool


def retract(layout: Layout, state: FitState, delta) -> FitState:
    """Move ``state`` by the parameter step ``delta`` (attitude by the exponential map)."""
    na = layout.n_attitude
    q0 = state.q0
    if na:
        q0 = qmul(q0, exp_quaternion(delta[:3]))
        q0 = q0 / np.linalg.norm(q0)
    return FitState(q0, state.omega0 + delta[na : na + 3], state.inertia_params + delta[na + 3 :])


def _valid(layout, state):
    I, _ = inertia_matrix(layout, state.inertia_params)
    return inertia_valid(I)


def _evaluate(layout, obs, state, prior):
    """Evaluation, with the prior's rows ``(p - p0)/sigma`` on the inertia parameters appended when given."""
    ev = evaluate(layout, obs, state)
    if prior is None or not len(state.inertia_params):
        return ev
    p0, sig = prior
    q = len(p0)
    r = (state.inertia_params - p0) / sig
    assert ev.jacobian is not None  # evaluate() computes it unless told not to
    Jp = np.zeros((q, ev.jacobian.shape[1]))
    Jp[:, -q:] = np.eye(q) / sig
    res = np.concatenate([ev.residuals, r])
    return Evaluation(res, np.vstack([ev.jacobian, Jp]), float(res @ res), ev.rows, ev.quaternion, ev.omega)


def _try(layout, obs, state, prior):
    try:
        ev = _evaluate(layout, obs, state, prior)
    except FloatingPointError:
        return None
    if not np.isfinite(ev.chi2) or not np.all(np.isfinite(ev.jacobian)):
        return None
    return ev


def levenberg_marquardt(
    layout: Layout, obs, state: FitState, *, max_iter: int = 200, rtol: float = 1e-12, prior=None
) -> LMOutcome:
    r"""Minimize the weighted sum of squares from ``state``.

    Stops when a kept step lowers :math:`\\chi^2` by less than ``rtol`` relative
    and the step is small against the parameters' scale, when the gradient
    vanishes, or after ``max_iter`` evaluations. ``prior = (p0, sigma)`` adds
    the rows :math:`(p - p_0)/\sigma` on the inertia parameters (used on the
    short windows of the continuation, which barely see the inertia). A step
    that leaves the physical inertias is halved until it stays inside.

    Raises
    ------
    FloatingPointError
        The motion cannot be integrated at the starting state.
    """
    ev = _evaluate(layout, obs, state, prior)
    lam = None
    nu = 2.0
    it = 0
    converged = False
    while it < max_iter:
        J, r = ev.jacobian, ev.residuals
        A = J.T @ J
        g = J.T @ r
        d = np.diag(A).copy()
        dmax = d.max() if d.size else 1.0
        d = np.maximum(d, 1e-12 * dmax + 1e-300)
        if np.max(np.abs(g)) <= 1e-14 * (ev.chi2 + 1e-300) * np.sqrt(dmax):
            converged = True
            break
        if lam is None:
            lam = 1e-3
        it += 1
        try:
            step = np.linalg.solve(A + lam * np.diag(d), -g)
        except np.linalg.LinAlgError:
            lam *= 10.0
            continue
        new_state = retract(layout, state, step)
        for _ in range(30):
            if _valid(layout, new_state):
                break
            step = 0.5 * step
            new_state = retract(layout, state, step)
        new = _try(layout, obs, new_state, prior) if _valid(layout, new_state) else None
        predicted = -(step @ g) - 0.5 * step @ (A @ step)  # decrease of chi2/2 by the linear model
        if new is not None and new.chi2 < ev.chi2:
            actual = 0.5 * (ev.chi2 - new.chi2)
            rho = actual / predicted if predicted > 0 else 0.0
            small = np.sqrt(step @ (d * step)) <= 1e-9 * np.sqrt(ev.chi2 + 1e-300)
            rel = (ev.chi2 - new.chi2) <= rtol * ev.chi2
            state, ev = new_state, new
            lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            lam = max(lam, 1e-15)
            nu = 2.0
            if rel or small:
                converged = True
                break
        else:
            if (
                new is not None
                and (ev.chi2 - new.chi2) >= -1e-15 * ev.chi2
                and np.sqrt(step @ (d * step)) <= 1e-9 * np.sqrt(ev.chi2 + 1e-300)
            ):
                converged = True  # at round-off level
                break
            lam *= nu
            nu *= 2.0
            if lam > 1e16:
                converged = True  # no step lowers chi2: a minimum to working precision
                break
    return LMOutcome(state, ev, it, converged)
