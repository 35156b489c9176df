r"""The torque protocol: the :class:`Torque` base class, its parameters and records, and the registry.

:class:`Torque` (what every torque implements: :meth:`~Torque.evaluate`,
:meth:`~Torque.potential`, :meth:`~Torque.polynomial`, :meth:`~Torque.shifted`,
:meth:`~Torque.integrals`, :meth:`~Torque.to_dict`, :attr:`~Torque.cli`), the
command-line description of a parameter (:class:`TorqueParam`), what
:meth:`Torque.integrals` receives (:class:`IntegralContext`), the polynomial
form the Taylor integrator differentiates (:class:`PolynomialTorque`), the
registry :data:`TORQUES` (:func:`register_torque`, :func:`torque_from_dict`),
the rotations about the space :math:`z` axis that continue a run from a later
time, and the small batched helpers the torque classes share. The torques
themselves are in :mod:`~eulerpoisson.model.torque_gravity`,
:mod:`~eulerpoisson.model.torque_orbit`, :mod:`~eulerpoisson.model.torque_simple`,
:mod:`~eulerpoisson.model.torque_magnetic` and
:mod:`~eulerpoisson.model.torque_callable`; :mod:`eulerpoisson.model.torques`
gathers them (see its docstring for the model).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal, NamedTuple, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..util.validate import as_float_array, scaled_norms

if TYPE_CHECKING:
    from .equations import Model

__all__ = [
    "Torque",
    "PolynomialTorque",
    "FlatPolynomialTorque",
    "TorqueParam",
    "IntegralContext",
    "TORQUES",
    "register_torque",
    "torque_from_dict",
    "rotate_about_z",
    "z_rotation_quaternion",
    "STANDARD_GRAVITY",
    "SYMMETRY_RTOL",
    "scaled_norms",
    "torque_bound",
    "check_torque_scales",
]

#: standard gravity (m s-2), the default magnitude of :class:`Gravity`
STANDARD_GRAVITY = 9.81

#: relative tolerance for recognizing equal moments and a centre of mass on an axis or plane (the integrals)
SYMMETRY_RTOL = 1e-12


def body_frame(R, v):
    r""":math:`R^T\mathbf v`, batched: R (..., 3, 3), v (..., 3)."""
    return np.einsum("...ji,...j->...i", R, v)


def batched_matvec(A, v):
    r""":math:`A\mathbf v`, batched: A (..., 3, 3), v (..., 3)."""
    return np.einsum("...ij,...j->...i", A, v)


def batched_dot(a, b):
    r""":math:`\mathbf a\cdot\mathbf b`, batched: (..., 3) each, (...) out."""
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


def torque_bound(tq: Torque, inertia_max: float) -> float | None:
    """An upper bound of ``|torque|`` over every attitude, from its polynomial form (None: unknown, e.g. a function).

    ``inertia_max`` is the largest principal moment (an orbit term's gain scales with it). The bound is inf
    where the torque's parameters overflow float64 together.

    Examples
    --------
    >>> from eulerpoisson.torques import Gravity
    >>> round(torque_bound(Gravity(2.0, [0.0, 0.0, 0.5], [0.0, 0.0, -10.0]), 1.0), 6)  # sqrt(2) |mu c| |g|
    14.142136
    >>> torque_bound(Gravity(1e300, [0.0, 0.0, 1e300]), 1.0)
    inf
    """
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            poly = tq.polynomial()
        except Exception:  # noqa: BLE001 - a torque without a usable polynomial form: no bound
            return None
    if poly is None:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        bound = float(np.max(scaled_norms(poly.constant), initial=0.0))
        for s, L in zip(poly.vectors, poly.maps):
            bound += float(np.max(scaled_norms(s) * scaled_norms(L, (-2, -1)), initial=0.0))
        bound += float(np.max(np.abs(np.asarray(poly.orbit_gain, dtype=float)), initial=0.0)) * inertia_max
    return bound if not np.isnan(bound) else np.inf


def check_torque_scales(torques: Sequence[Torque], inertia_max: float) -> None:
    """Refuse torques whose parameters overflow float64 together (a torque that would be inf or NaN).

    Raises
    ------
    InvalidInputError
        Naming the torque, when :func:`torque_bound` is inf.

    Examples
    --------
    >>> from eulerpoisson.torques import Gravity
    >>> check_torque_scales([Gravity(1e300, [0.0, 0.0, 1e300])], 1.0)
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: torque Gravity overflows float64: ...
    """
    for tq in torques:
        bound = torque_bound(tq, inertia_max)
        if bound is not None and not np.isfinite(bound):
            raise InvalidInputError(
                f"torque {type(tq).__name__} overflows float64: the product of its parameters is not a number "
                f"(above {np.finfo(float).max:.2g}); write them in other units"
            )


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


def cross_matrix(a):
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


def vector_param(x, name, kind):
    """A torque's parameter ``name`` of class ``kind`` as a float array (..., 3).

    Raises
    ------
    InvalidInputError
        Not ending in 3, or NaN (the message names ``kind: name``).
    TypeError
        Not numeric.
    """
    try:
        return as_float_array(x, f"{kind}: {name}", (3,))
    except TypeError as exc:
        raise TypeError(str(exc)) from None


def scalar_param(x, name, kind, *, positive=False, nonnegative=False):
    """A torque's scalar parameter ``name`` of class ``kind`` as a float array (...), > 0 or >= 0 if asked.

    Raises
    ------
    InvalidInputError
        NaN, or a value of the wrong sign (the message names ``kind: name``).
    TypeError
        Not numeric.
    """
    try:
        a = as_float_array(x, f"{kind}: {name}")
    except TypeError as exc:
        raise TypeError(str(exc)) from None
    if positive and np.any(a <= 0):
        raise InvalidInputError(f"{kind}: {name} must be > 0, got {a.tolist() if a.size < 7 else a.shape}")
    if nonnegative and np.any(a < 0):
        raise InvalidInputError(f"{kind}: {name} must be >= 0, got {a.tolist() if a.size < 7 else a.shape}")
    return a


def param_batch_shape(kind, **arrays):
    """The common batch shape of a torque's parameters (``name=array`` of their batch shapes).

    Raises
    ------
    InvalidInputError
        Shapes that do not broadcast (the message names ``kind`` and each parameter's shape).
    """
    try:
        return np.broadcast_shapes(*(a.shape for a in arrays.values()))
    except ValueError:
        desc = ", ".join(f"{k} {a.shape}" for k, a in arrays.items())
        raise InvalidInputError(f"{kind}: the parameters' batch shapes do not broadcast: {desc}") from None


def plain(a):
    """A parameter as a plain Python float or (nested) list, for records and reprs."""
    a = np.asarray(a)
    return a.item() if a.ndim == 0 else a.tolist()


def common_direction(vectors):
    """Common unit direction (...) of the space vectors (each (..., 3)), or None (a zero one, or two apart)."""
    if not vectors:
        return None
    g = vectors[0]
    n = np.sqrt(batched_dot(g, g))
    if np.any(n == 0):
        return None
    ghat = g / n[..., None]
    for other in vectors[1:]:
        n2 = np.sqrt(batched_dot(other, other))
        if np.any(n2 == 0) or not np.allclose(other / n2[..., None], ghat, rtol=0, atol=1e-14):
            return None
    return ghat


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
