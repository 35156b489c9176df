"""The compiled kernels of the symplectic method against the NumPy path and independent truth.

Truth: mpmath (the sine and cosine), the step schedule of ``_charts.run_fixed_step``,
the NumPy path itself (same operations: results equal bit for bit), the NumPy path in a
subprocess with ``EULERPOISSON_NO_NUMBA=1``, each body of a batch solved alone, and the
integrals of motion of large batches.
"""

import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from _limits import HANG_GUARD_S
from _markers import needs_numba
from eulerpoisson import EulerPoissonError
from eulerpoisson.solvers import charts as ch
from eulerpoisson.solvers import solve
from eulerpoisson.solvers.symplectic import kernels as K

I3 = np.array([1.0, 2.0, 3.0])
W0 = np.array([1.0, 0.3, 0.6])
FULL = [[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]]
COMPILED_SCHEMES = ["splitting", "splitting4", "gauss2", "gauss4", "gauss6"]
# unsorted, negative, zero and repeated output times
TIMES = np.array([0.7, -0.45, 0.0, 1.3, 1.3, -1.2, 0.05])


def random_batch(rng, B, scale=1.5):
    w0 = rng.normal(size=(B, 3)) * scale
    q0 = rng.normal(size=(B, 4))
    q0 /= np.linalg.norm(q0, axis=1, keepdims=True)
    return w0, q0


def numpy_path(monkeypatch):
    """Make Symplectic.run take the NumPy path in this process."""
    monkeypatch.setattr(K, "USE_NUMBA", False)


# ---------------------------------------------------------------------------
# sin and cos
# ---------------------------------------------------------------------------
def test_sincos_against_mpmath(rng):
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 40
    x = np.concatenate(
        [
            rng.uniform(-4, 4, 600),
            rng.uniform(-1e3, 1e3, 200),
            rng.uniform(-5e5, 5e5, 200),  # still reduced by Cody-Waite
            rng.uniform(5.3e5, 1e8, 50) * rng.choice([-1, 1], 50),  # libm
            np.arange(-40, 41) * (np.pi / 4),  # quadrant boundaries
            rng.uniform(-1e-4, 1e-4, 50),
        ]
    )
    s, c = K.sincos_numpy(x)
    for val, f in ((s, mpmath.sin), (c, mpmath.cos)):
        exact = np.array([float(f(mpmath.mpf(float(v)))) for v in x])
        err = np.array([float(abs(mpmath.mpf(float(a)) - f(mpmath.mpf(float(v))))) for a, v in zip(val, x)])
        # 1.5 ulp of max(|value|, 1/2), measured 1.45; relative 1.5 ulp without reduction
        assert np.max(err / np.spacing(np.maximum(np.abs(exact), 0.5))) < 1.6
        small = np.abs(x) <= np.pi / 4
        assert np.max(err[small] / np.spacing(np.abs(exact[small]))) < 1.6


def test_sincos_paths_bitwise(rng):
    x = np.concatenate(
        [
            rng.uniform(-10, 10, 3000),
            rng.uniform(-1e6, 1e6, 300),
            np.arange(-20, 21) * (np.pi / 4),
            [0.0, -0.0, 1e-300, 2.0**19, -(2.0**19) - 1.0, 1e12],
        ]
    )
    s, c = K.sincos_numpy(x)  # vectorized NumPy
    for k in range(0, x.size, 997):  # the Python-float path for a few values
        s1, c1 = K.sincos_numpy(x[k : k + 3])
        np.testing.assert_array_equal(s1, s[k : k + 3])
        np.testing.assert_array_equal(c1, c[k : k + 3])
    if K.USE_NUMBA:
        s2, c2 = K.sincos_compiled(x)
        np.testing.assert_array_equal(s2, s)
        np.testing.assert_array_equal(c2, c)
    # non-finite input gives NaN, not an error
    sn, cn = K.sincos_numpy(np.array([np.nan, np.inf, -np.inf, 1.0, 2.0]))
    assert np.all(np.isnan(sn[:3])) and np.all(np.isnan(cn[:3]))
    # complex input (complex-step derivatives): the analytic functions
    z = np.array([0.3 + 1e-20j, 2.0 - 0.5j])
    np.testing.assert_allclose(K.sincos_numpy(z)[0], np.sin(z), rtol=1e-15)


