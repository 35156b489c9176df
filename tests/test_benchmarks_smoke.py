"""Smoke test of the benchmark driver (benchmarks/run.py) in its tiny --quick configuration.

Checks that every benchmark runs, that the JSON files follow the schema the summary and the
README rely on, that the numbers are sane (finite, positive times; errors consistent with the
accuracy knobs: the exact and Taylor methods are far more accurate than a coarse splitting) and
that the work-precision PNG is written. No timing is asserted.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """The benchmark driver run in this process (the package's kernels it compiles serve the later tests).

    benchmarks/run.py sets its environment (one thread, ``EULERPOISSON_NUMPY_BELOW=0``: compiled kernels for
    every problem) when imported: the environment and the modules of benchmarks/ (``run``, ``_common``,
    ``bench_*``) are put back afterwards, so that the tests that run later in this process see the defaults.
    """
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("bench")
    env, modules = dict(os.environ), set(sys.modules)
    sys.path.insert(0, str(BENCH))
    try:
        run = importlib.import_module("run")
        rc = run.main(["--quick", "--peers", "scipy", "--no-readme", "--out", str(out)])
    finally:
        sys.path.remove(str(BENCH))
        os.environ.clear()
        os.environ.update(env)
        for name in set(sys.modules) - modules:
            if getattr(sys.modules[name], "__file__", None) and Path(sys.modules[name].__file__).parent == BENCH:
                del sys.modules[name]
    assert rc == 0
    return out


def _load(out, name):
    data = json.loads((out / f"{name}.json").read_text())
    assert data["benchmark"] == name
    assert data["schema_version"] == 1
    assert data["quick"] is True
    assert "benchmarks/run.py" in data["command"] and "--quick" in data["command"]
    for key in ("cpu", "usable_cpus", "python", "numpy", "scipy", "peers"):
        assert key in data["machine"], key
    return data


def _pos(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def test_work_precision_schema_and_png(quick_run):
    d = _load(quick_run, "work_precision")
    assert d["problem"]["inertia"] == [1.0, 2.0, 3.0]
    assert d["reference"]["source"]
    names = {c["name"] for c in d["curves"]}
    expected = {
        "exact",
        "taylor",
        "symplectic-splitting",
        "symplectic-splitting4",
        "symplectic-gauss4",
        "symplectic-gauss6",
        "rk-DOP853",
        "rk-RK45",
        "scipy-DOP853",
        "scipy-RK45",
    }
    assert expected <= names
    for c in d["curves"]:
        assert c["label"] and c["knob"] in ("none", "tol", "rtol", "dt")
        assert c["points"]
        for p in c["points"]:
            assert _pos(p["time_s"])
            assert math.isfinite(p["error_rad"]) and p["error_rad"] >= 0
            assert math.isfinite(p["energy_rel_error"])
    by = {c["name"]: c for c in d["curves"]}
    # independent truth: a 1.1e-19 reference; the closed form and Taylor at eps agree with it to
    # round-off at t = 10, a second-order splitting with dt = 0.2 is far off
    exact_err = by["exact"]["points"][0]["error_rad"]
    taylor_eps = min(p["error_rad"] for p in by["taylor"]["points"])
    split = by["symplectic-splitting"]["points"][0]["error_rad"]
    assert exact_err < 1e-13 and taylor_eps < 1e-13
    assert split > 1e-6
    png = quick_run / "work_precision.png"
    assert png.stat().st_size > 10_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_long_run_schema(quick_run):
    d = _load(quick_run, "long_run")
    rows = {r["name"]: r for r in d["rows"]}
    assert {"exact", "taylor", "scipy-DOP853"} <= set(rows)
    for r in rows.values():
        assert _pos(r["time_s"])
        assert math.isfinite(r["energy_rel_error"]) and r["energy_rel_error"] < 1e-9
        assert len(r["q"]) == 4
        assert math.isfinite(r["attitude_difference_from_exact_rad"])
    assert rows["exact"]["attitude_difference_from_exact_rad"] == 0.0
    assert rows["taylor"]["attitude_difference_from_exact_rad"] < 1e-12


def test_throughput_schema(quick_run):
    d = _load(quick_run, "throughput")
    rows = {r["name"]: r for r in d["rows"]}
    assert {
        "exact_solve",
        "exact_kernel",
        "taylor_batch",
        "symplectic_splitting",
        "symplectic_splitting4",
        "symplectic_gauss4",
        "scipy_ellipj",
    } <= set(rows)
    for r in rows.values():
        assert _pos(r["value"]) and r["unit"]


def test_fit_schema(quick_run):
    d = _load(quick_run, "fit")
    rows = {r["name"]: r for r in d["rows"]}
    assert {"fit_100", "fit_100_full", "fit_10000", "fit_toutatis"} <= set(rows)
    for r in rows.values():
        assert _pos(r["value"]) and r["unit"] == "s"
        if r["name"] == "fit_toutatis":
            # several optima: the default starts find the lowest chi2, that of a fit started at the truth
            assert r["lowest_found"] and r["chi2"] <= r["chi2_from_truth"] * (1 + 1e-9) + 1e-9
            continue
        # the fits find the truth: every parameter within 4 standard errors, chi2/dof near 1
        assert r["worst_z"] < 4.0 and 0.7 < r["reduced_chi2"] < 1.3
    assert "Spin-state estimation" in (quick_run / "summary.md").read_text()


def test_cold_start_schema(quick_run):
    d = _load(quick_run, "cold_start")
    rows = {r["name"]: r for r in d["rows"]}
    assert {
        "import_eulerpoisson",
        "cli_simulate_warm",
        "cli_simulate_warm_nopyc",
        "cli_first_simulate_after_warmup",
    } <= set(rows)
    for r in rows.values():
        assert _pos(r["value"]) and r["unit"] == "s" and r["runs"] >= 1
    goals = [g for g in _load(quick_run, "goals")["goals"] if g["goal"].startswith("cold start")]
    assert len(goals) == 2 and all(g["status"] in ("PASS", "MISS") for g in goals)
    assert "Cold and warm starts" in (quick_run / "summary.md").read_text()


def test_summary_and_goals(quick_run):
    g = _load(quick_run, "goals")
    statuses = [x["status"] for x in g["goals"]]
    assert set(statuses) <= {"PASS", "MISS", "N/A"}
    assert len(statuses) >= 6
    # without heyoka the goals measured against it are not applicable
    assert g["goals"][0]["status"] == "N/A" and g["goals"][2]["status"] == "N/A"
    text = (quick_run / "summary.md").read_text()
    assert "QUICK RUN" in text and "| goal |" in text and "work_precision.png" in text
    assert g["machine"]["cpu"] in text and g["command"] in text


def test_heyoka_peer_matches_exact():
    """The heyoka peer integrates the same ODE (skipped when heyoka is not installed)."""
    hy = pytest.importorskip("heyoka")
    sys.path.insert(0, str(BENCH))
    try:
        C = importlib.import_module("_common")
    finally:
        sys.path.remove(str(BENCH))
    from eulerpoisson.solvers import solve

    q, om = C.HeyokaPeer(hy, C.EPS).run(10.0)
    tr = solve(list(C.INERTIA), [10.0], omega0=list(C.OMEGA0))
    assert C.attitude_error(q, tr.quaternion[0]) < 1e-13
    assert max(abs(a - b) for a, b in zip(om, tr.omega[0])) < 1e-13
