"""Torques for :func:`eulerpoisson.solve` (``torque=``): the public home of :mod:`eulerpoisson.model.torques`.

``Gravity`` (a heavy top), ``GravityGradient`` (a circular orbit),
``BodyTorque`` and ``SpaceTorque`` (constant), ``MagneticDipoleTorque`` (a
magnetic dipole in a constant or time-dependent field), ``CallableTorque``
(any Python function ``torque(t, q, omega) -> tau_body``; a plain callable
passed as ``torque=`` is wrapped in it). ``TORQUES`` and ``register_torque``:
the registry of torque kinds that files and the command line know.
"""

from .model.torques import (  # noqa: F401
    STANDARD_GRAVITY,
    TORQUES,
    BodyTorque,
    CallableTorque,
    Gravity,
    GravityGradient,
    IntegralContext,
    MagneticDipoleTorque,
    PolynomialTorque,
    SpaceTorque,
    Torque,
    TorqueParam,
    UnrecordedTorque,
    as_torques,
    register_torque,
    torque_from_dict,
)

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
    "TorqueParam",
    "IntegralContext",
    "TORQUES",
    "register_torque",
    "as_torques",
    "torque_from_dict",
    "STANDARD_GRAVITY",
]
