"""The fused form of the JAX closed form (unrolled loops, masked steps: the GPU default) runs compiled here on the
CPU and gives the values of the rolled form (issue 24)."""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")

from eulerpoisson.jax import exact_motion  # noqa: E402
from eulerpoisson.jax.elliptic import fused_loops  # noqa: E402


@pytest.mark.slow
def test_fused_loops_give_the_values_of_the_rolled_loops(monkeypatch):
    rng = np.random.default_rng(4)
    mom = rng.uniform(1.0, 1.9, (5, 3))
    mom[0] = (1.0, 1.0, 1.5)  # symmetric
    w0 = rng.standard_normal((5, 3))
    w0[1] = (0.0, 1.0, 0.0)  # an equilibrium (middle axis)
    q0 = rng.standard_normal((5, 4))
    t = np.array([-3.0, 0.0, 2.5, 40.0])
    monkeypatch.setenv("EULERPOISSON_JAX_FUSED", "0")
    assert not fused_loops()
    q_r, w_r = (np.asarray(a) for a in exact_motion(mom[:, None], q0[:, None], w0[:, None], t[None, :]))
    monkeypatch.setenv("EULERPOISSON_JAX_FUSED", "1")
    assert fused_loops()
    # other input shapes than above: a new trace, which reads the setting
    q_f, w_f = (
        np.asarray(a) for a in exact_motion(mom[:, None, None], q0[:, None, None], w0[:, None, None], t[None, :, None])
    )
    q_f, w_f = q_f[:, :, 0], w_f[:, :, 0]
    np.testing.assert_allclose(q_f, q_r, rtol=0, atol=2e-14)
    np.testing.assert_allclose(w_f, w_r, rtol=0, atol=2e-14 * np.max(np.abs(w_r)))
