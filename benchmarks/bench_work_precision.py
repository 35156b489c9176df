"""Work-precision: attitude error at t = T_REF against wall time, for every method and peer.

The reference problem of the issue: one body, I = diag(1, 2, 3), Omega0 = (1, 0.1, 0.5), identity
attitude, to t = 100. Each method/peer is run over a sweep of its accuracy knob; each point is
the best wall time of several calls (after a warm-up call: numba, caches) and the attitude error,
the angle of the rotation between the computed attitude and a high-precision reference.

The reference is heyoka's Taylor integrator in 113-bit arithmetic when heyoka is installed
(independent code, error ~1e-30), else eulerpoisson's Taylor integrator in 80-bit long double
(~4e-18 at t = 100, checked against the former). The difference between the two, and the exact
method's error, are recorded.

Timed calls: eulerpoisson through the public ``solve`` (validation and the Trajectory included);
scipy's ``solve_ivp`` written out directly (the user's baseline); heyoka's ``propagate_until`` after
a state reset (the LLVM compilation, ~0.3 s, not timed, as numba's is not); MuJoCo's
``mj_step(nstep=n)`` after ``mj_resetData`` (model compilation not timed).

    .venv/bin/python benchmarks/bench_work_precision.py [--quick] [--out DIR]
"""

from __future__ import annotations

import numpy as np

import _common as C

#: error floor used in the diagram (errors below are drawn on it)
ERROR_FLOOR = 1e-17


def _sweeps(quick: bool):
    if quick:
        return {
            "taylor": [1e-8, C.EPS],
            "splitting": [0.2],
            "splitting4": [0.2],
            "gauss4": [0.5],
            "gauss6": [0.5],
            "rk-DOP853": [1e-8],
            "rk-RK45": [1e-6],
            "scipy-DOP853": [1e-8, 1e-13],
            "scipy-RK45": [1e-6],
            "heyoka": [C.EPS],
            "mujoco-RK4": [1e-2],
        }
    return {
        "taylor": [1e-6, 1e-8, 1e-10, 1e-12, 1e-14, C.EPS],
        "splitting": [0.1, 0.05, 0.02, 0.01],
        "splitting4": [0.2, 0.1, 0.05, 0.02],
        "gauss4": [0.2, 0.1, 0.05],
        "gauss6": [0.4, 0.2, 0.1],
        "rk-DOP853": [1e-6, 1e-8, 1e-10, 1e-12, 1e-13],
        "rk-RK45": [1e-5, 1e-7, 1e-9],
        "scipy-DOP853": [1e-6, 1e-8, 1e-10, 1e-12, 1e-13],
        "scipy-RK45": [1e-5, 1e-7, 1e-9],
        "heyoka": [1e-6, 1e-8, 1e-10, 1e-12, 1e-14, C.EPS],
        "mujoco-RK4": [1e-2, 3e-3, 1e-3],
    }


def reference(t_end: float, hy) -> dict:
    """High-precision reference attitude at ``t_end`` and the cross-checks between references."""
    out = {"t": t_end}
    ld_ref = C.taylor_longdouble_reference(t_end)
    hy_ref = C.heyoka_reference(hy, t_end, kind="real") if hy is not None else None
    if hy_ref is not None:
        out["source"] = hy_ref[2]
        out["q"], out["omega"] = hy_ref[0], hy_ref[1]
        out["crosscheck"] = {
            "what": ld_ref[2],
            "attitude_difference_rad": C.attitude_error(ld_ref[0], hy_ref[0]),
        }
    else:
        out["source"] = ld_ref[2]
        out["q"], out["omega"] = ld_ref[0], ld_ref[1]
        out["crosscheck"] = None
    return out


def _ep_runner(method: str, **opts):
    from eulerpoisson.solvers import solve

    def run(t_end):
        tr = solve(list(C.INERTIA), [t_end], omega0=list(C.OMEGA0), method=method, **opts)
        return tr.quaternion[0], tr.omega[0], tr.stats

    return run


def _scipy_runner(method, tol):
    def run(t_end):
        q, om, nfev = C.scipy_solve(t_end, method, tol, tol)
        return q, om, {"nfev": nfev}

    return run


