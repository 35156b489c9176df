"""Smoke test of the benchmark driver (benchmarks/run.py) in its tiny --quick configuration.

Checks that every benchmark runs, that the JSON files follow the schema the summary and the
README rely on, that the numbers are sane (finite, positive times; errors consistent with the
accuracy knobs: the exact and Taylor methods are far more accurate than a coarse splitting), that
the work-precision PNG is written and that every goal (issue 25's marked "[25.N]") is judged or N/A
with its reason. The test-suite benchmark (``make test`` on a fresh clone) does not run in --quick; its
plumbing is checked on a throw-away repository whose ``make test`` only prints. No timing is asserted.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from _limits import HANG_GUARD_S

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


#: the limit of the "timed out" case of the test-suite benchmark (its make test sleeps 20 s)
_SLEEPS_PAST = 0.5

#: issue 25's goals, by the prefix of their text, and how many goals each prefix has
ISSUE25 = {
    "[25.1a]": 1,
    "[25.1b]": 1,
    "[25.1c]": 1,
    "[25.2]": 2,
    "[25.3]": 2,
    "[25.4]": 1,
    "[25.5]": 2,
    "[25.6]": 1,
    "[25.7]": 1,
}


@contextlib.contextmanager
def _benchmarks():
    """benchmarks/ importable (``run``, ``_common``, ``bench_*``) for the block; then the environment and modules back.

    benchmarks/run.py sets its environment (one thread, ``EULERPOISSON_NUMPY_BELOW=0``: compiled kernels for
    every problem) when imported: the environment and the modules of benchmarks/ are put back afterwards, so
    that the tests that run later in this process see the defaults.
    """
    env, modules = dict(os.environ), set(sys.modules)
    sys.path.insert(0, str(BENCH))
    try:
        yield
    finally:
        sys.path.remove(str(BENCH))
        os.environ.clear()
        os.environ.update(env)
        for name in set(sys.modules) - modules:
            if getattr(sys.modules[name], "__file__", None) and Path(sys.modules[name].__file__).parent == BENCH:
                del sys.modules[name]


def _driver(argv):
    """``benchmarks/run.py``'s ``main(argv)`` run in this process; its exit code."""
    with _benchmarks():
        return importlib.import_module("run").main(argv)


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """The benchmark driver run in this process (the package's kernels it compiles serve the later tests)."""
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("bench")
    assert _driver(["--quick", "--peers", "scipy", "--no-readme", "--out", str(out)]) == 0
    return out


def _goals(out, prefix):
    return [g for g in json.loads((out / "goals.json").read_text())["goals"] if g["goal"].startswith(prefix)]


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
    first = {f"cli_first_simulate_1e5_{m}" for m in ("exact", "taylor", "symplectic", "rk")}
    assert {
        "import_eulerpoisson",
        "cli_simulate_warm",
        "cli_simulate_warm_nopyc",
        "cli_first_simulate_after_warmup",
    } | first <= set(rows)
    assert "warmup_fresh_cache" not in rows  # --quick: no warm-up
    for r in rows.values():
        assert _pos(r["value"]) and r["unit"] == "s" and r["runs"] >= 1
    for name in first:
        assert rows[name]["cache"] == "default" and "--method " + rows[name]["method"] in rows[name]["label"]
    (warm,) = _goals(quick_run, "cold start")
    assert warm["status"] in ("PASS", "MISS")
    warmup, simulate = _goals(quick_run, "[25.5]")
    assert "warmup" in warmup["goal"] and warmup["status"] == "N/A" and warmup["measured"] == "not run (--quick)"
    # judged on exact, taylor and symplectic; rk reported beside them, labelled as scipy's stepper
    assert simulate["status"] in ("PASS", "MISS") and simulate["target"].startswith("<= 0.5 s")
    assert "rk (scipy's solve_ivp stepper, not judged)" in simulate["measured"]
    worst = max(rows[f"cli_first_simulate_1e5_{m}"]["value"] for m in ("exact", "taylor", "symplectic"))
    assert simulate["ratio"] == pytest.approx(worst / 0.5)
    assert "Cold and warm starts" in (quick_run / "summary.md").read_text()


def test_test_suite_not_run_in_quick(quick_run):
    d = _load(quick_run, "test_suite")
    (row,) = d["rows"]
    assert row["name"] == "make_test" and row["value"] is None and row["status"] == "not run (--quick)"
    assert d["commit"] is None or len(d["commit"]) == 40
    (goal,) = _goals(quick_run, "[25.7]")
    assert goal["status"] == "N/A" and goal["measured"] == "not run (--quick)" and "360 s" in goal["target"]
    assert "The test suite on a fresh clone" in (quick_run / "summary.md").read_text()


