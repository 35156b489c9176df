"""Batches solved in threads (``solve(..., workers=)``, :mod:`eulerpoisson.solvers.parallel`).

The results must be the same, bit for bit, for every number of workers: checked for exact (free body, full
tensors, Lagrange top), taylor (free, under gravity) and symplectic (Gauss, splitting, exact splitting under
gravity) on batches of odd sizes, with the thresholds lowered so that even small batches are split. No
wall-clock time is asserted: that the chunks really run at the same time is checked with a barrier that
two threads must reach together.

Equality is of the bits (:func:`_same_bits`: every value and the sign of every zero; the exact method decides
once for the whole batch whether the body frame is the principal frame, so a chunk of diagonal bodies in a
batch that has full tensors takes the batch's path).
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.errors import EulerPoissonError, InvalidInputError
from eulerpoisson.solvers import get_method, parallel
from eulerpoisson.util.jit import USE_NUMBA

SIZES = (1, 5, 17, 33, 100)
WORKERS = (2, 3, 7)
TIMES = np.array([0.0, 0.7, -1.3, 3.0])


def _same_bits(a, b) -> bool:
    """The same shape and the same bits (``np.array_equal`` would take -0.0 == +0.0)."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.fixture
def split_everything(monkeypatch):
    """Split every batch of two lane groups or more (the real thresholds keep small batches on one thread), and
    solve these small batches with the compiled kernels (their NumPy twins: tests/test_cold_start.py)."""
    from eulerpoisson.util import jit

    monkeypatch.setattr(parallel, "MIN_BODIES", 1)
    monkeypatch.setattr(parallel, "MIN_WORK", 0.0)
    monkeypatch.setattr(jit, "NUMPY_BELOW", 0.0)
    monkeypatch.delenv(parallel.ENV_WORKERS, raising=False)


