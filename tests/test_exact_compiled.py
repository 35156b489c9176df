"""The compiled (numba) path of the closed-form solution against the NumPy path.

:mod:`eulerpoisson.solvers.exact.kernels` is a scalar transcription of the NumPy
implementation in :mod:`eulerpoisson.solvers.exact.motion` (same floating-point operations
in the same order).  Independent truths used here:

* the NumPy path itself (the reference, validated against mpmath in
  ``tests/test_exact_kernel.py``), run in this process and, with
  ``EULERPOISSON_NO_NUMBA=1``, in a subprocess;
* bitwise identity where both use the same elementary functions: NumPy may
  dispatch ``exp``, ``tanh``, ``atan``, ... to its own SIMD (AVX-512) code,
  which differs from the C library by 1-3 ulp; the subprocess disables those
  dispatch targets (``NPY_DISABLE_CPU_FEATURES``) and checks that its NumPy
  then agrees with ``math`` (the C library), in which case the compiled and
  NumPy results must agree to the last bit;
* otherwise the difference is bounded by a few ulp of the intermediate
  quantities, ``|dM|/|M0|, |dq| <= 32 eps (1 + |Omega| |t|)`` (measured
  maximum 3.8 eps (1 + |Omega| |t|) on 2800 bodies of all regimes);
* batch independence: lazily computed per-body constants must not change a
  bit whatever the order and number of the times evaluated.

Measured on x86-64 (AVX-512): bitwise identical (2800 bodies x 80 times,
every regime, plus the branch-switch times) with the C library's functions;
with NumPy's SIMD functions max |dM|/|M0| = 5.9e-16, max |dq| = 3e-15 for
|t| <= 20 and 2.6e-12 at |Omega t| ~ 1e5.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np

from _limits import HANG_GUARD_S
from _markers import needs_numba
from eulerpoisson.solvers.exact import kernels as K
from eulerpoisson.solvers.exact.motion import (
    _exact_constants_compiled,
    _exact_constants_numpy,
    _exact_motion_compiled,
    _exact_motion_numpy,
    exact_constants,
    exact_motion,
)

EPS = np.finfo(np.float64).eps


# ---------------------------------------------------------------------------
# cases: every regime and the hard corners
# ---------------------------------------------------------------------------
def _near_separatrix(rng, m1_target, side):
    """Sorted random body with 1 - k^2 ~ m1_target in regime B (side=+1) or A (-1)."""
    I1, I2, I3 = np.sort(rng.uniform(1, 3, 3))
    d21, d32, d31 = I2 - I1, I3 - I2, I3 - I1
    M1, M2 = rng.normal(size=2)
    mt = m1_target
    if side > 0:  # 1 - k^2 = d31 D / (d32 a1)
        M3sq = (mt * d32 * M2**2 * d21 / I2 + d31 * M1**2 * d21 / I1) / ((1 - mt) * d31 * d32 / I3)
    else:  # 1 - k^2 = d31 (-D) / (d21 a3)
        M3sq = (M1**2 * d21 / I1 * d31 - mt * d21 * (M1**2 * d31 / I1 + M2**2 * d32 / I2)) / (d31 * d32 / I3)
    return [I1, I2, I3], [M1, M2, np.sqrt(max(M3sq, 0.0))]


def _cases(seed=0, n_random=60):
    """Bodies (inertia, M0) in random axis order and signs, covering all regimes."""
    rng = np.random.default_rng(seed)
    bodies = []

    def add(inertia, M0):
        perm = rng.permutation(3)
        sgn = rng.choice([-1.0, 1.0], 3)
        bodies.append((np.asarray(inertia, float)[perm], np.asarray(M0, float)[perm] * sgn))

    for _ in range(n_random):
        add(rng.uniform(0.1, 10, 3), rng.normal(size=3))
    for _ in range(6):  # extreme magnitudes (exact power-of-two rescaling inside)
        u = rng.uniform(-150, 150)
        add(rng.uniform(1, 3, 3) * 10.0**u, rng.normal(size=3) * 10.0 ** (u + rng.uniform(-3, 1)))
    for mt in (1e-3, 1e-8, 1e-12, 1e-14, 1e-16):
        for side in (1, -1):
            for _ in range(2):
                add(*_near_separatrix(rng, mt, side))
    add([1.0, 1.5, 3.0], [0.3, 1.0, 0.3])  # exact separatrix
    add([1.0, 1.5, 3.0], [-0.3, 0.7, 0.3])
    add([1.0, 1.5, 3.0], [0.3, 1.0, 0.3 * (1 + 2.0**-46)])  # 1 - k^2 ~ 1e-14, both sides
    add([1.0, 1.5, 3.0], [0.3, 1.0, 0.3 * (1 - 2.0**-46)])
    for a, b in ((1.3, 2.9), (2.2, 1.1)):
        add([a, a, b], rng.normal(size=3))  # symmetric tops
        add([a, b, b], rng.normal(size=3))
        add([a, a, a], rng.normal(size=3))  # sphere
        add([a, a * (1 + 1e-9), b], rng.normal(size=3))  # nearly symmetric
        add([a, a * (1 + 1e-15), b], rng.normal(size=3))
        add([a, a, b], [0.4, -0.7, 0.0])  # symmetric, M in the degenerate plane
    add([1.0, 2.0, 3.0], [0.0, -1.5, 0.0])  # unstable middle axis
    add([1.0, 2.0, 3.0], [0.0, 0.0, 2.0])
    add([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])  # at rest
    add([1.0, 2.0, 3.0], [1.0, 1e-9, -1e-9])  # near the stable axis
    add([3.0, 5.0, 9.0], [0.0, 2.0, 0.01])  # tennis racket
    add([0.01, 1.0, 1.005], [0.3, -0.4, 0.5])  # slender, slow
    inertia = np.array([b[0] for b in bodies])
    M0 = np.array([b[1] for b in bodies])
    return inertia, M0


def _times(rng):
    return np.concatenate(
        [
            [0.0, -0.0, 1e-300, -1e-300, 1e-8],
            rng.uniform(-20, 20, 24),
            rng.uniform(-1e3, 1e3, 4),
            [1e4, -1e4, 1e5, -12345.678],
        ]
    )


def _switch_times(inertia, M0):
    """Per body: times just inside/outside the near/far switch |lambda t| = K."""
    c = exact_constants(inertia, M0)
    ok = np.isfinite(c.K) & (c.lam > 0)
    tk = np.where(ok, c.K / np.where(ok, c.lam, 1.0), 1.0)
    return tk[:, None] * np.array([1 - 1e-13, 1 + 1e-13, -(1 - 1e-13), -(1 + 1e-13), 3.0, 0.5])


def _scaled_diff(inertia, M0, t, a, b):
    """max over bodies/times of |dM|/|M0| and |dq| in units of eps (1 + |Omega| |t|)."""
    om = np.max(np.abs(M0 / inertia), axis=-1)
    fac = EPS * (1.0 + om[:, None] * np.abs(t))
    norm = np.linalg.norm(M0, axis=-1)
    norm = np.where(norm > 0, norm, 1.0)[:, None]
    dM = np.max(np.abs(a.M - b.M), axis=-1) / norm
    dq = np.max(np.abs(a.q - b.q), axis=-1)
    return float(np.max(dM / fac)), float(np.max(dq / fac))


def _libm_numpy():
    """True when NumPy's elementary functions used by the kernels equal the C library's here."""
    import math

    x = np.random.default_rng(1).uniform(-6, 6, 4000)
    pos = np.abs(x)
    pairs = [
        (np.sin, math.sin, x),
        (np.cos, math.cos, x),
        (np.tanh, math.tanh, x),
        (np.exp, math.exp, x),
        (np.sinh, math.sinh, x),
        (np.cosh, math.cosh, x),
        (np.arctan, math.atan, x),
        (np.log1p, math.log1p, pos),
        (np.arcsinh, math.asinh, x),
    ]
    for nf, mf, v in pairs:
        if not np.array_equal(nf(v), np.array([mf(e) for e in v])):
            return False
    # (np.hypot is the C library's hypot; Python's math.hypot is not, so it is not compared)
    y = x[::-1].copy()
    return np.array_equal(np.arctan2(x, y), np.array([math.atan2(a, b) for a, b in zip(x, y)]))


def _assert_close(inertia, M0, t, ref, out, bitwise):
    assert np.all(np.isfinite(out.M)) and np.all(np.isfinite(out.q))
    if bitwise:
        np.testing.assert_array_equal(out.M, ref.M)
        np.testing.assert_array_equal(out.q, ref.q)
    else:
        rM, rq = _scaled_diff(inertia, M0, t, ref, out)
        assert rM <= 32.0 and rq <= 32.0, (rM, rq)


# ---------------------------------------------------------------------------
# in-process comparison
# ---------------------------------------------------------------------------
@needs_numba
def test_compiled_matches_numpy_all_regimes():
    inertia, M0 = _cases(0)
    c = exact_constants(inertia, M0)
    assert set(np.unique(c.regime)) == {0, 1, 2, 3}
    assert np.sum((c.m1 > 0) & (c.m1 < 1e-13)) >= 4
    t = _times(np.random.default_rng(2))
    ref = _exact_motion_numpy(inertia, M0, t)
    out = _exact_motion_compiled(inertia, M0, t)
    bitwise = _libm_numpy()
    _assert_close(inertia, M0, t, ref, out, bitwise)
    # the public function dispatches to the compiled path
    pub = exact_motion(inertia, M0, t)
    np.testing.assert_array_equal(pub.M, out.M)
    np.testing.assert_array_equal(pub.q, out.q)
    # both branches of the increment and the switch between them
    ts = _switch_times(inertia, M0)
    for i in range(len(inertia)):
        r = _exact_motion_numpy(inertia[i], M0[i], ts[i])
        o = _exact_motion_compiled(inertia[i], M0[i], ts[i])
        _assert_close(inertia[i : i + 1], M0[i : i + 1], ts[i], r, o, bitwise)


@needs_numba
def test_compiled_constants_match_numpy():
    inertia, M0 = _cases(3)
    ref = _exact_constants_numpy(inertia, M0)
    out = _exact_constants_compiled(inertia, M0)
    np.testing.assert_array_equal(out.regime, ref.regime)
    assert out.regime.dtype == ref.regime.dtype
    for name in ("m", "m1", "K", "lam", "tau0", "period"):
        a, b = getattr(ref, name), getattr(out, name)
        # tau0 uses asinh on the separatrix (NumPy may use its SIMD version)
        np.testing.assert_allclose(b, a, rtol=4 * EPS, atol=0, err_msg=name)
    # the public function and the batch shape
    pub = exact_constants(inertia.reshape(2, -1, 3), M0.reshape(2, -1, 3))
    assert pub.period.shape == (2, len(inertia) // 2)
    np.testing.assert_array_equal(pub.m1.ravel(), out.m1)


@needs_numba
def test_lazy_constants_do_not_depend_on_batch_or_order():
    """Constants computed on first use (J_c, J(tau0), the values at tau0) give
    the same bits whether a body is evaluated at one time or many, in any order."""
    inertia, M0 = _cases(5, n_random=12)
    rng = np.random.default_rng(6)
    t = _times(rng)
    full = _exact_motion_compiled(inertia, M0, t)
    rev = _exact_motion_compiled(inertia, M0, t[::-1].copy())
    np.testing.assert_array_equal(rev.M, full.M[:, ::-1])
    np.testing.assert_array_equal(rev.q, full.q[:, ::-1])
    for j in rng.choice(len(t), 8, replace=False):
        one = _exact_motion_compiled(inertia, M0, t[j : j + 1])
        np.testing.assert_array_equal(one.M[:, 0], full.M[:, j])
        np.testing.assert_array_equal(one.q[:, 0], full.q[:, j])
    # a body alone equals its row in a batch; a broadcast batch shape
    for i in (0, 7, len(inertia) - 1):
        alone = _exact_motion_compiled(inertia[i], M0[i], t)
        np.testing.assert_array_equal(alone.M, full.M[i])
        np.testing.assert_array_equal(alone.q, full.q[i])
    M, q = exact_motion(inertia[:3][:, None, :], M0[:2][None, :, :], t[:5])
    assert M.shape == (3, 2, 5, 3) and q.shape == (3, 2, 5, 4)
    np.testing.assert_array_equal(M[2, 1], _exact_motion_compiled(inertia[2], M0[1], t[:5]).M)
    # empty inputs
    assert exact_motion(inertia, M0, np.zeros(0)).M.shape == (len(inertia), 0, 3)
    assert exact_motion(np.zeros((0, 3)) + 1.0, np.zeros((0, 3)), t).q.shape == (0, len(t), 4)
    # read-only, broadcast, non-contiguous and integer inputs all reuse the one compiled signature
    ro = np.broadcast_to(t[:3], (3,))
    exact_motion(np.broadcast_to(inertia[0], (2, 3)), M0[:2, ::-1], ro)
    exact_motion([1, 2, 3], [1, 0, 2], [0, 1])
    exact_constants(np.broadcast_to(inertia[0], (2, 3)), M0[:4:2])
    assert len(K.motion_kernel.signatures) == 1
    assert len(K.constants_kernel.signatures) == 1


# ---------------------------------------------------------------------------
# the fallback (EULERPOISSON_NO_NUMBA=1) in a subprocess
# ---------------------------------------------------------------------------
_SCRIPT = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    sys.path.insert(0, sys.argv[3])
    from test_exact_compiled import _libm_numpy
    from eulerpoisson.solvers.exact import kernels as K
    from eulerpoisson.solvers.exact.motion import exact_motion, exact_constants
    d = np.load(sys.argv[1])
    inertia, M0, t = d["inertia"], d["M0"], d["t"]
    res = exact_motion(inertia, M0, t)
    c = exact_constants(inertia, M0)
    # the plain-Python kernels (what numba compiles), a few bodies and times
    sub = [0, 3, len(inertia) - 1]
    Mp = np.empty((len(sub), 4, 3))
    qp = np.empty((len(sub), 4, 4))
    K.motion_kernel(np.ascontiguousarray(inertia[sub]), np.ascontiguousarray(M0[sub]),
                    np.ascontiguousarray(t[[2, 7, 9, -3]]), Mp, qp)
    np.savez(sys.argv[2], M=res.M, q=res.q, m1=c.m1, Mp=Mp, qp=qp)
    print(json.dumps({"use_numba": K.USE_NUMBA, "libm": bool(_libm_numpy())}))
    """
)


