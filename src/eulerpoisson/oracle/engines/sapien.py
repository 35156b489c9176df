"""SAPIEN 3 (``pip install sapien``): a PhysX 5 rigid dynamic actor on PhysX's CPU system (no renderer).

Conventions: the actor's pose ``q`` is scalar first (w, x, y, z), body (actor frame) to world; the
component's ``angular_velocity`` is in the world (space) frame. PhysX takes principal moments with the
pose of the principal frame (``cmass_local_pose``): a full tensor is given that way, the pose read is the
actor's. PhysX computes in float32. The damping PhysX applies by default is set to zero; its limit on
the angular velocity (``max_angular_velocity``, 100 rad/s by default) is left as it is.
"""

from __future__ import annotations

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import (
    Engine,
    EngineRun,
    SamplePlan,
    load,
    matrix_to_quaternion,
    principal_frame,
    quaternion_to_matrix,
    sampled_loop,
)

__all__ = ["SapienEngine"]


class SapienEngine(Engine):
    """SAPIEN's ``Scene.step`` on a PhysX CPU system."""

    name = "sapien"
    title = "SAPIEN 3 (PhysX 5, CPU)"
    package = "sapien"
    module = "sapien"
    settings = {"physx_cpu": "a PhysX rigid dynamic body, PhysX's CPU solver (TGS), float32"}
    conventions = Conventions("wxyz", "space", "body-to-space")
    max_steps = 100_000
    precision = "float32"

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "failed to find system libvulkan": no renderer is used
            sapien = load("sapien")

        scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
        scene.set_timestep(plan.dt)
        builder = scene.create_actor_builder()
        builder.add_sphere_collision(radius=0.01)
        moments, P = principal_frame(case.inertia)
        builder.set_mass_and_inertia(
            1.0,
            sapien.Pose(p=[0.0, 0.0, 0.0], q=[float(x) for x in matrix_to_quaternion(P)]),
            list(map(float, moments)),
        )
        actor = builder.build(name="body")
        q0 = np.asarray(case.quaternion0, float)
        actor.set_pose(sapien.Pose(p=[0.0, 0.0, 0.0], q=[float(x) for x in q0]))
        rb = actor.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
        default_damping = float(rb.get_angular_damping())
        rb.set_angular_damping(0.0)
        rb.set_linear_damping(0.0)
        rb.set_disable_gravity(True)
        rb.set_sleep_threshold(0.0)
        rb.set_angular_velocity([float(x) for x in quaternion_to_matrix(q0) @ np.asarray(case.omega0, float)])

        def step(n: int) -> None:
            for _ in range(n):
                scene.step()

        def read():
            return np.array(actor.get_pose().q, dtype=float), np.array(rb.get_angular_velocity(), dtype=float)

        q, w, wall = sampled_loop(plan, step, read)
        notes = (
            "float32 (PhysX)",
            f"angular damping set to 0 (default {default_damping:g}), max angular velocity "
            f"{float(rb.get_max_angular_velocity()):g} rad/s (default kept)",
        )
        return EngineRun(plan.times, q, w, self.conventions, case.inertia_array, plan.steps, wall, notes)
