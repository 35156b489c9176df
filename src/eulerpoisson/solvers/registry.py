r"""The registry of solution methods.

Every way of computing the motion — the closed form, the Lie (Taylor)
series, symplectic integrators, scipy's Runge-Kutta — is a small
:class:`Method` subclass registered under a name (one folder per method in
:mod:`eulerpoisson.solvers`), so that one call, :func:`~eulerpoisson.solve`,
runs any of them and one test can check all of them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ..errors import InvalidInputError, UnsupportedModelError
from ..model.equations import Model
from .problem import Problem

__all__ = [
    "Method",
    "MethodResult",
    "register_method",
    "available_methods",
    "get_method",
    "methods_supporting",
    "check_supported",
]

_REGISTRY: dict[str, type["Method"]] = {}


@dataclass
class MethodResult:
    """What a method returns: states at the output times.

    Attributes
    ----------
    q : ndarray, shape (*batch_shape, T, 4)
    omega : ndarray, shape (*batch_shape, T, 3)
    stats : dict
        Method-specific counters (steps, function evaluations, chart changes...).
    """

    q: np.ndarray
    omega: np.ndarray
    stats: dict = field(default_factory=dict)


class Method:
    """Base class of a solution method.

    Subclasses set :attr:`name`, :attr:`options` (allowed keyword options with
    their defaults) and implement :meth:`run`. Options are validated on
    construction: an unknown option raises ``TypeError`` naming it.

    Class attributes
    ----------------
    name : str
        Registry key used by ``solve(..., method=name)``.
    options : dict
        Allowed options and defaults.
    order : int or None
        Nominal order of convergence (None for exact methods).
    refine : str or None
        The option that controls accuracy (``"dt"`` or ``"tol"``), used by
        the registry-driven convergence test.
    negative_times : bool
        Whether the method accepts t < 0 (time reversal).
    """

    name: ClassVar[str] = ""
    options: ClassVar[dict[str, Any]] = {}
    order: ClassVar[int | None] = None
    refine: ClassVar[str | None] = None
    negative_times: ClassVar[bool] = True
    description: ClassVar[str] = ""

    def __init__(self, **options):
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            allowed = ", ".join(sorted(self.options)) or "none"
            raise TypeError(
                f"method {self.name!r} got unknown option(s) {', '.join(unknown)}; allowed: {allowed}"
            )
        self.config = {**self.options, **options}
        self.validate()

    def validate(self) -> None:
        """Check ``self.config``; override to validate option values."""

    @classmethod
    def supports(cls, model: Model) -> str | None:
        """Why this method cannot run ``model`` (a sentence), or None when it can.

        The default: the free body only. Methods that handle torques override it.
        """
        if model.is_free:
            return None
        return f"it solves the free body only (the model has {model.describe()})"

    def nominal_order(self) -> int | None:
        """Nominal order of this configured instance (may depend on options such as ``scheme``)."""
        return self.order

    def run(self, problem: Problem) -> MethodResult:  # pragma: no cover - abstract
        raise NotImplementedError


def register_method(cls: type[Method]) -> type[Method]:
    """Class decorator: register a :class:`Method` subclass under ``cls.name``."""
    if not cls.name:
        raise ValueError("a registered method needs a name")
    _REGISTRY[cls.name] = cls
    return cls


def available_methods() -> list[str]:
    """Names accepted by ``solve(..., method=...)``."""
    return sorted(_REGISTRY)


def methods_supporting(model: Model) -> list[str]:
    """Names of the registered methods that can run ``model``."""
    return sorted(name for name, cls in _REGISTRY.items() if cls.supports(model) is None)


def check_supported(name: str, model: Model) -> None:
    """Raise :class:`~eulerpoisson.errors.UnsupportedModelError` when method ``name`` cannot run ``model``.

    Raises
    ------
    UnsupportedModelError
        Naming the method, the reason and the methods that can run the model.
    """
    reason = get_method(name).supports(model)
    if reason is None:
        return
    able = methods_supporting(model)
    hint = f"methods that can: {', '.join(able)}" if able else "no registered method can"
    raise UnsupportedModelError(f"method {name!r} cannot run this model: {reason}; {hint}")


def get_method(name: str) -> type[Method]:
    """The method class registered as ``name``.

    Raises
    ------
    InvalidInputError
        Unknown method name (the message lists the available ones).
    """
    if not isinstance(name, str) or name not in _REGISTRY:
        raise InvalidInputError(
            f"unknown method {name!r}; available methods: {', '.join(sorted(_REGISTRY))}"
        )
    return _REGISTRY[name]