def test_summary_and_goals(quick_run):
    g = _load(quick_run, "goals")
    statuses = [x["status"] for x in g["goals"]]
    assert set(statuses) <= {"PASS", "MISS", "N/A"}
    assert len(statuses) >= 6
    for prefix, n in ISSUE25.items():
        assert len(_goals(quick_run, prefix)) == n, prefix
    # the superseded goals are gone: issue 25's versions replace them
    assert not any("within 3x of heyoka" in x["goal"] or "<= 3 s" == x["target"] for x in g["goals"])
    (many,) = [x for x in _goals(quick_run, "[25.3]") if "many times" in x["goal"]]
    assert many["target"] == "<= 0.15 us per evaluation"
    # --peers scipy: the goals measured against heyoka are not applicable, and say why
    against_heyoka = [x for x in g["goals"] if "heyoka" in x["goal"]]
    assert len(against_heyoka) == 5
    for x in against_heyoka:
        assert x["status"] == "N/A" and x["ratio"] is None and "heyoka not installed or disabled" in x["measured"]
    # the goals whose benchmark ran in --quick are judged
    for prefix in ("[25.1a]", "[25.1b]", "[25.3]", "[25.4]", "[25.6]"):
        assert all(x["status"] in ("PASS", "MISS") for x in _goals(quick_run, prefix)), prefix
    (toutatis,) = _goals(quick_run, "[25.6]")
    assert "lowest found" in toutatis["measured"]  # the fit finds the lowest chi2 (test_fit_schema)
    text = (quick_run / "summary.md").read_text()
    assert "QUICK RUN" in text and "| goal |" in text and "work_precision.png" in text
    assert g["machine"]["cpu"] in text and g["command"] in text
    assert all(x["goal"] in text for x in g["goals"])


def test_summary_only_with_older_json(quick_run, tmp_path):
    """--summary-only over JSON that predates the newer rows: their goals are N/A, "not run"; nothing fails."""
    for src in quick_run.glob("*.json"):
        if src.name not in ("goals.json", "test_suite.json"):
            shutil.copy(src, tmp_path / src.name)
    for name, drop in (("cold_start", "cli_first_simulate_1e5_"), ("fit", "fit_toutatis"), ("exact", "call_")):
        data = json.loads((tmp_path / f"{name}.json").read_text())
        data["rows"] = [r for r in data["rows"] if not r["name"].startswith(drop)]
        (tmp_path / f"{name}.json").write_text(json.dumps(data))
    assert _driver(["--summary-only", "--no-readme", "--out", str(tmp_path)]) == 0
    for prefix in ("[25.1a]", "[25.1b]", "[25.6]", "[25.7]"):
        (goal,) = _goals(tmp_path, prefix)
        assert goal["status"] == "N/A" and goal["measured"] == "not run", prefix
    assert [x["measured"] for x in _goals(tmp_path, "[25.5]")] == ["not run (--quick)", "not run"]
    assert "The test suite on a fresh clone" not in (tmp_path / "summary.md").read_text()


def test_test_suite_parsing_and_environment():
    with _benchmarks():
        B = importlib.import_module("bench_test_suite")
    out = "\n".join(
        [
            "12 kernel group(s) ready in 31.5 s (cache: /x, ...)",
            "SKIPPED [1] tests/test_x.py:3: chromium in 5s not found",
            "2904 passed, 18 skipped, 1 xfailed, 3 warnings in 713.25s (0:11:53)",
        ]
    )
    got = B.parse_pytest_summary(out)
    assert got["pytest_s"] == 713.25 and (got["passed"], got["failed"], got["skipped"]) == (2904, 0, 18)
    assert got["xfailed"] == 1 and got["warnings"] == 3
    assert B.parse_pytest_summary("===== 1 failed, 2 passed, 1 error in 3.50s =====")["errors"] == 1
    assert B.parse_pytest_summary("no tests ran in 0.01s") is None
    assert B.parse_warmup_total(out) == 31.5 and B.parse_warmup_total("") is None
    env = B.ci_environment(
        {
            "PATH": "/bin",
            "HOME": "/h",
            "NUMBA_CACHE_DIR": "/c",
            "EULERPOISSON_NUMPY_BELOW": "0",
            "EULERPOISSON_WORKERS": "1",
            "OMP_NUM_THREADS": "1",
            "OPENBLAS_NUM_THREADS": "1",
            "PYTHONPATH": "/p",
            "PYTHONDONTWRITEBYTECODE": "1",
            "MAKEFLAGS": " -- WORKERS=1",
            "MAKELEVEL": "1",
        }
    )
    assert env == {"PATH": "/bin", "HOME": "/h"}


