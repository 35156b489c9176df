"""Sweeps, third pass (issue 22): bodies that are not physical, where a sweep file may write, sizes checked up
front, nothing left behind by an unreachable scheduler, and the Ctrl-C message of sweeps and long runs."""

import json
import re
import shlex
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("zarr")
pytest.importorskip("xarray")
pytest.importorskip("distributed")

from eulerpoisson.cli import main  # noqa: E402
from eulerpoisson.errors import EulerPoissonError, InvalidInertiaError, InvalidInputError  # noqa: E402
from eulerpoisson.sweep import (  # noqa: E402
    load_config,
    load_sweep,
    plot_atlas,
    run_sweep,
    runner,
    sweep_summary,
)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_error(capsys, argv, match, code=2):
    got, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert got == code, (got, out, err)
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("eulerpoisson: error: "), lines[0]
    assert re.search(match, lines[0]), lines[0]
    return lines[0]


def sweep_file(folder: Path, *, inertia="I1 = 1.0\nI2 = 2.0\nI3 = 3.0", path="s.zarr", extra="", name="s.toml"):
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    p.write_text(
        f"[inertia]\n{inertia}\n{extra}"
        "[momentum]\npolar = {start = 10.0, stop = 170.0, num = 3}\nazimuth = {start = 0.0, stop = 90.0, num = 2}\n"
        f"[output]\npath = {json.dumps(path)}\nchunk = 2\n[compute]\nT = 2.0\nscheduler = 'serial'\n"
    )
    return p


def config(tmp_path, **inertia):
    return {
        "inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0, **inertia},
        "momentum": {"polar": [20.0, 70.0], "azimuth": 30.0},
        "output": {"path": str(tmp_path / "d.zarr"), "chunk": 1},
        "compute": {"T": 2.0, "scheduler": "serial"},
    }


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".") or p.suffix == ".zarr")


# ---------------------------------------------------------------------------
# item 8: bodies that are not physical
# ---------------------------------------------------------------------------
def test_a_sweep_of_bodies_that_are_not_physical_is_refused(capsys, tmp_path):
    cfg = sweep_file(tmp_path, inertia="I1 = 1.0\nI2 = 2.0\nI3 = 5.0")
    line = one_error(capsys, ["sweep", cfg], r"no body of the sweep is physical")
    assert "I = (1, 2, 5)" in line and "--allow-unphysical" in line and "allow_unphysical=True" not in line
    assert leftovers(tmp_path) == []
    with pytest.raises(InvalidInertiaError, match=r"<dict>: \[inertia\] no body of the sweep is physical"):
        run_sweep(config(tmp_path, I3=5.0), progress=False)
    with pytest.raises(InvalidInertiaError, match="all 2 violate the triangle inequality"):
        load_config(config(tmp_path, I3=[5.0, 6.0]))
    with pytest.raises(InvalidInputError, match=r"\[inertia\] allow_unphysical must be true or false"):
        load_config(config(tmp_path, allow_unphysical="yes"))


def test_allow_unphysical_runs_it_and_says_nothing_was_computed(capsys, tmp_path):
    cfg = sweep_file(tmp_path, inertia="I1 = 1.0\nI2 = 2.0\nI3 = 5.0")
    line = one_error(capsys, ["sweep", cfg, "--allow-unphysical"], r"nothing was computed", code=1)
    assert "all 6 points" in line and "not physical" in line
    assert sweep_summary(tmp_path / "s.zarr")["not a physical body"] == 6
    # the key of the file, and the keyword of run_sweep and load_config, say the same
    keyed = sweep_file(tmp_path / "k", inertia="I1 = 1.0\nI2 = 2.0\nI3 = 5.0\nallow_unphysical = true")
    assert load_config(keyed).allow_unphysical is True
    assert run(capsys, "sweep", keyed, "--quiet")[0] == 1
    ds = load_sweep(run_sweep(config(tmp_path, I3=5.0), allow_unphysical=True, progress=False))
    assert np.isnan(ds["sensitivity"].values).all() and (ds["status"].values == 3).all()
    assert load_config(config(tmp_path, I3=5.0), allow_unphysical=True).allow_unphysical


def test_a_mixed_sweep_runs_and_its_summary_counts_each_status(capsys, tmp_path):
    cfg = sweep_file(tmp_path, inertia="I1 = 1.0\nI2 = 2.0\nI3 = [3.0, 5.0, 2.0]")
    code, out, err = run(capsys, "sweep", cfg)
    assert code == 0, err
    assert out.strip() == (
        f"wrote {tmp_path / 's.zarr'}: 18 points: 6 regular, 6 of a symmetric body (no flips: half-period NaN), "
        "6 not a physical body (NaN)"
    )
    assert sweep_summary(tmp_path / "s.zarr") == {
        "points": 18,
        "regular": 6,
        "separatrix": 0,
        "symmetric body": 6,
        "not a physical body": 6,
        "unfinished": 0,
    }


