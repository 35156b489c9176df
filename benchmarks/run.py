"""Run the eulerpoisson benchmarks and write benchmarks/results/ (JSON, PNG, summary.md).

Eight benchmarks (``--only`` picks one, ``--skip`` leaves one out; the others' latest JSON in ``--out``
is reused for the summary when present):

``work_precision``
    attitude error against wall time on the issue's reference problem (I = diag(1, 2, 3),
    Omega0 = (1, 0.1, 0.5), t = 100) for every method and peer over its accuracy knob:
    ``work_precision.json`` and the diagram ``work_precision.png``;
``long_run``
    to t = 1e5: time, energy error and attitude error: ``long_run.json``;
``throughput``
    batched evaluation and integration rates, and the speed-up of exact, taylor and symplectic
    batches on every usable core against one thread (``solve(..., workers=)``): ``throughput.json``;
``torque``
    bodies under torque: taylor step cost with gravity against the free body, the exact Lagrange top
    per evaluation, the exact splitting's rate, accuracy of taylor and rk on a heavy top:
    ``torque.json``;
``exact``
    the closed form's speed: distinct bodies each at one time (Monte-Carlo) and one body at many
    times, through ``solve`` and the kernel, with the elliptic work counted: ``exact.json``;
``fit``
    spin-state estimation (``ep.fit``) from the default starts: 100 observations (diagonal and full
    inertia), 10^4 observations and a Toutatis-like tumbler with several optima: ``fit.json``;
``cold_start``
    whole command-line processes: ``import eulerpoisson``, a warm ``eulerpoisson simulate`` of the
    issue's small problem, ``eulerpoisson warmup`` into an empty numba cache and the first
    ``simulate`` after it in new processes (the small problem, and 10^5 samples with each method:
    exact, taylor, symplectic, and rk, scipy's stepper, reported but not judged): ``cold_start.json``;
``test_suite``
    ``make test`` on a fresh clone of the committed HEAD, as CI runs it (its own virtual environment,
    an empty numba cache, the benchmark's environment overrides removed): the wall time, pytest's time
    and counts, the commit; about 15 minutes on 2 cores, the last benchmark; ``--quick`` does not run it
    (the goal is N/A): ``test_suite.json``.

``summary.md`` gathers the tables, the ratios against the peers measured in the same run and a
PASS/MISS/N/A column for each goal: the older issues' goals, then issue 25's seven targets, marked
``[25.N]`` (a goal judged against heyoka is N/A without heyoka, never PASS; a goal whose benchmark
did not run, or whose JSON predates its rows, is N/A, "not run"), with the machine and the command. Every
measurement uses one thread (``EULERPOISSON_WORKERS=1`` unless set) and the compiled kernels
(``EULERPOISSON_NUMPY_BELOW=0`` unless set: small problems too; ``cold_start`` measures the
default, where small problems are solved by NumPy without importing numba), except the threads rows of
the throughput benchmark, which pass ``workers=`` explicitly, and ``make test`` of ``test_suite``, which
runs as CI does (every core, none of these settings). ``--quick`` runs a tiny
configuration (seconds; for the smoke test, not representative). When the full run writes to the default directory, the results block of
benchmarks/README.md is refreshed too (``--no-readme`` to skip).

Peers: scipy (always), heyoka and MuJoCo when importable (``pip install heyoka mujoco``).

    .venv/bin/python benchmarks/run.py                  # full run, about 20 minutes (test_suite: 15)
    .venv/bin/python benchmarks/run.py --skip test_suite  # the rest, about 5 minutes
    .venv/bin/python benchmarks/run.py --quick --out /tmp/bench
    .venv/bin/python benchmarks/run.py --only throughput
    .venv/bin/python benchmarks/run.py --summary-only   # the summary again from the JSON in --out
"""

from __future__ import annotations

import os

for _var in (
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "NUMBA_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "EULERPOISSON_WORKERS",
):
    os.environ.setdefault(_var, "1")
# the compiled kernels for every problem, small ones too (by default small problems take the NumPy twins, which
# start faster in a new process but cost more per call: the cold_start benchmark measures that default)
os.environ.setdefault("EULERPOISSON_NUMPY_BELOW", "0")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

import _common as C  # noqa: E402

DEFAULT_OUT = HERE / "results"
BENCHMARKS = ("work_precision", "long_run", "throughput", "torque", "fit", "exact", "cold_start", "test_suite")
README = HERE / "README.md"
README_START = "<!-- results:start -->"
README_END = "<!-- results:end -->"
#: the project's README: its Speed table is regenerated from the goals of a full run (between these markers)
MAIN_README = HERE.parent / "README.md"
SPEED_START = "<!-- speed:start -->"
SPEED_END = "<!-- speed:end -->"


def _module(name):
    import importlib

    return importlib.import_module(f"bench_{name}")


# ---------------------------------------------------------------------------
# goals of the issue
# ---------------------------------------------------------------------------
def _curve_point(wp, name, knob):
    for c in wp.get("curves", []):
        if c["name"] == name:
            for p in c["points"]:
                if knob is None or (p["knob"] is not None and abs(p["knob"] - knob) <= 1e-3 * abs(knob)):
                    return p
    return None