@pytest.mark.skipif(
    shutil.which("git") is None or shutil.which("make") is None,
    reason="the test-suite benchmark clones with git and runs make: git or make is not on PATH here",
)
@pytest.mark.parametrize("case", ["ok", "failed", "timed out"])
def test_test_suite_on_a_throwaway_repository(case, tmp_path, monkeypatch):
    """bench_test_suite.run clones a repository and times its ``make test``, which here only prints."""
    recipe = {
        "ok": ['@echo "9 kernel group(s) ready in 2.5 s"', '@echo "5 passed, 1 skipped in 7.25s"'],
        "failed": [
            '@echo "env: $${NUMBA_CACHE_DIR-unset} $${EULERPOISSON_WORKERS-unset} $${OMP_NUM_THREADS-unset}"',
            '@echo "1 failed, 4 passed in 7.00s"',
            "@exit 3",
        ],
        "timed out": ["@sleep 20"],
    }[case]
    repo = tmp_path / "repo"
    repo.mkdir()
    (repo / "Makefile").write_text("test:\n" + "".join(f"\t{line}\n" for line in recipe))
    git = ["git", "-c", "user.email=bench@example.org", "-c", "user.name=bench"]
    for cmd in (["init", "-q"], ["add", "Makefile"], ["commit", "-qm", "a make test that prints"]):
        subprocess.run([*git, *cmd], cwd=repo, check=True, capture_output=True)
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=repo, capture_output=True, text=True).stdout.strip()
    for var in ("NUMBA_CACHE_DIR", "EULERPOISSON_WORKERS", "OMP_NUM_THREADS"):
        monkeypatch.setenv(var, "1")
    with _benchmarks():
        # the "timed out" case: a deliberately short limit (the others: the hang guard, as every wait of the tests)
        limit = _SLEEPS_PAST if case == "timed out" else HANG_GUARD_S
        out = importlib.import_module("bench_test_suite").run(log=lambda line: None, root=repo, timeout=limit)
        goals = importlib.import_module("run").evaluate_goals(None, None, None, suite=out)
    rows = {r["name"]: r for r in out["rows"]}
    total = rows["make_test"]
    assert out["commit"] == head == total["commit"] and total["value"] > 0
    if case == "ok":
        assert total["status"] == "ok" and total["returncode"] == 0 and "output_tail" not in total
        assert rows["make_test_pytest"]["value"] == 7.25 and rows["make_test_pytest"]["passed"] == 5
        assert rows["make_test_warmup"]["value"] == 2.5 and "make_test_rest" in rows
    elif case == "failed":
        assert total["status"] == "failed (make exited 2)" and total["failed"] == 1 and total["passed"] == 4
        # make test runs as CI does: none of the benchmark's environment overrides
        assert "env: unset unset unset" in total["output_tail"]
    else:
        assert total["status"] == "timed out after 0.5 s" and total["returncode"] is None
    (goal,) = [g for g in goals if g["goal"].startswith("[25.7]")]
    assert goal["status"] == ("PASS" if case == "ok" else "MISS")


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


def test_the_readme_speed_table_is_made_from_the_goals(quick_run, tmp_path, monkeypatch):
    goals = json.loads((quick_run / "goals.json").read_text())
    with _benchmarks():
        run = importlib.import_module("run")
        table = run.speed_table(goals["goals"], goals["machine"])
        rows = [line for line in table.splitlines() if line.startswith("| ") and "---" not in line][1:]
        assert len(rows) == len(goals["goals"])
        for g, row in zip(goals["goals"], rows):
            assert row.startswith(f"| {g['goal']} |") and row.endswith(f"| {g['status'].lower()} |")
        # the README's table is replaced between its markers, the rest of the file kept
        readme = tmp_path / "README.md"
        readme.write_text(f"intro\n{run.SPEED_START}\nold table\n{run.SPEED_END}\nrest\n", encoding="utf-8")
        monkeypatch.setattr(run, "MAIN_README", readme)
        assert run._update_speed_table(goals["goals"], goals["machine"])
        text = readme.read_text(encoding="utf-8")
        assert text.startswith("intro\n") and text.endswith(f"{run.SPEED_END}\nrest\n") and "old table" not in text
        assert table in text
    # the project's README has the markers
    text = (BENCH.parent / "README.md").read_text(encoding="utf-8")
    assert text.count("<!-- speed:start -->") == 1 and text.count("<!-- speed:end -->") == 1
