"""Newton (``pip install newton``, on NVIDIA Warp's CPU device): one body on a free joint, three of its solvers.

Conventions: ``State.body_q`` is a Warp transform ``(px, py, pz, qx, qy, qz, qw)``, the quaternion
scalar last, body to world; ``State.body_qd`` is ``(vx, vy, vz, wx, wy, wz)`` with the angular velocity
in the world (space) frame. Warp computes in float32. The solvers' default angular damping (0.05 for
the semi-implicit and Featherstone solvers) is set to zero. A full inertia tensor is given as it is. The
first run of each solver compiles its Warp kernels (a minute or more on a CPU; cached on disk after),
which is not counted in the wall time. At about a millisecond a step on a CPU, the report runs it at
steps of 1e-3 s and more.
"""

from __future__ import annotations

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load, quaternion_to_matrix, sampled_loop

__all__ = ["NewtonEngine"]


class NewtonEngine(Engine):
    """Newton's ``SolverXPBD``, ``SolverSemiImplicit`` and ``SolverFeatherstone`` on Warp's CPU device."""

    name = "newton"
    title = "Newton (Warp, CPU)"
    package = "newton"
    module = "newton"
    settings = {
        "xpbd": "SolverXPBD (extended position-based dynamics), float32",
        "semi_implicit": "SolverSemiImplicit (semi-implicit Euler on maximal coordinates), float32",
        "featherstone": "SolverFeatherstone (reduced coordinates), float32",
    }
    conventions = Conventions("xyzw", "space", "body-to-space")
    max_steps = 10_100
    min_dt = 1e-3  # about 1 ms a step on a CPU: 10 periods at 1e-4 would take minutes a cell
    precision = "float32"

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        newton = load("newton")
        wp = load("warp")

        wp.config.quiet = True
        I = case.inertia_array
        tensor = np.diag(I) if I.ndim == 1 else I
        q0 = np.asarray(case.quaternion0, float)
        builder = newton.ModelBuilder(gravity=(0.0, 0.0, 0.0))
        body = builder.add_body(
            xform=wp.transform(wp.vec3(0.0, 0.0, 0.0), wp.quat(*(float(x) for x in q0[[1, 2, 3, 0]]))),
            mass=1.0,
            inertia=wp.mat33(*(float(x) for x in tensor.ravel())),
            lock_inertia=True,
        )
        if builder.joint_count == 0:  # add_body adds the free joint itself in recent versions
            builder.add_joint_free(body)
        model = builder.finalize(device="cpu")
        solver_class = {
            "xpbd": newton.solvers.SolverXPBD,
            "semi_implicit": newton.solvers.SolverSemiImplicit,
            "featherstone": newton.solvers.SolverFeatherstone,
        }[setting]
        solver = solver_class(model, angular_damping=0.0)
        states = [model.state(), model.state()]
        control = model.control()
        qd = states[0].joint_qd.numpy()
        qd[3:6] = quaternion_to_matrix(q0) @ np.asarray(case.omega0, float)
        states[0].joint_qd.assign(qd)
        newton.eval_fk(model, states[0].joint_q, states[0].joint_qd, states[0])
        scratch = [model.state(), model.state()]  # compile the solver's kernels outside the timed loop
        solver.step(scratch[0], scratch[1], control, None, plan.dt)

        def step(n: int) -> None:
            for _ in range(n):
                solver.step(states[0], states[1], control, None, plan.dt)
                states.reverse()

        def read():
            return (
                np.array(states[0].body_q.numpy()[0][3:7], dtype=float),
                np.array(states[0].body_qd.numpy()[0][3:6], dtype=float),
            )

        q, w, wall = sampled_loop(plan, step, read)
        notes = ("float32 (Warp)", "angular damping set to 0 (default 0.05 for semi_implicit, featherstone)")
        return EngineRun(plan.times, q, w, self.conventions, I, plan.steps, wall, notes)
