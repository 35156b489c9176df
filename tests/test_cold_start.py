"""Cold and warm starts (issue 15): what ``import eulerpoisson`` and a small problem load, and ``eulerpoisson warmup``.

* ``import eulerpoisson`` imports none of numba, scipy.linalg, xarray, dask, matplotlib, sympy (a fresh
  subprocess, checked in ``sys.modules``); the kernels are made lazily (:mod:`eulerpoisson.util.jit`);
* a small problem is solved by the NumPy twins without importing numba, a large one by the compiled
  kernels; the choice is made for the whole batch (the same bits for any number of threads) and the two
  paths agree (bit for bit where NumPy uses the C library's elementary functions, to a few ulp otherwise);
* after activation the modules hold real numba dispatchers (``inline="always"`` and caching as before);
* the first ``eulerpoisson simulate`` of a small problem with an empty numba cache compiles nothing (its
  wall time is printed, never asserted);
* ``eulerpoisson warmup`` (one cheap group), ``--list``, a bad ``--only``, and without numba.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from _markers import needs_numba
from eulerpoisson.cli import main
from eulerpoisson.solvers import get_method, parallel
from eulerpoisson.solvers.problem import make_problem
from eulerpoisson.util import jit

EXE = str(Path(sys.executable).with_name("eulerpoisson"))
HEAVY = ("numba", "scipy.linalg", "xarray", "dask", "matplotlib", "sympy")


def _default_env(**extra) -> dict:
    """This process's environment with the default threshold (benchmarks/run.py, imported by a test, sets it)."""
    env = {**os.environ, **extra}
    env.pop(jit.ENV_NUMPY_BELOW, None)
    return env


@pytest.fixture(autouse=True)
def default_threshold(monkeypatch):
    monkeypatch.delenv(jit.ENV_NUMPY_BELOW, raising=False)


