r"""One policy for every output a command writes: nothing replaced, deleted or overwritten by surprise.

Every command that writes a file (``simulate --out``, ``sweep --out``,
``audit --out``, ``fit --out``, ``validate --plot``, ``plot --out``,
``animate --out``, ``cases --out``) claims its output with
:func:`claim_output` before any work:

- the name is checked (:func:`check_output_name`): no control character
  (a newline), not only a suffix (``.nc``), no trailing slash for a file;
- an existing output is replaced only with ``--overwrite`` (``overwrite=True``);
- never an input of the same command (the configuration file, a file the
  configuration names, the trajectory being plotted), even with
  ``--overwrite``;
- never a file of another kind, even with ``--overwrite``: what is there is
  recognized by its content (:func:`content_kind`): a NetCDF/HDF5 signature,
  the metadata of our Zarr stores, the PNG/GIF/MP4/PDF/SVG signatures, and
  the marker we write into our JSON, Markdown, HTML and TeX files
  (:func:`mark_text`); a TOML, CSV or Python file, or any unknown file, is
  never replaced;

then holds an :class:`OutputLock` while it works and writes, so that a second
process writing to the same path fails at once, naming the first; the output
is checked again under the lock, and once more just before the final rename
(:func:`eulerpoisson.io.atomic.guard_replace`). Atomic writes (:mod:`.atomic`)
keep the mode of a file they replace.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path

from ..errors import InvalidInputError, OutputError
from .formats import file_format, is_zarr_store

__all__ = [
    "OutputError",
    "file_kind",
    "content_kind",
    "check_output",
    "check_output_name",
    "claim_output",
    "mark_text",
    "OutputLock",
    "KINDS",
    "REPLACES",
]

#: what a command writes
KINDS = (
    "netcdf",
    "trajectory-store",
    "sweep-store",
    "figure",
    "movie",
    "audit-report",
    "fit-result",
    "cases",
    "file",
)

#: what an output of each kind may replace with ``--overwrite``: the kinds of :func:`content_kind`
REPLACES: dict[str, tuple[str, ...]] = {
    "netcdf": ("netcdf",),
    "trajectory-store": ("trajectory-store",),
    "sweep-store": ("sweep-store",),
    "figure": ("png", "svg", "pdf"),
    "movie": ("gif", "mp4", "animation"),
    "audit-report": ("audit-report",),
    "fit-result": ("fit-result",),
    "cases": ("cases",),
    # any plain file of ours (a picture, a movie, a marked report or result)
    "file": ("png", "svg", "pdf", "gif", "mp4", "animation", "audit-report", "fit-result"),
}

#: the kinds of folder written (a trailing slash is fine in their names)
_FOLDER_KINDS = ("trajectory-store", "sweep-store", "cases")

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_GIF_SIGNATURES = (b"GIF87a", b"GIF89a")
_HEAD = 4096  # bytes read to recognize a file
#: the marker in our text files: ``<!-- written by eulerpoisson 0.2.0: audit-report -->`` or ``% written by ...``
_MARKER_LINE = re.compile(rb"^(?:<!--|%) written by eulerpoisson (\S+): ([a-z][a-z-]*)(?: -->)?\s*$", re.MULTILINE)
_MARKER_JSON = re.compile(rb'^\s*\{\s*"eulerpoisson"\s*:\s*\{\s*"kind"\s*:\s*"([a-z][a-z-]*)"')

_DESCRIPTION = {
    "netcdf": "a NetCDF file",
    "trajectory-store": "a trajectory store (.zarr)",
    "sweep-store": "a sweep store (.zarr)",
    "zarr": "a Zarr store that is not ours",
    "folder": "a folder that is not ours",
    "cases": "a folder of reference cases",
    "png": "a PNG picture",
    "svg": "an SVG picture",
    "pdf": "a PDF document",
    "gif": "a GIF movie",
    "mp4": "an MP4 movie",
    "animation": "an animation page written by eulerpoisson",
    "audit-report": "an audit report written by eulerpoisson",
    "fit-result": "a fit result written by eulerpoisson",
    "file": "a file that eulerpoisson did not write (a configuration, data, text?)",
}
_WRITES = {
    "netcdf": "a NetCDF file",
    "trajectory-store": "a trajectory store",
    "sweep-store": "a sweep store",
    "figure": "a figure",
    "movie": "a movie",
    "audit-report": "an audit report",
    "fit-result": "a fit result",
    "cases": "a folder of reference cases",
    "file": "a file",
}


def file_kind(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` holds: ``"netcdf"``, ``"trajectory-store"``, ``"sweep-store"``, ``"zarr"`` (another store),
    ``"folder"``, ``"file"``, or None when it does not exist."""
    p = Path(path)
    if not p.exists():
        return None
    if p.is_dir():
        if not is_zarr_store(p):
            return "folder"
        meta = p / "zarr.json" if (p / "zarr.json").exists() else (p / ".zattrs" if (p / ".zattrs").exists() else None)
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
    return "netcdf" if file_format(p) in ("netcdf4", "netcdf3") else "file"


