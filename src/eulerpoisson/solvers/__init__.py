r"""Solution methods and the ``solve`` driver.

- :mod:`.problem`: the initial value problem every method receives;
- :mod:`.registry`: the :class:`Method` base class and the registry of methods;
- one folder per method, each registering itself: :mod:`.exact` (closed form),
  :mod:`.taylor` (the paper's Lie series), :mod:`.symplectic`, :mod:`.rk`,
  :mod:`.rk4` (on the shared fixed-step driver, :mod:`.stepper`);
- :mod:`.charts`: the Gibbs-vector charts R = R_c R(n) and shared kernels;
- :mod:`.driver`: :func:`solve`.

A new method is one new folder here with a ``method`` module: every such folder is imported below.
"""

import importlib as _importlib
import os as _os
import pkgutil as _pkgutil

from .driver import solve
from .exact.method import ExactOptions
from .problem import Problem, compose_initial, make_problem
from .registry import (
    Method,
    MethodOptions,
    MethodResult,
    available_methods,
    check_supported,
    get_method,
    methods_supporting,
    register_method,
    unregister_method,
)
from .rk.method import RKOptions
from .symplectic.method import SymplecticOptions
from .taylor.method import TaylorOptions

# importing a method folder registers its method: every subpackage with a ``method`` module, in name order
for _info in sorted(_pkgutil.iter_modules(__path__), key=lambda info: info.name):
    if _info.ispkg and any(
        m.name == "method" for m in _pkgutil.iter_modules([_os.path.join(p, _info.name) for p in __path__])
    ):
        _importlib.import_module(f"{__name__}.{_info.name}")
del _info

__all__ = [
    "Problem",
    "make_problem",
    "compose_initial",
    "Method",
    "MethodOptions",
    "ExactOptions",
    "RKOptions",
    "SymplecticOptions",
    "TaylorOptions",
    "methods_supporting",
    "check_supported",
    "MethodResult",
    "register_method",
    "unregister_method",
    "available_methods",
    "get_method",
    "solve",
]
