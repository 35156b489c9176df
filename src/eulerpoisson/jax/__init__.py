"""eulerpoisson in JAX: the exact free motion, the Lagrange top and torque integrators as pure,
differentiable, jit-compiled and vectorizable functions (``pip install 'eulerpoisson[jax]'``).

- :func:`exact_motion`: the free rigid body in closed form (any inertia tensor, every regime);
- :func:`lagrange_top_motion`: the heavy symmetric top in closed form;
- :func:`integrate`: the exact-flow splitting (order 2 or 4) under any torque of :mod:`.torques`
  (``from_torque`` converts an ``ep.torques`` object), a ``lax.scan``;
- float64 by default (:mod:`.precision`), ``dtype=jnp.float32`` on request.

Every function is ``jit``-able, ``vmap``-able and differentiable with respect to every input.
"""

from __future__ import annotations

from ..errors import require

require("jax", "jax")

from . import torques  # noqa: E402
from .exact import exact_motion  # noqa: E402
from .lagrange import lagrange_top_motion  # noqa: E402
from .precision import float64_by_default, resolve_dtype, x64_enabled  # noqa: E402
from .splitting import SplittingResult, integrate  # noqa: E402
from .torques import from_torque  # noqa: E402

__all__ = [
    "exact_motion",
    "lagrange_top_motion",
    "integrate",
    "SplittingResult",
    "torques",
    "from_torque",
    "float64_by_default",
    "resolve_dtype",
    "x64_enabled",
]
