"""The test suite on a fresh clone, as CI runs it (issue 25 #7): ``make test``, whole, timed.

Clones the repository's committed HEAD (``git clone -q <root> <tmp>/p``: uncommitted changes of the working
tree are not measured; the row says when there are some) and runs ``make test`` there, as CI does on a fresh
machine: the clone's own virtual environment created and installed (pip, from the package index or pip's
cache), the optional test extras (chromium, MuJoCo, PyBullet) where they install, ``eulerpoisson warmup``
into an empty numba cache (the clone's own ``__pycache__``), then pytest on every core (``-n auto``). The
environment is this process's without the benchmark's overrides: every ``NUMBA_*``, ``EULERPOISSON_*`` and
``PYTHON*`` variable, the thread limits run.py sets (``OMP/MKL/OPENBLAS_NUM_THREADS``,
``VECLIB_MAXIMUM_THREADS``) and the variables of an enclosing make (``make bench``: ``MAKEFLAGS``,
``MAKELEVEL``...) are removed.

Rows: ``make_test`` (the wall time of ``make test``, its status and exit code, the commit, the cores),
``make_test_warmup`` (the warm-up's own total, from its last line), ``make_test_pytest`` (pytest's own time
and its counts, from its last line, e.g. "2904 passed, 18 skipped in 713.25s (0:11:53)") and
``make_test_rest`` (the difference: the virtual environment, the installs, the extras' checks). A failing
``make test`` is recorded in the ``make_test`` row (its status and the tail of its output) and its goal is a
MISS; the other benchmarks are not affected. The goal: ``make test`` under 6 minutes on 2 cores.

``--quick`` runs nothing (the smoke test runs the quick benchmarks inside ``make test``, which would recurse):
one row, "not run (--quick)", and the goal is N/A. A full run takes about 15 minutes.

    .venv/bin/python benchmarks/run.py --only test_suite
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the goal: ``make test`` on a fresh clone within 6 minutes (2 cores)
LIMIT_S = 360.0
#: ``make test`` is stopped (and the row says so) after this long
TIMEOUT_S = 3600.0
NOT_RUN_QUICK = "not run (--quick)"

_DROP_PREFIXES = ("NUMBA_", "EULERPOISSON_", "PYTHON")
_DROP = frozenset(
    {
        "OMP_NUM_THREADS",
        "MKL_NUM_THREADS",
        "OPENBLAS_NUM_THREADS",
        "VECLIB_MAXIMUM_THREADS",
        # `make bench` runs run.py inside make: its variables (command-line ones such as WORKERS=1, the jobserver)
        # would reach the nested `make test`, which CI runs at the top level
        "MAKEFLAGS",
        "MFLAGS",
        "MAKELEVEL",
        "MAKEOVERRIDES",
    }
)
_COUNT = re.compile(r"(\d+) (passed|failed|skipped|errors?|xfailed|xpassed|deselected|warnings?)\b")
_TIME = re.compile(r"\bin (\d+(?:\.\d+)?)s\b")
_WARMUP = re.compile(r"(\d+) kernel group\(s\) ready in (\d+(?:\.\d+)?) s")


def ci_environment(environ=None) -> dict:
    """``environ`` (default ``os.environ``) without the benchmark's overrides: what CI's ``make test`` sees."""
    env = dict(os.environ if environ is None else environ)
    for key in list(env):
        if key in _DROP or key.startswith(_DROP_PREFIXES):
            del env[key]
    return env


def parse_pytest_summary(output: str):
    """pytest's last summary line of ``output``: ``{"pytest_s", "passed", "failed", ..., "line"}``, or None."""
    for raw in reversed(output.splitlines()):
        line = raw.strip().strip("=").strip()
        m = _TIME.search(line)
        counts = _COUNT.findall(line)
        if m is None or not counts:
            continue
        out = {"pytest_s": float(m.group(1)), "passed": 0, "failed": 0, "skipped": 0, "errors": 0}
        for n, what in counts:
            key = {"error": "errors", "warning": "warnings"}.get(what, what)
            out[key] = out.get(key, 0) + int(n)
        out["line"] = line
        return out
    return None


def parse_warmup_total(output: str):
    """Seconds of ``eulerpoisson warmup`` from its last line ("N kernel group(s) ready in T s"), or None."""
    found = _WARMUP.findall(output)
    return float(found[-1][1]) if found else None


