"""Cold and warm starts of the command line (issues 15 and 25): whole processes, end to end.

Every row is the wall time of a new process (``subprocess``, ``time.perf_counter`` around it),
the best of several, in a temporary folder:

* ``import_eulerpoisson``: ``python -c "import eulerpoisson"``;
* ``cli_simulate_warm``: ``eulerpoisson simulate --inertia 1,2,3 --omega 1,0.1,0.5 --t-end 10
  --samples 1001 --out x.nc`` (the issue's command: a small problem, solved by NumPy without
  importing numba) with numba's default cache;
* ``cli_simulate_warm_nopyc``: the same with ``PYTHONDONTWRITEBYTECODE=1`` and no ``.pyc`` files of
  eulerpoisson (a copy of the package without them first on ``PYTHONPATH``: its modules are compiled
  from source at every start, as in a source tree where writing bytecode is disabled; not what an
  installed package does);
* with a fresh, empty ``NUMBA_CACHE_DIR``: ``warmup_fresh_cache``, the time of ``eulerpoisson
  warmup`` filling it (every kernel compiled, every usable core; measured once; the row records the
  cores), then in new processes the first ``simulate`` of the small problem
  (``cli_first_simulate_after_warmup``) and, for each method M of exact, taylor, symplectic and rk,
  the first ``simulate`` of 10^5 samples, ``eulerpoisson simulate --inertia 1,2,3 --omega 1,0.1,0.5
  --t-end 1000 --samples 100000 --method M --out y.nc`` (``cli_first_simulate_1e5_M``: numba imported
  and the method's kernels loaded from the cache; every run is a new process, so each is the first use
  of those kernels after the warm-up; rk is scipy's ``solve_ivp`` stepper, slow even warm: reported,
  not judged).

The subprocesses see the package as installed: ``.pyc`` files written and used (the default of
Python; ``pip install`` compiles them), except in the ``_nopyc`` row. ``EULERPOISSON_WORKERS=1`` and
the default ``EULERPOISSON_NUMPY_BELOW`` (run.py's 0 removed). The goals: warm ``simulate`` <= 0.5 s;
``eulerpoisson warmup`` <= 10 s on 2 cores (issue 25 #5); the first ``simulate`` of 10^5 samples after
the warm-up <= 0.5 s with exact, taylor and symplectic (issue 25 #5).
``--quick`` measures one run of each command, skips the warm-up, and runs the first-simulate rows
of each method with 1000 samples to t = 10 and numba's default cache (whatever it holds; not a fresh
warm-up; the rows keep their names).

    .venv/bin/python benchmarks/run.py --only cold_start [--quick]
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXE = str(Path(sys.executable).with_name("eulerpoisson"))
#: the reference body's command line up to its end time (the issue's small problem and the first-simulate rows)
BODY = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end"]
SMALL = [*BODY, "10", "--samples", "1001", "--out", "x.nc", "--overwrite", "--quiet"]
#: the methods of the first-simulate rows; rk (scipy's solve_ivp stepper) is reported, not judged
METHODS = ("exact", "taylor", "symplectic", "rk")


def first_simulate(method: str, quick: bool = False) -> list[str]:
    """The command line (after ``eulerpoisson``) of the first-simulate row of ``method``: 10^5 samples to t = 1000
    (``quick``: 1000 samples to t = 10, which costs the new process and numba's start but little else)."""
    t_end, samples = ("10", "1000") if quick else ("1000", "100000")
    return [*BODY, t_end, "--samples", samples, "--method", method, "--out", "y.nc", "--overwrite", "--quiet"]


def _env(**extra):
    env = dict(os.environ, EULERPOISSON_WORKERS="1", **extra)
    env.pop("EULERPOISSON_NUMPY_BELOW", None)  # the default: small problems without numba (run.py sets it to 0)
    if "PYTHONDONTWRITEBYTECODE" not in extra:
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # as installed: .pyc files written once and used
    return env


def _once(argv, cwd, env) -> float:
    t0 = time.perf_counter()
    res = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed ({res.returncode}): {res.stderr[-2000:]}")
    return wall


def _best(argv, cwd, env, repeats) -> tuple[float, int]:
    times = [_once(argv, cwd, env) for _ in range(repeats)]
    return min(times), len(times)


def run(quick: bool = False, log=print) -> dict:
    repeats = 1 if quick else 7
    first_repeats = 1 if quick else 3
    out = {
        "config": {
            "small": " ".join(["eulerpoisson", *SMALL]),
            "first_simulate": " ".join(["eulerpoisson", *first_simulate("M", quick)]),
            "methods": list(METHODS),
            "repeats": repeats,
            "first_simulate_repeats": first_repeats,
        },
        "rows": [],
    }

    def add(name, label, value, unit="s", **extra):
        out["rows"].append({"name": name, "label": label, "value": value, "unit": unit, **extra})
        log(f"  {label:72s} {value:8.3f} {unit}")

    with tempfile.TemporaryDirectory(prefix="ep_cold_") as tmp:
        tmp = Path(tmp)
        env = _env()
        # warm the .pyc files and numba's default cache for the small problem first (not timed)
        _once([EXE, *SMALL], tmp, env)
        wall, n = _best([sys.executable, "-c", "import eulerpoisson"], tmp, env, repeats)
        add("import_eulerpoisson", "python -c 'import eulerpoisson' (new process)", wall, runs=n)
        wall, n = _best([EXE, *SMALL], tmp, env, repeats)
        add("cli_simulate_warm", "eulerpoisson simulate, 1001 samples to t = 10, --out x.nc (warm)", wall, runs=n)
        import eulerpoisson

        copy = tmp / "nopyc" / "eulerpoisson"
        shutil.copytree(Path(eulerpoisson.__file__).parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
        nopyc = _env(PYTHONDONTWRITEBYTECODE="1", PYTHONPATH=str(copy.parent))
        wall, n = _best([EXE, *SMALL], tmp, nopyc, max(1, repeats // 2))
        add(
            "cli_simulate_warm_nopyc",
            "the same without .pyc files of eulerpoisson (compiled at every start)",
            wall,
            runs=n,
        )

        cache = tmp / "numba_cache"
        cache.mkdir()
        fresh = _env(NUMBA_CACHE_DIR=str(cache))
        if not quick:
            wall = _once([EXE, "warmup"], tmp, fresh)
            add(
                "warmup_fresh_cache",
                "eulerpoisson warmup into an empty NUMBA_CACHE_DIR (compiles every kernel)",
                wall,
                runs=1,
                cores=_cores(),
            )
        what = "after eulerpoisson warmup" if not quick else "empty NUMBA_CACHE_DIR, no warm-up (quick)"
        wall, n = _best([EXE, *SMALL], tmp, fresh, repeats)
        add("cli_first_simulate_after_warmup", f"first simulate of 1001 samples in a new process, {what}", wall, runs=n)
        # each method's first simulate of 10^5 samples: every run a new process, the first use of the method's
        # kernels there (numba's cache is on disk); quick: numba's default cache, no fresh warm-up
        what = "after the warm-up" if not quick else "numba's default cache (quick)"
        samples = "1000" if quick else "1e5"
        for method in METHODS:
            how = " (scipy's stepper)" if method == "rk" else ""
            wall, n = _best([EXE, *first_simulate(method, quick)], tmp, env if quick else fresh, first_repeats)
            add(
                f"cli_first_simulate_1e5_{method}",
                f"first simulate, {samples} samples, --method {method}{how}, new process, {what}",
                wall,
                runs=n,
                method=method,
                cache="default" if quick else "fresh, after eulerpoisson warmup",
            )
        shutil.rmtree(cache, ignore_errors=True)
    return out


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


if __name__ == "__main__":  # pragma: no cover
    import runpy

    sys.argv = [sys.argv[0], "--only", "cold_start", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
