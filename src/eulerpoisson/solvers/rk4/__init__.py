"""``method="rk4"``: the classical fourth-order Runge-Kutta method with a fixed step (:mod:`.method`)."""

from .method import RK4, RK4Options, RK4Stepper

__all__ = ["RK4", "RK4Options", "RK4Stepper"]