def _empty_file(path) -> bool:
    """A regular file of 0 bytes (not a link to one)."""
    try:
        st = os.lstat(path)
    except OSError:
        return False
    return stat.S_ISREG(st.st_mode) and st.st_size == 0


def _same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def content_kind(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` holds, recognized by its content (never by its name).

    Returns
    -------
    str or None
        None (nothing there); for a folder ``"trajectory-store"``,
        ``"sweep-store"``, ``"zarr"`` (another store), ``"cases"`` (a folder
        of reference cases written by ``eulerpoisson cases``) or ``"folder"``;
        for a file ``"netcdf"`` (NetCDF-3 or HDF5 signature), ``"png"``,
        ``"gif"``, ``"mp4"``, ``"pdf"``, ``"svg"`` (their signatures), the
        kind named by our marker (``"audit-report"``, ``"fit-result"``,
        ``"animation"``, ...: :func:`mark_text`), else ``"file"`` (unknown:
        a configuration, data, text, source).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> with open(os.path.join(d, "a.json"), "w") as fh:
    ...     _ = fh.write(mark_text('{"chi2": 1.0}', "fit-result", "json"))
    >>> content_kind(os.path.join(d, "a.json"))
    'fit-result'
    >>> with open(os.path.join(d, "run.toml"), "w") as fh:
    ...     _ = fh.write("[body]\\ninertia = [1, 2, 3]\\n")
    >>> content_kind(os.path.join(d, "run.toml")), content_kind(os.path.join(d, "none"))
    ('file', None)
    """
    kind = file_kind(path)
    p = Path(path)
    if kind == "folder":
        return "cases" if _is_cases_folder(p) else "folder"
    if kind != "file":
        return kind
    try:
        with open(p, "rb") as fh:
            head = fh.read(_HEAD)
    except OSError:
        return "file"
    if head.startswith(_PNG_SIGNATURE):
        return "png"
    if head[:6] in _GIF_SIGNATURES:
        return "gif"
    if head[4:8] == b"ftyp":
        return "mp4"
    if head.startswith(b"%PDF-"):
        return "pdf"
    m = _MARKER_JSON.match(head) or _MARKER_LINE.search(head[:1024])
    if m is not None:
        return m.group(m.lastindex or 1).decode("ascii")
    text = head.lstrip()
    if (text.startswith(b"<?xml") or text.startswith(b"<svg")) and b"<svg" in head:
        return "svg"
    return "file"


def _is_cases_folder(p: Path) -> bool:
    """A folder written by ``eulerpoisson cases``: its ``cases.json`` index lists the cases by name."""
    index = p / "cases.json"
    if not index.is_file():
        return False
    try:
        with open(index, encoding="utf-8") as fh:
            doc = json.load(fh)
    except (OSError, ValueError):
        return False
    return (
        isinstance(doc, list)
        and bool(doc)
        and all(isinstance(c, dict) and {"name", "inertia", "omega0"} <= set(c) for c in doc)
    )


def mark_text(text: str, kind: str, fmt: str) -> str:
    """``text`` with our marker, so that ``--overwrite`` later recognizes it as ours (:func:`content_kind`).

    Parameters
    ----------
    text : str
        What is written.
    kind : str
        What it is, e.g. ``"audit-report"``, ``"fit-result"``, ``"animation"``.
    fmt : {"json", "md", "html", "tex"}
        Its format: a JSON object gets the first key ``"eulerpoisson": {"kind": ..., "version": ...}``;
        Markdown and HTML an HTML comment ``<!-- written by eulerpoisson VERSION: KIND -->`` (after the
        doctype); TeX a comment line ``% written by eulerpoisson VERSION: KIND``.

    Returns
    -------
    str

    Raises
    ------
    InvalidInputError
        An unknown ``fmt``, a ``kind`` that is not lowercase words joined by
        ``-``, or JSON text that is not an object.

    Examples
    --------
    >>> print(mark_text("# Audit", "audit-report", "md").replace(_version(), "V"))
    <!-- written by eulerpoisson V: audit-report -->
    # Audit
    >>> import json
    >>> json.loads(mark_text('{"a": 1}', "fit-result", "json"))["eulerpoisson"]["kind"]
    'fit-result'
    """
    if not isinstance(kind, str) or not re.fullmatch(r"[a-z][a-z-]*", kind):
        raise InvalidInputError(f"kind must be lowercase words joined by '-', got {kind!r}")
    version = _version()
    if fmt == "json":
        body = text.lstrip()
        if not body.startswith("{"):
            raise InvalidInputError("fmt='json': the text must be a JSON object ({...})")
        rest = body[1:]
        tag = json.dumps({"kind": kind, "version": version})
        sep = "" if rest.lstrip().startswith("}") else ","
        lead = "\n  " if rest.startswith("\n") else ""
        return "{" + lead + f'"eulerpoisson": {tag}{sep}' + rest
    if fmt in ("md", "html"):
        line = f"<!-- written by eulerpoisson {version}: {kind} -->\n"
        if fmt == "html" and text.lstrip().lower().startswith("<!doctype"):
            first, nl, rest = text.partition("\n")
            return first + "\n" + line + rest if nl else first + "\n" + line
        return line + text
    if fmt == "tex":
        return f"% written by eulerpoisson {version}: {kind}\n" + text
    raise InvalidInputError(f"fmt must be one of json, md, html, tex; got {fmt!r}")


def _version() -> str:
    from ..version import package_version

    return package_version().replace(" ", "")


def check_output_name(path: str | os.PathLike[str], option: str = "--out", *, folder: bool = False) -> None:
    """Refuse an output name that cannot be what the user meant.

    Parameters
    ----------
    path : str or path
        The output's name.
    option : str
        Where it was given (named in the message), e.g. ``"--out"``.
    folder : bool
        The output is a folder (a trailing slash is fine).

    Raises
    ------
    InvalidInputError
        An empty name; a control character in it (a newline, a tab...); a
        last part that is only a suffix (``.nc``, ``out/.png``), ``.`` or
        ``..``; a trailing slash on a file's name.

    Examples
    --------
    >>> check_output_name("run.nc")
    >>> check_output_name("run\\n.nc")
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: --out 'run\\n.nc': a file name with a control character (a newline?); remove it
    >>> check_output_name(".nc")
    Traceback (most recent call last):
    ...
    eulerpoisson.errors.InvalidInputError: --out '.nc' is only a suffix; give a name before it, e.g. run.nc
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{option} must be a file name (str or os.PathLike), got {type(path).__name__}")
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if not text.strip():
        raise InvalidInputError(f"{option}: empty file name")
    if any(ord(c) < 32 or ord(c) == 127 for c in text):
        raise InvalidInputError(f"{option} {text!r}: a file name with a control character (a newline?); remove it")
    if not folder and text.endswith(("/", os.sep)):
        raise InvalidInputError(
            f"{option} {text!r} ends with '/', which names a folder; give a file name without the trailing slash"
        )
    last = os.path.basename(text.rstrip("/" + os.sep))
    if last in (".", ".."):
        raise InvalidInputError(f"{option} {text!r} names a folder ({last}); give a file name")
    if last.startswith(".") and "." not in last[1:] and last[1:].isalnum():
        raise InvalidInputError(f"{option} {text!r} is only a suffix; give a name before it, e.g. run{last}")


def check_output(
    path: str | os.PathLike[str],
    writes: str,
    *,
    overwrite: bool = False,
    inputs: Iterable[str | os.PathLike[str] | None] = (),
    flag: str = "--overwrite",
    option: str = "--out",
    replace_empty: bool = False,
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
        Every file the command reads (never overwritten): the files on the
        command line and the files a configuration names.
    flag : str
        How the user says "overwrite" (named in the message).
    option : str
        How the user gave ``path`` (named when the name is refused).
    replace_empty : bool
        Whether an empty file (0 bytes, such as ``tempfile.mkstemp`` leaves) may be written over where a
        file is written (the library's writers; the command line keeps every file it did not write).

    Raises
    ------
    OutputError
        ``path`` is an input; exists and ``overwrite`` is False; exists and
        holds another kind of data (recognized by content: :func:`content_kind`).
    InvalidInputError
        A name that cannot be meant (:func:`check_output_name`).
    ValueError
        An unknown ``writes``.

    Examples
    --------
    >>> import tempfile, os
    >>> cfg = os.path.join(tempfile.mkdtemp(), "run.toml")
    >>> with open(cfg, "w") as fh:
    ...     _ = fh.write("[time]\\nt_end = 1\\n")
    >>> try:
    ...     check_output(cfg, "audit-report", overwrite=True)
    ... except OutputError as exc:
    ...     print(str(exc).split(": ", 1)[1])
    it is a file that eulerpoisson did not write (a configuration, data, text?), and this command writes an audit
    report (--overwrite replaces only an output of the same kind; delete it yourself or choose another name)
    """
    if writes not in KINDS:
        raise ValueError(f"writes must be one of {', '.join(KINDS)}, got {writes!r}")
    check_output_name(path, option, folder=writes in _FOLDER_KINDS)
    exists = Path(path).exists()
    for src in inputs:
        if src is None:
            continue
        if (exists and _same_file(path, src)) or os.path.abspath(path) == os.path.abspath(src):
            raise OutputError(f"refusing to write {path}: it is an input of this command")
    have = content_kind(path)
    if have is None:
        return
    if replace_empty and have == "file" and writes not in _FOLDER_KINDS and _empty_file(path):
        return  # an empty file (mkstemp's): nothing in it to lose
    if writes == "cases" and have == "folder" and not any(Path(path).iterdir()):
        return  # an empty folder: written into
    if have == "folder":
        if writes == "cases":
            raise OutputError(
                f"{option} {path!r} is a folder with other files in it, not a folder of cases; "
                f"give a new or empty folder ({flag} never replaces it)"
            )
        raise OutputError(
            f"cannot write {path}: it is an existing directory, not a store of ours ({flag} never replaces it)"
        )
    if have not in REPLACES[writes]:
        what = _DESCRIPTION.get(have, "a " + have)
        if have == "file" and writes == "netcdf":
            what = "a file that is not NetCDF (a configuration, data, text?)"
        elif have == "file" and writes in ("trajectory-store", "sweep-store"):
            what = "a file, not a Zarr store (a folder) of ours (a configuration, data, text?)"
        raise OutputError(
            f"refusing to replace {path}: it is {what}, and this command writes "
            f"{_WRITES[writes]} ({flag} replaces only an output of the same kind; delete it yourself or "
            f"choose another name)"
        )
    if not overwrite:
        raise OutputError(f"{path} exists; run again with {flag} to replace it")


@contextlib.contextmanager
def claim_output(
    path: str | os.PathLike[str],
    writes: str,
    *,
    overwrite: bool = False,
    inputs: Iterable[str | os.PathLike[str] | None] = (),
    flag: str = "--overwrite",
    option: str = "--out",
) -> Iterator[Path]:
    """Claim an output for the whole work of a command: checked, locked, checked again, guarded.

    :func:`check_output`, then an :class:`OutputLock` (a second writer fails at
    once), then :func:`check_output` again under the lock (another writer
    may have finished meanwhile), and a check just before every atomic rename
    to ``path`` (:func:`eulerpoisson.io.atomic.guard_replace`): an output that
    appeared during the work is not replaced without ``overwrite``. Use it
    around the work, not only around the write.

    Parameters are those of :func:`check_output`; yields ``Path(path)``.

    Raises
    ------
    OutputError, InvalidInputError, ValueError
        As :func:`check_output`, on entry or before the rename; on entry,
        another process holds the output's lock.
    OSError
        The lock cannot be written (a read-only folder, a full disk): the
        message names ``path`` and what to do.

    Examples
    --------
    >>> import tempfile, os
    >>> from eulerpoisson.io.atomic import atomic_write_text
    >>> out = os.path.join(tempfile.mkdtemp(), "fit.json")
    >>> with claim_output(out, "fit-result"):
    ...     atomic_write_text(out, mark_text("{}", "fit-result", "json"))
    >>> content_kind(out)
    'fit-result'
    """
    from .atomic import guard_replace

    inputs = list(inputs)
    args = {"overwrite": overwrite, "inputs": inputs, "flag": flag, "option": option}
    check_output(path, writes, **args)  # type: ignore[arg-type]
    with OutputLock(path):
        check_output(path, writes, **args)  # type: ignore[arg-type]
        with guard_replace(path, lambda: check_output(path, writes, **args)):  # type: ignore[arg-type]
            yield Path(path)


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