def _python(code: str, **env) -> dict:
    """Run ``code`` in a fresh interpreter; it prints one JSON line (the last line of stdout)."""
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_GUARD_S, env=_default_env(**env)
    )
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_import_loads_no_heavy_module():
    out = _python(
        f"import json, sys\nimport eulerpoisson\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    assert out == []


def test_small_solve_does_not_import_numba_and_large_one_does():
    code = """
import json, sys
import numpy as np
import eulerpoisson as ep
from eulerpoisson.solvers.exact import kernels as K
from eulerpoisson.util import jit
lazy = type(K.motion_kernel).__name__
small = ep.solve([1.0, 2.0, 3.0], np.linspace(0, 10, 1001), omega0=[1.0, 0.1, 0.5])
top = ep.solve([1.0, 1.0, 0.5], np.linspace(0, 10, 1001), omega0=[0.0, 0.0, 10.0],
               torque=ep.torques.Gravity(1.0, [0.0, 0.0, 0.25]), method="exact")
before = "numba" in sys.modules
large = ep.solve([1.0, 2.0, 3.0], np.linspace(0, 10, 200001), omega0=[1.0, 0.1, 0.5], workers=1)
print(json.dumps({"lazy": lazy, "small": small.stats["compiled"], "top": top.stats["compiled"], "before": before,
                  "large": large.stats["compiled"], "after": "numba" in sys.modules, "active": jit.numba_active(),
                  "dispatcher": type(K.motion_kernel).__name__, "use_numba": jit.USE_NUMBA}))
"""
    out = _python(code)
    assert out["small"] is False and out["top"] is False and out["before"] is False
    if out["use_numba"]:
        assert out["lazy"] == "LazyDispatcher"
        assert out["large"] is True and out["after"] is True and out["active"] is True
        assert out["dispatcher"] == "CPUDispatcher"  # replaced in the module by the real one
    else:
        assert out["large"] is False and out["after"] is False


@needs_numba
@pytest.mark.parametrize("torque", [False, True])
def test_numpy_and_compiled_paths_agree(monkeypatch, torque):
    """The same problem through solve on both paths: the same motion to round-off."""
    kw = dict(omega0=[[1.0, 0.1, 0.5], [-0.3, 2.0, 0.2]], attitude0=[[1.0, 0, 0, 0], [0.6, 0.0, 0.8, 0.0]])
    t = np.linspace(-5.0, 20.0, 101)
    body = [2.0, 2.0, 1.0] if torque else [1.0, 2.0, 3.0]
    if torque:
        kw["torque"] = ep.torques.Gravity(1.0, [0.0, 0.0, 0.25])
    slow = ep.solve(body, t, **kw)
    monkeypatch.setattr(jit, "NUMPY_BELOW", 0.0)
    fast = ep.solve(body, t, **kw)
    assert slow.stats["compiled"] is False and fast.stats["compiled"] is True
    scale = 1.0 + np.abs(t)[:, None]
    s = np.where(np.sum(fast.quaternion * slow.quaternion, -1) < 0, -1.0, 1.0)[..., None]
    assert np.max(np.abs(fast.quaternion - s * slow.quaternion) / scale) <= 64 * np.finfo(float).eps
    assert np.max(np.abs(fast.omega - slow.omega) / scale) <= 64 * np.finfo(float).eps * 10


@pytest.mark.parametrize("below", [0.0, np.inf])
def test_path_chosen_for_the_whole_batch(monkeypatch, below):
    """Chunks solved in threads take the path of the whole batch: the same bits for any number of workers."""
    monkeypatch.setattr(parallel, "MIN_BODIES", 1)
    monkeypatch.setattr(parallel, "MIN_WORK", 0.0)
    monkeypatch.delenv(parallel.ENV_WORKERS, raising=False)
    rng = np.random.default_rng(3)
    n = 40
    w = 2.0 * rng.standard_normal((n, 3))
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    t = np.array([0.0, 0.7, -1.3, 3.0])
    method = get_method("exact")()
    problem = make_problem([1.0, 2.0, 3.0], t, omega0=w, attitude0=q)
    # the whole batch just at the threshold: each chunk alone would be below it
    monkeypatch.setattr(jit, "NUMPY_BELOW", method.numpy_estimate(problem) if below == 0.0 else below)
    chunk = parallel.take(problem, 0, 16)
    assert method.for_batch(problem)._compiled is (jit.USE_NUMBA and below == 0.0)
    assert jit.use_compiled(method.numpy_estimate(chunk)) is False
    ref = ep.solve([1.0, 2.0, 3.0], t, omega0=w, attitude0=q, workers=1)
    for workers in (2, 3):
        tr = ep.solve([1.0, 2.0, 3.0], t, omega0=w, attitude0=q, workers=workers)
        assert tr.stats["threads"] >= 2
        assert tr.stats["compiled"] is ref.stats["compiled"]
        assert np.array_equal(tr.quaternion, ref.quaternion) and np.array_equal(tr.omega, ref.omega)


def test_a_run_in_chunks_takes_one_path(tmp_path, capsys):
    """A run of 30000 samples in segments: the whole run decides the path (compiled or NumPy), as one call does."""
    from eulerpoisson.cli.commands import CHUNKED_SAMPLES

    n = 30_000
    assert n > CHUNKED_SAMPLES
    path = tmp_path / "run.nc"
    argv = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "50", "--samples", str(n)]
    assert main([*argv, "--out", str(path), "--quiet"]) == 0
    tr = ep.Trajectory.open(path)
    one = ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 50.0, n), omega0=[1.0, 0.1, 0.5])
    assert bool(tr.stats["compiled"]) is one.stats["compiled"] is jit.USE_NUMBA
    assert np.array_equal(tr.quaternion, one.quaternion) and np.array_equal(tr.omega, one.omega)
    with jit.whole_run(n_bodies=7, n_times=n):
        assert jit.run_shape(1, 600) == (7, n) and jit.run_shape(10, 600) == (10, n)
    assert jit.run_shape(1, 600) == (1, 600)


@needs_numba
def test_lazy_dispatchers_become_real_ones():
    from numba.core.registry import CPUDispatcher

    from eulerpoisson.solvers.exact import kernels as K
    from eulerpoisson.solvers.symplectic import kernels as SK

    jit.activate()
    assert jit.numba_active()
    for f in (K.motion_kernel, K.constants_kernel, K.two_sum, SK._nb_rotate, SK.nb_gauss):
        assert isinstance(f, CPUDispatcher), f
    assert SK._nb_rotate.targetoptions.get("inline") == "always"  # options passed unchanged
    made = jit.lazy_njit(cache=False, nogil=True)(lambda x: x + 1)
    assert isinstance(made, CPUDispatcher) and made(1) == 2


