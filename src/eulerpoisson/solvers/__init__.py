r"""Solution methods and the ``solve`` driver.

- :mod:`.problem`: the initial value problem every method receives;
- :mod:`.registry`: the :class:`Method` base class and the registry of methods;
- one folder per method, each registering itself: :mod:`.exact` (closed form),
  :mod:`.taylor` (the paper's Lie series), :mod:`.symplectic`, :mod:`.rk`;
- :mod:`.charts`: the Gibbs-vector charts R = R_c R(n) and shared kernels;
- :mod:`.driver`: :func:`solve`.

A new method is one new folder here plus its import below.
"""

from . import exact, rk, symplectic, taylor  # noqa: F401  (importing registers the methods)
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