def _point(run, t_end, ref, knob, *, repeats, budget):
    wall, (q, om, *extra), n = C.best_time(lambda: run(t_end), repeats=repeats, budget=budget)
    p = {
        "knob": knob,
        "time_s": wall,
        "error_rad": C.attitude_error(q, ref["q"]),
        "energy_rel_error": C.relative_energy_error(om),
        "timed_calls": n,
    }
    if extra and isinstance(extra[0], dict):
        st = {k: v for k, v in extra[0].items() if k in ("steps", "nfev", "max_order", "iterations", "chart_changes")}
        if st:
            p["stats"] = st
    return p


def run(quick: bool = False, log=print) -> dict:
    """Run the work-precision benchmark; returns the JSON payload body (curves, reference, notes)."""
    t_end = 10.0 if quick else C.T_REF
    repeats = 1 if quick else 25
    budget = 0.5 if quick else 1.5
    sw = _sweeps(quick)
    hy = C.heyoka_module()
    mj = C.mujoco_module()
    ref = reference(t_end, hy)
    log(f"  reference: {ref['source']}")
    curves = []
    notes = []

    def curve(name, label, family, knob_name, knobs, make_run, peer=False):
        pts = []
        for k in knobs:
            runner = make_run(k)
            p = _point(runner, t_end, ref, k, repeats=repeats, budget=budget)
            pts.append(p)
            ks = "-" if k is None else f"{k:.3g}"
            log(f"  {label:44s} {knob_name}={ks:<9s} time={p['time_s'] * 1e3:10.3f} ms  error={p['error_rad']:.2e} rad")
        curves.append({"name": name, "label": label, "family": family, "peer": peer, "knob": knob_name, "points": pts})

    # --- eulerpoisson -----------------------------------------------------------------
    curve("exact", "eulerpoisson exact", "exact", "none", [None], lambda _: _ep_runner("exact"))
    curve("taylor", "eulerpoisson taylor", "taylor", "tol", sw["taylor"], lambda k: _ep_runner("taylor", tol=k))
    curve(
        "symplectic-splitting",
        "eulerpoisson symplectic splitting",
        "symplectic",
        "dt",
        sw["splitting"],
        lambda k: _ep_runner("symplectic", scheme="splitting", dt=k),
    )
    curve(
        "symplectic-splitting4",
        "eulerpoisson symplectic splitting4",
        "symplectic",
        "dt",
        sw["splitting4"],
        lambda k: _ep_runner("symplectic", scheme="splitting4", dt=k),
    )
    curve(
        "symplectic-gauss4",
        "eulerpoisson symplectic gauss4 (quaternion)",
        "symplectic",
        "dt",
        sw["gauss4"],
        lambda k: _ep_runner("symplectic", scheme="gauss4", variables="quaternion", dt=k),
    )
    curve(
        "symplectic-gauss6",
        "eulerpoisson symplectic gauss6 (quaternion)",
        "symplectic",
        "dt",
        sw["gauss6"],
        lambda k: _ep_runner("symplectic", scheme="gauss6", variables="quaternion", dt=k),
    )
    curve(
        "rk-DOP853",
        "eulerpoisson rk DOP853",
        "rk",
        "tol",
        sw["rk-DOP853"],
        lambda k: _ep_runner("rk", integrator="DOP853", tol=k),
    )
    curve(
        "rk-RK45",
        "eulerpoisson rk RK45",
        "rk",
        "tol",
        sw["rk-RK45"],
        lambda k: _ep_runner("rk", integrator="RK45", tol=k),
    )

    # --- peers --------------------------------------------------------------------------
    curve(
        "scipy-DOP853",
        "scipy solve_ivp DOP853 (rtol=atol)",
        "peer",
        "rtol",
        sw["scipy-DOP853"],
        lambda k: _scipy_runner("DOP853", k),
        peer=True,
    )
    curve(
        "scipy-RK45",
        "scipy solve_ivp RK45 (rtol=atol)",
        "peer",
        "rtol",
        sw["scipy-RK45"],
        lambda k: _scipy_runner("RK45", k),
        peer=True,
    )
    if hy is not None:

        def make_hy(k):
            peer = C.HeyokaPeer(hy, k)
            return peer.run

        curve("heyoka", f"heyoka {hy.__version__} taylor_adaptive", "peer", "tol", sw["heyoka"], make_hy, peer=True)
    else:
        notes.append("heyoka is not installed (or --peers scipy): no heyoka curve (pip install heyoka)")
    if mj is not None:

        def make_mj(k):
            peer = C.MujocoPeer(mj, k)

            def run_mj(t):
                q, om, n = peer.run(t)
                return q, om, {"steps": n}

            return run_mj

        curve(
            "mujoco-RK4", f"MuJoCo {mj.__version__} RK4 (fixed dt)", "peer", "dt", sw["mujoco-RK4"], make_mj, peer=True
        )
    else:
        notes.append("MuJoCo is not installed (or --peers scipy): no MuJoCo curve (pip install mujoco)")
    notes.append("Basilisk is not measured (not installed); the issue quotes RK4 dt=1e-3: 2e-13 rad, 860 ms.")
    bodies = random_bodies_accuracy(hy, 4 if quick else 40, t_end) if hy is not None else None
    if bodies:
        log(
            f"  {bodies['bodies']} random bodies to t = {t_end:g}, tol = eps: median attitude error taylor "
            f"{bodies['taylor_median_rad']:.2e} rad ({bodies['taylor_steps']} steps), heyoka "
            f"{bodies['heyoka_median_rad']:.2e} rad ({bodies['heyoka_steps']} steps)"
        )
    return {
        "problem": {"inertia": C.INERTIA, "omega0": C.OMEGA0, "q0": C.Q0, "t_end": t_end},
        "error_measure": "rotation angle (rad) between the computed attitude and the reference at t_end",
        "reference": {"source": ref["source"], "q": [str(v) for v in ref["q"]], "crosscheck": ref["crosscheck"]},
        "timing": (
            "best of up to 25 calls (fewer for slow ones: about 1.5 s per point) after one warm-up "
            "call (time.perf_counter); compilation (numba, heyoka LLVM, MuJoCo model) not timed"
        ),
        "curves": curves,
        "random_bodies": bodies,
        "notes": notes,
    }


