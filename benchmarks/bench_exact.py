"""Where the exact method's time goes, one thread: the Monte-Carlo case and one body at many times.

* ``exact_montecarlo``: N distinct bodies (principal moments uniform in [1, 1.9], Omega0 of
  random direction with the length of the reference Omega0, fixed seed) each at one time
  (t = 10), ``solve(RigidBody(moments (N, 3)), [t], omega0=(N, 3))`` with the attitude:
  evaluations per second (the issue's goal: >= 2e6 per core); ``exact_montecarlo_kernel`` the
  same through the kernel alone (``exact_motion``), ``exact_montecarlo_scalar`` through the
  scalar kernel (one evaluation after the other, the reference of the lane kernel);
* ``exact_many_times``: one body (the reference problem) at 10^5 times in [0, 100] through
  ``solve``: microseconds per evaluation (goal: <= 0.3); ``_kernel`` and ``_scalar`` likewise;
* ``exact_counts_montecarlo`` / ``exact_counts_many_times``: the elliptic work per body (per
  time), counted by running the kernels as plain Python in a subprocess
  (``EULERPOISSON_NO_NUMBA=1``; the same code numba compiles): Jacobi arguments (each a
  reduction modulo K and a Landen ascent), Carlson R_J and R_F integrals, AGMs for K(m), the
  closed-form R_C terms of the R_J duplications and the C library calls. benchmarks/README.md
  ("Where the exact method's time goes") compares them with the least the formulas need;
* ``call_*``: one body at one time through ``solve`` in fresh interpreters (microseconds, best of
  many calls): ``call_exact_tiny`` at t = 1e5, ``call_exact_t0`` / ``call_taylor_t0`` at t = 0
  (tol = 1e-6: the Python around the kernel) beside the kernels alone; without a suffix with numba
  active (``EULERPOISSON_NUMPY_BELOW=0``, as the benchmarks run), ``_default`` with the default
  threshold (the exact method's scalar kernel as plain Python, no numba).

    .venv/bin/python benchmarks/run.py --only exact [--quick]
    .venv/bin/python benchmarks/bench_exact.py --counts N T     # the counts alone, as JSON
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import _common as C

HERE = Path(__file__).resolve().parent
T_MC = 10.0


def bodies(n: int, seed: int = 20261124):
    """Principal moments (n, 3), uniform in [1, 1.9] (triangle inequality holds), and Omega0 (n, 3)."""
    rng = np.random.default_rng(seed)
    mom = rng.uniform(1.0, 1.9, (n, 3))
    v = rng.standard_normal((n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return mom, v * np.linalg.norm(C.OMEGA0)


def _workers():
    import inspect

    import eulerpoisson as ep

    return {"workers": 1} if "workers" in inspect.signature(ep.solve).parameters else {}


def counts(nb: int, T: int) -> dict:
    """Elliptic work per (body, time) of the kernel, counted in plain Python (call in a subprocess)."""
    import collections
    import math

    from eulerpoisson.solvers.exact import kernels as K
    from eulerpoisson.solvers.exact import lanes as LN

    assert not K.USE_NUMBA, "counts need EULERPOISSON_NO_NUMBA=1"
    c = collections.Counter()

    import sys as _sys

    def wrap(mod, name, key, weigh=None):
        """Count the calls of ``mod.name`` wherever the function is referenced (every module of the exact kernels
        that imported it: the callers look it up in their own globals)."""
        f = getattr(mod, name)

        def g(*a):
            c[key] += 1 if weigh is None else weigh(*a)
            return f(*a)

        for m in list(_sys.modules.values()):
            if getattr(m, "__name__", "").startswith("eulerpoisson.solvers.exact") and getattr(m, name, None) is f:
                setattr(m, name, g)

    L = LN.LANES
    wrap(LN, "_rj_jobs", "R_J", lambda X, Y, Z, P, R, n: n)
    wrap(K, "rj3", "R_J", lambda *a: int(bool(a[4])) + int(bool(a[9])) + int(bool(a[14])))
    wrap(
        LN,
        "_jacobi_lanes",
        "Jacobi arguments",
        lambda CL, UH, UL, ON, ng, nl, O: int(sum(ON[g * L + l] != 0.0 for g in range(ng) for l in range(nl))),
    )
    wrap(K, "sncndn3", "Jacobi arguments", lambda k, *a: k)
    wrap(K, "rf_poly", "R_F")
    wrap(K, "dd_div_f", "K(m) (AGM in double-double)")
    wrap(K, "rc1", "R_C closed forms (atan/log1p) in R_J")

    class _Math:
        def __getattr__(self, name):
            f = getattr(math, name)
            if name in ("atan2", "sin", "cos", "sinh", "cosh", "atan", "log1p", "hypot", "asinh", "tanh", "exp"):

                def g(*a):
                    c[f"libm {name}"] += 1
                    return f(*a)

                return g
            return f

    K.math = _Math()
    LN.math = _Math()
    mom, w0 = bodies(nb)
    t = np.linspace(T_MC if T == 1 else 0.0, T_MC if T == 1 else 100.0, T)
    if T > 1:
        mom, w0 = np.array([C.INERTIA]), np.array([C.OMEGA0])
    M0 = np.ascontiguousarray(w0 * mom)
    Mo = np.empty((len(mom), T, 3))
    qo = np.empty((len(mom), T, 4))
    K.motion_kernel(np.ascontiguousarray(mom), M0, t, Mo, qo)
    n = len(mom) * T
    return {k: v / n for k, v in sorted(c.items())}


def _counts_subprocess(nb: int, T: int) -> dict:
    env = dict(os.environ, EULERPOISSON_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--counts", str(nb), str(T)],
        capture_output=True,
        text=True,
        env=env,
        timeout=1800,
        cwd=str(HERE),
    )
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-2000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


_PER_CALL = """
import json, sys, time
sys.path.insert(0, {here!r})
import numpy as np
import _common as C
import eulerpoisson as ep
from eulerpoisson.solvers.exact import kernels as EK
from eulerpoisson.solvers.taylor import kernels as TK
from eulerpoisson.solvers.taylor.method import auto_order
I, W = list(C.INERTIA), list(C.OMEGA0)
n = {n}

