"""Exceptions raised by :mod:`eulerpoisson`.

Every error the package raises on bad input is a subclass of the built-in
``ValueError`` or ``TypeError`` so that generic handlers keep working, and of
:class:`EulerPoissonError` so that callers (and the command line) can catch
the package's own errors in one place.
"""

from __future__ import annotations

__all__ = [
    "EulerPoissonError",
    "InvalidInputError",
    "InvalidInertiaError",
    "SingularChartError",
    "MissingDependencyError",
]


class EulerPoissonError(Exception):
    """Base class of every exception raised by eulerpoisson."""


class InvalidInputError(EulerPoissonError, ValueError):
    """An argument has the wrong shape, a non-finite value or an out-of-range value."""


class InvalidInertiaError(InvalidInputError):
    """An inertia tensor is not symmetric, not positive definite, or violates the
    triangle inequalities ``I_i + I_j >= I_k`` of a physical body."""


class UnsupportedModelError(InvalidInputError):
    """A solution method cannot run the model (its torques); the message names the methods that can."""


class SingularChartError(EulerPoissonError, ValueError):
    """An attitude lies on the singular set of a chart.

    The global Gibbs vector ``n = k tan(alpha/2)`` is infinite at ``alpha = pi``
    (quaternion scalar part ``w = 0``). Use a quaternion or a local chart
    (:func:`eulerpoisson.attitude.gibbs_chart`) instead.
    """


class MissingDependencyError(EulerPoissonError, ImportError):
    """An optional dependency is not installed; the message names the extra."""


def require(module: str, extra: str):
    """Import an optional dependency or raise :class:`MissingDependencyError`.

    Parameters
    ----------
    module : str
        Module to import, e.g. ``"sympy"``.
    extra : str
        The package extra that installs it, e.g. ``"symbolic"``.

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    MissingDependencyError
        If the module cannot be imported; the message says
        ``pip install 'eulerpoisson[extra]'``.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:  # pragma: no cover - depends on environment
        raise MissingDependencyError(
            f"{module!r} is required for this feature; install it with "
            f"pip install 'eulerpoisson[{extra}]'"
        ) from exc
