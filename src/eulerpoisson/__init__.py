"""eulerpoisson: rigid-body rotation, the free body exactly (in the paper's rotation vector n = k tan(alpha/2)) and bodies under torque.

Attitude sets centred on the Gibbs vector, the rigid-body model, the paper's
formulations and its machine-checked audit, the exact (elliptic-function)
motion, and geometric integrators.
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("eulerpoisson")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

from .attitude.core import Attitude
from .model.body import RigidBody
from .model.equations import Model
from . import torques
from .solvers import available_methods, solve
from .trajectory import Trajectory
from .model.formulations import FORMULATIONS, Formulation, formulation
from .errors import (
    EulerPoissonError,
    InvalidInertiaError,
    InvalidInputError,
    MissingDependencyError,
    SingularChartError,
    UnsupportedModelError,
)

__all__ = [
    "__version__",
    "Attitude",
    "RigidBody",
    "Model",
    "torques",
    "solve",
    "available_methods",
    "Trajectory",
    "formulation",
    "Formulation",
    "FORMULATIONS",
    "EulerPoissonError",
    "InvalidInputError",
    "InvalidInertiaError",
    "SingularChartError",
    "UnsupportedModelError",
    "MissingDependencyError",
]
