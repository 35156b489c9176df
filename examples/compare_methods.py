"""Every solution method on the same body, against the closed form.

Run: .venv/bin/python examples/compare_methods.py
"""

import time

import numpy as np

import eulerpoisson as ep

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
for method, opts in runs.items():
    start = time.perf_counter()
    tr = ep.solve(body, t, omega0=omega0, method=method, **opts)
    wall = time.perf_counter() - start
    err = ep.Attitude(tr.quaternion[-1]).angle_to(ep.Attitude(truth.quaternion[-1]))
    print(f"{method:11s} {str(opts):40s} attitude error at t=100: {err:.1e} rad   "
          f"energy drift {tr.drift()['energy']:.1e}   {wall * 1e3:8.2f} ms")
