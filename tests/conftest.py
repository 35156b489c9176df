"""Shared test configuration."""

import importlib.util
import os
import pickle
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from _limits import HANG_GUARD_S

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX: each worker computes its own copy
    fcntl = None

settings.register_profile(
    "default",
    deadline=None,
    max_examples=40,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    derandomize=True,
)
settings.register_profile("thorough", deadline=None, max_examples=500, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

# keep matplotlib off any display
os.environ.setdefault("MPLBACKEND", "Agg")
# the JAX tests (eulerpoisson.jax) compile large programs (the closed form and its derivatives): XLA's
# optimizing passes take most of that time (2.5x less without them, the same values: they only fuse and
# schedule); set before jax is imported
os.environ.setdefault("JAX_DISABLE_MOST_OPTIMIZATIONS", "1")
# ... and XLA's older CPU code generator for fusions: it compiles these programs in half the CPU time (the JAX
# test files 347 -> 175 CPU-s on 2 cores, the reverse-mode splitting program 170 -> 67 s), with the same
# results within the tests' tolerances. Set by the controller for its workers, and only where the installed
# jaxlib knows the flag (an unknown flag in XLA_FLAGS aborts the process); a user's XLA_FLAGS that name it win.
_FAST_COMPILE_FLAG = "--xla_cpu_use_fusion_emitters=false"


def _xla_knows(flag: str) -> bool:
    """Whether a JAX process starts with ``flag`` in XLA_FLAGS (False where jax is not installed)."""
    if importlib.util.find_spec("jax") is None:
        return False
    env = {**os.environ, "XLA_FLAGS": (os.environ.get("XLA_FLAGS", "") + " " + flag).strip(), "JAX_PLATFORMS": "cpu"}
    probe = "import jax.numpy as jnp; jnp.zeros(1).block_until_ready()"
    try:
        return (
            subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, timeout=HANG_GUARD_S).returncode
            == 0
        )
    except (OSError, subprocess.SubprocessError):
        return False


if (
    not os.environ.get("PYTEST_XDIST_WORKER")
    and "xla_cpu_use_fusion_emitters" not in os.environ.get("XLA_FLAGS", "")
    and _xla_knows(_FAST_COMPILE_FLAG)
):
    os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " " + _FAST_COMPILE_FLAG).strip()
# ... and JAX's persistent compilation cache, in a temporary folder of this run that the pytest-xdist workers
# share (they inherit the controller's environment; the controller removes it at the end): a program one worker
# or test has compiled (the same function at the same shapes) is read back instead of being compiled again
if not os.environ.get("PYTEST_XDIST_WORKER") and "JAX_COMPILATION_CACHE_DIR" not in os.environ:
    _JAX_CACHE = tempfile.mkdtemp(prefix="eulerpoisson-jax-cache-")
    os.environ["JAX_COMPILATION_CACHE_DIR"] = _JAX_CACHE
    os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "1")
else:
    _JAX_CACHE = None


def pytest_unconfigure(config):
    if _JAX_CACHE is not None:
        shutil.rmtree(_JAX_CACHE, ignore_errors=True)


