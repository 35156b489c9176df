"""Argument checking and constants shared by the elliptic modules.

:mod:`eulerpoisson.numerics.jacobi` (Jacobi functions, ``K``),
:mod:`eulerpoisson.numerics.carlson` (Carlson's integrals) and
:mod:`eulerpoisson.numerics.elliptic` (the Legendre integrals and the
whole set) check their arguments with these helpers, so that every function
rejects the same inputs with the same messages.

Examples
--------
>>> m, m1 = parameters(None, 0.25)
>>> float(m), float(m1)
(0.75, 0.25)
>>> scalar_out(real_array(2.0, "x"))
np.float64(2.0)
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidInputError

__all__ = ["EPS", "PI_HI", "PI_LO", "real_array", "parameters", "scalar_out"]

#: machine epsilon of float64
EPS = np.finfo(np.float64).eps
#: pi as a double-double number ``PI_HI + PI_LO``
PI_HI = 3.141592653589793
#: the low part of pi as a double-double number
PI_LO = 1.2246467991473532e-16


def real_array(x, name):
    """``x`` as a float64 array (:class:`~eulerpoisson.errors.InvalidInputError` naming ``name`` if not real or finite)."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be a real array_like, got {x!r}") from exc
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(f"{name} must be finite; got non-finite values (shape {arr.shape})")
    return arr


def parameters(m, m1):
    """Validate ``m``/``m1`` and return both as float64 arrays.

    Exactly one of them may be ``None``; if both are given they must agree,
    ``|m + m1 - 1| <= 4 eps``.
    """
    if m is None and m1 is None:
        raise InvalidInputError("give the parameter m or its complement m1 (m1 = 1 - m)")
    if m is not None:
        m = real_array(m, "m")
        if np.any((m < 0.0) | (m > 1.0)):
            bad = m[(m < 0.0) | (m > 1.0)].ravel()[0].item()
            raise InvalidInputError(f"parameter m must lie in [0, 1], got m={bad!r}")
    if m1 is not None:
        m1 = real_array(m1, "m1")
        if np.any((m1 < 0.0) | (m1 > 1.0)):
            bad = m1[(m1 < 0.0) | (m1 > 1.0)].ravel()[0].item()
            raise InvalidInputError(f"complementary parameter m1 = 1 - m must lie in [0, 1], got m1={bad!r}")
    if m is None:
        m = 1.0 - m1
    elif m1 is None:
        m1 = 1.0 - m
    else:
        m, m1 = np.broadcast_arrays(m, m1)
        if np.any(np.abs((m - 1.0) + m1) > 4.0 * EPS):
            raise InvalidInputError("m and m1 were both given but m + m1 != 1 (beyond 4 eps); pass only one of them")
    m, m1 = np.broadcast_arrays(m, m1)
    return np.array(m, dtype=np.float64), np.array(m1, dtype=np.float64)


def scalar_out(x):
    """Return numpy scalars for 0-d results."""
    return x[()] if isinstance(x, np.ndarray) and x.ndim == 0 else x