def best(fn):
    fn()
    out = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out) * 1e6

m, w, q = np.array([I]), np.array([W]), np.array([[1.0, 0.0, 0.0, 0.0]])
t0, pos, neg = np.array([0.0]), np.array([0]), np.zeros(0, dtype=np.int64)
qo, wo, st = np.zeros((1, 1, 4)), np.zeros((1, 1, 3)), np.zeros((1, 3), dtype=np.int64)
order = auto_order(1e-6)
Mo, qk = np.empty((1, 1, 3)), np.empty((1, 1, 4))
M0 = m * w
if {compiled} == "python":
    from eulerpoisson.util.jit import python_twins

    def kernel():
        with python_twins():
            EK.motion_kernel_scalar(m, M0, t0, Mo, qk)
else:
    def kernel():
        EK.motion_kernel(m, M0, t0, Mo, qk)
rows = {{
    "tiny": best(lambda: ep.solve(I, [1e5], omega0=W, method="exact")),
    "exact_t0": best(lambda: ep.solve(I, [0.0], omega0=W, method="exact")),
    "exact_t0_kernel": best(kernel),
    "taylor_t0": best(lambda: ep.solve(I, [0.0], omega0=W, method="taylor", tol=1e-6)),
}}
if TK.USE_NUMBA:
    rows["taylor_t0_kernel"] = best(lambda: TK.nb_integrate(m, w, q, t0, pos, neg, 1e-6, order, -1.0, 10**6, 1.0, qo, wo, st))
print(json.dumps(rows))
"""


def _per_call_rows(quick: bool) -> list[tuple[str, str, float]]:
    """One body at one time through ``solve``, in fresh interpreters: with numba active (the benchmarks'
    ``EULERPOISSON_NUMPY_BELOW=0``) and with the default threshold (the exact method's plain-Python kernel)."""
    rows = []
    n = 50 if quick else 2000
    for tag, below, compiled in (("", "0", "True"), ("_default", None, '"python"')):
        env = dict(os.environ, EULERPOISSON_WORKERS="1")
        env.pop("EULERPOISSON_NUMPY_BELOW", None)
        if below is not None:
            env["EULERPOISSON_NUMPY_BELOW"] = below
        code = _PER_CALL.format(here=str(HERE), n=n, compiled=compiled)
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=3600)
        if res.returncode != 0:  # pragma: no cover - reported, not fatal
            print(res.stderr[-2000:])
            continue
        r = json.loads(res.stdout.strip().splitlines()[-1])
        how = "numba active" if below == "0" else "default threshold (no numba)"
        rows.append((f"call_exact_tiny{tag}", f"solve: one body at t = 1e5, exact, {how}", r["tiny"]))
        rows.append((f"call_exact_t0{tag}", f"solve: one body at t = 0, exact, {how}", r["exact_t0"]))
        rows.append((f"call_exact_t0_kernel{tag}", f"exact kernel alone at t = 0, {how}", r["exact_t0_kernel"]))
        rows.append((f"call_taylor_t0{tag}", f"solve: one body at t = 0, taylor tol 1e-6, {how}", r["taylor_t0"]))
        if "taylor_t0_kernel" in r:
            rows.append(
                (f"call_taylor_t0_kernel{tag}", f"taylor kernel alone at t = 0, tol 1e-6, {how}", r["taylor_t0_kernel"])
            )
    return rows