def test_random_sweeps_are_checked_over_the_box_of_their_axes(tmp_path):
    base = config(tmp_path)
    base.update(sweep={"kind": "random", "samples": 5, "seed": 1})
    base["momentum"] = {"polar": {"start": 0.0, "stop": 90.0}, "azimuth": 0.0}
    base["inertia"] = {"I1": 1.0, "ratio21": {"start": 1.0, "stop": 1.2}, "ratio31": {"start": 2.5, "stop": 3.0}}
    with pytest.raises(InvalidInertiaError, match="the ranges of its axes hold only bodies that violate"):
        load_config(base)
    base["inertia"]["ratio31"] = {"start": 2.1, "stop": 3.0}  # 1 + 1.2 >= 2.1: some bodies are physical
    assert load_config(base).allow_unphysical is False
    base["inertia"] = {"I1": {"start": 1.0, "stop": 2.0}, "I2": [1.0, 2.0], "I3": {"start": 5.0, "stop": 9.0}}
    with pytest.raises(InvalidInertiaError, match=r"I = \(1, 1, 5\)"):
        load_config(base)
    base["inertia"]["I1"] = {"start": 1.0, "stop": 3.0}  # (3, 2, 5) is physical
    load_config(base)


def test_the_atlas_of_a_store_without_values_is_one_line(capsys, tmp_path):
    cfg = sweep_file(tmp_path, inertia="I1 = 1.0\nI2 = 2.0\nI3 = 5.0")
    assert run(capsys, "sweep", cfg, "--allow-unphysical")[0] == 1
    line = one_error(
        capsys, ["plot", tmp_path / "s.zarr", "--kind", "atlas", "--out", tmp_path / "a.png"], r"nothing to draw"
    )
    assert "s.zarr" in line and "6 not a physical body" in line
    assert not (tmp_path / "a.png").exists()
    with pytest.raises(InvalidInputError, match="nothing to draw: half_period has no finite value"):
        plot_atlas(load_sweep(tmp_path / "s.zarr"), tmp_path / "b.png", variables=["half_period"])


def test_the_atlas_of_a_symmetric_body_draws_the_panels_it_can(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    cfg = sweep_file(tmp_path, inertia="I1 = 1.0\nI2 = 3.0\nI3 = 3.0")
    assert run(capsys, "sweep", cfg, "--quiet")[0] == 0
    code, out, err = run(capsys, "plot", tmp_path / "s.zarr", "--kind", "atlas", "--out", tmp_path / "a.png")
    assert code == 0, err
    assert (tmp_path / "a.png").stat().st_size > 1000


# ---------------------------------------------------------------------------
# item 9: where a sweep file may write
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("given", ["../../x.zarr", "../x.zarr", "sub/../../x.zarr", ".", "ABS"])
def test_a_sweep_file_writes_only_inside_its_folder(capsys, tmp_path, given):
    folder = tmp_path / "a" / "b"
    path = str(tmp_path / "x.zarr") if given == "ABS" else given
    cfg = sweep_file(folder, path=path)
    line = one_error(capsys, ["sweep", cfg], r"is outside the folder of the sweep file")
    assert "--out" in line
    assert not (tmp_path / "x.zarr").exists() and not (tmp_path / "a" / "x.zarr").exists()
    with pytest.raises(InvalidInputError, match=r"\[output\] path .* is outside the folder"):
        load_config(cfg)
    # --out on the command line names another place: the file's path is not used
    code, out, err = run(capsys, "sweep", cfg, "--out", tmp_path / "mine.zarr", "--quiet")
    assert code == 0, err
    assert (tmp_path / "mine.zarr").is_dir() and not (tmp_path / "x.zarr").exists()


def test_paths_of_a_sweep_file_resolve_in_its_folder(capsys, tmp_path, monkeypatch):
    folder = tmp_path / "sweeps"
    sweep_file(folder, path="out/s.zarr")
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "sweep", "sweeps/s.toml")
    assert code == 0, err
    assert (folder / "out" / "s.zarr").is_dir() and not (tmp_path / "out").exists()
    assert out.startswith(f"wrote {Path('sweeps', 'out', 's.zarr')}: 6 points")
    # an absolute path inside the folder is the same place
    inside = sweep_file(folder, path=str(folder / "abs.zarr"), name="abs.toml")
    assert load_config(inside).path == str(folder / "abs.zarr")
    # a dictionary (a program's choice) is used as it is
    assert load_config(config(tmp_path)).path == str(tmp_path / "d.zarr")


@pytest.mark.parametrize("out", ["x.nc", "x", "x.zarr.nc", ".zarr", "x\n.zarr"])
def test_the_output_of_a_sweep_is_named_zarr(capsys, tmp_path, out):
    cfg = sweep_file(tmp_path)
    one_error(
        capsys,
        ["sweep", cfg, "--out", tmp_path / out],
        r"a sweep writes a Zarr store|control character|only a suffix|newline",
    )
    assert leftovers(tmp_path) == [] and not (tmp_path / "x.nc").exists()
    bad = sweep_file(tmp_path / "f", path="x.nc")
    one_error(capsys, ["sweep", bad], r"\[output\] path 'x.nc': a sweep writes a Zarr store: name it NAME\.zarr")


