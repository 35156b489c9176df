"""Everything we write, we read (issue 12, item 5): NetCDF-4, NetCDF-3 and the .zarr stores of 'simulate'.

``Trajectory.open`` dispatches on the content of the file; a Zarr store is a
``LazyTrajectory`` that reads its metadata when opened and its samples on
demand; ``info``, ``plot`` and ``animate`` read all three formats (a store
used to be refused: "is a directory, not a trajectory file").
"""

import json
import shutil

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("zarr")
pytest.importorskip("scipy.io")

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.cli.commands import main  # noqa: E402
from eulerpoisson.errors import EulerPoissonError, InvalidInputError  # noqa: E402
from eulerpoisson.io.read import LazyTrajectory, StoredArray, file_format, open_trajectory  # noqa: E402
from eulerpoisson.io.stream import solve_to_file  # noqa: E402
from eulerpoisson.trajectory import Trajectory  # noqa: E402

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("formats")
    t = np.linspace(0.0, 20.0, 95)
    tr = ep.solve(ep.RigidBody(I, name="probe"), t, omega0=W0)
    nc4 = d / "run.nc"
    tr.to_netcdf(nc4)
    nc3 = d / "run3.nc"
    tr.to_xarray().to_netcdf(nc3, engine="scipy", format="NETCDF3_64BIT")
    store = d / "run.zarr"
    solve_to_file(ep.RigidBody(I, name="probe"), (0.0, 20.0, 95), store, omega0=W0, chunk=10, progress=False)
    return tr, nc4, nc3, store


def test_file_format_by_content(files, tmp_path):
    _, nc4, nc3, store = files
    assert (file_format(nc4), file_format(nc3), file_format(store)) == ("netcdf4", "netcdf3", "zarr")
    odd = tmp_path / "run.zarr.nc"  # the name does not matter, the content does
    shutil.copy(nc3, odd)
    assert file_format(odd) == "netcdf3"
    (tmp_path / "junk.nc").write_bytes(b"not a netcdf file at all")
    assert file_format(tmp_path / "junk.nc") == "unknown"


def test_open_netcdf4_and_netcdf3_bit_for_bit(files):
    tr, nc4, nc3, _ = files
    for path in (nc4, nc3):
        back = Trajectory.open(path)
        assert isinstance(back, Trajectory)
        np.testing.assert_array_equal(back.t, tr.t)
        np.testing.assert_array_equal(back.quaternion, tr.quaternion)
        np.testing.assert_array_equal(back.omega, tr.omega)
        assert back.body.name == "probe" and back.method == "exact"
    # NetCDF-3 used to be refused (the file was opened with h5netcdf only)
    assert isinstance(Trajectory.from_netcdf(nc3), Trajectory)


def test_open_zarr_store_is_lazy_and_exact(files):
    tr, _, _, store = files
    lz = Trajectory.open(store)
    assert isinstance(lz, LazyTrajectory) and lz is not None
    assert len(lz) == 95 and lz.chunk == 10 and lz.batch_shape == ()
    assert isinstance(lz.quaternion, StoredArray) and lz.quaternion.shape == (95, 4)
    assert lz.body.name == "probe" and lz.method == "exact" and lz.model.is_free
    full = lz.load()
    # the closed form chunk by chunk is the closed form: bit for bit
    np.testing.assert_array_equal(full.t, tr.t)
    np.testing.assert_array_equal(full.quaternion, tr.quaternion)
    np.testing.assert_array_equal(full.omega, tr.omega)
    np.testing.assert_array_equal(lz[7].quaternion, tr.quaternion[7:8])
    np.testing.assert_array_equal(lz[-1].t, tr.t[-1:])
    np.testing.assert_array_equal(lz[3:50:7].omega, tr.omega[3:50:7])
    np.testing.assert_array_equal(lz[[90, 2, 45]].t, tr.t[[90, 2, 45]])
    np.testing.assert_array_equal(np.asarray(lz.omega), tr.omega)
    pieces = list(lz.iter_chunks(25))
    assert [len(p.t) for p in pieces] == [30, 30, 30, 5]  # whole Zarr chunks
    np.testing.assert_array_equal(np.concatenate([p.omega for p in pieces]), tr.omega)
    d = lz.drift_endpoints()
    assert set(d) == set(tr.drift()) and max(d.values()) < 1e-13
    with pytest.raises(IndexError):
        lz[95]
    with pytest.raises(TypeError):
        lz[1.5]


