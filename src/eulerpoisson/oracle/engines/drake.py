"""Drake (``pip install drake``): a free body of a ``MultibodyPlant``, continuous (the Simulator's integrators at a
fixed step) or discrete (the plant's own time step).

Conventions: the plant's state is ``(qw, qx, qy, qz, x, y, z)`` for the positions (body to world,
scalar first) and ``(wx, wy, wz, vx, vy, vz)`` for the velocities, the angular velocity in the world
(space) frame. A full inertia tensor is given as it is (``UnitInertia`` with products). The continuous
integrators run in fixed-step mode with the step ``dt``; they do not renormalize the quaternion.
"""

from __future__ import annotations

import time

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load, quaternion_to_matrix

__all__ = ["DrakeEngine"]


class DrakeEngine(Engine):
    """Drake's continuous plant with ``runge_kutta2``, ``runge_kutta3``, ``semi_explicit_euler``; or a discrete plant."""

    name = "drake"
    title = "Drake"
    package = "drake"
    module = "pydrake.all"
    settings = {
        "runge_kutta2": "continuous plant, explicit 2nd-order Runge-Kutta (fixed step)",
        "runge_kutta3": "continuous plant, 3rd-order Runge-Kutta, its default integrator (here at a fixed step)",
        "semi_explicit_euler": "continuous plant, semi-explicit (symplectic) Euler",
        "discrete": "a discrete plant (MultibodyPlant(time_step=dt)), its default discrete solver",
    }
    conventions = Conventions("wxyz", "space", "body-to-space")
    max_steps = 100_000

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        pd = load("pydrake.all")

        I = case.inertia_array
        if I.ndim == 1:
            unit = pd.UnitInertia(*(float(x) for x in I))
        else:
            unit = pd.UnitInertia(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
        plant = pd.MultibodyPlant(plan.dt if setting == "discrete" else 0.0)
        plant.AddRigidBody("body", pd.SpatialInertia(1.0, np.zeros(3), unit))
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
        plant.Finalize()
        context = plant.CreateDefaultContext()
        q0 = np.asarray(case.quaternion0, float)
        positions = np.concatenate([q0, np.zeros(3)])
        velocities = np.concatenate([quaternion_to_matrix(q0) @ np.asarray(case.omega0, float), np.zeros(3)])
        plant.SetPositions(context, positions)
        plant.SetVelocities(context, velocities)
        simulator = pd.Simulator(plant, context)
        if setting != "discrete":
            integrator = pd.ResetIntegratorFromFlags(simulator, setting, plan.dt)
            integrator.set_fixed_step_mode(True)
        simulator.Initialize()
        q = np.full((plan.samples, 4), np.nan)
        w = np.full((plan.samples, 3), np.nan)
        q[0], w[0] = positions[:4], velocities[:3]
        times = plan.times
        wall = 0.0
        for k in range(1, plan.samples):
            t0 = time.perf_counter()
            simulator.AdvanceTo(float(times[k]))
            wall += time.perf_counter() - t0
            q[k] = plant.GetPositions(context)[:4]
            w[k] = plant.GetVelocities(context)[:3]
            if not (np.all(np.isfinite(q[k])) and np.all(np.isfinite(w[k]))):
                break
        return EngineRun(times, q, w, self.conventions, I, plan.steps, wall)
