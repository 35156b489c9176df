r"""The initial value problem every solution method receives: :class:`Problem`.

:func:`make_problem` validates and broadcasts the arguments of
:func:`~eulerpoisson.solve` into one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..attitude.core import Attitude, as_quaternion
from ..errors import InvalidInputError
from ..model.body import RigidBody
from ..model.equations import Model, as_model
from ..numerics.quaternion import qmul
from ..util.validate import as_float_array

if TYPE_CHECKING:
    from ..attitude.core import AttitudeLike
    from ..model.torques import TorqueLike

__all__ = ["Problem", "make_problem", "initial_quaternion", "compose_initial", "left_composed"]


@dataclass(frozen=True)
class Problem:
    """A batch of initial value problems for the model's equations of motion.

    Attributes
    ----------
    model : Model
        The equations: bodies and torques, batch shape broadcastable to
        ``batch_shape``.
    q0 : ndarray, shape ``(*batch_shape, 4)``
        Initial attitudes (unit quaternions, scalar first).
    omega0 : ndarray, shape ``(*batch_shape, 3)``
        Initial body angular velocities, in the body frame of ``body.inertia``.
    t : ndarray, shape (T,)
        Output times, any order, negative allowed.
    extended : dict
        ``"omega0"``, ``"q0"``: the initial state as given in long double,
        broadcast like ``omega0``/``q0`` (only when it was given so), for
        methods that compute in extended precision.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.solvers import make_problem
    >>> p = make_problem([1.0, 2.0, 2.5], [0.0, 1.0, 2.0], omega0=[[1.0, 0.1, 0.5], [0.0, 1.0, 0.0]])
    >>> type(p).__name__, p.q0.shape, p.omega0.shape, p.t.shape
    ('Problem', (2, 4), (2, 3), (3,))
    >>> print(p.q0)
    [[1. 0. 0. 0.]
     [1. 0. 0. 0.]]
    """

    model: Model
    q0: np.ndarray
    omega0: np.ndarray
    t: np.ndarray
    extended: dict = field(default_factory=dict)

    @property
    def body(self) -> RigidBody:
        """The bodies (the free-body part of ``model``)."""
        return self.model.body

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.q0.shape[:-1]

    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensors broadcast to the batch, ``(*batch_shape, 3, 3)``."""
        return np.broadcast_to(self.body.inertia, self.batch_shape + (3, 3))

    @property
    def principal_moments(self) -> np.ndarray:
        return _read_only_to(self.body.principal_moments, self.batch_shape + (3,))

    @property
    def principal_axes(self) -> np.ndarray:
        return _read_only_to(self.body.principal_axes, self.batch_shape + (3, 3))

    @property
    def M0(self) -> np.ndarray:
        """Initial body angular momentum, ``(*batch_shape, 3)``."""
        return np.einsum("...ij,...j->...i", self.inertia, self.omega0)


