r"""The ``solve`` driver and the registry of solution methods.

Every way of computing the motion — the closed form, the Lie (Taylor)
series, symplectic integrators, scipy's Runge-Kutta — is a small
:class:`Method` subclass registered under a name, so that one call,
:func:`solve`, runs any of them and one test can check all of them.

A method receives a :class:`Problem` (bodies, initial attitudes and body
angular velocities, output times, all batched) and returns the attitude
quaternions and body angular velocities at the output times; :func:`solve`
wraps them in a :class:`~eulerpoisson.trajectory.Trajectory`.

References
----------
Paper eq. 1.4-1.5 (the equations solved) and 1.23.1 (the general solution as
the exponential of the Hamiltonian vector field).
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ._validate import as_float_array
from .attitude import Attitude, _as_quaternion, _qmul
from .body import RigidBody
from .errors import InvalidInputError

__all__ = [
    "Problem",
    "Method",
    "MethodResult",
    "register_method",
    "available_methods",
    "get_method",
    "solve",
]

_REGISTRY: dict[str, type["Method"]] = {}


@dataclass(frozen=True)
class Problem:
    """A batch of free-rigid-body initial value problems.

    Attributes
    ----------
    body : RigidBody
        Bodies, batch shape broadcastable to ``batch_shape``.
    q0 : ndarray, shape (*batch_shape, 4)
        Initial attitudes (unit quaternions, scalar first).
    omega0 : ndarray, shape (*batch_shape, 3)
        Initial body angular velocities, in the body frame of ``body.inertia``.
    t : ndarray, shape (T,)
        Output times, any order, negative allowed.
    """

    body: RigidBody
    q0: np.ndarray
    omega0: np.ndarray
    t: np.ndarray

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.q0.shape[:-1]

    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensors broadcast to the batch, (*batch_shape, 3, 3)."""
        return np.broadcast_to(self.body.inertia, self.batch_shape + (3, 3))

    @property
    def principal_moments(self) -> np.ndarray:
        return np.broadcast_to(self.body.principal_moments, self.batch_shape + (3,))

    @property
    def principal_axes(self) -> np.ndarray:
        return np.broadcast_to(self.body.principal_axes, self.batch_shape + (3, 3))

    @property
    def M0(self) -> np.ndarray:
        """Initial body angular momentum, (*batch_shape, 3)."""
        return np.einsum("...ij,...j->...i", self.inertia, self.omega0)


@dataclass
class MethodResult:
    """What a method returns: states at the output times.

    Attributes
    ----------
    q : ndarray, shape (*batch_shape, T, 4)
    omega : ndarray, shape (*batch_shape, T, 3)
    stats : dict
        Method-specific counters (steps, function evaluations, chart changes...).
    """

    q: np.ndarray
    omega: np.ndarray
    stats: dict = field(default_factory=dict)


class Method:
    """Base class of a solution method.

    Subclasses set :attr:`name`, :attr:`options` (allowed keyword options with
    their defaults) and implement :meth:`run`. Options are validated on
    construction: an unknown option raises ``TypeError`` naming it.

    Class attributes
    ----------------
    name : str
        Registry key used by ``solve(..., method=name)``.
    options : dict
        Allowed options and defaults.
    order : int or None
        Nominal order of convergence (None for exact methods).
    refine : str or None
        The option that controls accuracy (``"dt"`` or ``"tol"``), used by
        the registry-driven convergence test.
    negative_times : bool
        Whether the method accepts t < 0 (time reversal).
    """

    name: ClassVar[str] = ""
    options: ClassVar[dict[str, Any]] = {}
    order: ClassVar[int | None] = None
    refine: ClassVar[str | None] = None
    negative_times: ClassVar[bool] = True
    description: ClassVar[str] = ""

    def __init__(self, **options):
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            allowed = ", ".join(sorted(self.options)) or "none"
            raise TypeError(
                f"method {self.name!r} got unknown option(s) {', '.join(unknown)}; allowed: {allowed}"
            )
        self.config = {**self.options, **options}
        self.validate()

    def validate(self) -> None:
        """Check ``self.config``; override to validate option values."""

    def nominal_order(self) -> int | None:
        """Nominal order of this configured instance (may depend on options such as ``scheme``)."""
        return self.order

    def run(self, problem: Problem) -> MethodResult:  # pragma: no cover - abstract
        raise NotImplementedError


def register_method(cls: type[Method]) -> type[Method]:
    """Class decorator: register a :class:`Method` subclass under ``cls.name``."""
    if not cls.name:
        raise ValueError("a registered method needs a name")
    _REGISTRY[cls.name] = cls
    return cls


def _load_builtin_methods() -> None:
    # importing the modules registers their methods
    from . import exact  # noqa: F401

    for mod in ("integrators",):
        try:
            __import__(f"{__package__}.{mod}")
        except ModuleNotFoundError as exc:  # integrators may be absent in a partial install
            if exc.name != f"{__package__}.{mod}":
                raise


def available_methods() -> list[str]:
    """Names accepted by ``solve(..., method=...)``."""
    _load_builtin_methods()
    return sorted(_REGISTRY)


def get_method(name: str) -> type[Method]:
    """The method class registered as ``name``.

    Raises
    ------
    InvalidInputError
        Unknown method name (the message lists the available ones).
    """
    _load_builtin_methods()
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InvalidInputError(
            f"unknown method {name!r}; available methods: {', '.join(sorted(_REGISTRY))}"
        )
    return _REGISTRY[name]


