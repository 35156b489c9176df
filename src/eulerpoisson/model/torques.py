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
- :meth:`Torque.to_dict` / :meth:`Torque.from_dict` (:func:`torque_from_dict`):
  a JSON-able record for files, read back through the registry
  :data:`TORQUES` of torque kinds (:func:`register_torque`);
- :meth:`Torque.shifted` and :attr:`Torque.frame_rate`: the torque seen from
  a later time in a space frame turned about :math:`z` (the chunks of a long
  run, :meth:`eulerpoisson.Model.shifted`);
- :meth:`Torque.integrals`: the conserved quantities of a model whose torques
  are all of one class (:meth:`eulerpoisson.Model.integrals` combines them);
- :attr:`Torque.cli` (:class:`TorqueParam`) and :meth:`Torque.from_params`:
  the command-line flags and TOML keys of the torque, and the torque built
  from their values.

A new torque is one new class in this module (or a user's module): subclass
:class:`Torque`, implement :meth:`~Torque.evaluate`, and optionally
:meth:`~Torque.potential`, :meth:`~Torque.polynomial`, :meth:`~Torque.shifted`,
:meth:`~Torque.integrals` and :attr:`~Torque.cli`, and register it with
:func:`register_torque`; the methods that need more refuse it with a clear
error naming the methods that can run it (:class:`MagneticDipoleTorque` is
an example).

References
----------
E. Leimanis, *The General Problem of the Motion of Coupled Rigid Bodies about
a Fixed Point*, Springer (1965), ch. I (the Euler–Poisson equations).
P. C. Hughes, *Spacecraft Attitude Dynamics*, Wiley (1986), §8.3 (gravity
gradient). A. V. Borisov and I. S. Mamaev, *Rigid Body Dynamics*, De Gruyter
(2018), §2.1. J. R. Wertz (ed.), *Spacecraft Attitude Determination and
Control*, Reidel (1978), §17.2 (magnetic torque).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal, NamedTuple, TypeAlias, TypeVar, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..util.validate import as_float_array

if TYPE_CHECKING:
    from .equations import Model

__all__ = [
    "Torque",
    "Gravity",
    "GravityGradient",
    "BodyTorque",
    "SpaceTorque",
    "CallableTorque",
    "MagneticDipoleTorque",
    "UnrecordedTorque",
    "PolynomialTorque",
    "FlatPolynomialTorque",
    "TorqueParam",
    "IntegralContext",
    "TORQUES",
    "register_torque",
    "as_torques",
    "torque_from_dict",
    "rotate_about_z",
    "z_rotation_quaternion",
    "STANDARD_GRAVITY",
    "SYMMETRY_RTOL",
]

#: standard gravity (m s-2), the default magnitude of :class:`Gravity`
STANDARD_GRAVITY = 9.81

#: relative tolerance for recognizing equal moments and a centre of mass on an axis or plane (the integrals)
SYMMETRY_RTOL = 1e-12


def _bT(R, v):
    r""":math:`R^T\mathbf v`, batched: R (..., 3, 3), v (..., 3)."""
    return np.einsum("...ji,...j->...i", R, v)


def _mv(A, v):
    return np.einsum("...ij,...j->...i", A, v)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def z_rotation_quaternion(phi: ArrayLike) -> NDArray[np.float64]:
    r"""Quaternions (..., 4) of the rotations by ``phi`` (...) about the space :math:`z` axis.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> print(np.round(ep.model.torques.z_rotation_quaternion(np.pi), 12) + 0.0)
    [0. 0. 0. 1.]
    """
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.cos(phi / 2), np.zeros_like(phi), np.zeros_like(phi), np.sin(phi / 2)], -1)