#: the JAX test files (tests/test_jax_*.py) and the files that share compiled programs (tests/_jax_programs.py)
_JAX_FILE = re.compile(r"(?:^|/)(test_jax_[^/]*)\.py::")
_JAX_SHARED = {"test_jax_derivatives": "test_jax_exact"}
#: the files whose tests share one expensive module fixture: each one unit of work too, so that one worker
#: computes the fixture and the other goes on with other tests (split between the two, the second worker
#: computed it again, or waited for the first: the paper's audit, 70 s; the quick benchmark run, 36 s)
_WHOLE_FILE = re.compile(r"(?:^|/)(test_audit|test_benchmarks_smoke)\.py::")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup`` (the Makefile's test target): each JAX test file is one unit of work (the files of
    one :data:`_JAX_SHARED` set together), so that the programs its tests compile (the closed form and its
    derivatives: most of their time) are compiled once, by one worker, and so is each file of
    :data:`_WHOLE_FILE` (one expensive module fixture); the largest units are handed out first
    (pytest-xdist's ``--loadscope-reorder``), every other test is a unit of its own, as with ``xdist_group``
    marks. (pytest 9.2 no longer sees the group suffix that pytest-xdist 3.8 gives a marked test's id: the
    scopes are made here.)"""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class JaxFilesTogether(LoadGroupScheduling):
        def _split_scope(self, nodeid: str) -> str:
            found = _JAX_FILE.search(nodeid)
            if found:
                return "jax:" + _JAX_SHARED.get(found.group(1), found.group(1))
            found = _WHOLE_FILE.search(nodeid)
            if found:
                return "file:" + found.group(1)
            return super()._split_scope(nodeid)

    return JaxFilesTogether(config, log)


@pytest.fixture
def xla_optimized():
    """XLA's optimizing passes on for one test (the module turns them off: JAX_DISABLE_MOST_OPTIMIZATIONS).

    For the tests whose programs run longer than they compile: the docstring examples of eulerpoisson.jax
    (measured on 2 cores: 210 s without the passes for the five modules, 66 s with them) and the gradient fit
    of examples/jax_fit.py (67 s against 41 s: 400 evaluations of its chi2). The two settings can round
    differently (fused or reordered operations), and JAX's in-memory cache of compiled programs does not
    tell them apart: it is emptied before and after, so that no program compiled one way serves a test that
    runs the other way (later tests of the worker compile again, or read the persistent cache, whose key
    has the setting).

    Not with XLA's older fusion emitter (:data:`_FAST_COMPILE_FLAG`, set above where jaxlib knows it): the
    unoptimized programs then compile fast enough that they win (measured on 2 cores: the docstring examples
    of eulerpoisson.jax.exact 25 s against 31 s, examples/jax_fit.py 66 s against 78 s), and the test keeps
    the module's setting and its compiled programs.
    """
    jax = pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")
    if _FAST_COMPILE_FLAG in os.environ.get("XLA_FLAGS", ""):
        yield
        return
    previous = jax.config.values["jax_disable_most_optimizations"]
    jax.clear_caches()
    jax.config.update("jax_disable_most_optimizations", False)
    try:
        yield
    finally:
        jax.config.update("jax_disable_most_optimizations", previous)
        jax.clear_caches()


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


@pytest.fixture(autouse=True)
def _crash_reports_in_a_temporary_folder(tmp_path_factory, monkeypatch):
    """The command line saves the traceback of an internal error under $XDG_CACHE_HOME: not the user's, in tests."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path_factory.getbasetemp() / "cache"))


def _run_folder(tmp_path_factory) -> Path:
    """The temporary folder of this test run, common to every pytest-xdist worker (each has a subfolder)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def once_per_run(tmp_path_factory, name: str, compute):
    """``compute()`` once per test run, whatever the number of pytest-xdist workers: each caller gets a copy.

    The first worker that needs it computes it under a lock and keeps it (pickled) in the run's temporary
    folder; a worker that needs it meanwhile waits for it, a later one reads it. For the expensive,
    deterministic results that several test files check from different angles (the paper's audit).
    """
    folder = _run_folder(tmp_path_factory)
    path = folder / f"once-{name}.pickle"
    with open(folder / f"once-{name}.lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.exists():
            value = compute()
            tmp = path.with_suffix(".tmp")
            tmp.write_bytes(pickle.dumps(value))
            os.replace(tmp, path)
    return pickle.loads(path.read_bytes())


@pytest.fixture(scope="session")
def run_once(tmp_path_factory):
    """``run_once(name, compute)``: :func:`once_per_run` for a test module's expensive, deterministic references
    (``name`` unique in the run, e.g. ``"<module>-<what>"``), which tests on different pytest-xdist workers share."""
    return lambda name, compute: once_per_run(tmp_path_factory, name, compute)


@pytest.fixture(scope="session")
def audit_report_once(tmp_path_factory):
    """A function returning a copy of ``run_audit()`` (the paper's whole audit, about 45 s of CPU), computed once.

    tests/test_audit.py checks it; the README's examples that run ``run_audit()`` (its Python block and its
    ``eulerpoisson audit`` command) get this same report (see :func:`shared_audit`).
    """
    from eulerpoisson.paper import audit as A

    # the real function, taken now: ``shared_audit`` replaces ``A.run_audit`` by a function that calls this
    # one, and looking it up at call time would recurse into the lock this process already holds (a hang
    # whenever a README example was the run's first user of the audit)
    real = A.run_audit
    return lambda: once_per_run(tmp_path_factory, "audit", real)


@pytest.fixture
def shared_audit(monkeypatch, audit_report_once):
    """``eulerpoisson.paper.audit.run_audit()`` without arguments returns the run's one report (with: computes)."""
    from eulerpoisson.paper import audit as A

    real = A.run_audit

    def run_audit(**kwargs):
        return audit_report_once() if not kwargs else real(**kwargs)

    monkeypatch.setattr(A, "run_audit", run_audit)
