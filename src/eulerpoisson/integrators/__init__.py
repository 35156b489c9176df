"""Numerical integrators registered as ``solve`` methods.

``taylor`` (the paper's Lie series, eq. 1.23.1, as an arbitrary-order Taylor
integrator), ``symplectic`` (Gauss-Legendre collocation in the canonical
variables (n, pi), and the Moser-Veselov discrete rigid body) and ``rk``
(scipy's ``solve_ivp``). All of them continue through the rotation angle pi
by chart changes R = R0 R(n) (see :mod:`eulerpoisson.integrators._charts`).
"""

import importlib as _importlib

for _name in ("rk", "symplectic", "taylor"):
    try:
        _importlib.import_module(f"{__name__}.{_name}")
    except ModuleNotFoundError as _exc:  # a module still being written
        if _exc.name != f"{__name__}.{_name}":
            raise
