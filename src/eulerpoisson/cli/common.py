"""What the commands of the ``eulerpoisson`` command line share.

The usage error and its exit status, the one-line-error argument parser,
the parsing of numbers, inertia tensors, file names and TOML files, the
reading of a trajectory file, the one-line text of an exception, strict
JSON (:func:`json_text`) and the range checks of a run's scales
(:func:`check_run_scales`).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
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
    "json_text",
    "check_run_scales",
]

EXIT_USAGE = 2


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2.

    The line names the subcommand once (the program's name starts every
    error line already): ``eulerpoisson: error: simulate: argument --t-end:
    expected one argument (see 'eulerpoisson simulate --help')``.
    """

    def error(self, message):  # noqa: D401 - argparse API
        command = self.prog.partition(" ")[2]  # "eulerpoisson simulate" -> "simulate"; "eulerpoisson" -> ""
        where = f"{command}: " if command else ""
        raise UsageError(f"{where}{message} (see '{self.prog} --help')")


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


# ---------------------------------------------------------------------------
# strict JSON
# ---------------------------------------------------------------------------
def _strict(x, where: str, reasons: dict[str, str]):
    """``x`` as plain JSON values; a non-finite float becomes None and its path goes to ``reasons``."""
    if isinstance(x, dict):
        return {str(k): _strict(v, f"{where}.{k}" if where else str(k), reasons) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        x = x.tolist()
    if isinstance(x, (list, tuple)):
        return [_strict(v, f"{where}[{i}]", reasons) for i, v in enumerate(x)]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        if math.isfinite(v):
            return v
        reasons[where] = "NaN: undefined in float64" if math.isnan(v) else f"{v}: overflows float64"
        return None
    return x


def json_text(obj) -> str:
    """``obj`` as one line of strict JSON (RFC 8259: no ``NaN`` nor ``Infinity``).

    A value that is not a finite number is written ``null``, and the object
    gets a ``"non_finite"`` entry that says, for each such value (by its path),
    why it is null. NumPy scalars and arrays become plain numbers and lists.

    Examples
    --------
    >>> from eulerpoisson.cli.common import json_text
    >>> print(json_text({"energy": 1.5, "drift": {"m_norm": float("nan")}, "m": [1e308, float("inf")]}))
    {"energy": 1.5, "drift": {"m_norm": null}, "m": [1e+308, null], "non_finite": {"drift.m_norm": "NaN: ...", ...}}
    """
    reasons: dict[str, str] = {}
    clean = _strict(obj, "", reasons)
    if reasons:
        if isinstance(clean, dict):
            clean["non_finite"] = reasons
        else:
            clean = {"value": clean, "non_finite": reasons}
    return json.dumps(clean, allow_nan=False)


# ---------------------------------------------------------------------------
# the scales of a run: what float64 can hold and follow
# ---------------------------------------------------------------------------
#: the largest |m| whose square (the invariant |m|^2) is a float64 number
MAX_MOMENTUM = math.sqrt(np.finfo(float).max)


def check_run_scales(model, omega0, m0, q0, t_end: float, name) -> None:
    """Refuse a run whose numbers float64 cannot hold or follow, before it starts; the message names the flags.

    - The invariants: the energy ``1/2 omega.I omega`` and ``|m|^2`` must be
      float64 numbers: ``|m| = |I omega|`` below 1.3e154 (``--inertia`` with
      ``--omega`` or ``--m``).
    - A torque (``--gravity``, ``--com``, ...) too strong to follow: the rates
      it can drive (by the energy for a conservative torque, growing with the
      time for another one) must not turn the body through more than
      2^48 rad by ``t_end``, the range of the closed form too (a float64
      phase beyond it is noise), nor overflow.

    ``name(key)`` is the flag or ``file: [section] key`` of a configuration key.

    Raises
    ------
    UsageError
        With the values, the range and the flags to change.

    Examples
    --------
    >>> from eulerpoisson import Model, RigidBody
    >>> from eulerpoisson.cli.common import check_run_scales
    >>> from eulerpoisson.cli.config import namer
    >>> model = Model(RigidBody([1e308, 1e308, 1e308]))
    >>> try:
    ...     check_run_scales(model, [1.0, 0.1, 0.5], None, None, 1.0, namer({}))
    ... except UsageError as err:
    ...     print(err)
    the angular momentum |m| = |I omega| = 1.12e+308 of --inertia and --omega overflows float64 ...
    """
    from ..attitude.core import Attitude
    from ..model.torque_base import torque_bound
    from ..util.validate import MAX_PHASE, scaled_norms

    body = model.body
    inertia = np.asarray(body.inertia, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        if omega0 is not None:
            w = np.asarray(omega0, dtype=float)
            M = np.einsum("...ij,...j->...i", inertia, w)
            given = name("initial.omega")
        else:
            R0 = Attitude(q0).as_matrix() if q0 is not None else np.eye(3)
            M = np.einsum("...ji,...j->...i", R0, np.asarray(m0, dtype=float))
            w = np.einsum("...ij,...j->...i", np.asarray(body.inertia_inv, dtype=float), M)
            given = name("initial.m")
        m_norm = float(np.max(scaled_norms(M), initial=0.0))
        energy = float(np.max(0.5 * np.sum(w * M, axis=-1), initial=0.0))
        w_norm = float(np.max(scaled_norms(w), initial=0.0))
    if not (m_norm < MAX_MOMENTUM and math.isfinite(energy) and math.isfinite(w_norm)):
        raise UsageError(
            f"the angular momentum |m| = |I omega| = {m_norm:.3g} of {name('body.inertia')} and {given} overflows "
            f"float64 (its square |m|^2, an invariant of the motion, or the energy 1/2 omega.I omega = {energy:.3g} "
            f"is not a number): keep |I omega| below {MAX_MOMENTUM:.2g} and the energy below "
            f"{np.finfo(float).max:.2g}; write the inertia and the rates in other units"
        )
    if not model.torques or t_end == 0.0:
        return
    moments = np.asarray(body.principal_moments, dtype=float)
    i_min, i_max = float(np.min(moments)), float(np.max(moments))
    if not i_min > 0.0:
        return  # refused by the body already
    ratio = math.sqrt(i_max / i_min)
    with np.errstate(over="ignore", invalid="ignore"):
        conservative, driven = 0.0, 0.0
        strongest, strongest_bound = None, -1.0
        for tq in model.torques:
            bound = torque_bound(tq, i_max)
            if bound is None:
                continue
            if bound > strongest_bound:
                strongest, strongest_bound = tq, bound
            if getattr(tq, "conservative", False) and not getattr(tq, "time_dependent", False):
                conservative += bound
            else:
                driven += bound
        # energy: 1/2 I_min w^2 <= 1/2 I_max |w0|^2 + (the range of the potential, at most 2 |tau|max)
        rate = w_norm * ratio + 2.0 * math.sqrt(conservative / i_min) + driven * abs(t_end) / i_min
        phase = rate * abs(t_end)
    if strongest is None or (math.isfinite(phase) and phase <= MAX_PHASE):
        return
    flags = [name(f"torque.{p.toml_key}") for p in type(strongest).cli] or [repr(strongest)]
    if not math.isfinite(strongest_bound):
        raise UsageError(
            f"the torque {strongest.kind.replace('_', ' ')} ({', '.join(flags)}) overflows float64: the product of "
            f"its parameters is not a number (above {np.finfo(float).max:.2g}); use smaller values"
        )
    raise UsageError(
        f"the torque {strongest.kind.replace('_', ' ')} ({', '.join(flags)}) is too strong for float64: up to "
        f"{strongest_bound:.3g} on a smallest moment of inertia {i_min:.3g}, it drives the rates to about "
        f"{rate:.3g} rad/s, and by |t| = {abs(t_end):g} the body would turn through {phase:.3g} rad, beyond the "
        f"2^48 = {MAX_PHASE:.3g} rad over which float64 can follow the motion (the rounding of each step shifts "
        f"it by more than 0.1 rad); use a weaker torque or a shorter {name('time.t_end')}"
    )
