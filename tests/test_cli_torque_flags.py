"""The torque flags and ``[torque]`` keys of ``simulate`` come from the torque registry.

Every registered torque with command-line parameters (``Torque.cli``) has its
flags in ``simulate --help`` and its keys in the TOML schema, and is built by
``build_torques`` with no edit of the command line: ``MagneticDipoleTorque``
(``--magnetic-dipole``, ``--magnetic-field``) and a torque registered by a
test (a user's plugin) show it. Each CLI test runs in-process through
``eulerpoisson.cli.main(argv)``.
"""

import json
import re

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import main
from eulerpoisson.cli.config import FLAGS, build_torques, sync_torque_keys, torque_params
from eulerpoisson.torques import TORQUES, MagneticDipoleTorque, Torque, TorqueParam, register_torque

BASE = ["--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", "--samples", "3", "--method", "rk"]
MAG = MagneticDipoleTorque([0.0, 0.0, 1.0], [0.2, 0.0, 0.0])


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def ok_json(capsys, *argv):
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    assert err == ""
    return json.loads(out)


def one_error(capsys, argv, match):
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and out == "", (code, out, err)
    assert lines[0].startswith("eulerpoisson: error: ") and "Traceback" not in err
    assert re.search(match, lines[0][len("eulerpoisson: error: ") :]), lines[0]


def help_text(capsys) -> str:
    code, out, err = run(capsys, "simulate", "--help")
    assert code == 0, err
    return out


def reference(torque):
    return ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 1.0, 3), omega0=[1.0, 0.1, 0.5], torque=torque, method="rk")


def close_state(d, tr, atol=1e-12):
    np.testing.assert_allclose(d["omega"], tr.omega[-1], rtol=0, atol=atol)
    np.testing.assert_allclose(d["quaternion"], tr.quaternion[-1], rtol=0, atol=atol)
    np.testing.assert_allclose(d["m"], tr.m[-1], rtol=0, atol=atol)


# ---------------------------------------------------------------------------
# the magnetic dipole: flags and TOML keys it gets from the registry
# ---------------------------------------------------------------------------
def test_magnetic_dipole_flags_give_the_solve_of_the_torque(capsys):
    d = ok_json(capsys, "simulate", *BASE, "--magnetic-dipole", "0,0,1", "--magnetic-field", "0.2,0,0")
    assert d["method"] == "rk"
    assert d["torque"] == [MAG.to_dict()]
    ref = reference(MAG)
    close_state(d, ref)
    assert d["energy"] == pytest.approx(float(ref.energy[-1]), rel=1e-12, abs=1e-12)
    assert set(d["integrals"]) == set(ref.integrals())


def test_magnetic_dipole_from_a_toml_file(capsys, tmp_path):
    cfg = tmp_path / "mag.toml"
    cfg.write_text(
        "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\nsamples = 3\n"
        '[method]\nname = "rk"\n[torque]\nmagnetic_dipole = [0, 0, 1]\nmagnetic_field = [0.2, 0, 0]\n'
    )
    d = ok_json(capsys, "simulate", str(cfg))
    assert d["torque"] == [MAG.to_dict()]
    close_state(d, reference(MAG))
    flags = ok_json(capsys, "simulate", *BASE, "--magnetic-dipole", "0,0,1", "--magnetic-field", "0.2,0,0")
    assert d == flags
    # a flag replaces what the file says
    d2 = ok_json(capsys, "simulate", str(cfg), "--magnetic-field", "0,0.3,0")
    assert d2["torque"] == [{"kind": "magnetic_dipole", "dipole": [0.0, 0.0, 1.0], "field": [0.0, 0.3, 0.0]}]


def test_magnetic_dipole_adds_to_the_other_torques_in_registry_order(capsys):
    d = ok_json(
        capsys,
        "simulate",
        *BASE,
        "--magnetic-field",
        "0.2,0,0",
        "--body-torque",
        "0,0,0.1",
        "--magnetic-dipole",
        "0,0,1",
        "--com",
        "0,0,0.1",
    )
    want = [ep.torques.Gravity(1.0, [0.0, 0.0, 0.1]), ep.torques.BodyTorque([0.0, 0.0, 0.1]), MAG]
    assert d["torque"] == [t.to_dict() for t in want]
    close_state(d, reference(want))


@pytest.mark.parametrize(
    "extra, match",
    [
        (["--magnetic-dipole", "0,0", "--magnetic-field", "1,0,0"], r"^--magnetic-dipole: expected 3 numbers, got 2"),
        (["--magnetic-dipole", "0,0,x", "--magnetic-field", "1,0,0"], r"^--magnetic-dipole: 'x' is not a number"),
        (["--magnetic-dipole", "0,0,1", "--magnetic-field", "0,nan,0"], r"^--magnetic-field: values must be finite"),
        (
            ["--magnetic-field", "0.2,0,0"],
            r"^--magnetic-field needs the dipole of the magnetic dipole torque: --magnetic-dipole MX,MY,MZ "
            r"or \[torque\] magnetic_dipole$",
        ),
        (["--magnetic-dipole", "0,0,1"], r"^--magnetic-dipole needs the field of .*: --magnetic-field BX,BY,BZ"),
    ],
)
def test_a_bad_magnetic_value_names_the_flag(capsys, extra, match):
    one_error(capsys, ["simulate", *BASE, *extra], match)


