"""The conformance report (issue 23): engines held against the exact motion.

- The metrics of a cell are the oracle's reading of the run: checked on runs made here (the exact motion,
  a perturbed one) against errors computed in the test.
- A reduced report (one case, one step) with each engine installed; for MuJoCo and PyBullet the numbers
  are checked against the engine driven by hand in the test, its raw output converted by hand, and the
  closed form (``ep.solve(method="exact")``): within 2 %.
- Each installed engine's claimed conventions: the oracle finds nothing to correct, and names the flag
  when one convention is deliberately misstated.
- Resumability (a second run reads the cells back), the files written, the command's errors (exit 2).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import main
from eulerpoisson.oracle import Conventions, compare_run, run_from_arrays
from eulerpoisson.oracle.cases import CONFORMANCE_CASE_NAMES, conformance_cases
from eulerpoisson.oracle.conformance import (
    cell_path,
    conformance_case,
    evaluate_run,
    natural_period,
    plan_cell,
    run_cell,
    run_matrix,
    step_needed,
    write_report,
)
from eulerpoisson.oracle.engines import ENGINE_NAMES, Engine, EngineRun, get_engine, sample_plan

INSTALLED = [n for n in ENGINE_NAMES if get_engine(n).available()[0]]


def _true_angle(q_ref, q):
    """The plain formula 2 arccos |<q_ref, q>| (unit quaternions): independent of the oracle's."""
    qn = q / np.linalg.norm(q, axis=1, keepdims=True)
    return 2.0 * np.arccos(np.clip(np.abs(np.sum(q_ref * qn, axis=1)), 0.0, 1.0))


def _rot(q):
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


class ExactEngine(Engine):
    """A stand-in engine: the closed form, perturbed by a known rotation growing in time; counts its runs."""

    name = "exact-test"
    title = "test"
    package = "numpy"
    module = "numpy"
    settings = {"plain": "the exact motion", "drifting": "the exact motion turned by 1e-3 t rad about z in space"}
    conventions = Conventions("xyzw", "space", "body-to-space")
    runs = 0

    def simulate(self, case, setting, plan):
        type(self).runs += 1
        tr = ep.solve(case.inertia_array, plan.times, omega0=case.omega0, attitude0=case.quaternion0, method="exact")
        q = tr.quaternion
        if setting == "drifting":
            a = 1e-3 * plan.times
            rz = np.stack([np.cos(a / 2), 0 * a, 0 * a, np.sin(a / 2)], -1)
            q = np.asarray(ep.attitude.quaternion_multiply(rz, q))
        space = np.einsum("tij,tj->ti", _rot(q), tr.omega)  # the body rate stays the exact one
        return EngineRun(plan.times, q[:, [1, 2, 3, 0]], space, self.conventions, case.inertia_array, plan.steps, 0.0)


def test_cases_and_periods():
    cases = conformance_cases()
    assert tuple(cases) == CONFORMANCE_CASE_NAMES and len(cases) == 7
    # the periods from their definitions: the racket's flips from the closed form's own sign changes
    case = cases["racket_near_separatrix"]
    T, kind = natural_period(case)
    tr = ep.solve(case.inertia, np.linspace(0, 6.0, 60001), omega0=case.omega0, method="exact")
    w1 = tr.omega[:, 0]
    flips = tr.t[1:][np.sign(w1[1:]) != np.sign(w1[:-1])]
    assert kind == "flip" and np.diff(flips) == pytest.approx(T, abs=2e-4)
    T, kind = natural_period(cases["symmetric_precession"])
    assert kind == "precession" and T == pytest.approx(2 * np.pi / ((3.0 - 2.0) / 2.0 * 4 * np.pi))
    T, kind = natural_period(cases["nearly_spherical"])
    assert kind == "rotation" and T == pytest.approx(1.0)
    case = cases["spin_largest_axis"]
    T, _ = natural_period(case)
    tr = ep.solve(case.inertia, np.linspace(0, 3.0, 30001), omega0=case.omega0, method="exact")
    up = tr.t[1:][(tr.omega[1:, 0] > 0) & (tr.omega[:-1, 0] <= 0)]
    assert np.diff(up) == pytest.approx(T, abs=2e-4)
    with pytest.raises(ValueError, match="unknown case 'cube'"):
        conformance_case("cube")


