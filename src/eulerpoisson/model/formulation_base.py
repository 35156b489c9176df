r"""The base class :class:`Formulation` and the array helpers of the formulations (part of :mod:`.formulations`).

:class:`Formulation` holds what every coordinate description shares (the
body, the conservative torques and their potential, the layout of the
state, the integrals, the conversions through ``(q, Omega)``); the families
(:mod:`eulerpoisson.model.formulation_euler_poisson`,
:mod:`eulerpoisson.model.formulation_gibbs`) fill in the dynamics. The
batched array helpers below are shared with
:mod:`eulerpoisson.model.gibbs_lagrangian`. Everything public here is
re-exported by :mod:`eulerpoisson.model.formulations`.

Examples
--------
>>> import numpy as np
>>> transpose(np.arange(4.0).reshape(2, 2)).tolist()
[[0.0, 2.0], [1.0, 3.0]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import (
    conversion_matrix,
    gibbs_from_quaternion,
    matrix_from_quaternion,
)
from ..errors import InvalidInputError, UnsupportedModelError
from ..util.validate import as_float_array
from .body import RigidBody
from .formulation_registry import formulation
from .torques import Gravity, GravityGradient, Torque, TorqueLike, as_torques

__all__ = [
    "Formulation",
    "gibbs_potential_gradient",
    "GENERATORS",
    "component_first",
    "component_first_matrix",
    "stack_last",
    "transpose",
    "antisymmetric",
    "matvec",
    "as_body",
    "add_block",
]

# Levi-Civita symbol and the generators E_k = [e_k]x, E[k, a, b] = -eps_{kab}
_EPS3 = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _EPS3[_i, _j, _k] = 1.0
    _EPS3[_i, _k, _j] = -1.0
#: the generators E_k = [e_k]x of so(3): E[k, a, b] = -eps_{kab}, shape (3, 3, 3)
GENERATORS = -_EPS3


# ---------------------------------------------------------------------------
# array helpers
# ---------------------------------------------------------------------------
def component_first(x):
    """(..., 3) -> (3, ...) component-first view."""
    return np.moveaxis(x, -1, 0)


def component_first_matrix(M):
    """(..., 3, 3) -> (3, 3, ...) component-first view."""
    return np.moveaxis(M, (-2, -1), (0, 1))


def stack_last(comps):
    """Components (a sequence of arrays, broadcast) -> (..., k): the inverse of :func:`component_first`."""
    return np.stack(np.broadcast_arrays(*comps), axis=-1)


def transpose(M):
    """Transpose of the last two axes."""
    return np.swapaxes(M, -1, -2)


def antisymmetric(M):
    """Antisymmetric part of the last two axes."""
    # exact antisymmetry (the products are antisymmetric up to rounding)
    return 0.5 * (M - transpose(M))


def matvec(M, v):
    """Batched matrix-vector product ``M @ v`` (..., 3, 3) x (..., 3)."""
    return np.einsum("...ij,...j->...i", M, v)


def as_body(body) -> RigidBody:
    """The :class:`~eulerpoisson.model.body.RigidBody` of ``body`` (a body, a Formulation, a Model or an inertia)."""
    if isinstance(body, RigidBody):
        return body
    if isinstance(body, Formulation):
        return body.body
    from .equations import Model

    if isinstance(body, Model):
        return body.body
    return RigidBody(body)


#: what ``torque=`` of the formulations accepts (for the error messages)
_ACCEPTED = (
    "None (the free body), or conservative torques: eulerpoisson.torques.Gravity, "
    "eulerpoisson.torques.GravityGradient (or any Torque with conservative = True and a "
    "potential), or a list of them"
)


def _potential_torques(body, torque, where: str) -> tuple:
    """The conservative torques of ``torque=`` (and of a Model given as ``body``) as a tuple."""
    from .equations import Model

    if isinstance(body, Model):
        if torque is not None:
            raise TypeError(f"{where}: give the torque either in the Model or as torque=, not both")
        torque = list(body.torques) or None
    elif isinstance(body, Formulation) and torque is None:
        torque = list(body.torques) or None
    try:
        torques = as_torques(torque)
    except TypeError as exc:
        raise TypeError(f"{where}: torque must be {_ACCEPTED}; got {torque!r}") from exc
    for tq in torques:
        if not (isinstance(tq, Torque) and tq.conservative and not tq.depends_on_omega):
            raise UnsupportedModelError(
                f"{where}: torque {tq!r} derives from no potential U(t, R), and the formulations are "
                f"Hamiltonian (H = H0 + U); torque must be {_ACCEPTED}. For non-conservative torques use "
                f"eulerpoisson.solve(..., torque=..., method='rk' or 'taylor')"
            )
    return torques


def gibbs_potential_gradient(n: ArrayLike, tau: ArrayLike) -> NDArray[np.float64]:
    r"""Gradient :math:`\partial U/\partial\mathbf n` of a potential from its body-frame torque.

    A potential :math:`U(R)` whose torque is :math:`\boldsymbol\tau`
    (:math:`\delta U = -\boldsymbol\tau\cdot\delta\boldsymbol\theta` for
    :math:`\delta R = R[\delta\boldsymbol\theta]_\times`) has, in the Gibbs
    chart where :math:`\delta\boldsymbol\theta = 2A^T(\mathbf n)\delta\mathbf n`
    (eq. 1.11),

    .. math::
        \frac{\partial U}{\partial\mathbf n} = -2A(\mathbf n)\boldsymbol\tau
        = -\frac{2}{1+\mathbf n^2}\left(\boldsymbol\tau + \mathbf n\times\boldsymbol\tau\right).

    Parameters
    ----------
    n : array_like, shape (..., 3)
        Gibbs vectors.
    tau : array_like, shape (..., 3)
        Body-frame torques :math:`\boldsymbol\tau(R(\mathbf n))` (broadcast against ``n``).

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    InvalidInputError
        Wrong trailing shape or non-finite values.

    References
    ----------
    Paper eq. 1.9, 1.11, 1.12 (:math:`A`), 1.15-1.16 (the canonical equations
    it enters: :math:`\dot{\boldsymbol\pi} = -\partial H_0/\partial\mathbf n - \partial U/\partial\mathbf n`).
    """
    n = as_float_array(n, "n", (3,))
    tau = as_float_array(tau, "tau", (3,))
    return -2.0 * matvec(conversion_matrix(n), tau)


def add_block(out, sl, extra):
    """``out`` (..., d) with ``extra`` (..., k) added to ``out[..., sl]``, broadcasting both."""
    shape = np.broadcast_shapes(out.shape, extra.shape[:-1] + out.shape[-1:])
    out = np.broadcast_to(out, shape).copy()
    out[..., sl] += extra
    return out


# ---------------------------------------------------------------------------
# formulations
# ---------------------------------------------------------------------------
class Formulation:
    r"""One coordinate description of the free rigid body, with its invariants.

    Subclasses fix the class attributes below and implement the kernels'
    batched wrappers. States are arrays of shape ``(..., dimension)``; the
    body may itself be a batch (its batch shape broadcasts against the
    states').

    Parameters
    ----------
    body : RigidBody, Model or array_like
        The body, or its principal moments (3,) or inertia tensor (3, 3)
        (any symmetric positive-definite tensor obeying the triangle
        inequality), or a :class:`~eulerpoisson.Model` (its body and torques).
    torque : Torque or list of Torque, optional
        Conservative torques (:class:`~eulerpoisson.torques.Gravity`,
        :class:`~eulerpoisson.torques.GravityGradient`): the Hamiltonian
        becomes :math:`H_0 + U(t, R)` and the vector field gains the torque
        (see the module docstring); the Poisson tensor is unchanged. None:
        the free body. For a heavy top the inertia is about the fixed point.

    Raises
    ------
    UnsupportedModelError
        (a ``ValueError``) A torque that derives from no potential
        (``BodyTorque``, ``SpaceTorque``, a callable).
    TypeError
        A ``torque`` that is not a torque, or a Model together with ``torque``.
    InvalidInputError
        Torque parameters whose batch shape does not broadcast with the body's.

    Attributes
    ----------
    name : str
        Registry name.
    title : str
        Human-readable name.
    variables : tuple of str
        Name of each state component.
    layout : dict of str to slice
        Named blocks of the state (``unpack``/``pack``).
    block_shapes : dict of str to tuple
        Shape of each block (``(3,)`` or ``(3, 3)``).
    dimension : int
        ``d``, the length of the last state axis.
    rank : int
        Rank of the Poisson tensor (``d`` when nondegenerate).
    equations : dict of str to str
        Paper equation numbers of each ingredient.
    torques : tuple of Torque
        The conservative torques (empty for the free body).

    Notes
    -----
    The *common* representation used by the conversions is the pair
    ``(q, Omega)``: a unit quaternion (..., 4) (scalar first) and the body
    angular velocity (..., 3). Formulations in :math:`\mathbf n` raise
    :class:`~eulerpoisson.errors.SingularChartError` for rotations by
    :math:`\pi`, where :math:`\mathbf n` is infinite.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> f = ep.formulation("canonical", [1.0, 2.0, 2.5])              # (n, pi), paper eq. 1.14-1.16
    >>> type(f).__name__, f.name
    ('Canonical', 'canonical')
    >>> z = f.from_common([1.0, 0.0, 0.0, 0.0], [1.0, 0.1, 0.5])
    >>> print(np.round(z, 6))
    [0.  0.  0.  2.  0.4 2.5]
    >>> print(np.round(f.vector_field(z), 6))
    [ 0.5    0.05   0.25  -0.025  0.75  -0.1  ]
    """

    name: str = ""
    title: str = ""
    variables: tuple = ()
    layout: dict = {}
    block_shapes: dict = {}
    dimension: int = 0
    rank: int = 0
    equations: dict = {}

    def __init__(self, body: RigidBody | ArrayLike, torque: TorqueLike = None) -> None:
        self.torques = _potential_torques(body, torque, f"the {self.name!r} formulation")
        self.body = as_body(body)
        self._I = self.body.inertia
        self._Iinv = self.body.inertia_inv
        self._Icf = component_first_matrix(self._I)
        self._Iinvcf = component_first_matrix(self._Iinv)
        shapes = [self.body.batch_shape] + [tq.batch_shape for tq in self.torques]
        try:
            self._bshape = np.broadcast_shapes(*shapes)
        except ValueError:
            desc = ", ".join(f"{type(tq).__name__} {tq.batch_shape}" for tq in self.torques)
            raise InvalidInputError(
                f"the {self.name!r} formulation: the torques' batch shapes ({desc}) do not broadcast with "
                f"the body's {self.body.batch_shape}"
            ) from None

    @property
    def is_free(self) -> bool:
        """True for the free body (no torque)."""
        return not self.torques

    @property
    def time_dependent(self) -> bool:
        """True when the potential depends explicitly on the time (the gravity gradient)."""
        return any(tq.time_dependent for tq in self.torques)

    # -- the potential ------------------------------------------------------
    @staticmethod
    def _time(t: ArrayLike) -> np.ndarray:
        return as_float_array(t, "t")

    def _torque_at(self, t, R):
        """Body-frame torque of the potential at the attitudes R (..., 3, 3), (..., 3)."""
        tau = np.zeros(R.shape[:-2] + (3,))
        w = np.zeros(R.shape[:-2] + (3,))
        for tq in self.torques:
            tau = tau + np.asarray(tq.evaluate(t, R, w, self._I), dtype=float)
        return tau

    def _potential_at(self, t, R):
        """Potential :math:`U(t, R)` summed over the torques, (...)."""
        U = np.zeros(R.shape[:-2])
        for tq in self.torques:
            U = U + np.asarray(tq.potential(t, R, self._I), dtype=float)
        return U

    def potential(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        r"""Potential energy :math:`U(t, R)` of the torques, shape (...) (zero for the free body).

        Parameters
        ----------
        state : array_like, shape (..., d)
        t : float or array_like, shape (...)
            Time (only the gravity gradient depends on it).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        t = self._time(t)
        shape = np.broadcast_shapes(self._batch(x), t.shape)
        if not self.torques:
            return np.zeros(shape)
        return np.broadcast_to(self._potential_at(t, self.matrix(x)), shape).copy()

    def torque(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        r"""Body-frame torque :math:`\boldsymbol\tau(t, R)` of the potential, shape (..., 3).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values of ``state`` or ``t``.
        """
        x = self._check(state)
        t = self._time(t)
        shape = np.broadcast_shapes(self._batch(x), t.shape) + (3,)
        if not self.torques:
            return np.zeros(shape)
        return np.broadcast_to(self._torque_at(t, self.matrix(x)), shape).copy()

    def _with_potential(self, H0, x, t):
        if not self.torques:
            return H0
        t = self._time(t)
        U = self._potential_at(t, self.matrix(x))
        return np.asarray(H0 + U)

    def _gravity_direction(self):
        """Common unit direction of ``g`` when every torque is a Gravity with parallel ``g``; else None."""
        if not self.torques or not all(isinstance(tq, Gravity) for tq in self.torques):
            return None
        ghat = None
        for tq in self.torques:
            norm = np.sqrt(np.sum(tq.g * tq.g, -1))
            if np.any(norm == 0):
                return None
            d = tq.g / norm[..., None]
            if ghat is not None and not np.allclose(d, ghat, rtol=0.0, atol=1e-14):
                return None
            ghat = d
        return ghat

    # -- validation and layout ---------------------------------------------
    def _check(self, state, what="state"):
        return as_float_array(state, f"{what} of the {self.name!r} formulation", (self.dimension,))

    def _batch(self, x):
        return np.broadcast_shapes(x.shape[:-1], self._bshape)

    def unpack(self, state: ArrayLike) -> dict[str, NDArray[np.float64]]:
        """Named blocks of ``state`` (views), e.g. ``{'n': (..., 3), 'pi': (..., 3)}``.

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        x = self._check(state)
        return {k: x[..., sl].reshape(x.shape[:-1] + self.block_shapes[k]) for k, sl in self.layout.items()}

    def pack(self, **blocks: ArrayLike) -> NDArray[np.float64]:
        """Assemble a state (..., d) from named blocks (broadcast against each other).

        Raises
        ------
        InvalidInputError
            Missing or unknown block names, wrong block shapes, non-finite values.
        """
        names = set(self.layout)
        if set(blocks) != names:
            raise InvalidInputError(
                f"the {self.name!r} formulation needs the blocks {sorted(names)}, got {sorted(blocks)}"
            )
        arrs = [as_float_array(blocks[k], k, self.block_shapes[k]) for k in self.layout]
        flat = [a.reshape(a.shape[: a.ndim - len(self.block_shapes[k])] + (-1,)) for a, k in zip(arrs, self.layout)]
        shape = np.broadcast_shapes(*[f.shape[:-1] for f in flat])
        return np.concatenate([np.broadcast_to(f, shape + f.shape[-1:]) for f in flat], -1)

    # -- dynamics -------------------------------------------------------------
    def vector_field(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Right-hand side :math:`\\dot z = P(z)\\nabla H(z, t)`, shape (..., d).

        ``t`` (float or array broadcast against the batch) matters only for a
        time-dependent potential (the gravity gradient).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        raise NotImplementedError

    def rhs(self, t: float, y: ArrayLike) -> NDArray[np.float64]:
        """``vector_field(y, t)`` with scipy's ``fun(t, y)`` signature."""
        return self.vector_field(y, t)

    def hamiltonian(self, state: ArrayLike, t: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Hamiltonian in these variables, :math:`H_0 + U(t, R)` (the kinetic energy plus the potential), shape (...)."""
        raise NotImplementedError

    def poisson_tensor(self, state: ArrayLike) -> NDArray[np.float64]:
        """Poisson tensor :math:`P_{ab} = \\{z_a, z_b\\}`, shape (..., d, d)."""
        raise NotImplementedError

    def poisson_determinant(self, state: ArrayLike) -> NDArray[np.float64]:
        """Closed-form :math:`\\det P(z)`, shape (...) (0 for a degenerate structure)."""
        raise NotImplementedError

    def casimirs(self, state: ArrayLike) -> NDArray[np.float64]:
        """Casimir functions (..., k); ``k = 0`` for a nondegenerate structure."""
        x = self._check(state)
        return np.zeros(self._batch(x) + (0,))

    def integrals(self, state: ArrayLike, t: ArrayLike = 0.0) -> dict[str, NDArray[np.float64]]:
        r"""First integrals.

        Free body: ``H`` (...), ``m`` (..., 3), ``m2`` (...), ``m3`` (...).
        ``m`` is the spatial angular momentum :math:`R I\boldsymbol\Omega`,
        ``m2`` :math:`= \mathbf m^2`, ``m3`` its third component; ``H``,
        ``m2``, ``m3`` are in involution (paper eq. 1.19, 1.23).

        With a potential: ``H`` :math:`= H_0 + U(t, R)` (conserved when no
        torque depends on the time); for gravity along one direction
        :math:`\hat{\mathbf g}` also ``m_vertical`` :math:`= \mathbf m\cdot\hat{\mathbf g}`
        (the space torque :math:`(R\mathbf c)\times\mu\mathbf g` is
        horizontal); for one gravity gradient the Jacobi integral ``jacobi``
        :math:`= H - \nu m_3` (:math:`U` depends on :math:`t` only through a
        rotation by :math:`\nu t` about :math:`\mathbf e_3`, generated by :math:`m_3`).

        Parameters
        ----------
        state : array_like, shape (..., d)
        t : float or array_like, shape (...)
            Time (for a time-dependent potential).

        Raises
        ------
        InvalidInputError
            Wrong trailing shape or non-finite values.
        """
        x = self._check(state)
        m = self.spatial_momentum(x)
        H = self.hamiltonian(x, t)
        if not self.torques:
            return {"H": H, "m": m, "m2": np.sum(m * m, -1), "m3": m[..., 2]}
        out = {"H": H}
        ghat = self._gravity_direction()
        if ghat is not None:
            out["m_vertical"] = np.sum(m * ghat, -1)
        if len(self.torques) == 1 and isinstance(self.torques[0], GravityGradient):
            out["jacobi"] = H - self.torques[0].mean_motion * m[..., 2]
        return out

    # -- conversions --------------------------------------------------------
    def to_common(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(q, Omega)``: unit quaternions (..., 4) and body angular velocity (..., 3)."""
        raise NotImplementedError

    def from_common(self, q: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        """State (..., d) from unit quaternions (..., 4) and body angular velocities (..., 3)."""
        raise NotImplementedError

    def convert(self, state: ArrayLike, target: str | Formulation) -> NDArray[np.float64]:
        """The same physical states in another formulation (a name or a :class:`Formulation`).

        The target uses this formulation's body unless a Formulation is given.

        Raises
        ------
        InvalidInputError
            Unknown target name, bad state.
        SingularChartError
            A rotation by pi converted to a formulation in ``n``.
        """
        if not isinstance(target, Formulation):
            target = formulation(target, self.body)
        return target.from_common(*self.to_common(state))

    def quaternion(self, state: ArrayLike) -> NDArray[np.float64]:
        """Unit quaternion (scalar first) of the attitude, (..., 4)."""
        return self.to_common(state)[0]

    def matrix(self, state: ArrayLike) -> NDArray[np.float64]:
        """Rotation matrix R (x_space = R x_body), (..., 3, 3)."""
        return matrix_from_quaternion(self.quaternion(state))

    def gibbs(self, state: ArrayLike) -> NDArray[np.float64]:
        """The paper's Gibbs vector n, (..., 3). Raises SingularChartError at angle pi."""
        return gibbs_from_quaternion(self.quaternion(state))

    def omega(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular velocity :math:`\boldsymbol\Omega`, (..., 3)."""
        return self.to_common(state)[1]

    def body_momentum(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Body angular momentum :math:`\mathbf M = I\boldsymbol\Omega`, (..., 3)."""
        return matvec(self._I, self.omega(state))

    def spatial_momentum(self, state: ArrayLike) -> NDArray[np.float64]:
        r"""Spatial angular momentum :math:`\mathbf m = RI\boldsymbol\Omega`, (..., 3)."""
        return matvec(self.matrix(state), self.body_momentum(state))

    def __repr__(self) -> str:
        tq = f", torque={list(self.torques)!r}" if self.torques else ""
        return f"{type(self).__name__}(name={self.name!r}, dimension={self.dimension}, body={self.body!r}{tq})"