def _row(rows, name):
    for r in rows:
        if r["name"] == name:
            return r
    return None


def _status(ok):
    if ok is None:
        return "N/A"
    return "PASS" if ok else "MISS"


NOT_RUN = "not run"
NO_HEYOKA = "heyoka not installed or disabled (--peers scipy): no peer, not judged"


def _goal(goal, target, measured=NOT_RUN, ratio=None, status="N/A") -> dict:
    return {"goal": goal, "target": target, "measured": measured, "ratio": ratio, "status": status}


def evaluate_goals(wp, lr, tp, tq=None, ft=None, exact=None, cold=None, suite=None) -> list[dict]:
    """One row per goal: target, measured value(s), ratio to the peer or the target, PASS/MISS/N/A.

    The older issues' goals first (unprefixed), then issue 25's, each prefixed with its target's number
    ("[25.1c]"). A goal whose benchmark did not run (or whose JSON predates its rows) is N/A, "not run"; a goal
    judged against heyoka is N/A when heyoka is not installed or disabled, never PASS.
    """
    goals = []

    # exact, long run vs heyoka
    g = _goal(
        "exact: one output at t = 1e5 at least 100x faster than heyoka, equal or better accuracy",
        "t_heyoka / t_exact >= 100 and attitude error <= 2x heyoka's",
    )
    if lr:
        ex, hy = _row(lr["rows"], "exact"), _row(lr["rows"], "heyoka")
        t_end = lr["problem"]["t_end"]
        if ex and hy:
            ratio = hy["time_s"] / ex["time_s"]
            e_ex, e_hy = ex.get("attitude_error_rad"), hy.get("attitude_error_rad")
            acc = None if e_ex is None else e_ex <= 2 * e_hy
            g["measured"] = (
                f"t = {t_end:g}: exact {ex['time_s'] * 1e3:.3g} ms, heyoka {hy['time_s'] * 1e3:.3g} ms; "
                f"errors {e_ex:.1e} vs {e_hy:.1e} rad; energy {ex['energy_rel_error']:.0e} vs "
                f"{hy['energy_rel_error']:.0e}"
            )
            g["ratio"] = ratio
            g["status"] = _status(ratio >= 100 and bool(acc))
        else:
            g["measured"] = NO_HEYOKA
    goals.append(g)

    # exact throughput
    g = _goal(
        "exact: vectorized over bodies and times, <= 1 us per (body, time) with the attitude",
        ">= 1e6 evaluations/s per core",
    )
    if tp:
        r = _row(tp["rows"], "exact_solve")
        k = _row(tp["rows"], "exact_kernel")
        g["measured"] = (
            f"{r['value']:.3g} evaluations/s ({r['us_per_evaluation']:.2f} us) via solve; "
            f"kernel alone {k['value']:.3g}/s ({k['us_per_evaluation']:.2f} us)"
        )
        g["ratio"] = r["value"] / 1e6
        g["status"] = _status(r["value"] >= 1e6)
    goals.append(g)

    # taylor vs scipy DOP853 at 1e-13
    g = _goal(
        "taylor: at least 50x faster than scipy DOP853 at rtol = 1e-13 while more accurate",
        "t_DOP853 / t_taylor >= 50 and error_taylor < error_DOP853",
    )
    if wp:
        ta, dp = _curve_point(wp, "taylor", C.EPS), _curve_point(wp, "scipy-DOP853", 1e-13)
        if ta and dp:
            ratio = dp["time_s"] / ta["time_s"]
            g["measured"] = (
                f"taylor {ta['time_s'] * 1e3:.3g} ms ({ta['error_rad']:.1e} rad), "
                f"DOP853 {dp['time_s'] * 1e3:.3g} ms ({dp['error_rad']:.1e} rad)"
            )
            g["ratio"] = ratio
            g["status"] = _status(ratio >= 50 and ta["error_rad"] < dp["error_rad"])
    goals.append(g)

    # taylor batch
    g = _goal("taylor: batch mode at least 1e6 body-seconds per second per core at tol = eps", ">= 1e6 body-seconds/s")
    if tp:
        r = _row(tp["rows"], "taylor_batch")
        h = _row(tp["rows"], "heyoka_batch")
        g["measured"] = f"{r['value']:.3g} body-s/s" + (f" (heyoka batch {h['value']:.3g})" if h else "")
        g["ratio"] = r["value"] / 1e6
        g["status"] = _status(r["value"] >= 1e6)
    goals.append(g)

    # symplectic batch
    if tp:
        for scheme in ("splitting", "splitting4", "gauss4"):
            r = _row(tp["rows"], f"symplectic_{scheme}")
            if r:
                goals.append(
                    _goal(
                        f"symplectic ({scheme}): at least 1e7 body-steps per second per core in batch",
                        ">= 1e7 body-steps/s",
                        f"{r['value']:.3g} body-steps/s",
                        r["value"] / 1e7,
                        _status(r["value"] >= 1e7),
                    )
                )
    else:
        goals.append(_goal("symplectic: at least 1e7 body-steps per second per core in batch", ">= 1e7 body-steps/s"))

    # threads: every core against one
    g = _goal(
        "batches use all cores: exact, taylor and symplectic scale to >= 0.8 x the number of cores "
        "(bitwise identical results for any number of workers)",
        ">= 1.6x on 2 cores / >= 0.8 x cores (the slowest of the three)",
    )
    names = ("exact", "taylor", "symplectic")
    rows = {name: _row(tp["rows"], f"threads_{name}_speedup") for name in names} if tp else {}
    if rows and all(rows.values()):
        cores = int(next(iter(rows.values()))["cores"])
        need = 0.8 * cores
        worst = min(r["value"] for r in rows.values())
        g["measured"] = (
            f"{cores} cores: "
            + ", ".join(f"{n} {r['value']:.2f}x" for n, r in rows.items())
            + " (best of alternating runs, one thread vs all)"
        )
        g["ratio"] = worst / need if cores > 1 else None
        g["status"] = _status(worst >= need) if cores > 1 else "N/A"
        if cores == 1:
            g["measured"] += "; one usable core: nothing to scale"
    goals.append(g)
    # taylor on every core against heyoka's ensemble propagation on the same number of threads
    g = _goal(
        "taylor batch on all cores faster than heyoka's ensemble propagation on as many threads",
        "body-seconds/s(taylor) / body-seconds/s(heyoka ensemble_propagate_until_batch) > 1",
    )
    r = _row(tp["rows"], "threads_taylor_vs_heyoka_taylor") if tp else None
    h = _row(tp["rows"], "heyoka_ensemble") if tp else None
    if r and h:
        g["measured"] = f"{r['value']:.3g} vs {h['value']:.3g} body-s/s on {r['workers']} threads"
        g["ratio"] = r["value"] / h["value"]
        g["status"] = _status(r["value"] > h["value"])
    elif tp:
        g["measured"] = NO_HEYOKA
    goals.append(g)
    if tq:
        r = _row(tq["rows"], "exact_lagrange")
        if r:
            goals.append(
                _goal(
                    "exact: the Lagrange top <= 1 us per evaluation",
                    "<= 1 us per (body, time)",
                    f"{r['value']:.3g} us per (body, time)",
                    r["value"],
                    _status(r["value"] <= 1.0),
                )
            )
    if ft:
        for name, limit in (("fit_100", 2.0), ("fit_100_full", 2.0), ("fit_10000", 20.0)):
            r = _row(ft["rows"], name)
            if r is None:
                continue
            goals.append(
                _goal(
                    f"fit: {r['observations']} observations from the default starts under {limit:g} s "
                    f"({r['label'].split('principal_axes=')[-1]})",
                    f"<= {limit:g} s",
                    f"{r['value']:.3g} s, worst |z| {r['worst_z']:.2f}",
                    r["value"] / limit,
                    _status(r["value"] <= limit),
                )
            )
    if cold:
        # whole processes (bench_cold_start.py)
        r, i, n = (
            _row(cold["rows"], k) for k in ("cli_simulate_warm", "import_eulerpoisson", "cli_simulate_warm_nopyc")
        )
        goals.append(
            _goal(
                "cold start: a warm 'eulerpoisson simulate' of 1001 samples, end to end",
                "<= 0.5 s",
                f"{r['value']:.3g} s (import eulerpoisson {i['value']:.3g} s"
                + (f"; without .pyc files {n['value']:.3g} s" if n else "")
                + ")",
                r["value"] / 0.5,
                _status(r["value"] <= 0.5),
            )
        )
    goals += _issue25_goals(wp, tp, tq, ft, exact, cold, suite)
    return goals