@pytest.mark.parametrize(
    "text, match",
    [
        (
            "magnetic_dipole = [0, 0]\nmagnetic_field = [1, 0, 0]\n",
            r"mag\.toml: \[torque\] magnetic_dipole: expected 3",
        ),
        ("magnetic_dipole = 1\nmagnetic_field = [1, 0, 0]\n", r"\[torque\] magnetic_dipole must be a list of numbers"),
        ("magnetic_field = [1, 0, 0]\n", r"mag\.toml: \[torque\] magnetic_field needs the dipole"),
        (
            "magnetic = [1, 0, 0]\n",
            r"unknown key\(s\) magnetic in \[torque\]; known: .*magnetic_dipole, magnetic_field",
        ),
    ],
)
def test_a_bad_magnetic_key_names_the_file_and_key(capsys, tmp_path, text, match):
    cfg = tmp_path / "mag.toml"
    cfg.write_text("[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0, 0]\n[time]\nt_end = 1\n[torque]\n" + text)
    one_error(capsys, ["simulate", str(cfg)], match)


# ---------------------------------------------------------------------------
# every registered torque: its flags in --help, its keys in the schema
# ---------------------------------------------------------------------------
def test_every_registered_torque_has_its_flags_in_simulate_help(capsys):
    text = help_text(capsys)
    with_cli = [cls for cls in TORQUES.values() if cls.cli]
    assert MagneticDipoleTorque in with_cli and len(with_cli) >= 5
    positions = []
    for cls in with_cli:
        for p in cls.cli:
            assert f"{p.flag} {p.metavar}" in text, (cls.__name__, p.flag)
            assert FLAGS[f"torque.{p.toml_key}"] == p.flag
            assert f"{p.toml_key}=[...]" in text if p.kind == "vector3" else re.search(rf"\b{p.toml_key}\b", text)
            positions.append(text.index(f"\n  {p.flag} {p.metavar}"))
    assert positions == sorted(positions)  # in the registry's order, the magnetic flags after the others


def test_flags_keep_their_names_and_metavars(capsys):
    text = help_text(capsys)
    for flag, metavar in [
        ("--com", "CX,CY,CZ"),
        ("--mass", "M"),
        ("--gravity", "GX,GY,GZ"),
        ("--gravity-gradient", "NU"),
        ("--body-torque", "TX,TY,TZ"),
        ("--space-torque", "TX,TY,TZ"),
        ("--magnetic-dipole", "MX,MY,MZ"),
        ("--magnetic-field", "BX,BY,BZ"),
    ]:
        assert f"[{flag} {metavar}]" in text
    flags = [p.flag for _, p in torque_params()]
    assert flags[:6] == ["--com", "--mass", "--gravity", "--gravity-gradient", "--body-torque", "--space-torque"]
    assert flags[6:8] == ["--magnetic-dipole", "--magnetic-field"]


def test_build_torques_takes_flags_text_and_toml_values():
    from_flags = build_torques({"torque.magnetic_dipole": "0,0,1", "torque.magnetic_field": "0.2,0,0"})
    from_toml = build_torques({"torque.magnetic_dipole": [0, 0, 1], "torque.magnetic_field": [0.2, 0.0, 0.0]})
    assert [t.to_dict() for t in from_flags] == [t.to_dict() for t in from_toml] == [MAG.to_dict()]
    assert build_torques({}) == []


# ---------------------------------------------------------------------------
# a torque registered later (a user's plugin) gets its flag with no CLI edit
# ---------------------------------------------------------------------------
class Spring(Torque):
    """tau = -k e_z x (R^T e_z): a torsion spring that pulls the body's z axis to the space z axis (a test)."""

    kind = "test_cli_spring"
    cli = (
        TorqueParam(
            "stiffness",
            "--test-spring",
            "test_spring",
            "positive",
            help="a test spring K > 0",
            units="N m",
            metavar="K",
        ),
    )

    def __init__(self, stiffness):
        self.stiffness = float(stiffness)

    def evaluate(self, t, R, omega, inertia):
        z_body = np.einsum("...ji,...j->...i", R, np.array([0.0, 0.0, 1.0]))
        return -self.stiffness * np.cross(np.array([0.0, 0.0, 1.0]), z_body)

    def to_dict(self):
        return {"kind": self.kind, "stiffness": self.stiffness}

    def __repr__(self):
        return f"Spring({self.stiffness!r})"


@pytest.fixture
def spring():
    register_torque(Spring)
    try:
        yield Spring
    finally:
        TORQUES.pop(Spring.kind, None)
        sync_torque_keys()
        assert "torque.test_spring" not in FLAGS


def test_a_torque_registered_later_gets_its_flag_and_key(capsys, tmp_path, spring):
    assert "--test-spring K" in help_text(capsys)
    argv = ["simulate", *BASE, "--quaternion", "0.9950041652780258,0.09983341664682815,0,0"]
    d = ok_json(capsys, *argv, "--test-spring", "0.5")
    assert d["torque"] == [{"kind": "test_cli_spring", "stiffness": 0.5}]
    ref = ep.solve(
        [1.0, 2.0, 3.0],
        np.linspace(0.0, 1.0, 3),
        omega0=[1.0, 0.1, 0.5],
        attitude0=[0.9950041652780258, 0.09983341664682815, 0.0, 0.0],
        torque=Spring(0.5),
        method="rk",
    )
    close_state(d, ref)
    cfg = tmp_path / "spring.toml"
    cfg.write_text(
        "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n[time]\nt_end = 1\nsamples = 3\n"
        '[method]\nname = "rk"\n[torque]\ntest_spring = 0.5\n'
    )
    assert ok_json(capsys, "simulate", str(cfg))["torque"] == d["torque"]
    one_error(capsys, [*argv, "--test-spring", "0"], r"^--test-spring must be a finite number > 0, got '0'$")
