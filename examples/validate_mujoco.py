"""
Validating MuJoCo
=================

MuJoCo's free body against the exact motion: its default integrator and RK4 on the tennis racket.

A flat racket (principal moments 0.03, 0.05, 0.08 kg m^2, no gravity) spun at
10 rad/s about its intermediate axis, with a 0.1% perturbation, for 15 s
(about five flips). MuJoCo integrates it with its default integrator (Euler,
dt = 2 ms, its default step) and with RK4 (dt = 1 ms); each run is written as
a CSV (t,qw,qx,qy,qz,wx,wy,wz) and validated by ``eulerpoisson validate``.

MuJoCo's conventions for a free joint, established numerically by
``tests/test_oracle_mujoco.py``: ``qpos[3:7]`` is the body-to-space quaternion
scalar first (w, x, y, z), ``qvel[3:6]`` the angular velocity in the body frame.

Run: ``python examples/validate_mujoco.py [OUTDIR]`` (needs ``pip install mujoco``; the documentation
shows it without running it where MuJoCo is not installed); it prints the table of the README and writes
the CSVs and ``validate_mujoco.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

INERTIA = (0.03, 0.05, 0.08)
OMEGA0 = (0.0, 10.0, 0.01)
T_END = 15.0
SAMPLES = 751
TOLERANCE = 1e-6  # rad
#: (label, MuJoCo integrator, time step)
RUNS = (("Euler (default), dt = 2 ms", "Euler", 0.002), ("RK4, dt = 1 ms", "RK4", 0.001))

MJCF = """<mujoco>
  <option gravity="0 0 0" integrator="{integrator}" timestep="{dt!r}"/>
  <worldbody>
    <body name="racket">
      <freejoint/>
      <inertial pos="0 0 0" mass="1" diaginertia="{I[0]!r} {I[1]!r} {I[2]!r}"/>
    </body>
  </worldbody>
</mujoco>"""


def simulate(integrator: str, dt: float, *, inertia=INERTIA, omega0=OMEGA0, t_end=T_END, samples=SAMPLES):
    """MuJoCo's free body: times (T,), qpos quaternions (T, 4) and qvel angular velocities (T, 3), as MuJoCo gives them."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(MJCF.format(integrator=integrator, dt=dt, I=inertia))
    data = mujoco.MjData(model)
    data.qvel[3:6] = omega0
    steps = int(round(t_end / dt))
    every = steps // (samples - 1)
    if every * (samples - 1) != steps:
        raise ValueError(f"t_end/dt = {steps} steps is not a multiple of samples - 1 = {samples - 1}")
    t, q, w = [0.0], [data.qpos[3:7].copy()], [data.qvel[3:6].copy()]
    for k in range(1, samples):
        mujoco.mj_step(model, data, nstep=every)
        t.append(k * every * dt)  # exact sample times (data.time accumulates round-off)
        q.append(data.qpos[3:7].copy())
        w.append(data.qvel[3:6].copy())
    return np.array(t), np.array(q), np.array(w)


def write_csv(path, t, q, w) -> None:
    """A run as ``t,qw,qx,qy,qz,wx,wy,wz`` with 17 significant digits."""
    np.savetxt(
        path, np.column_stack([t, q, w]), delimiter=",", header="t,qw,qx,qy,qz,wx,wy,wz", comments="", fmt="%.17g"
    )


def main(out="out/mujoco") -> list:
    import mujoco

    from eulerpoisson.oracle import plot_report, validate

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    reports = []
    for label, integ, dt in RUNS:
        path = out / f"mujoco_{integ.lower()}.csv"
        write_csv(path, *simulate(integ, dt))
        reports.append((label, validate(path, INERTIA, tolerance=TOLERANCE)))
    print(
        f"MuJoCo {mujoco.__version__}, racket I = {INERTIA}, Omega0 = {OMEGA0}, t = 0 to {T_END:g} s, "
        f"tolerance {TOLERANCE:g} rad"
    )
    print(
        "| MuJoCo integrator | max attitude error (rad) | max omega error | energy drift | momentum drift | "
        "largest flip time error (s) | verdict |"
    )
    print("|---|---|---|---|---|---|---|")
    for label, r in reports:
        fe = max(abs(e) for e in r.flip_time_errors) if r.flip_time_errors else float("nan")
        print(
            f"| {label} | {r.max_attitude_error:.2g} | {r.max_omega_error:.2g} | {r.energy_drift:.2g} | "
            f"{r.momentum_drift:.2g} | {fe:.2g} | {r.verdict} |"
        )
    plot_report(
        reports,
        out / "validate_mujoco.png",
        title=f"MuJoCo {mujoco.__version__}: a flat racket spun near its intermediate axis",
    )
    return reports


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/mujoco")