def _unit_quaternions(rng, n):
    q = rng.standard_normal((n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _tensors(rng, n):
    """Random physical inertia tensors in random body frames."""
    m = rng.uniform(1.0, 2.0, (n, 3))
    m[:, 2] = m[:, 0] + m[:, 1] - 0.5 * rng.uniform(size=n)
    a = rng.standard_normal((n, 3, 3))
    Q, _ = np.linalg.qr(a)
    return np.einsum("bij,bj,bkj->bik", Q, m, Q)


def _cases(n):
    rng = np.random.default_rng(1000 + n)
    w = 2.0 * rng.standard_normal((n, 3))
    q = _unit_quaternions(rng, n)
    top = ep.torques.Gravity(
        mass=rng.uniform(0.5, 2.0, n), center_of_mass=np.c_[np.zeros((n, 2)), rng.uniform(-0.5, 0.5, n)]
    )
    heavy = ep.torques.Gravity(mass=rng.uniform(0.5, 2.0, n), center_of_mass=rng.uniform(-0.5, 0.5, (n, 3)))
    tensors = _tensors(rng, n)
    # diagonal tensors among full ones: the body frame is principal for some bodies only; the first half
    # diagonal, so that a chunk may hold diagonal bodies only, and some rates with signed zeros
    mixed = tensors.copy()
    half = (n + 1) // 2
    mixed[:half] = np.einsum("bi,ij->bij", np.diagonal(tensors[:half], axis1=1, axis2=2), np.eye(3))
    w[::3, 1] = -0.0
    return (
        {
            "exact-free": dict(body=[1.0, 2.0, 3.0], method="exact"),
            "exact-tensors": dict(body=tensors, method="exact"),
            "exact-mixed-frames": dict(body=mixed, method="exact"),
            "exact-lagrange-top": dict(body=[2.0, 2.0, 1.0], torque=top, method="exact"),
            "taylor-free": dict(body=[1.0, 2.0, 3.0], method="taylor"),
            "taylor-tensors": dict(body=tensors, method="taylor"),
            "taylor-mixed-frames": dict(body=mixed, method="taylor"),
            "taylor-gravity": dict(body=[1.0, 2.0, 3.0], torque=heavy, method="taylor"),
            "symplectic-gauss4": dict(body=[1.0, 2.0, 3.0], method="symplectic"),
            "symplectic-tensors": dict(body=tensors, method="symplectic"),
            "symplectic-mixed-frames": dict(body=mixed, method="symplectic"),
            "symplectic-splitting4": dict(body=[1.0, 2.0, 3.0], method="symplectic", scheme="splitting4"),
            "symplectic-gravity": dict(body=[1.0, 2.0, 3.0], torque=heavy, method="symplectic"),
        },
        w,
        q,
    )


CASE_NAMES = list(_cases(1)[0])


@pytest.mark.parametrize("name", CASE_NAMES)
@pytest.mark.parametrize("n", SIZES)
def test_bitwise_identical_for_any_number_of_workers(split_everything, name, n):
    cases, w, q = _cases(n)
    kw = dict(cases[name])
    body = kw.pop("body")
    ref = ep.solve(body, TIMES, omega0=w, attitude0=q, workers=1, **kw)
    assert ref.stats["threads"] == 1
    for workers in WORKERS:
        tr = ep.solve(body, TIMES, omega0=w, attitude0=q, workers=workers, **kw)
        assert _same_bits(tr.quaternion, ref.quaternion), (name, n, workers)
        assert _same_bits(tr.omega, ref.omega), (name, n, workers)
        expected = 1 if n <= parallel.CHUNK_ALIGN or (name.startswith("taylor") and not USE_NUMBA) else None
        if expected is not None:
            assert tr.stats["threads"] == expected
        else:
            assert 2 <= tr.stats["threads"] <= workers


def test_counters_add_up_and_maxima_stay(split_everything):
    cases, w, q = _cases(100)
    one = ep.solve([1.0, 2.0, 3.0], [0.0, 5.0], omega0=w, method="taylor", workers=1)
    many = ep.solve([1.0, 2.0, 3.0], [0.0, 5.0], omega0=w, method="taylor", workers=3)
    for key in ("steps", "steps_max", "chart_changes", "max_order", "backend"):
        assert many.stats[key] == one.stats[key], key
    one = ep.solve([1.0, 2.0, 3.0], [0.0, 5.0], omega0=w, method="symplectic", workers=1)
    many = ep.solve([1.0, 2.0, 3.0], [0.0, 5.0], omega0=w, method="symplectic", workers=3)
    for key in ("dt", "steps", "iterations", "max_iterations", "scheme"):
        assert many.stats[key] == one.stats[key], key
    one = ep.solve([1.0, 2.0, 3.0], TIMES, omega0=w, method="exact", workers=1)
    many = ep.solve([1.0, 2.0, 3.0], TIMES, omega0=w, method="exact", workers=3)
    assert many.stats["evaluations"] == one.stats["evaluations"] == 100 * TIMES.size
    assert many.stats["threads"] == 3 and one.stats["threads"] == 1


def test_batches_of_several_axes_and_shared_parameters(split_everything):
    """Bodies (25,), initial states (4, 25), torque parameters (4, 1): chunks cut across the axes."""
    rng = np.random.default_rng(7)
    moments = rng.uniform(1.0, 2.0, (25, 3))
    moments[:, 2] = moments[:, 0] + moments[:, 1] - 0.3
    w = rng.standard_normal((4, 25, 3))
    q = _unit_quaternions(rng, 100).reshape(4, 25, 4)
    g = ep.torques.Gravity(mass=rng.uniform(0.5, 1.5, (4, 1)), center_of_mass=[0.1, -0.2, 0.3])
    body = ep.RigidBody.from_moments(moments)
    for method, torque in (("exact", None), ("taylor", None), ("taylor", g), ("symplectic", g)):
        ref = ep.solve(body, TIMES, omega0=w, attitude0=q, torque=torque, method=method, workers=1)
        tr = ep.solve(body, TIMES, omega0=w, attitude0=q, torque=torque, method=method, workers=3)
        assert tr.quaternion.shape == (4, 25, TIMES.size, 4)
        assert _same_bits(tr.quaternion, ref.quaternion), method
        assert _same_bits(tr.omega, ref.omega), method
        if method != "taylor" or USE_NUMBA:
            assert tr.stats["threads"] == 3


def test_chunks_run_in_concurrent_threads(split_everything, monkeypatch):
    """Two chunks, two workers: both threads are inside the method at once (a barrier both must reach)."""
    cls = get_method("exact")
    original = cls.run
    barrier = threading.Barrier(2, timeout=HANG_GUARD_S)  # a guard against a hang, not a timing
    seen = set()
    lock = threading.Lock()

    def run(self, problem):
        with lock:
            seen.add(threading.get_ident())
        barrier.wait()
        return original(self, problem)

    monkeypatch.setattr(cls, "run", run)
    w = np.random.default_rng(3).standard_normal((32, 3))
    tr = ep.solve([1.0, 2.0, 3.0], TIMES, omega0=w, workers=2)
    assert tr.stats["threads"] == 2
    assert len(seen) == 2  # the calling thread and one thread of the pool


def test_errors_are_those_of_one_thread(split_everything):
    rng = np.random.default_rng(11)
    w = rng.standard_normal((40, 3))
    w[29] *= 50.0  # body 29 needs far more steps than the others
    kw = dict(method="taylor", max_steps=300)
    with pytest.raises(EulerPoissonError) as one:
        ep.solve([1.0, 2.0, 3.0], [10.0], omega0=w, workers=1, **kw)
    with pytest.raises(EulerPoissonError) as many:
        ep.solve([1.0, 2.0, 3.0], [10.0], omega0=w, workers=3, **kw)
    assert type(many.value) is type(one.value)
    assert str(many.value) == str(one.value)
    assert "29" in str(one.value)
    # the exact method's phase check names the body by its index in a batch of two axes
    w2 = rng.standard_normal((2, 20, 3))
    w2[1, 7] = [1e12, 0.0, 0.0]
    with pytest.raises(InvalidInputError) as one:
        ep.solve([1.0, 2.0, 3.0], [0.0, 1e3], omega0=w2, workers=1)
    with pytest.raises(InvalidInputError) as many:
        ep.solve([1.0, 2.0, 3.0], [0.0, 1e3], omega0=w2, workers=4)
    assert str(many.value) == str(one.value)


@pytest.mark.parametrize("bad", [0, -2, 2.5, 2.0, "2", True, np.True_, [2]])
def test_invalid_workers_are_refused_by_name(bad):
    kind = InvalidInputError if isinstance(bad, int) and not isinstance(bad, bool) else TypeError
    with pytest.raises(kind, match="workers"):
        ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], workers=bad)


