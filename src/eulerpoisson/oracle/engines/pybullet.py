"""PyBullet (``pip install pybullet``): one body with principal moments, in reduced or maximal coordinates.

Conventions: ``getBasePositionAndOrientation`` gives the quaternion scalar last (x, y, z, w), body to
space, of the body's *inertial* frame; ``getBaseVelocity`` the angular velocity in the space (world)
frame. PyBullet takes principal moments (``localInertiaDiagonal``): a full tensor is built in its
principal frame, and the run is read with the principal moments. The damping PyBullet applies by default
(linear and angular damping 0.04 on a multibody) is set to zero; the rest stays as PyBullet sets it
(notably a multibody's 100 rad/s limit on each velocity coordinate). PyBullet's API has no switch for
Bullet's gyroscopic flags (``BT_ENABLE_GYROSCOPIC_FORCE_*``): the two settings are its two body models.
"""

from __future__ import annotations

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load, principal_state, quaternion_to_matrix, sampled_loop

__all__ = ["PyBulletEngine"]


class PyBulletEngine(Engine):
    """PyBullet's ``stepSimulation`` (its semi-implicit Euler) on a multibody or a maximal-coordinates body."""

    name = "pybullet"
    title = "PyBullet (Bullet 3)"
    package = "pybullet"
    module = "pybullet"
    settings = {
        "multibody": "the default body model: a btMultiBody (Featherstone, reduced coordinates)",
        "maximal": "useMaximalCoordinates=True: a btRigidBody (its default implicit body-frame gyroscopic term)",
    }
    conventions = Conventions("xyzw", "space", "body-to-space")
    max_steps = 1_000_000

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        p = load("pybullet")

        moments, q0, w0 = principal_state(case)
        c = p.connect(p.DIRECT)
        try:
            p.setGravity(0, 0, 0, physicsClientId=c)
            p.setTimeStep(plan.dt, physicsClientId=c)
            shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.01, physicsClientId=c)
            body = p.createMultiBody(
                baseMass=1.0,
                baseCollisionShapeIndex=shape,
                basePosition=[0.0, 0.0, 0.0],
                baseOrientation=[float(x) for x in q0[[1, 2, 3, 0]]],
                useMaximalCoordinates=setting == "maximal",
                physicsClientId=c,
            )
            p.changeDynamics(
                body,
                -1,
                localInertiaDiagonal=[float(x) for x in moments],
                linearDamping=0.0,
                angularDamping=0.0,
                physicsClientId=c,
            )
            space = quaternion_to_matrix(q0) @ w0
            p.resetBaseVelocity(body, [0.0, 0.0, 0.0], [float(x) for x in space], physicsClientId=c)

            def step(n: int) -> None:
                for _ in range(n):
                    p.stepSimulation(physicsClientId=c)

            def read():
                return (
                    np.array(p.getBasePositionAndOrientation(body, physicsClientId=c)[1], dtype=float),
                    np.array(p.getBaseVelocity(body, physicsClientId=c)[1], dtype=float),
                )

            q, w, wall = sampled_loop(plan, step, read)
        finally:
            p.disconnect(physicsClientId=c)
        notes = ["linear and angular damping set to 0 (PyBullet's default is 0.04)"]
        if np.asarray(case.inertia).ndim == 2:
            notes.append("built in the principal frame (PyBullet takes principal moments)")
        return EngineRun(plan.times, q, w, self.conventions, moments, plan.steps, wall, tuple(notes))