def _read_only_to(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``np.broadcast_to(a, shape)`` (a read-only view); a plain read-only view where ``a`` has that shape already
    (what the methods of one body read, without broadcast_to's cost)."""
    if a.shape != shape:
        return np.broadcast_to(a, shape)
    view = a.view()
    view.flags.writeable = False
    return view


def _as_times(t) -> np.ndarray:
    ta = as_float_array(t, "t")
    if ta.ndim > 1:
        raise InvalidInputError(f"t must be a scalar or a 1-D array of output times, got shape {ta.shape}")
    return np.atleast_1d(ta)


def initial_quaternion(attitude0: AttitudeLike | None = None, gibbs0: ArrayLike | None = None) -> np.ndarray:
    """The initial attitude as unit quaternions (..., 4) from what :func:`solve` accepts.

    ``attitude0``: an :class:`~eulerpoisson.Attitude`, a scipy ``Rotation`` or
    unit quaternions (w, x, y, z) (norm 1 within
    :data:`~eulerpoisson.attitude.UNIT_QUATERNION_TOLERANCE`, renormalized);
    ``gibbs0``: Gibbs vectors n = k tan(alpha/2). At most one of them; none:
    the identity.

    Raises
    ------
    TypeError
        Both given, or an object that is not an attitude.
    InvalidInputError
        A quaternion that is not unit, NaN, wrong shapes.
    """
    from ..attitude.core import UNIT_QUATERNION_TOLERANCE, quaternion_from_gibbs, quaternion_from_scipy

    if attitude0 is not None and gibbs0 is not None:
        raise TypeError("give at most one of attitude0 and gibbs0 (the initial attitude), not both")
    if gibbs0 is not None:
        return np.asarray(quaternion_from_gibbs(as_float_array(gibbs0, "gibbs0", (3,))), dtype=float)
    if attitude0 is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    if isinstance(attitude0, Attitude):
        return attitude0.as_quaternion()
    if type(attitude0).__name__ == "Rotation" and hasattr(attitude0, "as_quat"):
        return quaternion_from_scipy(attitude0)
    q0 = as_float_array(attitude0, "attitude0", (4,))
    nrm = np.linalg.norm(q0, axis=-1)
    if np.any(np.abs(nrm - 1.0) > UNIT_QUATERNION_TOLERANCE):
        worst = float(nrm.ravel()[np.argmax(np.abs(nrm.ravel() - 1.0))])
        raise InvalidInputError(
            f"attitude0 must be a unit quaternion (w, x, y, z), norm 1 within {UNIT_QUATERNION_TOLERANCE:g}; "
            f"its norm is {worst:.9g}"
        )
    return as_quaternion(q0, "attitude0")


def make_problem(
    body: RigidBody | Model | ArrayLike,
    t: ArrayLike,
    *,
    omega0: ArrayLike | None = None,
    m0: ArrayLike | None = None,
    attitude0: AttitudeLike | None = None,
    gibbs0: ArrayLike | None = None,
    torque: TorqueLike = None,
) -> Problem:
    """Validate and broadcast the arguments of :func:`solve` into a :class:`Problem`.

    Raises
    ------
    TypeError, InvalidInputError
        See :func:`solve`.

    Examples
    --------
    >>> from eulerpoisson.solvers import make_problem
    >>> p = make_problem([1.0, 2.0, 2.5], [0.0, 5.0], m0=[0.0, 0.0, 2.5])   # from the spatial momentum
    >>> print(p.omega0, p.model.is_free)
    [0. 0. 1.] True
    """
    model = as_model(body, torque)
    body = model.body
    times = _as_times(t)
    if (omega0 is None) == (m0 is None):
        raise TypeError("give exactly one of omega0 (body angular velocity) or m0 (spatial angular momentum)")
    q0 = initial_quaternion(attitude0, gibbs0)
    name, v0 = ("omega0", omega0) if omega0 is not None else ("m0", m0)
    v0 = as_float_array(v0, name, (3,))
    try:
        shape = np.broadcast_shapes(q0.shape[:-1], v0.shape[:-1], model.batch_shape)
    except ValueError:
        raise InvalidInputError(
            f"the batch shapes do not broadcast: body {body.batch_shape} (inertia {body.inertia.shape}), "
            f"model {model.batch_shape}, "
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
    extended = {}
    if omega0 is not None and getattr(omega0, "dtype", None) == np.longdouble:
        extended["omega0"] = np.broadcast_to(omega0, shape + (3,)).copy()
    if getattr(attitude0, "dtype", None) == np.longdouble:
        qe = np.asarray(attitude0)
        qe = qe / np.sqrt(np.sum(qe * qe, axis=-1, keepdims=True))
        extended["q0"] = np.broadcast_to(qe, shape + (4,)).copy()
    return Problem(model=model, q0=q0, omega0=w0, t=times, extended=extended)


def compose_initial(problem: Problem, q_rel: np.ndarray) -> np.ndarray:
    r"""Attitudes :math:`q_0\otimes q_\mathrm{rel}(t)` for relative motions starting at the identity.

    ``q_rel`` has shape ``(*batch_shape, T, 4)``; left invariance of the free body
    makes this the motion from ``q0`` (a free-body shortcut: only valid when
    ``problem.model.is_free``, which is checked). When every ``q0`` is the identity,
    ``q_rel`` is returned as it is (the product would only copy it).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers import compose_initial, make_problem
    >>> q0 = [np.cos(0.25), np.sin(0.25), 0.0, 0.0]                 # 0.5 rad about x
    >>> p = make_problem([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.0, 0.0], attitude0=q0)
    >>> q_rel = np.array([[1.0, 0.0, 0.0, 0.0], [np.cos(0.25), np.sin(0.25), 0.0, 0.0]])
    >>> print(np.round(compose_initial(p, q_rel), 9))               # q0, then q0 q_rel: 1 rad about x
    [[0.96891242 0.24740396 0.         0.        ]
     [0.87758256 0.47942554 0.         0.        ]]
    """
    if not problem.model.is_free:
        raise ValueError("compose_initial is a free-body shortcut (left invariance); the model has torques")
    return left_composed(problem.q0, q_rel)


def left_composed(q0: np.ndarray, q_rel: np.ndarray) -> np.ndarray:
    r""":math:`q_0\otimes q_\mathrm{rel}(t)`: ``q0`` (*batch, 4), ``q_rel`` (*batch, T, 4); ``q_rel`` itself where
    every ``q0`` is the identity (:func:`compose_initial` without its problem).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.solvers.problem import left_composed
    >>> q_rel = np.array([[0.0, 1.0, 0.0, 0.0]])
    >>> left_composed(np.array([1.0, 0.0, 0.0, 0.0]), q_rel) is q_rel
    True
    >>> print(left_composed(np.array([0.0, 0.0, 1.0, 0.0]), q_rel))
    [[ 0.  0.  0. -1.]]
    """
    if q0.ndim == 1:  # one body (plain floats: cheaper than four array reductions)
        w, x, y, z = q0.tolist()
        if w == 1.0 and x == 0.0 and y == 0.0 and z == 0.0:
            return q_rel
    elif (q0[..., 0] == 1.0).all() and not q0[..., 1:].any():
        return q_rel
    return qmul(q0[..., None, :], q_rel)
