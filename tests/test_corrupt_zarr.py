"""A corrupt chunk of a Zarr store is the user's data problem, not a bug: an input error (CLI exit 2).

A chunk whose bytes the codecs cannot decode (garbage, a truncated or empty
file, a frame that decodes to the wrong number of values) raises
``EulerPoissonError("STORE is not a readable Zarr store: chunk omega/c/3/0 is
corrupt (...)")``, as a corrupt NetCDF file raises "is not a readable NetCDF
file"; ``info``, ``plot`` and ``animate`` print that one line and exit 2.
"""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("zarr")
numcodecs_zstd = pytest.importorskip("numcodecs.zstd")

import eulerpoisson as ep  # noqa: E402
from _limits import HANG_GUARD_S  # noqa: E402
from eulerpoisson.cli.commands import main  # noqa: E402
from eulerpoisson.errors import EulerPoissonError  # noqa: E402
from eulerpoisson.io.read import LazyTrajectory  # noqa: E402
from eulerpoisson.io.stream import solve_to_file  # noqa: E402

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]
T = 95  # samples; chunks of 10: omega/c/0/0 ... omega/c/9/0, time/c/0 ... time/c/9


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    d = tmp_path_factory.mktemp("corrupt")
    path = d / "run.zarr"
    solve_to_file(ep.RigidBody(I, name="probe"), (0.0, 20.0, T), path, omega0=W0, chunk=10, progress=False)
    return path


def _copy(store, tmp_path, name="bad.zarr"):
    out = tmp_path / name
    shutil.copytree(store, out)
    return out


def _garbage(raw):
    return b"garbage\n"


def _truncated(raw):
    return raw[: len(raw) // 2]


def _empty(raw):
    return b""


def _short_frame(raw):  # a valid Zstandard frame of 3 values where a chunk holds 30
    return bytes(numcodecs_zstd.Zstd().encode(np.zeros(3).tobytes()))


@pytest.mark.parametrize(
    "damage, reason",
    [
        (_garbage, "Zstd decompression error"),
        (_truncated, "Zstd decompression error"),
        (_empty, "Zstd decompression error"),
        (_short_frame, "cannot reshape array"),
    ],
)
def test_corrupt_middle_chunk_is_an_input_error_naming_the_chunk(store, tmp_path, damage, reason):
    bad = _copy(store, tmp_path)
    chunk = bad / "omega" / "c" / "3" / "0"
    assert chunk.is_file()  # the layout named in the message is the layout on disk
    chunk.write_bytes(damage(chunk.read_bytes()))
    lazy = ep.Trajectory.open(bad)  # the first and last chunks are fine: it opens
    assert isinstance(lazy, LazyTrajectory)
    np.testing.assert_array_equal(lazy[:30].omega, LazyTrajectory(store)[:30].omega)  # chunks 0-2 still read
    with pytest.raises(
        EulerPoissonError, match=rf"bad\.zarr is not a readable Zarr store: chunk omega/c/3/0 is corrupt \({reason}"
    ):
        lazy.load()
    with pytest.raises(EulerPoissonError, match=r"chunk omega/c/3/0 is corrupt"):
        lazy[35]
    with pytest.raises(EulerPoissonError, match=r"bad\.zarr is not a readable Zarr store: a chunk of variable omega"):
        np.asarray(lazy.omega)  # through zarr itself: the chunk is not known, the variable is


def test_corrupt_first_chunk_refuses_to_open(store, tmp_path):
    bad = _copy(store, tmp_path)
    (bad / "time" / "c" / "0").write_bytes(b"garbage\n")
    with pytest.raises(EulerPoissonError, match=r"bad\.zarr is not a readable Zarr store: chunk time/c/0 is corrupt"):
        ep.Trajectory.open(bad)


def test_corrupt_inertia_names_the_variable(store, tmp_path):
    bad = _copy(store, tmp_path)
    (bad / "inertia" / "c" / "0" / "0").write_bytes(b"garbage\n")
    with pytest.raises(EulerPoissonError, match=r"not a readable Zarr store: a chunk of variable inertia is corrupt"):
        LazyTrajectory(bad)


def test_other_damage_keeps_its_own_message(store, tmp_path):
    """Narrow: a missing chunk file is the fill value, not a corrupt chunk; in a finished store (not an unfinished
    run's work folder) it is data lost, not a run to resume."""
    bad = _copy(store, tmp_path)
    (bad / "omega" / "c" / "3" / "0").unlink()
    lazy = LazyTrajectory(bad)
    with pytest.raises(EulerPoissonError, match=r"samples 0:95 are missing \(NaN\) in a finished store") as info:
        lazy.load()
    assert "corrupt" not in str(info.value) and "resume" not in str(info.value)
    with pytest.raises(EulerPoissonError, match=r"samples 0:95 of omega are missing \(NaN\) in a finished store"):
        lazy.read_arrays(["omega"])
    partial = tmp_path / ".run.zarr.partial"  # an unfinished run's work folder: resume it
    bad.rename(partial)
    with pytest.raises(EulerPoissonError, match=r"not all written yet \(NaN\): the run is unfinished; resume it"):
        LazyTrajectory(partial).load()


def test_intact_store_reads_as_before(store):
    lazy = LazyTrajectory(store)
    tr = ep.solve(ep.RigidBody(I, name="probe"), np.asarray(lazy.t), omega0=W0)
    np.testing.assert_allclose(lazy.load().omega, tr.omega, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "argv",
    [["info", "{}"], ["plot", "{}", "--kind", "omega", "--out", "{d}/p.png"], ["animate", "{}", "--out", "{d}/a.html"]],
)
def test_cli_exit_2_with_one_line(store, tmp_path, capsys, argv):
    if argv[0] != "info":
        pytest.importorskip("matplotlib")
    bad = _copy(store, tmp_path)
    (bad / "omega" / "c" / "0" / "0").write_bytes(b"garbage\n")
    code = main([a.format(str(bad), d=tmp_path) for a in argv])
    out, err = capsys.readouterr()
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("eulerpoisson: error: ") and str(bad) in err
    assert "not a readable Zarr store: chunk omega/c/0/0 is corrupt" in err
    assert not (tmp_path / "p.png").exists() and not (tmp_path / "a.html").exists()


def test_console_script_exit_2(store, tmp_path):
    bad = _copy(store, tmp_path)
    (bad / "omega" / "c" / "0" / "0").write_bytes(b"garbage\n")
    exe = os.path.join(os.path.dirname(sys.executable), "eulerpoisson")
    res = subprocess.run([exe, "info", str(bad)], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert res.returncode == 2, res.stderr
    assert res.stderr.count("\n") == 1 and "internal error" not in res.stderr and "Traceback" not in res.stderr
    assert "chunk omega/c/0/0 is corrupt" in res.stderr
