"""Spin-state estimation: the torque-free body behind observations of its rotation.

:func:`fit` finds the inertia ratios and the attitude and angular velocity at
the first observation that best explain observed attitudes, angular
velocities (body or space frame) and directions of a body axis, with
calibrated uncertainties; :class:`FitResult` holds the answer, its
covariance, residuals, the distinct optima found, the prediction and plots.
"""

from ..errors import PoorFitError
from .data import FitInputError
from .estimate import fit
from .result import FitResult, LocalOptimum

__all__ = ["fit", "FitResult", "LocalOptimum", "FitInputError", "PoorFitError"]
