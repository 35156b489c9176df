r"""The quick lane of :func:`~eulerpoisson.solve`: one free body at a few times, without the engine's set-up.

A call such as ``ep.solve(body, [t], omega0=w)`` spends most of its time in
the general set-up (:func:`~eulerpoisson.solvers.engine.prepare_run`: the
options checked, the arguments converted and broadcast, the segments
planned), not in the method. :func:`quick_solve` recognizes the plain case
and does only what it needs:

* one free body: a :class:`~eulerpoisson.RigidBody` of batch shape ``()``
  or three principal moments (validated once per distinct moments,
  :func:`~eulerpoisson.model.body.cached_body`), no torque;
* ``omega0`` three finite numbers, ``attitude0`` None or one quaternion,
  no ``m0``/``gibbs0``/``workers``;
* at most :data:`QUICK_MAX_TIMES` finite output times;
* the method by name (or None: the default for the free body, ``exact``),
  with options of plain values (the configured method, and its support of
  a body given by its moments, are checked once per kind of call and kept
  in a small cache, :class:`_Plan`).

It then calls the method's shortcut for one body (:meth:`~.Method.run_one`:
the exact method and taylor have one, which skip the problem and its
layers), or else what the engine calls (the method's
:meth:`~.Method.for_batch` and :meth:`~.Method.run` through
:func:`~.parallel.solve_batch`), and makes the same
:class:`~eulerpoisson.trajectory.Trajectory`: the result is the one of the
general path, bit for bit and field for field (tested). Anything else,
including every input that is not valid, returns None: the general path
then solves it or raises its error.
"""

from __future__ import annotations

import math
import time as _time
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError
from ..model.body import RigidBody, cached_body
from ..model.equations import Model
from ..trajectory import Trajectory, stored_attitudes
from ..util.env import env_value
from ..util.jit import run_shape, whole_run
from . import engine
from .parallel import ENV_WORKERS, resolve_workers, solve_batch
from .problem import Problem, initial_quaternion
from .registry import check_supported, get_method

if TYPE_CHECKING:
    from .registry import Method

__all__ = ["QUICK_MAX_TIMES", "quick_solve"]

#: most output times a call takes through the quick lane
QUICK_MAX_TIMES = 64

#: what the lane keeps of the calls seen, by (method name, plain options, moments or None): :class:`_Plan` (bounded)
_PLANS: dict[tuple, _Plan] = {}
_PLANS_MAX = 64

_FLOAT64 = np.dtype(np.float64)
_IDENTITY = (1.0, 0.0, 0.0, 0.0)


class _Plan:
    """The checked part of a kind of call: the configured method (for a body given by its three moments, the
    method's support of that body checked too)."""

    __slots__ = ("cls", "method", "name")

    def __init__(self, name: str, method: Method):
        self.name = name
        self.method = method
        self.cls = type(method)

    def current(self) -> bool:
        """Whether the name still stands for the method's class (a plug-in may register another since)."""
        try:
            return get_method(self.name) is self.cls
        except InvalidInputError:
            return False  # unregistered since: the general path raises


def _number(x: Any) -> float | None:
    """A finite Python float from an int or a float (NumPy float64 included), else None."""
    if type(x) is float or type(x) is int or type(x) is np.float64:
        v = float(x)
        return v if math.isfinite(v) else None
    return None


def _floats(x: Any, n: int | None) -> list[float] | None:
    """``x`` as a list of finite floats (length ``n``, or 1 to :data:`QUICK_MAX_TIMES` when None), else None."""
    if type(x) is np.ndarray:
        if x.dtype != _FLOAT64 or x.ndim != 1:
            return None
        seq = x.tolist()
    elif type(x) is list or type(x) is tuple:
        seq = x
    else:
        return None
    if (len(seq) != n) if n is not None else not 1 <= len(seq) <= QUICK_MAX_TIMES:
        return None
    out = []
    for v in seq:
        f = (v if math.isfinite(v) else None) if type(v) is float else _number(v)
        if f is None:
            return None
        out.append(f)
    return out


def _options_key(options: dict[str, Any]) -> tuple | None:
    """The options as a key of plain values (sorted by name), or None where one is not plain (the general path)."""
    if not options:
        return ()
    items = []
    for k, v in options.items():
        if v is not None and type(v) not in (bool, int, float, str):
            return None
        items.append((k, type(v).__name__, v))
    return tuple(sorted(items))


def _make_plan(name: str, options: dict[str, Any], moments: tuple[float, float, float] | None) -> _Plan | None:
    """The plan of a kind of call (configured and checked once), or None where the general path must decide."""
    try:
        _, m = engine.configure_method(name, dict(options))
    except (TypeError, InvalidInputError):
        return None  # the general path raises it
    if m is None:  # pragma: no cover - a name is given
        return None
    if moments is not None:
        try:
            check_supported(m, Model(cached_body(moments)))  # the configured method: its options count
        except (TypeError, ValueError):  # (InvalidInputError is a ValueError)
            return None  # the general path raises it
    return _Plan(name, m)


