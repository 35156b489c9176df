"""Long runs of the symplectic and Runge-Kutta integrators: energy and momentum errors, cost.

For each configuration, the free asymmetric body I = (1, 2, 3), Omega0 = (1, 0.3, 0.6)
(|Omega0| = 1.2, period of the body motion ~ 9) is integrated over ``--steps`` steps of
0.2 rad (dt = 0.2/|Omega0|), and the script prints the relative energy error in ten
windows (max |E - E0|/E0 per window: a drift shows as growth), the largest relative
drift of m, the wall time, and the cost per step. A batch of ``--batch`` identical
bodies measures the batched cost per body-step.

The splittings and the quaternion Gauss schemes run in the compiled kernels when numba is
installed ("compiled" in the output); ``EULERPOISSON_NO_NUMBA=1`` times the NumPy path (same
results bit for bit).

    .venv/bin/python benchmarks/bench_symplectic_long.py              # 1e5 steps, all schemes
    .venv/bin/python benchmarks/bench_symplectic_long.py --steps 20000 --schemes gauss4
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from eulerpoisson.solvers import solve

CONFIGS = {
    "splitting": {"method": "symplectic", "scheme": "splitting"},
    "splitting4": {"method": "symplectic", "scheme": "splitting4"},
    "gauss2": {"method": "symplectic", "scheme": "gauss2"},
    "gauss4": {"method": "symplectic", "scheme": "gauss4"},
    "gauss6": {"method": "symplectic", "scheme": "gauss6"},
    "gauss2-quaternion": {"method": "symplectic", "scheme": "gauss2", "variables": "quaternion"},
    "gauss4-quaternion": {"method": "symplectic", "scheme": "gauss4", "variables": "quaternion"},
    "gauss6-quaternion": {"method": "symplectic", "scheme": "gauss6", "variables": "quaternion"},
    "rk-DOP853-1e-10": {"method": "rk", "tol": 1e-10},
}


def run(name, steps, batch):
    opts = dict(CONFIGS[name])
    method = opts.pop("method")
    I = np.array([1.0, 2.0, 3.0])
    w0 = np.array([1.0, 0.3, 0.6])
    dt = 0.2 / np.linalg.norm(w0)
    if method == "symplectic":
        opts["dt"] = dt
    t = np.linspace(0.0, steps * dt, min(1001, steps + 1))
    w0b = np.broadcast_to(w0, (batch, 3)) if batch > 1 else w0
    solve(I, [t[1]], omega0=w0b, method=method, **opts)  # warm-up: numba compilation or cache load
    t0 = time.perf_counter()
    tr = solve(I, t, omega0=w0b, method=method, **opts)
    wall = time.perf_counter() - t0
    E = tr.energy if batch == 1 else tr.energy[0]
    err = np.abs(E - E[0]) / E[0]
    windows = [w.max() for w in np.array_split(err[1:], 10)]
    d = tr.drift()
    m = max(np.max(d["m_x"]), np.max(d["m_y"]), np.max(d["m_z"]))
    nst = tr.stats.get("steps", steps)
    per = wall / max(nst, 1) * 1e6
    kind = "compiled" if tr.stats.get("compiled") else "numpy"
    print(
        f"{name:20s} steps={nst:7d} batch={batch:5d} wall={wall:8.2f}s  {per:8.1f} us/step "
        f"({per / batch:7.3f} us/body-step, {kind})  max|dm|/|m|={m:.2e}  "
        f"chart changes={tr.stats.get('chart_changes', 0)}"
    )
    print("    energy error per window:", " ".join(f"{w:.1e}" for w in windows))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--batch", type=int, default=1)
    ap.add_argument("--schemes", nargs="*", default=list(CONFIGS), choices=list(CONFIGS))
    a = ap.parse_args()
    for name in a.schemes:
        run(name, a.steps, a.batch)


if __name__ == "__main__":
    main()
