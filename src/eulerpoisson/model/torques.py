r"""Torques on a rigid body: the right-hand side of the Euler–Poisson equations beyond the free body.

A torque enters Euler's equations in the body frame,

.. math:: I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega + \boldsymbol\tau,
          \qquad \dot R = R[\boldsymbol\Omega]_\times ,

with :math:`\boldsymbol\tau` a function of the time, the attitude
:math:`R` (:math:`x_\text{space} = Rx_\text{body}`) and the body angular
velocity. Each class here is *data* (its parameters, batched like bodies) with
what the methods need beside it:

- :meth:`Torque.evaluate`: :math:`\boldsymbol\tau(t, R, \boldsymbol\Omega)`
  for the generic integrators (``rk``);
- :meth:`Torque.potential`: :math:`U(t, R)` with
  :math:`\boldsymbol\tau = -\,\partial U` (the body-frame gradient, see
  :class:`Gravity`) for the conservative torques, used by the energy, the
  splitting integrators and the canonical formulation;
- :meth:`Torque.polynomial`: the torque as a polynomial in auxiliary
  body-frame vectors :math:`\mathbf v = R^T\mathbf s(t)` of space-fixed (or
  uniformly rotating) vectors, which obey :math:`\dot{\mathbf v} =
  \mathbf v\times\boldsymbol\Omega` (the Poisson equation that gives the
  Euler–Poisson system its name): this is what the Taylor integrator
  differentiates to any order;
- :meth:`Torque.to_dict` / :func:`torque_from_dict`: a JSON-able record for
  files and the command line.

A new torque is one new class in this module (or a user's module): subclass
:class:`Torque`, implement :meth:`~Torque.evaluate`, and optionally
:meth:`~Torque.potential` and :meth:`~Torque.polynomial`; the methods that
need more refuse it with a clear error naming the methods that can run it.

References
----------
E. Leimanis, *The General Problem of the Motion of Coupled Rigid Bodies about
a Fixed Point*, Springer (1965), ch. I (the Euler–Poisson equations).
P. C. Hughes, *Spacecraft Attitude Dynamics*, Wiley (1986), §8.3 (gravity
gradient). A. V. Borisov and I. S. Mamaev, *Rigid Body Dynamics*, De Gruyter
(2018), §2.1.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..util.validate import as_float_array

__all__ = [
    "Torque",
    "Gravity",
    "GravityGradient",
    "BodyTorque",
    "SpaceTorque",
    "CallableTorque",
    "UnrecordedTorque",
    "PolynomialTorque",
    "FlatPolynomialTorque",
    "as_torques",
    "torque_from_dict",
    "STANDARD_GRAVITY",
]

#: standard gravity (m s-2), the default magnitude of :class:`Gravity`
STANDARD_GRAVITY = 9.81


def _bT(R, v):
    r""":math:`R^T\mathbf v`, batched: R (..., 3, 3), v (..., 3)."""
    return np.einsum("...ji,...j->...i", R, v)


@dataclass(frozen=True)
class PolynomialTorque:
    r"""A torque written as a polynomial in body-frame images of space vectors.

    With :math:`\mathbf v_i = R^T\mathbf s_i` for space-fixed vectors
    :math:`\mathbf s_i` and, for an orbit, :math:`\mathbf r = R^T\hat{\mathbf r}(t)`
    with :math:`\hat{\mathbf r}(t) = (\cos\nu t, \sin\nu t, 0)`,

    .. math:: \boldsymbol\tau = \boldsymbol\tau_0 + \sum_i L_i\mathbf v_i
              + \kappa\,\mathbf r\times(I\mathbf r).

    The auxiliary vectors obey :math:`\dot{\mathbf v}_i = \mathbf v_i\times
    \boldsymbol\Omega` and :math:`\dot{\mathbf r} = \mathbf r\times\boldsymbol\Omega
    + \nu\,\mathbf z\times\mathbf r` with :math:`\mathbf z = R^T\hat{\mathbf e}_z`,
    all polynomial: Taylor coefficients of any order follow by Cauchy
    products.

    Attributes
    ----------
    constant : ndarray, shape (..., 3)
        :math:`\boldsymbol\tau_0` (body frame).
    vectors : tuple of ndarray, each (..., 3)
        Space vectors :math:`\mathbf s_i`.
    maps : tuple of ndarray, each (..., 3, 3)
        :math:`L_i`.
    orbit_rate : ndarray, shape (...)
        :math:`\nu` (0: no orbit term).
    orbit_gain : ndarray, shape (...)
        :math:`\kappa` (:math:`3\nu^2` for the gravity gradient).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> p = ep.torques.Gravity(1.0, [0.0, 0.0, 0.1]).polynomial()   # tau = L (R^T s) for the gravity
    >>> type(p).__name__, len(p.vectors)
    ('PolynomialTorque', 1)
    >>> print(p.vectors[0])
    [ 0.    0.   -9.81]
    >>> print(np.round(p.maps[0], 6) + 0.0)
    [[ 0.  -0.1  0. ]
     [ 0.1  0.   0. ]
     [ 0.   0.   0. ]]
    """

    constant: np.ndarray
    vectors: tuple = ()
    maps: tuple = ()
    orbit_rate: np.ndarray = field(default_factory=lambda: np.zeros(()))
    orbit_gain: np.ndarray = field(default_factory=lambda: np.zeros(()))

    @staticmethod
    def zero() -> PolynomialTorque:
        return PolynomialTorque(constant=np.zeros(3))

    def __add__(self, other: PolynomialTorque) -> PolynomialTorque:
        og = np.broadcast_arrays(self.orbit_gain, other.orbit_gain)
        orate = np.broadcast_arrays(self.orbit_rate, other.orbit_rate)
        # one orbit per model: the rates of two orbit terms must agree where both act
        both = (og[0] != 0) & (og[1] != 0)
        if np.any(both & (orate[0] != orate[1])):
            raise InvalidInputError("two gravity-gradient torques with different mean motions cannot be combined")
        rate = np.where(og[0] != 0, orate[0], orate[1])
        return PolynomialTorque(
            constant=self.constant + other.constant,
            vectors=self.vectors + other.vectors,
            maps=self.maps + other.maps,
            orbit_rate=rate,
            orbit_gain=og[0] + og[1],
        )

    @property
    def has_orbit(self) -> bool:
        return bool(np.any(self.orbit_gain != 0))

    def flatten(self, batch_shape: tuple[int, ...]) -> FlatPolynomialTorque:
        """The torque broadcast to ``batch_shape`` as flat per-body arrays (what the compiled kernels read)."""
        B = int(np.prod(batch_shape, dtype=int))
        tau0 = np.ascontiguousarray(np.broadcast_to(self.constant, batch_shape + (3,)).reshape(B, 3), dtype=float)
        nv = len(self.vectors)
        S = np.zeros((B, nv, 3))
        L = np.zeros((B, nv, 3, 3))
        for i, (s, Lm) in enumerate(zip(self.vectors, self.maps)):
            S[:, i] = np.broadcast_to(s, batch_shape + (3,)).reshape(B, 3)
            L[:, i] = np.broadcast_to(Lm, batch_shape + (3, 3)).reshape(B, 3, 3)
        nu = np.ascontiguousarray(np.broadcast_to(self.orbit_rate, batch_shape).reshape(B), dtype=float)
        kappa = np.ascontiguousarray(np.broadcast_to(self.orbit_gain, batch_shape).reshape(B), dtype=float)
        return FlatPolynomialTorque(tau0, S, L, nu, kappa)


@dataclass(frozen=True)
class FlatPolynomialTorque:
    """A :class:`PolynomialTorque` as flat per-body arrays: ``tau0`` (B, 3), ``S`` (B, nv, 3),
    ``L`` (B, nv, 3, 3), ``nu`` and ``kappa`` (B,)."""

    tau0: np.ndarray
    S: np.ndarray
    L: np.ndarray
    nu: np.ndarray
    kappa: np.ndarray

    def in_frame(self, P: NDArray[np.float64]) -> FlatPolynomialTorque:
        r"""The torque in a rotated body frame, :math:`\mathbf x' = P^T\mathbf x` (``P`` (B, 3, 3)).

        The body-frame parts turn (:math:`\boldsymbol\tau_0' = P^T\boldsymbol\tau_0`,
        :math:`L' = P^TLP`); the space vectors and the orbit do not (the orbit
        term takes the inertia of the new frame).
        """
        tau0 = np.ascontiguousarray(np.einsum("bji,bj->bi", P, self.tau0))
        L = np.ascontiguousarray(np.einsum("bji,bvjk,bkl->bvil", P, self.L, P))
        return FlatPolynomialTorque(tau0, self.S, L, self.nu, self.kappa)


class Torque:
    """Base class of torques; see the module docstring.

    Attributes
    ----------
    kind : str
        Name used in files and the command line.
    conservative : bool
        The torque derives from a potential :math:`U(t, R)` (:meth:`potential`).
    time_dependent : bool
        The torque depends explicitly on time.
    depends_on_omega : bool
        The torque depends on the angular velocity (not a potential torque).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> class Drag(ep.torques.Torque):
    ...     # tau = -c Omega: a damping (an example)
    ...     kind, depends_on_omega = "drag", True
    ...     def __init__(self, c):
    ...         self.c = float(c)
    ...     def evaluate(self, t, R, omega, inertia):
    ...         return -self.c * omega
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 10.0], omega0=[0.0, 0.0, 1.0], torque=Drag(0.25), method="rk", tol=1e-10)
    >>> print(np.round(tr.omega[-1], 6) + 0.0)                       # 2.5 Omega' = -0.25 Omega: exp(-1)
    [0.       0.       0.367879]
    """

    kind: ClassVar[str] = ""
    conservative: ClassVar[bool] = False
    time_dependent: ClassVar[bool] = False
    depends_on_omega: ClassVar[bool] = False

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Batch shape of the parameters (``()`` for one set)."""
        return ()

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        r"""Body-frame torque :math:`\boldsymbol\tau`.

        Parameters
        ----------
        t : ndarray, shape (...)
            Times (broadcast against the batch).
        R : ndarray, shape (..., 3, 3)
            Attitudes, :math:`x_\text{space} = Rx_\text{body}`.
        omega : ndarray, shape (..., 3)
            Body angular velocities.
        inertia : ndarray, shape (..., 3, 3)
            Inertia tensors (body frame, about the body origin).

        Returns
        -------
        ndarray, shape (..., 3)
        """
        raise NotImplementedError

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        r"""Potential energy :math:`U(t, R)`, shape (...).

        Raises
        ------
        NotImplementedError
            For torques that derive from no potential.
        """
        raise NotImplementedError(f"{type(self).__name__} derives from no potential")

    def polynomial(self) -> PolynomialTorque | None:
        """The torque as a :class:`PolynomialTorque`, or None when it is not polynomial."""
        return None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able record (``{"kind": ..., parameters...}``) read back by :func:`torque_from_dict`."""
        raise NotImplementedError(f"{type(self).__name__} cannot be written to a file")

    def __getitem__(self, idx: Any) -> Torque:
        """The torque of one body (or a sub-batch) of a batch of parameters."""
        return self


def _vec(x, name, kind):
    try:
        return as_float_array(x, f"{kind}: {name}", (3,))
    except TypeError as exc:
        raise TypeError(str(exc)) from None


def _scalar_array(x, name, kind, *, positive=False, nonnegative=False):
    try:
        a = as_float_array(x, f"{kind}: {name}")
    except TypeError as exc:
        raise TypeError(str(exc)) from None
    if positive and np.any(a <= 0):
        raise InvalidInputError(f"{kind}: {name} must be > 0, got {a.tolist() if a.size < 7 else a.shape}")
    if nonnegative and np.any(a < 0):
        raise InvalidInputError(f"{kind}: {name} must be >= 0, got {a.tolist() if a.size < 7 else a.shape}")
    return a


def _shape(kind, **arrays):
    try:
        return np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        desc = ", ".join(f"{k} {a.shape}" for k, a in arrays.items())
        raise InvalidInputError(f"{kind}: the parameters' batch shapes do not broadcast: {desc}") from None


def _plain(a):
    a = np.asarray(a)
    return a.item() if a.ndim == 0 else a.tolist()


class Gravity(Torque):
    r"""A heavy top: uniform gravity on a body with a fixed point at the body origin.

    .. math:: \boldsymbol\tau = \mathbf c\times(\mu R^T\mathbf g), \qquad
              U = -\mu\,\mathbf g\cdot(R\mathbf c),

    with :math:`\mu` the mass, :math:`\mathbf c` the centre of mass in the
    body frame and :math:`\mathbf g` the gravitational acceleration in the
    space frame. The inertia tensor of the body is taken about the fixed
    point (the body origin), not about the centre of mass. With
    :math:`\boldsymbol\gamma = R^T\mathbf g` (the Poisson vector,
    :math:`\dot{\boldsymbol\gamma} = \boldsymbol\gamma\times\boldsymbol\Omega`)
    these are the Euler–Poisson equations.

    Parameters
    ----------
    mass : float or array_like, shape (...)
        > 0.
    center_of_mass : array_like, shape (..., 3)
        Body frame, relative to the fixed point.
    g : array_like, shape (..., 3)
        Space frame; default (0, 0, -9.81).

    Raises
    ------
    InvalidInputError
        Non-positive mass, NaN, wrong shapes, batch shapes that do not broadcast.
    TypeError
        Non-numeric parameters.

    References
    ----------
    Leimanis (1965), ch. I; Borisov and Mamaev (2018), §2.1.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])   # g = (0, 0, -9.81)
    >>> top
    Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81])
    >>> R = ep.Attitude.from_rotvec([np.pi / 2, 0.0, 0.0]).as_matrix()       # the axis horizontal
    >>> print(np.round(top.evaluate(0.0, R, np.zeros(3), np.eye(3)), 12) + 0.0)   # body frame
    [0.981 0.    0.   ]
    >>> print(np.round(top.potential(0.0, np.eye(3), np.eye(3)), 12))        # U = -m g.(R c)
    0.981
    """

    kind = "gravity"
    conservative = True

    def __init__(
        self, mass: ArrayLike, center_of_mass: ArrayLike, g: ArrayLike = (0.0, 0.0, -STANDARD_GRAVITY)
    ) -> None:
        self.mass = _scalar_array(mass, "mass", "Gravity", positive=True)
        self.center_of_mass = _vec(center_of_mass, "center_of_mass", "Gravity")
        self.g = _vec(g, "g", "Gravity")
        self._shape = _shape("Gravity", mass=self.mass, center_of_mass=self.center_of_mass[..., 0], g=self.g[..., 0])

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self._shape

    @property
    def moment_arm(self) -> np.ndarray:
        r""":math:`\mu\mathbf c`, shape (..., 3)."""
        return self.mass[..., None] * self.center_of_mass

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.cross(self.moment_arm, _bT(R, self.g))

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        return -np.einsum("...i,...i->...", self.g, np.einsum("...ij,...j->...i", R, self.moment_arm))

    def polynomial(self) -> PolynomialTorque:
        mc = self.moment_arm
        L = np.zeros(mc.shape[:-1] + (3, 3))
        L[..., 0, 1], L[..., 0, 2] = -mc[..., 2], mc[..., 1]
        L[..., 1, 0], L[..., 1, 2] = mc[..., 2], -mc[..., 0]
        L[..., 2, 0], L[..., 2, 1] = -mc[..., 1], mc[..., 0]
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.g,), maps=(L,))

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "mass": _plain(self.mass),
            "center_of_mass": _plain(self.center_of_mass),
            "g": _plain(self.g),
        }

    def __getitem__(self, idx: Any) -> Gravity:
        b = self._shape
        return Gravity(
            np.broadcast_to(self.mass, b)[idx],
            np.broadcast_to(self.center_of_mass, b + (3,))[idx],
            np.broadcast_to(self.g, b + (3,))[idx],
        )

    def __repr__(self) -> str:
        return (
            f"Gravity(mass={_plain(self.mass)!r}, center_of_mass={_plain(self.center_of_mass)!r}, g={_plain(self.g)!r})"
        )


class GravityGradient(Torque):
    r"""Gravity-gradient torque on a body in a circular orbit.

    The orbit lies in the space frame's :math:`x`–:math:`y` plane; the unit
    vector from the planet to the body is :math:`\hat{\mathbf r}(t) =
    (\cos\nu t, \sin\nu t, 0)` with the mean motion :math:`\nu`. To second
    order in the body's size,

    .. math:: \boldsymbol\tau = 3\nu^2\,\mathbf r\times(I\mathbf r), \qquad
              U = \tfrac32\nu^2\,\mathbf r\cdot I\mathbf r, \qquad
              \mathbf r = R^T\hat{\mathbf r}(t),

    with :math:`I` the inertia about the centre of mass (the body origin).
    The potential depends on time through :math:`\hat{\mathbf r}(t)`, so the
    energy is not conserved; in the frame rotating with the orbit the
    Jacobi integral is (:meth:`~eulerpoisson.Model.integrals`).

    Parameters
    ----------
    mean_motion : float or array_like, shape (...)
        :math:`\nu` (rad per time unit), >= 0.

    References
    ----------
    P. C. Hughes, *Spacecraft Attitude Dynamics* (1986), §8.3; V. V. Beletsky,
    *Motion of an Artificial Satellite about its Center of Mass* (1966), ch. 1.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> gg = ep.torques.GravityGradient(mean_motion=0.1)
    >>> print(gg.direction(0.0), gg.conservative, gg.time_dependent)
    [1. 0. 0.] True True
    >>> R = ep.Attitude.from_rotvec([0.0, 0.0, 0.3]).as_matrix()
    >>> print(np.round(gg.evaluate(0.0, R, np.zeros(3), np.diag([1.0, 2.0, 2.5])), 9) + 0.0)
    [ 0.          0.         -0.00846964]
    """

    kind = "gravity_gradient"
    conservative = True
    time_dependent = True

    def __init__(self, mean_motion: ArrayLike) -> None:
        self.mean_motion = _scalar_array(mean_motion, "mean_motion", "GravityGradient", nonnegative=True)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.mean_motion.shape

    def direction(self, t: ArrayLike) -> NDArray[np.float64]:
        r""":math:`\hat{\mathbf r}(t)` in the space frame, shape (..., 3)."""
        phase = np.asarray(t, dtype=float) * self.mean_motion
        return np.stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)], -1)

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        r = _bT(R, self.direction(t))
        Ir = np.einsum("...ij,...j->...i", inertia, r)
        return 3.0 * (self.mean_motion**2)[..., None] * np.cross(r, Ir)

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        r = _bT(R, self.direction(t))
        Ir = np.einsum("...ij,...j->...i", inertia, r)
        return 1.5 * self.mean_motion**2 * np.einsum("...i,...i->...", r, Ir)

    def polynomial(self) -> PolynomialTorque:
        return PolynomialTorque(constant=np.zeros(3), orbit_rate=self.mean_motion, orbit_gain=3.0 * self.mean_motion**2)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "mean_motion": _plain(self.mean_motion)}

    def __getitem__(self, idx: Any) -> GravityGradient:
        return GravityGradient(np.broadcast_to(self.mean_motion, self.batch_shape)[idx])

    def __repr__(self) -> str:
        return f"GravityGradient(mean_motion={_plain(self.mean_motion)!r})"


class BodyTorque(Torque):
    r"""A torque constant in the body frame (a thruster fixed to the body).

    Parameters
    ----------
    tau : array_like, shape (..., 3)
        Body frame.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> kick = ep.torques.BodyTorque([0.0, 0.0, 0.5])
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 2.0], omega0=[0.0, 0.0, 0.0], torque=kick, method="taylor")
    >>> print(np.round(tr.omega[-1], 12) + 0.0)                      # about a principal axis: 2.5 Omega' = 0.5
    [0.  0.  0.4]
    """

    kind = "body_torque"

    def __init__(self, tau: ArrayLike) -> None:
        self.tau = _vec(tau, "tau", "BodyTorque")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.tau.shape[:-1]

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.broadcast_to(self.tau, np.broadcast_shapes(self.tau.shape, np.shape(omega))).copy()

    def polynomial(self) -> PolynomialTorque:
        return PolynomialTorque(constant=self.tau)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "tau": _plain(self.tau)}

    def __getitem__(self, idx: Any) -> BodyTorque:
        return BodyTorque(self.tau[idx]) if self.tau.ndim > 1 else self

    def __repr__(self) -> str:
        return f"BodyTorque(tau={_plain(self.tau)!r})"


class SpaceTorque(Torque):
    r"""A torque constant in the space frame, :math:`\boldsymbol\tau = R^T\boldsymbol\tau_s`.

    Parameters
    ----------
    tau : array_like, shape (..., 3)
        Space frame.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> push = ep.torques.SpaceTorque([0.1, 0.0, 0.0])
    >>> tr = ep.solve([1.0, 2.0, 2.5], [0.0, 3.0], omega0=[0.0, 0.2, 0.0], torque=push, method="taylor")
    >>> print(np.round(tr.m[-1] - tr.m[0], 12) + 0.0)                # m grows by tau_s t
    [0.3 0.  0. ]
    """

    kind = "space_torque"

    def __init__(self, tau: ArrayLike) -> None:
        self.tau = _vec(tau, "tau", "SpaceTorque")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.tau.shape[:-1]

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return _bT(R, self.tau)

    def polynomial(self) -> PolynomialTorque:
        eye = np.broadcast_to(np.eye(3), self.tau.shape[:-1] + (3, 3))
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.tau,), maps=(eye,))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "tau": _plain(self.tau)}

    def __getitem__(self, idx: Any) -> SpaceTorque:
        return SpaceTorque(self.tau[idx]) if self.tau.ndim > 1 else self

    def __repr__(self) -> str:
        return f"SpaceTorque(tau={_plain(self.tau)!r})"


class CallableTorque(Torque):
    r"""Any Python function ``torque(t, q, omega) -> tau_body``.

    The function receives the time (a float, or an array broadcast against the
    batch), the attitude quaternions ``q`` (..., 4) (scalar first) and the body
    angular velocities (..., 3), and must return the body-frame torque with the
    shape of ``omega``, vectorized over the batch. Only methods that evaluate a
    right-hand side can run it (``rk``).

    Parameters
    ----------
    func : callable
    conservative : bool, default False
        Informational only (a callable has no potential here).

    Raises
    ------
    TypeError
        ``func`` is not callable.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> def damping(t, q, omega):
    ...     return -0.1 * omega
    >>> tq = ep.torques.CallableTorque(damping)
    >>> tq, tq.kind
    (CallableTorque('damping'), 'callable')
    >>> print(tq.evaluate(0.0, np.eye(3), np.array([1.0, 2.0, 3.0]), np.eye(3)))
    [-0.1 -0.2 -0.3]
    """

    kind = "callable"
    depends_on_omega = True  # unknown: assume the worst
    time_dependent = True

    def __init__(self, func: Callable[..., ArrayLike]) -> None:
        if not callable(func):
            raise TypeError(f"torque must be a Torque or a callable torque(t, q, omega), got {func!r}")
        self.func = func

    def evaluate(
        self,
        t: ArrayLike,
        R: NDArray[np.float64],
        omega: NDArray[np.float64],
        inertia: NDArray[np.float64],
        q: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        if q is None:
            from ..attitude.core import quaternion_from_rotation_matrix

            q = quaternion_from_rotation_matrix(R)
        tau = self.func(t, q, omega)
        try:
            tau = np.asarray(tau, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"the torque function {self.func!r} must return a float array, got {tau!r}") from None
        if tau.shape != np.shape(omega):
            try:
                tau = np.broadcast_to(tau, np.shape(omega))
            except ValueError:
                raise InvalidInputError(
                    f"the torque function {self.func!r} returned shape {tau.shape}; expected {np.shape(omega)} "
                    f"(the shape of omega: one body-frame torque per body)"
                ) from None
        if not np.all(np.isfinite(tau)):
            raise InvalidInputError(f"the torque function {self.func!r} returned NaN or infinite values at t = {t!s}")
        return tau

    def __repr__(self) -> str:
        return f"CallableTorque({getattr(self.func, '__name__', self.func)!r})"


class UnrecordedTorque(Torque):
    """Stand-in, read from a file, for a torque whose code was not recorded (a callable).

    The trajectory's data is intact; anything that must evaluate the torque
    raises :class:`NotImplementedError` naming it.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tq = ep.torques.UnrecordedTorque("CallableTorque('damping')")   # as read back from a file
    >>> tq, tq.to_dict()
    (UnrecordedTorque("CallableTorque('damping')"), {'kind': 'unrecorded', 'description': "CallableTorque('damping')"})
    >>> try:
    ...     tq.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3))
    ... except NotImplementedError as err:
    ...     print(err)
    the torque CallableTorque('damping') was a Python function and was not saved in the file
    """

    kind = "unrecorded"
    depends_on_omega = True
    time_dependent = True

    def __init__(self, description: str = "") -> None:
        self.description = description

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        raise NotImplementedError(f"the torque {self.description} was a Python function and was not saved in the file")

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "description": self.description}

    def __repr__(self) -> str:
        return f"UnrecordedTorque({self.description!r})"


_KINDS = {cls.kind: cls for cls in (Gravity, GravityGradient, BodyTorque, SpaceTorque)}


def torque_from_dict(d: dict) -> Torque:
    """Rebuild a torque from :meth:`Torque.to_dict`.

    Raises
    ------
    InvalidInputError
        Unknown kind or missing/unknown parameters.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> rec = ep.torques.Gravity(2.0, [0.0, 0.0, 0.1]).to_dict()
    >>> rec
    {'kind': 'gravity', 'mass': 2.0, 'center_of_mass': [0.0, 0.0, 0.1], 'g': [0.0, 0.0, -9.81]}
    >>> ep.torques.torque_from_dict(rec)
    Gravity(mass=2.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81])
    """
    if not isinstance(d, dict) or "kind" not in d:
        raise InvalidInputError(f"a torque record must be a dict with a 'kind', got {d!r}")
    kind = d["kind"]
    if kind not in _KINDS:
        raise InvalidInputError(f"unknown torque kind {kind!r}; known: {', '.join(sorted(_KINDS))}")
    params = {k: v for k, v in d.items() if k != "kind"}
    try:
        return _KINDS[kind](**params)
    except TypeError as exc:
        raise InvalidInputError(f"torque {kind!r}: {exc}") from None


#: what ``torque=`` accepts: a :class:`Torque`, a callable ``torque(t, q, omega) -> tau_body``, a list of
#: them, or None (the free body)
TorqueLike: TypeAlias = "Torque | Callable[..., ArrayLike] | Sequence[Torque | Callable[..., ArrayLike]] | None"


def as_torques(torque: TorqueLike) -> tuple[Torque, ...]:
    """Normalize ``torque=`` (None, a Torque, a callable, or a list of them) to a tuple of :class:`Torque`.

    Raises
    ------
    TypeError
        An entry that is neither a :class:`Torque` nor callable.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> ep.torques.as_torques(None)
    ()
    >>> ep.torques.as_torques([ep.torques.BodyTorque([0.0, 0.0, 1.0]), lambda t, q, omega: 0.0 * omega])
    (BodyTorque(tau=[0.0, 0.0, 1.0]), CallableTorque('<lambda>'))
    """
    if torque is None:
        return ()
    if isinstance(torque, Torque):
        return (torque,)
    if isinstance(torque, (list, tuple)):
        out: list[Torque] = []
        for item in torque:
            out.extend(as_torques(item))
        return tuple(out)
    if callable(torque):
        return (CallableTorque(torque),)
    raise TypeError(
        f"torque must be a Torque (eulerpoisson.torques.Gravity, GravityGradient, BodyTorque, SpaceTorque), "
        f"a callable torque(t, q, omega) -> tau_body, or a list of them; got {torque!r}"
    )
