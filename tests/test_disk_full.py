"""A full disk during a NetCDF write: one line naming the file, exit 2, nothing left behind (no crash at exit)."""

import subprocess
import sys
from pathlib import Path

import pytest

from _limits import HANG_GUARD_S

pytest.importorskip("h5netcdf")

EXE = str(Path(sys.executable).with_name("eulerpoisson"))


@pytest.fixture
def small_disk(tmp_path):
    mnt = tmp_path / "small"
    mnt.mkdir()
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=512k", "tmpfs", str(mnt)], capture_output=True, text=True)
    if res.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here (needs root): {res.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


def test_disk_full_during_netcdf_write(small_disk):
    out = small_disk / "x.nc"
    res = subprocess.run(
        [
            EXE,
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0.1,0.5",
            "--t-end",
            "10",
            "--samples",
            "20000",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
    )
    assert res.returncode == 2, (res.returncode, res.stderr)
    # the file, the cause, and what to do
    assert res.stderr.strip().startswith(f"eulerpoisson: error: cannot write {out}: No space left on device")
    assert list(small_disk.iterdir()) == []
