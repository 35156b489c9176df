"""Torques on the command line and in files: flags, the [torque] TOML section, NetCDF and Zarr records,
the ``apex`` picture, the heavy-top scene of the demo, and the examples of ``simulate --help`` (run, with every
other help example, by tests/test_issue12_help_examples.py).

Each CLI test runs in-process through ``eulerpoisson.cli.main(argv)``.
"""

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.cli import commands as cli
from eulerpoisson.cli import main

ROOT = Path(__file__).resolve().parents[1]

TOP = ["--inertia", "1,1,0.5", "--omega", "0,0,10", "--gibbs", "0.5773502691896257,0,0"]
TOP_BODY = ep.RigidBody([1.0, 1.0, 0.5])
Q60 = [np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0, 0.0]  # 60 degrees about x = Gibbs (tan 30 deg, 0, 0)


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
    """Exit status 2, one stderr line matching ``match``, no traceback, nothing on stdout."""
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2, (code, out, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert lines[0].startswith("eulerpoisson: error: "), lines[0]  # every error line starts the same way
    msg = lines[0][len("eulerpoisson: error: ") :]
    assert re.search(match, lines[0]) or re.search(match, msg), lines[0]
    assert out == ""
    return lines[0]


def close_state(d, tr, atol=1e-12):
    np.testing.assert_allclose(d["omega"], tr.omega[-1], atol=atol)
    assert abs(abs(np.dot(d["quaternion"], tr.quaternion[-1])) - 1.0) < atol


# ---------------------------------------------------------------------------
# flags
# ---------------------------------------------------------------------------
def test_heavy_top_flags_json(capsys):
    d = ok_json(
        capsys,
        "simulate",
        *TOP,
        "--com",
        "0,0,0.25",
        "--mass",
        "2",
        "--gravity",
        "0,0,-9.8",
        "--t-end",
        "3",
        "--samples",
        "301",
    )
    assert (
        d["method"] == "exact"
    )  # the default: the most accurate method that runs it (the Lagrange top in closed form)
    assert d["torque"] == [{"kind": "gravity", "mass": 2.0, "center_of_mass": [0.0, 0.0, 0.25], "g": [0.0, 0.0, -9.8]}]
    top = ep.torques.Gravity(2.0, [0, 0, 0.25], g=[0, 0, -9.8])
    ref = ep.solve(TOP_BODY, np.linspace(0, 3, 301), omega0=[0, 0, 10], attitude0=Q60, torque=top, method="taylor")
    close_state(d, ref)
    # the energy includes the potential; the integrals at T and their drift are reported
    assert d["energy"] == pytest.approx(float(ref.energy[-1]), rel=1e-12)
    kinetic = 0.5 * (0.5 * 100.0)
    potential = 2.0 * 9.8 * 0.25 * np.cos(np.pi / 3)  # U = -mu g.(R c): the centre of mass 60 deg from up
    assert d["integrals"]["energy"] == pytest.approx(kinetic + potential, rel=1e-12)
    assert set(d["integrals"]) >= {"energy", "m_vertical", "M3"}
    assert set(d["drift"]) == set(d["integrals"])
    assert max(d["drift"].values()) < 1e-12


def test_com_alone_gives_unit_mass_and_standard_gravity(capsys):
    d = ok_json(capsys, "simulate", *TOP, "--com", "0,0,0.25", "--t-end", "1", "--samples", "11")
    assert d["torque"] == [{"kind": "gravity", "mass": 1.0, "center_of_mass": [0.0, 0.0, 0.25], "g": [0.0, 0.0, -9.81]}]
    d2 = ok_json(
        capsys,
        "simulate",
        *TOP,
        "--com",
        "0,0,0.25",
        "--mass",
        "1",
        "--gravity",
        "0,0,-9.81",
        "--t-end",
        "1",
        "--samples",
        "11",
    )
    assert d2 == d


@pytest.mark.parametrize(
    "flag, value, tq",
    [
        ("--gravity-gradient", "0.3", ep.torques.GravityGradient(0.3)),
        ("--body-torque", "0.1,-0.2,0.3", ep.torques.BodyTorque([0.1, -0.2, 0.3])),
        ("--space-torque", "-0.1,0.2,0.05", ep.torques.SpaceTorque([-0.1, 0.2, 0.05])),
    ],
)
def test_each_torque_flag(capsys, flag, value, tq):
    d = ok_json(
        capsys, "simulate", "--inertia", "1,2,3", "--omega", "0.3,1,0.2", flag, value, "--t-end", "4", "--samples", "41"
    )
    assert d["method"] == "taylor"
    assert d["torque"] == [tq.to_dict()]
    ref = ep.solve([1, 2, 3], np.linspace(0, 4, 41), omega0=[0.3, 1, 0.2], torque=tq, method="taylor")
    close_state(d, ref)
    assert d["energy"] == pytest.approx(float(ref.energy[-1]), rel=1e-12)
    assert set(d["integrals"]) == set(ref.integrals())


def test_torques_add_up_and_other_methods(capsys):
    argv = [
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "0.3,1,0.2",
        "--com",
        "0.1,0,0.2",
        "--body-torque",
        "0,0,0.1",
        "--space-torque",
        "0.1,0,0",
        "--t-end",
        "2",
        "--samples",
        "21",
    ]
    d = ok_json(capsys, *argv)
    assert [r["kind"] for r in d["torque"]] == ["gravity", "body_torque", "space_torque"]
    d_rk = ok_json(capsys, *argv, "--method", "rk", "--tol", "1e-12")
    assert d_rk["method"] == "rk" and d_rk["torque"] == d["torque"]
    np.testing.assert_allclose(d_rk["omega"], d["omega"], atol=1e-8)


def test_free_body_json_has_empty_torque_and_integrals(capsys):
    d = ok_json(capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "2")
    assert d["method"] == "exact" and d["torque"] == []
    assert set(d["integrals"]) == {"energy", "m_x", "m_y", "m_z", "m_norm"}
    np.testing.assert_allclose([d["integrals"][f"m_{c}"] for c in "xyz"], d["m"], atol=1e-13)


def test_text_output_names_the_torque(capsys):
    code, out, err = run(capsys, "simulate", *TOP, "--com", "0,0,0.25", "--t-end", "1", "--samples", "11")
    assert code == 0, err
    assert out.startswith("exact:")  # the Lagrange top: the closed form by default
    assert "torque        Gravity(mass=1.0" in out and "(kinetic + potential)" in out
    assert "m_vertical" in out


def test_method_exact_with_an_unsupported_torque(capsys):
    line = one_error(
        capsys,
        [
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0,0",
            "--gravity-gradient",
            "0.1",
            "--t-end",
            "1",
            "--method",
            "exact",
        ],
        r"method 'exact' cannot run",
    )
    assert line.startswith("eulerpoisson: error:") and "taylor" in line and "rk" in line


def test_method_exact_for_a_lagrange_top_either_way(capsys):
    """The closed form of the Lagrange top where the exact method has it; otherwise its one-line refusal."""
    argv = ["simulate", *TOP, "--com", "0,0,0.25", "--t-end", "2", "--samples", "21", "--method", "exact"]
    top = ep.torques.Gravity(1.0, [0, 0, 0.25])
    try:
        ref = ep.solve(TOP_BODY, np.linspace(0, 2, 21), omega0=[0, 0, 10], attitude0=Q60, torque=top, method="exact")
    except ep.UnsupportedModelError:
        one_error(capsys, argv, r"^eulerpoisson: error: method 'exact' cannot run this model: .*methods that can")
        return
    d = ok_json(capsys, *argv[:-2], "--method", "exact")
    assert d["method"] == "exact"
    close_state(d, ref)
    d_taylor = ok_json(capsys, *argv[:-2])
    np.testing.assert_allclose(d["omega"], d_taylor["omega"], atol=1e-12)


def test_method_exact_with_a_torque_writes_nothing(capsys, tmp_path):
    store = tmp_path / "r.zarr"
    one_error(
        capsys,
        [
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0,0",
            "--body-torque",
            "0,0,1",
            "--t-end",
            "1",
            "--method",
            "exact",
            "--out",
            str(store),
        ],
        r"cannot run",
    )
    assert not store.exists() and os.listdir(tmp_path) == []


BAD = [
    (["--com", "0,0,0.2", "--mass", "0"], r"^--mass must be a finite number > 0"),
    (["--com", "0,0,0.2", "--mass", "-1"], r"^--mass must be a finite number > 0"),
    (["--com", "0,0,0.2", "--mass", "heavy"], r"^--mass: 'heavy' is not a number"),
    (["--com", "0,0,0.2", "--mass", "inf"], r"^--mass must be a finite number > 0"),
    (["--com", "0,0.2"], r"^--com: expected 3 numbers, got 2"),
    (["--com", "0,0,nan"], r"^--com: values must be finite"),
    (["--com", "a,b,c"], r"^--com: 'a' is not a number"),
    (["--com", "0,0,0.2", "--gravity", "0,-9.81"], r"^--gravity: expected 3 numbers"),
    (["--com", "0,0,0.2", "--gravity", "0,0,x"], r"^--gravity: 'x' is not a number"),
    (["--mass", "2"], r"^--mass needs the centre of mass of the heavy top: --com"),
    (["--gravity", "0,0,-1"], r"^--gravity needs the centre of mass of the heavy top: --com"),
    (["--gravity-gradient", "-0.1"], r"^--gravity-gradient must be a finite number >= 0"),
    (["--gravity-gradient", "fast"], r"^--gravity-gradient: 'fast' is not a number"),
    (["--gravity-gradient", "1,2"], r"^--gravity-gradient: '1,2' is not a number"),
    (["--body-torque", "1,2"], r"^--body-torque: expected 3 numbers"),
    (["--body-torque", "1,2,inf"], r"^--body-torque: values must be finite"),
    (["--space-torque", "1,2,3,4"], r"^--space-torque: expected 3 numbers"),
    (["--space-torque", ""], r"^--space-torque: expected 3 numbers"),
]


@pytest.mark.parametrize("extra, match", BAD)
def test_bad_torque_flags_are_one_line(capsys, extra, match):
    one_error(capsys, ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", *extra], match)


def test_negative_values_after_torque_flags(capsys):
    """``--body-torque -1,0,0`` is read as a value, as for --omega."""
    d = ok_json(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0,0",
        "--body-torque",
        "-1,0,0",
        "--space-torque",
        "-0.5,0,0",
        "--t-end",
        "1",
        "--samples",
        "3",
    )
    assert d["torque"][0]["tau"] == [-1.0, 0.0, 0.0] and d["torque"][1]["tau"] == [-0.5, 0.0, 0.0]


# ---------------------------------------------------------------------------
# TOML
# ---------------------------------------------------------------------------
TOP_TOML = (
    "[body]\ninertia = [1.0, 1.0, 0.5]\n[initial]\nomega = [0.0, 0.0, 10.0]\nquaternion = "
    f"[{float(Q60[0])!r}, {float(Q60[1])!r}, 0.0, 0.0]\n[time]\nt_end = 2.0\nsamples = 201\n"
    "[torque]\ngravity = [0.0, 0.0, -9.8]\nmass = 2.0\ncenter_of_mass = [0.0, 0.0, 0.1]\n"
)


def test_toml_torque_section(capsys, tmp_path):
    cfg = tmp_path / "top.toml"
    cfg.write_text(TOP_TOML)
    d = ok_json(capsys, "simulate", str(cfg))
    assert d["method"] == "exact"  # the Lagrange top: the closed form by default
    assert d["torque"] == [{"kind": "gravity", "mass": 2.0, "center_of_mass": [0.0, 0.0, 0.1], "g": [0.0, 0.0, -9.8]}]
    ref = ep.solve(
        TOP_BODY,
        np.linspace(0, 2, 201),
        omega0=[0, 0, 10],
        attitude0=Q60,
        torque=ep.torques.Gravity(2.0, [0, 0, 0.1], g=[0, 0, -9.8]),
        method="taylor",
    )
    close_state(d, ref)
    # flags override the file, key by key
    d2 = ok_json(capsys, "simulate", str(cfg), "--mass", "3", "--com", "0,0,0.2")
    assert d2["torque"] == [{"kind": "gravity", "mass": 3.0, "center_of_mass": [0.0, 0.0, 0.2], "g": [0.0, 0.0, -9.8]}]
    d3 = ok_json(capsys, "simulate", str(cfg), "--method", "rk")
    assert d3["method"] == "rk"


def test_toml_all_torque_keys(capsys, tmp_path):
    cfg = tmp_path / "all.toml"
    cfg.write_text(
        "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [0.3, 1, 0.2]\n[time]\nt_end = 1\nsamples = 11\n"
        "[torque]\ncenter_of_mass = [0, 0, 0.1]\ngravity_gradient = 0.01\nbody_torque = [0, 0, 0.1]\n"
        "space_torque = [0.1, 0, 0]\n"
    )
    d = ok_json(capsys, "simulate", str(cfg))
    assert d["torque"] == [
        {"kind": "gravity", "mass": 1.0, "center_of_mass": [0.0, 0.0, 0.1], "g": [0.0, 0.0, -9.81]},
        {"kind": "gravity_gradient", "mean_motion": 0.01},
        {"kind": "body_torque", "tau": [0.0, 0.0, 0.1]},
        {"kind": "space_torque", "tau": [0.1, 0.0, 0.0]},
    ]


@pytest.mark.parametrize(
    "text, match",
    [
        (
            "[torque]\nmass = 'heavy'\ncenter_of_mass = [0, 0, 1]\n",
            r"top\.toml: \[torque\] mass must be a number, got \"heavy\"",
        ),
        ("[torque]\ncenter_of_mass = 0.1\n", r"\[torque\] center_of_mass must be a list of numbers"),
        ("[torque]\ngravity_gradient = [0.1]\n", r"\[torque\] gravity_gradient must be a number"),
        ("[torque]\nbody_torque = [1, 'a', 3]\n", r"\[torque\] body_torque must be a list of numbers"),
        (
            "[torque]\ncom = [0, 0, 1]\n",
            r"unknown key\(s\) com in \[torque\]; known: body_torque, center_of_mass, gravity",
        ),
        ("[torque]\nmass = 2.0\n", r"top\.toml: \[torque\] mass needs the centre of mass of the heavy top"),
        ("[torque]\ncenter_of_mass = [0, 0]\n", r"top\.toml: \[torque\] center_of_mass: expected 3 numbers"),
        ("[torque]\ncenter_of_mass = [0, 0, 1]\nmass = -2\n", r"\[torque\] mass must be a finite number > 0"),
        ("[torque]\ngravity_gradient = -1\n", r"\[torque\] gravity_gradient must be a finite number >= 0"),
    ],
)
def test_bad_torque_section_is_one_line(capsys, tmp_path, text, match):
    cfg = tmp_path / "top.toml"
    cfg.write_text("[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0, 0]\n[time]\nt_end = 1\n" + text)
    one_error(capsys, ["simulate", str(cfg)], match)


def test_torque_that_is_not_a_table(capsys, tmp_path):
    cfg = tmp_path / "top.toml"
    cfg.write_text("torque = 1\n[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0, 0]\n[time]\nt_end = 1\n")
    one_error(capsys, ["simulate", str(cfg)], r"top\.toml: \[torque\] must be a table")


# ---------------------------------------------------------------------------
# files: NetCDF round trip and info, Zarr streaming, long runs in chunks
# ---------------------------------------------------------------------------
def test_netcdf_round_trip_and_info(capsys, tmp_path):
    path = tmp_path / "top.nc"
    code, out, err = run(
        capsys,
        "simulate",
        *TOP,
        "--com",
        "0,0,0.25",
        "--mass",
        "1.5",
        "--body-torque",
        "0,0,0.01",
        "--t-end",
        "2",
        "--samples",
        "101",
        "--out",
        str(path),
    )
    assert code == 0, err
    tr = ep.Trajectory.from_netcdf(path)
    assert [t.to_dict() for t in tr.model.torques] == [
        {"kind": "gravity", "mass": 1.5, "center_of_mass": [0.0, 0.0, 0.25], "g": [0.0, 0.0, -9.81]},
        {"kind": "body_torque", "tau": [0.0, 0.0, 0.01]},
    ]
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert json.loads(ds.attrs["torque"]) == [t.to_dict() for t in tr.model.torques]
        np.testing.assert_allclose(ds["energy"].values, tr.energy, rtol=1e-14)  # with the potential
    code, out, err = run(capsys, "info", str(path))
    assert code == 0, err
    assert (
        "torque      Gravity(mass=1.5, center_of_mass=[0.0, 0.0, 0.25], g=[0.0, 0.0, -9.81]) + "
        "BodyTorque(tau=[0.0, 0.0, 0.01])" in out
    )
    assert "(kinetic + potential)" in out and "energy" in out
    # a free-body file says so
    free = tmp_path / "free.nc"
    assert run(capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "1", "--out", str(free))[0] == 0
    code, out, err = run(capsys, "info", str(free))
    assert "torque      free body" in out


def test_zarr_streaming_records_the_torque(capsys, tmp_path):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("zarr")
    store = tmp_path / "top.zarr"
    d = ok_json(capsys, "simulate", *TOP, "--com", "0,0,0.25", "--t-end", "2", "--samples", "201", "--out", str(store))
    ds = xr.open_zarr(store)
    assert (
        json.loads(ds.attrs["torque"])
        == d["torque"]
        == [{"kind": "gravity", "mass": 1.0, "center_of_mass": [0.0, 0.0, 0.25], "g": [0.0, 0.0, -9.81]}]
    )
    assert ds.attrs["method"] == "exact" and "under torque" in ds.attrs["title"]
    ref = ep.solve(
        TOP_BODY,
        np.linspace(0, 2, 201),
        omega0=[0, 0, 10],
        attitude0=Q60,
        torque=ep.torques.Gravity(1.0, [0, 0, 0.25]),
        method="taylor",
    )
    np.testing.assert_allclose(ds["omega"].values, ref.omega, atol=1e-12)
    np.testing.assert_allclose(ds["energy"].values, ref.energy, rtol=1e-13)  # with the potential


@pytest.mark.parametrize("method, opts, atol", [("taylor", {}, 1e-12), ("rk", {"tol": 1e-12}, 1e-8)])
def test_solve_to_file_in_chunks_under_time_dependent_torques(tmp_path, method, opts, atol):
    """Chunks continue the motion: a gravity gradient (time dependent) turns the frame of the other torques."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("zarr")
    from eulerpoisson.io.stream import solve_to_file

    torques = [
        ep.torques.GravityGradient(0.7),
        ep.torques.Gravity(1.0, [0.1, 0, 0.2], g=[0.3, 0.1, -9.81]),
        ep.torques.SpaceTorque([0.1, 0.2, 0.3]),
        ep.torques.BodyTorque([0, 0.1, 0]),
    ]
    t = np.linspace(0, 6, 61)
    path = solve_to_file(
        [1, 2, 3],
        (0.0, 6.0, 61),
        tmp_path / "gg.zarr",
        omega0=[0.3, 1, 0.2],
        torque=torques,
        method=method,
        chunk=20,
        progress=False,
        **opts,
    )
    ref = ep.solve([1, 2, 3], t, omega0=[0.3, 1, 0.2], torque=torques, method=method, **opts)
    ds = xr.open_zarr(path)
    np.testing.assert_allclose(ds["omega"].values, ref.omega, atol=atol)
    np.testing.assert_allclose(ds["quaternion"].values, ref.quaternion, atol=atol)
    np.testing.assert_allclose(ds["energy"].values, ref.energy, atol=atol * 10)
    assert json.loads(ds.attrs["torque"]) == [tq.to_dict() for tq in torques]


def test_solve_to_file_callable_torque_in_chunks_and_resume_fingerprint(tmp_path):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("zarr")
    from eulerpoisson.errors import InvalidInputError
    from eulerpoisson.io.stream import partial_store, solve_to_file

    def kick(t, q, omega):
        return np.stack([np.sin(t) + 0 * omega[..., 0], q[..., 1], 0 * omega[..., 2]], -1)

    torques = [ep.torques.GravityGradient(0.5), kick]
    t = np.linspace(0, 4, 41)
    path = solve_to_file(
        [1, 2, 3],
        t,
        tmp_path / "k.zarr",
        omega0=[0.3, 1, 0.2],
        torque=torques,
        method="rk",
        tol=1e-12,
        chunk=15,
        progress=False,
    )
    ref = ep.solve([1, 2, 3], t, omega0=[0.3, 1, 0.2], torque=torques, method="rk", tol=1e-12)
    ds = xr.open_zarr(path)
    np.testing.assert_allclose(ds["omega"].values, ref.omega, atol=1e-8)
    assert json.loads(ds.attrs["torque"])[1]["kind"] == "unrecorded"

    # an interrupted run resumes only with the same torque
    calls = []

    def stop(done, total):
        calls.append(done)
        if len(calls) == 2:
            raise KeyboardInterrupt

    dest = tmp_path / "r.zarr"
    top = ep.torques.Gravity(1.0, [0, 0, 0.2])
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(
            [1, 1, 0.5],
            (0.0, 2.0, 40),
            dest,
            omega0=[0, 0, 10],
            attitude0=Q60,
            torque=top,
            method="taylor",
            chunk=10,
            progress=stop,
        )
    assert Path(partial_store(dest)).exists()
    with pytest.raises(InvalidInputError, match="different arguments"):
        solve_to_file(
            [1, 1, 0.5],
            (0.0, 2.0, 40),
            dest,
            omega0=[0, 0, 10],
            attitude0=Q60,
            torque=ep.torques.Gravity(2.0, [0, 0, 0.2]),
            method="taylor",
            chunk=10,
            progress=False,
            resume=True,
        )
    solve_to_file(
        [1, 1, 0.5],
        (0.0, 2.0, 40),
        dest,
        omega0=[0, 0, 10],
        attitude0=Q60,
        torque=top,
        method="taylor",
        chunk=10,
        progress=False,
        resume=True,
    )
    ref = ep.solve([1, 1, 0.5], np.linspace(0, 2, 40), omega0=[0, 0, 10], attitude0=Q60, torque=top, method="taylor")
    np.testing.assert_allclose(xr.open_zarr(dest)["omega"].values, ref.omega, atol=1e-12)


def test_solve_to_file_refuses_an_unsupported_model_before_writing(tmp_path):
    pytest.importorskip("zarr")
    from eulerpoisson.io.stream import solve_to_file

    with pytest.raises(ep.UnsupportedModelError, match="methods that can"):
        solve_to_file(
            [1, 2, 3],
            (0.0, 1.0, 5),
            tmp_path / "x.zarr",
            omega0=[1, 0, 0],
            torque=ep.torques.GravityGradient(0.1),
            method="exact",
        )
    assert os.listdir(tmp_path) == []


def test_long_simulate_in_chunks_under_a_gravity_gradient(capsys, tmp_path):
    n = cli.CHUNKED_SAMPLES + 1
    path = tmp_path / "long.nc"
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "0.3,1,0.2",
        "--gravity-gradient",
        "0.5",
        "--com",
        "0,0,0.1",
        "--t-end",
        "20",
        "--samples",
        str(n),
        "--out",
        str(path),
        "--json",
    )
    assert code == 0, err
    tr = ep.Trajectory.from_netcdf(path)
    assert len(tr.model.torques) == 2
    ref = ep.solve(
        [1, 2, 3],
        tr.t,
        omega0=[0.3, 1, 0.2],
        method="taylor",
        torque=[ep.torques.Gravity(1.0, [0, 0, 0.1]), ep.torques.GravityGradient(0.5)],
    )
    np.testing.assert_allclose(tr.omega, ref.omega, atol=1e-10)
    assert np.max(np.abs(np.abs(np.sum(tr.quaternion * ref.quaternion, -1)) - 1)) < 1e-12


# ---------------------------------------------------------------------------
# the apex picture
# ---------------------------------------------------------------------------
def test_plot_apex_from_the_command_line(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "top.nc"
    assert (
        run(capsys, "simulate", *TOP, "--com", "0,0,0.25", "--t-end", "3", "--samples", "301", "--out", str(path))[0]
        == 0
    )
    png = tmp_path / "apex.png"
    code, out, err = run(capsys, "plot", str(path), "--kind", "apex", "--out", str(png))
    assert code == 0, err
    assert png.stat().st_size > 5000 and f"wrote {png}" in out
    code, out, err = run(capsys, "plot", str(path), "--kind", "apexx")
    assert code == 2 and "invalid choice" in err


def test_plot_apex_geometry():
    pytest.importorskip("matplotlib")
    from eulerpoisson.viz import plots

    top = ep.torques.Gravity(1.0, [0, 0, 0.25])
    tr = ep.solve(TOP_BODY, np.linspace(0, 3, 301), omega0=[0, 0, 10], attitude0=Q60, torque=top, method="taylor")
    e, what = plots.apex_axis(tr.model)
    np.testing.assert_allclose(e, [0, 0, 1]) and "c/|c|" in what
    fig = plots.plot(tr, "apex")
    ax = fig.axes[0]
    assert "c/|c|" in ax.get_title() and "method: taylor" in ax.get_title()
    # the drawn curve is the horizontal projection of R(t) e_3 (view from above: -g is +z)
    from matplotlib.collections import LineCollection

    lc = [c for c in ax.collections if isinstance(c, LineCollection)][0]
    segs = np.array(lc.get_segments())
    a = tr.matrix[:, :, 2]
    np.testing.assert_allclose(np.hypot(segs[:, 0, 0], segs[:, 0, 1]), np.hypot(a[:-1, 0], a[:-1, 1]), atol=1e-12)
    # the polar angle starts at 60 deg (released at rest: the highest point, a cusp) and nutates below it
    theta = np.degrees(np.arccos(a[:, 2]))
    assert theta[0] == pytest.approx(60.0) and theta.min() > 60.0 - 1e-6 and theta.max() > 65.0
    # a free symmetric body: its symmetry axis; a given axis; a bad axis
    free = ep.solve([2.0, 1.0, 1.0], np.linspace(0, 5, 51), omega0=[1.0, 0.2, 0.0])
    e, what = plots.apex_axis(free.model)
    np.testing.assert_allclose(np.abs(e), [1, 0, 0]) and "symmetry axis 1" in what
    plots.plot_apex(free, axis=[0, 1, 1])
    with pytest.raises(ep.InvalidInputError, match="axis must be three finite numbers"):
        plots.plot_apex(free, axis=[0, 0, 0])


def test_plot_apex_decimates_long_runs():
    pytest.importorskip("matplotlib")
    from eulerpoisson.viz import plots

    n = 100_001
    tr = ep.Trajectory(
        np.linspace(0, 10, n), np.tile([1.0, 0, 0, 0], (n, 1)), np.zeros((n, 3)), ep.RigidBody([1, 1, 0.5])
    )
    fig = plots.plot_apex(tr)
    from matplotlib.collections import LineCollection

    lc = [c for c in fig.axes[0].collections if isinstance(c, LineCollection)][0]
    assert len(lc.get_segments()) <= 40_000


# ---------------------------------------------------------------------------
# the demo's heavy top
# ---------------------------------------------------------------------------
def test_demo_heavy_top_scene(tmp_path):
    pytest.importorskip("matplotlib")
    from eulerpoisson.cli.demo import run_top

    lines = []
    files = run_top(tmp_path, say=lines.append, t_end=3.0, samples=301)
    assert [f.name for f in files] == ["top.nc", "top_apex.png"] and all(f.exists() for f in files)
    text = "\n".join(lines)
    assert "heavy top" in text and "nutates between 60.00" in text
    assert re.search(r"energy \d\.\de-1[3-9]", text) and "vertical momentum" in text
    assert "closed form (exact)" in text  # run beside taylor, or the reason it was not
    tr = ep.Trajectory.from_netcdf(files[0])
    assert tr.method == "taylor" and tr.model.lagrange_top() is not None


def test_gallery_image_exists():
    p = ROOT / "docs" / "gallery" / "top_apex.png"
    assert p.exists() and p.stat().st_size > 10_000


# ---------------------------------------------------------------------------
# the examples of `simulate --help` and `plot --help`: run, with every other help example, by
# tests/test_issue12_help_examples.py, which checks their files (top.nc a Lagrange top, top_apex.png, apex.png)
# ---------------------------------------------------------------------------
def test_simulate_and_plot_help_show_the_torque_examples():
    from test_issue12_help_examples import EXAMPLES

    sim, plot = EXAMPLES["simulate"], EXAMPLES["plot"]
    assert any("--com" in c for c in sim) and any("--gravity-gradient" in c for c in sim)
    assert any("apex" in c for c in sim + plot)
    assert len(sim) + len(plot) >= 8