def _rate_against_heyoka(g: dict, tp, ours: str, peer: str, detail) -> None:
    """Fill goal ``g``: the rate of row ``ours`` of the throughput benchmark against heyoka's row ``peer`` (>= 1)."""
    r, h = (_row(tp["rows"], k) for k in (ours, peer)) if tp else (None, None)
    if r and h:
        g["measured"] = f"{r['value']:.3g} vs {h['value']:.3g} body-s/s" + detail(r, h)
        g["ratio"], g["status"] = r["value"] / h["value"], _status(r["value"] >= h["value"])
    elif tp:
        g["measured"] = NO_HEYOKA


def _issue25_goals(wp, tp, tq, ft, exact, cold, suite) -> list[dict]:
    """The seven targets of issue 25, in its order, each with its peer where it has one."""
    goals = []

    # 1. per call ---------------------------------------------------------------------------------------
    calls = {r["name"]: r["value"] for r in exact["rows"] if r["name"].startswith("call_")} if exact else {}
    g = _goal(
        "[25.1a] per call: a tiny problem (one body, one time) with the exact method in a warm process, end to end",
        "<= 50 us",
    )
    if "call_exact_tiny" in calls:
        worst = max(v for k, v in calls.items() if k.startswith("call_exact_tiny"))
        g["measured"] = (
            f"{calls['call_exact_tiny']:.3g} us with numba active; "
            f"{calls.get('call_exact_tiny_default', float('nan')):.3g} us with the default threshold "
            "(the scalar kernel as plain Python, no numba)"
        )
        g["ratio"], g["status"] = worst / 50.0, _status(worst <= 50.0)
    goals.append(g)
    g = _goal("[25.1b] per call: the Python around a kernel (one body at t = 0; taylor at tol = 1e-6)", "<= 20 us")
    if {"call_exact_t0", "call_exact_t0_kernel", "call_taylor_t0"} <= set(calls):
        around = {
            "exact": calls["call_exact_t0"] - calls["call_exact_t0_kernel"],
            "taylor": calls["call_taylor_t0"] - calls.get("call_taylor_t0_kernel", 0.0),
        }
        g["measured"] = "; ".join(f"{k} {v:.3g} us" for k, v in around.items()) + " (numba active)"
        g["ratio"], g["status"] = max(around.values()) / 20.0, _status(max(around.values()) <= 20.0)
    goals.append(g)
    g = _goal(
        "[25.1c] taylor: one body to t = 100 at tol = eps no slower than heyoka's taylor_adaptive, "
        "at equal or better accuracy",
        "t_taylor / t_heyoka <= 1 on the reference problem and error_taylor <= error_heyoka (the median over "
        "40 random bodies when measured: one problem's error is one sample of the rounding)",
    )
    if wp:
        ta, hy = _curve_point(wp, "taylor", C.EPS), _curve_point(wp, "heyoka", C.EPS)
        if ta and hy:
            ratio = ta["time_s"] / hy["time_s"]
            g["measured"] = (
                f"t = {wp['problem']['t_end']:g}: taylor {ta['time_s'] * 1e3:.3g} ms "
                f"({ta['error_rad']:.1e} rad), heyoka {hy['time_s'] * 1e3:.3g} ms ({hy['error_rad']:.1e} rad)"
            )
            rb = wp.get("random_bodies")
            if rb:
                accurate = rb["taylor_median_rad"] <= rb["heyoka_median_rad"]
                g["measured"] += (
                    f"; {rb['bodies']} random bodies: median error taylor {rb['taylor_median_rad']:.1e} rad "
                    f"({rb['taylor_steps']} steps), heyoka {rb['heyoka_median_rad']:.1e} rad ({rb['heyoka_steps']} steps)"
                )
            else:
                accurate = ta["error_rad"] <= hy["error_rad"]
            g["ratio"] = ratio
            g["status"] = _status(ratio <= 1.0 and accurate)
        else:
            g["measured"] = NO_HEYOKA
    goals.append(g)

    # 2. batches per core and on all cores, against heyoka --------------------------------------------------
    g = _goal(
        "[25.2] taylor: batch mode per core at least heyoka's batch mode (tol = eps, one thread each)",
        "body-s/s(taylor batch) / body-s/s(heyoka batch) >= 1",
    )
    _rate_against_heyoka(
        g, tp, "taylor_batch", "heyoka_batch", lambda r, h: f" (heyoka SIMD width {h.get('simd_width', '?')})"
    )
    goals.append(g)
    g = _goal(
        "[25.2] taylor batch on all cores at least heyoka with one batch integrator per thread "
        "(written the fast way, as many threads)",
        "body-s/s(taylor, workers = cores) / body-s/s(heyoka, a batch integrator per thread) >= 1",
    )
    _rate_against_heyoka(
        g, tp, "threads_taylor_vs_heyoka_taylor", "heyoka_per_thread", lambda r, h: f" on {r['workers']} threads"
    )
    goals.append(g)

    # 3. the closed form (bench_exact.py) --------------------------------------------------------------------
    g = _goal(
        "[25.3] exact: distinct bodies each at one time (Monte-Carlo), with the attitude, via solve",
        ">= 2e6 evaluations/s per core",
    )
    r, k = (_row(exact["rows"], n) for n in ("exact_montecarlo", "exact_montecarlo_kernel")) if exact else (None, None)
    if r:
        g["measured"] = f"{r['value']:.3g}/s via solve ({r['us_per_evaluation']:.2f} us per body)" + (
            f"; kernel alone {k['value']:.3g}/s" if k else ""
        )
        g["ratio"], g["status"] = r["value"] / 2e6, _status(r["value"] >= 2e6)
    goals.append(g)
    g = _goal("[25.3] exact: one body at many times, via solve", "<= 0.15 us per evaluation")
    r, k = (_row(exact["rows"], n) for n in ("exact_many_times", "exact_many_times_kernel")) if exact else (None, None)
    if r:
        g["measured"] = f"{r['value']:.3g} us via solve" + (f"; kernel alone {k['value']:.3g} us" if k else "")
        g["ratio"], g["status"] = r["value"] / 0.15, _status(r["value"] <= 0.15)
    goals.append(g)

    # 4. taylor under gravity (bench_torque.py) ----------------------------------------------------------------
    g = _goal(
        "[25.4] taylor: a step under gravity within 1.5x the cost of a free-body step",
        "t_step(heavy top) / t_step(free body) <= 1.5",
    )
    r = _row(tq["rows"], "taylor_gravity_ratio") if tq else None
    if r:
        s, f = _row(tq["rows"], "taylor_gravity_step"), _row(tq["rows"], "taylor_free_step")
        g["measured"] = f"{s['value']:.3g} us vs {f['value']:.3g} us per step (a full tensor)"
        p = _row(tq["rows"], "taylor_gravity_ratio_principal")
        if p:  # (informative: the goal is judged on the benchmark's full tensor)
            g["measured"] += f"; the body given by its principal moments: {p['value']:.3g}x"
        g["ratio"], g["status"] = r["value"], _status(r["value"] <= 1.5)
    goals.append(g)

    # 5. waiting: the warm-up and the first simulate after it (bench_cold_start.py) -------------------------------
    g = _goal("[25.5] cold start: 'eulerpoisson warmup' into an empty numba cache", "<= 10 s on 2 cores")
    w = _row(cold["rows"], "warmup_fresh_cache") if cold else None
    if w:
        cores = w.get("cores")
        g["measured"] = f"{w['value']:.3g} s" + (f" on {cores} cores" if cores else "")
        if cores and cores != 2:
            g["measured"] += " (the target is for 2 cores)"
        g["ratio"], g["status"] = w["value"] / 10.0, _status(w["value"] <= 10.0)
    elif cold and cold.get("quick"):
        g["measured"] = "not run (--quick)"
    goals.append(g)
    g = _goal(
        "[25.5] cold start: the first 'eulerpoisson simulate' of 10^5 samples after the warm-up, each method, "
        "in a new process, end to end",
        "<= 0.5 s (the slowest of exact, taylor, symplectic)",
    )
    methods = ("exact", "taylor", "symplectic", "rk")
    first = {m: _row(cold["rows"], f"cli_first_simulate_1e5_{m}") for m in methods} if cold else {}
    first = {m: r for m, r in first.items() if r}
    judged = {m: first[m]["value"] for m in ("exact", "taylor", "symplectic") if m in first}
    if len(judged) == 3:
        worst = max(judged.values())
        g["measured"] = ", ".join(f"{m} {v:.3g} s" for m, v in judged.items())
        if "rk" in first:
            g["measured"] += f"; rk (scipy's solve_ivp stepper, not judged) {first['rk']['value']:.3g} s"
        if first["exact"].get("cache") == "default":
            g["measured"] += " (quick: 1000 samples, numba's default cache, no fresh warm-up)"
        g["ratio"], g["status"] = worst / 0.5, _status(worst <= 0.5)
    goals.append(g)

    # 6. fit on the Toutatis-like case (bench_fit.py) ---------------------------------------------------------
    g = _goal(
        "[25.6] fit: the Toutatis-like case (a long-axis-mode tumbler, several optima) from the default starts",
        "<= 2 s and the lowest chi2 found (that of a fit started at the truth)",
    )
    r = _row(ft["rows"], "fit_toutatis") if ft else None
    if r:
        found = bool(r.get("lowest_found"))
        g["measured"] = (
            f"{r['value']:.3g} s, {r['starts']} starts, distinct optima found: {r['optima']}; chi2 {r['chi2']:.3f} "
            f"(from the truth {r['chi2_from_truth']:.3f}): " + ("lowest found" if found else "lowest MISSED")
        )
        g["ratio"], g["status"] = r["value"] / 2.0, _status(r["value"] <= 2.0 and found)
    goals.append(g)

    # 7. make test on a fresh clone (bench_test_suite.py) -----------------------------------------------------
    g = _goal(
        "[25.7] 'make test' on a fresh clone as CI runs it (its own venv, an empty numba cache)",
        "<= 360 s wall on 2 cores",
    )
    r = _row(suite["rows"], "make_test") if suite else None
    if r:
        state = str(r.get("status", "ok"))
        if state.startswith("not run"):
            g["measured"] = state
        elif r["value"] is None:  # e.g. the clone failed
            g["measured"], g["status"] = f"make test not run: {state}", "MISS"
        else:
            g["measured"] = _suite_measured(suite, r)
            g["ratio"], g["status"] = r["value"] / 360.0, _status(state == "ok" and r["value"] <= 360.0)
    goals.append(g)
    return goals