# ---------------------------------------------------------------------------
# item 12: sizes checked up front, nothing left behind, the Ctrl-C message
# ---------------------------------------------------------------------------
def test_huge_sweeps_are_refused_before_anything_is_allocated(capsys, tmp_path, monkeypatch):
    cfg = tmp_path / "big.toml"
    body = sweep_file(tmp_path).read_text()
    cfg.write_text(body.replace("num = 3}", "num = 1000000000000}"))
    one_error(capsys, ["sweep", cfg], r"polar\.num = 1000000000000 is more than 1,000,000 values on one axis")
    cfg.write_text(body.replace("num = 3}", "num = 1000000}").replace("num = 2}", "num = 100000}"))
    one_error(capsys, ["sweep", cfg], r"the grid has 1e\+11 points, more than 10,000,000,000")
    rnd = config(tmp_path)
    rnd.update(sweep={"kind": "random", "samples": 10**11})
    rnd["momentum"] = {"polar": {"start": 0.0, "stop": 90.0}, "azimuth": 0.0}
    with pytest.raises(InvalidInputError, match=r"\[sweep\] samples has 1e\+11 points"):
        load_config(rnd)
    rnd["sweep"]["samples"] = 10**8
    monkeypatch.setattr(runner, "_memory_available", lambda: 2.0**30)
    with pytest.raises(InvalidInputError, match=r"samples = 100000000 needs about 8\.94 GiB in memory"):
        run_sweep(rnd, progress=False)
    assert leftovers(tmp_path) == []


def test_an_unreachable_scheduler_leaves_nothing_behind(capsys, tmp_path):
    import dask

    cfg = sweep_file(tmp_path)
    with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
        one_error(capsys, ["sweep", cfg, "--scheduler", "tcp://127.0.0.1:9"], r"cannot connect to the Dask scheduler")
        with pytest.raises(EulerPoissonError, match="cannot connect"):
            run_sweep(cfg, scheduler="tcp://127.0.0.1:9", progress=False)
    assert leftovers(tmp_path) == []


def test_a_failure_before_the_first_chunk_leaves_nothing_behind(tmp_path, monkeypatch):
    def broken(*args):
        raise RuntimeError("a worker failed")

    monkeypatch.setattr(runner, "_compute_chunk", broken)
    with pytest.raises(RuntimeError, match="a worker failed"):
        run_sweep(config(tmp_path), progress=False)
    assert leftovers(tmp_path) == []


def test_ctrl_c_of_a_sweep_names_the_kept_store_and_the_command_that_resumes(capsys, tmp_path, monkeypatch):
    cfg = sweep_file(tmp_path / "in")
    store = tmp_path / "my store.zarr"
    real = runner._compute_chunk
    calls = []

    def interrupted(*args):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(runner, "_compute_chunk", interrupted)
    code, out, err = run(capsys, "sweep", cfg, "--out", store, "--scheduler", "serial", "--overwrite")
    assert code == 130
    kept = tmp_path / ".my store.zarr.partial" / "store.zarr"
    assert f"the finished chunks are kept in {kept}" in err and kept.is_dir() and not store.exists()
    assert "finished chunks of" not in err
    resume = err.split("to resume, run: ", 1)[1].splitlines()[0]
    argv = shlex.split(resume)
    assert argv[:3] == ["eulerpoisson", "sweep", str(cfg)] and "--overwrite" not in argv
    monkeypatch.setattr(runner, "_compute_chunk", real)
    code, out, err = run(capsys, *argv[1:])
    assert code == 0, err
    assert load_sweep(store)["chunk_count"].values.tolist() == [1, 1, 1]  # the first chunk was not recomputed


def test_ctrl_c_of_a_long_run_names_the_hidden_folder_and_the_command(capsys, tmp_path, monkeypatch):
    from eulerpoisson.io import stream

    real = stream.solve_to_file

    def interrupted(*args, **kwargs):
        seen = []

        def progress(done, total):
            seen.append(done)
            if done > 0:
                raise KeyboardInterrupt

        kwargs["progress"] = progress
        return real(*args, **kwargs)

    out = tmp_path / "long.zarr"
    argv = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "50", "--samples", "200000"]
    argv += ["--out", str(out), "--quiet"]
    monkeypatch.setattr(stream, "solve_to_file", interrupted)
    code, _, err = run(capsys, *argv)
    assert code == 130
    kept = tmp_path / ".long.zarr.partial" / "store.zarr"
    assert f"the finished chunks are kept in {kept}" in err and kept.is_dir()
    assert "the finished chunks of" not in err and "run the same command again to resume" in err
    # run as the program, the message gives the command line (without --overwrite, which would start afresh)
    monkeypatch.setattr(sys, "argv", ["/usr/bin/eulerpoisson", *argv, "--overwrite"])
    code, _, err = run(capsys, *argv, "--overwrite")
    assert code == 130
    resume = err.split("run the same command again without --overwrite to resume: ", 1)[1].splitlines()[0]
    assert shlex.split(resume) == ["eulerpoisson", *argv]
    monkeypatch.setattr(stream, "solve_to_file", real)
    assert run(capsys, *shlex.split(resume)[1:])[0] == 0
    assert out.is_dir() and not kept.exists()
