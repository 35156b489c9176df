r"""Floating-point precision of :mod:`eulerpoisson.jax`: float64 by default, float32 on request.

JAX computes in float32 unless 64-bit floats are enabled (``jax_enable_x64``). The functions of
:mod:`eulerpoisson.jax` take a keyword ``dtype`` (``None``: float64, or ``jnp.float32``) and are
wrapped by :func:`float64_by_default`:

* called eagerly (concrete inputs: Python numbers, NumPy or JAX arrays) with 64-bit floats off,
  they enable them for the duration of the call only (``jax.enable_x64(True)``), so the user's
  global setting is unchanged and the result is a float64 JAX array;
* called inside a user's transformation (``jit``, ``grad``, ``vmap``: the inputs are tracers) with
  64-bit floats off, they cannot change the precision of the trace and raise
  :class:`~eulerpoisson.errors.PrecisionError`, which says how to enable them or to ask for float32;
* with ``dtype=jnp.float32`` they compute in float32 whatever the setting.

A float64 JAX array returned to a session whose 64-bit floats are off is demoted to float32 by the
next JAX operation on it (JAX's rule, not ours); enable 64-bit floats to keep computing in float64.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, TypeVar

import jax
import jax.numpy as jnp
import numpy as np

from ..errors import InvalidInputError, PrecisionError

__all__ = ["as_float", "float64_by_default", "resolve_dtype", "x64_enabled"]

F = TypeVar("F", bound=Callable[..., Any])

_HINT = (
    "enable 64-bit floats with jax.config.update('jax_enable_x64', True) (or run inside "
    "`with jax.enable_x64(True):`), or pass dtype=jnp.float32 to compute in single precision"
)


def x64_enabled() -> bool:
    """Whether JAX's 64-bit floats are enabled in this context.

    Examples
    --------
    >>> from eulerpoisson.jax.precision import x64_enabled
    >>> isinstance(x64_enabled(), bool)
    True
    """
    return bool(jax.config.read("jax_enable_x64"))


def resolve_dtype(dtype) -> np.dtype:
    """The computing dtype: float64 for ``None``, else ``float64`` or ``float32``.

    Raises
    ------
    InvalidInputError
        For any other dtype.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.precision import resolve_dtype
    >>> resolve_dtype(None), resolve_dtype(jnp.float32)
    (dtype('float64'), dtype('float32'))
    """
    if dtype is None:
        return np.dtype(np.float64)
    try:
        dt = np.dtype(dtype)
    except TypeError as exc:
        raise InvalidInputError(f"dtype must be float64 or float32, got {dtype!r}") from exc
    if dt not in (np.dtype(np.float64), np.dtype(np.float32)):
        raise InvalidInputError(f"dtype must be float64 or float32, got {dt}")
    return dt


def _has_tracer(tree) -> bool:
    return any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree_util.tree_leaves(tree))


def float64_by_default(fn: F) -> F:
    """Decorate a function taking a keyword ``dtype`` so that float64 is its default (see module docs).

    The decorated function receives ``dtype`` resolved to a NumPy dtype.

    Raises
    ------
    PrecisionError
        When float64 is asked for (the default) inside a traced call with 64-bit floats off.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.precision import float64_by_default
    >>> @float64_by_default
    ... def double(x, *, dtype=None):
    ...     return 2 * jnp.asarray(x, dtype)
    >>> double(1.5).dtype, double(1.5, dtype=jnp.float32).dtype
    (dtype('float64'), dtype('float32'))
    """

    @functools.wraps(fn)
    def wrapper(*args, dtype=None, **kwargs):
        dt = resolve_dtype(dtype)
        if dt == np.float64 and not x64_enabled():
            if _has_tracer((args, kwargs)):
                raise PrecisionError(
                    f"{fn.__name__} computes in float64 by default, but it is traced with 64-bit floats off: {_HINT}"
                )
            with jax.enable_x64(True):
                return fn(*args, dtype=dt, **kwargs)
        return fn(*args, dtype=dt, **kwargs)

    return wrapper  # type: ignore[return-value]


def as_float(x, dtype, name: str):
    """``x`` as a JAX array of the computing dtype; a clear error for non-numeric input.

    Raises
    ------
    InvalidInputError
        If ``x`` is not a real numeric array.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.jax.precision import as_float
    >>> as_float([1, 2], np.float32, "t").dtype
    dtype('float32')
    """
    if isinstance(x, jax.core.Tracer) or isinstance(x, jax.Array):
        if not (jnp.issubdtype(x.dtype, jnp.floating) or jnp.issubdtype(x.dtype, jnp.integer)):
            raise InvalidInputError(f"{name} must be a real array, got dtype {x.dtype}")
        return x.astype(dtype)
    try:
        arr = np.asarray(x)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be a real array, got {x!r}") from exc
    if arr.dtype.kind not in "fiu":  # (booleans too: as eulerpoisson.solve refuses them)
        raise InvalidInputError(f"{name} must be a real array, got dtype {arr.dtype} ({x!r})")
    return jnp.asarray(arr, dtype=dtype)