def _suite_measured(suite, r) -> str:
    """The measured text of the make-test goal: the total, its parts, the counts, the commit."""
    p, w, rest = (_row(suite["rows"], k) for k in ("make_test_pytest", "make_test_warmup", "make_test_rest"))
    text = f"{r['value']:.0f} s in all"
    state = r.get("status", "ok")
    if state != "ok":
        text = f"make test {state}" + ("" if state.startswith("timed out") else f" after {r['value']:.0f} s")
    parts = []
    if p:
        counts = ", ".join(f"{p[k]} {k}" for k in ("passed", "failed", "skipped", "errors") if p.get(k))
        parts.append(f"pytest {p['value']:.0f} s" + (f": {counts}" if counts else ""))
    if w:
        parts.append(f"warm-up {w['value']:.0f} s")
    if rest:
        parts.append(f"venv, installs and the rest {rest['value']:.0f} s")
    if parts:
        text += " (" + "; ".join(parts) + ")"
    cores = r.get("cores")
    if cores:
        text += f" on {cores} cores" + (" (the target is for 2 cores)" if cores != 2 else "")
    if r.get("commit"):
        text += f", commit {r['commit'][:10]}"
    return text


# ---------------------------------------------------------------------------
# summary
# ---------------------------------------------------------------------------
def _fmt_ratio(r):
    return "" if r is None else f"{r:.3g}"