def test_workers_accepts_numpy_integers_and_none(monkeypatch):
    monkeypatch.delenv(parallel.ENV_WORKERS, raising=False)
    a = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], workers=np.int64(2))
    b = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], workers=None)
    assert _same_bits(a.quaternion, b.quaternion)
    assert a.stats["threads"] == 1  # one body: never worth a thread pool


def test_default_from_the_environment(monkeypatch):
    monkeypatch.setenv(parallel.ENV_WORKERS, "3")
    assert parallel.resolve_workers(None) == 3
    assert parallel.resolve_workers(5) == 5  # the argument wins
    for bad in ("0", "-2", "two", "1.5"):
        monkeypatch.setenv(parallel.ENV_WORKERS, bad)
        with pytest.raises(InvalidInputError, match=parallel.ENV_WORKERS):
            ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
    monkeypatch.delenv(parallel.ENV_WORKERS)
    assert parallel.resolve_workers(None) == parallel.available_cores() >= 1


def test_unknown_keyword_hint_knows_workers():
    with pytest.raises(TypeError, match="workers"):
        ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], worker=2)


def test_chunk_plan():
    assert parallel.plan_chunks(1000, 1, 10.0) is None  # one worker
    assert parallel.plan_chunks(parallel.MIN_BODIES - 1, 8, 10.0) is None  # few bodies
    assert parallel.plan_chunks(10_000, 8, parallel.MIN_WORK / 2) is None  # little work
    for n, workers, work in ((10_000, 2, 1.0), (1000, 7, 0.05), (33, 2, 1.0), (100_001, 16, float("inf"))):
        bounds = parallel.plan_chunks(n, workers, work)
        assert bounds[0][0] == 0 and bounds[-1][1] == n
        assert all(b == c for (_, b), (c, _) in zip(bounds[:-1], bounds[1:]))
        assert all(a % parallel.CHUNK_ALIGN == 0 and b > a for a, b in bounds)
        assert workers <= len(bounds) or len(bounds) == -(-n // parallel.CHUNK_ALIGN)
        assert len(bounds) <= parallel.CHUNKS_PER_WORKER * workers


def test_rk_and_extended_precision_stay_on_one_thread(split_everything):
    w = np.random.default_rng(5).standard_normal((40, 3))
    tr = ep.solve([1.0, 2.0, 3.0], [0.0, 0.5], omega0=w, method="rk", workers=4)
    assert tr.stats["threads"] == 1
    tr = ep.solve([1.0, 2.0, 3.0], [0.0, 0.5], omega0=w[:20], method="taylor", precision="longdouble", workers=4)
    assert tr.stats["threads"] == 1


def test_an_invalid_output_fails_as_on_one_thread(split_everything, monkeypatch):
    """A method whose output the trajectory refuses (a zero quaternion, NaN): the error of workers=1."""
    from dataclasses import dataclass

    from eulerpoisson.solvers import registry
    from eulerpoisson.solvers.registry import Method, MethodOptions, MethodResult

    @dataclass(frozen=True)
    class BrokenOptions(MethodOptions):
        method = "broken-for-test"

    class Broken(Method):
        name = "broken-for-test"
        Options = BrokenOptions

        def run(self, problem):
            B = int(np.prod(problem.batch_shape))
            T = problem.t.shape[0]
            q = np.zeros((B, T, 4))
            q[..., 0] = 1.0
            w = np.ones((B, T, 3))
            bad = np.flatnonzero(problem.omega0.reshape(B, 3)[:, 0] > 100)  # the marked bodies
            q[bad, -1] = 0.0
            w[bad, 0, 1] = np.nan
            shape = problem.batch_shape
            return MethodResult(q=q.reshape(shape + (T, 4)), omega=w.reshape(shape + (T, 3)))

    Broken.options = BrokenOptions.defaults()
    monkeypatch.setitem(registry._REGISTRY, Broken.name, Broken)
    w = np.random.default_rng(2).standard_normal((50, 3))
    ok = ep.solve([1.0, 2.0, 3.0], TIMES, omega0=w, method=Broken.name, workers=3)
    assert ok.stats["threads"] == 3 and np.all(ok.quaternion[..., 0] == 1.0)
    w[37, 0] = 1e3
    for kind in (1, 3):
        with pytest.raises(InvalidInputError) as err:
            ep.solve([1.0, 2.0, 3.0], TIMES, omega0=w, method=Broken.name, workers=kind)
        if kind == 1:
            message = str(err.value)
        assert str(err.value) == message
    assert "NaN" in message


#: the fork scenario, run in a fresh interpreter: a pytest worker may have imported JAX (multithreaded), and
#: forking a multithreaded process can deadlock whatever the package does (Python warns of it)
_FORK_SCRIPT = """
import os, sys, time
import numpy as np
import eulerpoisson as ep
from eulerpoisson.solvers import parallel
from eulerpoisson.util import jit

parallel.MIN_BODIES, parallel.MIN_WORK, jit.NUMPY_BELOW = 1, 0.0, 0.0  # split every batch, compiled kernels
os.environ.pop(parallel.ENV_WORKERS, None)
guard, times = float(sys.argv[1]), np.array([0.0, 0.7, -1.3, 3.0])
w = np.random.default_rng(4).standard_normal((64, 3))
ref = ep.solve([1.0, 2.0, 3.0], times, omega0=w, workers=2)  # the parent's pool exists now
assert ref.stats["threads"] == 2
pid = os.fork()
if pid == 0:  # the child
    code = 1
    try:
        tr = ep.solve([1.0, 2.0, 3.0], times, omega0=w, workers=2)
        code = 0 if tr.stats["threads"] == 2 and np.array_equal(tr.quaternion, ref.quaternion) else 1
    finally:
        os._exit(code)
deadline = time.monotonic() + guard  # a guard against a hang, not a timing
while True:
    done, status = os.waitpid(pid, os.WNOHANG)
    if done:
        break
    if time.monotonic() > deadline:
        os.kill(pid, 9)
        os.waitpid(pid, 0)
        sys.exit("the forked child did not finish its solve")
    time.sleep(0.05)
sys.exit(os.waitstatus_to_exitcode(status))
"""


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="needs os.fork")
def test_a_forked_child_gets_a_pool_of_its_own():
    """The pool's threads do not survive a fork: the child starts its own (it would wait forever otherwise)."""
    import subprocess
    import sys

    res = subprocess.run(
        [sys.executable, "-c", _FORK_SCRIPT, str(HANG_GUARD_S)],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S * 2,
    )
    assert res.returncode == 0, res.stderr[-3000:]


def test_minus_one_means_every_core(monkeypatch):
    """workers=-1 is every core, as scipy spells it (issue 21); the results are the bits of workers=1."""
    import eulerpoisson as ep
    from eulerpoisson.solvers.parallel import available_cores, check_workers, resolve_workers

    assert resolve_workers(-1) == available_cores()
    monkeypatch.setenv("EULERPOISSON_WORKERS", "-1")
    assert resolve_workers(None) == available_cores()
    with pytest.raises(ep.InvalidInputError, match="-1 or None for every core; got -2"):
        check_workers(-2)
    rng = np.random.default_rng(3)
    w = rng.normal(size=(64, 3))
    one = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 5.0], omega0=w, method="taylor", workers=1)
    every = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 5.0], omega0=w, method="taylor", workers=-1)
    assert np.array_equal(one.quaternion, every.quaternion) and np.array_equal(one.omega, every.omega)
