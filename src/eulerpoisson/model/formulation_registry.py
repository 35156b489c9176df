r"""The registry of the formulations by name (part of :mod:`.formulations`).

:data:`FORMULATIONS` maps each registry name to its class; the modules of
the formulation families (:mod:`eulerpoisson.model.formulation_euler_poisson`,
:mod:`eulerpoisson.model.formulation_gibbs`) add their classes with
:func:`register` when imported, and :mod:`eulerpoisson.model.formulations`
imports them all (in the order of the registry), so that the registry is
complete wherever a formulation can be made. This module imports none of
them: :meth:`Formulation.convert <eulerpoisson.model.formulations.Formulation.convert>`
finds its target here without an import cycle.

Examples
--------
>>> import eulerpoisson.model.formulations as F
>>> list(FORMULATIONS) == list(F.FORMULATIONS)
True
>>> ALIASES["n-pi"]
'canonical'
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from numpy.typing import ArrayLike

from ..errors import InvalidInputError

if TYPE_CHECKING:
    from .body import RigidBody
    from .formulation_base import Formulation
    from .torques import TorqueLike

__all__ = ["FORMULATIONS", "ALIASES", "formulation", "register"]

#: Registry of the formulations by name.
FORMULATIONS: dict[str, type[Formulation]] = {}

#: Other names of the formulations (lower case, ``-`` for ``_``).
ALIASES = {
    "r-omega": "euler-poisson",
    "ep": "euler-poisson",
    "n-pi": "canonical",
    "n-m": "momentum",
    "noncanonical": "momentum",
    "n-omega": "velocity",
    "lagrangian": "geodesic",
    "n-ndot": "geodesic",
}


def register(name: str, cls: type[Formulation]) -> type[Formulation]:
    """Add ``cls`` to :data:`FORMULATIONS` under ``name`` (done once, by the module defining it).

    Parameters
    ----------
    name : str
        The registry name (``cls.name``).
    cls : type
        A subclass of :class:`~eulerpoisson.model.formulations.Formulation`.

    Returns
    -------
    type
        ``cls``.

    Raises
    ------
    InvalidInputError
        ``name`` is taken by another class.
    """
    if FORMULATIONS.get(name, cls) is not cls:
        raise InvalidInputError(f"the formulation name {name!r} is taken by {FORMULATIONS[name].__name__}")
    FORMULATIONS[name] = cls
    return cls


def formulation(name: str, body: RigidBody | ArrayLike, torque: TorqueLike = None) -> Formulation:
    r"""Construct a formulation by registry name, for the free body or with a potential.

    Parameters
    ----------
    name : str
        One of ``FORMULATIONS`` (``'euler-poisson'``, ``'canonical'``,
        ``'momentum'``, ``'velocity'``, ``'geodesic'``) or an alias
        (``'R-Omega'``, ``'n-pi'``, ``'n-m'``, ``'n-Omega'``, ``'n-ndot'``,
        ``'lagrangian'``, ``'noncanonical'``); case and ``_`` / ``-`` are ignored.
    body : RigidBody, Model or array_like
        The body or its inertia (moments (3,) or tensor (3, 3)), or a
        :class:`~eulerpoisson.Model` (its body and torques).
    torque : Torque or list of Torque, optional
        Conservative torques (:class:`~eulerpoisson.torques.Gravity`,
        :class:`~eulerpoisson.torques.GravityGradient`):
        :math:`H = H_0 + U(t, R)`, the same Poisson tensor, and in the
        canonical chart :math:`\dot{\boldsymbol\pi} = -\partial H_0/\partial\mathbf n
        - \partial U/\partial\mathbf n` with :math:`\partial U/\partial\mathbf n
        = -2A(\mathbf n)\boldsymbol\tau` (see the module docstring). None: the free body.

    Returns
    -------
    Formulation

    Raises
    ------
    InvalidInputError
        Unknown name.
    UnsupportedModelError
        (a ``ValueError``) A non-conservative torque (``BodyTorque``,
        ``SpaceTorque``, a callable); the message names what is accepted.
    TypeError
        ``name`` is not a string; ``torque`` is not a torque.
    InvalidInertiaError
        Not a physical inertia tensor.

    References
    ----------
    Paper eq. 1.9-1.16 (the canonical formulation the potential is added to).

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1])
    >>> f = ep.formulation("canonical", [1.0, 1.0, 0.5], torque=top)
    >>> z = f.from_common([1.0, 0.0, 0.0, 0.0], [0.0, 0.2, 20.0])
    >>> f.vector_field(z).shape
    (6,)
    """
    if not isinstance(name, str):
        raise TypeError(f"formulation name must be a string, got {type(name).__name__} {name!r}")
    key = name.strip().lower().replace("_", "-")
    key = ALIASES.get(key, key)
    if key not in FORMULATIONS:
        raise InvalidInputError(
            f"unknown formulation {name!r}; expected one of {sorted(FORMULATIONS)} or an alias {sorted(ALIASES)}"
        )
    return FORMULATIONS[key](body, torque)
