"""DART (``pip install dartpy``): a skeleton of one body on a ``FreeJoint``, DART's world step.

Conventions: DART's attitude is the body node's world transform, a rotation matrix (body to world); the
adapter converts it to a quaternion (w, x, y, z) of the same rotation. The rate is the first three
generalized velocities of the free joint, which dartpy 6.20 expresses in the world (space) frame (the
world-frame rate the node reports, ``getAngularVelocity()``, equals them; the finite differences of the
attitude agree). A full inertia tensor is given as it is (``setMoment``). DART steps with its one
integrator, semi-implicit Euler.
"""

from __future__ import annotations

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load, matrix_to_quaternion, quaternion_to_matrix, sampled_loop

__all__ = ["DARTEngine"]


class DARTEngine(Engine):
    """DART's ``World.step`` (semi-implicit Euler, its only integrator)."""

    name = "dart"
    title = "DART (dartpy)"
    package = "dartpy"
    module = "dartpy"
    settings = {"semi_implicit_euler": "DART's only integrator: velocities, then positions on the Lie group"}
    conventions = Conventions("wxyz", "space", "body-to-space")
    max_steps = 200_000

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        dart = load("dartpy")

        world = dart.simulation.World()
        world.setGravity([0.0, 0.0, 0.0])
        world.setTimeStep(plan.dt)
        skel = dart.dynamics.Skeleton("body")
        joint, node = skel.createFreeJointAndBodyNodePair(None, dart.dynamics.FreeJointProperties())
        inertia = dart.dynamics.Inertia()
        inertia.setMass(1.0)
        I = case.inertia_array
        inertia.setMoment(np.diag(I) if I.ndim == 1 else I)
        node.setInertia(inertia)
        world.addSkeleton(skel)
        R0 = quaternion_to_matrix(np.asarray(case.quaternion0, float))
        tf = dart.math.Isometry3()
        tf.set_rotation(R0)
        joint.setPositions(dart.dynamics.FreeJoint.convertToPositions(tf))
        joint.setVelocities(np.concatenate([R0 @ np.asarray(case.omega0, float), np.zeros(3)]))

        def step(n: int) -> None:
            for _ in range(n):
                world.step()

        def read():
            R = np.array(node.getWorldTransform().rotation(), dtype=float)
            return matrix_to_quaternion(R), np.array(joint.getVelocities()[:3], dtype=float)

        q, w, wall = sampled_loop(plan, step, read)
        notes = ("attitude: the node's world rotation matrix, as a quaternion",)
        return EngineRun(plan.times, q, w, self.conventions, I, plan.steps, wall, notes)
