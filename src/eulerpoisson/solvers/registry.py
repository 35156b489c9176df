r"""The registry of solution methods.

Every way of computing the motion — the closed form, the Lie (Taylor)
series, symplectic integrators, scipy's Runge-Kutta — is a small
:class:`Method` subclass registered under a name (one folder per method in
:mod:`eulerpoisson.solvers`), so that one call, :func:`~eulerpoisson.solve`,
runs any of them and one test can check all of them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..errors import InvalidInputError, UnsupportedModelError
from ..model.equations import Model
from .problem import Problem

if TYPE_CHECKING:
    from ..model.body import RigidBody

__all__ = [
    "hybridmethod",
    "MethodOptions",
    "Method",
    "MethodResult",
    "overrides",
    "register_method",
    "unregister_method",
    "available_methods",
    "get_method",
    "methods_supporting",
    "check_supported",
]

_REGISTRY: dict[str, type[Method]] = {}


class hybridmethod:  # noqa: N801 - a decorator, named like classmethod
    """A method bound to the instance when called on one, to the class otherwise.

    :meth:`Method.supports` is one: ``Symplectic.supports(model)`` says whether
    some configuration of the method runs the model, and
    ``Symplectic(scheme="gauss4").supports(model)`` whether this one does.
    """

    def __init__(self, func):
        self.func = func
        self.__doc__ = func.__doc__

    def __get__(self, obj, owner=None):
        import functools

        return functools.partial(self.func, owner if obj is None else obj)


@dataclass
class MethodResult:
    """What a method returns: states at the output times.

    Attributes
    ----------
    q : ndarray, shape ``(*batch_shape, T, 4)``
    omega : ndarray, shape ``(*batch_shape, T, 3)``
    stats : dict
        Method-specific counters (steps, function evaluations, chart changes...).
    prepared : bool
        Set by the driver (:mod:`.parallel`), never by a method: ``q`` and
        ``omega`` were checked and ``q`` stored as a
        :class:`~eulerpoisson.trajectory.Trajectory` stores it, chunk by
        chunk, in the threads that solved them.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers import MethodResult
    >>> res = MethodResult(q=np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)), omega=np.zeros((2, 3)), stats={"steps": 0})
    >>> res.q.shape, res.omega.shape, res.stats, res.prepared
    ((2, 4), (2, 3), {'steps': 0}, False)
    """

    q: np.ndarray
    omega: np.ndarray
    stats: dict = field(default_factory=dict)
    prepared: bool = False


@dataclass(frozen=True)
class MethodOptions:
    """Base of the typed, frozen option sets of the methods (one dataclass per method).

    Constructing one validates it (``TypeError`` or
    :class:`~eulerpoisson.errors.InvalidInputError` naming the option), so an
    options object is always valid; :meth:`replace` makes a validated copy.
    Pass one as ``solve(..., method=TaylorOptions(tol=1e-12))``: the class
    knows its method (:attr:`method`).

    Examples
    --------
    >>> from eulerpoisson.solvers import MethodOptions, TaylorOptions
    >>> opts = TaylorOptions(tol=1e-12)
    >>> isinstance(opts, MethodOptions), opts.method
    (True, 'taylor')
    >>> opts.replace(order=20).to_dict()["order"]
    20
    >>> try:
    ...     opts.replace(tolerance=1e-9)
    ... except TypeError as err:
    ...     print(err)
    method 'taylor' got unknown option(s) tolerance; allowed: chart_threshold, dps, dt, max_steps, order, precision, tol
    """

    #: name of the method these options belong to
    method: ClassVar[str] = ""

    def __post_init__(self) -> None:
        self.check()

    def check(self) -> None:
        """Validate (and normalize) the fields; override in subclasses."""

    def _update(self, values: dict) -> None:
        """Store normalized values (used by :meth:`check`; the dataclass is frozen)."""
        for k, v in values.items():
            object.__setattr__(self, k, v)

    def to_dict(self) -> dict[str, Any]:
        """The options as a plain dict (as recorded in trajectories and files)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def names(cls) -> list[str]:
        """The option names."""
        return [f.name for f in fields(cls)]

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """The default value of every option."""
        return {f.name: f.default for f in fields(cls)}

    def replace(self, **changes: Any) -> MethodOptions:
        """A validated copy with some options changed.

        Raises
        ------
        TypeError
            An unknown option (the message lists the allowed ones).
        """
        _check_names(type(self), changes)
        return dataclasses.replace(self, **changes)


