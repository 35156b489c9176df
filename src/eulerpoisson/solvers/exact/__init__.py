"""``method="exact"``: the closed form (:mod:`.motion`, numba twins in :mod:`.kernels`), registered by :mod:`.method`."""

from .method import Exact

__all__ = ["Exact"]