def run(quick: bool = False, log=print) -> dict:
    import eulerpoisson as ep
    from eulerpoisson.solvers.exact import kernels as K
    from eulerpoisson.solvers.exact.motion import exact_motion

    cfg = {
        "montecarlo_bodies": 2000 if quick else 100_000,
        "montecarlo_time": T_MC,
        "many_times": 2000 if quick else 100_000,
        "count_bodies": 64 if quick else 1000,
        "count_times": 64 if quick else 2000,
    }
    repeats = 1 if quick else 7
    wk = _workers()
    out = {"config": cfg, "rows": []}

    def add(name, label, value, unit, **extra):
        out["rows"].append({"name": name, "label": label, "value": value, "unit": unit, **extra})
        log(f"  {label:64s} {value:12.4g} {unit}")

    def kernel_scalar(mom, M0, t):
        Mo = np.empty((len(mom), len(t), 3))
        qo = np.empty((len(mom), len(t), 4))
        K.motion_kernel_scalar(np.ascontiguousarray(mom), np.ascontiguousarray(M0), np.ascontiguousarray(t), Mo, qo)

    # Monte-Carlo: distinct bodies, one time each ----------------------------------------------
    N = cfg["montecarlo_bodies"]
    mom, w0 = bodies(N)
    body = ep.RigidBody(mom)
    tt = np.array([T_MC])
    wall, _, n = C.best_time(lambda: ep.solve(body, tt, omega0=w0, method="exact", **wk), repeats=repeats, budget=20)
    add(
        "exact_montecarlo",
        f"exact Monte-Carlo via solve ({N} bodies x 1 time, attitude)",
        N / wall,
        "evaluations/s",
        us_per_evaluation=wall / N * 1e6,
        time_s=wall,
        timed_calls=n,
    )
    M0 = w0 * mom
    wall, _, n = C.best_time(lambda: exact_motion(mom, M0, tt), repeats=repeats, budget=20)
    add(
        "exact_montecarlo_kernel",
        f"exact Monte-Carlo, kernel alone ({N} x 1)",
        N / wall,
        "evaluations/s",
        us_per_evaluation=wall / N * 1e6,
        time_s=wall,
        timed_calls=n,
    )
    scalar = K.USE_NUMBA and hasattr(K, "motion_kernel_scalar")  # (absent before the lane kernel)
    if scalar:
        wall, _, n = C.best_time(lambda: kernel_scalar(mom, M0, tt), repeats=repeats, budget=20)
        add(
            "exact_montecarlo_scalar",
            f"exact Monte-Carlo, scalar kernel (reference of the lanes) ({N} x 1)",
            N / wall,
            "evaluations/s",
            us_per_evaluation=wall / N * 1e6,
            time_s=wall,
            timed_calls=n,
        )

    # one body at many times ---------------------------------------------------------------------
    T = cfg["many_times"]
    t = np.linspace(0.0, 100.0, T)
    wall, _, n = C.best_time(
        lambda: ep.solve(list(C.INERTIA), t, omega0=C.OMEGA0, method="exact", **wk), repeats=repeats, budget=20
    )
    add(
        "exact_many_times",
        f"exact one body at {T} times via solve, per evaluation",
        wall / T * 1e6,
        "us/evaluation",
        time_s=wall,
        timed_calls=n,
    )
    I1 = np.array([C.INERTIA])
    M1 = I1 * np.array([C.OMEGA0])
    wall, _, n = C.best_time(lambda: exact_motion(I1, M1, t), repeats=repeats, budget=20)
    add(
        "exact_many_times_kernel",
        f"exact one body at {T} times, kernel alone, per evaluation",
        wall / T * 1e6,
        "us/evaluation",
        time_s=wall,
        timed_calls=n,
    )
    if scalar:
        wall, _, n = C.best_time(lambda: kernel_scalar(I1, M1, t), repeats=repeats, budget=20)
        add(
            "exact_many_times_scalar",
            f"exact one body at {T} times, scalar kernel, per evaluation",
            wall / T * 1e6,
            "us/evaluation",
            time_s=wall,
            timed_calls=n,
        )

    # per call: one body at one time, end to end (issue 25 #1) ------------------------------------
    for name, label, value in _per_call_rows(quick):
        add(name, label, value, "us")

    # the elliptic work, counted ---------------------------------------------------------------
    for name, nb, TT, per in (
        ("montecarlo", cfg["count_bodies"], 1, "body"),
        ("many_times", 1, cfg["count_times"], "time"),
    ):
        try:
            cnt = _counts_subprocess(nb, TT)
        except Exception as exc:  # pragma: no cover - reported, not fatal
            log(f"  counts ({name}) failed: {exc}")
            continue
        add(
            f"exact_counts_{name}",
            f"exact {name}: elliptic work per {per} (counted)",
            cnt.get("R_J", 0.0),
            f"R_J per {per}",
            counts=cnt,
        )
        log("    " + ", ".join(f"{k} {v:.3g}" for k, v in cnt.items()))
    return out


if __name__ == "__main__":  # pragma: no cover
    if len(sys.argv) >= 2 and sys.argv[1] == "--counts":
        print(json.dumps(counts(int(sys.argv[2]), int(sys.argv[3]))))
        sys.exit(0)
    import runpy

    sys.argv = [sys.argv[0], "--only", "exact", *sys.argv[1:]]
    runpy.run_path(str(Path(__file__).with_name("run.py")), run_name="__main__")
