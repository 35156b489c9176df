r"""Scipy's ``solve_ivp`` on the free body (``method="rk"``): the baseline users know.

Two formulations (option ``formulation``):

``"quaternion"`` (default)
    :math:`(q, \boldsymbol\Omega)` with the quaternion kinematics
    :math:`\dot q = \tfrac12 q\otimes(0, \boldsymbol\Omega)` (paper eq. 1.4
    in quaternions) and Euler's equations
    :math:`I\dot{\boldsymbol\Omega} = I\boldsymbol\Omega\times\boldsymbol\Omega`
    (eq. 1.5). The quaternion is renormalized only at output.
``"gibbs"``
    :math:`(\mathbf n, \boldsymbol\Omega)` with the paper's eq. 1.30,
    :math:`\dot{\mathbf n} = \tfrac12\tilde A^T\boldsymbol\Omega`, in charts
    :math:`R = R_cR(\mathbf n)`: a terminal event at
    :math:`|\mathbf n| = ` ``chart_threshold`` stops the integration, folds
    :math:`R(\mathbf n)` into :math:`R_c` and restarts at :math:`\mathbf n = 0`
    with the same :math:`\boldsymbol\Omega`
    (:mod:`~eulerpoisson.solvers.charts`).

The equations are solved in the principal frame of each body (exact by left
invariance, see :class:`~eulerpoisson.solvers.charts.PrincipalFrame`).
Each body of a batch is integrated by its own ``solve_ivp`` call, so its
adaptive steps and its result do not depend on the rest of the batch.
Outputs are read from the integrator's dense output at the requested times.

Nothing is conserved exactly; energy and angular momentum errors follow the
tolerances and grow (typically linearly) with time.

References
----------
Paper eqs. 1.4-1.5, 1.30. P. Virtanen et al., "SciPy 1.0", Nat. Methods 17
(2020) 261 (``scipy.integrate.solve_ivp``). J. R. Dormand and P. J. Prince,
"A family of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980)
19; E. Hairer, S. P. Nørsett and G. Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed. (1993), II.5 (DOP853).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...errors import EulerPoissonError, InvalidInputError
from ...model.free_body import euler_coefficients
from ...numerics.quaternion import qmul_components
from .. import charts as ch
from ..problem import Problem
from ..registry import Method, MethodOptions, MethodResult, register_method

__all__ = ["RK", "INTEGRATORS"]

#: scipy's solve_ivp methods and their (highest) orders
INTEGRATORS = {"RK23": 3, "RK45": 5, "DOP853": 8, "Radau": 5, "BDF": 5, "LSODA": 12}

FORMULATIONS = ("quaternion", "gibbs")


def _rhs_quaternion(inv_moments, moments):
    """Right-hand side of (q, Omega) for one body in its principal frame."""
    a1, a2, a3 = euler_coefficients(*moments)

    def f(t, y):
        w, x, yy, z, o1, o2, o3 = y
        d0, d1, d2, d3 = qmul_components(w, x, yy, z, 0.0, o1, o2, o3)
        return np.array([0.5 * d0, 0.5 * d1, 0.5 * d2, 0.5 * d3, a1 * o2 * o3, a2 * o3 * o1, a3 * o1 * o2])

    return f


def _rhs_gibbs(moments):
    r"""Right-hand side of (n, Omega), eq. 1.30, for one body in its principal frame."""
    a1, a2, a3 = euler_coefficients(*moments)

    def f(t, y):
        n1, n2, n3, o1, o2, o3 = y
        no = n1 * o1 + n2 * o2 + n3 * o3
        return np.array(
            [
                0.5 * (o1 + n2 * o3 - n3 * o2 + no * n1),
                0.5 * (o2 + n3 * o1 - n1 * o3 + no * n2),
                0.5 * (o3 + n1 * o2 - n2 * o1 + no * n3),
                a1 * o2 * o3,
                a2 * o3 * o1,
                a3 * o1 * o2,
            ]
        )

    return f


class _StepBudgetExhausted(Exception):
    """Raised inside the right-hand side when ``max_steps`` is used up."""


class _NonFiniteRate(Exception):
    """Raised inside the right-hand side when it is not finite (its argument: the time)."""


#: smallest relative tolerance scipy's solve_ivp honours (100 machine epsilons)
_RTOL_MIN = 100 * np.finfo(float).eps

#: right-hand side evaluations allowed per step of ``max_steps`` (DOP853 uses 12 per step)
_NFEV_PER_STEP = 16


@dataclass(frozen=True)
class RKOptions(MethodOptions):
    """Options of ``method="rk"`` (scipy's ``solve_ivp``); see :class:`RK` for their meaning.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers import RKOptions
    >>> opts = RKOptions(integrator="RK45", tol=1e-9)
    >>> opts.integrator, opts.tol
    ('RK45', 1e-09)
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], method=opts)
    >>> tr.method, bool(tr.drift()["energy"] < 1e-7)
    ('rk', True)
    """

    method: ClassVar[str] = "rk"

    integrator: str = "DOP853"
    formulation: str = "quaternion"
    tol: float = 1e-10
    rtol: float | None = None
    atol: float | None = None
    chart_threshold: float = 1.0
    max_steps: int = 10_000_000

    def check(self) -> None:
        cfg = self.to_dict()
        integ = cfg["integrator"]
        if not isinstance(integ, str) or integ not in INTEGRATORS:
            raise InvalidInputError(
                f"rk: unknown integrator {integ!r}; choose one of scipy's solve_ivp methods {', '.join(INTEGRATORS)}"
            )
        form = cfg["formulation"]
        if not isinstance(form, str) or form not in FORMULATIONS:
            raise InvalidInputError(f"rk: unknown formulation {form!r}; choose one of {', '.join(FORMULATIONS)}")
        for key in ("tol", "rtol", "atol"):
            v = cfg[key]
            if v is None and key != "tol":
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
                raise InvalidInputError(f"rk: {key} must be a positive number, got {v!r}")
            if not (math.isfinite(float(v)) and float(v) > 0):
                raise InvalidInputError(f"rk: {key} must be a finite number > 0, got {v!r}")
            if key != "atol" and not (_RTOL_MIN <= float(v) < 1.0):
                raise InvalidInputError(
                    f"rk: {key} must be in [{_RTOL_MIN:.3g}, 1) (scipy's solve_ivp raises a smaller relative "
                    f"tolerance to 100 machine epsilons), got {v!r}"
                )
        thr = ch.check_threshold(cfg["chart_threshold"])
        if thr == 0:
            raise InvalidInputError("rk: chart_threshold must be > 0 (the chart event is |n| = chart_threshold)")
        cfg["chart_threshold"] = thr
        cfg["max_steps"] = ch.check_count("rk", "max_steps", cfg["max_steps"])

        self._update(cfg)


@register_method
class RK(Method):
    r"""``scipy.integrate.solve_ivp`` on the quaternion or Gibbs-vector formulation.

    Parameters
    ----------
    integrator : str
        A ``solve_ivp`` method: ``"DOP853"`` (default), ``"RK45"``,
        ``"RK23"``, ``"Radau"``, ``"BDF"`` or ``"LSODA"``.
    formulation : str
        ``"quaternion"`` (default) or ``"gibbs"`` (eq. 1.30 with charts).
    tol : float
        Accuracy knob (default 1e-10): ``rtol = tol`` and ``atol = tol`` times
        the scale of each component (1 for the attitude, :math:`|\boldsymbol\Omega_0|`
        for the angular velocity), unless ``rtol``/``atol`` are given.
    rtol, atol : float or None
        Passed to ``solve_ivp`` as they are when given (``atol`` a scalar).
    chart_threshold : float
        ``"gibbs"`` only: re-centre the chart when :math:`|\mathbf n|`
        reaches it (default 1, > 0).
    max_steps : int
        Per body (default 10^7). Refused up front when the times need at
        least :math:`|\boldsymbol\Omega||t|/(8\pi)` steps more than that;
        during the run, 16 evaluations of the right-hand side count as one
        step. Exhausted: :class:`~eulerpoisson.errors.EulerPoissonError`.

    :meth:`nominal_order` is the order of the chosen integrator (the highest
    order for the variable-order BDF and LSODA).

    One thread: ``solve(..., workers=)`` does not split ``rk`` batches into
    threads (``threads = False``), since ``solve_ivp`` steps in Python and
    holds the GIL (threads would only add overhead); use processes (e.g.
    ``eulerpoisson sweep``) to spread many bodies over cores.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.solvers.rk import RK
    >>> RK.name, RK.refine
    ('rk', 'tol')
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], method="rk", tol=1e-12)
    >>> ref = ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
    >>> bool(np.max(np.abs(tr.omega - ref.omega)) < 1e-9)
    True
    """

    name = "rk"
    Options = RKOptions
    order = 8
    refine = "tol"
    negative_times = True
    description = "scipy solve_ivp (DOP853 by default) on (q, Omega) or (n, Omega) with charts"
    threads = False
    additive_stats = ("nfev", "njev", "steps", "chart_changes")

    def nominal_order(self) -> int:
        """Order of the configured scipy integrator."""
        return INTEGRATORS[self.config["integrator"]]

    # ------------------------------------------------------------------
    def _tolerances(self, w0, n_attitude):
        """``(rtol, atol)``; atol scaled per component unless given."""
        cfg = self.config
        tol = float(cfg["tol"])
        rtol = tol if cfg["rtol"] is None else float(cfg["rtol"])
        if cfg["atol"] is not None:
            return rtol, float(cfg["atol"])
        wscale = float(np.sqrt(np.sum(w0 * w0)))
        wscale = wscale if wscale > 0 else 1.0
        return rtol, np.r_[np.full(n_attitude, tol), np.full(3, tol * wscale)]

    @classmethod
    def supports(cls, model) -> str | None:
        bad = [t for t in model.torques if t.kind == "unrecorded"]
        if bad:
            return f"the torque {bad[0].description} was not recorded (a Python function read back from a file)"
        return None

    def run(self, problem: Problem) -> MethodResult:
        if not problem.model.is_free:
            return self._run_torque(problem)
        cfg = self.config
        bshape = problem.batch_shape
        B = int(np.prod(bshape, dtype=int))
        T = problem.t.shape[0]
        frame = ch.principal_frame(problem)
        q0 = np.ascontiguousarray(problem.q0.reshape(B, 4).T)
        w0 = np.ascontiguousarray(problem.omega0.reshape(B, 3).T)
        q0, w0 = frame.to_principal(q0, w0)
        moments = frame.moments
        qout = np.empty((4, B, T))
        wout = np.empty((3, B, T))
        stats = {
            "integrator": cfg["integrator"],
            "formulation": cfg["formulation"],
            "nfev": 0,
            "njev": 0,
            "steps": 0,
            "chart_changes": 0,
        }
        t = problem.t
        if B:
            # an explicit Runge-Kutta step turns the body by at most a few radians (stability of
            # the oscillating solution): at least |Omega| |t| / (8 pi) steps, checked up front
            with np.errstate(over="ignore"):
                wmax = float(np.max(np.sqrt(ch.dot(w0, w0))))
            ch.check_step_budget(
                "rk", t, wmax / (8.0 * math.pi), cfg["max_steps"], "raise max_steps or shorten the times"
            )
        branches = [np.flatnonzero(t >= 0), np.flatnonzero(t < 0)]
        for b in range(B):
            stats["_nfev_body"] = 0  # max_steps is per body, both branches together
            for idx in branches:
                if idx.size == 0:
                    continue
                if cfg["formulation"] == "quaternion":
                    q, w = self._solve_quaternion(q0[:, b], w0[:, b], moments[:, b], t[idx], stats)
                else:
                    q, w = self._solve_gibbs(q0[:, b], w0[:, b], moments[:, b], t[idx], stats)
                qout[:, b, idx] = q
                wout[:, b, idx] = w
        stats.pop("_nfev_body", None)
        q, w = frame.from_principal(qout, wout)
        q = np.moveaxis(q, 0, -1).reshape(bshape + (T, 4))
        w = np.moveaxis(w, 0, -1).reshape(bshape + (T, 3))
        return MethodResult(q=q, omega=w, stats=stats)

    def _call(self, f, t0, t1, y0, rtol, atol, stats, events=None):
        from scipy.integrate import solve_ivp

        max_steps = self.config["max_steps"]
        budget = _NFEV_PER_STEP * max_steps  # right-hand side evaluations allowed for this body
        count = [stats.get("_nfev_body", 0)]

        def g(t, y):
            count[0] += 1
            if count[0] > budget:
                raise _StepBudgetExhausted
            dy = f(t, y)
            if not np.isfinite(dy).all():
                # stop at once: the adaptive steps would shrink on NaN until max_steps, hours at the default
                raise _NonFiniteRate(t)
            return dy

        with np.errstate(over="ignore", invalid="ignore"):
            try:
                sol = solve_ivp(
                    g,
                    (t0, t1),
                    y0,
                    method=self.config["integrator"],
                    rtol=rtol,
                    atol=atol,
                    dense_output=True,
                    events=events,
                )
            except _NonFiniteRate as exc:
                raise EulerPoissonError(
                    f"rk: the right-hand side is not finite at t = {exc.args[0]:.6g} (a torque or a rate that "
                    "overflows float64, or a torque function that returned NaN); use smaller values"
                ) from None
            except _StepBudgetExhausted:
                raise EulerPoissonError(
                    f"rk: max_steps={max_steps} exhausted ({budget} evaluations of the right-hand side) before "
                    f"t = {t1:.6g}; raise max_steps or tol, or shorten the times"
                ) from None
        stats["_nfev_body"] = count[0]
        if not np.all(np.isfinite(sol.y)):
            raise EulerPoissonError(
                f"rk: the state became non-finite before t = {t1:.6g} (overflow: too large angular velocity "
                f"or Gibbs vector); use smaller values or formulation='quaternion'"
            )
        stats["nfev"] += int(sol.nfev)
        stats["njev"] += int(sol.njev)
        stats["steps"] += max(len(sol.t) - 1, 0)
        if sol.status == -1:
            hint = ""
            if self.config["formulation"] == "gibbs":
                hint = (
                    f" (formulation='gibbs': |n| grows without bound near a half turn unless the chart is "
                    f"changed; chart_threshold={self.config['chart_threshold']:g})"
                )
            raise EulerPoissonError(f"rk: solve_ivp ({self.config['integrator']}) failed: {sol.message}{hint}")
        return sol

    def _solve_quaternion(self, q0, w0, moments, times, stats):
        rtol, atol = self._tolerances(w0, 4)
        f = _rhs_quaternion(1.0 / moments, moments)
        y0 = np.r_[q0, w0]
        tend = times[np.argmax(np.abs(times))]
        if tend == 0:
            y = np.repeat(y0[:, None], times.size, axis=1)
        else:
            sol = self._call(f, 0.0, float(tend), y0, rtol, atol, stats)
            y = sol.sol(times)
        q = y[:4] / np.sqrt(np.sum(y[:4] ** 2, axis=0))
        return q, y[4:]

    def _solve_gibbs(self, q0, w0, moments, times, stats):
        f = _rhs_gibbs(moments)  # left invariance: the free body's field does not depend on the chart centre
        return self._charts(lambda qc: f, q0, w0, times, self._tolerances(w0, 3), stats)

    def _charts(self, make_rhs, q0, w0, times, tolerances, stats):
        r"""Integrate :math:`(\mathbf n, \boldsymbol\Omega)` in charts :math:`R = R_cR(\mathbf n)` (one time direction).

        ``make_rhs(qc)`` gives the right-hand side in the chart centred at the
        unit quaternion ``qc`` (4, 1); a terminal event at
        :math:`|\mathbf n|` = ``chart_threshold`` folds :math:`R(\mathbf n)` into
        the centre and restarts at :math:`\mathbf n = 0` with the same
        :math:`\boldsymbol\Omega`. Returns ``q`` (4, T) and ``omega`` (3, T).
        """
        rtol, atol = tolerances
        thr = self.config["chart_threshold"]
        thr2 = thr * thr  # float: inf for a huge threshold (no chart change), no OverflowError

        def event(t, y):
            return y[0] * y[0] + y[1] * y[1] + y[2] * y[2] - thr2

        event.terminal = True  # type: ignore[attr-defined]  # scipy's solve_ivp reads these attributes
        event.direction = 1.0  # type: ignore[attr-defined]

        order = np.argsort(np.abs(times), kind="stable")
        ts = times[order]
        qo = np.empty((4, times.size))
        wo = np.empty((3, times.size))
        qc = np.asarray(q0, dtype=float).reshape(4, 1).copy()
        y = np.r_[np.zeros(3), w0]
        tcur = 0.0
        tend = float(ts[-1])
        k = 0  # next output (in ts order)
        while True:
            if tcur == tend:
                nrem = times.size - k
                ys = np.repeat(y[:, None], nrem, axis=1)
                stop = tend
            else:
                sol = self._call(make_rhs(qc), tcur, tend, y, rtol, atol, stats, events=event)
                stop = float(sol.t[-1])
                nrem = int(np.sum(np.abs(ts[k:]) <= abs(stop)))
                ys = sol.sol(ts[k : k + nrem]) if nrem else np.empty((6, 0))
            if nrem:
                sel = order[k : k + nrem]
                qq = ch.qmul(qc, ch.quaternion_from_gibbs(ys[:3]))
                qo[:, sel] = qq / np.sqrt(ch.dot4(qq, qq))
                wo[:, sel] = ys[3:]
                k += nrem
            if k >= times.size or tcur == tend:
                break
            # chart change at the event
            ye = sol.y[:, -1]
            qc = ch.qmul(qc, ch.quaternion_from_gibbs(ye[:3, None]))
            qc = qc / np.sqrt(ch.dot4(qc, qc))
            y = np.r_[np.zeros(3), ye[3:]]
            tcur = stop
            stats["chart_changes"] += 1
        return qo, wo

    # ------------------------------------------------------------------
    # under torque: the model's right-hand side in the body frame
    # ------------------------------------------------------------------
    def _run_torque(self, problem: Problem) -> MethodResult:
        cfg = self.config
        bshape = problem.batch_shape
        B = int(np.prod(bshape, dtype=int))
        T = problem.t.shape[0]
        t = problem.t
        q0 = problem.q0.reshape(B, 4)
        w0 = problem.omega0.reshape(B, 3)
        qout = np.empty((B, T, 4))
        wout = np.empty((B, T, 3))
        stats = {
            "integrator": cfg["integrator"],
            "formulation": cfg["formulation"],
            "nfev": 0,
            "njev": 0,
            "steps": 0,
            "chart_changes": 0,
        }
        branches = [np.flatnonzero(t >= 0), np.flatnonzero(t < 0)]
        for b in range(B):
            model = problem.model.element(np.unravel_index(b, bshape) if bshape else ())
            stats["_nfev_body"] = 0
            for idx in branches:
                if idx.size == 0:
                    continue
                if cfg["formulation"] == "quaternion":
                    q, w = self._solve_quaternion_model(model, q0[b], w0[b], t[idx], stats)
                else:
                    q, w = self._solve_gibbs_model(model, q0[b], w0[b], t[idx], stats)
                qout[b, idx] = q.T
                wout[b, idx] = w.T
        stats.pop("_nfev_body", None)
        return MethodResult(q=qout.reshape(bshape + (T, 4)), omega=wout.reshape(bshape + (T, 3)), stats=stats)

    def _solve_quaternion_model(self, model, q0, w0, times, stats):
        rtol, atol = self._tolerances(w0, 4)
        if not np.any(w0):  # a body released from rest: scale the rate by the torque's natural frequency
            rtol, atol = self._tolerances(self._rate_scale(model, q0), 4)

        def f(t, y):
            qd, wd = model.rhs(t, y[:4], y[4:])
            return np.concatenate([qd, wd])

        y0 = np.r_[q0, w0]
        tend = times[np.argmax(np.abs(times))]
        if tend == 0:
            y = np.repeat(y0[:, None], times.size, axis=1)
        else:
            sol = self._call(f, 0.0, float(tend), y0, rtol, atol, stats)
            y = sol.sol(times)
        q = y[:4] / np.sqrt(np.sum(y[:4] ** 2, axis=0))
        return q, y[4:]

    @staticmethod
    def _rate_scale(model, q0):
        """A rate for the tolerance of Omega when Omega0 = 0: sqrt(|I^-1 tau(0)|)."""
        tau = model.torque(0.0, q0, np.zeros(3))
        acc = np.linalg.norm(model.body.inertia_inv @ tau)
        return np.full(3, math.sqrt(acc) / math.sqrt(3.0) if acc > 0 else 0.0)

    def _solve_gibbs_model(self, model, q0, w0, times, stats):
        r"""(n, Omega) in charts R = R_c R(n); the torque sees the full attitude R_c R(n)."""

        def make_rhs(qc):
            def f(t, y):
                n = y[:3]
                o = y[3:]
                no = n @ o
                ndot = 0.5 * (o + np.cross(n, o) + no * n)
                q = ch.qmul(qc, ch.quaternion_from_gibbs(n[:, None]))[:, 0]
                return np.concatenate([ndot, model.omega_dot(t, q, o)])

            return f

        tolerances = self._tolerances(w0 if np.any(w0) else self._rate_scale(model, q0), 3)
        return self._charts(make_rhs, q0, w0, times, tolerances, stats)
