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

A new torque is one new class in a module of its own (or a user's module): subclass
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

The code is split by torque: :mod:`~eulerpoisson.model.torque_base` (the
protocol, the registry, the shared helpers), :mod:`~eulerpoisson.model.torque_gravity`
(the heavy top and its integrals), :mod:`~eulerpoisson.model.torque_orbit`
(the gravity gradient), :mod:`~eulerpoisson.model.torque_simple` (constant
torques), :mod:`~eulerpoisson.model.torque_magnetic` (the magnetic dipole) and
:mod:`~eulerpoisson.model.torque_callable` (Python functions); this module
gathers them, importing them in the order that registers the kinds of
:data:`TORQUES` (gravity, gravity gradient, body, space, magnetic dipole,
unrecorded).
"""

from __future__ import annotations

# isort: off
# the import order is the registration order of TORQUES (the order of the command line's torques): keep it
from .torque_base import (
    STANDARD_GRAVITY,
    SYMMETRY_RTOL,
    TORQUES,
    FlatPolynomialTorque,
    IntegralContext,
    PolynomialTorque,
    Torque,
    TorqueParam,
    register_torque,
    rotate_about_z,
    torque_from_dict,
    z_rotation_quaternion,
)
from .torque_gravity import Gravity
from .torque_orbit import GravityGradient
from .torque_simple import BodyTorque, SpaceTorque
from .torque_magnetic import MagneticDipoleTorque
from .torque_callable import CallableTorque, TorqueLike, UnrecordedTorque, as_torques  # noqa: F401 (TorqueLike: a type)

# isort: on

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
