"""MuJoCo (``pip install mujoco``): a body on a free joint, its four integrators.

Conventions (established numerically by ``tests/test_oracle_mujoco.py``): ``qpos[3:7]`` is the
body-to-space quaternion scalar first, ``qvel[3:6]`` the angular velocity in the body frame. A full
inertia tensor is given as ``fullinertia`` (MuJoCo finds the principal frame itself; ``qpos`` stays the
body frame's).
"""

from __future__ import annotations

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load, sampled_loop

__all__ = ["MuJoCoEngine", "mjcf"]

_MJCF = """<mujoco>
  <option gravity="0 0 0" integrator="{integrator}" timestep="{dt!r}"/>
  <worldbody>
    <body name="body">
      <freejoint/>
      <inertial pos="0 0 0" mass="1" {inertia}/>
    </body>
  </worldbody>
</mujoco>"""


def mjcf(inertia, integrator: str, dt: float) -> str:
    """The MJCF model of one free body with ``inertia`` (3 moments or a 3x3 tensor), no gravity, no geometry.

    Examples
    --------
    >>> from eulerpoisson.oracle.engines.mujoco import mjcf
    >>> 'fullinertia="2.0 1.5 1.2 0.1 0.0 -0.2"' in mjcf([[2, .1, 0], [.1, 1.5, -.2], [0, -.2, 1.2]], "RK4", 1e-3)
    True
    """
    I = np.asarray(inertia, dtype=float)
    if I.shape == (3,):
        attr = 'diaginertia="' + " ".join(repr(float(v)) for v in I) + '"'
    else:
        vals = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
        attr = 'fullinertia="' + " ".join(repr(float(v)) for v in vals) + '"'
    return _MJCF.format(integrator=integrator, dt=float(dt), inertia=attr)


class MuJoCoEngine(Engine):
    """MuJoCo's free joint stepped by ``mj_step`` with its ``Euler``, ``implicit``, ``implicitfast`` or ``RK4``."""

    name = "mujoco"
    title = "MuJoCo"
    package = "mujoco"
    module = "mujoco"
    settings = {
        "Euler": "the default: semi-implicit Euler (velocities first, then positions)",
        "implicitfast": "implicit in the velocity-dependent forces, without the Coriolis/gyroscopic derivatives",
        "implicit": "implicit in the velocity-dependent forces, with the Coriolis/gyroscopic derivatives",
        "RK4": "the classical 4th-order Runge-Kutta",
    }
    conventions = Conventions("wxyz", "body", "body-to-space")
    max_steps = 200_000

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        mujoco = load("mujoco")

        warnings: list[str] = []
        previous = mujoco.get_mju_user_warning()
        # MuJoCo's warnings (an unstable simulation) are kept in the run's notes, not printed nor logged to a file
        mujoco.set_mju_user_warning(lambda text: warnings.append(str(text).strip()))
        try:
            model = mujoco.MjModel.from_xml_string(mjcf(case.inertia, setting, plan.dt))
            data = mujoco.MjData(model)
            data.qpos[3:7] = case.quaternion0
            data.qvel[3:6] = case.omega0
            mujoco.mj_forward(model, data)

            def step(n: int) -> None:
                mujoco.mj_step(model, data, nstep=n)

            def read():
                return data.qpos[3:7].copy(), data.qvel[3:6].copy()

            q, w, wall = sampled_loop(plan, step, read)
        finally:
            mujoco.set_mju_user_warning(previous)
        notes = tuple(f"MuJoCo: {text}" for text in dict.fromkeys(warnings))[:3]
        return EngineRun(plan.times, q, w, self.conventions, case.inertia_array, plan.steps, wall, notes)