def summary_markdown(
    wp, lr, tp, goals, machine, command, quick, tq=None, ft=None, exact=None, cold=None, suite=None
) -> str:
    L = []
    L.append("# Benchmark summary")
    L.append("")
    if quick:
        L.append("**QUICK RUN: tiny configuration, not representative.**")
        L.append("")
    L.append(f"- generated: {C.now_iso()}")
    L.append(f"- command: `{command}`")
    L.append(
        f"- machine: {machine['cpu']}, {machine['usable_cpus']} usable cores ({machine['logical_cpus']} logical); "
        f"{machine['platform']}; 1-min load average {machine.get('load_average_at_start')} at the start, "
        f"{machine.get('load_average_at_end')} at the end (above ~0 other processes shared the cores)"
    )
    L.append(
        f"- software: Python {machine['python']}, numpy {machine['numpy']}, scipy {machine['scipy']}, "
        f"numba {machine['numba']}, eulerpoisson {machine['eulerpoisson']}, heyoka {machine['heyoka'] or 'not installed'}, "
        f"MuJoCo {machine['mujoco'] or 'not installed'}; peers measured: {', '.join(machine.get('peers', []))}"
    )
    L.append(
        "- every measurement on one thread except the threads rows (one thread against every core); "
        "times are the best of several calls after a warm-up call, "
        "compilation (numba, heyoka's LLVM, MuJoCo's model) not timed (details in benchmarks/README.md); "
        "goals are ratios against peers of the same run"
    )
    L.append("")
    L.append("## Goals of the issue")
    L.append("")
    L.append("| goal | target | measured | ratio | status |")
    L.append("|---|---|---|---|---|")
    for g in goals:
        L.append(f"| {g['goal']} | {g['target']} | {g['measured']} | {_fmt_ratio(g['ratio'])} | **{g['status']}** |")
    L.append("")
    L.append(
        "Ratio: the goal's quotient as its target writes it (peer time / our time, our time / peer time, our "
        "rate / the peer's rate or the target rate, our time / the time allowed). Issue 25's goals are marked "
        "[25.N]; a goal judged against heyoka is N/A when heyoka is not installed, never PASS."
    )
    if wp:
        L.append("")
        L.append(f"## Work-precision (t = {wp['problem']['t_end']:g})")
        L.append("")
        L.append(f"Reference: {wp['reference']['source']}.")
        cc = wp["reference"].get("crosscheck")
        if cc:
            L.append(f"Cross-check: {cc['what']} differs from it by {cc['attitude_difference_rad']:.1e} rad.")
        L.append("")
        L.append("![work-precision diagram](work_precision.png)")
        L.append("")
        L.append("| method | knob | time (ms) | attitude error (rad) | energy error |")
        L.append("|---|---|---|---|---|")
        for c in wp["curves"]:
            for p in c["points"]:
                knob = "-" if p["knob"] is None else f"{c['knob']} = {p['knob']:.3g}"
                L.append(
                    f"| {c['label']} | {knob} | {p['time_s'] * 1e3:.4g} | {p['error_rad']:.2e} | "
                    f"{p['energy_rel_error']:.1e} |"
                )
        for n in wp.get("notes", []):
            L.append(f"\n- {n}")
    if lr:
        L.append("")
        L.append(f"## Long run (t = {lr['problem']['t_end']:g}, one output time)")
        L.append("")
        if lr.get("reference"):
            L.append(f"Reference: {lr['reference']['source']}.")
            L.append("")
        L.append("| method | time (s) | attitude error (rad) | difference from exact (rad) | energy error |")
        L.append("|---|---|---|---|---|")
        for r in lr["rows"]:
            e = r.get("attitude_error_rad")
            L.append(
                f"| {r['label']} | {r['time_s']:.4g} | {'-' if e is None else f'{e:.2e}'} | "
                f"{r['attitude_difference_from_exact_rad']:.2e} | {r['energy_rel_error']:.1e} |"
            )
        for n in lr.get("notes", []):
            L.append(f"\n- {n}")
    if tp:
        L.append("")
        L.append("## Throughput (one thread; the threads rows: one thread and every core)")
        L.append("")
        L.append("| what | rate | unit |")
        L.append("|---|---|---|")
        for r in tp["rows"]:
            L.append(f"| {r['label']} | {r['value']:.3g} | {r['unit']} |")
        ex = _row(tp["rows"], "exact_solve")
        ej = _row(tp["rows"], "scipy_ellipj")
        if ex and ej:
            L.append("")
            L.append(
                f"One exact evaluation (body, time, attitude included) costs "
                f"{ex['us_per_evaluation'] * 1e3 / ej['value']:.3g} scipy ellipj evaluations."
            )
    if tq:
        L.append("")
        L.append("## Bodies under torque (one thread)")
        L.append("")
        L.append("| what | value | unit | attitude error (rad) |")
        L.append("|---|---|---|---|")
        for r in tq["rows"]:
            e = r.get("attitude_error_rad")
            L.append(f"| {r['label']} | {r['value']:.3g} | {r['unit']} | {'-' if e is None else f'{e:.1e}'} |")
    if ft:
        L.append("")
        L.append("## Spin-state estimation (one thread)")
        L.append("")
        L.append("| what | time (s) | starts | distinct optima | reduced chi2 | worst \\|z\\| |")
        L.append("|---|---|---|---|---|---|")
        for r in ft["rows"]:
            if "reduced_chi2" not in r:  # the Toutatis-like row: chi2 against that of a start at the truth
                found = "lowest found" if r.get("lowest_found") else "**lowest missed**"
                L.append(
                    f"| {r['label']} | {r['value']:.3g} | {r['starts']} | {r['optima']} | chi2 {r['chi2']:.3f} "
                    f"(from the truth {r['chi2_from_truth']:.3f}) | {found} |"
                )
                continue
            L.append(
                f"| {r['label']} | {r['value']:.3g} | {r['starts']} | {r['optima']} | {r['reduced_chi2']:.3f} "
                f"| {r['worst_z']:.2f} |"
            )
    if exact:
        L.append("")
        L.append("## The exact method: Monte-Carlo and many times (one thread)")
        L.append("")
        L.append("| what | value | unit |")
        L.append("|---|---|---|")
        for r in exact["rows"]:
            if "counts" in r:
                work = ", ".join(f"{k} {v:.3g}" for k, v in r["counts"].items())
                L.append(f"| {r['label']} | {work} | per {r['unit'].split(' per ')[-1]} |")
            else:
                L.append(f"| {r['label']} | {r['value']:.3g} | {r['unit']} |")
    if cold:
        L.append("")
        L.append("## Cold and warm starts (whole processes, best of several)")
        L.append("")
        L.append("| what | wall time (s) |")
        L.append("|---|---|")
        for r in cold["rows"]:
            L.append(f"| {r['label']} | {r['value']:.3g} |")
    if suite:
        L.append("")
        L.append("## The test suite on a fresh clone (`make test` as CI runs it, an empty numba cache)")
        L.append("")
        if suite.get("commit"):
            dirty = suite.get("uncommitted_changes")
            L.append(
                f"Commit {suite['commit']}"
                + (" (the working tree had uncommitted changes, which a clone leaves out)" if dirty else "")
                + "."
            )
            L.append("")
        L.append("| what | wall time (s) | status |")
        L.append("|---|---|---|")
        for r in suite["rows"]:
            value = "-" if r["value"] is None else f"{r['value']:.1f}"
            state = r.get("status") or r.get("line") or ""
            L.append(f"| {r['label'].strip()} | {value} | {state} |")
        tail = next((r.get("output_tail") for r in suite["rows"] if r.get("output_tail")), None)
        if tail:
            L.append("")
            L.append("The end of its output:")
            L.append("")
            L.append("```")
            L.append(tail.strip()[-2000:])
            L.append("```")
    L.append("")
    L.append("## Reference points quoted by the issue (2-core machine, not measured here)")
    L.append("")
    L.append(
        "heyoka tol = eps: 4e-15 rad, 0.20 ms; scipy DOP853 1e-13: 7e-12, 38 ms; scipy RK45 1e-9: 1e-7, 31 ms; "
        "MuJoCo RK4 dt = 1e-3: 3e-13, 520 ms; Basilisk RK4 dt = 1e-3: 2e-13, 860 ms. To t = 1e5: heyoka 0.2 s "
        "(energy drift 2e-14), DOP853 28 s (5e-9). heyoka batch ~2e6 body-s/s/core; SIMD C RK4 4e8 "
        "body-steps/s; scipy ellipj ~200 ns."
    )
    L.append("")
    return "\n".join(L)


