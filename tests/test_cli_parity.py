"""The command line says what the API can (issue: files, long runs and the command line made whole)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_allow_unphysical_flag_and_toml_key(capsys, tmp_path):
    code, out, err = run(capsys, "simulate", "--inertia", "3,5,9", "--omega", "0,0.4,0.001", "--t-end", "1")
    assert code == 2 and "allow_unphysical" in err or "triangle" in err
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "3,5,9",
        "--omega",
        "0,0.4,0.001",
        "--t-end",
        "1",
        "--allow-unphysical",
        "--json",
    )
    assert code == 0 and '"t": 1.0' in out
    cfg = tmp_path / "r.toml"
    cfg.write_text(
        "[body]\ninertia = [3, 5, 9]\nallow_unphysical = true\n[initial]\nomega = [0, 0.4, 0.001]\n"
        "[time]\nt_end = 1.0\n"
    )
    code, out, err = run(capsys, "simulate", str(cfg), "--json")
    assert code == 0, err


def test_negative_t_end_runs_backwards(capsys):
    import json

    code, out, err = run(
        capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "-5", "--samples", "11", "--json"
    )
    assert code == 0, err
    state = json.loads(out)
    ref = ep.solve([1, 2, 3], [-5.0], omega0=[1, 0.1, 0.5])
    assert state["t"] == -5.0
    np.testing.assert_allclose(state["quaternion"], ref.quaternion[-1], atol=1e-15)


def test_every_method_option_is_a_flag(capsys):
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "2",
        "--method",
        "rk",
        "--integrator",
        "RK45",
        "--rtol",
        "1e-9",
        "--atol",
        "1e-12",
        "--json",
    )
    assert code == 0, err
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "2",
        "--method",
        "taylor",
        "--order",
        "12",
        "--max-steps",
        "100000",
        "--json",
    )
    assert code == 0, err
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "2",
        "--method",
        "taylor",
        "--integrator",
        "RK45",
    )
    assert code == 2 and err.strip().endswith(
        "--integrator is not an option of method 'taylor' "
        "(its options: --chart-threshold, --dps, --dt, --max-steps, --order, --precision, --tol)"
    )


def test_toml_output_file_is_relative_to_the_file(capsys, tmp_path, monkeypatch):
    sub = tmp_path / "cfg"
    sub.mkdir()
    (sub / "r.toml").write_text(
        "[body]\ninertia = [1, 2, 3]\n[initial]\nomega = [1, 0.1, 0.5]\n"
        '[time]\nt_end = 1.0\nsamples = 3\n[output]\nfile = "out.nc"\n'
    )
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "simulate", "cfg/r.toml", "--quiet")
    assert code == 0, err
    assert (sub / "out.nc").exists() and not (tmp_path / "out.nc").exists()


def test_numbers_must_be_ascii_and_nesting_is_bounded(capsys, tmp_path):
    code, out, err = run(capsys, "simulate", "--inertia", "\uff11,2,3", "--omega", "1,0,0", "--t-end", "1")
    assert code == 2 and "is not a number written in ASCII digits" in err
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    code, out, err = run(capsys, "simulate", str(deep))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "deep.toml" in err


def test_a_closed_pipe_is_not_an_error(tmp_path):
    exe = str(Path(sys.executable).with_name("eulerpoisson"))
    cmd = (
        f"{exe} simulate --inertia 1,2,3 --omega 1,0.1,0.5 --t-end 10 --samples 200000 --method exact --json "
        f"| head -c 10"
    )
    res = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert "Broken pipe" not in res.stderr, res.stderr
    assert res.returncode == 0, res.stderr


def test_overflow_and_masked_or_boolean_input_are_errors():
    with pytest.raises(ep.InvalidInputError, match="inverse_conversion_matrix overflows float64"):
        ep.attitude.inverse_conversion_matrix([1e308, 0, 0])
    with pytest.raises(ep.InvalidInputError, match="quaternion_multiply overflows float64"):
        ep.attitude.quaternion_multiply([1e308, 0, 0, 0], [1e308, 0, 0, 0])
    with pytest.raises(ep.InvalidInputError, match="energy overflows float64"):
        ep.RigidBody([1, 2, 3]).energy([1e308, 0, 0])
    with pytest.raises(TypeError, match="masked array; its mask would be ignored"):
        ep.RigidBody(np.ma.masked_array([1.0, 2.0, 3.0], [0, 1, 0]))
    with pytest.raises(TypeError, match="inertia must be a real numeric array, got dtype bool"):
        ep.RigidBody(np.array([True, True, True]))


def test_absurd_and_too_large_sample_counts_are_named_before_allocating(capsys):
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0,0",
        "--t-end",
        "1",
        "--samples",
        "99999999999999999999999",
    )
    assert code == 2 and "--samples = 99999999999999999999999 is more than 1e+13 output times" in err
    code, out, err = run(
        capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "1", "--samples", "1000000000000"
    )
    assert code == 2 and "GiB in memory" in err and "--out run.zarr" in err


def test_a_file_with_non_unit_quaternions_is_refused(tmp_path):
    xr = pytest.importorskip("xarray")
    tr = ep.solve([1, 2, 3], [0.0, 1.0], omega0=[1, 0.1, 0.5])
    tr.to_netcdf(tmp_path / "a.nc")
    ds = xr.open_dataset(tmp_path / "a.nc", engine="h5netcdf").load()
    ds["quaternion"] = ds["quaternion"] * 2.0
    ds.to_netcdf(tmp_path / "b.nc", engine="h5netcdf")
    with pytest.raises(ep.InvalidInputError, match="b.nc: the quaternion variable is not made of unit quaternions"):
        ep.Trajectory.from_netcdf(tmp_path / "b.nc")


def test_a_long_stepping_run_goes_in_segments_with_progress(monkeypatch):
    """A run of few samples but many turns is cut into segments (progress, resumable), the same in every route."""
    from eulerpoisson.cli import simulate as commands
    from eulerpoisson.solvers import engine

    monkeypatch.setattr(engine, "SEGMENT_TURNS", 100.0)
    t = np.linspace(0.0, 1e4, 5)
    model = ep.Model([1, 2, 3])
    tr = commands.solve_run(model, 1e4, 5, np.array([1.0, 0.1, 0.5]), None, None, "taylor", {}, False)
    assert tr.stats["segments"] == 4
    same = ep.solve([1, 2, 3], t, omega0=[1, 0.1, 0.5], method="taylor")  # the same segments: the same bits
    assert np.array_equal(tr.quaternion, same.quaternion) and np.array_equal(tr.omega, same.omega)
    ref = ep.solve([1, 2, 3], t, omega0=[1, 0.1, 0.5])
    assert np.max(np.abs(tr.quaternion - ref.quaternion)) < 1e-8


def test_a_run_written_nowhere_keeps_its_ends_and_the_same_drift():
    from eulerpoisson.cli import simulate as commands

    model = ep.Model([1, 2, 3])
    w0 = np.array([1.0, 0.1, 0.5])
    full = commands.solve_run(model, 50.0, 12001, w0, None, None, "taylor", {}, False)
    ends, drift = commands.solve_run(model, 50.0, 12001, w0, None, None, "taylor", {}, False, keep=False)
    assert ends.t.tolist() == [0.0, 50.0]
    np.testing.assert_array_equal(ends.quaternion[-1], full.quaternion[-1])
    assert drift == full.drift()


def test_atlas_of_a_trajectory_says_it_needs_a_sweep_store(capsys, tmp_path):
    nc = tmp_path / "run.nc"
    ep.solve([1, 2, 3], [0.0, 1.0], omega0=[1, 0, 0]).to_netcdf(nc)
    code, out, err = run(capsys, "plot", str(nc), "--kind", "atlas", "--out", str(tmp_path / "a.png"))
    assert code == 2 and "--kind atlas draws a sweep store" in err


def test_a_file_whose_times_are_all_equal_is_refused(tmp_path):
    xr = pytest.importorskip("xarray")
    ep.solve([1, 2, 3], [0.0, 1.0, 2.0], omega0=[1, 0.1, 0.5]).to_netcdf(tmp_path / "a.nc")
    ds = xr.open_dataset(tmp_path / "a.nc", engine="h5netcdf").load()
    ds = ds.assign_coords(time=np.zeros(3))
    ds.to_netcdf(tmp_path / "b.nc", engine="h5netcdf")
    with pytest.raises(ep.InvalidInputError, match="b.nc: the time variable holds the same value 0.0 for all 3"):
        ep.Trajectory.from_netcdf(tmp_path / "b.nc")
