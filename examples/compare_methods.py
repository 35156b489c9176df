"""
Every method against the closed form
====================================

Every solution method on the same body, against the closed form.

Run: ``.venv/bin/python examples/compare_methods.py [OUTDIR]`` (writes ``compare_methods.png``, the
error and time of each method, into OUTDIR, default the current folder).
"""

import sys
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import eulerpoisson as ep

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")

body = ep.RigidBody([1.0, 2.0, 3.0])
omega0 = [1.0, 0.1, 0.5]
t = np.array([0.0, 25.0, 50.0, 100.0])
truth = ep.solve(body, t, omega0=omega0, method="exact")

runs = {
    "exact": {},
    "taylor": {"tol": 1e-15},
    "symplectic": {"scheme": "gauss6", "dt": 0.05},
    "rk": {"integrator": "DOP853", "tol": 1e-12},
}
errors, walls = [], []
for method, opts in runs.items():
    ep.solve(body, t[:2], omega0=omega0, method=method, **opts)  # warm-up: compilation is not timed
    start = time.perf_counter()
    tr = ep.solve(body, t, omega0=omega0, method=method, **opts)
    wall = time.perf_counter() - start
    err = ep.Attitude(tr.quaternion[-1]).angle_to(ep.Attitude(truth.quaternion[-1]))
    print(
        f"{method:11s} {str(opts):40s} attitude error at t=100: {err:.1e} rad   "
        f"energy drift {tr.drift()['energy']:.1e}   {wall * 1e3:8.2f} ms"
    )
    errors.append(max(err, 1e-17))  # the closed form against itself: round-off (drawn at 1e-17 if 0)
    walls.append(wall * 1e3)

fig = Figure(figsize=(7, 3), layout="constrained")
ax1, ax2 = fig.subplots(1, 2)
ax1.bar(list(runs), errors, color=[f"C{i}" for i in range(len(runs))])
ax1.set_yscale("log")
ax1.set_ylabel("attitude error at t = 100 [rad]")
ax2.bar(list(runs), walls, color=[f"C{i}" for i in range(len(runs))])
ax2.set_ylabel("wall time [ms]")
fig.suptitle("I = (1, 2, 3), Omega0 = (1, 0.1, 0.5), outputs at t = 0, 25, 50, 100", fontsize=9)
OUT.mkdir(parents=True, exist_ok=True)
fig.savefig(OUT / "compare_methods.png", dpi=110)
print("wrote", OUT / "compare_methods.png")
