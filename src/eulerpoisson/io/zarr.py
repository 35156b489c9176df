r"""Zarr stores of trajectories: the layout of :func:`eulerpoisson.io.netcdf.dataset_content`, chunked along time.

One module per file format (as xarray keeps one backend per format): :mod:`.netcdf` describes a trajectory's
variables, dimensions and attributes and writes NetCDF files; this module creates a Zarr store of the same
layout for a run of ``n`` output times, empty (NaN) until the chunks are written
(:func:`eulerpoisson.io.stream.solve_to_file`), so that ``xarray.open_zarr`` reads a store as it reads the
dataset of a small run. xarray is not needed to write one.

Examples
--------
>>> import tempfile, pathlib, numpy as np, eulerpoisson as ep
>>> from eulerpoisson.io.zarr import create_trajectory_store
>>> tr = ep.solve([1.0, 2.0, 3.0], [0.0], omega0=[1.0, 0.1, 0.5])
>>> store = pathlib.Path(tempfile.mkdtemp()) / "run.zarr"
>>> g = create_trajectory_store(store, tr, n=10, chunk=4, variables=["quaternion", "omega"])
>>> g["omega"].shape, g["omega"].chunks, bool(np.isnan(g["omega"][0, 0]))
((10, 3), (4, 3), True)
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import require
from .netcdf import dataset_content

if TYPE_CHECKING:
    from ..trajectory import Trajectory

__all__ = ["quiet_zarr", "create_trajectory_store"]


@contextlib.contextmanager
def quiet_zarr() -> Iterator[None]:
    """Silence zarr's warnings about v3 extensions (fixed-width strings, consolidated metadata)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*Zarr format 3 specification.*")
        warnings.filterwarnings("ignore", message=".*does not have a Zarr V3 specification.*")
        warnings.filterwarnings("ignore", message=".*Consolidated metadata.*")
        yield


def create_trajectory_store(
    store: str | Path,
    template: Trajectory,
    *,
    n: int,
    chunk: int,
    variables: Sequence[str],
    attrs: dict[str, Any] | None = None,
) -> Any:
    """Create an empty Zarr store for a run of ``n`` output times with the layout of ``template``'s file.

    Parameters
    ----------
    store : str or Path
        The store (a folder; created).
    template : Trajectory
        A trajectory of the run (its body, model, method and options; one sample is enough): the layout, the
        attributes and the variables without a time dimension (inertia, particle data) are taken from it.
    n : int
        Output times of the run.
    chunk : int
        Samples per Zarr chunk along ``time``.
    variables : sequence of str
        The time-dependent variables to create (``time`` always is).
    attrs : dict, optional
        Global attributes added to (or replacing) the template's.

    Returns
    -------
    zarr.Group
        The store, open for writing; its metadata consolidated (the store reads like a finished one).

    Raises
    ------
    MissingDependencyError
        zarr is not installed (extra ``dask``).
    """
    zarr = require("zarr", "dask")
    data, coords, gattrs = dataset_content(template)
    with quiet_zarr():
        g = zarr.open_group(str(store), mode="w")
        g.attrs.update({**gattrs, **(attrs or {})})
        for name, var in {**coords, **data}.items():
            dims, values, vattrs = var if len(var) == 3 else (*var, {})
            dims = (dims,) if isinstance(dims, str) else tuple(dims)
            if "time" in dims and name != "time" and name not in variables:
                continue
            values = np.asarray(values)
            shape = list(values.shape)
            chunks = list(values.shape)
            if "time" in dims:
                i = dims.index("time")
                shape[i] = n
                chunks[i] = min(chunk, n)
            kind = values.dtype.kind
            fill = np.nan if kind == "f" else ("" if kind == "U" else 0)
            arr = g.create_array(
                name,
                shape=tuple(shape),
                chunks=tuple(chunks),
                dtype=values.dtype,
                fill_value=fill,
                dimension_names=list(dims),
            )
            arr.attrs.update(dict(vattrs))
            if "time" not in dims:
                arr[...] = values
        zarr.consolidate_metadata(str(store))
    return g
