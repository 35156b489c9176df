"""The lane kernel of the closed form and the compiled Lagrange top against their references.

* :mod:`eulerpoisson.solvers.exact.lanes` runs sixteen evaluations in lockstep
  (SIMD) by calling the scalar kernel's helper functions lane by lane; its
  results must equal those of the scalar kernel
  (``kernels.motion_kernel_scalar``, itself checked bitwise against the NumPy
  path in ``tests/test_exact_compiled.py``) to the last bit, in both of its
  modes (one body at many times; many bodies at one time), for partial
  blocks, relative equilibria and separatrix bodies in a block of generic
  ones, and whatever the order and grouping of the work.
* :mod:`eulerpoisson.solvers.exact.lagrange_kernels` evaluates the Lagrange
  top at its output times; it must agree with the NumPy evaluation (the
  reference, checked against DOP853 and mpmath in
  ``tests/test_lagrange_top.py``) to a few ulp (NumPy's complex ``exp`` and
  its SIMD elementary functions round differently from the C library):
  measured at most 1.2 eps (1 + |t|) in the quaternion and 2.4 eps (1 + |t|)
  max|Omega| in the angular velocity over every top of
  ``tests/test_lagrange_top.py`` up to |t| = 1e4; allowed 64 eps.
"""

from __future__ import annotations

import numpy as np
import pytest

from _markers import needs_numba
from eulerpoisson.solvers.exact import kernels as K
from eulerpoisson.solvers.exact import lagrange as LG
from eulerpoisson.solvers.exact import lanes as LN
from test_exact_compiled import _cases, _switch_times, _times
from test_lagrange_top import CASES, SEPARATRIX, T_CHECK

EPS = np.finfo(np.float64).eps


def _run(kern, inertia, M0, t):
    nb, T = len(inertia), len(t)
    M = np.full((nb, T, 3), np.nan)
    q = np.full((nb, T, 4), np.nan)
    kern(np.ascontiguousarray(inertia, float), np.ascontiguousarray(M0, float), np.ascontiguousarray(t, float), M, q)
    return M, q


def _assert_same(inertia, M0, t):
    Ms, qs = _run(K.motion_kernel_scalar, inertia, M0, t)
    Ml, ql = _run(K.motion_kernel, inertia, M0, t)
    assert np.all(np.isfinite(Ml)) and np.all(np.isfinite(ql))
    np.testing.assert_array_equal(Ml, Ms)
    np.testing.assert_array_equal(ql, qs)


@needs_numba
@pytest.mark.parametrize("seed", [0, 3])
def test_lanes_equal_scalar_kernel_many_times(seed):
    """One body at many times (blocks of LANES times), every regime and corner, partial last blocks."""
    inertia, M0 = _cases(seed)
    t = _times(np.random.default_rng(seed + 1))
    assert len(t) % LN.LANES != 0
    _assert_same(inertia, M0, t)
    _assert_same(inertia, M0, t[: LN.LANES])


@needs_numba
@pytest.mark.parametrize("seed", [0, 3])
def test_lanes_equal_scalar_kernel_monte_carlo(seed):
    """Many bodies at few times (blocks of LANES bodies set up together), mixed regimes in every block."""
    inertia, M0 = _cases(seed)
    rng = np.random.default_rng(seed + 7)
    perm = rng.permutation(len(inertia))  # equilibria, separatrix and generic bodies share blocks
    inertia, M0 = inertia[perm], M0[perm]
    assert len(inertia) % LN.LANES != 0
    t = _times(rng)
    for j in range(0, len(t), 5):
        _assert_same(inertia, M0, t[j : j + 2])
    # every body at its own switch time between the near and the far branch
    sw = _switch_times(inertia, M0)
    for k in range(sw.shape[1]):
        for i in range(0, len(inertia), 9):
            _assert_same(inertia[i : i + 9], M0[i : i + 9], sw[i, k : k + 1])
    for n in (1, LN.LANES - 1, LN.LANES, LN.LANES + 1, 2 * LN.LANES + 3):
        _assert_same(inertia[:n], M0[:n], np.array([0.37, -2.5]))


