"""A real engine validated: MuJoCo's free body (default integrator and RK4) exported to CSV, run through `validate`.

The test establishes MuJoCo's conventions itself (quaternion order and the frame of the free joint's
angular velocity, from finite differences of its own quaternions), checks that the reported error is the
true error (against an independent DOP853 integration, tests/_reference.py), that the default integrator
fails the tennis racket by a large angle and that RK4 at a small step passes.
"""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip(
    "mujoco",
    exc_type=ImportError,
    reason="the optional test dependency mujoco is not installed "
    "(pip install mujoco, or `make test` installs it where it can)",
)

from _reference import quaternion_distance  # noqa: E402
from _torque_reference import reference_motion  # noqa: E402
from eulerpoisson.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("validate_mujoco", ROOT / "examples" / "validate_mujoco.py")
vm = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(vm)


def _qmul(p, q):
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    return np.concatenate([pw * qw - np.sum(pv * qv, -1, keepdims=True), pw * qv + qw * pv + np.cross(pv, qv)], -1)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("mujoco")
    res = {}
    for _label, integ, dt in vm.RUNS:
        t, q, w = vm.simulate(integ, dt)
        path = out / f"mujoco_{integ.lower()}.csv"
        vm.write_csv(path, t, q, w)
        res[integ] = (path, t, q, w)
    return res


def test_mujoco_conventions_established_numerically():
    """qpos[3:7] is (w, x, y, z) body to space and qvel[3:6] the body-frame rate: finite differences say so."""
    q0 = np.array([0.8, 0.36, -0.48, 0.0])  # a tilted start, so body and space frames differ
    model = mujoco.MjModel.from_xml_string(vm.MJCF.format(integrator="RK4", dt=1e-5, I=vm.INERTIA))
    data = mujoco.MjData(model)
    data.qpos[3:7] = q0
    data.qvel[3:6] = [1.0, 2.0, -0.5]
    qa, wa = data.qpos[3:7].copy(), data.qvel[3:6].copy()
    mujoco.mj_step(model, data)
    qb, wb = data.qpos[3:7].copy(), data.qvel[3:6].copy()
    dq = (qb - qa) / 1e-5
    qm = 0.5 * (qa + qb)
    wm = 0.5 * (wa + wb)
    conj = qm * [1, -1, -1, -1]
    body = 2 * _qmul(conj, dq)[1:]  # q^-1 dq/dt = (0, Omega)/2 for a body-frame rate
    space = 2 * _qmul(dq, conj)[1:]  # dq/dt q^-1 = (0, omega)/2 for a space-frame rate
    assert np.linalg.norm(body - wm) < 1e-6 * np.linalg.norm(wm)
    assert np.linalg.norm(space - wm) > 0.1 * np.linalg.norm(wm)
    # scalar first: the identity is (1, 0, 0, 0) in a fresh model
    assert np.array_equal(mujoco.MjData(model).qpos[3:7], [1.0, 0.0, 0.0, 0.0])


def _validate(capsys, path, *extra):
    code = main(["validate", str(path), "--inertia", ",".join(map(repr, vm.INERTIA)), "--json", *extra])
    out, err = capsys.readouterr()
    return code, json.loads(out), err


@pytest.mark.parametrize("integ", ["Euler", "RK4"])
def test_reported_error_is_the_true_error(capsys, runs, integ):
    path, t, q, w = runs[integ]
    code, rep, err = _validate(capsys, path)
    assert code == 0, err
    # an independent integration (30-digit Taylor series in mpmath, no eulerpoisson code) from the CSV's first sample
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    q_ref, w_ref = reference_motion(
        vm.INERTIA, data[0, 1:5] / np.linalg.norm(data[0, 1:5]), data[0, 5:8], data[:, 0], dps=30
    )
    true = quaternion_distance(q_ref, data[:, 1:5] / np.linalg.norm(data[:, 1:5], axis=1, keepdims=True))
    assert rep["max_attitude_error"] == pytest.approx(true.max(), rel=1e-6, abs=1e-13)
    true_w = np.max(np.linalg.norm(data[:, 5:8] - w_ref, axis=1)) / np.max(np.linalg.norm(w_ref, axis=1))
    assert rep["max_omega_error"] == pytest.approx(true_w, rel=1e-6, abs=1e-13)


def test_default_integrator_fails_the_tennis_racket(capsys, runs):
    path = runs["Euler"][0]
    code, rep, err = _validate(capsys, path, "--tolerance", str(vm.TOLERANCE))
    assert code == 1 and rep["verdict"] == "fail"
    assert rep["max_attitude_error"] > 1.0  # a large angle: radians, not round-off
    assert rep["exceeded_at"] < 0.1
    assert len(rep["flip_times"]) == 5 and rep["convention_hint"] is None
    assert rep["energy_drift"] > 1e-2  # the default integrator dissipates/gains energy


def test_rk4_small_step_passes(capsys, runs, tmp_path):
    path = runs["RK4"][0]
    plot = tmp_path / "rk4.png"
    code, rep, err = _validate(capsys, path, "--tolerance", str(vm.TOLERANCE), "--plot", str(plot))
    assert code == 0 and rep["verdict"] == "pass", rep
    assert rep["max_attitude_error"] < 1e-8 and rep["energy_drift"] < 1e-9
    assert len(rep["flip_times"]) == 5 and max(abs(e) for e in rep["flip_time_errors"]) < 1e-8
    assert rep["warnings"] == [] and err == ""
    assert plot.stat().st_size > 10_000


def test_mujoco_space_frame_rates_are_detected(capsys, runs, tmp_path):
    """Written out as space-frame rates (R Omega), the mislabeled file is named as such."""
    _, t, q, w = runs["RK4"]
    from eulerpoisson.attitude.core import matrix_from_unit_quaternion

    bad = tmp_path / "space.csv"
    vm.write_csv(
        bad, t, q, np.einsum("tij,tj->ti", matrix_from_unit_quaternion(q / np.linalg.norm(q, axis=1)[:, None]), w)
    )
    code, rep, err = _validate(capsys, bad, "--tolerance", "1e-6")
    assert code == 1 and "--omega-frame space" in rep["convention_hint"]
    code, rep, err = _validate(capsys, bad, "--tolerance", "1e-6", "--omega-frame", "space")
    assert code == 0 and rep["verdict"] == "pass"


def test_example_script_writes_table_and_plot(tmp_path, capsys):
    reports = vm.main(tmp_path)
    out = capsys.readouterr().out
    assert "| Euler (default), dt = 2 ms |" in out and "| RK4, dt = 1 ms |" in out
    assert [r.verdict for _, r in reports] == ["fail", "pass"]
    assert (tmp_path / "validate_mujoco.png").stat().st_size > 10_000
