"""eulerpoisson: rigid-body rotation, the free body exactly (in the paper's rotation vector n = k tan(alpha/2)) and bodies under torque.

Attitude sets centred on the Gibbs vector, the rigid-body model, the paper's
formulations and its machine-checked audit, the exact (elliptic-function)
motion, and geometric integrators.
"""

from . import torques
from .attitude.core import Attitude
from .errors import (
    EulerPoissonError,
    InvalidInertiaError,
    InvalidInputError,
    MissingDependencyError,
    SingularChartError,
    UnsupportedModelError,
)
from .model.body import RigidBody
from .model.equations import Model
from .solvers import available_methods, solve
from .trajectory import Trajectory

__all__ = [
    "__version__",
    "Attitude",
    "RigidBody",
    "Model",
    "torques",
    "solve",
    "available_methods",
    "Trajectory",
    "fit",
    "FitResult",
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


#: modules reachable as attributes (``ep.plots``, ``ep.analysis``...), imported on first use so that
#: ``import eulerpoisson`` does not pay for matplotlib, sympy or dask
_LAZY_MODULES = {
    "analysis": ".analysis",
    "attitude": ".attitude",
    "plots": ".viz.plots",
    "animate": ".viz.animate",
    "audit": ".paper.audit",
    "symbolic": ".paper.symbolic",
    "heavy_top": ".paper.heavy_top",
    "formulations": ".model.formulations",
    "stream": ".io.stream",
    "sweep": ".sweep",
    "solvers": ".solvers",
    "model": ".model",
    "testing": ".testing",
    "oracle": ".oracle",
    "estimation": ".estimation",
}


#: names imported on first use, as the modules above: ``fit`` (the estimation package), the formulations,
#: and ``__version__`` (importlib.metadata) are not needed by most programs and cost about 50 ms together
_LAZY_NAMES = {
    "fit": ".estimation",
    "FitResult": ".estimation",
    "FORMULATIONS": ".model.formulations",
    "Formulation": ".model.formulations",
    "formulation": ".model.formulations",
}


def __getattr__(name):
    if name == "__version__":
        from .version import package_version

        globals()[name] = value = package_version()
        return value
    if name in _LAZY_NAMES:
        import importlib

        value = getattr(importlib.import_module(_LAZY_NAMES[name], __name__), name)
        globals()[name] = value
        return value
    if name in _LAZY_MODULES:
        import importlib

        module = importlib.import_module(_LAZY_MODULES[name], __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"module 'eulerpoisson' has no attribute {name!r}")


def __dir__():
    return sorted(set(__all__) | set(_LAZY_MODULES))