@needs_numba
def test_lanes_do_not_depend_on_grouping():
    """A body gives the same bits alone, in any block, at any position, in either mode."""
    inertia, M0 = _cases(5, n_random=24)
    t = _times(np.random.default_rng(6))
    Mf, qf = _run(K.motion_kernel, inertia, M0, t)
    order = np.random.default_rng(8).permutation(len(inertia))
    Mp, qp = _run(K.motion_kernel, inertia[order], M0[order], t)
    np.testing.assert_array_equal(Mp, Mf[order])
    np.testing.assert_array_equal(qp, qf[order])
    for j in (0, 3, len(t) - 1):
        Mj, qj = _run(K.motion_kernel, inertia, M0, t[j : j + 1])  # Monte-Carlo mode
        np.testing.assert_array_equal(Mj[:, 0], Mf[:, j])
        np.testing.assert_array_equal(qj[:, 0], qf[:, j])


@needs_numba
def test_lanes_extreme_scales_and_degenerate_bodies():
    """Exponents at the ends of the range (the scalar fallback lanes), spheres, rest, principal axes."""
    rng = np.random.default_rng(11)
    inertia = np.array([[1.0, 2.0, 3.0]] * 6 + [[2.0, 2.0, 2.0], [1.0, 1.0, 3.0], [1.0, 3.0, 3.0]] * 2)
    M0 = rng.normal(size=inertia.shape)
    M0[0] *= 1e-300  # |Omega| ~ 1e-300
    M0[1] *= 1e300  # both huge: |Omega| ~ 1
    inertia[1] *= 1e300
    inertia[2] *= 1e-300  # both tiny
    M0[2] *= 1e-300
    inertia[3] *= 1e300
    M0[4] = 0.0
    M0[5] = [0.0, 1.0, 0.0]
    t = np.array([0.0, 1e-3, 0.5, -7.0, 40.0])
    _assert_same(inertia, M0, t)
    _assert_same(inertia, M0, np.concatenate([t] * 5))


# ---------------------------------------------------------------------------
# the compiled Lagrange top
# ---------------------------------------------------------------------------
def _lagrange(case, t, compiled, monkeypatch):
    monkeypatch.setattr(LG, "_use_kernel", lambda: compiled)
    return LG.lagrange_top_motion(*case, t)


ALL_TOPS = {**CASES, **SEPARATRIX}


@needs_numba
@pytest.mark.parametrize("name", sorted(ALL_TOPS))
def test_lagrange_kernel_matches_numpy(name, monkeypatch):
    case = ALL_TOPS[name]
    if name in SEPARATRIX:  # the hyperbolic point: shorter times, as in tests/test_lagrange_top.py
        t = np.concatenate([T_CHECK, np.linspace(-8.0, 8.0, 17)])
    else:
        t = np.concatenate([T_CHECK, np.linspace(-30.0, 30.0, 41), [1e3, -1e4]])
    qc, wc = _lagrange(case, t, True, monkeypatch)
    qn, wn = _lagrange(case, t, False, monkeypatch)
    # the same initial state exactly, unit quaternions, the same motion to round-off
    np.testing.assert_array_equal(qc[t == 0.0], qn[t == 0.0])
    np.testing.assert_array_equal(wc[t == 0.0], wn[t == 0.0])
    np.testing.assert_allclose(np.linalg.norm(qc, axis=-1), 1.0, rtol=0, atol=4 * EPS)
    scale = 1.0 + np.abs(t)[:, None]
    s = np.where(np.sum(qc * qn, -1) < 0, -1.0, 1.0)[:, None]
    assert np.max(np.abs(qc - s * qn) / scale) <= 64 * EPS, np.max(np.abs(qc - s * qn) / scale) / EPS
    wmax = max(1.0, float(np.max(np.abs(wn))))
    assert np.max(np.abs(wc - wn) / scale) <= 64 * EPS * wmax, np.max(np.abs(wc - wn) / scale) / EPS / wmax


@needs_numba
def test_lagrange_kernel_batch(monkeypatch):
    """A batch of tops of every regime with a shared time grid: compiled and NumPy agree, row by row."""
    cases = [CASES[k] for k in sorted(CASES)]
    cols = list(zip(*cases))
    args = [np.array(c, dtype=float) for c in cols]
    t = np.linspace(-5.0, 12.0, 23)
    qc, wc = _lagrange(args, t, True, monkeypatch)
    qn, wn = _lagrange(args, t, False, monkeypatch)
    s = np.where(np.sum(qc * qn, -1) < 0, -1.0, 1.0)[..., None]
    assert np.max(np.abs(qc - s * qn)) <= 1e-13
    assert np.max(np.abs(wc - wn)) <= 1e-12 * max(1.0, float(np.max(np.abs(wn))))
