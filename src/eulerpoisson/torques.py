"""Torques for :func:`eulerpoisson.solve` (``torque=``): the public home of :mod:`eulerpoisson.model.torques`.

``Gravity`` (a heavy top), ``GravityGradient`` (a circular orbit),
``BodyTorque`` and ``SpaceTorque`` (constant), ``CallableTorque`` (any
Python function ``torque(t, q, omega) -> tau_body``; a plain callable passed
as ``torque=`` is wrapped in it).
"""

from .model.torques import (  # noqa: F401
    STANDARD_GRAVITY,
    BodyTorque,
    CallableTorque,
    Gravity,
    GravityGradient,
    PolynomialTorque,
    SpaceTorque,
    Torque,
    UnrecordedTorque,
    as_torques,
    torque_from_dict,
)

__all__ = [
    "Torque",
    "Gravity",
    "GravityGradient",
    "BodyTorque",
    "SpaceTorque",
    "CallableTorque",
    "UnrecordedTorque",
    "PolynomialTorque",
    "as_torques",
    "torque_from_dict",
    "STANDARD_GRAVITY",
]