def rotate_about_z(v: ArrayLike, phi: ArrayLike) -> NDArray[np.float64]:
    r"""Space vectors ``v`` (..., 3) rotated by ``phi`` (...) about the :math:`z` axis, (..., 3).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> print(np.round(ep.model.torques.rotate_about_z([1.0, 0.0, 2.0], np.pi / 2), 12) + 0.0)
    [0. 1. 2.]
    """
    v = np.asarray(v, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack(
        [
            c * v[..., 0] - s * v[..., 1],
            s * v[..., 0] + c * v[..., 1],
            np.broadcast_to(v[..., 2], np.broadcast_shapes(v[..., 2].shape, np.shape(c))),
        ],
        -1,
    )


def _cross_matrix(a):
    r""":math:`[\mathbf a]_\times` (..., 3, 3): :math:`[\mathbf a]_\times\mathbf v = \mathbf a\times\mathbf v`."""
    L = np.zeros(a.shape[:-1] + (3, 3))
    L[..., 0, 1], L[..., 0, 2] = -a[..., 2], a[..., 1]
    L[..., 1, 0], L[..., 1, 2] = a[..., 2], -a[..., 0]
    L[..., 2, 0], L[..., 2, 1] = -a[..., 1], a[..., 0]
    return L


@dataclass(frozen=True)
class TorqueParam:
    r"""One parameter of a torque as the command line and the TOML files give it.

    Attributes
    ----------
    name : str
        The torque's constructor argument (and the field of its
        :meth:`~Torque.to_dict` record), e.g. ``"center_of_mass"``.
    flag : str
        The ``simulate`` flag, e.g. ``"--com"``.
    toml_key : str
        The key of the ``[torque]`` section, e.g. ``"center_of_mass"``.
    kind : {"number", "positive", "vector3"}
        A finite number >= 0, a finite number > 0, or three finite numbers.
    help : str
        The flag's help text.
    units : str
        Units of the value (SI, for the record; the package is unit-agnostic).
    metavar : str
        The flag's placeholder (``"CX,CY,CZ"``).
    default : float, tuple of float or None
        The value when the flag is left out; None: required (the torque is
        built when its required parameters are given).

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> [(p.flag, p.toml_key, p.kind, p.required) for p in ep.torques.Gravity.cli]
    [('--com', 'center_of_mass', 'vector3', True), ('--mass', 'mass', 'positive', False), ('--gravity', 'gravity', 'vector3', False)]
    """

    name: str
    flag: str
    toml_key: str
    kind: Literal["number", "positive", "vector3"]
    help: str = ""
    units: str = ""
    metavar: str = ""
    default: float | tuple[float, ...] | None = None

    @property
    def required(self) -> bool:
        """No default: the torque needs the value."""
        return self.default is None

    @property
    def toml_kind(self) -> str:
        """What the TOML key holds in the command line's checks: ``"number"`` or ``"numbers"``."""
        return "numbers" if self.kind == "vector3" else "number"

    def value(self, v: Any, owner: str) -> float | NDArray[np.float64]:
        """``v`` checked against :attr:`kind` (a float or an array (3,)); errors name the flag and the key.

        Raises
        ------
        InvalidInputError
            Not a finite number of the right sign, or not three finite numbers.
        """
        where = f"{owner}: {self.name} ({self.flag} or [torque] {self.toml_key})"
        if self.kind == "vector3":
            try:
                return as_float_array(v, where, (3,))
            except TypeError as exc:
                raise InvalidInputError(str(exc)) from None
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise InvalidInputError(f"{where} must be a number, got {v!r}")
        x = float(v)
        bad = not np.isfinite(x) or (x <= 0 if self.kind == "positive" else x < 0)
        if bad:
            raise InvalidInputError(
                f"{where} must be a finite number {'> 0' if self.kind == 'positive' else '>= 0'}, got {v!r}"
            )
        return x


class IntegralContext(NamedTuple):
    r"""What :meth:`Torque.integrals` receives: a trajectory's state and its kinematic quantities.

    Arrays are ``(*batch, T, ...)``; :meth:`per_body` gives a parameter of
    batch shape ``(*batch, ...)`` the time axis (``(*batch, 1, ...)``) so that
    it broadcasts against them.

    Attributes
    ----------
    t : ndarray, shape (T,)
    R : ndarray, shape ``(*batch, T, 3, 3)``
        Attitude matrices.
    omega : ndarray, shape ``(*batch, T, 3)``
        Body angular velocities.
    M : ndarray, shape ``(*batch, T, 3)``
        Body angular momenta :math:`I\boldsymbol\Omega`.
    m : ndarray, shape ``(*batch, T, 3)``
        Space angular momenta :math:`R\mathbf M`.
    kinetic : ndarray, shape ``(*batch, T)``
        :math:`\tfrac12\boldsymbol\Omega\cdot\mathbf M`.
    inertia : ndarray, shape ``(*batch, 1, 3, 3)``
        The inertia tensors, per body.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> ep.torques.IntegralContext.per_body(np.zeros((5, 3)), 1).shape     # a batch of 5 vectors
    (5, 1, 3)
    """

    t: np.ndarray
    R: np.ndarray
    omega: np.ndarray
    M: np.ndarray
    m: np.ndarray
    kinetic: np.ndarray
    inertia: np.ndarray

    @staticmethod
    def per_body(a: ArrayLike, tail: int) -> NDArray[np.float64]:
        """``a`` of shape ``(*batch, *core)`` (``tail = len(core)``) with a time axis: ``(*batch, 1, *core)``."""
        a = np.asarray(a, dtype=float)
        return a.reshape(a.shape[: a.ndim - tail] + (1,) + a.shape[a.ndim - tail :])


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
        Name used in files and the command line (the key of :data:`TORQUES`).
    summary : str
        A one-line description of the kind of torque (:meth:`describe`).
    conservative : bool
        The torque derives from a potential :math:`U(t, R)` (:meth:`potential`).
    time_dependent : bool
        The torque depends explicitly on time.
    depends_on_omega : bool
        The torque depends on the angular velocity (not a potential torque).
    cli : tuple of TorqueParam
        The torque's command-line flags and ``[torque]`` TOML keys
        (:meth:`from_params`); empty: not given on the command line.

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
    summary: ClassVar[str] = ""
    # plain class attributes (not ClassVar): a torque may decide them per instance (MagneticDipoleTorque)
    conservative: bool = False
    time_dependent: bool = False
    depends_on_omega: bool = False
    cli: ClassVar[tuple[TorqueParam, ...]] = ()

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
        """A JSON-able record (``{"kind": ..., parameters...}``) read back by :meth:`from_dict`."""
        raise NotImplementedError(f"{type(self).__name__} cannot be written to a file")

    @classmethod
    def from_dict(cls, record: dict) -> Torque:
        """Rebuild a torque from its :meth:`to_dict` record, by its ``kind`` in :data:`TORQUES`.

        On a subclass, the record must be of that class (or of a subclass of it).

        Raises
        ------
        InvalidInputError
            Not a dict with a ``kind``, unknown kind, a kind of another class,
            or missing/unknown parameters.

        Examples
        --------
        >>> import eulerpoisson as ep
        >>> ep.torques.Torque.from_dict({"kind": "body_torque", "tau": [0.0, 0.0, 1.0]})
        BodyTorque(tau=[0.0, 0.0, 1.0])
        >>> ep.torques.SpaceTorque.from_dict({"kind": "space_torque", "tau": [1.0, 0.0, 0.0]})
        SpaceTorque(tau=[1.0, 0.0, 0.0])
        """
        if not isinstance(record, dict) or "kind" not in record:
            raise InvalidInputError(f"a torque record must be a dict with a 'kind', got {record!r}")
        kind = record["kind"]
        if not isinstance(kind, str) or kind not in TORQUES:
            raise InvalidInputError(f"unknown torque kind {kind!r}; known: {', '.join(sorted(TORQUES))}")
        target = TORQUES[kind]
        if not issubclass(target, cls):
            raise InvalidInputError(f"a torque record of kind {kind!r} is a {target.__name__}, not a {cls.__name__}")
        params = {k: v for k, v in record.items() if k != "kind"}
        try:
            return target(**params)
        except TypeError as exc:
            raise InvalidInputError(f"torque {kind!r}: {exc}") from None

    @classmethod
    def from_params(cls, values: dict[str, Any]) -> Torque:
        """The torque from the values of its :attr:`cli` parameters (as the command line parsed them).

        Parameters
        ----------
        values : dict
            Keyed by the parameters' :attr:`TorqueParam.name` (the constructor's
            arguments) or :attr:`TorqueParam.toml_key`; parameters left out
            take their defaults.

        Raises
        ------
        InvalidInputError
            A class without command-line parameters, an unknown key, a key
            given twice (by name and TOML key), a required parameter left
            out, or a value of the wrong kind (the message names the flag and
            the TOML key).

        Examples
        --------
        >>> import eulerpoisson as ep
        >>> ep.torques.Gravity.from_params({"center_of_mass": [0.0, 0.0, 0.1]})
        Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81])
        >>> ep.torques.GravityGradient.from_params({"gravity_gradient": 0.001})
        GravityGradient(mean_motion=0.001)
        """
        if not cls.cli:
            raise InvalidInputError(f"{cls.__name__} has no command-line parameters (Torque.cli is empty)")
        if not isinstance(values, dict):
            raise InvalidInputError(f"{cls.__name__}.from_params: values must be a dict, got {values!r}")
        by_key = {}
        for p in cls.cli:
            by_key[p.name] = p
            by_key[p.toml_key] = p
        unknown = sorted(str(k) for k in values if k not in by_key)
        if unknown:
            known = ", ".join(sorted({p.name for p in cls.cli}))
            raise InvalidInputError(f"{cls.__name__}: unknown parameter(s) {', '.join(unknown)}; known: {known}")
        args: dict[str, Any] = {}
        for key, v in values.items():
            p = by_key[key]
            if p.name in args:
                raise InvalidInputError(f"{cls.__name__}: {p.name} given twice (as {p.name} and {p.toml_key})")
            args[p.name] = p.value(v, cls.__name__)
        for p in cls.cli:
            if p.name not in args:
                if p.required:
                    raise InvalidInputError(
                        f"{cls.__name__} needs {p.name}: {p.flag} {p.metavar} or [torque] {p.toml_key}"
                    )
                args[p.name] = p.default
        return cls(**args)

    def describe(self) -> str:
        """A one-line description: the torque's repr and, if the class has one, its :attr:`summary`.

        Examples
        --------
        >>> import eulerpoisson as ep
        >>> ep.torques.BodyTorque([0.0, 0.0, 1.0]).describe()
        'BodyTorque(tau=[0.0, 0.0, 1.0]): a torque constant in the body frame'
        """
        return f"{self!r}: {self.summary}" if self.summary else repr(self)

    # ------------------------------------------------------------------
    # continuing from a later time
    # ------------------------------------------------------------------
    @property
    def frame_rate(self) -> NDArray[np.float64] | None:
        r"""Rate (...) about the space :math:`z` axis at which this torque turns the space frame, or None.

        A gravity gradient's orbit turns at its mean motion :math:`\nu`: seen
        from the time :math:`t_0` on, it is the same torque in a space frame
        turned by :math:`\varphi = \nu t_0` (:meth:`eulerpoisson.Model.shifted`).
        """
        return None

    def shifted(self, t_start: float, phi: ArrayLike) -> Torque:
        r"""The torque seen from the time ``t_start`` on, in a space frame turned by :math:`-\varphi` about z.

        With :math:`s = t - t_\mathrm{start}` the new torque at :math:`(s, R')`,
        :math:`R' = R_z(-\varphi)R`, is the old one at :math:`(t, R)`:
        space-frame vectors turn by :math:`-\varphi`, body-frame ones do not,
        and an explicit time :math:`t` becomes :math:`s + t_\mathrm{start}`.
        This default keeps an autonomous torque that turns nothing in space
        (``phi`` zero) and refuses the others.

        Parameters
        ----------
        t_start : float
        phi : ndarray, shape (...)
            Angle (rad); see :meth:`eulerpoisson.Model.shifted`.

        Raises
        ------
        InvalidInputError
            A time-dependent torque (or, when ``phi`` is not zero, any torque)
            whose class does not override this method.
        """
        if self.time_dependent or bool(np.any(np.asarray(phi) != 0)):
            raise InvalidInputError(
                f"the torque {self!r} depends on time (or on the space frame with a gravity gradient) and "
                "cannot be continued from a later state; solve the run in one piece"
            )
        return self

    # ------------------------------------------------------------------
    # integrals
    # ------------------------------------------------------------------
    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""The conserved quantities (beside none) of ``model``, whose torques are ``torques``.

        :meth:`eulerpoisson.Model.integrals` calls the hook of the torques'
        class when they are all of one class, and this base rule for a mix of
        classes: the energy :math:`\tfrac12\boldsymbol\Omega\cdot I\boldsymbol\Omega
        + \sum U` when every torque is conservative and autonomous, else nothing.
        A subclass overrides it with what its own torques conserve.

        Parameters
        ----------
        model : Model
        torques : sequence of Torque
            The model's torques.
        ctx : IntegralContext
            The trajectory and its kinematic quantities, ``(*batch, T, ...)``.

        Returns
        -------
        dict of str to ndarray, shape ``(*batch, T)``
        """
        if not torques or not all(tq.conservative and not tq.time_dependent for tq in torques):
            return {}
        T = ctx.t.shape[0]
        Rt = np.moveaxis(ctx.R, -3, 0)  # time first: the torques' parameters broadcast over the batch
        tt = ctx.t.reshape((T,) + (1,) * (Rt.ndim - 3))
        U = np.zeros(Rt.shape[:-2])
        for tq in torques:
            U = U + tq.potential(tt, Rt, model.body.inertia)
        return {"energy": ctx.kinetic + np.moveaxis(U, 0, -1)}

    def __getitem__(self, idx: Any) -> Torque:
        """The torque of one body (or a sub-batch) of a batch of parameters."""
        return self


#: the torque kinds that files and the command line know, by :attr:`Torque.kind` (:func:`register_torque`);
#: in the order of registration (the order of the command line's torques)
TORQUES: dict[str, type[Torque]] = {}

_T = TypeVar("_T", bound=type[Torque])


def register_torque(cls: _T) -> _T:
    """Class decorator: add a :class:`Torque` subclass to :data:`TORQUES` under its :attr:`~Torque.kind`.

    Raises
    ------
    InvalidInputError
        Not a Torque subclass, an empty kind, or a kind taken by another class.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> list(ep.torques.TORQUES)[:4]
    ['gravity', 'gravity_gradient', 'body_torque', 'space_torque']
    """
    if not (isinstance(cls, type) and issubclass(cls, Torque)):
        raise InvalidInputError(f"register_torque: {cls!r} is not a Torque subclass")
    kind = cls.kind
    if not isinstance(kind, str) or not kind:
        raise InvalidInputError(f"register_torque: {cls.__name__}.kind must be a non-empty string, got {kind!r}")
    other = TORQUES.get(kind)
    if other is not None and other is not cls:
        raise InvalidInputError(f"register_torque: kind {kind!r} is already {other.__name__}'s")
    TORQUES[kind] = cls
    return cls


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


def _common_direction(vectors):
    """Common unit direction (...) of the space vectors (each (..., 3)), or None (a zero one, or two apart)."""
    if not vectors:
        return None
    g = vectors[0]
    n = np.sqrt(_dot(g, g))
    if np.any(n == 0):
        return None
    ghat = g / n[..., None]
    for other in vectors[1:]:
        n2 = np.sqrt(_dot(other, other))
        if np.any(n2 == 0) or not np.allclose(other / n2[..., None], ghat, rtol=0, atol=1e-14):
            return None
    return ghat


def _gravity_direction(torques):
    """Common unit direction of g of the Gravity torques among ``torques``, or None."""
    return _common_direction([t.g for t in torques if isinstance(t, Gravity)])


def _equatorial_top(model, ratio):
    r"""``(frame, x0y0, kappa, ghat)`` when the model is a heavy top with :math:`I = \mathrm{diag}(r, r, 1)I_3`
    and c in the equatorial plane, else None."""
    gs = [t for t in model.torques if isinstance(t, Gravity)]
    if len(gs) != 1 or len(model.torques) != 1 or model.batch_shape:
        return None
    grav = gs[0]
    ev = model.body.principal_moments
    P = model.body.principal_axes
    order = np.argsort(ev)
    small, a, b = ev[order[0]], ev[order[1]], ev[order[2]]
    if not (abs(a - b) <= SYMMETRY_RTOL * b and abs(a - ratio * small) <= 1e-12 * a):
        return None
    e3 = P[:, order[0]]
    e1 = P[:, order[1]]
    e2 = np.cross(e3, e1)
    F = np.stack([e1, e2, e3], axis=1)  # body = F @ frame
    c = F.T @ grav.center_of_mass
    if abs(c[2]) > SYMMETRY_RTOL * max(float(np.linalg.norm(c)), 1e-300) or np.linalg.norm(c) == 0:
        return None
    gn = float(np.linalg.norm(grav.g))
    kappa = float(grav.mass) * gn / float(small)
    return F, c[:2], kappa, grav.g / gn


@register_torque
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
    summary = "heavy top: uniform gravity on a body with a fixed point at the body origin"
    conservative = True
    cli = (
        TorqueParam(
            "center_of_mass",
            "--com",
            "center_of_mass",
            "vector3",
            help="heavy top: centre of mass in the body frame, from the fixed point (the inertia is about it)",
            units="m",
            metavar="CX,CY,CZ",
        ),
        TorqueParam(
            "mass",
            "--mass",
            "mass",
            "positive",
            help="heavy top: mass M > 0 (default 1; needs --com)",
            units="kg",
            metavar="M",
            default=1.0,
        ),
        TorqueParam(
            "g",
            "--gravity",
            "gravity",
            "vector3",
            help="heavy top: gravitational acceleration, space frame (default 0,0,-9.81; needs --com)",
            units="m s-2",
            metavar="GX,GY,GZ",
            default=(0.0, 0.0, -STANDARD_GRAVITY),
        ),
    )

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
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.g,), maps=(_cross_matrix(self.moment_arm),))

    def shifted(self, t_start: float, phi: ArrayLike) -> Gravity:
        """``g`` turned by ``-phi`` about z (see :meth:`Torque.shifted`)."""
        turn = bool(np.any(np.asarray(phi) != 0))
        return Gravity(self.mass, self.center_of_mass, rotate_about_z(self.g, -np.asarray(phi))) if turn else self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Heavy tops: the energy; with every ``g`` along one direction :math:`\hat{\mathbf g}`,
        ``m_vertical`` (:math:`\mathbf m\cdot\hat{\mathbf g}`); for one body, ``M3`` (a Lagrange top),
        ``kovalevskaya`` and ``goryachev_chaplygin`` (see :meth:`eulerpoisson.Model.integrals`)."""
        per_body = ctx.per_body
        R, M, m, omega = ctx.R, ctx.M, ctx.m, ctx.omega
        out: dict[str, np.ndarray] = {}
        U: Any = 0.0
        for tq in cast(Sequence[Gravity], torques):
            U = U - _dot(per_body(tq.g, 1), _mv(R, per_body(tq.moment_arm, 1)))
        out["energy"] = ctx.kinetic + U
        ghat = _gravity_direction(cast(Sequence[Gravity], torques))
        if ghat is None:
            return out
        out["m_vertical"] = _dot(m, per_body(ghat, 1))
        if model.batch_shape:
            return out
        lt = model.lagrange_top()
        if lt is not None:
            out["M3"] = _dot(M, lt.frame[:, 2])
        for ratio, key in ((2.0, "kovalevskaya"), (4.0, "goryachev_chaplygin")):
            eq = _equatorial_top(model, ratio)
            if eq is None:
                continue
            F, c2, kappa, gh1 = eq
            w = _mv(F.T, omega)
            gamma = -_mv(F.T, np.einsum("...ji,j->...i", R, gh1))
            if key == "kovalevskaya":
                val = (w[..., 0] + 1j * w[..., 1]) ** 2 - kappa * (c2[0] + 1j * c2[1]) * (
                    gamma[..., 0] + 1j * gamma[..., 1]
                )
                out[key] = (val * np.conj(val)).real
            else:
                area = out["m_vertical"]
                scale = float(np.sqrt(np.max(_dot(m, m)))) if m.size else 0.0
                if area.size and np.all(np.abs(area[..., 0]) <= 1e-12 * max(scale, 1e-300)):
                    out[key] = w[..., 2] * (w[..., 0] ** 2 + w[..., 1] ** 2) - kappa * gamma[..., 2] * (
                        c2[0] * w[..., 0] + c2[1] * w[..., 1]
                    )
        return out

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


@register_torque
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
    summary = "gravity gradient on a body in a circular orbit in the space x-y plane"
    conservative = True
    time_dependent = True
    cli = (
        TorqueParam(
            "mean_motion",
            "--gravity-gradient",
            "gravity_gradient",
            "number",
            help="gravity-gradient torque of a circular orbit with mean motion NU >= 0 (rad per time unit)",
            units="rad s-1",
            metavar="NU",
        ),
    )

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

    @property
    def frame_rate(self) -> NDArray[np.float64]:
        """The mean motion: the orbit turns the space frame at this rate about z."""
        return self.mean_motion

    def shifted(self, t_start: float, phi: ArrayLike) -> GravityGradient:
        """Unchanged: in the space frame turned with the orbit the torque is the same (:meth:`Torque.shifted`)."""
        return self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""One gravity gradient: the Jacobi integral ``jacobi`` (:meth:`eulerpoisson.Model.integrals`)."""
        if len(torques) != 1:
            return {}
        nu = ctx.per_body(cast(GravityGradient, torques[0]).mean_motion, 0)
        phase = ctx.t * nu
        rhat = np.stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)], -1)
        r = np.einsum("...ji,...j->...i", ctx.R, rhat)
        return {"jacobi": ctx.kinetic - nu * ctx.m[..., 2] + 1.5 * nu**2 * _dot(r, _mv(ctx.inertia, r))}

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "mean_motion": _plain(self.mean_motion)}

    def __getitem__(self, idx: Any) -> GravityGradient:
        return GravityGradient(np.broadcast_to(self.mean_motion, self.batch_shape)[idx])

    def __repr__(self) -> str:
        return f"GravityGradient(mean_motion={_plain(self.mean_motion)!r})"


@register_torque
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
    summary = "a torque constant in the body frame"
    cli = (
        TorqueParam(
            "tau",
            "--body-torque",
            "body_torque",
            "vector3",
            help="constant torque in the body frame",
            units="N m",
            metavar="TX,TY,TZ",
        ),
    )

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

    def shifted(self, t_start: float, phi: ArrayLike) -> BodyTorque:
        """Unchanged: a body-frame torque turns with nothing in space (:meth:`Torque.shifted`)."""
        return self

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "tau": _plain(self.tau)}

    def __getitem__(self, idx: Any) -> BodyTorque:
        return BodyTorque(self.tau[idx]) if self.tau.ndim > 1 else self

    def __repr__(self) -> str:
        return f"BodyTorque(tau={_plain(self.tau)!r})"


@register_torque
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
    summary = "a torque constant in the space frame"
    cli = (
        TorqueParam(
            "tau",
            "--space-torque",
            "space_torque",
            "vector3",
            help="constant torque in the space frame",
            units="N m",
            metavar="TX,TY,TZ",
        ),
    )

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

    def shifted(self, t_start: float, phi: ArrayLike) -> SpaceTorque:
        """``tau`` turned by ``-phi`` about z (see :meth:`Torque.shifted`)."""
        turn = bool(np.any(np.asarray(phi) != 0))
        return SpaceTorque(rotate_about_z(self.tau, -np.asarray(phi))) if turn else self

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Constant space-frame torques: the components of :math:`\mathbf m - \boldsymbol\tau_s t`."""
        tau = sum(ctx.per_body(tq.tau, 1) for tq in cast(Sequence[SpaceTorque], torques))
        rest = ctx.m - ctx.t[:, None] * tau
        return {f"m_{ax} - tau_{ax} t": rest[..., i] for i, ax in enumerate("xyz")}

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
    summary = "a Python function torque(t, q, omega) -> tau_body"
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

    def shifted(self, t_start: float, phi: ArrayLike) -> CallableTorque:
        """The function called at ``s + t_start`` with the attitude turned back by ``phi`` (:meth:`Torque.shifted`)."""
        from ..numerics.quaternion import qmul

        turn = bool(np.any(np.asarray(phi) != 0))
        func, rz = self.func, z_rotation_quaternion(phi)

        def shifted(s, q, omega, _f=func, _rz=rz, _turn=turn):
            return _f(np.asarray(s) + t_start, qmul(_rz, q) if _turn else q, omega)

        shifted.__name__ = getattr(func, "__name__", "torque")
        return CallableTorque(shifted)

    def __repr__(self) -> str:
        return f"CallableTorque({getattr(self.func, '__name__', self.func)!r})"


@register_torque
class MagneticDipoleTorque(Torque):
    r"""The torque of a magnetic field on a body that carries a magnetic dipole.

    .. math:: \boldsymbol\tau = \boldsymbol\mu\times R^T\mathbf B(t), \qquad
              U = -(R\boldsymbol\mu)\cdot\mathbf B ,

    with :math:`\boldsymbol\mu` the body's magnetic dipole moment (body frame,
    A m², e.g. a magnetorquer or a permanent magnet) and :math:`\mathbf B` the
    magnetic flux density (space frame, T); the torque is in N m. The field
    is either constant, and the torque is then conservative (the sign:
    :math:`\delta U = -(R[\delta\boldsymbol\theta]_\times\boldsymbol\mu)\cdot\mathbf B
    = -(\boldsymbol\mu\times R^T\mathbf B)\cdot\delta\boldsymbol\theta`), autonomous
    and polynomial in the Poisson vector :math:`\mathbf b = R^T\mathbf B` (a heavy
    top with :math:`\mu\mathbf c \to \boldsymbol\mu`, :math:`\mathbf g \to \mathbf B`:
    every method that runs :class:`Gravity` runs it, and the model conserves the
    energy and :math:`\mathbf m\cdot\hat{\mathbf B}`); or a function of time
    ``field(t) -> (..., 3)`` (a field that turns, as seen along an orbit), and
    the torque is then time dependent and has no potential (``rk`` only).

    Parameters
    ----------
    dipole : array_like, shape (..., 3)
        :math:`\boldsymbol\mu`, body frame (A m²).
    field : array_like, shape (..., 3), or callable
        :math:`\mathbf B`, space frame (T): a constant, or a function of the
        time ``field(t)`` returning an array (3,) or (..., 3) that broadcasts
        against the batch (``t`` as :meth:`Torque.evaluate` receives it).

    Raises
    ------
    InvalidInputError
        A ``dipole`` or constant ``field`` of the wrong shape, with NaN, or
        batch shapes that do not broadcast; a callable field that returns
        an array not ending in 3 or not finite (when evaluated).
    TypeError
        Non-numeric parameters.

    Notes
    -----
    With a callable field the torque cannot be written to a file
    (``to_dict`` raises :class:`NotImplementedError`, as for
    :class:`CallableTorque`: files record it as unrecorded); indexing a
    batch (``torque[i]``) indexes the dipole and keeps the function.

    References
    ----------
    J. R. Wertz (ed.), *Spacecraft Attitude Determination and Control*,
    Reidel (1978), §17.2 (magnetic disturbance torque, :math:`\mathbf N =
    \mathbf m\times\mathbf B`). M. J. Sidi, *Spacecraft Dynamics and
    Control*, Cambridge (1997), §7.4 (magnetic torquers).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> mag = ep.torques.MagneticDipoleTorque(dipole=[0.0, 0.0, 2.0], field=[3e-5, 0.0, 0.0])
    >>> mag, mag.conservative, mag.time_dependent
    (MagneticDipoleTorque(dipole=[0.0, 0.0, 2.0], field=[3e-05, 0.0, 0.0]), True, False)
    >>> print(mag.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3)))        # mu x B
    [0.e+00 6.e-05 0.e+00]
    >>> print(mag.potential(0.0, np.eye(3), np.eye(3)))                     # -(R mu).B
    -0.0
    >>> turning = ep.torques.MagneticDipoleTorque([0.0, 0.0, 2.0], lambda t: [3e-5 * np.cos(t), 3e-5 * np.sin(t), 0.0])
    >>> turning.conservative, turning.time_dependent, turning.polynomial() is None
    (False, True, True)
    """

    kind = "magnetic_dipole"
    summary = "a magnetic dipole of the body in a magnetic field (constant or a function of time)"
    cli = (
        TorqueParam(
            "dipole",
            "--magnetic-dipole",
            "magnetic_dipole",
            "vector3",
            help="magnetic torque: the body's magnetic dipole moment, body frame (needs --magnetic-field)",
            units="A m2",
            metavar="MX,MY,MZ",
        ),
        TorqueParam(
            "field",
            "--magnetic-field",
            "magnetic_field",
            "vector3",
            help="magnetic torque: the magnetic flux density, space frame, constant (needs --magnetic-dipole)",
            units="T",
            metavar="BX,BY,BZ",
        ),
    )

    field: NDArray[np.float64] | Callable[..., ArrayLike]

    def __init__(self, dipole: ArrayLike, field: ArrayLike | Callable[..., ArrayLike]) -> None:
        self.dipole = _vec(dipole, "dipole", "MagneticDipoleTorque")
        if callable(field):
            self.field = field
            self._shape = self.dipole.shape[:-1]
        else:
            B = _vec(field, "field", "MagneticDipoleTorque")
            self.field = B
            self._shape = _shape("MagneticDipoleTorque", dipole=self.dipole[..., 0], field=B[..., 0])
        varying = callable(field)
        self.conservative = not varying
        self.time_dependent = varying

    @property
    def field_is_callable(self) -> bool:
        """The field is a function of time."""
        return callable(self.field)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self._shape

    def field_at(self, t: ArrayLike) -> NDArray[np.float64]:
        r""":math:`\mathbf B(t)`, space frame, shape (..., 3).

        Raises
        ------
        InvalidInputError
            A callable field that returns an array not ending in 3, or NaN or infinite values.
        """
        if not callable(self.field):
            return self.field
        B = self.field(t)
        try:
            B = np.asarray(B, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(
                f"the magnetic field function {self.field!r} must return a float array, got {B!r}"
            ) from None
        if B.ndim == 0 or B.shape[-1] != 3:
            raise InvalidInputError(
                f"the magnetic field function {self.field!r} returned shape {B.shape}; expected (..., 3) "
                "(the field in the space frame)"
            )
        if not np.all(np.isfinite(B)):
            raise InvalidInputError(
                f"the magnetic field function {self.field!r} returned NaN or infinite values at t = {t!s}"
            )
        return B

    def evaluate(
        self, t: ArrayLike, R: NDArray[np.float64], omega: NDArray[np.float64], inertia: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.cross(self.dipole, _bT(R, self.field_at(t)))

    def potential(self, t: ArrayLike, R: NDArray[np.float64], inertia: NDArray[np.float64]) -> NDArray[np.float64]:
        if callable(self.field):
            raise NotImplementedError(
                "MagneticDipoleTorque with a field that depends on time derives from no potential"
            )
        return -np.einsum("...i,...i->...", self.field, np.einsum("...ij,...j->...i", R, self.dipole))

    def polynomial(self) -> PolynomialTorque | None:
        if callable(self.field):
            return None
        return PolynomialTorque(constant=np.zeros(3), vectors=(self.field,), maps=(_cross_matrix(self.dipole),))

    def shifted(self, t_start: float, phi: ArrayLike) -> MagneticDipoleTorque:
        """The field turned by ``-phi`` about z and, for a callable, called at ``s + t_start`` (:meth:`Torque.shifted`)."""
        phi = np.asarray(phi)
        turn = bool(np.any(phi != 0))
        if not callable(self.field):
            return MagneticDipoleTorque(self.dipole, rotate_about_z(self.field, -phi)) if turn else self
        func = self.field

        def field(s, _f=func, _turn=turn):
            B = np.asarray(_f(np.asarray(s) + t_start), dtype=float)
            return rotate_about_z(B, -phi) if _turn else B

        field.__name__ = getattr(func, "__name__", "field")
        return MagneticDipoleTorque(self.dipole, field)

    @classmethod
    def integrals(cls, model: Model, torques: Sequence[Torque], ctx: IntegralContext) -> dict[str, np.ndarray]:
        r"""Constant fields: the energy and, with the fields along one direction :math:`\hat{\mathbf B}`,
        ``m_field`` (:math:`\mathbf m\cdot\hat{\mathbf B}`: the potential is invariant under rotations
        about :math:`\hat{\mathbf B}`). A field that depends on time: nothing."""
        mags = cast(Sequence[MagneticDipoleTorque], torques)
        if any(callable(tq.field) for tq in mags):
            return {}
        per_body = ctx.per_body
        U: Any = 0.0
        for tq in mags:
            U = U - _dot(per_body(cast(np.ndarray, tq.field), 1), _mv(ctx.R, per_body(tq.dipole, 1)))
        out = {"energy": ctx.kinetic + U}
        bhat = _common_direction([cast(np.ndarray, tq.field) for tq in mags])
        if bhat is not None:
            out["m_field"] = _dot(ctx.m, per_body(bhat, 1))
        return out

    def to_dict(self) -> dict[str, Any]:
        if callable(self.field):
            raise NotImplementedError(
                "MagneticDipoleTorque with a callable field cannot be written to a file (a Python function)"
            )
        return {"kind": self.kind, "dipole": _plain(self.dipole), "field": _plain(self.field)}

    def __getitem__(self, idx: Any) -> MagneticDipoleTorque:
        b = self._shape
        if callable(self.field):
            return MagneticDipoleTorque(np.broadcast_to(self.dipole, b + (3,))[idx], self.field)
        return MagneticDipoleTorque(
            np.broadcast_to(self.dipole, b + (3,))[idx], np.broadcast_to(self.field, b + (3,))[idx]
        )

    def __repr__(self) -> str:
        f = self.field
        shown = repr(getattr(f, "__name__", f)) if callable(f) else repr(_plain(f))
        return f"MagneticDipoleTorque(dipole={_plain(self.dipole)!r}, field={shown})"


@register_torque
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
    summary = "a torque read from a file whose code was not recorded"
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


def torque_from_dict(d: dict) -> Torque:
    """Rebuild a torque from :meth:`Torque.to_dict` (:meth:`Torque.from_dict`, by its kind in :data:`TORQUES`).

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
    return Torque.from_dict(d)


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
