"""Whether the numba-compiled kernels are used (private).

numba is the optional ``fast`` extra. Every compiled kernel has a pure
numpy/Python twin that gives the same results; setting the environment
variable ``EULERPOISSON_NO_NUMBA=1`` before importing eulerpoisson selects
the twins (tests use it to check that both paths agree).
"""

from __future__ import annotations

import os


def numba_wanted() -> bool:
    """True when numba is importable and ``EULERPOISSON_NO_NUMBA`` is not ``"1"``."""
    if os.environ.get("EULERPOISSON_NO_NUMBA", "") == "1":
        return False
    try:
        import numba  # noqa: F401
    except ImportError:  # pragma: no cover - depends on environment
        return False
    return True


#: decided once, when eulerpoisson is imported
USE_NUMBA = numba_wanted()