def test_plan_reaches_100_then_10_periods():
    plan, periods = plan_cell(1.0, 1e-3, 100_000)
    assert periods == pytest.approx(100.0) and plan.steps <= 100_000 and plan.t_end == pytest.approx(100.0)
    plan, periods = plan_cell(1.0, 1e-4, 100_000)
    assert periods == pytest.approx(10.0)
    plan, periods = plan_cell(1.0, 1e-4, 5_000)
    assert periods == pytest.approx(0.5, rel=0.05)
    with pytest.raises(ValueError, match="dt must be a positive finite number"):
        sample_plan(0.0, 1.0, 0.1)


def test_metrics_are_the_true_errors():
    """A run turned by 1e-3 t rad about the space z axis: error 1e-3 t; energy and |m| are conserved."""
    case = conformance_case("racket_near_separatrix")
    T, _ = natural_period(case)
    eng = ExactEngine()
    plan, _ = plan_cell(T, 1e-2, 20_000)
    run = eng.run(case, 1e-2, "drifting", plan)
    m = evaluate_run(run, case, T)
    assert m["status"] == "ok" and m["convention_hint"] is None
    t = plan.times
    assert m["error_10"] == pytest.approx(1e-3 * t[t <= 10 * T].max(), rel=1e-6)
    assert m["error_100"] == pytest.approx(1e-3 * plan.t_end, rel=1e-3)
    assert m["flip"] == "yes" and m["flip_exact"] >= 100 and m["flip_time_error"] < 1e-9
    # E is conserved; m turns about z with the attitude: |m(t) - m(0)| = 2 |m_perp| sin(1e-3 t / 2)
    assert m["energy_drift_per_1000"] < 1e-9
    m0 = np.array(case.inertia) * np.array(case.omega0)
    tilt = np.linalg.norm(m0[:2]) / np.linalg.norm(m0)
    assert m["momentum_drift_per_1000"] == pytest.approx(1e-3 * tilt * 1000 * T, rel=1e-2)
    plain = evaluate_run(eng.run(case, 1e-2, "plain", plan), case, T)
    assert plain["error_100"] < 1e-9


def test_diverged_run_is_cut_where_it_blows_up():
    case = conformance_case("spin_largest_axis")
    t = np.linspace(0.0, 2.0, 41)
    tr = ep.solve(case.inertia, t, omega0=case.omega0, method="exact")
    w = tr.omega.copy()
    w[30:] *= 1e4
    run = EngineRun(t, tr.quaternion, w, Conventions("wxyz"), case.inertia_array, 40, 0.0)
    m = evaluate_run(run, case, 1.0)
    assert m["status"] == "diverged" and "t = 1.5" in m["message"] and m["error_10"] is None


def test_resumable_cells_and_report_files(tmp_path):
    eng = ExactEngine()
    ExactEngine.runs = 0
    cells = tmp_path / "cells"
    rep = run_matrix([eng], ["spin_largest_axis"], [1e-2], cells, max_steps=10_100)
    assert ExactEngine.runs == 2 and len(rep["cells"]) == 2
    assert (cells / "exact-test__plain__spin_largest_axis__dt0.01.json").is_file()
    lines = []
    rep2 = run_matrix([eng], ["spin_largest_axis"], [1e-2], cells, max_steps=10_100, progress=lines.append)
    assert ExactEngine.runs == 2 and all("(done before)" in line for line in lines)
    assert [c["error_10"] for c in rep2["cells"]] == [c["error_10"] for c in rep["cells"]]
    # a damaged cell file is run again
    cell_file = cell_path(cells, "exact-test", "plain", "spin_largest_axis", 1e-2)
    with open(cell_file, "w") as fh:
        fh.write("{")
    _, old = run_cell(eng, "plain", "spin_largest_axis", 1e-2, cells, max_steps=10_100)
    assert not old and ExactEngine.runs == 3
    # in two worker processes: the same cells, read back
    rep3 = run_matrix([eng], ["spin_largest_axis"], [1e-2], cells, max_steps=10_100, jobs=2)
    assert [c["error_10"] for c in rep3["cells"]] == [c["error_10"] for c in rep["cells"]]
    files = write_report(rep2, tmp_path / "out")
    names = sorted(p.rsplit("/", 1)[-1] for p in files)
    assert names == ["report.json", "spin_largest_axis.png", "table.csv", "table.md"]
    text = (tmp_path / "out" / "table.md").read_text()
    assert "## `spin_largest_axis`" in text and "| exact-test | drifting | 0.01 |" in text
    data = json.loads((tmp_path / "out" / "report.json").read_text())
    assert data["step_needed"]["exact-test/plain"]["spin_largest_axis"]["dt"] == 0.01
    assert "cannot reach" in data["step_needed"]["exact-test/drifting"]["spin_largest_axis"]["text"]


