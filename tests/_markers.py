"""Markers shared by the test modules."""

from __future__ import annotations

import pytest

from eulerpoisson.util.jit import USE_NUMBA

#: tests of the compiled kernels themselves (their code paths, their bitwise agreement with the NumPy twins):
#: skipped where numba is not installed or EULERPOISSON_NO_NUMBA=1, as then nothing is compiled and the
#: NumPy twins, which the rest of the suite exercises, are all that runs
needs_numba = pytest.mark.skipif(
    not USE_NUMBA, reason="tests the compiled kernels: numba is not installed or EULERPOISSON_NO_NUMBA=1"
)
