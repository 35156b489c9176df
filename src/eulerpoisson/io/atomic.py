"""Atomic file writes (private).

Results are written to a temporary file in the destination folder and moved
into place with :func:`os.replace`, so an interrupted run (Ctrl-C, a crash, a
full disk) never leaves a half-written file under the final name.

Errors name the file the caller asked for, never the temporary file: a
failure to write raises :class:`OSError` (the subclass and ``errno`` of the
original error, e.g. :class:`FileNotFoundError`) with the message
``cannot write PATH: REASON; WHAT TO DO`` (the advice for a full disk, a
read-only file system or a folder without write permission).

A command that claims an output (:func:`eulerpoisson.io.outputs.claim_output`)
registers a check with :func:`guard_replace`: every atomic write to that path
runs it just before the rename, so that an output that appeared meanwhile is
not replaced.
"""

from __future__ import annotations

import contextlib
import errno as _errno
import glob
import os
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from ..errors import InvalidInputError

#: what to do about a failed write, by errno
WRITE_ADVICE = {
    _errno.ENOSPC: "free some space on that disk or write to another one",
    _errno.EDQUOT: "free some space within your disk quota or write to another disk",
    _errno.EROFS: "its file system is read-only: write to a folder on a writable disk",
    _errno.EACCES: "you may not write in that folder: write to another folder or change its permissions",
    _errno.EPERM: "you may not write there: write to another folder or change its permissions",
    _errno.EMFILE: "too many open files: close other programs or raise the limit (ulimit -n)",
}

#: checks run just before an atomic rename to a path (absolute path -> check), see :func:`guard_replace`
_GUARDS: dict[str, Callable[[], None]] = {}


def _target(path) -> Path:
    """Check a destination file name: not empty, not an existing directory."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or os.PathLike), got {type(path).__name__} {path!r}")
    text = os.fspath(path)
    if not str(text).strip():
        raise InvalidInputError("cannot write a file with an empty name; give a file name")
    dest = Path(text)
    if dest.is_dir():
        raise IsADirectoryError(_errno.EISDIR, f"cannot write {text}: it is an existing directory; give a file name")
    return dest


def write_error(dest, exc: OSError) -> OSError:
    """``exc`` re-worded to name ``dest`` (the caller's file) and say what to do, keeping its errno and class.

    Examples
    --------
    >>> import errno
    >>> str(write_error("out/r.nc", OSError(errno.EROFS, "Read-only file system", "out/.r.nc.x.tmp")))
    '[Errno 30] cannot write out/r.nc: Read-only file system; its file system is read-only: write to a folder on a writable disk'
    """
    reason = exc.strerror or str(exc) or type(exc).__name__
    if exc.errno in (_errno.EEXIST, _errno.ENOTDIR):
        # a folder of the path is a file ("File exists" from mkdir, "Not a directory" from open)
        blocking = next((p for p in Path(os.fspath(dest)).parents if p.exists()), None)
        if blocking is not None and not blocking.is_dir():
            return OSError(exc.errno, f"cannot write {dest}: {blocking} is a file, not a folder")
    advice = WRITE_ADVICE.get(exc.errno) if exc.errno is not None else None
    if advice and advice not in reason:
        reason = f"{reason}; {advice}"
    if exc.errno is None:
        return OSError(f"cannot write {dest}: {reason}")
    return OSError(exc.errno, f"cannot write {dest}: {reason}")  # OSError(errno, ...) picks the subclass


def _names_tmp(exc: OSError, tmp: str) -> bool:
    return tmp in (exc.filename, exc.filename2) or os.path.basename(tmp) in str(exc)


@contextlib.contextmanager
def guard_replace(path, check: Callable[[], None]) -> Iterator[None]:
    """Run ``check()`` just before every atomic rename to ``path`` made meanwhile (in this process).

    ``check`` raises to stop the rename: the temporary file is removed and
    ``path`` is left as it is.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> def refuse():
    ...     raise FileExistsError("no")
    >>> with guard_replace(os.path.join(d, "a.txt"), refuse):
    ...     atomic_write_text(os.path.join(d, "a.txt"), "x")
    Traceback (most recent call last):
    ...
    FileExistsError: no
    >>> os.listdir(d)
    []
    """
    key = os.path.abspath(os.fspath(path))
    previous = _GUARDS.get(key)
    _GUARDS[key] = check
    try:
        yield
    finally:
        if previous is None:
            _GUARDS.pop(key, None)
        else:
            _GUARDS[key] = previous


def check_guard(path) -> None:
    """Run the check registered for ``path`` with :func:`guard_replace` (nothing when there is none).

    For writers that move a whole folder into place rather than a file
    (:func:`atomic_path` calls it itself).
    """
    check = _GUARDS.get(os.path.abspath(os.fspath(path)))
    if check is not None:
        check()


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path next to ``path``; on success rename it to ``path``.

    On any exception (including ``KeyboardInterrupt``) the temporary file is
    removed and the previous content of ``path``, if any, is untouched.

    Raises
    ------
    InvalidInputError
        ``path`` is empty.
    IsADirectoryError
        ``path`` is an existing directory.
    OSError
        The file cannot be written (missing or read-only folder, full disk,
        ...): the message is ``cannot write PATH: REASON``, naming ``path``
        (not the temporary file); ``errno`` and the subclass are those of the
        original error.
    """
    dest = _target(path)
    parent = dest.parent if str(dest.parent) else Path(".")
    _remove_stale_temporaries(dest, parent, suffix or ".tmp")
    try:
        parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=suffix or ".tmp", dir=parent)
    except OSError as exc:
        raise write_error(dest, exc) from exc
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
    try:
        try:
            yield tmp
        except OSError as exc:
            if _names_tmp(exc, tmp):
                raise write_error(dest, exc) from exc
            raise
        check_guard(dest)  # the output's claim: checked again just before the rename
        try:
            if dest.is_file():  # a replaced file keeps its permissions
                os.chmod(tmp, stat.S_IMODE(os.stat(dest).st_mode))
            os.replace(tmp, dest)
        except OSError as exc:
            raise write_error(dest, exc) from exc
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _remove_stale_temporaries(dest: Path, parent: Path, suffix: str) -> None:
    """Remove the temporary files a killed writer left next to ``dest`` (not while another process holds its lock)."""
    lock = parent / f".{dest.name}.lock"
    if lock.exists():
        try:
            pid = int(lock.read_text().strip() or "0")
        except (OSError, ValueError):
            pid = 0
        if pid and pid != os.getpid():
            try:
                os.kill(pid, 0)
                return  # a live writer: its temporary file is not stale
            except ProcessLookupError:
                pass
            except PermissionError:
                return
    for old in parent.glob(f".{glob.escape(dest.name)}.*{glob.escape(suffix)}"):
        with contextlib.suppress(OSError):
            if old.is_file():
                old.unlink()


def atomic_write_text(path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically.

    Raises
    ------
    InvalidInputError, IsADirectoryError, OSError
        As :func:`atomic_path`: an empty name, an existing directory, or a
        failure to write (the message names ``path``).
    """
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding=encoding) as fh:
            fh.write(text)