def test_step_needed_names_the_largest_step_or_why_none():
    cells = [
        {"engine": "e", "setting": "s", "case": "c", "dt": 1e-2, "error_100": 0.3},
        {"engine": "e", "setting": "s", "case": "c", "dt": 1e-3, "error_100": 2e-3},
    ]
    assert step_needed(cells)["e/s"]["c"] == {"dt": None, "text": "cannot reach (2.0e-03 rad at dt = 0.001)"}
    # out of reach already at 10 periods, or blown up: cannot reach; a step that might reach it: not run
    cells = [
        {"engine": "e", "setting": "s", "case": "c", "dt": 1e-2, "error_100": None, "status": "diverged"},
        {"engine": "e", "setting": "s", "case": "c", "dt": 1e-3, "error_100": None, "error_10": 0.2},
    ]
    assert step_needed(cells)["e/s"]["c"]["text"] == "cannot reach (2.0e-01 rad by 10 periods at dt = 0.001)"
    cells[1]["error_10"] = 1e-5
    assert step_needed(cells)["e/s"]["c"]["text"] == "not run to 100 periods"


@pytest.mark.parametrize(
    "argv, match",
    [
        (["--dt", "abc"], "--dt: 'abc' is not a number"),
        (["--dt", "-1e-3"], "--dt must be positive"),
        (["--engine", "havok"], "unknown engine 'havok'"),
        (["--case", "cube", "--engine", "genesis"], "unknown case 'cube'"),
        (["--setting", "RK5", "--engine", "genesis"], "unknown setting"),
        (["--max-steps", "0"], "--max-steps must be a positive number"),
        (["--max-steps", "many"], "invalid int value"),
        (["--jobs", "0"], "--jobs must be a positive number"),
    ],
)
def test_cli_errors_exit_2(capsys, tmp_path, argv, match):
    code = main(["conformance", "--out", str(tmp_path / "r"), *argv])
    err = capsys.readouterr().err
    assert code == 2 and match in err and len(err.strip().splitlines()) == 1


def test_cli_out_is_a_file(capsys, tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["conformance", "--out", str(f)]) == 2
    assert "is a file" in capsys.readouterr().err


def test_cli_list_names_every_engine(capsys):
    assert main(["conformance", "--list"]) == 0
    out = capsys.readouterr().out
    assert all(f"  {n} (" in out for n in ENGINE_NAMES) and "racket_near_separatrix" in out


# ---------------------------------------------------------------------------
# with the engines installed here
# ---------------------------------------------------------------------------
def _exact(case, t):
    return ep.solve(case.inertia_array, t, omega0=case.omega0, attitude0=case.quaternion0, method="exact")


