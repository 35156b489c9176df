r"""Read every trajectory file eulerpoisson writes: NetCDF-4, NetCDF-3 and Zarr stores.

:func:`open_trajectory` (also :meth:`Trajectory.open
<eulerpoisson.trajectory.Trajectory.open>`) looks at the file, not at its
name:

============================ ===============================================
what                         read by
============================ ===============================================
NetCDF-4 (HDF5) file         :meth:`Trajectory.from_netcdf` (h5netcdf)
NetCDF-3 classic / 64-bit    the same checks, through xarray's ``scipy``
                             engine
a Zarr store (a folder)      :class:`LazyTrajectory`: nothing but the
                             metadata is read when it is opened
============================ ===============================================

A :class:`LazyTrajectory` is what ``simulate --out run.zarr`` (or
:func:`~eulerpoisson.io.stream.solve_to_file`) wrote: up to :math:`10^8`
samples and more, far more than memory. It reads samples on demand — one
sample, a slice, a whole chunk at a time (:meth:`LazyTrajectory.iter_chunks`)
— and gives an ordinary in-memory :class:`~eulerpoisson.trajectory.Trajectory`
for any selection (``lazy[a:b]``, :meth:`LazyTrajectory.load`).
The plots (:mod:`eulerpoisson.viz.plots`) draw it chunk by chunk, decimated
to the resolution of the picture, in bounded memory.

Reading fast. Decoding the chunks is what a long picture costs (a
:math:`10^8`-sample store holds 2.4 GB of Ω). zarr's synchronous reads go
through one event loop and hold the GIL for about as long as Zstandard
takes, so they do not get faster with threads; the chunks of the layout we
write are therefore read from their files and decoded by numcodecs directly
(:class:`_DirectChunks`, bit for bit what zarr reads; anything else goes
through zarr), by several threads at once (:meth:`LazyTrajectory.map_arrays`,
:func:`ordered_map`, :func:`read_workers` threads), each reading into
buffers of its own that it reuses piece after piece (fresh memory costs a
page fault per 4 kB, which adds up to a third of the decoding). Only the
variables asked for are read; equally spaced times are computed, not read.
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
import zlib
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import EulerPoissonError, InvalidInputError, require
from .formats import HDF5_MAGIC, NETCDF3_MAGIC, file_format, is_zarr_store

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..trajectory import Trajectory

__all__ = ["open_trajectory", "LazyTrajectory", "StoredArray", "file_format", "NETCDF3_MAGIC", "HDF5_MAGIC"]

#: stores of at most this many samples are loaded into memory by ``LazyTrajectory.load()`` without asking
LOAD_LIMIT = 20_000_000


def open_trajectory(path: str | os.PathLike[str]) -> Trajectory | LazyTrajectory:
    """Open a trajectory file of any of our formats (see the module notes).

    Parameters
    ----------
    path : str or os.PathLike
        A NetCDF file (version 4 or 3) written by :meth:`Trajectory.to_netcdf`
        (or converted by another tool), or a Zarr store written by
        ``simulate --out run.zarr`` / :func:`~eulerpoisson.io.stream.solve_to_file`.

    Returns
    -------
    Trajectory or LazyTrajectory
        An in-memory trajectory for NetCDF, a :class:`LazyTrajectory` for a Zarr store.

    Raises
    ------
    TypeError
        ``path`` is not a file name.
    FileNotFoundError
        Nothing at ``path``.
    EulerPoissonError
        Not a trajectory file of ours (a folder that is not a Zarr store, an
        unreadable file, a newer format version).
    InvalidInputError
        A malformed file (as :meth:`Trajectory.from_netcdf`).
    MissingDependencyError
        xarray/h5netcdf (extra ``io``), scipy, or zarr (extra ``dask``) missing.
    """
    from ..trajectory import Trajectory

    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path must be a file name (str or os.PathLike), got {type(path).__name__} {path!r}")
    if isinstance(path, bytes):
        path = os.fsdecode(path)  # named as text in the messages below, not b'...'
    p = Path(os.fsdecode(path))
    if not p.exists():
        raise FileNotFoundError(f"no such file: {path}")
    if p.is_dir():
        if not is_zarr_store(p):
            raise EulerPoissonError(
                f"{path} is a folder but not a Zarr store (a trajectory is a NetCDF file or a .zarr store "
                "written by 'eulerpoisson simulate --out')"
            )
        return LazyTrajectory(p)
    return Trajectory.from_netcdf(path)


# ---------------------------------------------------------------------------
# Zarr stores
# ---------------------------------------------------------------------------
def _time_grid(attrs, T: int, first: float, last: float):
    """The :class:`~eulerpoisson.io.stream.TimeGrid` of a store streamed on ``(t0, t1, n)``, or None.

    Read from the run's record (attribute ``eulerpoisson_run``, when the
    writer kept one) and checked against the first and last stored times;
    its values are bit for bit ``numpy.linspace(t0, t1, n)``, as written, so
    the ``time`` variable need not be read.
    """
    from .stream import TimeGrid

    try:
        grid = json.loads(attrs.get("eulerpoisson_run", "null"))["times"]["grid"]
        t0, t1, n = float(grid[0]), float(grid[1]), int(grid[2])
    except (TypeError, ValueError, KeyError, IndexError):
        return None
    if n != T:
        return None
    g = TimeGrid(t0, t1, n)
    if float(g[0:1][0]) != first or float(g[n - 1 : n][0]) != last:
        return None
    return g


# ---------------------------------------------------------------------------
# reading chunks without zarr's machinery (the layout we write)
# ---------------------------------------------------------------------------
class _NotDirect(Exception):
    """The direct reader cannot read this chunk (zarr reads it instead).

    ``chunk`` names the chunk (``"omega/c/0/0"``) when its bytes could not be decoded.
    """

    def __init__(self, message: str, chunk: str | None = None) -> None:
        super().__init__(message)
        self.chunk = chunk


def _is_codec_error(exc: BaseException) -> bool:
    """Whether ``exc`` says that a stored chunk cannot be decoded (its bytes are not what the codecs wrote).

    Only these: numcodecs' ``RuntimeError`` ("Zstd decompression error ...",
    "error during blosc decompression ..."), zlib's error (gzip), and the
    ``ValueError`` of a chunk that decodes to the wrong number of values
    ("cannot reshape array of size 3 into shape (5,3)").
    """
    if isinstance(exc, zlib.error):
        return True
    text = str(exc).lower()
    if isinstance(exc, RuntimeError):
        return "decompress" in text or "zstd" in text or "blosc" in text or "lz4" in text
    if isinstance(exc, ValueError):
        return text.startswith("cannot reshape array")
    return False


@contextlib.contextmanager
def _decoding(store: Any, name: str, chunk: str | None = None) -> Iterator[None]:
    """Re-raise a codec error (:func:`_is_codec_error`) met while reading variable ``name`` as an input error.

    Raises
    ------
    EulerPoissonError
        ``"{store} is not a readable Zarr store: chunk {chunk} is corrupt (...)"`` (or "a chunk of {name}"
        when the chunk is not known); any other exception passes unchanged.
    """
    try:
        yield
    except (RuntimeError, ValueError, zlib.error) as exc:
        if not _is_codec_error(exc):
            raise
        what = f"chunk {chunk}" if chunk else f"a chunk of variable {name}"
        raise EulerPoissonError(
            f"{store} is not a readable Zarr store: {what} is corrupt ({exc}); write the store again"
        ) from exc


def _zstd_content_size(raw) -> int | None:
    """The decompressed size recorded in a single Zstandard frame's header (RFC 8878 §3.1.1), or None."""
    if len(raw) < 6 or bytes(raw[:4]) != b"\x28\xb5\x2f\xfd":
        return None
    fhd = raw[4]
    fcs_flag, single, dict_flag = fhd >> 6, (fhd >> 5) & 1, fhd & 3
    pos = 5 + (0 if single else 1) + (0, 1, 2, 4)[dict_flag]
    size = (1 if single else 0, 2, 4, 8)[fcs_flag]
    if size == 0 or len(raw) < pos + size:
        return None
    value = int.from_bytes(bytes(raw[pos : pos + size]), "little")
    return value + 256 if size == 2 else value


