"""One policy for every output (issue: files, long runs and the command line made whole, items 1-4, 6).

The concurrency and interruption tests run real processes. They never depend on timing: such a process
runs the command line under :data:`LAUNCH`, which holds the run after a chunk of the test's choice until the
test lets it go on or interrupts it.
"""

import json
import os
import shlex
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.cli import main

pytest.importorskip("zarr")
xr = pytest.importorskip("xarray")

EXE = str(Path(sys.executable).with_name("eulerpoisson"))
SIM = ["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "10"]

# The command line as the program runs it, in a process of its own, with two things the test controls:
# - Ctrl-C acts whatever the test's process passes on: a suite started in the background (``make test &``, a CI
#   job) has SIGINT ignored, and an ignored signal stays ignored in every process it starts (POSIX; Python then
#   installs no KeyboardInterrupt handler): the program rightly keeps running, the interrupt never lands;
# - after writing the marker of chunk ``PAUSE`` the run touches ``READY`` and waits until ``GO`` exists (or
#   a Ctrl-C interrupts the wait): the test acts while the run is known to be in the middle, under any load.
LAUNCH = """
import signal, sys, time
from pathlib import Path

signal.signal(signal.SIGINT, signal.default_int_handler)
signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
from eulerpoisson.cli import main
from eulerpoisson.io.resumable import PartialRun

pause, ready, go, exe = int(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]), sys.argv[4]
mark = PartialRun.mark


def mark_then_wait(self, k, info):
    mark(self, k, info)
    if k == pause:
        ready.touch()
        while not go.exists():
            time.sleep(0.05)


PartialRun.mark = mark_then_wait
sys.argv = [exe, *sys.argv[5:]]
sys.exit(main())
"""


@pytest.fixture
def launch(tmp_path):
    """``launch(pause, *argv)``: the program run with ``argv``, held after chunk ``pause`` (see :data:`LAUNCH`),
    and the file GO that lets it go on; a run still going when the test ends is killed."""
    procs = []

    def start(pause, *argv):
        ready, go = tmp_path / "held", tmp_path / "go"
        cmd = [sys.executable, "-c", LAUNCH, str(pause), str(ready), str(go), EXE, *argv]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        procs.append(proc)
        for _ in range(int(HANG_GUARD_S / 0.05)):  # polls: a guard against a hang, not a timing
            if ready.exists() or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert proc.poll() is None and ready.exists(), f"the run did not reach chunk {pause}: {proc.communicate()}"
        return proc, go

    yield start
    for proc in procs:
        if proc.poll() is None:
            proc.kill()
        proc.communicate()


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_existing_outputs_are_replaced_only_with_overwrite_and_keep_their_mode(capsys, tmp_path):
    out = tmp_path / "run.nc"
    assert run(capsys, *SIM, "--out", str(out), "--quiet")[0] == 0
    code, _, err = run(capsys, *SIM, "--out", str(out))
    assert code == 2 and f"{out} exists; run again with --overwrite to replace it" in err
    os.chmod(out, 0o444)
    code, _, err = run(capsys, *SIM, "--samples", "7", "--out", str(out), "--overwrite", "--quiet")
    assert code == 0, err
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o444
    assert len(ep.Trajectory.from_netcdf(out).t) == 7


def test_never_an_input_nor_a_file_of_another_kind(capsys, tmp_path):
    notes = tmp_path / "notes.zarr"
    notes.write_text("my notes")
    code, _, err = run(capsys, *SIM, "--out", str(notes), "--overwrite")
    assert code == 2 and "it is a file, not a Zarr store (a folder) of ours" in err and notes.read_text() == "my notes"
    nc = tmp_path / "run.nc"
    ep.solve([1, 2, 3], [0.0, 1.0], omega0=[1, 0, 0]).to_netcdf(nc)
    code, _, err = run(capsys, "audit", "--out", str(nc), "--overwrite")
    assert code == 2 and "it is a NetCDF file" in err
    cfg = tmp_path / "sweep.toml"
    cfg.write_text((Path(__file__).resolve().parents[1] / "examples" / "sweep.toml").read_text())
    code, _, err = run(capsys, "sweep", str(cfg), "--out", str(cfg), "--overwrite")
    assert code == 2 and "it is an input of this command" in err and "[sweep]" in cfg.read_text()
    store = tmp_path / "t.zarr"
    assert run(capsys, *SIM, "--samples", "50", "--out", str(store), "--quiet")[0] == 0
    code, _, err = run(capsys, "sweep", str(cfg), "--out", str(store), "--overwrite")
    assert code == 2 and "it is a trajectory store" in err and (store / "zarr.json").exists()


def test_json_of_a_streamed_run_is_the_last_sample_of_the_file(capsys, tmp_path):
    store = tmp_path / "r.zarr"
    code, out, err = run(capsys, *SIM, "--samples", "20000", "--method", "rk", "--out", str(store), "--json")
    assert code == 0, err
    state = json.loads(out)
    with xr.open_zarr(store) as ds:
        last = ds["quaternion"].values[-1]
    np.testing.assert_array_equal(state["quaternion"], last)


def test_a_second_writer_to_the_same_store_fails_and_the_first_finishes(tmp_path, launch):
    store = tmp_path / "c.zarr"
    argv = [*SIM, "--t-end", "100", "--samples", "300000", "--out", str(store), "--quiet"]
    first, go = launch(0, *argv)  # held after its first chunk, with the store's lock
    lock = tmp_path / ".c.zarr.lock"
    assert lock.exists(), "the first writer did not take the lock"
    second = subprocess.run([EXE, *argv], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert second.returncode == 2
    assert "is being written by another process" in second.stderr and len(second.stderr.strip().splitlines()) == 1
    go.touch()
    out, err = first.communicate(timeout=HANG_GUARD_S)
    assert first.returncode == 0, err
    with xr.open_zarr(store) as ds:
        assert ds.sizes["time"] == 300_000
        assert np.isfinite(ds["quaternion"].values[-1]).all()
    assert not lock.exists()


def test_an_interrupted_stream_resumes_where_it_stopped(tmp_path, launch):
    store = tmp_path / "r.zarr"
    argv = [*SIM, "--t-end", "200", "--samples", "400000", "--method", "taylor", "--out", str(store)]
    proc, _ = launch(1, *argv)  # held after 2 of its 4 chunks
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=HANG_GUARD_S)
    assert proc.returncode == 130, err
    assert f"run the same command again to resume: {shlex.join(['eulerpoisson', *argv])}" in err
    done = tmp_path / ".r.zarr.partial" / "done"
    assert sorted(p.name for p in done.iterdir() if p.name.isdigit()) == ["000000000", "000000001"]
    assert not store.exists()
    res = subprocess.run([EXE, *argv, "--json"], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert res.returncode == 0, res.stderr
    ref = ep.solve([1, 2, 3], [200.0], omega0=[1, 0.1, 0.5], method="taylor")
    state = json.loads(res.stdout)
    assert np.max(np.abs(np.array(state["quaternion"]) - ref.quaternion[-1])) < 1e-12


def test_stale_temporaries_of_a_killed_writer_are_cleaned_up(capsys, tmp_path):
    out = tmp_path / "x.nc"
    stale = tmp_path / ".x.nc.abcd1234.tmp"
    stale.write_text("half a file")
    assert run(capsys, *SIM, "--out", str(out), "--quiet")[0] == 0
    assert out.exists() and not stale.exists()


def test_resume_after_a_finished_run_finds_it_complete(tmp_path):
    from eulerpoisson.io.stream import solve_to_file

    p = tmp_path / "a.zarr"
    solve_to_file([1, 2, 3], (0.0, 10.0, 1000), p, omega0=[1, 0.1, 0.5], progress=False)
    mtime = (p / "zarr.json").stat().st_mtime_ns
    assert solve_to_file([1, 2, 3], (0.0, 10.0, 1000), p, omega0=[1, 0.1, 0.5], progress=False, resume=True) == p
    assert (p / "zarr.json").stat().st_mtime_ns == mtime
    with pytest.raises(FileExistsError, match="exists; pass overwrite=True"):
        solve_to_file([1, 2, 3], (0.0, 10.0, 1001), p, omega0=[1, 0.1, 0.5], progress=False, resume=True)