def _numpy_libm_env():
    """Environment for the subprocess: numba off, NumPy's SIMD dispatch targets off."""
    env = dict(os.environ, EULERPOISSON_NO_NUMBA="1")
    try:
        from numpy._core import _multiarray_umath as mu
    except ImportError:  # pragma: no cover - numpy < 2
        from numpy.core import _multiarray_umath as mu
    found = [f for f in getattr(mu, "__cpu_dispatch__", []) if getattr(mu, "__cpu_features__", {}).get(f)]
    if found:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(found)
    return env


@needs_numba
def test_numpy_fallback_in_subprocess_matches(tmp_path):
    inertia, M0 = _cases(8, n_random=20)
    t = _times(np.random.default_rng(9))
    np.savez(tmp_path / "in.npz", inertia=inertia, M0=M0, t=t)
    script = tmp_path / "run.py"
    script.write_text(_SCRIPT)
    proc = subprocess.run(
        [
            sys.executable,
            str(script),
            str(tmp_path / "in.npz"),
            str(tmp_path / "out.npz"),
            os.path.dirname(os.path.abspath(__file__)),
        ],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        env=_numpy_libm_env(),
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    info = json.loads(proc.stdout.strip().splitlines()[-1])
    assert info["use_numba"] is False
    d = np.load(tmp_path / "out.npz")
    out = _exact_motion_compiled(inertia, M0, t)

    class Ref:
        M = d["M"]
        q = d["q"]

    _assert_close(inertia, M0, t, Ref, out, info["libm"])
    np.testing.assert_allclose(exact_constants(inertia, M0).m1, d["m1"], rtol=4 * EPS, atol=0)
    # the plain-Python kernel functions reproduce the NumPy path bitwise (same libm)
    sub = [0, 3, len(inertia) - 1]
    cols = [2, 7, 9, len(t) - 3]
    np.testing.assert_array_equal(d["Mp"], d["M"][sub][:, cols])
    np.testing.assert_array_equal(d["qp"], d["q"][sub][:, cols])