def _check_names(options_cls, given) -> None:
    unknown = sorted(set(given) - set(options_cls.names()))
    if unknown:
        allowed = ", ".join(sorted(options_cls.names())) or "none"
        raise TypeError(f"method {options_cls.method!r} got unknown option(s) {', '.join(unknown)}; allowed: {allowed}")


def overrides(method: object, base: type, names: tuple[str, ...]) -> bool:
    """Whether the class of ``method`` redefines any of the attributes ``names`` of ``base`` (a plug-in subclass).

    A shortcut that stands for some of a method's steps (:meth:`Method.run_one`) holds only while the class
    runs those steps as ``base`` defines them.

    Examples
    --------
    >>> from eulerpoisson.solvers.registry import Method, overrides
    >>> class Mine(Method):
    ...     def run(self, problem):
    ...         raise NotImplementedError
    >>> overrides(Mine(), Method, ("run",)), overrides(Mine(), Method, ("for_batch",))
    (True, False)
    """
    cls = type(method)
    if cls is base:
        return False
    return any(getattr(cls, n) is not getattr(base, n) for n in names)


class Method:
    """Base class of a solution method.

    Subclasses set :attr:`name`, :attr:`Options` (a frozen
    :class:`MethodOptions` dataclass of the options with their defaults and
    validation) and implement :meth:`run`; :meth:`supports` says which models
    they can run. Constructed from an ``Options`` instance and/or keyword
    options: an unknown option raises ``TypeError`` naming it.

    Attributes
    ----------
    name : str
        Registry key used by ``solve(..., method=name)``.
    Options : type
        The options dataclass.
    options : dict
        The default of every option (derived from ``Options`` on registration).
    order : int or None
        Nominal order of convergence (None for exact methods).
    refine : str or None
        The option that controls accuracy (``"dt"`` or ``"tol"``), used by
        the registry-driven convergence test.
    negative_times : bool
        Whether the method accepts t < 0 (time reversal).
    threads : bool
        Whether :func:`~eulerpoisson.solve` may split a batch into chunks of
        bodies solved in threads (``workers=``, :mod:`.parallel`): the bodies
        must be independent and the compiled code must release the GIL.
    additive_stats : tuple of str
        The ``stats`` that count over the bodies (e.g. the total number of
        steps): added over the chunks of a batch solved in threads; every
        other number is the largest over the chunks (a per-body maximum or a
        value that every chunk shares), every other value the first chunk's.
    opts : MethodOptions
        The validated options of this instance.
    config : dict
        The same as a dict.

    Examples
    --------
    >>> from eulerpoisson.solvers import Method, get_method
    >>> rk = get_method("rk")
    >>> issubclass(rk, Method), rk.name, rk.order
    (True, 'rk', 8)
    >>> m = rk(tol=1e-12)                                           # options validated
    >>> m.config["tol"], m.config["integrator"]
    (1e-12, 'DOP853')
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[MethodOptions]] = MethodOptions
    options: ClassVar[dict[str, Any]] = {}
    order: ClassVar[int | None] = None
    refine: ClassVar[str | None] = None
    negative_times: ClassVar[bool] = True
    description: ClassVar[str] = ""
    threads: ClassVar[bool] = True
    additive_stats: ClassVar[tuple[str, ...]] = ("evaluations",)

    def __init__(self, options: MethodOptions | None = None, /, **kwargs: Any) -> None:
        if options is not None:
            if not isinstance(options, self.Options):
                raise TypeError(
                    f"method {self.name!r} takes options of type {self.Options.__name__}, got {type(options).__name__}"
                )
            opts = options.replace(**kwargs) if kwargs else options
        else:
            _check_names(self.Options, kwargs)
            opts = self.Options(**kwargs)
        self.opts = opts
        self.config = opts.to_dict()

    def nominal_order(self) -> int | None:
        """Nominal order of this configured instance (may depend on options such as ``scheme``)."""
        return self.order

    def run(self, problem: Problem) -> MethodResult:  # pragma: no cover - abstract
        raise NotImplementedError

    def run_one(self, body: RigidBody, q0: np.ndarray, omega0: np.ndarray, t: np.ndarray) -> MethodResult | None:
        """One free body, for the quick lane of :func:`~eulerpoisson.solve` (:mod:`.quick`): or None.

        ``body`` has batch shape ``()``; ``q0`` (4,), ``omega0`` (3,) and ``t``
        (T,) are checked float64 arrays (a unit quaternion, finite numbers,
        the method's time range). A method may return here what
        ``solve_batch(self.for_batch(problem), problem)`` returns for that
        problem, bit for bit and stats included (``"threads": 1``), without
        building the problem; None (the default) where it has no such
        shortcut: the quick lane then takes that general route. The lane
        calls it with the problem as the whole run (no
        :class:`~eulerpoisson.util.jit.whole_run` of its own: one body at
        ``T`` times is the run's size, and an enclosing one stays in force).
        """
        return None

    def for_batch(self, problem: Problem) -> Method:
        """This method with every choice that depends on the whole batch made on ``problem``.

        Before a batch is split into chunks solved in threads (:mod:`.parallel`),
        the driver calls this on the whole problem and runs the returned
        method on every chunk: whatever a method decides from the batch as a
        whole (a default step from the fastest body, a kernel chosen by the
        number of bodies) must be decided here, once, so that every body gets
        the same bits whatever the chunks (the compiled kernels or their
        NumPy twins, :meth:`numpy_estimate`, included). The default (no such
        choice): ``self``.
        """
        return self

    def work_estimate(self, problem: Problem) -> float:
        """Rough seconds that ``problem`` takes on one core (decides whether threads pay off).

        The default (the closed form's costs): half a microsecond per body
        and per (body, output time).
        """
        B = int(np.prod(problem.batch_shape, dtype=int))
        return 0.5e-6 * B * (1 + problem.t.shape[0])

    def numpy_estimate(self, problem: Problem) -> float:
        """Rough seconds that the NumPy twin of the method's compiled kernels takes on ``problem``.

        Below :data:`~eulerpoisson.util.jit.NUMPY_BELOW` (a small problem)
        a method with such a twin runs it, without importing numba
        (:func:`~eulerpoisson.util.jit.use_compiled`): numba and a kernel
        loaded from its cache cost about half a second in a fresh process.
        The choice is made for the whole batch (:meth:`for_batch`), so that
        the chunks solved in threads take the same path. The default
        (``inf``): no twin worth running, the compiled kernels whenever
        numba is in use.
        """
        return float("inf")

    @hybridmethod
    def supports(cls, model: Model) -> str | None:
        """Why this method cannot run ``model`` (a sentence), or None when it can.

        Asked of the class: whether some configuration of the method runs the
        model; asked of a configured instance (as :func:`~eulerpoisson.solve`
        does): whether this one does, with its options (e.g. a symplectic
        scheme for the free body only). The default: the free body only.
        Methods that handle torques override it (as a ``hybridmethod``
        when the answer depends on the options).
        """
        if model.is_free:
            return None
        return f"it solves the free body only (the model has {model.describe()})"


def register_method(cls: type[Method]) -> type[Method]:
    """Class decorator: register a :class:`Method` subclass under ``cls.name``.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from dataclasses import dataclass
    >>> from eulerpoisson.solvers import Method, MethodOptions, MethodResult, register_method
    >>> @dataclass(frozen=True)
    ... class StillOptions(MethodOptions):
    ...     method = "still"
    >>> @register_method
    ... class Still(Method):
    ...     # a body that does not move (an example)
    ...     name, Options = "still", StillOptions
    ...     def run(self, problem):
    ...         T = problem.t.shape[0]
    ...         q = np.broadcast_to(problem.q0[..., None, :], problem.q0.shape[:-1] + (T, 4))
    ...         return MethodResult(q=q.copy(), omega=np.zeros(q.shape[:-1] + (3,)))
    >>> "still" in ep.available_methods()
    True
    >>> print(ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.0, 0.0], method="still").omega)
    [[0. 0. 0.]
     [0. 0. 0.]]
    >>> from eulerpoisson.solvers import unregister_method
    >>> unregister_method("still").__name__                          # the registry as it was
    'Still'
    """
    if not cls.name:
        raise ValueError("a registered method needs a name")
    cls.options = cls.Options.defaults()
    _REGISTRY[cls.name] = cls
    return cls


def unregister_method(name: str) -> type[Method]:
    """Remove the method registered under ``name`` (a plug-in's, or one registered for a test) and return it.

    Raises
    ------
    InvalidInputError
        ``name`` is not a registered method.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.solvers import register_method, unregister_method
    >>> from eulerpoisson.solvers.exact import Exact
    >>> @register_method
    ... class Exact2(Exact):
    ...     name = "exact2"
    >>> "exact2" in ep.available_methods()
    True
    >>> unregister_method("exact2").__name__
    'Exact2'
    >>> "exact2" in ep.available_methods()
    False
    """
    cls = get_method(name)
    del _REGISTRY[name]
    return cls


def available_methods() -> list[str]:
    """Names accepted by ``solve(..., method=...)``.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> ep.available_methods()
    ['exact', 'rk', 'rk4', 'symplectic', 'taylor']
    """
    return sorted(_REGISTRY)


def methods_supporting(model: Model) -> list[str]:
    """Names of the registered methods that can run ``model``.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.solvers import methods_supporting
    >>> methods_supporting(ep.Model([1.0, 2.0, 2.5]))
    ['exact', 'rk', 'rk4', 'symplectic', 'taylor']
    >>> methods_supporting(ep.Model([1.0, 2.0, 2.5], lambda t, q, omega: -0.1 * omega))
    ['rk', 'rk4']
    """
    return sorted(name for name, cls in _REGISTRY.items() if cls.supports(model) is None)


def check_supported(name: str | Method, model: Model) -> None:
    """Raise :class:`~eulerpoisson.errors.UnsupportedModelError` when method ``name`` cannot run ``model``.

    ``name`` may be a configured method (an instance): then its options count (:meth:`Method.supports`).

    Raises
    ------
    UnsupportedModelError
        Naming the method, the reason and the methods that can run the model.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.solvers import check_supported
    >>> check_supported("taylor", ep.Model([1.0, 2.0, 2.5], ep.torques.BodyTorque([0.0, 0.0, 0.1])))   # fine: None
    >>> try:
    ...     check_supported("exact", ep.Model([1.0, 2.0, 2.5], ep.torques.BodyTorque([0.0, 0.0, 0.1])))
    ... except ep.UnsupportedModelError as err:
    ...     print(err)
    method 'exact' cannot run this model: the closed form covers the free body and the Lagrange top ...;
    methods that can: rk, rk4, symplectic, taylor
    """
    method = name if isinstance(name, Method) else get_method(name)
    reason = method.supports(model)
    if reason is None:
        return
    name = method.name
    able = methods_supporting(model)
    hint = f"methods that can: {', '.join(able)}" if able else "no registered method can"
    raise UnsupportedModelError(f"method {name!r} cannot run this model: {reason}; {hint}")


def get_method(name: str) -> type[Method]:
    """The method class registered as ``name``.

    Raises
    ------
    InvalidInputError
        Unknown method name (the message lists the available ones).

    Examples
    --------
    >>> from eulerpoisson.solvers import get_method
    >>> get_method("taylor").__name__, get_method("taylor").refine
    ('Taylor', 'dt')
    >>> try:
    ...     get_method("euler")
    ... except ValueError as err:
    ...     print(err)
    unknown method 'euler'; available methods: exact, rk, ...
    """
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InvalidInputError(f"unknown method {name!r}; available methods: {', '.join(sorted(_REGISTRY))}")
    return _REGISTRY[name]
