"""MuJoCo MJX (``pip install mujoco-mjx``): MuJoCo's model stepped by its JAX port on JAX's CPU device.

Same conventions as MuJoCo (``qpos[3:7]`` scalar-first body to space, ``qvel[3:6]`` body rate). JAX
computes in float32 (its default; turning its 64-bit mode on and off inside one process breaks MJX's
compilation, so the report keeps the default). A run is one compiled call (per 4096 samples): a ``lax.fori_loop`` over
the samples of a ``lax.fori_loop`` over the steps between them (compiled ahead once per integrator and kind of inertia, the
compilation not counted).
"""

from __future__ import annotations

import time

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load
from .mujoco import mjcf

__all__ = ["MJXEngine"]

_COMPILED: dict = {}
#: samples per compiled call
_BUFFER = 4096


class MJXEngine(Engine):
    """MJX's ``step`` (Euler, implicitfast or RK4) in float32, JAX's default precision."""

    name = "mjx"
    title = "MuJoCo MJX (JAX, CPU)"
    package = "mujoco-mjx"
    module = "mujoco.mjx"
    settings = {
        "Euler": "MJX's default integrator, float32 (JAX's default precision)",
        "implicitfast": "implicit in the velocity-dependent forces without their Coriolis derivatives, float32",
        "RK4": "the classical 4th-order Runge-Kutta, float32",
    }
    conventions = Conventions("wxyz", "body", "body-to-space")
    max_steps = 30_000
    precision = "float32"

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        import jax
        import jax.numpy as jnp

        mujoco = load("mujoco")
        mjx = load("mujoco.mjx")

        model = mujoco.MjModel.from_xml_string(mjcf(case.inertia, setting, plan.dt))
        mx = mjx.put_model(model)
        d = mjx.make_data(mx)
        qpos = np.zeros(7)
        qpos[3:7] = case.quaternion0
        qvel = np.zeros(6)
        qvel[3:6] = case.omega0
        d = d.replace(qpos=jnp.asarray(qpos, dtype=d.qpos.dtype), qvel=jnp.asarray(qvel, dtype=d.qvel.dtype))
        key = (setting, case.inertia_array.ndim)  # a full tensor makes another model structure
        if key not in _COMPILED:

            def run(m, data, every, count):
                def sample(k, carry):
                    dd, qb, wb = carry
                    dd = jax.lax.fori_loop(0, every, lambda _, x: mjx.step(m, x), dd)
                    return dd, qb.at[k].set(dd.qpos[3:7]), wb.at[k].set(dd.qvel[3:6])

                qb = jnp.zeros((_BUFFER, 4), dtype=data.qpos.dtype)
                wb = jnp.zeros((_BUFFER, 3), dtype=data.qvel.dtype)
                return jax.lax.fori_loop(0, count, sample, (data, qb, wb))

            # compiled ahead of time, once per integrator (the numbers of steps are arguments): not timed
            _COMPILED[key] = jax.jit(run).lower(mx, d, plan.every, 1).compile()
        compiled = _COMPILED[key]
        qs, ws = [], []
        wall = 0.0
        left = plan.samples - 1
        while left > 0:
            count = min(left, _BUFFER)
            t0 = time.perf_counter()
            d, qb, wb = compiled(mx, d, plan.every, count)
            qb.block_until_ready()
            wall += time.perf_counter() - t0
            qs.append(np.asarray(qb[:count], dtype=float))
            ws.append(np.asarray(wb[:count], dtype=float))
            left -= count
        q = np.concatenate([qpos[None, 3:7], *qs])
        w = np.concatenate([qvel[None, 3:6], *ws])
        return EngineRun(plan.times, q, w, self.conventions, case.inertia_array, plan.steps, wall, ("float32 (JAX)",))