def speed_table(goals: list[dict], machine: dict) -> str:
    """The Speed table of the project's README: every goal of this run with its measurement and status."""
    lines = [
        f"Measured {C.now_iso()[:10]} by `make bench` on {machine['cpu']}, {machine['usable_cpus']} cores "
        f"(peers: {', '.join(machine.get('peers', []))}; goals prefixed [25.N] are issue 25's targets):",
        "",
        "| goal (ratio against a peer in the same run) | measured | status |",
        "|---|---|---|",
    ]
    for g in goals:
        measured = str(g["measured"]).replace("|", "\\|")
        lines.append(f"| {g['goal']} | {measured} | {g['status'].lower()} |")
    return "\n".join(lines)


def _update_speed_table(goals: list[dict], machine: dict) -> bool:
    """Write :func:`speed_table` between the markers of the README's Speed section; False without them."""
    if not MAIN_README.exists():
        return False
    text = MAIN_README.read_text(encoding="utf-8")
    if SPEED_START not in text or SPEED_END not in text:
        return False
    head, rest = text.split(SPEED_START, 1)
    _, tail = rest.split(SPEED_END, 1)
    MAIN_README.write_text(f"{head}{SPEED_START}\n{speed_table(goals, machine)}\n{SPEED_END}{tail}", encoding="utf-8")
    return True