@needs_numba
def test_lazy_objects_held_outside_the_package_still_compile():
    """A lazy dispatcher or intrinsic kept by other code (not replaced at activation) is typed as the real one."""
    code = """
import json
from eulerpoisson.solvers.exact import kernels as K
two_sum, sqrt_ = K.two_sum, K.fast_sqrt
kinds = [type(two_sum).__name__, type(sqrt_).__name__]
from numba import njit

@njit
def f(a, b):
    s, e = two_sum(a, b)
    return s + e + sqrt_(4.0)

print(json.dumps({"kinds": kinds, "value": f(1.0, 2.0), "python": two_sum(1.0, 2.0)}))
"""
    out = _python(code)
    assert out["kinds"] == ["LazyDispatcher", "LazyIntrinsic"]
    assert out["value"] == 5.0 and out["python"] == [3.0, 0.0]


def test_lazy_objects_before_numba():
    """Before numba is used: a lazy dispatcher says so, a lazy intrinsic runs its Python twin."""
    lazy = jit.LazyDispatcher(lambda x: x, {"cache": True})
    assert "lazy numba dispatcher" in repr(lazy) and lazy.options == {"cache": True}
    buf = jit.LazyIntrinsic(lambda typingctx, n: None, python=lambda n: np.zeros(n))(4)
    assert buf.shape == (4,) and not buf.any()
    with pytest.raises(NotImplementedError, match="not usable in Python"):
        jit.LazyIntrinsic(lambda typingctx, x: None)(1.0)


def test_first_small_simulate_with_an_empty_numba_cache(tmp_path):
    """A small problem needs no kernel: nothing is compiled into the empty cache. The time is printed only."""
    cache = tmp_path / "numba_cache"
    cache.mkdir()
    env = _default_env(NUMBA_CACHE_DIR=str(cache), EULERPOISSON_WORKERS="1")
    t0 = time.perf_counter()
    res = subprocess.run(
        [
            EXE,
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0.1,0.5",
            "--t-end",
            "10",
            "--samples",
            "1001",
            "--out",
            "x.nc",
            "--quiet",
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
    )
    wall = time.perf_counter() - t0
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "x.nc").exists()
    assert list(cache.iterdir()) == []  # no kernel compiled, none loaded
    print(f"\nfirst 'eulerpoisson simulate' (1001 samples) with an empty NUMBA_CACHE_DIR: {wall:.2f} s")


def test_warmup_command(capsys):
    assert main(["warmup", "--list"]) == 0
    listed = capsys.readouterr().out
    from eulerpoisson.util.warmup import group_names

    assert all(name in listed for name in group_names())
    assert main(["warmup", "--only", "plots"]) == 0
    out = capsys.readouterr().out
    if jit.USE_NUMBA:
        assert "  plots " in out and "1 kernel group(s) ready in" in out
    else:
        assert "nothing to compile" in out
    assert main(["warmup", "--only", "plots,nope"]) == 2
    assert "unknown kernel group(s) 'nope'" in capsys.readouterr().err


@needs_numba
def test_a_failing_group_does_not_stop_the_others(monkeypatch, capsys):
    from eulerpoisson.util import warmup as W

    def boom():
        raise RuntimeError("no compiler today\nsecond line")

    plots = next(g for g in W.GROUPS if g.name == "plots")
    monkeypatch.setattr(W, "GROUPS", (W.WarmupGroup("boom", "a broken group", boom), plots))
    assert main(["warmup", "-j", "1"]) == 2
    out, err = capsys.readouterr()
    assert "boom             FAILED: RuntimeError: no compiler today" in out and "second line" not in out
    assert "  plots " in out and "1 kernel group(s) ready" in out
    assert "warm-up of the kernel group(s) boom failed" in err


def test_threshold_from_the_environment(monkeypatch):
    monkeypatch.setenv(jit.ENV_NUMPY_BELOW, "0")
    assert jit.numpy_below() == 0.0 and jit.use_compiled(1e-9) is jit.USE_NUMBA
    monkeypatch.setenv(jit.ENV_NUMPY_BELOW, "1e9")
    assert jit.use_compiled(10.0) is False
    for bad in ("-1", "fast", "nan"):
        monkeypatch.setenv(jit.ENV_NUMPY_BELOW, bad)
        with pytest.raises(ep.InvalidInputError, match="EULERPOISSON_NUMPY_BELOW must be a number of seconds"):
            ep.solve([1.0, 2.0, 3.0], [1.0], omega0=[1.0, 0.1, 0.5])


def test_warmup_without_numba():
    res = subprocess.run(
        [EXE, "warmup"],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        env=_default_env(EULERPOISSON_NO_NUMBA="1"),
    )
    assert res.returncode == 0, res.stderr
    assert "nothing to compile" in res.stdout