def _as_body(body) -> RigidBody:
    if isinstance(body, RigidBody):
        return body
    if isinstance(body, (str, bytes)) or body is None:
        raise TypeError(f"body must be a RigidBody or an inertia array, got {body!r}")
    return RigidBody(body)


def _as_times(t) -> np.ndarray:
    ta = as_float_array(t, "t")
    if ta.ndim > 1:
        raise InvalidInputError(f"t must be a scalar or a 1-D array of output times, got shape {ta.shape}")
    return np.atleast_1d(ta)


def make_problem(body, t, *, omega0=None, m0=None, attitude0=None) -> Problem:
    """Validate and broadcast the arguments of :func:`solve` into a :class:`Problem`.

    Raises
    ------
    TypeError, InvalidInputError
        See :func:`solve`.
    """
    body = _as_body(body)
    times = _as_times(t)
    if (omega0 is None) == (m0 is None):
        raise TypeError("give exactly one of omega0 (body angular velocity) or m0 (spatial angular momentum)")
    if attitude0 is None:
        q0 = np.array([1.0, 0.0, 0.0, 0.0])
    elif isinstance(attitude0, Attitude):
        q0 = attitude0.as_quaternion()
    else:
        q0 = as_float_array(attitude0, "attitude0", (4,))
        nrm = np.linalg.norm(q0, axis=-1)
        if np.any(np.abs(nrm - 1.0) > 1e-8):
            raise InvalidInputError(
                f"attitude0 must be a unit quaternion (w, x, y, z); its norm is {float(nrm.ravel()[np.argmax(np.abs(nrm.ravel() - 1.0))]):.9g}"
            )
        q0 = _as_quaternion(q0, "attitude0")
    name, v0 = ("omega0", omega0) if omega0 is not None else ("m0", m0)
    v0 = as_float_array(v0, name, (3,))
    try:
        shape = np.broadcast_shapes(q0.shape[:-1], v0.shape[:-1], body.batch_shape)
    except ValueError:
        raise InvalidInputError(
            f"the batch shapes do not broadcast: body {body.batch_shape} (inertia {body.inertia.shape}), "
            f"{name} {v0.shape[:-1]} (array {v0.shape}), attitude0 {q0.shape[:-1]} (array {q0.shape}); "
            f"leading axes must broadcast as in numpy"
        ) from None
    if omega0 is not None:
        w0 = v0
    else:
        R0 = Attitude(q0).as_matrix()
        M = np.einsum("...ji,...j->...i", R0, v0)
        w0 = np.einsum("...ij,...j->...i", body.inertia_inv, M)
    q0 = np.broadcast_to(q0, shape + (4,)).copy()
    w0 = np.broadcast_to(w0, shape + (3,)).copy()
    return Problem(body=body, q0=q0, omega0=w0, t=times)


def solve(body, t, *, omega0=None, m0=None, attitude0=None, method: str = "exact", **options):
    r"""Motion of free rigid bodies at the output times ``t``.

    Parameters
    ----------
    body : RigidBody or array_like
        The body (or a batch of bodies); an array is passed to :class:`RigidBody`.
    t : float or array_like, shape (T,)
        Output times, any order; negative times run the motion backwards
        from the initial state at ``t = 0``.
    omega0 : array_like, shape (..., 3), optional
        Initial body angular velocity :math:`\boldsymbol\Omega(0)` in the
        body frame.
    m0 : array_like, shape (..., 3), optional
        Initial spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`.
        Exactly one of ``omega0`` and ``m0``.
    attitude0 : Attitude or array_like, shape (..., 4), optional
        Initial attitude (unit quaternion); the identity by default, as for
        the paper's trajectories through the unit of SO(3) (eq. 1.2).
    method : str
        A name from :func:`available_methods`: ``"exact"`` (closed form,
        default) and the integrators.
    **options
        Method options (e.g. ``tol`` or ``dt``); unknown ones raise TypeError.

    Returns
    -------
    Trajectory
        Times, attitudes, angular velocities and integrals.

    Raises
    ------
    TypeError
        Neither or both of ``omega0``/``m0``; an unknown option.
    InvalidInputError
        Unknown method, bad shapes, NaN/inf, a non-unit quaternion.
    InvalidInertiaError
        A non-physical inertia tensor.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 10.0], omega0=[1.0, 0.1, 0.5])
    >>> tr.omega.shape
    (3, 3)
    """
    from .trajectory import Trajectory

    cls = get_method(method)
    m = cls(**options)
    problem = make_problem(body, t, omega0=omega0, m0=m0, attitude0=attitude0)
    if not cls.negative_times and np.any(problem.t < 0):
        raise InvalidInputError(f"method {method!r} cannot run backwards in time; got negative times in t")
    start = _time.perf_counter()
    res = m.run(problem)
    wall = _time.perf_counter() - start
    stats = {"wall_time": wall, **res.stats}
    return Trajectory(
        t=problem.t,
        quaternion=res.q,
        omega=res.omega,
        body=problem.body,
        method=method,
        options=dict(m.config),
        stats=stats,
    )


def compose_initial(problem: Problem, q_rel: np.ndarray) -> np.ndarray:
    r"""Attitudes :math:`q_0\otimes q_\mathrm{rel}(t)` for relative motions starting at the identity.

    ``q_rel`` has shape (*batch_shape, T, 4); left invariance of the free body
    makes this the motion from ``q0``. When every ``q0`` is the identity,
    ``q_rel`` is returned as it is (the product would only copy it).
    """
    q0 = problem.q0
    if np.all(q0[..., 0] == 1.0) and not np.any(q0[..., 1:]):
        return q_rel
    return _qmul(q0[..., None, :], q_rel)
