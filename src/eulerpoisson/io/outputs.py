r"""One policy for every output a command writes: nothing replaced, deleted or overwritten by surprise.

Every command that writes a file (``simulate --out``, ``sweep --out``,
``audit --out``) checks its output with :func:`check_output` before any work:

- an existing output is replaced only with ``--overwrite`` (``overwrite=True``);
- never an input of the same command (the configuration file, the trajectory
  being plotted), even with ``--overwrite``;
- never a file of another kind, even with ``--overwrite``: a NetCDF
  trajectory is replaced only by a NetCDF file, a trajectory store by a
  trajectory store, a sweep store by a sweep store, a text or picture by a
  file that is neither a NetCDF file nor a store, and a folder that is not a
  store of ours never;

and holds an :class:`OutputLock` while it writes, so that two processes
writing to one path do not corrupt it: the second fails at once, naming the
first. Atomic writes (:mod:`.atomic`) keep the mode of a file they replace.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterable
from pathlib import Path

from ..errors import OutputError

__all__ = ["OutputError", "file_kind", "check_output", "OutputLock", "KINDS"]

#: what a command writes
KINDS = ("netcdf", "trajectory-store", "sweep-store", "file")

_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_CDF_SIGNATURES = (b"CDF\x01", b"CDF\x02", b"CDF\x05")


def file_kind(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` holds: ``"netcdf"``, ``"trajectory-store"``, ``"sweep-store"``, ``"zarr"`` (another store),
    ``"folder"``, ``"file"``, or None when it does not exist."""
    p = Path(path)
    if not p.exists():
        return None
    if p.is_dir():
        meta = p / "zarr.json" if (p / "zarr.json").exists() else (p / ".zattrs" if (p / ".zattrs").exists() else None)
        if meta is None and not (p / ".zgroup").exists():
            return "folder"
        attrs: dict = {}
        try:
            if meta is not None:  # a v2 group without attributes has none
                with open(meta, encoding="utf-8") as fh:
                    doc = json.load(fh)
                attrs = doc.get("attributes", doc) if isinstance(doc, dict) else {}
        except (OSError, ValueError, TypeError):
            pass
        if "sweep_format_version" in attrs:
            return "sweep-store"
        if "eulerpoisson_format_version" in attrs:
            return "trajectory-store"
        return "zarr"
    try:
        with open(p, "rb") as fh:
            head = fh.read(8)
    except OSError:
        return "file"
    if head.startswith(_HDF5_SIGNATURE) or head[:4] in _CDF_SIGNATURES:
        return "netcdf"
    return "file"


def _same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def check_output(
    path: str | os.PathLike[str],
    writes: str,
    *,
    overwrite: bool = False,
    inputs: Iterable[str | os.PathLike[str]] = (),
    flag: str = "--overwrite",
) -> None:
    """Refuse an output that must not be written (before any work is done).

    Parameters
    ----------
    path : str or path
        The output.
    writes : str
        What will be written there, one of :data:`KINDS`.
    overwrite : bool
        Whether an existing output of the same kind may be replaced.
    inputs : iterable of paths
        The inputs of the command (never overwritten).
    flag : str
        How the user says "overwrite" (named in the message).

    Raises
    ------
    OutputError
        ``path`` is an input; exists and ``overwrite`` is False; exists and
        holds another kind of data.
    ValueError
        An unknown ``writes``.
    """
    if writes not in KINDS:
        raise ValueError(f"writes must be one of {', '.join(KINDS)}, got {writes!r}")
    for src in inputs:
        if src is not None and Path(path).exists() and _same_file(path, src):
            raise OutputError(f"refusing to write {path}: it is an input of this command")
        if src is not None and not Path(path).exists() and os.path.abspath(path) == os.path.abspath(src):
            raise OutputError(f"refusing to write {path}: it is an input of this command")
    have = file_kind(path)
    if have is None:
        return
    if have == "folder":
        raise OutputError(
            f"cannot write {path}: it is an existing directory, not a store of ours (--overwrite never replaces it)"
        )
    if not overwrite:
        raise OutputError(f"{path} exists; run again with {flag} to replace it")
    compatible = {
        "netcdf": ("netcdf",),
        "trajectory-store": ("trajectory-store",),
        "sweep-store": ("sweep-store",),
        "file": ("file",),
    }[writes]
    if have not in compatible:
        what = {
            "netcdf": "a NetCDF file",
            "trajectory-store": "a trajectory store (.zarr)",
            "sweep-store": "a sweep store (.zarr)",
            "zarr": "a Zarr store that is not ours",
            "folder": "a folder",
            "file": "a file that is not NetCDF",
        }[have]
        raise OutputError(
            f"refusing to replace {path}: it is {what}, and this command writes "
            f"{ {'netcdf': 'a NetCDF file', 'trajectory-store': 'a trajectory store', 'sweep-store': 'a sweep store', 'file': 'a plain file'}[writes] } "
            f"({flag} replaces only an output of the same kind)"
        )


def pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class OutputLock:
    """An exclusive lock on an output path: ``<path>.lock`` created with ``O_EXCL``, holding the owner's pid.

    A lock left by a process that no longer runs (killed) is taken over.

    Raises
    ------
    OutputError
        On entry, when another running process holds the lock.
    """

    def __init__(self, path):
        p = Path(path)
        self.path = p
        self.lock = p.with_name(f".{p.name}.lock")
        self._fd = None

    def __enter__(self) -> OutputLock:
        from .atomic import write_error

        try:
            self.lock.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise write_error(self.path, exc) from None
        for _ in range(2):
            try:
                self._fd = os.open(self.lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
                os.write(self._fd, str(os.getpid()).encode())
                return self
            except OSError as exc:
                if not isinstance(exc, FileExistsError):
                    raise write_error(self.path, exc) from None
                try:
                    pid = int(self.lock.read_text().strip() or "0")
                except (OSError, ValueError):
                    pid = 0
                if pid and pid != os.getpid() and pid_alive(pid):
                    raise OutputError(
                        f"{self.path} is being written by another process (pid {pid}); wait for it "
                        f"to finish, or write to another file"
                    ) from None
                with contextlib.suppress(OSError):
                    self.lock.unlink()  # stale: its process is gone
        raise OutputError(f"cannot lock {self.path} ({self.lock} keeps coming back)")

    def __exit__(self, *exc) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
            with contextlib.suppress(OSError):
                self.lock.unlink()