def quick_solve(
    body: Any,
    t: Any,
    *,
    omega0: Any = None,
    m0: Any = None,
    attitude0: Any = None,
    gibbs0: Any = None,
    torque: Any = None,
    method: Any = None,
    workers: Any = None,
    **options: Any,
) -> Trajectory | None:
    """:func:`~eulerpoisson.solve` of one free body at a few times, or None where the general path must run.

    The arguments are those of :func:`~eulerpoisson.solve` (a tuple ``t`` is a list of times there too).

    Returns
    -------
    Trajectory or None
        The trajectory the general path returns, bit for bit; None when the call is not of the plain kind
        described in the module notes (or has an invalid input: the general path raises its error).

    Examples
    --------
    >>> from eulerpoisson.solvers.quick import quick_solve
    >>> tr = quick_solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
    >>> tr.method, tr.omega.shape
    ('exact', (2, 3))
    >>> quick_solve([1.0, 2.0, 3.0], [0.0, 1.0], m0=[1.0, 0.1, 0.5]) is None  # not of the plain kind
    True
    """
    start = _time.perf_counter()
    if torque is not None or m0 is not None or gibbs0 is not None or workers is not None or omega0 is None:
        return None
    if method is None:
        if options:
            return None
        name = "exact"  # the default method of the free body (engine.default_method)
    elif type(method) is str:
        name = method
    else:
        return None
    times = [f] if (f := _number(t)) is not None else _floats(t, None)
    w = _floats(omega0, 3)
    if times is None or w is None:
        return None
    if type(body) is RigidBody:
        if body.batch_shape != ():
            return None
        moments = None
    else:
        mo = _floats(body, 3)
        if mo is None:
            return None
        moments = (mo[0], mo[1], mo[2])
    okey = _options_key(options)
    if okey is None:
        return None
    key = (name, okey, moments)
    plan = _PLANS.get(key)
    if plan is None or not plan.current():
        plan = _make_plan(name, options, moments)
        if plan is None:
            return None
        if len(_PLANS) >= _PLANS_MAX:
            _PLANS.clear()
        _PLANS[key] = plan
    m, cls = plan.method, plan.cls
    if attitude0 is None:
        q0 = np.array(_IDENTITY)
    else:
        if _floats(attitude0, 4) is None:
            return None
        try:
            q0 = initial_quaternion(attitude0, None).copy()
        except (TypeError, InvalidInputError):
            return None
    # a body given by its moments: checked once per distinct moments (arrays of its own), its support in the plan
    b = body if moments is None else cached_body(moments)
    model = Model(b)
    if moments is None:
        try:
            check_supported(m, model)  # the configured method: its options count (a free-body-only scheme)
        except (TypeError, ValueError):  # (InvalidInputError is a ValueError)
            return None
    if not cls.negative_times and min(times) < 0:
        return None
    tt = np.array(times)
    wa = np.array(w)
    if cls.order is not None:
        # a stepping method's long run is cut into segments (engine.plan_segments): the general path
        # as prepare_run computes it (a sum of three in order, a correctly rounded square root)
        turns = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * max(abs(v) for v in times)
        if not (math.isfinite(turns) and turns <= engine.SEGMENT_TURNS):
            return None
    if env_value(ENV_WORKERS):  # (a bad setting is an error for one body too: the general path raises it)
        try:
            resolve_workers(None)
        except (TypeError, ValueError):
            return None
    n = len(times)
    # the method's shortcut for one body, when it has one (the problem is the whole run: whole_run's sizes are
    # those a method's run_one reads already)
    res = m.run_one(b, q0, wa, tt)
    if res is None:
        with whole_run(*run_shape(0, n)):
            problem = Problem(model=model, q0=q0, omega0=wa, t=tt)
            m = m.for_batch(problem)
            res = solve_batch(m, problem, None)
    stats = {"wall_time": 0.0, **res.stats}
    q, om = res.q, res.omega
    if type(q) is np.ndarray and type(om) is np.ndarray and q.shape == (n, 4) and om.shape == (n, 3):
        # what Trajectory makes of them (stored_attitudes: checked, normalized, signs continuous), without
        # its checks of the parts this lane made
        if not res.prepared:
            q = stored_attitudes(tt, q, om)
        if q.dtype == _FLOAT64 and om.dtype == _FLOAT64:
            tr = Trajectory._assembled(tt, q, om, model, name, m.config, stats)
            tr.stats["wall_time"] = _time.perf_counter() - start
            return tr
    tr = Trajectory(
        t=tt,
        quaternion=res.q,
        omega=res.omega,
        body=b,
        torque=model.torques,
        method=name,
        options=dict(m.config),
        stats=stats,
        _prepared=res.prepared,
    )
    tr.stats["wall_time"] = _time.perf_counter() - start
    return tr