# ---------------------------------------------------------------------------
# the schedule
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "t,dt",
    [
        (TIMES, 0.1),
        (TIMES, 0.3),
        (np.array([3.0]), math.inf),
        (np.array([-2.0, -2.0, 0.0]), 0.7),
        (np.linspace(0.0, 1.0, 11), 0.1),  # multiples of dt up to rounding: exactly one step each
    ],
)
def test_schedule_is_the_steps_of_run_fixed_step(t, dt):
    calls = []

    def advance(state, h, n):
        calls.append((state, h, n))
        return state + 1

    ch.run_fixed_step(t, dt, 0, advance, lambda state: (np.array([[state]]),))
    h, n, out, restart, total = K.schedule(t, dt)
    assert sorted(out.tolist()) == list(range(t.size))
    assert total == sum(c[2] for c in calls) == int(n.sum())
    # the advancing segments, in order, with the same h and n
    seg = [(float(hh), int(nn)) for hh, nn in zip(h, n) if nn > 0]
    assert seg == [(c[1], c[2]) for c in calls]
    # one restart per branch (t >= 0 forwards, t < 0 backwards); within a branch the steps add up to t
    assert restart[0] == 1 and restart.sum() == int(np.any(t >= 0)) + int(np.any(t < 0))
    tt = t[out]
    reached = 0.0
    for k in range(t.size):
        if restart[k]:
            reached = 0.0
        else:
            assert (tt[k] >= 0) == (tt[k - 1] >= 0) and abs(tt[k]) >= abs(tt[k - 1])
        reached += h[k] * n[k]
        assert abs(reached - tt[k]) <= 1e-13 * max(1.0, abs(tt[k]))
        assert n[k] == 0 or abs(h[k]) <= dt * (1 + 1e-12)


# ---------------------------------------------------------------------------
# compiled == NumPy, bit for bit
# ---------------------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize("scheme", COMPILED_SCHEMES)
@pytest.mark.parametrize("body", ["diagonal", "full"])
def test_compiled_equals_numpy_bitwise(scheme, body, rng, monkeypatch):
    """19 bodies (padded lanes of 16 and 8), mixed speeds, all kinds of output times."""
    w0, q0 = random_batch(rng, 19)
    inertia = I3 if body == "diagonal" else FULL
    kw = dict(omega0=w0, attitude0=q0, method="symplectic", scheme=scheme, dt=0.04)
    fast = solve(inertia, TIMES, **kw)
    assert fast.stats["compiled"] is True
    numpy_path(monkeypatch)
    slow = solve(inertia, TIMES, **kw)
    assert slow.stats["compiled"] is False
    np.testing.assert_array_equal(fast.quaternion, slow.quaternion)
    np.testing.assert_array_equal(fast.omega, slow.omega)
    for key in ("steps", "iterations", "max_iterations", "chart_changes"):
        assert fast.stats.get(key) == slow.stats.get(key), key


@needs_numba
@pytest.mark.parametrize("scheme", COMPILED_SCHEMES)
def test_each_body_of_a_batch_as_if_alone(scheme, rng):
    """Lockstep lanes: a body's result does not depend on its neighbours (bit for bit)."""
    w0, q0 = random_batch(rng, 21, scale=3.0)
    w0[3] = 0.0  # a body at rest among fast ones
    kw = dict(method="symplectic", scheme=scheme, dt=0.05)
    tr = solve(I3, TIMES, omega0=w0, attitude0=q0, **kw)
    for i in (0, 3, 16, 20):
        one = solve(I3, TIMES, omega0=w0[i], attitude0=q0[i], **kw)
        np.testing.assert_array_equal(tr.quaternion[i], one.quaternion)
        np.testing.assert_array_equal(tr.omega[i], one.omega)


def test_no_numba_subprocess_matches(tmp_path):
    """``EULERPOISSON_NO_NUMBA=1`` selects the NumPy path, which gives the same numbers."""
    script = textwrap.dedent("""
        import json, sys
        import numpy as np
        from eulerpoisson.solvers import solve
        rng = np.random.default_rng(7)
        w0 = rng.normal(size=(11, 3)) * 1.5
        q0 = rng.normal(size=(11, 4)); q0 /= np.linalg.norm(q0, axis=1, keepdims=True)
        t = np.array(json.loads(sys.argv[2]))
        out, flags = {}, {}
        for scheme in ("splitting", "splitting4", "gauss2", "gauss4", "gauss6"):
            tr = solve([[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]], t, omega0=w0, attitude0=q0,
                       method="symplectic", scheme=scheme, dt=0.05)
            out[scheme + "_q"], out[scheme + "_w"] = tr.quaternion, tr.omega
            flags[scheme] = tr.stats["compiled"]
        np.savez(sys.argv[1], **out)
        print(json.dumps(flags))
    """)
    path = tmp_path / "numpy_path.npz"
    env = dict(os.environ, EULERPOISSON_NO_NUMBA="1")
    res = subprocess.run(
        [sys.executable, "-c", script, str(path), json.dumps(TIMES.tolist())],
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
    )
    assert res.returncode == 0, res.stderr
    flags = json.loads(res.stdout.strip().splitlines()[-1])
    assert not any(flags.values())  # the child used NumPy
    child = np.load(path)
    rng = np.random.default_rng(7)
    w0 = rng.normal(size=(11, 3)) * 1.5
    q0 = rng.normal(size=(11, 4))
    q0 /= np.linalg.norm(q0, axis=1, keepdims=True)
    for scheme in COMPILED_SCHEMES:
        tr = solve(FULL, TIMES, omega0=w0, attitude0=q0, method="symplectic", scheme=scheme, dt=0.05)
        assert tr.stats["compiled"] is K.USE_NUMBA
        dq = np.max(np.abs(tr.quaternion - child[scheme + "_q"]))
        dw = np.max(np.abs(tr.omega - child[scheme + "_w"]))
        assert dq == 0.0 and dw == 0.0, (scheme, dq, dw)


