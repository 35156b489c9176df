"""What a file is, by its content (never by its name): NetCDF-4, NetCDF-3 or a Zarr store.

The one place where a file's format is sniffed (:func:`file_format`): :func:`eulerpoisson.io.read.open_trajectory`
opens any of them, the NetCDF reader picks xarray's engine (:func:`netcdf_engine`), and the output policy
(:mod:`.outputs`) recognizes the files it may replace.

Examples
--------
>>> from eulerpoisson.io.formats import file_format
>>> file_format("no/such/file")
'unknown'
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["NETCDF3_MAGIC", "HDF5_MAGIC", "is_zarr_store", "file_format", "netcdf_engine"]

#: first bytes of a NetCDF-3 file (classic, 64-bit offset, 64-bit data)
NETCDF3_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05")
#: first bytes of an HDF5 file (NetCDF-4)
HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


def is_zarr_store(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a folder holding Zarr metadata (version 3 ``zarr.json`` or version 2)."""
    p = Path(path)
    return p.is_dir() and any((p / name).is_file() for name in ("zarr.json", ".zgroup", ".zattrs"))


def file_format(path: str | os.PathLike[str]) -> str:
    """The format of a trajectory file by its content: ``"zarr"``, ``"netcdf4"``, ``"netcdf3"`` or ``"unknown"``."""
    p = Path(os.fsdecode(path))
    if p.is_dir():
        return "zarr" if is_zarr_store(p) else "unknown"
    try:
        with open(p, "rb") as fh:
            head = fh.read(8)
    except OSError:
        return "unknown"
    if head.startswith(HDF5_MAGIC):
        return "netcdf4"
    if head[:4] in NETCDF3_MAGIC:
        return "netcdf3"
    return "unknown"


def netcdf_engine(path: str | os.PathLike[str]) -> str:
    """xarray's engine for a NetCDF file: ``"scipy"`` for NetCDF-3, ``"h5netcdf"`` otherwise."""
    return "scipy" if file_format(path) == "netcdf3" else "h5netcdf"
