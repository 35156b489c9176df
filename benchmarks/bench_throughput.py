"""Throughput of the batched (vectorized) paths: one thread, and all cores against one thread.

* exact: evaluations per second for B bodies x T output times, attitude and angular velocity
  included, through ``solve`` and through the kernel ``_exact.exact_motion`` alone;
* taylor: body-seconds per second (simulated time x bodies / wall time) at tol = eps for a batch
  of B bodies integrated to t_end, and the same for heyoka's batch (SIMD) mode when installed;
* symplectic: body-steps per second for a batch of B bodies (splitting, splitting4, gauss4);
* scipy's ``special.ellipj``: nanoseconds per evaluation, the cost of one Jacobi elliptic
  function triple, as the yardstick of the exact method;
* threads (``solve(..., workers=)``): exact, taylor and symplectic (gauss4, the default scheme)
  batches on one thread and on every usable core, and the speed-up. The two are timed alternately
  (one thread, all cores, one thread, ...) and the best of each is kept, so that another process
  that loads the machine for a while slows both alike.

Every row but the threads rows runs with ``workers=1`` (one thread).

The bodies: I = diag(1, 2, 3), identity attitude, Omega0 of random direction (fixed seed) with
the length of the reference Omega0 = (1, 0.1, 0.5), so all regimes of the motion occur.

    .venv/bin/python benchmarks/bench_throughput.py [--quick] [--out DIR]
"""

from __future__ import annotations

import numpy as np

import _common as C


def bodies(n: int, seed: int = 20240601) -> np.ndarray:
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v * np.linalg.norm(C.OMEGA0)


def alternate_best(fns: dict, *, repeats: int, budget: float) -> dict:
    """Best wall time of each callable of ``fns``, timed in turn (a, b, a, b, ...) after one warm-up call each.

    Up to ``repeats`` rounds, fewer when a round would exceed ``budget`` seconds in total (at least two).
    """
    import time

    for fn in fns.values():
        fn()
    best = {k: float("inf") for k in fns}
    spent = 0.0
    for r in range(repeats):
        t_round = time.perf_counter()
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t0)
        spent += time.perf_counter() - t_round
        if r >= 1 and spent / (r + 1) * (r + 2) > budget:
            break
    return best