# ---------------------------------------------------------------------------
# edge cases
# ---------------------------------------------------------------------------
@needs_numba
@pytest.mark.parametrize(
    "opts",
    [
        {"t": [0.0, 100.0], "dt": 50.0},  # diverges
        {"t": [0.0, 1.0], "max_iter": 2},  # does not converge in 2 iterations
        {"t": [0.0, 1.0], "dt": 1.0, "omega0": [1e160, 2e160, 0.0]},  # overflows: non-finite stages
    ],
    ids=["diverged", "max_iter", "nonfinite"],
)
def test_failures_same_as_numpy(opts, monkeypatch):
    opts = dict(opts)
    t = opts.pop("t")
    w0 = opts.pop("omega0", W0)
    with pytest.raises(EulerPoissonError) as fast:
        solve(I3, t, omega0=np.array([w0, W0]), method="symplectic", **opts)
    numpy_path(monkeypatch)
    with np.errstate(all="ignore"), pytest.raises(EulerPoissonError) as slow:
        solve(I3, t, omega0=np.array([w0, W0]), method="symplectic", **opts)
    assert str(fast.value) == str(slow.value)
    assert "reduce dt" in str(fast.value)


@needs_numba
def test_giant_splitting_steps_use_libm(monkeypatch):
    """Rotation angles beyond 2**19 rad (0.5 h Omega_i up to 3e6): the libm branch; still exact rotations."""
    w0 = np.array([[1.0, 0.3, 0.6], [2.0, -1.0, 0.5], [0.001, 0.002, 0.0]])
    t = [1e6, -3e6]
    fast = solve(I3, t, omega0=w0, method="symplectic", scheme="splitting", dt=1e7)
    numpy_path(monkeypatch)
    slow = solve(I3, t, omega0=w0, method="symplectic", scheme="splitting", dt=1e7)
    np.testing.assert_allclose(fast.quaternion, slow.quaternion, rtol=0, atol=1e-15)
    np.testing.assert_allclose(fast.omega, slow.omega, rtol=0, atol=1e-15)
    M = fast.M
    np.testing.assert_allclose(
        np.linalg.norm(M, axis=-1), np.linalg.norm(I3 * w0, axis=-1)[:, None].repeat(2, 1), rtol=1e-14
    )
    np.testing.assert_allclose(fast.m, (I3 * w0)[:, None, :].repeat(2, 1), rtol=0, atol=1e-13)


@needs_numba
@pytest.mark.parametrize("scheme", ["splitting4", "gauss4"])
def test_large_batch_keeps_integrals(scheme, rng):
    """500 bodies x 2000 steps of 0.1 rad: m conserved to round-off, the energy error O(h^4)."""
    B = 500
    w0, q0 = random_batch(rng, B, scale=1.0)
    w0 /= np.linalg.norm(w0, axis=1, keepdims=True)
    tr = solve(FULL, np.linspace(0.0, 200.0, 5), omega0=w0, attitude0=q0, method="symplectic", scheme=scheme, dt=0.1)
    assert tr.stats["steps"] == 2000 and tr.stats["compiled"]
    m = tr.m
    # round-off only: a random walk of ~1e-16 |m| per rotation (24000 rotations for splitting4);
    # the discretization error at this step would be ~1e-5
    assert np.max(np.abs(m - m[:, :1]) / np.linalg.norm(m[:, :1], axis=-1, keepdims=True)) < 1e-13
    E = tr.energy
    rel = np.abs(E - E[:, :1]) / E[:, :1]
    assert 1e-12 < np.max(rel) < 1e-4
    np.testing.assert_allclose(np.linalg.norm(tr.quaternion, axis=-1), 1.0, atol=1e-15)
