r"""Torques in JAX: the torques of :mod:`eulerpoisson.torques` as pure, differentiable pytrees.

Each torque is a callable pytree ``tau(t, q, omega, inertia=None) -> (..., 3)`` giving the body-frame
torque at the time ``t`` (...), the attitude quaternions ``q`` (..., 4) (scalar first, unit,
:math:`x_\text{space} = R(q)x_\text{body}`) and the body angular velocities ``omega`` (..., 3);
``inertia`` ((..., 3) principal moments or a (..., 3, 3) tensor, body frame) is needed by
:class:`GravityGradient` only. The parameters are the pytree's leaves: ``jax.grad`` differentiates
with respect to them, ``jax.vmap`` maps over them, and they broadcast elementwise against the state
like the parameters of the NumPy torques (a batch of parameters ``(..., 3)``).

=============================  =========================================  ============================
:mod:`eulerpoisson.torques`    here                                       torque (body frame)
=============================  =========================================  ============================
``Gravity``                    :class:`Gravity`                           :math:`\mu\mathbf c\times R^T\mathbf g`
``GravityGradient``            :class:`GravityGradient`                   :math:`3\nu^2\mathbf r\times I\mathbf r`
``BodyTorque``                 :class:`BodyTorque`                        :math:`\boldsymbol\tau`
``SpaceTorque``                :class:`SpaceTorque`                       :math:`R^T\boldsymbol\tau_s`
``MagneticDipoleTorque``       :class:`MagneticDipoleTorque`              :math:`\boldsymbol\mu\times R^T\mathbf B(t)`
a list of torques              :class:`TorqueSum` (also ``a + b``)        the sum
a JAX function                 :class:`FunctionTorque`                    ``func(t, q, omega)``
=============================  =========================================  ============================

:func:`from_torque` turns an :mod:`eulerpoisson.torques` object (or a list of them) into its JAX
twin. A :class:`~eulerpoisson.torques.CallableTorque` (a NumPy function), a magnetic field given as a
Python function, or an :class:`~eulerpoisson.torques.UnrecordedTorque` has none: write the function
with ``jax.numpy`` and wrap it in :class:`FunctionTorque` (or give the field function to
:class:`MagneticDipoleTorque` here).

Each class declares what its torque depends on (``time_dependent``, ``depends_on_omega``), which
the splitting integrator :func:`eulerpoisson.jax.splitting.integrate` reads to choose its kicks.

Examples
--------
>>> import numpy as np, eulerpoisson as ep
>>> from eulerpoisson.jax.torques import Gravity, from_torque
>>> top = Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])
>>> q = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])   # the axis horizontal
>>> print(np.round(np.asarray(top(0.0, q, np.zeros(3))), 12) + 0.0)   # float64 (the default)
[0.981 0.    0.   ]
>>> from_torque(ep.torques.Gravity(1.0, [0.0, 0.0, 0.1]))
Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81])
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, ClassVar

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import InvalidInputError, UnsupportedModelError
from ..model.torque_base import STANDARD_GRAVITY
from .precision import as_float, float64_by_default

__all__ = [
    "JaxTorque",
    "Gravity",
    "GravityGradient",
    "BodyTorque",
    "SpaceTorque",
    "MagneticDipoleTorque",
    "FunctionTorque",
    "TorqueSum",
    "from_torque",
    "rotate_to_body",
    "inertia_tensor",
]


def rotate_to_body(q, s):
    r""":math:`R(q)^T\mathbf s`: space vectors ``s`` (..., 3) seen in the body frame of the unit quaternions
    ``q`` (..., 4), broadcast against each other.

    .. math:: R^T\mathbf s = \mathbf s + 2\big(w\,\mathbf c - \mathbf v\times\mathbf c\big),
              \qquad \mathbf c = \mathbf s\times\mathbf v,\ \ q = (w, \mathbf v).

    Examples
    --------
    >>> import jax, numpy as np
    >>> from eulerpoisson.jax.torques import rotate_to_body
    >>> q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])   # 90 degrees about z
    >>> with jax.enable_x64(True):
    ...     print(np.round(np.asarray(rotate_to_body(q, np.array([1.0, 0.0, 0.0]))), 12) + 0.0)
    [ 0. -1.  0.]
    """
    w = q[..., 0:1]
    v = q[..., 1:]
    c = jnp.cross(s, v)
    return s + 2.0 * (w * c - jnp.cross(v, c))


def inertia_tensor(inertia):
    """The inertia as a tensor (..., 3, 3): principal moments (..., 3) become a diagonal matrix.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.torques import inertia_tensor
    >>> inertia_tensor(jnp.array([1.0, 2.0, 3.0])).shape
    (3, 3)
    """
    inertia = jnp.asarray(inertia)
    if inertia.ndim >= 2 and inertia.shape[-2:] == (3, 3):
        return inertia
    if inertia.ndim >= 1 and inertia.shape[-1] == 3:
        return inertia[..., :, None] * jnp.eye(3, dtype=inertia.dtype)
    raise InvalidInputError(
        f"inertia must have shape (..., 3) (moments) or (..., 3, 3) (a tensor), got {inertia.shape}"
    )


def _plain(a):
    a = np.asarray(a)
    return a.item() if a.ndim == 0 else a.tolist()


class JaxTorque:
    """Base class of the JAX torques: a callable pytree ``tau(t, q, omega, inertia=None) -> (..., 3)``.

    Subclasses list their array parameters in ``_fields`` (the pytree's leaves) and implement
    :meth:`evaluate`; calling the torque casts its inputs and parameters to the computing dtype
    (float64 by default) and evaluates it. ``a + b`` is their :class:`TorqueSum`.

    Attributes
    ----------
    time_dependent : bool
        The torque depends explicitly on the time.
    depends_on_omega : bool
        The torque depends on the angular velocity.

    Examples
    --------
    >>> import jax, numpy as np
    >>> from eulerpoisson.jax.torques import JaxTorque
    >>> class Spring(JaxTorque):       # a torsion spring about the body z axis (an example)
    ...     _fields = ("k",)
    ...     def __init__(self, k):
    ...         self.k = np.asarray(k, dtype=float)
    ...     def evaluate(self, t, q, omega, inertia=None):
    ...         return -2.0 * self.k * q[..., 3:4] * q[..., 0:1] * np.array([0.0, 0.0, 1.0])
    >>> spring = Spring(0.5)
    >>> jax.tree_util.tree_leaves(spring), spring
    ([array(0.5)], Spring(k=0.5))
    >>> q = [np.cos(0.25), 0.0, 0.0, np.sin(0.25)]          # turned by 0.5 rad about z
    >>> print(np.round(np.asarray(spring(0.0, q, [0.0, 0.0, 0.0])), 8) + 0.0)
    [ 0.          0.         -0.23971277]
    """

    _fields: ClassVar[tuple[str, ...]] = ()
    time_dependent: bool = False
    depends_on_omega: bool = False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        jax.tree_util.register_pytree_node_class(cls)

    def tree_flatten(self):
        return tuple(getattr(self, f) for f in self._fields), None

    @classmethod
    def tree_unflatten(cls, aux, children):
        obj = object.__new__(cls)
        for f, c in zip(cls._fields, children):
            object.__setattr__(obj, f, c)
        return obj

    @float64_by_default
    def __call__(self, t, q, omega, inertia=None, *, dtype=None):
        """The body-frame torque (..., 3) at ``t`` (...), ``q`` (..., 4), ``omega`` (..., 3).

        The inputs and the parameters are cast to ``dtype`` (float64 by default,
        :func:`~eulerpoisson.jax.precision.float64_by_default`), then :meth:`evaluate` runs.
        """
        tq = jax.tree_util.tree_map(lambda x: as_float(x, dtype, "torque parameter"), self)
        t = as_float(t, dtype, "t")
        q = as_float(q, dtype, "q")
        omega = as_float(omega, dtype, "omega")
        if inertia is not None:
            inertia = as_float(inertia, dtype, "inertia")
        return tq.evaluate(t, q, omega, inertia)

    def evaluate(self, t, q, omega, inertia=None):
        """The torque, without casting (what :meth:`__call__` and the integrators run)."""
        raise NotImplementedError

    def __add__(self, other):
        if not isinstance(other, JaxTorque):
            return NotImplemented
        return TorqueSum((self, other))

    def __repr__(self) -> str:
        args = ", ".join(f"{f}={_plain(getattr(self, f))!r}" for f in self._fields)
        return f"{type(self).__name__}({args})"


def _vector(x, name, owner):
    a = x if isinstance(x, jax.Array) else np.asarray(x, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise InvalidInputError(f"{owner}: {name} must have shape (..., 3), got {a.shape}")
    return a


def _scalar(x):
    return x if isinstance(x, jax.Array) else np.asarray(x, dtype=float)


class Gravity(JaxTorque):
    r"""A heavy top: :math:`\boldsymbol\tau = \mu\,\mathbf c\times R^T\mathbf g` (:class:`eulerpoisson.torques.Gravity`).

    Parameters
    ----------
    mass : float or array_like, shape (...)
    center_of_mass : array_like, shape (..., 3)
        Body frame, from the fixed point.
    g : array_like, shape (..., 3)
        Space frame; default (0, 0, -9.81).

    Raises
    ------
    InvalidInputError
        ``center_of_mass`` or ``g`` not of shape (..., 3).

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.torques import Gravity
    >>> print(np.asarray(Gravity(2.0, [0.1, 0.0, 0.0])(0.0, [1.0, 0.0, 0.0, 0.0], np.zeros(3))) + 0.0)
    [0.    1.962 0.   ]
    """

    _fields = ("mass", "center_of_mass", "g")

    def __init__(self, mass, center_of_mass, g=(0.0, 0.0, -STANDARD_GRAVITY)):
        self.mass = _scalar(mass)
        self.center_of_mass = _vector(center_of_mass, "center_of_mass", "Gravity")
        self.g = _vector(g, "g", "Gravity")

    def evaluate(self, t, q, omega, inertia=None):
        arm = jnp.asarray(self.mass)[..., None] * self.center_of_mass
        return jnp.cross(arm, rotate_to_body(q, self.g))


class GravityGradient(JaxTorque):
    r"""Gravity gradient of a circular orbit in the space :math:`x`-:math:`y` plane
    (:class:`eulerpoisson.torques.GravityGradient`):
    :math:`\boldsymbol\tau = 3\nu^2\,\mathbf r\times I\mathbf r`,
    :math:`\mathbf r = R^T(\cos\nu t, \sin\nu t, 0)`.

    Needs the ``inertia`` argument (moments (..., 3) or tensor (..., 3, 3)).

    Parameters
    ----------
    mean_motion : float or array_like, shape (...)

    Raises
    ------
    InvalidInputError
        Called without ``inertia``.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.torques import GravityGradient
    >>> q = np.array([np.cos(0.15), 0.0, 0.0, np.sin(0.15)])     # 0.3 rad about z
    >>> tau = GravityGradient(0.1)(0.0, q, np.zeros(3), [1.0, 2.0, 2.5])
    >>> print(np.round(np.asarray(tau), 9) + 0.0)
    [ 0.          0.         -0.00846964]
    """

    _fields = ("mean_motion",)
    time_dependent = True

    def __init__(self, mean_motion):
        self.mean_motion = _scalar(mean_motion)

    def evaluate(self, t, q, omega, inertia=None):
        if inertia is None:
            raise InvalidInputError("GravityGradient needs the inertia: call it as tau(t, q, omega, inertia)")
        nu = jnp.asarray(self.mean_motion)
        phase = jnp.asarray(t) * nu
        rhat = jnp.stack([jnp.cos(phase), jnp.sin(phase), jnp.zeros_like(phase)], -1)
        r = rotate_to_body(q, rhat)
        Ir = jnp.einsum("...ij,...j->...i", inertia_tensor(inertia), r)
        return 3.0 * (nu**2)[..., None] * jnp.cross(r, Ir)


class BodyTorque(JaxTorque):
    """A torque constant in the body frame (:class:`eulerpoisson.torques.BodyTorque`).

    Parameters
    ----------
    tau : array_like, shape (..., 3)

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.torques import BodyTorque
    >>> print(BodyTorque([0.0, 0.0, 0.5])(0.0, [1.0, 0.0, 0.0, 0.0], np.zeros(3)))
    [0.  0.  0.5]
    """

    _fields = ("tau",)

    def __init__(self, tau):
        self.tau = _vector(tau, "tau", "BodyTorque")

    def evaluate(self, t, q, omega, inertia=None):
        shape = jnp.broadcast_shapes(self.tau.shape, jnp.shape(q)[:-1] + (3,), jnp.shape(omega))
        return jnp.broadcast_to(self.tau, shape)


class SpaceTorque(JaxTorque):
    r"""A torque constant in the space frame, :math:`R^T\boldsymbol\tau_s` (:class:`eulerpoisson.torques.SpaceTorque`).

    Parameters
    ----------
    tau : array_like, shape (..., 3)

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.torques import SpaceTorque
    >>> q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    >>> print(np.round(np.asarray(SpaceTorque([0.1, 0.0, 0.0])(0.0, q, np.zeros(3))), 12) + 0.0)
    [ 0.  -0.1  0. ]
    """

    _fields = ("tau",)

    def __init__(self, tau):
        self.tau = _vector(tau, "tau", "SpaceTorque")

    def evaluate(self, t, q, omega, inertia=None):
        return rotate_to_body(q, self.tau)


class MagneticDipoleTorque(JaxTorque):
    r"""A magnetic dipole in a field, :math:`\boldsymbol\mu\times R^T\mathbf B(t)`
    (:class:`eulerpoisson.torques.MagneticDipoleTorque`).

    Parameters
    ----------
    dipole : array_like, shape (..., 3)
        Body frame.
    field : array_like, shape (..., 3), or callable
        Space frame: a constant (a leaf of the pytree), or a function ``field(t) -> (..., 3)`` written
        with ``jax.numpy`` (static: not differentiated as a parameter); the torque is then time dependent.

    Raises
    ------
    InvalidInputError
        ``dipole`` or a constant ``field`` not of shape (..., 3).

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.torques import MagneticDipoleTorque
    >>> mag = MagneticDipoleTorque([0.0, 0.0, 2.0], [3e-5, 0.0, 0.0])
    >>> print(mag(0.0, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]))
    [0.e+00 6.e-05 0.e+00]
    >>> turning = MagneticDipoleTorque([0.0, 0.0, 2.0], lambda t: 3e-5 * jnp.stack([jnp.cos(t), jnp.sin(t), 0.0 * t], -1))
    >>> turning.time_dependent
    True
    """

    _fields = ("dipole", "field")

    def __init__(self, dipole, field):
        self.dipole = _vector(dipole, "dipole", "MagneticDipoleTorque")
        self.field = field if callable(field) else _vector(field, "field", "MagneticDipoleTorque")

    @property
    def time_dependent(self) -> bool:  # type: ignore[override]
        return callable(self.field)

    def tree_flatten(self):
        if callable(self.field):
            return (self.dipole,), self.field
        return (self.dipole, self.field), None

    @classmethod
    def tree_unflatten(cls, aux, children):
        obj = object.__new__(cls)
        obj.dipole = children[0]
        obj.field = aux if aux is not None else children[1]
        return obj

    def evaluate(self, t, q, omega, inertia=None):
        B = self.field(jnp.asarray(t)) if callable(self.field) else self.field
        return jnp.cross(self.dipole, rotate_to_body(q, jnp.asarray(B)))

    def __repr__(self) -> str:
        f = self.field
        shown = repr(getattr(f, "__name__", f)) if callable(f) else repr(_plain(f))
        return f"MagneticDipoleTorque(dipole={_plain(self.dipole)!r}, field={shown})"


class FunctionTorque(JaxTorque):
    """A torque given as a JAX-traceable function ``func(t, q, omega) -> (..., 3)`` (body frame).

    Parameters
    ----------
    func : callable
        Written with ``jax.numpy`` (it is traced); ``t`` (...), ``q`` (..., 4), ``omega`` (..., 3).
    depends_on_omega : bool, default True
        Whether it depends on ``omega`` (the splitting integrator then integrates its kicks by a
        Runge-Kutta step instead of exactly); False when it depends on the time and attitude only.
    time_dependent : bool, default True

    Raises
    ------
    InvalidInputError
        ``func`` is not callable.

    Examples
    --------
    >>> from eulerpoisson.jax.torques import FunctionTorque
    >>> drag = FunctionTorque(lambda t, q, omega: -0.1 * omega)
    >>> print(drag(0.0, [1.0, 0.0, 0.0, 0.0], [1.0, 2.0, 3.0]))
    [-0.1 -0.2 -0.3]
    """

    def __init__(self, func: Callable[..., Any], *, depends_on_omega: bool = True, time_dependent: bool = True):
        if not callable(func):
            raise InvalidInputError(f"FunctionTorque: func must be a callable func(t, q, omega), got {func!r}")
        self.func = func
        self.depends_on_omega = bool(depends_on_omega)
        self.time_dependent = bool(time_dependent)

    def tree_flatten(self):
        return (), (self.func, self.depends_on_omega, self.time_dependent)

    @classmethod
    def tree_unflatten(cls, aux, children):
        func, dep, td = aux
        return cls(func, depends_on_omega=dep, time_dependent=td)

    def evaluate(self, t, q, omega, inertia=None):
        return jnp.asarray(self.func(t, q, omega))

    def __repr__(self) -> str:
        return f"FunctionTorque({getattr(self.func, '__name__', self.func)!r})"


class TorqueSum(JaxTorque):
    """The sum of JAX torques (``a + b``; what :func:`from_torque` makes of a list).

    Parameters
    ----------
    terms : sequence of JaxTorque

    Raises
    ------
    InvalidInputError
        A term that is not a :class:`JaxTorque`.

    Examples
    --------
    >>> from eulerpoisson.jax.torques import BodyTorque, SpaceTorque
    >>> both = BodyTorque([0.0, 0.0, 1.0]) + SpaceTorque([1.0, 0.0, 0.0])
    >>> print(both(0.0, [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]))
    [1. 0. 1.]
    """

    terms: tuple[JaxTorque, ...]

    def __init__(self, terms: Sequence[JaxTorque]):
        flat: list[JaxTorque] = []
        for tq in terms:
            if isinstance(tq, TorqueSum):
                flat.extend(tq.terms)
            elif isinstance(tq, JaxTorque):
                flat.append(tq)
            else:
                raise InvalidInputError(f"TorqueSum: every term must be a JaxTorque, got {tq!r}")
        self.terms = tuple(flat)

    @property
    def time_dependent(self) -> bool:  # type: ignore[override]
        return any(tq.time_dependent for tq in self.terms)

    @property
    def depends_on_omega(self) -> bool:  # type: ignore[override]
        return any(tq.depends_on_omega for tq in self.terms)

    def tree_flatten(self):
        return (self.terms,), None

    @classmethod
    def tree_unflatten(cls, aux, children):
        obj = object.__new__(cls)
        obj.terms = tuple(children[0])
        return obj

    def evaluate(self, t, q, omega, inertia=None):
        total = self.terms[0].evaluate(t, q, omega, inertia)
        for tq in self.terms[1:]:
            total = total + tq.evaluate(t, q, omega, inertia)
        return total

    def __repr__(self) -> str:
        return " + ".join(repr(tq) for tq in self.terms) if self.terms else "TorqueSum(())"


def from_torque(torque) -> JaxTorque | None:
    """The JAX twin of an :mod:`eulerpoisson.torques` torque (or of a list of them: their sum).

    Parameters
    ----------
    torque : eulerpoisson.torques.Torque, JaxTorque, list of them, or None
        None or an empty list: None (the free body). A :class:`JaxTorque` is returned as it is.

    Returns
    -------
    JaxTorque or None

    Raises
    ------
    UnsupportedModelError
        A torque without a JAX twin: a :class:`~eulerpoisson.torques.CallableTorque` or a plain
        Python function (NumPy code cannot be traced: rewrite it with ``jax.numpy`` and wrap it in
        :class:`FunctionTorque`), a magnetic field given as a NumPy function, an
        :class:`~eulerpoisson.torques.UnrecordedTorque`, or a user's Torque subclass.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.jax.torques import from_torque
    >>> from_torque([ep.torques.BodyTorque([0.0, 0.0, 1.0]), ep.torques.GravityGradient(0.1)])
    BodyTorque(tau=[0.0, 0.0, 1.0]) + GravityGradient(mean_motion=0.1)
    >>> try:
    ...     from_torque(lambda t, q, omega: -omega)
    ... except ep.UnsupportedModelError as err:
    ...     print(str(err).split(": ", 1)[1][:46])
    a Python function cannot be traced by JAX; wri
    """
    from ..model import torques as mt

    if torque is None:
        return None
    if isinstance(torque, JaxTorque):
        return torque
    if isinstance(torque, (list, tuple)):
        terms = [from_torque(tq) for tq in torque]
        kept = [tq for tq in terms if tq is not None]
        if not kept:
            return None
        return kept[0] if len(kept) == 1 else TorqueSum(kept)
    if isinstance(torque, mt.Gravity):
        return Gravity(torque.mass, torque.center_of_mass, torque.g)
    if isinstance(torque, mt.GravityGradient):
        return GravityGradient(torque.mean_motion)
    if isinstance(torque, mt.BodyTorque):
        return BodyTorque(torque.tau)
    if isinstance(torque, mt.SpaceTorque):
        return SpaceTorque(torque.tau)
    if isinstance(torque, mt.MagneticDipoleTorque):
        if torque.field_is_callable:
            raise UnsupportedModelError(
                f"torque {torque!r} has no JAX twin: its field is a NumPy function of time; build "
                "eulerpoisson.jax.torques.MagneticDipoleTorque(dipole, field) with a field written in jax.numpy"
            )
        return MagneticDipoleTorque(torque.dipole, torque.field)
    if isinstance(torque, mt.CallableTorque) or (callable(torque) and not isinstance(torque, mt.Torque)):
        raise UnsupportedModelError(
            f"torque {torque!r} has no JAX twin: a Python function cannot be traced by JAX; write it with "
            "jax.numpy and wrap it in eulerpoisson.jax.torques.FunctionTorque(func, depends_on_omega=...)"
        )
    if isinstance(torque, mt.Torque):
        raise UnsupportedModelError(
            f"torque {torque!r} ({type(torque).__name__}) has no JAX twin; known: Gravity, GravityGradient, "
            "BodyTorque, SpaceTorque, MagneticDipoleTorque with a constant field (or wrap a jax.numpy "
            "function in eulerpoisson.jax.torques.FunctionTorque)"
        )
    raise InvalidInputError(
        f"torque must be an eulerpoisson.torques.Torque, a JaxTorque, a list of them or None, got {torque!r}"
    )
