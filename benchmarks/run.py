"""Run the eulerpoisson benchmarks and write benchmarks/results/ (JSON, PNG, summary.md).

Three benchmarks (``--only`` picks one; the others' latest JSON in ``--out`` is reused for the
summary when present):

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
    inertia) and 10^4 observations: ``fit.json``;
``cold_start``
    whole command-line processes: ``import eulerpoisson``, a warm ``eulerpoisson simulate`` of the
    issue's small problem, ``eulerpoisson warmup`` into an empty numba cache and the first
    ``simulate`` after it (small, and large enough for the compiled kernel): ``cold_start.json``.

``summary.md`` gathers the tables, the ratios against the peers measured in the same run and a
PASS/MISS column for each goal of the issue, with the machine and the command. Every
measurement uses one thread (``EULERPOISSON_WORKERS=1`` unless set) and the compiled kernels
(``EULERPOISSON_NUMPY_BELOW=0`` unless set: small problems too; ``cold_start`` measures the
default, where small problems are solved by NumPy without importing numba), except the threads rows of
the throughput benchmark, which pass ``workers=`` explicitly. ``--quick`` runs a tiny
configuration (seconds; for the smoke test, not representative). When the full run writes to the default directory, the results block of
benchmarks/README.md is refreshed too (``--no-readme`` to skip).

Peers: scipy (always), heyoka and MuJoCo when importable (``pip install heyoka mujoco``).

    .venv/bin/python benchmarks/run.py                  # full run, about 3-5 minutes
    .venv/bin/python benchmarks/run.py --quick --out /tmp/bench
    .venv/bin/python benchmarks/run.py --only throughput
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
BENCHMARKS = ("work_precision", "long_run", "throughput", "torque", "fit", "exact", "cold_start")
README = HERE / "README.md"
README_START = "<!-- results:start -->"
README_END = "<!-- results:end -->"


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


def evaluate_goals(wp, lr, tp, tq=None, ft=None, exact=None, cold=None) -> list[dict]:
    """One row per goal of the issue: target, measured value(s), ratio to the peer, PASS/MISS/N/A."""
    goals = []

    # exact, long run vs heyoka
    g = {
        "goal": "exact: one output at t = 1e5 at least 100x faster than heyoka, equal or better accuracy",
        "target": "t_heyoka / t_exact >= 100 and attitude error <= 2x heyoka's",
    }
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
            g["measured"], g["ratio"], g["status"] = "heyoka not installed or disabled", None, "N/A"
    goals.append(g)

    # exact throughput
    g = {
        "goal": "exact: vectorized over bodies and times, <= 1 us per (body, time) with the attitude",
        "target": ">= 1e6 evaluations/s per core",
    }
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

    # taylor vs heyoka, one body, tol = eps
    g = {
        "goal": "taylor: one body at tol = eps within 3x of heyoka's time at equal accuracy",
        "target": "t_taylor / t_heyoka <= 3 and error <= 2x heyoka's",
    }
    if wp:
        ta, hy = _curve_point(wp, "taylor", C.EPS), _curve_point(wp, "heyoka", C.EPS)
        if ta and hy:
            ratio = ta["time_s"] / hy["time_s"]
            g["measured"] = (
                f"t = {wp['problem']['t_end']:g}: taylor {ta['time_s'] * 1e3:.3g} ms "
                f"({ta['error_rad']:.1e} rad), heyoka {hy['time_s'] * 1e3:.3g} ms ({hy['error_rad']:.1e} rad)"
            )
            g["ratio"] = ratio
            g["status"] = _status(ratio <= 3 and ta["error_rad"] <= 2 * hy["error_rad"])
        else:
            g["measured"], g["ratio"], g["status"] = "heyoka not installed or disabled", None, "N/A"
    goals.append(g)

    # taylor vs scipy DOP853 at 1e-13
    g = {
        "goal": "taylor: at least 50x faster than scipy DOP853 at rtol = 1e-13 while more accurate",
        "target": "t_DOP853 / t_taylor >= 50 and error_taylor < error_DOP853",
    }
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
    g = {
        "goal": "taylor: batch mode at least 1e6 body-seconds per second per core at tol = eps",
        "target": ">= 1e6 body-seconds/s",
    }
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
                    {
                        "goal": f"symplectic ({scheme}): at least 1e7 body-steps per second per core in batch",
                        "target": ">= 1e7 body-steps/s",
                        "measured": f"{r['value']:.3g} body-steps/s",
                        "ratio": r["value"] / 1e7,
                        "status": _status(r["value"] >= 1e7),
                    }
                )
    else:
        goals.append(
            {
                "goal": "symplectic: at least 1e7 body-steps per second per core in batch",
                "target": ">= 1e7 body-steps/s",
            }
        )

    # threads: every core against one
    g = {
        "goal": "batches use all cores: exact, taylor and symplectic scale to >= 0.8 x the number of cores "
        "(bitwise identical results for any number of workers)",
        "target": ">= 1.6x on 2 cores / >= 0.8 x cores (the slowest of the three)",
    }
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
    g = {
        "goal": "taylor batch on all cores faster than heyoka's ensemble propagation on as many threads",
        "target": "body-seconds/s(taylor) / body-seconds/s(heyoka ensemble_propagate_until_batch) > 1",
    }
    r = _row(tp["rows"], "threads_taylor_vs_heyoka_taylor") if tp else None
    h = _row(tp["rows"], "heyoka_ensemble") if tp else None
    if r and h:
        hp = _row(tp["rows"], "heyoka_per_thread")
        g["measured"] = f"{r['value']:.3g} vs {h['value']:.3g} body-s/s on {r['workers']} threads" + (
            f"; heyoka with one batch integrator per thread (hand-written) {hp['value']:.3g}" if hp else ""
        )
        g["ratio"] = r["value"] / h["value"]
        g["status"] = _status(r["value"] > h["value"])
    elif tp:
        g["measured"] = "heyoka not installed"
    goals.append(g)
    for g in goals:
        g.setdefault("measured", "not run")
        g.setdefault("ratio", None)
        g.setdefault("status", "N/A")
    if tq:
        r = _row(tq["rows"], "taylor_gravity_ratio")
        g = {
            "goal": "taylor: a step under gravity within 1.5x the cost of a free-body step",
            "target": "t_step(heavy top) / t_step(free body) <= 1.5",
        }
        g["measured"] = (
            f"{_row(tq['rows'], 'taylor_gravity_step')['value']:.3g} us vs "
            f"{_row(tq['rows'], 'taylor_free_step')['value']:.3g} us per step"
        )
        g["ratio"] = r["value"]
        g["status"] = _status(r["value"] <= 1.5)
        goals.append(g)
        r = _row(tq["rows"], "exact_lagrange")
        g = {
            "goal": "exact: the Lagrange top <= 1 us per evaluation",
            "target": "<= 1 us per (body, time)",
            "measured": f"{r['value']:.3g} us per (body, time)",
            "ratio": r["value"],
            "status": _status(r["value"] <= 1.0),
        }
        goals.append(g)
    if ft:
        for name, limit in (("fit_100", 2.0), ("fit_100_full", 2.0), ("fit_10000", 20.0)):
            r = _row(ft["rows"], name)
            if r is None:
                continue
            g = {
                "goal": f"fit: {r['observations']} observations from the default starts under {limit:g} s "
                f"({r['label'].split('principal_axes=')[-1]})",
                "target": f"<= {limit:g} s",
                "measured": f"{r['value']:.3g} s, worst |z| {r['worst_z']:.2f}",
                "ratio": r["value"] / limit,
                "status": _status(r["value"] <= limit),
            }
            goals.append(g)
    if exact:
        # the closed form: distinct bodies at one time each, one body at many times (bench_exact.py)
        r, k = _row(exact["rows"], "exact_montecarlo"), _row(exact["rows"], "exact_montecarlo_kernel")
        goals.append(
            {
                "goal": "exact: distinct bodies each at one time (Monte-Carlo), with the attitude",
                "target": ">= 2e6 evaluations/s per core",
                "measured": f"{r['value']:.3g}/s via solve ({r['us_per_evaluation']:.2f} us per body); "
                f"kernel alone {k['value']:.3g}/s",
                "ratio": r["value"] / 2e6,
                "status": _status(r["value"] >= 2e6),
            }
        )
        r, k = _row(exact["rows"], "exact_many_times"), _row(exact["rows"], "exact_many_times_kernel")
        goals.append(
            {
                "goal": "exact: one body at many times",
                "target": "<= 0.3 us per evaluation",
                "measured": f"{r['value']:.3g} us via solve; kernel alone {k['value']:.3g} us",
                "ratio": r["value"] / 0.3,
                "status": _status(r["value"] <= 0.3),
            }
        )
        calls = {r["name"]: r["value"] for r in exact["rows"] if r["name"].startswith("call_")}
        if "call_exact_tiny" in calls:
            worst = max(v for k, v in calls.items() if k.startswith("call_exact_tiny"))
            goals.append(
                {
                    "goal": "per call: a tiny problem (one body, one time) with the exact method, end to end",
                    "target": "<= 50 us",
                    "measured": f"{calls['call_exact_tiny']:.3g} us with numba active; "
                    f"{calls.get('call_exact_tiny_default', float('nan')):.3g} us with the default threshold "
                    "(the scalar kernel as plain Python, no numba)",
                    "ratio": worst / 50.0,
                    "status": _status(worst <= 50.0),
                }
            )
            around = {
                "exact": calls["call_exact_t0"] - calls["call_exact_t0_kernel"],
                "taylor": calls["call_taylor_t0"] - calls.get("call_taylor_t0_kernel", 0.0),
            }
            goals.append(
                {
                    "goal": "per call: the Python around a kernel (one body at t = 0; taylor at tol = 1e-6)",
                    "target": "<= 20 us",
                    "measured": "; ".join(f"{k} {v:.3g} us" for k, v in around.items()) + " (numba active)",
                    "ratio": max(around.values()) / 20.0,
                    "status": _status(max(around.values()) <= 20.0),
                }
            )
    if cold:
        # whole processes (bench_cold_start.py)
        r, i, n = (
            _row(cold["rows"], k) for k in ("cli_simulate_warm", "import_eulerpoisson", "cli_simulate_warm_nopyc")
        )
        goals.append(
            {
                "goal": "cold start: a warm 'eulerpoisson simulate' of 1001 samples, end to end",
                "target": "<= 0.5 s",
                "measured": f"{r['value']:.3g} s (import eulerpoisson {i['value']:.3g} s"
                + (f"; without .pyc files {n['value']:.3g} s" if n else "")
                + ")",
                "ratio": r["value"] / 0.5,
                "status": _status(r["value"] <= 0.5),
            }
        )
        f, c, w = (
            _row(cold["rows"], k)
            for k in (
                "cli_first_simulate_after_warmup",
                "cli_first_compiled_simulate_after_warmup",
                "warmup_fresh_cache",
            )
        )
        worst = max(x["value"] for x in (f, c) if x)
        goals.append(
            {
                "goal": "cold start: the first 'eulerpoisson simulate' after the warm-up (an empty numba cache "
                "filled by 'eulerpoisson warmup')",
                "target": "<= 3 s",
                "measured": f"1001 samples {f['value']:.3g} s"
                + (f"; 2e5 samples (compiled) {c['value']:.3g} s" if c else "")
                + (f"; the warm-up {w['value']:.3g} s" if w else "; no warm-up run (quick)"),
                "ratio": worst / 3.0,
                "status": _status(worst <= 3.0),
            }
        )
    return goals


# ---------------------------------------------------------------------------
# summary
# ---------------------------------------------------------------------------
def _fmt_ratio(r):
    return "" if r is None else f"{r:.3g}"


def summary_markdown(wp, lr, tp, goals, machine, command, quick, tq=None, ft=None, exact=None, cold=None) -> str:
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
        "Ratio: the goal's quotient (peer time / our time, or our time / peer time for the 3x goal, "
        "or measured rate / target rate)."
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
    selected = [] if args.summary_only else (args.only or list(BENCHMARKS))
    print(f"eulerpoisson benchmarks -> {out}  ({C.machine_line(machine)})")
    results = {}
    for name in BENCHMARKS:
        path = out / f"{name}.json"
        if name in selected:
            print(f"[{name}]")
            t0 = time.perf_counter()
            body = _module(name).run(quick=args.quick)
            machine["load_average_at_end"] = C.load_average()
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
    machine["load_average_at_end"] = C.load_average()
    wp, lr, tp, tq, ft, exact, cold = (results.get(n) for n in BENCHMARKS)
    if args.summary_only:
        # describe the machine and command of the runs that produced the JSON, not of this call
        runs = [r for r in (wp, lr, tp, tq, ft, exact, cold) if r]
        if runs:
            machine, command = dict(runs[0]["machine"]), runs[0]["command"]
            ends = [r["machine"].get("load_average_at_end") for r in runs]
            machine["load_average_at_end"] = max((e for e in ends if e is not None), default=None)
            args.quick = bool(runs[0].get("quick"))
    goals = evaluate_goals(wp, lr, tp, tq, ft, exact, cold)
    C.write_json(
        out / "goals.json", C.envelope("goals", quick=args.quick, command=command, machine=machine, goals=goals)
    )
    summary = summary_markdown(wp, lr, tp, goals, machine, command, args.quick, tq, ft, exact, cold)
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