def _update_readme(summary: str) -> bool:
    if not README.exists():
        return False
    text = README.read_text()
    if README_START not in text or README_END not in text:
        return False
    head, rest = text.split(README_START, 1)
    _, tail = rest.split(README_END, 1)
    lines = summary.splitlines()
    if lines and lines[0].startswith("# "):
        lines = lines[1:]
    body = "\n".join("#" + ln if ln.startswith("## ") else ln for ln in lines).strip("\n")
    body = body.replace("](work_precision.png)", "](results/work_precision.png)")
    README.write_text(f"{head}{README_START}\n{body}\n{README_END}{tail}")
    return True


# ---------------------------------------------------------------------------
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="tiny configuration (seconds); not representative")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output directory (default benchmarks/results)")
    ap.add_argument(
        "--only",
        choices=BENCHMARKS,
        action="append",
        help="run only this benchmark (repeatable); the summary reuses the others' JSON in --out",
    )
    ap.add_argument(
        "--skip",
        choices=BENCHMARKS,
        action="append",
        default=[],
        help="run every benchmark (or every --only) but this one (repeatable; e.g. --skip test_suite); "
        "the summary reuses its JSON in --out",
    )
    ap.add_argument(
        "--summary-only",
        action="store_true",
        help="run nothing: rebuild summary.md, goals.json (and the README block) from the JSON in --out",
    )
    ap.add_argument(
        "--peers",
        choices=("all", "scipy"),
        default="all",
        help="'all': scipy and the optional peers that import (heyoka, MuJoCo); 'scipy': scipy only",
    )
    ap.add_argument("--no-readme", action="store_true", help="do not refresh the results block of benchmarks/README.md")
    args = ap.parse_args(argv)
    command = C.command_line(argv)
    machine = C.machine_info()
    C.OPTIONAL_PEERS.clear()
    if args.peers == "all":
        C.OPTIONAL_PEERS.update(C.ALL_OPTIONAL_PEERS)
    machine["peers"] = ["scipy", *sorted(p for p in C.OPTIONAL_PEERS if machine.get(p))]
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    selected = [] if args.summary_only else [n for n in (args.only or BENCHMARKS) if n not in args.skip]
    print(f"eulerpoisson benchmarks -> {out}  ({C.machine_line(machine)})")
    results = {}
    for name in BENCHMARKS:
        path = out / f"{name}.json"
        if name in selected:
            print(f"[{name}]")
            t0 = time.perf_counter()
            load_before = C.load_average()
            body = _module(name).run(quick=args.quick)
            # the load that make test itself puts on every core is not "other processes"
            machine["load_average_at_end"] = load_before if name == "test_suite" else C.load_average()
            payload = C.envelope(name, quick=args.quick, command=command, machine=machine, **body)
            payload["elapsed_s"] = time.perf_counter() - t0
            C.write_json(path, payload)
            print(f"  -> {path} ({payload['elapsed_s']:.1f} s)")
            results[name] = json.loads(path.read_text())
            if name == "work_precision":
                _module(name).plot(results[name], out / "work_precision.png")
                print(f"  -> {out / 'work_precision.png'}")
        elif path.exists():
            results[name] = json.loads(path.read_text())
    if "test_suite" not in selected or args.quick:
        machine["load_average_at_end"] = C.load_average()
    wp, lr, tp, tq, ft, exact, cold, suite = (results.get(n) for n in BENCHMARKS)
    if args.summary_only:
        # describe the machine and command of the runs that produced the JSON, not of this call
        runs = [r for r in (wp, lr, tp, tq, ft, exact, cold, suite) if r]
        if runs:
            machine, command = dict(runs[0]["machine"]), runs[0]["command"]
            ends = [r["machine"].get("load_average_at_end") for r in runs]
            machine["load_average_at_end"] = max((e for e in ends if e is not None), default=None)
            args.quick = bool(runs[0].get("quick"))
    goals = evaluate_goals(wp, lr, tp, tq, ft, exact, cold, suite)
    C.write_json(
        out / "goals.json", C.envelope("goals", quick=args.quick, command=command, machine=machine, goals=goals)
    )
    summary = summary_markdown(wp, lr, tp, goals, machine, command, args.quick, tq, ft, exact, cold, suite)
    (out / "summary.md").write_text(summary)
    print(f"  -> {out / 'summary.md'}")
    for g in goals:
        print(f"  {g['status']:4s}  {g['goal']}  [{g['measured']}]")
    if (
        not args.quick
        and not args.no_readme
        and out.resolve() == DEFAULT_OUT.resolve()
        and all(results.get(n) for n in BENCHMARKS)
    ):
        if _update_readme(summary):
            print(f"  -> {README} (results block)")
        if _update_speed_table(goals, machine):
            print(f"  -> {MAIN_README} (Speed table)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
