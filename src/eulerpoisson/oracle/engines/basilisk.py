"""Basilisk (``pip install bsk``): the spacecraft module's rigid hub, integrated by its state-vector integrators.

Conventions: the hub's attitude is the MRP set ``sigma_BN`` (switched to its shadow set past 1), its rate
``omega_BN_B`` in the body frame. The adapter converts ``sigma_BN`` to the Euler parameters
``beta_BN = ((1 - s^2), 2 sigma) / (1 + s^2)``, written as a quaternion (w, x, y, z); read as a Hamilton
quaternion these rotate body to space. A full inertia tensor is given as it is (``IHubPntBc_B``).
"""

from __future__ import annotations

import time

import numpy as np

from ..cases import ReferenceCase
from ..runs import Conventions
from .base import Engine, EngineRun, SamplePlan, load

__all__ = ["BasiliskEngine", "quaternion_from_sigma"]


def quaternion_from_sigma(sigma) -> np.ndarray:
    """Euler parameters (w, x, y, z) of modified Rodrigues parameters ``sigma`` (..., 3).

    Examples
    --------
    >>> from eulerpoisson.oracle.engines.basilisk import quaternion_from_sigma
    >>> quaternion_from_sigma([0.0, 0.0, 1.0]).tolist()                 # 180 degrees about z
    [0.0, 0.0, 0.0, 1.0]
    """
    s = np.asarray(sigma, dtype=float)
    s2 = np.sum(s * s, axis=-1, keepdims=True)
    return np.concatenate([(1.0 - s2), 2.0 * s], axis=-1) / (1.0 + s2)


def _sigma_from_quaternion(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    q = q if q[0] >= 0 else -q
    return q[1:] / (1.0 + q[0])


class BasiliskEngine(Engine):
    """Basilisk's spacecraft hub with its fixed-step ``svIntegratorEuler``, ``svIntegratorRK2`` or ``svIntegratorRK4``."""

    name = "basilisk"
    title = "Basilisk (spacecraft hub)"
    package = "bsk"
    module = "Basilisk.simulation.spacecraft"
    settings = {
        "Euler": "svIntegratorEuler: explicit Euler",
        "RK2": "svIntegratorRK2: Heun's 2nd-order Runge-Kutta",
        "RK4": "svIntegratorRK4: the classical 4th-order Runge-Kutta, the default",
    }
    conventions = Conventions("wxyz", "body", "body-to-space")
    max_steps = 100_000

    def simulate(self, case: ReferenceCase, setting: str, plan: SamplePlan) -> EngineRun:
        spacecraft = load("Basilisk.simulation.spacecraft")
        svIntegrators = load("Basilisk.simulation.svIntegrators")
        SimulationBaseClass = load("Basilisk.utilities.SimulationBaseClass")

        ns = int(round(plan.dt * 1e9))
        if ns <= 0 or abs(ns - plan.dt * 1e9) > 1e-6 * plan.dt * 1e9:
            raise ValueError(f"Basilisk's clock counts whole nanoseconds: dt = {plan.dt!r} s is not one")
        sim = SimulationBaseClass.SimBaseClass()
        proc = sim.CreateNewProcess("process")
        proc.addTask(sim.CreateNewTask("task", ns))
        sc = spacecraft.Spacecraft()
        sc.ModelTag = "hub"
        sc.hub.mHub = 1.0
        I = case.inertia_array
        sc.hub.IHubPntBc_B = (np.diag(I) if I.ndim == 1 else I).tolist()
        sc.hub.sigma_BNInit = [[float(x)] for x in _sigma_from_quaternion(case.quaternion0)]
        sc.hub.omega_BN_BInit = [[float(x)] for x in case.omega0]
        sim.AddModelToTask("task", sc)
        integrator = getattr(svIntegrators, f"svIntegrator{setting}")(sc)
        sc.setIntegrator(integrator)
        recorder = sc.scStateOutMsg.recorder(ns * plan.every)
        sim.AddModelToTask("task", recorder)
        sim.InitializeSimulation()
        sim.ConfigureStopTime(ns * plan.steps)
        t0 = time.perf_counter()
        sim.ExecuteSimulation()
        wall = time.perf_counter() - t0
        sigma = np.array(recorder.sigma_BN, dtype=float)[: plan.samples]
        w = np.array(recorder.omega_BN_B, dtype=float)[: plan.samples]
        q = quaternion_from_sigma(sigma)
        t = np.array(recorder.times(), dtype=float)[: plan.samples] * 1e-9
        notes = ("attitude: sigma_BN (MRP) as Euler parameters beta_BN",)
        return EngineRun(t, q, w, self.conventions, I, plan.steps, wall, notes)
