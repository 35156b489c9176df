"""The compiled chart path of ``plot --kind gibbs`` (issue 22, item 20): it runs compiled, and equals its NumPy twin.

A run of more than 20 000 samples takes the numba kernel; it once failed to compile (an untyped helper) and the
command line reported the bug as bad input.
"""

from __future__ import annotations

import numpy as np

import eulerpoisson as ep
from _markers import needs_numba
from eulerpoisson.viz import gibbs_charts


@needs_numba
def test_the_compiled_chart_bounds_equal_the_numpy_twin():
    tr = ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 300.0, 30_001), omega0=[1.0, 0.1, 2.5])
    q = tr.quaternion
    gibbs_charts.CHART_KERNEL.clear()
    compiled = gibbs_charts.chart_bounds(q, 1.0, 4.0)
    assert gibbs_charts.CHART_KERNEL, "the compiled kernel was not used"
    assert compiled == gibbs_charts.chart_bounds_numpy(q, 1.0, 4.0)
    assert len(compiled) > 5 and compiled[0][0] == 0 and compiled[-1][1] == q.shape[0]
