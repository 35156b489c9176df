"""
The tennis-racket effect
========================

The tennis-racket effect in five lines, plus the closed-form flip time.

Run: ``.venv/bin/python examples/tennis_racket.py [OUTDIR]`` (writes ``tennis_racket.png``, Omega(t), into
OUTDIR, default the current folder).
"""

import sys
from pathlib import Path

import numpy as np

import eulerpoisson as ep
from eulerpoisson.analysis import flip_times, tennis_racket_half_period
from eulerpoisson.viz import plots

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")

body = ep.RigidBody([3.0, 5.0, 8.0], name="flat racket")  # I1 + I2 = I3: a flat body
M0 = np.array([0.0, 2.0, 0.01])  # spun almost exactly about the intermediate axis
tr = ep.solve(body, np.linspace(0.0, 300.0, 3001), omega0=M0 / body.principal_moments)

flips = flip_times(tr, component=1)
print("flips of Omega_2 at t =", np.round(flips, 6))
print(
    "time between flips:",
    np.diff(flips).mean(),
    " closed form 2K/lambda:",
    tennis_racket_half_period(body.principal_moments, M0),
)
print("relative drift of the integrals:", {k: f"{v:.1e}" for k, v in tr.drift().items()})
OUT.mkdir(parents=True, exist_ok=True)
plots.plot(tr, "omega", out=OUT / "tennis_racket.png")
print("wrote", OUT / "tennis_racket.png")
