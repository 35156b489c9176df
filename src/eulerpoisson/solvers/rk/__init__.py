"""``method="rk"``: scipy's solve_ivp on the model's equations (:mod:`.method`)."""

from .method import RK

__all__ = ["RK"]