# ---------------------------------------------------------------------------
# diagram
# ---------------------------------------------------------------------------
_STYLE = {
    "exact": dict(color="k", marker="*", ms=16),
    "taylor": dict(color="tab:blue", marker="o"),
    "symplectic-splitting": dict(color="tab:green", marker="v"),
    "symplectic-splitting4": dict(color="tab:green", marker="^", ls="--"),
    "symplectic-gauss4": dict(color="tab:olive", marker="s"),
    "symplectic-gauss6": dict(color="tab:olive", marker="D", ls="--"),
    "rk-DOP853": dict(color="tab:purple", marker="p"),
    "rk-RK45": dict(color="tab:purple", marker="h", ls="--"),
    "scipy-DOP853": dict(color="tab:red", marker="P", ls=":"),
    "scipy-RK45": dict(color="tab:red", marker="X", ls="-."),
    "heyoka": dict(color="tab:orange", marker="o", ls=":"),
    "mujoco-RK4": dict(color="tab:brown", marker="d", ls=":"),
}


def plot(payload: dict, path) -> None:
    """Log-log error against wall time, one labelled curve per method and peer."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(13, 7.5))
    fig.subplots_adjust(left=0.07, right=0.70, bottom=0.09, top=0.88)
    for c in payload["curves"]:
        x = [p["time_s"] for p in c["points"]]
        y = [max(p["error_rad"], ERROR_FLOOR) for p in c["points"]]
        st = dict(_STYLE.get(c["name"], {}))
        st.setdefault("ls", "-")
        ax.plot(x, y, label=c["label"], lw=1.5, **st)
        if c["knob"] in ("tol", "rtol", "dt"):
            for p, xi, yi in zip(c["points"], x, y):
                if p is c["points"][0] or p is c["points"][-1]:
                    ax.annotate(
                        f"{p['knob']:.0e}" if p["knob"] < 1e-3 else f"{p['knob']:g}",
                        (xi, yi),
                        textcoords="offset points",
                        xytext=(4, 3),
                        fontsize=7,
                        color=st.get("color"),
                    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per solve (s), best of repeats, one thread")
    ax.set_ylabel(f"attitude error at t = {payload['problem']['t_end']:g} (rad)")
    ax.axhline(ERROR_FLOOR, color="0.8", lw=0.8)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.1)
    ax.legend(fontsize=8.5, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, framealpha=0.9)
    m = payload["machine"]
    quick = " [QUICK RUN - not representative]" if payload.get("quick") else ""
    fig.suptitle(
        f"Work-precision, I = diag(1, 2, 3), $\\Omega_0$ = (1, 0.1, 0.5), t = {payload['problem']['t_end']:g}{quick}\n"
        f"{C.machine_line(m)}\n"
        f"reference: {payload['reference']['source']}; labels: tol / rtol / dt at the ends of each curve",
        fontsize=9.5,
        x=0.40,
    )
    fig.text(0.01, 0.005, f"{payload['generated']}  command: {payload['command']}", fontsize=7, color="0.4")
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":  # pragma: no cover
    import runpy
    import sys

    sys.argv = [sys.argv[0], "--only", "work_precision", *sys.argv[1:]]
    runpy.run_path(str(__import__("pathlib").Path(__file__).with_name("run.py")), run_name="__main__")


def random_bodies_accuracy(hy, n: int, t_end: float, seed: int = 5) -> dict:
    """Attitude errors of taylor and heyoka at tol = eps over ``n`` random bodies (one sample says little).

    Moments uniform in [1, 3] (triangle inequality kept), |Omega0| in [0.5, 1.5] in a random direction, the
    identity at t = 0; the reference: heyoka in 80-bit long double (tol 1.1e-19, compiled once, the moments as
    runtime parameters); heyoka double precision with the same system. Returns the medians, means, maxima and
    the total steps of each.
    """
    from eulerpoisson.solvers import solve

    ld = np.longdouble
    sysm = C.heyoka_system(hy, runtime_inertia=True)
    ic = np.array([*C.Q0, *C.OMEGA0])
    ta_ld = hy.taylor_adaptive(sysm, ic.astype(ld), fp_type=ld, pars=np.array(C.INERTIA, dtype=ld))
    ta_d = hy.taylor_adaptive(sysm, ic, tol=C.EPS, pars=np.array(C.INERTIA))
    rng = np.random.default_rng(seed)
    errs: dict[str, list] = {"taylor": [], "heyoka": []}
    steps = {"taylor": 0, "heyoka": 0}
    for _ in range(n):
        moments = np.sort(rng.uniform(1.0, 3.0, 3))
        moments[2] = min(moments[2], moments[0] + moments[1] - 1e-3)
        w = rng.normal(size=3)
        w *= rng.uniform(0.5, 1.5) / np.linalg.norm(w)
        for ta, dt in ((ta_ld, ld), (ta_d, float)):
            ta.state[:] = np.r_[1.0, 0.0, 0.0, 0.0, w].astype(dt)
            ta.time = dt(0.0)
            ta.pars[:] = np.asarray(moments, dtype=dt)
            out = ta.propagate_until(dt(t_end))
        steps["heyoka"] += int(out[3])
        ref = np.array(ta_ld.state[:4], dtype=ld)
        ref /= np.sqrt(np.sum(ref * ref))
        errs["heyoka"].append(C.attitude_error(np.array(ta_d.state[:4]) / np.linalg.norm(ta_d.state[:4]), ref))
        tr = solve(list(moments), [t_end], omega0=list(w), method="taylor", tol=C.EPS)
        steps["taylor"] += int(tr.stats["steps"])
        errs["taylor"].append(C.attitude_error(tr.quaternion[0], ref))
    out = {"bodies": n, "t_end": t_end, "seed": seed}
    for k, e in errs.items():
        a = np.array(e)
        out.update(
            {f"{k}_median_rad": float(np.median(a)), f"{k}_mean_rad": float(a.mean()), f"{k}_max_rad": float(a.max())}
        )
        out[f"{k}_steps"] = steps[k]
    return out