def test_opening_a_store_reads_only_metadata_and_ends(files, tmp_path, monkeypatch, capsys):
    """Middle chunks removed from the store: opening it and 'info' still work (they never read them)."""
    _, _, _, store = files
    cut = tmp_path / "cut.zarr"
    shutil.copytree(store, cut)
    for name in ("quaternion", "omega", "time"):
        for k in range(1, 9):
            for f in (cut / name / "c").glob(f"{k}/*" if name != "time" else f"{k}"):
                f.unlink() if f.is_file() else shutil.rmtree(f)
    calls = []
    real = StoredArray.read

    def spy(self, a, b, step=1):
        calls.append((a, b))
        return real(self, a, b, step)

    monkeypatch.setattr(StoredArray, "read", spy)
    lz = Trajectory.open(cut)
    assert all(b - a == 1 for a, b in calls), calls  # the first and the last sample, nothing else
    assert main(["info", str(cut)]) == 0
    out = capsys.readouterr().out
    assert "95, t from 0 to 20" in out and "Zarr store" in out and "drift" in out
    assert all(b - a == 1 for a, b in calls), calls
    with pytest.raises(EulerPoissonError, match="missing \\(NaN\\) in a finished store"):
        lz.load()


def test_store_checks(files, tmp_path):
    _, _, _, store = files
    bad = tmp_path / "bad.zarr"
    shutil.copytree(store, bad)
    import zarr

    g = zarr.open_group(str(bad), mode="r+")
    g["quaternion"][94] = [2.0, 0.0, 0.0, 0.0]
    with pytest.raises(InvalidInputError, match="not made of unit quaternions"):
        Trajectory.open(bad)
    newer = tmp_path / "newer.zarr"
    shutil.copytree(store, newer)
    meta = json.loads((newer / "zarr.json").read_text())
    meta["attributes"]["eulerpoisson_format_version"] = 99
    meta.get("consolidated_metadata", {}).pop("metadata", None)
    meta.pop("consolidated_metadata", None)
    (newer / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(EulerPoissonError, match="newer"):
        Trajectory.open(newer)
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(EulerPoissonError, match="not a Zarr store"):
        open_trajectory(folder)
    with pytest.raises(FileNotFoundError):
        Trajectory.open(tmp_path / "missing.nc")
    with pytest.raises(TypeError):
        Trajectory.open(3)


def test_cli_reads_every_format(files, tmp_path, capsys):
    """info, plot and animate on a .zarr store written by simulate (refused before) and on NetCDF-3."""
    _, _, nc3, _ = files
    store = tmp_path / "sim.zarr"
    assert (
        main(
            [
                "simulate",
                "--inertia",
                "1,2,3",
                "--omega",
                "1,0.1,0.5",
                "--t-end",
                "10",
                "--samples",
                "300",
                "--out",
                str(store),
                "--quiet",
            ]
        )
        == 0
    )
    capsys.readouterr()
    for path in (store, nc3):
        assert main(["info", str(path)]) == 0, capsys.readouterr().err
        out = capsys.readouterr().out
        assert "eulerpoisson trajectory" in out and "energy" in out
        png = tmp_path / f"{path.stem}.png"
        assert main(["plot", str(path), "--kind", "omega", "--out", str(png), "--quiet"]) == 0
        assert png.stat().st_size > 1000
        html = tmp_path / f"{path.stem}.html"
        assert main(["animate", str(path), "--out", str(html), "--quiet"]) == 0
        assert "ep-data" in html.read_text()
    folder = tmp_path / "empty_dir"
    folder.mkdir()
    assert main(["info", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a trajectory file" in err