def run(quick: bool = False, log=print) -> dict:
    from eulerpoisson.solvers import solve
    from eulerpoisson.solvers.exact.motion import exact_motion

    cfg = {
        "exact_bodies": 20 if quick else 1000,
        "exact_times": 20 if quick else 1000,
        "taylor_bodies": 40 if quick else 10_000,
        "taylor_t_end": 10.0 if quick else 100.0,
        "symplectic_bodies": 40 if quick else 10_000,
        "symplectic_steps": 10 if quick else 100,
        "symplectic_dt": 0.01,
        "ellipj_evaluations": 10_000 if quick else 1_000_000,
        "threads_exact_bodies": 64 if quick else 1000,
        "threads_exact_times": 20 if quick else 1000,
        "threads_taylor_bodies": 64 if quick else 4000,
        "threads_taylor_t_end": 2.0 if quick else 100.0,
        "threads_symplectic_bodies": 64 if quick else 10_000,
        "threads_symplectic_steps": 10 if quick else 500,
    }
    repeats = 1 if quick else 3
    I = list(C.INERTIA)
    out = {"config": cfg, "rows": []}

    def add(name, label, value, unit, **extra):
        out["rows"].append({"name": name, "label": label, "value": value, "unit": unit, **extra})
        log(f"  {label:52s} {value:12.4g} {unit}")

    # exact ---------------------------------------------------------------------------
    B, T = cfg["exact_bodies"], cfg["exact_times"]
    w0 = bodies(B)
    t = np.linspace(0.0, 100.0, T)
    wall, tr, n = C.best_time(lambda: solve(I, t, omega0=w0, method="exact", workers=1), repeats=repeats, budget=20)
    add(
        "exact_solve",
        f"exact via solve ({B} bodies x {T} times)",
        B * T / wall,
        "evaluations/s",
        us_per_evaluation=wall / (B * T) * 1e6,
        time_s=wall,
        timed_calls=n,
    )
    M0 = w0 * np.asarray(C.INERTIA)
    wall, _, n = C.best_time(lambda: exact_motion(np.asarray(C.INERTIA), M0, t), repeats=repeats, budget=20)
    add(
        "exact_kernel",
        f"exact kernel exact_motion ({B} x {T})",
        B * T / wall,
        "evaluations/s",
        us_per_evaluation=wall / (B * T) * 1e6,
        time_s=wall,
        timed_calls=n,
    )

    # taylor --------------------------------------------------------------------------
    B, te = cfg["taylor_bodies"], cfg["taylor_t_end"]
    w0 = bodies(B)
    wall, tr, n = C.best_time(
        lambda: solve(I, [te], omega0=w0, method="taylor", tol=C.EPS, workers=1), repeats=repeats, budget=30
    )
    add(
        "taylor_batch",
        f"taylor tol=eps batch ({B} bodies to t={te:g})",
        B * te / wall,
        "body-seconds/s",
        time_s=wall,
        timed_calls=n,
        steps=tr.stats.get("steps"),
    )
    hy = C.heyoka_module()
    if hy is not None:
        rate, bs, wall, nb = C.heyoka_batch_throughput(hy, w0, te)
        add(
            "heyoka_batch",
            f"heyoka batch mode tol=eps (SIMD width {bs}, {nb} bodies)",
            rate,
            "body-seconds/s",
            time_s=wall,
            simd_width=bs,
        )
        peer = C.HeyokaPeer(hy, C.EPS)
        wall1, _, _ = C.best_time(lambda: peer.run(C.T_REF), repeats=5, budget=2)
        add("heyoka_scalar", "heyoka scalar mode tol=eps (one body)", C.T_REF / wall1, "body-seconds/s", time_s=wall1)

    # symplectic ----------------------------------------------------------------------
    B, ns, dt = cfg["symplectic_bodies"], cfg["symplectic_steps"], cfg["symplectic_dt"]
    w0 = bodies(B)
    for scheme, extra in (("splitting", {}), ("splitting4", {}), ("gauss4", {"variables": "quaternion"})):
        wall, tr, n = C.best_time(
            lambda scheme=scheme, extra=extra: solve(
                I, [ns * dt], omega0=w0, method="symplectic", scheme=scheme, dt=dt, workers=1, **extra
            ),
            repeats=repeats,
            budget=30,
        )
        steps = int(tr.stats["steps"])
        add(
            f"symplectic_{scheme}",
            f"symplectic {scheme} batch ({B} bodies x {steps} steps)",
            B * steps / wall,
            "body-steps/s",
            time_s=wall,
            timed_calls=n,
        )

    # threads: one against every core -------------------------------------------------------
    from eulerpoisson.solvers.parallel import available_cores

    cores = available_cores()
    out["cores"] = cores
    Be, Te = cfg["threads_exact_bodies"], cfg["threads_exact_times"]
    Bt, tt = cfg["threads_taylor_bodies"], cfg["threads_taylor_t_end"]
    Bs, nsteps = cfg["threads_symplectic_bodies"], cfg["threads_symplectic_steps"]
    hs = cfg["symplectic_dt"]
    we, wt, ws = bodies(Be), bodies(Bt), bodies(Bs)
    te_grid = np.linspace(0.0, 100.0, Te)
    jobs = {
        "exact": (
            lambda k: solve(I, te_grid, omega0=we, method="exact", workers=k),
            f"exact ({Be} bodies x {Te} times)",
            lambda tr: Be * Te,
            "evaluations/s",
        ),
        "taylor": (
            lambda k: solve(I, [tt], omega0=wt, method="taylor", tol=C.EPS, workers=k),
            f"taylor tol=eps ({Bt} bodies to t={tt:g})",
            lambda tr: Bt * tt,
            "body-seconds/s",
        ),
        "symplectic": (
            lambda k: solve(I, [nsteps * hs], omega0=ws, method="symplectic", dt=hs, workers=k),
            f"symplectic gauss4 ({Bs} bodies x {nsteps} steps)",
            lambda tr: Bs * int(tr.stats["steps"]),
            "body-steps/s",
        ),
    }
    for name, (fn, what, count, unit) in jobs.items():
        trial = fn(cores)
        threads, amount = trial.stats["threads"], count(trial)
        best = alternate_best(
            {1: lambda fn=fn: fn(1), cores: lambda fn=fn: fn(cores)},
            repeats=2 if quick else 15,
            budget=2.0 if quick else 30.0,
        )
        add(f"threads_{name}_1", f"{what}, 1 thread", amount / best[1], unit, time_s=best[1], workers=1)
        add(
            f"threads_{name}_all",
            f"{what}, workers={cores} (threads: {threads})",
            amount / best[cores],
            unit,
            time_s=best[cores],
            workers=cores,
            threads=threads,
        )
        add(
            f"threads_{name}_speedup",
            f"{name}: speed-up on {cores} cores (best of alternating runs)",
            best[1] / best[cores],
            "x",
            cores=cores,
            threads=threads,
        )

    # taylor on every core against heyoka's ensemble propagation on as many threads -----------
    if hy is not None:
        jobs = {"taylor": lambda: solve(I, [tt], omega0=wt, method="taylor", tol=C.EPS, workers=cores)}
        for per_thread in (False, True):
            fn, bs, nb = C.heyoka_ensemble(hy, wt, tt, cores, per_thread=per_thread)
            jobs["per_thread" if per_thread else "ensemble"] = fn
        best = alternate_best(jobs, repeats=2 if quick else 10, budget=2.0 if quick else 30.0)
        add(
            "threads_taylor_vs_heyoka_taylor",
            f"taylor tol=eps ({Bt} bodies to t={tt:g}), workers={cores}",
            Bt * tt / best["taylor"],
            "body-seconds/s",
            time_s=best["taylor"],
            workers=cores,
        )
        add(
            "heyoka_ensemble",
            f"heyoka ensemble_propagate_until_batch, {cores} threads (SIMD {bs}, {nb} bodies)",
            nb * tt / best["ensemble"],
            "body-seconds/s",
            time_s=best["ensemble"],
            workers=cores,
            simd_width=bs,
        )
        add(
            "heyoka_per_thread",
            f"heyoka batch integrator per thread, {cores} threads (hand-written, {nb} bodies)",
            nb * tt / best["per_thread"],
            "body-seconds/s",
            time_s=best["per_thread"],
            workers=cores,
            simd_width=bs,
        )

    # scipy ellipj yardstick ------------------------------------------------------------
    from scipy.special import ellipj

    N = cfg["ellipj_evaluations"]
    rng = np.random.default_rng(1)
    u = rng.uniform(0.0, 10.0, N)
    m = rng.uniform(0.0, 0.99, N)
    wall, _, n = C.best_time(lambda: ellipj(u, m), repeats=repeats, budget=10)
    add(
        "scipy_ellipj",
        f"scipy.special.ellipj ({N} evaluations)",
        wall / N * 1e9,
        "ns/evaluation",
        time_s=wall,
        timed_calls=n,
    )
    return out


if __name__ == "__main__":  # pragma: no cover
    import runpy
    import sys
    from pathlib import Path

    sys.argv = [sys.argv[0], "--only", "throughput", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
