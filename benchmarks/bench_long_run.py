"""Long run: the reference body to t = 1e5 (quick mode: 100), one output time.

For each method: wall time (best of repeats after a warm-up, except for the slow scipy run,
which is timed once), relative energy error at the end, and the attitude error against an
80-bit heyoka reference (when heyoka is installed; otherwise the attitude is compared with the
exact method, which is then marked as the reference, not as a measured error).

Methods: eulerpoisson exact (one output time, O(1)), eulerpoisson taylor at tol = eps, heyoka at
tol = eps (double precision), and the user's baseline scipy ``solve_ivp`` DOP853 with
rtol = atol = 1e-13, run over the whole interval (about half a minute; nothing extrapolated).

    .venv/bin/python benchmarks/bench_long_run.py [--quick] [--out DIR]
"""

from __future__ import annotations

import time

import _common as C


def run(quick: bool = False, log=print) -> dict:
    t_end = 100.0 if quick else 1e5
    repeats = 1 if quick else 5
    hy = C.heyoka_module()
    ref = None
    if hy is not None:
        t0 = time.perf_counter()
        r = C.heyoka_reference(hy, t_end, kind="longdouble")
        ref = {"q": r[0], "source": r[2], "wall_s": time.perf_counter() - t0}
        log(f"  reference: {ref['source']} ({ref['wall_s']:.1f} s)")
    rows = []

    def row(name, label, fn, *, timed_repeats, warmup=True):
        wall, (q, om), n = C.best_time(fn, repeats=timed_repeats, budget=10.0, warmup=warmup)
        rows.append(
            {
                "name": name,
                "label": label,
                "time_s": wall,
                "timed_calls": n,
                "q": q,
                "energy_rel_error": C.relative_energy_error(om),
            }
        )
        log(f"  {label:40s} time={wall:10.4f} s  energy error={rows[-1]['energy_rel_error']:.1e}")

    from eulerpoisson.solvers import solve

    def ep(method, **opts):
        def f():
            tr = solve(list(C.INERTIA), [t_end], omega0=list(C.OMEGA0), method=method, **opts)
            return tr.quaternion[0], tr.omega[0]

        return f

    row("exact", "eulerpoisson exact (one output time)", ep("exact"), timed_repeats=50)
    row("taylor", "eulerpoisson taylor tol=eps", ep("taylor", tol=C.EPS), timed_repeats=repeats)
    if hy is not None:
        peer = C.HeyokaPeer(hy, C.EPS)
        row("heyoka", f"heyoka {hy.__version__} tol=eps", lambda: peer.run(t_end), timed_repeats=repeats)

    def dop():
        q, om, _ = C.scipy_solve(t_end, "DOP853", 1e-13, 1e-13)
        return q, om

    row("scipy-DOP853", "scipy solve_ivp DOP853 rtol=atol=1e-13", dop, timed_repeats=1, warmup=quick)

    exact_q = rows[0]["q"]
    for r in rows:
        if ref is not None:
            r["attitude_error_rad"] = C.attitude_error(r["q"], ref["q"])
        r["attitude_difference_from_exact_rad"] = C.attitude_error(r["q"], exact_q)
        r["q"] = [float(v) for v in r["q"]]
    notes = []
    if ref is None:
        notes.append(
            "heyoka is not installed (or --peers scipy): no high-precision reference; attitudes are "
            "compared with the exact method only (attitude_difference_from_exact_rad)"
        )
    notes.append("scipy DOP853 is run over the whole interval and timed once (no warm-up, no repeats)")
    return {
        "problem": {"inertia": C.INERTIA, "omega0": C.OMEGA0, "q0": C.Q0, "t_end": t_end},
        "reference": None if ref is None else {"source": ref["source"], "q": [str(v) for v in ref["q"]]},
        "rows": rows,
        "notes": notes,
    }


if __name__ == "__main__":  # pragma: no cover
    import runpy
    import sys
    from pathlib import Path

    sys.argv = [sys.argv[0], "--only", "long_run", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
