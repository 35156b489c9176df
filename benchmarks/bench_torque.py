"""Bodies under torque, one thread: what a torque costs each method, and how accurate they are.

* taylor: microseconds per step for the free body (its Gibbs-chart kernel) and for the heavy
  top (the (q, Omega) kernel with Poisson vectors), one body at tol = eps to t = 100, and the ratio;
* exact: microseconds per (body, time) evaluation of the Lagrange top (closed form), 100 bodies x
  1000 times, attitude and angular velocity included;
* symplectic: body-steps per second of the exact splitting (closed-form free flow + gravity kick);
* heavy asymmetric top to t = 10: taylor (tol = eps) and rk DOP853 (rtol 1e-13) time and attitude
  error against a 40-digit reference (tests/_torque_reference.py, mpmath).

    .venv/bin/python benchmarks/run.py --only torque [--quick]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import _common as C

I_FULL = np.array([[2.0, 0.1, 0.05], [0.1, 1.5, -0.2], [0.05, -0.2, 1.2]])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
W0 = np.array([0.7, -1.1, 2.0])
MASS, COM = 1.3, [0.1, -0.2, 0.4]


def run(quick: bool = False, log=print) -> dict:
    import eulerpoisson as ep
    from eulerpoisson.torques import Gravity

    repeats = 1 if quick else 3
    t_end = 10.0 if quick else 100.0
    out = {"config": {"taylor_t_end": t_end}, "rows": []}

    def add(name, label, value, unit, **extra):
        out["rows"].append({"name": name, "label": label, "value": value, "unit": unit, **extra})
        log(f"  {label:60s} {value:12.4g} {unit}")

    grav = Gravity(MASS, COM)
    # taylor: cost per step, free vs heavy top: the time of a run to t_end less that of a run to t = 0 (the
    # per-call checks and set-up, ~0.5 ms, would otherwise be a third of the time at t_end = 100), divided by
    # the steps; the four runs alternate and the best of each is kept
    t_end_steps = 100.0 if quick else 1000.0

    def taylor(t1, inertia=I_FULL, **kw):
        return lambda: ep.solve(inertia, [t1], omega0=W0, attitude0=Q0, method="taylor", tol=C.EPS, **kw)

    # the same body given by its principal moments (a diagonal tensor: the heavy top's principal-frame kernel;
    # a full tensor keeps the body frame, see solvers/taylor/torque.py)
    moments = np.linalg.eigvalsh(I_FULL)
    runs = {
        "free": taylor(t_end_steps),
        "free0": taylor(0.0),
        "gravity": taylor(t_end_steps, torque=grav),
        "gravity0": taylor(0.0, torque=grav),
        "free_p": taylor(t_end_steps, moments),
        "free0_p": taylor(0.0, moments),
        "gravity_p": taylor(t_end_steps, moments, torque=grav),
        "gravity0_p": taylor(0.0, moments, torque=grav),
    }
    from bench_throughput import alternate_best

    best = alternate_best(runs, repeats=3 if quick else 15, budget=3.0 if quick else 30.0)
    tr_f, tr_g = runs["free"](), runs["gravity"]()
    us_f = (best["free"] - best["free0"]) / tr_f.stats["steps"] * 1e6
    us_g = (best["gravity"] - best["gravity0"]) / tr_g.stats["steps"] * 1e6
    add(
        "taylor_free_step",
        f"taylor free body, tol=eps, per step (order {tr_f.stats['max_order']}, t = {t_end_steps:g})",
        us_f,
        "us/step",
        steps=tr_f.stats["steps"],
        time_s=best["free"],
        call_overhead_s=best["free0"],
    )
    add(
        "taylor_gravity_step",
        f"taylor heavy top, tol=eps, per step (order {tr_g.stats['max_order']}, t = {t_end_steps:g})",
        us_g,
        "us/step",
        steps=tr_g.stats["steps"],
        time_s=best["gravity"],
        call_overhead_s=best["gravity0"],
    )
    add("taylor_gravity_ratio", "taylor: heavy-top step / free-body step", us_g / us_f, "x")
    trp_f, trp_g = runs["free_p"](), runs["gravity_p"]()
    usp_f = (best["free_p"] - best["free0_p"]) / trp_f.stats["steps"] * 1e6
    usp_g = (best["gravity_p"] - best["gravity0_p"]) / trp_g.stats["steps"] * 1e6
    add(
        "taylor_free_step_principal",
        "taylor free body given by its principal moments, per step",
        usp_f,
        "us/step",
        steps=trp_f.stats["steps"],
    )
    add(
        "taylor_gravity_step_principal",
        "taylor heavy top given by its principal moments, per step",
        usp_g,
        "us/step",
        steps=trp_g.stats["steps"],
    )
    add(
        "taylor_gravity_ratio_principal",
        "taylor: heavy-top step / free-body step, principal moments",
        usp_g / usp_f,
        "x",
    )

    # exact Lagrange top
    B, T = (10, 100) if quick else (100, 1000)
    rng = np.random.default_rng(7)
    spins = rng.uniform(5.0, 30.0, B)
    w0 = np.stack([rng.normal(0, 1, B), rng.normal(0, 1, B), spins], -1)
    top = Gravity(1.0, [0.0, 0.0, 0.1])
    t = np.linspace(0.0, 100.0, T)
    wall, _, _ = C.best_time(
        lambda: ep.solve([1.0, 1.0, 0.5], t, omega0=w0, attitude0=Q0, torque=top, method="exact"),
        repeats=repeats,
        budget=20,
    )
    add(
        "exact_lagrange",
        f"exact Lagrange top ({B} bodies x {T} times), per evaluation",
        wall / (B * T) * 1e6,
        "us/evaluation",
        time_s=wall,
    )

    # symplectic exact splitting
    nsteps = 10_000 if quick else 200_000
    dt = 0.01
    wall, tr, _ = C.best_time(
        lambda: ep.solve(
            I_FULL,
            [nsteps * dt],
            omega0=W0,
            attitude0=Q0,
            torque=grav,
            method="symplectic",
            scheme="exact_splitting",
            dt=dt,
        ),
        repeats=repeats,
        budget=20,
    )
    add(
        "symplectic_exact_splitting",
        f"symplectic exact_splitting, heavy top ({tr.stats['steps']} steps)",
        tr.stats["steps"] / wall,
        "body-steps/s",
        time_s=wall,
    )

    # accuracy against the 40-digit reference at t = 10
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from _torque_reference import reference_motion

    qr, _ = reference_motion(I_FULL, Q0, W0, [10.0], gravity=[(MASS, COM, [0.0, 0.0, -9.81])])
    for name, opts in (("taylor", {"tol": C.EPS}), ("rk", {"integrator": "DOP853", "tol": 1e-13})):
        wall, tr, _ = C.best_time(
            lambda name=name, opts=opts: ep.solve(
                I_FULL, [10.0], omega0=W0, attitude0=Q0, torque=grav, method=name, **opts
            ),
            repeats=repeats,
            budget=10,
            warmup=not quick,  # (quick: one call; the kernels were compiled by the runs above)
        )
        err = C.attitude_error(tr.quaternion[-1], qr[0])
        add(
            f"heavy_top_{name}",
            f"heavy asymmetric top to t = 10: {name} ({opts})",
            wall * 1e3,
            "ms",
            attitude_error_rad=err,
            time_s=wall,
        )
    return out


if __name__ == "__main__":  # pragma: no cover
    import runpy

    sys.argv = [sys.argv[0], "--only", "torque", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