@pytest.mark.parametrize("name", ENGINE_NAMES)
def test_reduced_report_per_engine(name, tmp_path, capsys):
    engine = get_engine(name)
    ok, why = engine.available()
    if not ok:
        pytest.skip(f"{name} is not installed here: {why}")
    code = main(
        [
            "conformance",
            "--engine",
            name,
            "--case",
            "spin_largest_axis",
            "--dt",
            "1e-2",
            "--max-steps",
            "1010",
            "--out",
            str(tmp_path / "r"),
            "--json",
            "--no-plots",
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    rep = json.loads(captured.out)
    cells = rep["cells"]
    assert [c["setting"] for c in cells] == list(engine.settings)
    for c in cells:
        assert c["status"] != "error", c
        assert c["convention_hint"] is None, c  # the adapter's claimed conventions need no correction
        assert c["periods_run"] == pytest.approx(10.0, rel=0.01) and c["error_10"] is not None
    assert "(done before)" not in captured.err and "[1/" in captured.err


def _mujoco_by_hand(case, integrator, dt, steps, every):
    import mujoco

    I = case.inertia
    diag = " ".join(repr(float(x)) for x in I)
    xml = (
        f'<mujoco><option gravity="0 0 0" integrator="{integrator}" timestep="{dt!r}"/><worldbody><body>'
        f'<freejoint/><inertial pos="0 0 0" mass="1" diaginertia="{diag}"/></body></worldbody></mujoco>'
    )
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[3:7] = case.quaternion0
    d.qvel[3:6] = case.omega0
    qs = [d.qpos[3:7].copy()]
    for _ in range(steps // every):
        mujoco.mj_step(m, d, nstep=every)
        qs.append(d.qpos[3:7].copy())
    return np.array(qs)  # scalar first, body to space: as it is


def _pybullet_by_hand(case, dt, steps, every):
    import pybullet as p

    c = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, 0, physicsClientId=c)
        p.setTimeStep(dt, physicsClientId=c)
        shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.01, physicsClientId=c)
        w0, x0, y0, z0 = case.quaternion0
        b = p.createMultiBody(1.0, shape, basePosition=[0, 0, 0], baseOrientation=[x0, y0, z0, w0], physicsClientId=c)
        p.changeDynamics(
            b, -1, localInertiaDiagonal=list(case.inertia), linearDamping=0, angularDamping=0, physicsClientId=c
        )
        R0 = _rot(np.array([case.quaternion0]))[0]
        p.resetBaseVelocity(b, [0, 0, 0], list(R0 @ np.array(case.omega0)), physicsClientId=c)
        qs = [p.getBasePositionAndOrientation(b, physicsClientId=c)[1]]
        for _ in range(steps // every):
            for _ in range(every):
                p.stepSimulation(physicsClientId=c)
            qs.append(p.getBasePositionAndOrientation(b, physicsClientId=c)[1])
    finally:
        p.disconnect(c)
    q = np.array(qs)
    return q[:, [3, 0, 1, 2]]  # scalar last -> scalar first, by hand


@pytest.mark.parametrize(
    "engine_name, setting",
    [("mujoco", "RK4"), ("mujoco", "Euler"), ("pybullet", "multibody")],
)
def test_reported_error_matches_the_engine_driven_by_hand(engine_name, setting, tmp_path):
    engine = get_engine(engine_name)
    ok, why = engine.available()
    if not ok:
        pytest.skip(f"{engine_name} is not installed here: {why}")
    case = conformance_cases()["spin_largest_axis"]
    dt = 1e-2
    cell, _ = run_cell(engine, setting, case.name, dt, tmp_path, max_steps=1010)
    T = cell["period"]
    steps = int(round(10 * T / dt))
    every = cell["steps"] // (cell["samples"] - 1)
    if engine_name == "mujoco":
        q = _mujoco_by_hand(case, setting, dt, steps - steps % every, every)
    else:
        q = _pybullet_by_hand(case, dt, steps - steps % every, every)
    t = np.arange(q.shape[0]) * every * dt
    ref = _exact(case, t)
    true = _true_angle(ref.quaternion, q)
    assert true.max() > 1e-8  # a real error, not round-off
    assert cell["error_10"] == pytest.approx(true.max(), rel=0.02)


#: each engine's most accurate setting (the first one for the others)
ACCURATE = {"mujoco": "RK4", "mjx": "RK4", "drake": "runge_kutta3", "basilisk": "RK4"}


@pytest.mark.parametrize("name", ENGINE_NAMES)
def test_claimed_conventions_per_engine(name):
    """The adapter's run, read with its claimed conventions: no hint; with one misstated: the hint names it."""
    engine = get_engine(name)
    ok, why = engine.available()
    if not ok:
        pytest.skip(f"{name} is not installed here: {why}")
    case = conformance_cases()["symmetric_precession"]  # tilted start: body and space frames differ
    setting = ACCURATE.get(name, next(iter(engine.settings)))
    plan = sample_plan(1e-3, 0.3, 0.01)
    run = engine.run(case, 1e-3, setting, plan)
    c = run.conventions
    raw = run_from_arrays(run.t, run.quaternion, run.omega, quaternion_order=c.quaternion_order)
    rep = compare_run(raw, run.inertia, conventions=c)
    assert rep.convention_hint is None and rep.max_attitude_error < 0.05 and rep.max_omega_error < 0.05
    wrong = Conventions(c.quaternion_order, "space" if c.omega_frame == "body" else "body", c.attitude_convention)
    rep = compare_run(raw, run.inertia, conventions=wrong)
    assert rep.convention_hint is not None and f"--omega-frame {c.omega_frame}" in rep.convention_hint
