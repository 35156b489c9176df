"""
A fast heavy top
================

A fast heavy top (a Lagrange top): precession, nutation, and the locus of its axis.

Run: ``.venv/bin/python examples/heavy_top.py [OUTDIR]`` (writes ``heavy_top_apex.png`` into OUTDIR,
default the current folder). The same run from the command line:
``eulerpoisson simulate examples/heavy_top.toml``.
"""

import sys
from pathlib import Path

import numpy as np

import eulerpoisson as ep
from eulerpoisson.viz import plots

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
body = ep.RigidBody([1.0, 1.0, 0.5], name="heavy top")  # moments about the fixed point
top = ep.torques.Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.25])  # g = (0, 0, -9.81) by default
q0 = [np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0, 0.0]  # tilted 60 degrees about x
t = np.linspace(0.0, 15.0, 3001)
tr = ep.solve(body, t, omega0=[0.0, 0.0, 10.0], attitude0=q0, torque=top, method="taylor", tol=1e-15)

axis = tr.matrix[:, :, 2]  # R(t) e3: the symmetry axis, through the centre of mass
theta = np.degrees(np.arccos(axis[:, 2]))
print(f"nutation between {theta.min():.2f} and {theta.max():.2f} degrees from the vertical")
print("relative drift of the integrals:", {k: f"{v:.1e}" for k, v in tr.drift().items()})
try:  # the closed form of the Lagrange top, where this version has it
    ex = ep.solve(body, t, omega0=[0.0, 0.0, 10.0], attitude0=q0, torque=top, method="exact")
    print("max |omega_exact - omega_taylor|:", np.max(np.abs(ex.omega - tr.omega)))
except ep.UnsupportedModelError as exc:
    print("closed form not available:", str(exc).split(";")[0])
OUT.mkdir(parents=True, exist_ok=True)
plots.plot(tr, "apex", out=OUT / "heavy_top_apex.png")
print("wrote", OUT / "heavy_top_apex.png")