def _git(*args, cwd) -> str | None:
    try:
        res = subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return res.stdout.strip() if res.returncode == 0 else None


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def _run_make(cwd: Path, env: dict, timeout: float) -> tuple[int | None, str, float]:
    """``make test`` in ``cwd``: (exit code or None on time-out, stdout and stderr together, wall seconds)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        ["make", "test"],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own process group: pytest's workers too are stopped on a time-out
    )
    try:
        output, _ = proc.communicate(timeout=timeout)
        rc: int | None = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        output, _ = proc.communicate()
        rc = None
    return rc, output or "", time.perf_counter() - t0


def run(quick: bool = False, log=print, *, root: Path | None = None, timeout: float = TIMEOUT_S) -> dict:
    """The rows of ``make test`` on a fresh clone of ``root`` (default: this repository); see the module's notes.

    ``timeout``: seconds before ``make test`` and its children are stopped (the row says so).
    """
    root = ROOT if root is None else Path(root)
    commit = _git("rev-parse", "HEAD", cwd=root)
    dirty = bool(_git("status", "--porcelain", "--untracked-files=no", cwd=root))
    cores = _cores()
    out = {
        "config": {"command": "make test", "root": str(root), "limit_s": LIMIT_S, "timeout_s": timeout},
        "commit": commit,
        "uncommitted_changes": dirty,
        "rows": [],
    }

    def add(name, label, value, unit="s", **extra):
        out["rows"].append({"name": name, "label": label, "value": value, "unit": unit, **extra})
        shown = "-" if value is None else f"{value:8.1f} {unit}"
        log(f"  {label:72s} {shown}")

    label = "make test on a fresh clone (venv and installs, warm-up into an empty numba cache, pytest)"
    if quick:
        add("make_test", label, None, status=NOT_RUN_QUICK, commit=commit, cores=cores)
        return out
    with tempfile.TemporaryDirectory(prefix="ep_make_test_", ignore_cleanup_errors=True) as tmp:
        clone = Path(tmp) / "p"
        log(
            f"  cloning {root} (commit {commit[:10] if commit else '?'}) into {clone}, then running make test "
            f"there, about 15 minutes (run.py --skip test_suite to leave it out)"
        )
        if dirty:
            log("  (the working tree has uncommitted changes: they are not part of the clone)")
        res = subprocess.run(["git", "clone", "-q", str(root), str(clone)], capture_output=True, text=True)
        if res.returncode != 0:
            add(
                "make_test",
                label,
                None,
                status=f"clone failed ({res.returncode})",
                output_tail=res.stderr[-4000:],
                commit=commit,
                cores=cores,
            )
            return out
        commit = _git("rev-parse", "HEAD", cwd=clone) or commit
        out["commit"] = commit
        rc, output, wall = _run_make(clone, ci_environment(), timeout)
    if rc is None:
        status = f"timed out after {timeout:g} s"
    elif rc != 0:
        status = f"failed (make exited {rc})"
    else:
        status = "ok"
    summary = parse_pytest_summary(output)
    warm = parse_warmup_total(output)
    extra = {"status": status, "returncode": rc, "commit": commit, "cores": cores}
    if status != "ok":
        extra["output_tail"] = output[-4000:]
    if summary:
        extra.update({k: v for k, v in summary.items() if k not in ("pytest_s", "line")})
    add("make_test", label, wall, **extra)
    if warm is not None:
        add("make_test_warmup", "  of which eulerpoisson warmup (an empty numba cache; its own total)", warm)
    if summary:
        counts = {k: v for k, v in summary.items() if k not in ("pytest_s", "line")}
        add("make_test_pytest", "  of which pytest (its own time)", summary["pytest_s"], line=summary["line"], **counts)
    if summary and warm is not None:
        add(
            "make_test_rest",
            "  the rest: the virtual environment, the installs, the extras' checks",
            max(0.0, wall - warm - summary["pytest_s"]),
        )
    log(f"  make test: {status}, {wall:.0f} s" + (f"; pytest: {summary['line']}" if summary else ""))
    return out


if __name__ == "__main__":  # pragma: no cover
    import runpy

    sys.argv = [sys.argv[0], "--only", "test_suite", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
