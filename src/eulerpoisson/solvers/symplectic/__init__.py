"""``method="symplectic"``: Gauss-Legendre collocation and Lie-Poisson splitting (:mod:`.method`, numba lanes in :mod:`.kernels`)."""

from .method import Symplectic

__all__ = ["Symplectic"]