_LOCAL = threading.local()


def _thread_buffer(size: int) -> bytearray:
    """This thread's reusable read buffer, at least ``size`` bytes (fresh memory costs a page fault per 4 kB)."""
    buf = getattr(_LOCAL, "buf", None)
    if buf is None or len(buf) < size:
        buf = _LOCAL.buf = bytearray(max(size, 2 * len(buf) if buf is not None else size))
    return buf


class _DirectChunks:
    """Whole chunks of a plain Zarr (format 3) array in a local folder, read and decoded without zarr.

    zarr's synchronous reads go through one event loop and hold the GIL
    for about as long as Zstandard takes to decode a chunk, so threads do
    not read a long store faster. This reader opens the chunk files itself
    and decodes them with numcodecs (which releases the GIL): several
    threads decode in parallel. Only the layout eulerpoisson writes is read
    this way — format 3, a regular grid split along time only, the codecs
    ``bytes`` and optionally ``zstd``, no storage transformers, a local
    folder (:meth:`of` gives None otherwise); a missing chunk file is the
    fill value, as for zarr. A chunk it cannot decode raises
    :class:`_NotDirect`, and the caller reads it through zarr.
    """

    def __init__(self, root: Path, arr, axis: int, dtype: np.dtype, compressed: bool):
        self.root = root
        self.key = arr.metadata.encode_chunk_key
        self.axis = axis
        self.shape = tuple(int(n) for n in arr.shape)
        self.chunks = tuple(int(n) for n in arr.chunks)
        self.c = self.chunks[axis]
        self.dtype = dtype
        self.native = dtype.newbyteorder("=")
        self.compressed = compressed
        self.fill = arr.fill_value
        self.nbytes = int(np.prod(self.chunks)) * dtype.itemsize
        self.name = str(arr.path).strip("/")

    @classmethod
    def of(cls, arr, axis: int):
        """The direct reader of ``arr`` (time along ``axis``), or None where zarr must read it."""
        try:
            from zarr.codecs import BytesCodec, ZstdCodec
            from zarr.core.chunk_grids import RegularChunkGrid
            from zarr.storage import LocalStore

            md = arr.metadata
            if getattr(md, "zarr_format", None) != 3 or not isinstance(arr.store, LocalStore):
                return None
            if not isinstance(md.chunk_grid, RegularChunkGrid) or tuple(getattr(md, "storage_transformers", ())):
                return None
            codecs = tuple(md.codecs)
            if not 1 <= len(codecs) <= 2 or type(codecs[0]) is not BytesCodec:
                return None
            if len(codecs) == 2 and type(codecs[1]) is not ZstdCodec:
                return None
            dtype = np.dtype(arr.dtype)
            if dtype.kind not in "fiu":
                return None
            endian = getattr(codecs[0].endian, "value", codecs[0].endian)
            dtype = dtype.newbyteorder(">" if endian == "big" else "<")
            shape, chunks = tuple(arr.shape), tuple(arr.chunks)
            if (
                len(shape) != len(chunks)
                or not 0 <= axis < len(shape)
                or not all(c == s for i, (c, s) in enumerate(zip(chunks, shape)) if i != axis)
                or chunks[axis] < 1
            ):
                return None
            root = Path(str(arr.store.root)) / str(arr.path)
            if not root.is_dir():
                return None
            return cls(root, arr, axis, dtype, len(codecs) == 2)
        except Exception:  # noqa: BLE001 - any surprise: zarr reads it
            return None

    def _chunk(self, k: int, out: np.ndarray | None = None) -> np.ndarray:
        """Chunk ``k`` (full chunk shape), decoded into ``out`` (C-contiguous, native) when given."""
        coords = [0] * len(self.shape)
        coords[self.axis] = k
        key = self.key(tuple(coords))
        fn = self.root.joinpath(*key.split("/"))
        try:
            with open(fn, "rb", buffering=0) as fh:
                size = os.fstat(fh.fileno()).st_size
                buf = _thread_buffer(size + 1)  # the file read into this thread's buffer: no fresh pages
                got = fh.readinto(buf)
            raw = memoryview(buf)[:got]
            if got > size:  # the file grew meanwhile (a writer): not ours to read
                raise _NotDirect(f"{fn} is being written")
        except FileNotFoundError:  # never written: the fill value (NaN for an unfinished chunk)
            if out is None:
                out = np.empty(self.chunks, self.native)
            out[...] = self.fill
            return out
        except OSError as exc:
            raise _NotDirect(str(exc)) from exc
        if self.compressed:
            from numcodecs.zstd import decompress

            try:
                if (
                    out is not None
                    and self.dtype.isnative
                    and out.flags.c_contiguous
                    and _zstd_content_size(raw) == self.nbytes == out.nbytes
                ):
                    decompress(raw, out)
                    return out
                raw = memoryview(decompress(raw))
            except Exception as exc:  # noqa: BLE001 - not what we wrote: zarr reads it (and says what is wrong)
                raise _NotDirect(str(exc), f"{self.name}/{key}") from exc
        if raw.nbytes != self.nbytes:
            raise _NotDirect(f"chunk {k} holds {raw.nbytes} bytes, expected {self.nbytes}", f"{self.name}/{key}")
        x = np.frombuffer(raw, self.dtype).reshape(self.chunks)
        if out is None:
            return x.astype(self.native)  # a copy: the buffer is reused
        out[...] = x
        return out

    def read(self, a: int, b: int, step: int = 1, out: np.ndarray | None = None) -> np.ndarray:
        """Elements ``a:b:step`` along the time axis (``0 <= a``, ``b <= len``, ``step >= 1``).

        Into ``out`` when it is an array of the result's shape and dtype (C-contiguous), else a new array.
        """
        ax, c = self.axis, self.c
        idx = range(a, b, step)
        n = len(idx)
        shape = list(self.shape)
        shape[ax] = n
        if not (
            isinstance(out, np.ndarray)
            and out.shape == tuple(shape)
            and out.dtype == self.native
            and out.flags.c_contiguous
            and out.flags.writeable
        ):
            out = np.empty(shape, self.native)
        if n == 0:
            return out
        pos = 0
        for k in range(idx[0] // c, idx[-1] // c + 1):
            lo, hi = k * c, min((k + 1) * c, self.shape[ax])
            i0 = max(a, lo)
            i0 = a + -(-(i0 - a) // step) * step  # the first index of the range in this chunk
            i1 = min(b, hi)
            if i0 >= i1:
                continue
            m = len(range(i0, i1, step))
            dst = [slice(None)] * len(shape)
            dst[ax] = slice(pos, pos + m)
            target = out[tuple(dst)]
            if step == 1 and i0 == lo and i1 - lo == c and target.flags.c_contiguous:
                self._chunk(k, target)  # straight into the result
            else:
                src = [slice(None)] * len(shape)
                src[ax] = slice(i0 - lo, i1 - lo, step)
                target[...] = self._chunk(k)[tuple(src)]
            pos += m
        return out


_COUNT = np.zeros(0)  # 0, 1, 2, ... as float64 (numpy's float arange is several times slower than arithmetic)


def _grid_times(grid, a: int, b: int, step: int, out: np.ndarray | None = None) -> np.ndarray:
    """``grid[a:b:step]`` of a :class:`~eulerpoisson.io.stream.TimeGrid`, bit for bit, in a few in-place passes.

    The sample indices are exact integers in float64, so ``index * step + t0``
    is computed exactly as the grid does it.
    """
    global _COUNT
    m = len(range(a, b, step)) if step >= 1 else 0
    if grid.n == 1 or grid._step == 0 or step < 1 or b > 2**53:
        return grid[a:b:step]
    if _COUNT.size < m:
        _COUNT = np.arange(max(m, 2 * _COUNT.size), dtype=np.float64)
    if not (isinstance(out, np.ndarray) and out.shape == (m,) and out.dtype == np.float64 and out.flags.writeable):
        out = None
    y = np.multiply(_COUNT[:m], float(step), out=out)
    y += a
    y *= grid._step
    y += grid.t0
    if m and a + (m - 1) * step == grid.n - 1:
        y[-1] = grid.t1
    return y


class StoredArray:
    """A time-dependent variable of a Zarr store, read on demand: shape ``(*batch, T, ...)``.

    Indexing reads only what is asked for (``a[..., 1000:2000, :]``,
    ``a[-1]``); ``numpy.asarray(a)`` reads everything.
    """

    def __init__(self, arr: Any, batch_shape: tuple[int, ...], *, store: str | os.PathLike[str] | None = None) -> None:
        self._arr = arr
        self._bshape = tuple(batch_shape)
        self._store = store if store is not None else getattr(getattr(arr, "store", None), "root", "the store")
        self._name = str(getattr(arr, "path", "") or "?").strip("/")
        shp = tuple(arr.shape)
        self.shape = self._bshape + shp[1:] if self._bshape else shp
        self.dtype = np.dtype(arr.dtype)
        self.ndim = len(self.shape)
        self.chunks = tuple(getattr(arr, "chunks", shp))
        self._direct: _DirectChunks | Literal[False] | None = (
            None  # the direct chunk reader (False: zarr reads everything)
        )

    def __len__(self) -> int:
        return self.shape[0]

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    def read(self, a: int, b: int, step: int = 1, out: np.ndarray | None = None) -> np.ndarray:
        """Samples ``a:b:step`` along time, shape ``(*batch, n, ...)``.

        Whole chunks of the layout we write are read from their files and
        decoded directly (:class:`_DirectChunks`, several threads may read at
        once), into ``out`` when it is an array of the stored shape
        ``(n, ...)`` (or ``(bodies, n, ...)``) and dtype; anything else through zarr.
        """
        sl = slice(a, b, step)
        axis = 1 if self._bshape else 0
        if self._direct is None:
            self._direct = _DirectChunks.of(self._arr, axis) or False
        chunk = None
        if self._direct and (step or 1) > 0:
            try:
                x = self._direct.read(*sl.indices(int(self._arr.shape[axis])), out=out)
            except _NotDirect as exc:
                chunk = exc.chunk  # the chunk it could not decode: named if zarr cannot either
            else:
                return x.reshape(self._bshape + x.shape[1:]) if self._bshape else x
        with _decoding(self._store, self._name, chunk):
            if self._bshape:
                x = np.asarray(self._arr[:, sl])
                return x.reshape(self._bshape + x.shape[1:])
            return np.asarray(self._arr[sl])

    def __getitem__(self, index: Any) -> NDArray[np.float64]:
        if not self._bshape:
            with _decoding(self._store, self._name):
                return np.asarray(self._arr[index])
        return np.asarray(self)[index]  # batches are small stores in practice

    def __array__(self, dtype=None, copy=None):
        with _decoding(self._store, self._name):
            x = np.asarray(self._arr[...])
        if self._bshape:
            x = x.reshape(self.shape)
        return x if dtype is None else x.astype(dtype)

    def __repr__(self) -> str:
        return f"StoredArray(shape={self.shape}, dtype={self.dtype})"


def _all_finite(x: np.ndarray) -> bool:
    """True when every value of ``x`` is finite (one pass: the sum is finite, else a check value by value)."""
    with np.errstate(all="ignore"):
        total = np.add.reduce(x, axis=None) if x.size else 0.0
    return bool(np.isfinite(total)) or bool(np.all(np.isfinite(x)))


def read_workers() -> int:
    """Threads that read (and draw) a long store at once: the CPUs this process may use, 2 to 8."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        n = os.cpu_count() or 1
    return max(2, min(8, n))


_END = object()


def ordered_map(fn, items, workers: int | None = None):
    """``fn(item)`` for every item, computed by ``workers`` threads, yielded in the order of ``items``.

    At most ``workers + 1`` calls are in flight (bounded memory); an
    exception of a call is raised where its result is yielded; what is not
    yet started when the caller stops is cancelled.
    """
    import collections
    from concurrent.futures import ThreadPoolExecutor

    items = iter(items)
    workers = read_workers() if workers is None else max(1, int(workers))
    with ThreadPoolExecutor(workers, thread_name_prefix="eulerpoisson-read") as ex:
        pending = collections.deque(ex.submit(fn, it) for _, it in zip(range(workers + 1), items))
        try:
            while pending:
                res = pending.popleft().result()
                nxt = next(items, _END)
                if nxt is not _END:
                    pending.append(ex.submit(fn, nxt))
                yield res
        finally:
            for f in pending:
                f.cancel()


def zarr_group(path: Path):
    import warnings

    zarr = require("zarr", "dask")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return zarr.open_group(str(path), mode="r")
        except Exception as exc:  # noqa: BLE001 - any failure: not a readable store
            raise EulerPoissonError(f"{path} is not a readable Zarr store: {exc}") from exc


class LazyTrajectory:
    r"""A trajectory in a Zarr store (written by ``simulate --out run.zarr``), read on demand.

    Opening reads the metadata (attributes, the body, the torques) and the
    first and last samples, and checks them as :meth:`Trajectory.from_netcdf`
    does; the other samples are read when asked for (an unwritten sample of
    an unfinished run's partial store is an error naming it). ``len(lazy)`` is the number of samples; ``lazy[i]``,
    ``lazy[a:b]`` (a slice with any step) and ``lazy[[i, j]]`` are in-memory
    :class:`~eulerpoisson.trajectory.Trajectory` objects; :meth:`head` and
    :meth:`tail` the first and last samples; :meth:`iter_chunks` walks the
    store one Zarr chunk at a time; :meth:`load` reads it all.

    Attributes
    ----------
    path : pathlib.Path
    t, quaternion, omega : StoredArray
        Read on demand (``numpy.asarray`` reads all of it).
    body, model, method, options, stats, batch_shape
        As for :class:`~eulerpoisson.trajectory.Trajectory`.
    chunk : int
        Samples per Zarr chunk along time.
    variables : tuple of str
        The time-dependent variables stored (``quaternion``, ``omega`` and any
        of ``M``, ``m``, ``energy``, ``gibbs``).

    Raises
    ------
    EulerPoissonError
        Not an eulerpoisson store, or a newer format version.
    InvalidInputError
        Malformed attributes or variables (shapes, the body, the torques), or
        first or last attitudes that are not unit quaternions.
    """

    lazy = True

    def __init__(self, path: str | os.PathLike[str]) -> None:
        from ..model.body import RigidBody
        from ..model.equations import Model
        from ..trajectory import FORMAT_VERSION
        from .netcdf import format_version, json_attr, read_torques

        self.path = Path(path)
        g = zarr_group(self.path)
        self._group = g
        attrs = dict(g.attrs)
        names = set(g.array_keys()) if hasattr(g, "array_keys") else set(g.keys())
        ver = attrs.get("eulerpoisson_format_version")
        if ver is None or "quaternion" not in names or "omega" not in names:
            raise EulerPoissonError(f"{path} is not an eulerpoisson trajectory store")
        ver = format_version(path, ver)
        if ver > FORMAT_VERSION:
            raise EulerPoissonError(
                f"{path} has format version {ver}, newer than this eulerpoisson ({FORMAT_VERSION}); upgrade the package"
            )
        missing = [v for v in ("time", "inertia") if v not in names]
        if missing:
            raise InvalidInputError(f"{path}: malformed eulerpoisson trajectory store, variable(s) {missing} missing")

        class _Attrs:  # what the NetCDF helpers expect: ds.attrs
            attrs: dict

        ds = _Attrs()
        ds.attrs = attrs
        bshape = json_attr(path, ds, "batch_shape", "[]", list)
        if not all(isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in bshape):
            raise InvalidInputError(
                f"{path}: attribute batch_shape must be a JSON list of non-negative integers, got {bshape!r}"
            )
        self.batch_shape = tuple(bshape)
        self.options = json_attr(path, ds, "method_options", "{}", dict)
        self.stats = json_attr(path, ds, "stats", "{}", dict)
        self.method = str(attrs.get("method", ""))
        tarr = g["time"]
        if len(tarr.shape) != 1:
            raise InvalidInputError(f"{path}: variable time must be 1-D, got shape {tuple(tarr.shape)}")
        T = int(tarr.shape[0])
        lead = (int(np.prod(self.batch_shape)),) if self.batch_shape else ()
        self.variables = tuple(v for v in ("quaternion", "omega", "M", "m", "energy", "gibbs") if v in names)
        for nm in self.variables:
            tail = {"quaternion": (4,), "energy": ()}.get(nm, (3,))
            if tuple(g[nm].shape) != lead + (T,) + tail:
                raise InvalidInputError(
                    f"{path}: variable {nm} has shape {tuple(g[nm].shape)}, expected {lead + (T,) + tail} "
                    f"(batch_shape {list(self.batch_shape)}, {T} times)"
                )
        with _decoding(path, "inertia"):
            inertia = np.asarray(g["inertia"][...], dtype=float)
        if inertia.shape != lead + (3, 3):
            raise InvalidInputError(f"{path}: variable inertia has shape {inertia.shape}, expected {lead + (3, 3)}")
        if self.batch_shape:
            inertia = inertia.reshape(self.batch_shape + (3, 3))
        name = attrs.get("body_name") or None
        try:
            if "particle_masses" in names:
                with _decoding(path, "particle_masses, particle_positions or center_of_mass"):
                    masses = np.asarray(g["particle_masses"][...])
                    positions = np.asarray(g["particle_positions"][...]) + np.asarray(g["center_of_mass"][...])
                body = RigidBody.from_particles(masses, positions, name=None if name is None else str(name))
            else:
                body = RigidBody(inertia, name=None if name is None else str(name), allow_unphysical=True)
            self.model = Model(body, read_torques(path, ds))
        except (InvalidInputError, TypeError) as exc:
            raise type(exc)(f"{path}: {exc}") from exc
        self.body = body
        self.T = T
        self.chunk = int(tarr.chunks[0]) if T else 1
        self.t = StoredArray(tarr, (), store=path)
        self.quaternion = StoredArray(g["quaternion"], self.batch_shape, store=path)
        self.omega = StoredArray(g["omega"], self.batch_shape, store=path)
        self.attrs = attrs
        self._grid = None
        if T:
            first, last = self.head(), self.tail()  # checks the first and last attitudes (unit quaternions)
            self._grid = _time_grid(attrs, T, float(first.t[0]), float(last.t[-1]))

    # ------------------------------------------------------------------
    def __len__(self) -> int:
        return self.T

    def stored(self, name: str) -> StoredArray:
        """A stored time-dependent variable (``"quaternion"``, ``"omega"``, ``"M"``, ``"m"``, ``"energy"``, ``"gibbs"``)."""
        if name not in self.variables:
            raise KeyError(f"{self.path} has no variable {name!r} (it has {', '.join(self.variables)})")
        cache = self.__dict__.setdefault("_stored", {"quaternion": self.quaternion, "omega": self.omega})
        if name not in cache:
            cache[name] = StoredArray(self._group[name], self.batch_shape, store=self.path)
        return cache[name]

    def _check_unit(self, q: np.ndarray, where: str) -> None:
        from ..attitude.core import UNIT_QUATERNION_TOLERANCE

        with np.errstate(invalid="ignore", over="ignore"):
            w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
            norms = np.sqrt(w * w + x * x + y * y + z * z)
        norms = norms[np.isfinite(norms)]
        if norms.size and not np.all(np.abs(norms - 1.0) <= UNIT_QUATERNION_TOLERANCE):
            worst = float(norms[np.argmax(np.abs(norms - 1.0))])
            raise InvalidInputError(
                f"{self.path}: the quaternion variable is not made of unit quaternions ({where}: a norm of "
                f"{worst:.9g}; we write norm 1 within {UNIT_QUATERNION_TOLERANCE:g}): the store was modified or is not ours"
            )

    def read(self, a: int = 0, b: int | None = None, step: int = 1) -> Trajectory:
        """The samples ``a:b:step`` as an in-memory :class:`~eulerpoisson.trajectory.Trajectory`.

        Raises
        ------
        EulerPoissonError
            Samples not written yet (NaN: an unfinished run's partial store).
        """
        from ..trajectory import Trajectory

        a, b, step = slice(a, b, step).indices(self.T)
        t = self.t.read(a, b, step)
        q = self.quaternion.read(a, b, step)
        w = self.omega.read(a, b, step)
        self._check_unit(q, f"samples {a}:{b}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q)) and np.all(np.isfinite(w))):
            raise EulerPoissonError(self._unwritten(f"samples {a}:{b}"))
        return Trajectory(t, q, w, self.body, self.method, self.options, self.stats, torque=list(self.model.torques))

    def _unwritten(self, what: str) -> str:
        """The message for samples that read as NaN: an unfinished run's work folder (``.NAME.partial``: resume
        it), or a finished store that lost data (a chunk file deleted: write it again)."""
        if self.path.name.startswith(".") and self.path.name.endswith(".partial"):
            return (
                f"{self.path}: {what} are not all written yet (NaN): the run is unfinished; resume it with the "
                f"command that wrote it ('simulate' again, or solve_to_file(..., resume=True))"
            )
        return (
            f"{self.path}: {what} are missing (NaN) in a finished store: chunk files deleted or lost? "
            f"write it again (the command that wrote it, with --overwrite)"
        )

    def read_arrays(
        self, names: Iterable[str], a: int = 0, b: int | None = None, step: int = 1, *, scratch: dict | None = None
    ) -> dict[str, NDArray[np.float64]]:
        """The raw arrays ``names`` (``"time"`` and stored variables) at samples ``a:b:step``, without a Trajectory.

        The cheapest way through a long store: only the named variables are
        read (a plot of Ω reads ``time`` and ``omega``, nothing else).
        Quaternions read are checked to be unit; any NaN (an unwritten sample
        of a partial store) is an error. With a dict ``scratch`` the arrays
        are read into those it holds from an earlier call (same names and
        shapes; fresh memory costs a page fault per 4 kB), and it keeps
        the arrays read: the caller must be done with them before the next call.
        """
        a, b, step = slice(a, b, step).indices(self.T)
        out = {}
        for nm in names:
            buf = None if scratch is None or self.batch_shape else scratch.get(nm)
            if nm == "time" and self._grid is not None:  # equally spaced times: computed, bit for bit those stored
                out[nm] = _grid_times(self._grid, a, b, step, out=buf)
                if scratch is not None:
                    scratch[nm] = out[nm]
                continue
            arr = self.t if nm == "time" else self.stored(nm)
            x = arr.read(a, b, step, out=buf)
            if scratch is not None and not self.batch_shape:
                scratch[nm] = x
            if nm == "quaternion":
                self._check_unit(x, f"samples {a}:{b}")
            if nm != "gibbs" and not _all_finite(x):
                raise EulerPoissonError(self._unwritten(f"samples {a}:{b} of {nm}"))
            out[nm] = x
        return out

    def iter_arrays(
        self, names: Iterable[str], size: int | None = None, ranges: Iterable[tuple[int, int]] | None = None
    ) -> Iterator[dict[str, NDArray[np.float64]]]:
        """:meth:`read_arrays` piece by piece (``size`` samples, whole Zarr chunks; or the given ``(a, b)`` ranges).

        The next pieces are read in background threads while the caller works on the current one.
        """
        return self.map_arrays(names, None, size, ranges)

    def map_arrays(
        self,
        names: Iterable[str],
        fn: Callable[[dict[str, NDArray[np.float64]]], Any] | None = None,
        size: int | None = None,
        ranges: Iterable[tuple[int, int]] | None = None,
        workers: int | None = None,
        reuse: bool = False,
    ) -> Iterator[Any]:
        """``fn(piece)`` for the pieces of :meth:`iter_arrays`, in order, each read and computed in a thread.

        The chunks are decoded in parallel (numcodecs and NumPy release the
        GIL): with ``workers`` threads (default :func:`read_workers`) at most
        ``workers + 1`` pieces are in flight, so memory stays bounded by
        the piece size. ``fn=None`` yields the pieces themselves. With
        ``reuse=True`` (and an ``fn``) each thread reads its pieces into the
        same arrays (``read_arrays(scratch=...)``): ``fn`` must not keep or
        return them (a reduction of them, such as a min/max envelope, is fine).
        """
        ranges = list(self.chunk_bounds(size) if ranges is None else ranges)

        def task(r):
            scratch = _LOCAL.__dict__.setdefault("scratch", {}) if reuse and fn is not None else None
            piece = self.read_arrays(names, *r, scratch=scratch)
            return piece if fn is None else fn(piece)

        return ordered_map(task, ranges, workers)

    def __getitem__(self, index: Any) -> Trajectory:
        if isinstance(index, slice):
            return (
                self.read(index.start or 0, index.stop, index.step or 1)
                if (index.step or 1) > 0
                else self.load()[index]
            )
        if isinstance(index, (int, np.integer)) and not isinstance(index, (bool, np.bool_)):
            i = int(index) + (self.T if index < 0 else 0)
            if not 0 <= i < self.T:
                raise IndexError(f"sample {index} out of range for {self.T} samples")
            return self.read(i, i + 1)
        if isinstance(index, (tuple, float, np.floating, str, bool, np.bool_)):
            raise TypeError(f"a trajectory is indexed by sample (int, slice or integer array), got {index!r}")
        idx = np.atleast_1d(np.asarray(index))
        if idx.dtype == bool:
            if idx.shape != (self.T,):
                raise IndexError(f"boolean index of shape {idx.shape} for {self.T} samples")
            idx = np.flatnonzero(idx)
        if idx.size and not np.issubdtype(idx.dtype, np.integer):
            raise TypeError(f"a trajectory is indexed by sample (int, slice or integer array), got {index!r}")
        idx = idx.astype(np.int64)
        if np.any((idx < -self.T) | (idx >= self.T)):
            raise IndexError(f"sample index out of range for {self.T} samples")
        idx = np.where(idx < 0, idx + self.T, idx)
        if idx.size == 0:
            return self.read(0, 0)
        return self.gather(idx)

    def gather(self, idx: ArrayLike) -> Trajectory:
        """The samples ``idx`` (any integers in range, any order) as a Trajectory; each Zarr chunk is read once."""
        from ..trajectory import Trajectory

        idx = np.asarray(idx, dtype=np.int64)
        order = np.argsort(idx, kind="stable")
        srt = idx[order]
        blocks = srt // self.chunk
        cut = np.flatnonzero(np.diff(blocks)) + 1
        parts = []
        for grp in np.split(srt, cut):
            lo, hi = int(grp[0]), int(grp[-1]) + 1
            raw = self.read_arrays(("time", "quaternion", "omega"), lo, hi)
            k = grp - lo
            parts.append((raw["time"][k], raw["quaternion"][..., k, :], raw["omega"][..., k, :]))
        t = np.concatenate([p[0] for p in parts])
        q = np.concatenate([p[1] for p in parts], axis=-2)
        w = np.concatenate([p[2] for p in parts], axis=-2)
        inv = np.empty_like(order)
        inv[order] = np.arange(order.size)
        return Trajectory(
            t[inv],
            q[..., inv, :],
            w[..., inv, :],
            self.body,
            self.method,
            self.options,
            self.stats,
            torque=list(self.model.torques),
            keep_signs=True,  # the stored signs (continuous over the whole run): a selection never flips one
        )

    def head(self, n: int = 1) -> Trajectory:
        """The first ``n`` samples (a Trajectory)."""
        return self.read(0, min(n, self.T))

    def tail(self, n: int = 1) -> Trajectory:
        """The last ``n`` samples (a Trajectory)."""
        return self.read(max(0, self.T - n), self.T)

    def chunk_bounds(self, size: int | None = None) -> list[tuple[int, int]]:
        """``(a, b)`` sample ranges of ``size`` (default: the store's chunk) covering the store."""
        size = int(size or self.chunk)
        size = max(1, -(-size // self.chunk) * self.chunk)  # whole Zarr chunks
        return [(a, min(self.T, a + size)) for a in range(0, self.T, size)]

    def iter_chunks(self, size: int | None = None) -> Iterator[Trajectory]:
        """In-memory trajectories of consecutive pieces of the store, ``size`` samples each (whole Zarr chunks)."""
        for a, b in self.chunk_bounds(size):
            yield self.read(a, b)

    def load(self, *, limit: int | None = LOAD_LIMIT) -> Trajectory:
        """The whole store as an in-memory Trajectory.

        Raises
        ------
        EulerPoissonError
            More than ``limit`` samples (pass ``limit=None`` to read them anyway).
        """
        if limit is not None and self.T * max(1, int(np.prod(self.batch_shape))) > limit:
            raise EulerPoissonError(
                f"{self.path} has {self.T} samples, more than {limit} to load into memory "
                "(about 100 bytes each); read a part (lazy[a:b], iter_chunks()) or pass limit=None"
            )
        return self.read(0, self.T)

    # ------------------------------------------------------------------
    def drift_endpoints(self) -> dict:
        """Relative change of every integral from the first to the last sample (reads two samples).

        The drift of :meth:`Trajectory.drift` is a maximum over all samples;
        for a long store this is its value at the end, which costs nothing.
        """
        from ..trajectory import Trajectory

        if self.T == 0:
            raise InvalidInputError("drift of a store with no output times")
        h, tl = self.head(), self.tail()
        both = Trajectory(
            np.concatenate([h.t, tl.t]),
            np.concatenate([h.quaternion, tl.quaternion], axis=-2),
            np.concatenate([h.omega, tl.omega], axis=-2),
            self.body,
            self.method,
            torque=list(self.model.torques),
            keep_signs=True,
        )
        return both.drift()

    def plot(self, kind: str = "omega", **kwargs: Any) -> Figure:
        """A picture of the stored trajectory, drawn chunk by chunk: :func:`eulerpoisson.viz.plots.plot`."""
        from ..viz import plots

        return plots.plot(self, kind, **kwargs)

    def __repr__(self) -> str:
        b = f", batch_shape={self.batch_shape}" if self.batch_shape else ""
        return f"LazyTrajectory({str(self.path)!r}, method={self.method!r}, T={self.T}{b})"

    def _repr_html_(self) -> str:
        """HTML view for notebooks, drawn from a few samples spread over the store (a few chunks read, not the file).

        See :func:`eulerpoisson.util.htmlrepr.trajectory_html`.
        """
        from ..util.htmlrepr import trajectory_html

        return trajectory_html(self)
