"""A resumed Zarr run verifies every chunk it trusts (issue 22, item 4).

A chunk of the partial store overwritten with garbage and another deleted while the run was interrupted: the
resume finds them by their checksums (recorded when each chunk was written), computes them again, and
publishes a store equal bit for bit to an uninterrupted run (never the damage, never a decompression error).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from eulerpoisson.io.stream import partial_store, solve_to_file

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]
GRID = (0.0, 12.0, 1000)
CHUNK = 100


class _Stop:
    def __init__(self, after):
        self.after = after

    def __call__(self, done, total):
        if done >= self.after:
            raise KeyboardInterrupt


def _chunk_files(store: Path, name: str) -> list[Path]:
    return sorted(p for p in (store / name).rglob("*") if p.is_file() and p.name not in ("zarr.json", ".zarray"))


@pytest.mark.parametrize("method", ["exact", "taylor"])
def test_a_damaged_partial_store_is_repaired_on_resume(tmp_path, method):
    ref = tmp_path / "ref.zarr"
    solve_to_file(I, GRID, ref, omega0=W0, method=method, chunk=CHUNK, progress=False)
    path = tmp_path / "run.zarr"
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(I, GRID, path, omega0=W0, method=method, chunk=CHUNK, progress=_Stop(6 * CHUNK))
    store = partial_store(path)
    markers = sorted((store.parent / "done").iterdir())
    assert len(markers) == 6 and all("sha256" in json.loads(m.read_text()) for m in markers)
    files = _chunk_files(store, "omega")
    assert len(files) >= 6
    files[1].write_bytes(b"garbage" * 40)  # chunk 1 overwritten
    _chunk_files(store, "quaternion")[3].unlink()  # chunk 3 deleted
    solve_to_file(I, GRID, path, omega0=W0, method=method, chunk=CHUNK, progress=False, resume=True)
    out, want = xr.open_zarr(str(path)), xr.open_zarr(str(ref))
    for name in ("time", "quaternion", "omega", "M", "m", "energy", "gibbs"):
        np.testing.assert_array_equal(out[name].values, want[name].values)


def test_an_intact_partial_store_is_trusted(tmp_path):
    """Verification recomputes nothing that is intact: only the missing chunks are written (progress says so)."""
    path = tmp_path / "run.zarr"
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(I, GRID, path, omega0=W0, chunk=CHUNK, progress=_Stop(4 * CHUNK))
    calls: list[int] = []
    solve_to_file(I, GRID, path, omega0=W0, chunk=CHUNK, resume=True, progress=lambda d, t: calls.append(d))
    assert calls == list(range(4 * CHUNK, 1000 + 1, CHUNK))
