"""The command line: simulate, info, errors (one line, exit status 2)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_simulate_json_keys_and_values(capsys):
    code, out, err = run(capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "10", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert set(d) >= {"t", "quaternion", "omega", "gibbs", "m", "energy", "method", "drift"}
    assert d["t"] == 10.0 and d["method"] == "exact"
    tr = ep.solve([1, 2, 3], [0.0, 10.0], omega0=[1, 0.1, 0.5])
    np.testing.assert_allclose(d["omega"], tr.omega[-1], atol=1e-13)
    np.testing.assert_allclose(np.abs(np.dot(d["quaternion"], tr.quaternion[-1])), 1.0, atol=1e-13)
    q = np.array(d["quaternion"])
    np.testing.assert_allclose(d["gibbs"], q[1:] / q[0], rtol=1e-14)
    np.testing.assert_allclose(d["energy"], 0.5 * (1 + 2 * 0.01 + 3 * 0.25), rtol=1e-14)
    assert max(d["drift"].values()) < 1e-13


def test_simulate_full_tensor_gibbs_and_m(capsys):
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "2,0.1,0,0.1,3,0,0,0,4",
        "--m",
        "0.5,1,0.2",
        "--gibbs",
        "0.1,0.2,0.3",
        "--t-end",
        "3",
        "--json",
    )
    assert code == 0, err
    d = json.loads(out)
    np.testing.assert_allclose(d["m"], [0.5, 1.0, 0.2], atol=1e-13)


def test_simulate_writes_netcdf_and_info(capsys, tmp_path):
    path = tmp_path / "run.nc"
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "3,5,8",
        "--omega",
        "0,0.4,0.001",
        "--t-end",
        "20",
        "--samples",
        "50",
        "--out",
        str(path),
    )
    assert code == 0, err
    assert path.exists() and "wrote" in out
    code, out, err = run(capsys, "info", str(path))
    assert code == 0, err
    assert "samples     50" in out and "exact" in out


def test_simulate_toml_and_flag_override(capsys, tmp_path):
    cfg = tmp_path / "run.toml"
    cfg.write_text(
        '[body]\nmasses = [1.0, 2.0, 3.0, 1.0]\npositions = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nname = "tetra"\n'
        "[initial]\nomega = [0.3, 1.0, -0.2]\n[time]\nt_end = 5.0\nsamples = 11\n"
    )
    code, out, err = run(capsys, "simulate", str(cfg), "--json")
    assert code == 0, err
    assert json.loads(out)["t"] == 5.0
    code, out, err = run(capsys, "simulate", str(cfg), "--t-end", "2", "--json")
    assert json.loads(out)["t"] == 2.0


@pytest.mark.parametrize(
    "argv, match",
    [
        (["simulate", "--inertia", "1,2,x", "--omega", "1,0,0", "--t-end", "1"], "'x' is not a number"),
        (["simulate", "--inertia", "1,2", "--omega", "1,0,0", "--t-end", "1"], "expected 3 or 9 numbers"),
        (["simulate", "--inertia", "1,1,3", "--omega", "1,0,0", "--t-end", "1"], "triangle inequality"),
        (["simulate", "--inertia", "1,2,3,4,5,6,7,8,9", "--omega", "1,0,0", "--t-end", "1"], "not symmetric"),
        (
            ["simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--quaternion", "1,1,0,0", "--t-end", "1"],
            "unit quaternion",
        ),
        (["simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "inf"], "t-end must be a finite number"),
        (["simulate", "--inertia", "1,2,3", "--omega", "1,0,nan", "--t-end", "1"], "finite"),
        (
            ["simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "1", "--method", "magic"],
            "unknown method 'magic'",
        ),
        (["simulate", "--inertia", "1,2,3", "--t-end", "1"], "exactly one initial condition"),
        (["simulate", "--inertia", "1,2,3", "--omega", "1,0,0"], "--t-end"),
        (
            ["simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "1", "--samples", "1"],
            "samples must be an integer >= 2",
        ),
        (["simulate", "--bogus"], "unrecognized arguments: --bogus"),
        (["simulate", "missing.toml"], "does not exist"),
        (["info", "missing.nc"], "no such file"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_errors_are_one_line_exit_2(capsys, argv, match):
    code, out, err = run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    import re

    assert re.search(match, lines[0]), lines[0]


def test_bad_toml(capsys, tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[body\ninertia = 1")
    code, out, err = run(capsys, "simulate", str(cfg))
    assert code == 2 and "invalid TOML" in err
    cfg.write_text("[body]\ninertia=[1,2,3]\ncolour='red'\n")
    code, out, err = run(capsys, "simulate", str(cfg))
    assert code == 2 and "unknown key(s) colour in [body]" in err


def test_corrupt_file_is_one_line(capsys, tmp_path):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"\x89HDF garbage")
    code, out, err = run(capsys, "info", str(bad))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "not a readable NetCDF" in err


def test_version_and_help(capsys):
    code, out, err = run(capsys, "--version")
    assert code == 0 and ep.__version__ in out
    code, out, err = run(capsys, "simulate", "--help")
    assert code == 0 and "examples:" in out


def test_console_script_entry_point(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "eulerpoisson")
    res = subprocess.run(
        [exe, "simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "nan"],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
    )
    assert res.returncode == 2
    assert len(res.stderr.strip().splitlines()) == 1


def test_sweep_and_atlas_plot(capsys, tmp_path):
    cfg = tmp_path / "s.toml"
    cfg.write_text(
        "[sweep]\nkind = 'grid'\n[inertia]\nI1 = 1.0\nI2 = 2.0\nI3 = 3.0\n"
        "[momentum]\npolar = {start = 10.0, stop = 170.0, num = 5}\nazimuth = {start = 0.0, stop = 90.0, num = 4}\n"
        "degrees = true\n[output]\npath = 'x.zarr'\nchunk = 8\n[compute]\nT = 5.0\nscheduler = 'serial'\n"
    )
    store = tmp_path / "atlas.zarr"
    code, out, err = run(capsys, "sweep", str(cfg), "--out", str(store))
    assert code == 0, err
    from eulerpoisson.sweep import load_sweep

    ds = load_sweep(store)
    assert ds["half_period"].size == 20
    code, out, err = run(capsys, "plot", str(store), "--kind", "atlas", "--out", str(tmp_path / "a.png"))
    assert code == 0, err
    assert (tmp_path / "a.png").stat().st_size > 1000
    code, out, err = run(capsys, "sweep", str(tmp_path / "none.toml"))
    assert code == 2 and "does not exist" in err


def test_simulate_streams_to_zarr(capsys, tmp_path):
    store = tmp_path / "r.zarr"
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "10",
        "--samples",
        "1001",
        "--out",
        str(store),
        "--json",
    )
    assert code == 0, err
    import xarray as xr

    ds = xr.open_zarr(store)
    assert ds["quaternion"].shape == (1001, 4)
    last = json.loads(out)
    np.testing.assert_allclose(ds["omega"].values[-1], last["omega"], atol=1e-15)
    code, out, err = run(
        capsys, "simulate", "--inertia", "1,2,3", "--omega", "1,0,0", "--t-end", "1", "--out", str(tmp_path / "r.txt")
    )
    assert code == 2 and ".nc (NetCDF) or .zarr" in err


def test_long_simulate_works_in_chunks(capsys, tmp_path):
    from eulerpoisson.cli.commands import CHUNKED_SAMPLES

    n = CHUNKED_SAMPLES + 1
    path = tmp_path / "long.nc"
    code, out, err = run(
        capsys,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "50",
        "--samples",
        str(n),
        "--method",
        "taylor",
        "--out",
        str(path),
        "--json",
    )
    assert code == 0, err
    assert err == ""  # no progress bar without a terminal
    tr = ep.Trajectory.from_netcdf(path)
    assert tr.t.size == n
    same = ep.solve([1, 2, 3], np.linspace(0.0, 50.0, n), omega0=[1, 0.1, 0.5], method="taylor")
    assert np.array_equal(tr.omega, same.omega)  # the engine's segments in every route: the bits of ep.solve
    ref = ep.solve([1, 2, 3], tr.t, omega0=[1, 0.1, 0.5])
    np.testing.assert_allclose(tr.omega, ref.omega, atol=1e-12)
    assert np.max(np.abs(np.abs(np.sum(tr.quaternion * ref.quaternion, -1)) - 1)) < 1e-13
