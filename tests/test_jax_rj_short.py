"""Carlson's ``R_J`` in JAX (issue 24).

* The short loop of the fused (GPU) form: in a large batch most elements take fewer duplication steps, with the
  closed forms of ``R_C`` in the first steps only, and the few that need more are recomputed by the full loop.
  Checked against mpmath (40 digits, independent code) element by element, when the redone elements fit the
  buffer and when they do not, and an element's bits do not depend on the rest of the batch.
* The public ``elliprj`` converges or says so: widely spread arguments (``p`` far above ``x, y, z``, where the
  duplication shrinks ``p`` only 4-fold per step) take more steps when concrete, NaN when traced, never a wrong
  number.
"""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")
mpmath = pytest.importorskip("mpmath")

from eulerpoisson.errors import InvalidInputError  # noqa: E402
from eulerpoisson.jax.elliptic import elliprj, rj  # noqa: E402

N = 4096  # above the size where the short loop is taken


def _mp_rj(x, y, z, p):
    with mpmath.workdps(40):
        return np.array([float(mpmath.elliprj(*map(mpmath.mpf, a))) for a in zip(x, y, z, p)])


def _args(seed, x_low, p_low, p_high):
    rng = np.random.default_rng(seed)
    x = 10.0 ** rng.uniform(x_low, 0.0, N)
    y = 10.0 ** rng.uniform(x_low, 0.0, N)
    p = 10.0 ** rng.uniform(p_low, p_high, N)
    return x, y, np.ones(N), p


@pytest.mark.slow
def test_short_rj_loop_matches_mpmath_whatever_the_batch(monkeypatch):
    monkeypatch.setenv("EULERPOISSON_JAX_FUSED", "1")
    with jax.enable_x64(True):
        f = jax.jit(rj)
        # about 4 % of the elements redone (fit the buffer of 1/16), then about 80 % (the whole batch again)
        for x_low, p_low, p_high in ((-3.0, -2.0, 1.0), (0.0, 0.5, 6.0)):
            x, y, z, p = _args(5, x_low, p_low, p_high)
            got = np.asarray(f(x, y, z, p))
            pick = np.random.default_rng(1).choice(N, 200, replace=False)
            np.testing.assert_allclose(got[pick], _mp_rj(x[pick], y[pick], z[pick], p[pick]), rtol=4e-15, atol=0)
            # an element's value does not depend on the rest of the batch: the same bits in another batch
            other = _args(6, -12.0, -6.0, 2.0)
            mixed = [np.concatenate([a[: N // 2], b[N // 2 :]]) for a, b in zip((x, y, z, p), other)]
            np.testing.assert_array_equal(np.asarray(f(*mixed))[: N // 2], got[: N // 2])


def test_public_elliprj_converges_or_says_so():
    x = np.array([1e-3, 1.0, 2.0, 0.5])
    p = np.array([1e12, 1e-9, 1e100, 1e20])
    got = np.asarray(elliprj(x, x + 1.0, x + 2.0, p))
    np.testing.assert_allclose(got, _mp_rj(x, x + 1.0, x + 2.0, p), rtol=1e-14, atol=0)
    with jax.enable_x64(True):
        traced = np.asarray(jax.jit(lambda p: elliprj(x, x + 1.0, x + 2.0, p))(p))
    np.testing.assert_allclose(traced[[0, 1, 3]], got[[0, 1, 3]], rtol=1e-15)
    assert np.isnan(traced[2]), traced  # too far apart for the fixed steps: NaN, not a wrong number
    with pytest.raises(InvalidInputError, match=r"elliprj: the arguments are too far apart .* 480 steps"):
        elliprj(1.0, 2.0, 3.0, 1e300)
