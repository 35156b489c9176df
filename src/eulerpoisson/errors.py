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
    "UnsupportedModelError",
    "SingularChartError",
    "MissingDependencyError",
    "UsageError",
    "OutputError",
    "FitInputError",
    "PoorFitError",
    "AuditError",
]


class EulerPoissonError(Exception):
    """Base class of every exception raised by eulerpoisson.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> issubclass(ep.InvalidInputError, ep.EulerPoissonError), issubclass(ep.InvalidInputError, ValueError)
    (True, True)
    >>> try:
    ...     ep.RigidBody([1.0, 2.0, 0.0])
    ... except ep.EulerPoissonError as err:                           # every error of the package
    ...     print(type(err).__name__)
    InvalidInertiaError
    """


class InvalidInputError(EulerPoissonError, ValueError):
    """An argument has the wrong shape, a non-finite value or an out-of-range value.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> try:
    ...     ep.solve([1.0, 2.0, 2.5], [0.0, 1.0], omega0=[1.0, 0.1])
    ... except ep.InvalidInputError as err:
    ...     print(err)
    omega0 must have shape (..., 3), got shape (2,)
    >>> issubclass(ep.InvalidInputError, ValueError)
    True
    """


class InvalidInertiaError(InvalidInputError):
    """An inertia tensor is not symmetric, not positive definite, or violates the
    triangle inequalities ``I_i + I_j >= I_k`` of a physical body.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> try:
    ...     ep.RigidBody([3.0, 5.0, 9.0])                              # 3 + 5 < 9: no mass distribution
    ... except ep.InvalidInertiaError as err:
    ...     print(err)
    inertia violates the triangle inequality I1 + I2 >= I3 of a physical body: principal moments [3.0, 5.0, 9.0] ...
    >>> ep.RigidBody([3.0, 5.0, 9.0], allow_unphysical=True).kind
    'asymmetric'
    """


class UnsupportedModelError(InvalidInputError):
    """A solution method cannot run the model (its torques); the message names the methods that can.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> def damping(t, q, omega):
    ...     return -0.1 * omega
    >>> try:
    ...     ep.solve([1.0, 2.0, 2.5], [1.0], omega0=[1.0, 0.1, 0.5], torque=damping, method="taylor")
    ... except ep.UnsupportedModelError as err:
    ...     print(err)
    method 'taylor' cannot run this model: ...; methods that can: rk, rk4
    """


class SingularChartError(EulerPoissonError, ValueError):
    """An attitude lies on the singular set of a chart.

    The global Gibbs vector ``n = k tan(alpha/2)`` is infinite at ``alpha = pi``
    (quaternion scalar part ``w = 0``). Use a quaternion or a local chart
    (:func:`eulerpoisson.attitude.gibbs_chart`) instead.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> a = ep.Attitude([0.0, 1.0, 0.0, 0.0])                        # 180 degrees about x
    >>> try:
    ...     a.as_gibbs()
    ... except ep.SingularChartError as err:
    ...     print(err)
    the attitude has rotation angle alpha = pi (quaternion w = 0), where the global Gibbs vector
    n = k tan(alpha/2) is infinite; ...
    >>> print(a.as_chart([0.0, 1.0, 0.0, 0.0]))                      # a chart centred there: n = 0
    [0. 0. 0.]
    """


class MissingDependencyError(EulerPoissonError, ImportError):
    """An optional dependency is not installed; the message names the extra.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.errors import require
    >>> try:
    ...     require("no_such_module_here", "plot")
    ... except ep.MissingDependencyError as err:
    ...     print(err)
    'no_such_module_here' is required for this feature; install it with pip install 'eulerpoisson[plot]'
    """


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
            f"{module!r} is required for this feature; install it with pip install 'eulerpoisson[{extra}]'"
        ) from exc


class UsageError(EulerPoissonError, ValueError):
    """Bad command-line input (exit status 2)."""


class AuditError(EulerPoissonError, RuntimeError):
    """Internal inconsistency of the audit (e.g. exact and random-point verdicts disagree)."""


class FitInputError(InvalidInputError):
    """Observations or options that a fit cannot use (a ValueError).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.estimation import FitInputError
    >>> try:
    ...     ep.fit([0.0, 1.0, 2.0])                                    # no observations at all
    ... except FitInputError as err:
    ...     print(err)
    no observations: give attitude, omega or axis_direction (rows of NaN are missing ones)
    >>> issubclass(FitInputError, ValueError)
    True
    """


class OutputError(EulerPoissonError, FileExistsError):
    """An output that may not be written: it exists (no overwrite), is an input, is of another kind, or is locked."""


class PoorFitError(FitInputError):
    """A fit far from its data: the reduced chi2 is absurd, or a converted reading of the data fits far better.

    Raised by :func:`eulerpoisson.fit` unless ``accept_poor_fit=True`` (the
    command line: ``--accept-poor-fit``). ``result`` holds the
    :class:`~eulerpoisson.estimation.FitResult` that was refused, and
    ``result.convention_hint`` the reading that fits better, if any.

    Examples
    --------
    >>> import eulerpoisson as ep
    >>> from eulerpoisson.errors import FitInputError, PoorFitError
    >>> issubclass(PoorFitError, FitInputError), issubclass(PoorFitError, ValueError)
    (True, True)
    """

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result


class PrecisionError(EulerPoissonError, TypeError):
    """A JAX function of :mod:`eulerpoisson.jax` was traced without 64-bit floats and no ``dtype`` was chosen.

    The functions of :mod:`eulerpoisson.jax` compute in float64 by default. Called eagerly they
    enable 64-bit floats for themselves; inside a user's ``jit``/``grad``/``vmap`` they cannot, and
    say how: ``jax.config.update("jax_enable_x64", True)`` (or ``with jax.enable_x64(True):``), or
    ``dtype=jnp.float32`` for single precision.

    Examples
    --------
    >>> from eulerpoisson.errors import PrecisionError
    >>> issubclass(PrecisionError, TypeError)
    True
    """
