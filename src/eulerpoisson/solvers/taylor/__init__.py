"""``method="taylor"``: the paper's Lie series as an arbitrary-order Taylor integrator (:mod:`.method`, numba kernels in :mod:`.kernels`)."""

from .method import Taylor

__all__ = ["Taylor"]
