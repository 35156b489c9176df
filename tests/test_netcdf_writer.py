"""The NetCDF writer (h5netcdf directly): xarray reads back exactly the dataset of ``to_xarray()``; no xarray import."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.torques import Gravity

xr = pytest.importorskip("xarray")


@pytest.mark.parametrize("case", ["single", "batch", "torque", "particles"])
def test_file_reads_back_as_to_xarray(tmp_path, case):
    t = np.linspace(0.0, 1.0, 5)
    if case == "single":
        tr = ep.solve(ep.RigidBody([1, 2, 3], name="racket $x$"), t, omega0=[1, 0.1, 0.5])
    elif case == "batch":
        tr = ep.solve(ep.RigidBody(np.array([[1, 2, 3], [2, 3, 4.0]])), t, omega0=[1, 0.1, 0.5])
    elif case == "torque":
        tr = ep.solve(ep.RigidBody([1, 1, 0.5]), t, omega0=[0, 0, 10.0], torque=Gravity(1.0, [0, 0, 0.2]))
    else:
        body = ep.RigidBody.from_particles([1.0, 2.0, 3.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
        tr = ep.solve(body, t, omega0=[0.3, 0.2, 1.0])
    path = tmp_path / "run.nc"
    tr.to_netcdf(path)
    back = xr.open_dataset(path, engine="h5netcdf").load()
    ref = tr.to_xarray()
    back.attrs.pop("history")
    ref.attrs.pop("history")
    assert back.identical(ref)
    again = ep.Trajectory.from_netcdf(path)
    assert np.array_equal(again.quaternion, tr.quaternion) and np.array_equal(again.omega, tr.omega)


def test_writing_imports_neither_xarray_nor_dask(tmp_path):
    code = (
        "import sys, numpy as np, eulerpoisson as ep\n"
        f"ep.solve(ep.RigidBody([1, 2, 3]), np.linspace(0, 1, 11), omega0=[1, 0.1, 0.5]).to_netcdf({str(tmp_path / 'a.nc')!r})\n"
        "print('xarray' in sys.modules, 'dask' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]
