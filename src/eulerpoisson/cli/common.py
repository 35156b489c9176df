"""What the commands of the ``eulerpoisson`` command line share.

The usage error and its exit status, the one-line-error argument parser,
the parsing of numbers, inertia tensors, file names and TOML files, the
reading of a trajectory file and the one-line text of an exception.
"""

from __future__ import annotations

import argparse
import contextlib
import os
from pathlib import Path

import numpy as np

from ..errors import EulerPoissonError, MissingDependencyError, UsageError

__all__ = [
    "EXIT_USAGE",
    "UsageError",
    "Parser",
    "parse_floats",
    "inertia_from",
    "check_file_name",
    "load_toml",
    "naming_target",
    "read_trajectory",
    "error_message",
]

EXIT_USAGE = 2


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message):  # noqa: D401 - argparse API
        raise UsageError(f"{self.prog}: {message} (see '{self.prog} --help')")


# ---------------------------------------------------------------------------
# parsing helpers
# ---------------------------------------------------------------------------
def parse_floats(text, name: str, sizes: tuple[int, ...]) -> list[float]:
    if isinstance(text, (list, tuple)):
        vals = text
    else:
        parts = [p for p in str(text).replace(";", ",").replace(" ", ",").split(",") if p != ""]
        vals = []
        for p in parts:
            if not p.isascii():
                raise UsageError(
                    f"{name}: {p!r} is not a number written in ASCII digits (expected "
                    f"{' or '.join(map(str, sizes))} comma-separated numbers)"
                )
            try:
                vals.append(float(p))
            except ValueError:
                raise UsageError(
                    f"{name}: {p!r} is not a number (expected {' or '.join(map(str, sizes))} comma-separated numbers)"
                ) from None
    try:
        arr = np.asarray(vals, dtype=float)
    except (TypeError, ValueError):
        raise UsageError(f"{name}: expected numbers, got {text!r}") from None
    arr = arr.ravel()
    if arr.size not in sizes:
        raise UsageError(f"{name}: expected {' or '.join(map(str, sizes))} numbers, got {arr.size} ({text!r})")
    if not np.all(np.isfinite(arr)):
        raise UsageError(f"{name}: values must be finite, got {text!r}")
    return arr.tolist()


def inertia_from(value, name="--inertia"):
    v = parse_floats(value, name, (3, 9))
    return np.array(v) if len(v) == 3 else np.array(v).reshape(3, 3)


def check_file_name(value, name: str) -> None:
    """Reject an empty (or blank) file name given to option ``name``."""
    if value is not None and not str(value).strip():
        raise UsageError(f"{name}: empty file name")


def load_toml(path: str) -> dict:
    import tomllib

    check_file_name(path, "configuration file")
    p = Path(path)
    if not p.exists():
        raise UsageError(f"configuration file {path!r} does not exist")
    if not p.is_file():
        raise UsageError(f"configuration file {path!r} is not a file")
    try:
        with open(p, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise UsageError(f"{path}: invalid TOML: {exc}") from None
    except RecursionError:
        raise UsageError(f"{path}: invalid TOML: nested too deeply (a configuration has two levels)") from None
    except UnicodeDecodeError as exc:
        raise UsageError(
            f"{path}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at position {exc.start}); "
            "a TOML file must be UTF-8"
        ) from None


@contextlib.contextmanager
def naming_target(target):
    """Re-word an OSError about a helper file next to ``target`` (``.NAME.partial``, ...) to name ``target``."""
    try:
        yield
    except OSError as exc:
        dest = Path(os.path.abspath(str(target)))

        def helper(f) -> bool:  # dest's hidden sibling ``.NAME...`` or anything inside one
            q = Path(os.path.abspath(os.fsdecode(f)))
            return any(a.parent == dest.parent and a.name.startswith(f".{dest.name}") for a in (q, *q.parents))

        for f in (exc.filename, exc.filename2):
            if isinstance(f, (str, bytes)) and helper(f):
                reason = exc.strerror or error_message(exc)
                raise (
                    OSError(exc.errno, f"cannot write {target}: {reason}")
                    if exc.errno is not None
                    else OSError(f"cannot write {target}: {reason}")
                ) from exc
        raise


def read_trajectory(path):
    """The trajectory in ``path``: NetCDF-4 or NetCDF-3 (in memory), or a .zarr store (read lazily)."""
    from ..io.formats import file_format
    from ..trajectory import Trajectory

    check_file_name(path, "trajectory file")
    if not os.path.exists(path):
        raise UsageError(f"{path}: no such file (write one with 'eulerpoisson simulate ... --out {path}')")
    if os.path.isdir(path) and file_format(path) != "zarr":
        raise UsageError(
            f"{path} is a directory, not a trajectory file (a NetCDF file or a .zarr store, written by "
            "'eulerpoisson simulate --out')"
        )
    try:
        return Trajectory.open(path)
    except MissingDependencyError:
        raise
    except (EulerPoissonError, ValueError, TypeError, LookupError, AttributeError) as exc:
        # a malformed file: make sure the message says which file
        msg = error_message(exc)
        if str(path) in msg:
            raise
        raise EulerPoissonError(f"{path}: not a valid eulerpoisson trajectory file: {msg}") from exc


def error_message(exc: BaseException) -> str:
    """The first non-empty line of an exception's message (the type name if it has none)."""
    if isinstance(exc, KeyError) and len(exc.args) == 1 and isinstance(exc.args[0], str):
        text = exc.args[0]  # str(KeyError) is the repr of its argument
    elif isinstance(exc, OSError) and exc.strerror and exc.filename is None:
        text = exc.strerror  # without the "[Errno N]" prefix
    else:
        text = str(exc)
    for line in text.splitlines():
        if line.strip():
            return line.strip()
    return type(exc).__name__
