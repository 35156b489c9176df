"""Shared test configuration."""

import os
import pickle
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

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
def audit_report_once(tmp_path_factory):
    """A function returning a copy of ``run_audit()`` (the paper's whole audit, about 45 s of CPU), computed once.

    tests/test_audit.py checks it; the README's examples that run ``run_audit()`` (its Python block and its
    ``eulerpoisson audit`` command) get this same report (see :func:`shared_audit`).
    """
    from eulerpoisson.paper import audit as A

    return lambda: once_per_run(tmp_path_factory, "audit", A.run_audit)


@pytest.fixture
def shared_audit(monkeypatch, audit_report_once):
    """``eulerpoisson.paper.audit.run_audit()`` without arguments returns the run's one report (with: computes)."""
    from eulerpoisson.paper import audit as A

    real = A.run_audit

    def run_audit(**kwargs):
        return audit_report_once() if not kwargs else real(**kwargs)

    monkeypatch.setattr(A, "run_audit", run_audit)
