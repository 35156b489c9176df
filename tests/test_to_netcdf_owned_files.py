"""Trajectory.to_netcdf replaces a NetCDF file, never a file of another kind, a folder or a store."""

import os

import pytest

import eulerpoisson as ep
from eulerpoisson.errors import InvalidInputError, OutputError

pytest.importorskip("h5netcdf")


@pytest.fixture(scope="module")
def traj():
    return ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5])


def test_a_netcdf_file_is_replaced(tmp_path, traj):
    path = tmp_path / "run.nc"
    traj.to_netcdf(path)
    other = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 2.0], omega0=[1.0, 0.1, 0.5])
    other.to_netcdf(path)
    assert ep.Trajectory.from_netcdf(path).t.tolist() == [0.0, 1.0, 2.0]


@pytest.mark.parametrize(
    "name, content",
    [("run.toml", b"[body]\ninertia = [1, 2, 3]\n"), ("data.nc", b"t,x\n0,1\n"), ("f.png", b"\x89PNG\r\n\x1a\n")],
)
def test_a_file_of_another_kind_is_kept(tmp_path, traj, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(OutputError, match=f"refusing to replace .*{name}: it is a"):
        traj.to_netcdf(path)
    assert path.read_bytes() == content
    assert sorted(os.listdir(tmp_path)) == [name]  # no temporary left


def test_a_folder_or_a_store_is_kept(tmp_path, traj):
    with pytest.raises(OutputError, match="it is an existing directory"):
        traj.to_netcdf(tmp_path)
    store = tmp_path / "run.zarr"
    from eulerpoisson.io.stream import solve_to_file

    solve_to_file([1.0, 2.0, 3.0], (0.0, 1.0, 3), store, omega0=[1.0, 0.1, 0.5])
    with pytest.raises(OutputError, match="refusing to replace"):
        traj.to_netcdf(store)
    assert ep.Trajectory.open(store).t.shape == (3,)


def test_a_name_that_cannot_be_meant_is_refused(tmp_path, traj):
    with pytest.raises(InvalidInputError, match="only a suffix"):
        traj.to_netcdf(tmp_path / ".nc")


def test_an_empty_file_is_written_over(tmp_path, traj):
    """(tempfile.mkstemp's file, a placeholder: nothing in it to lose; the command line keeps it, its own policy)"""
    import tempfile

    fd, name = tempfile.mkstemp(suffix=".nc", dir=tmp_path)
    os.close(fd)
    traj.to_netcdf(name)
    assert ep.Trajectory.from_netcdf(name).t.tolist() == [0.0, 1.0]
