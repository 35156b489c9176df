"""The ``eulerpoisson`` command line.

Commands: ``simulate``, ``audit``, ``plot``, ``animate``, ``info``, ``sweep``, ``demo``, ``validate``,
``cases``, ``fit``, ``warmup``.
Bad input prints one line that says what is wrong and exits with status 2
(``--debug``, anywhere on the command line, shows the traceback instead).
Python warnings (overflow, ill-conditioning, ...) are silenced unless
``--debug`` is given, so that an error is a single line.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..attitude.core import UNIT_QUATERNION_TOLERANCE
from ..errors import EulerPoissonError, MissingDependencyError

__all__ = ["main"]

EXIT_USAGE = 2

#: frames per second accepted by ``animate --fps``
FPS_RANGE = (1.0, 240.0)
#: most frames of a GIF/MP4 written by ``animate`` (each frame is rendered by matplotlib)
MAX_FRAMES = 1200


class UsageError(EulerPoissonError, ValueError):
    """Bad command-line input (exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message):  # noqa: D401 - argparse API
        raise UsageError(f"{self.prog}: {message} (see '{self.prog} --help')")


# ---------------------------------------------------------------------------
# parsing helpers
# ---------------------------------------------------------------------------
def _floats(text, name: str, sizes: tuple[int, ...]) -> list[float]:
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
    v = _floats(value, name, (3, 9))
    return np.array(v) if len(v) == 3 else np.array(v).reshape(3, 3)


def check_file_name(value, name: str) -> None:
    """Reject an empty (or blank) file name given to option ``name``."""
    if value is not None and not str(value).strip():
        raise UsageError(f"{name}: empty file name")


def _load_toml(path: str) -> dict:
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


def _option_kind(annotation) -> str:
    """The TOML/flag kind of a method option from its dataclass annotation ("float | None" -> "number")."""
    text = str(annotation)
    if "float" in text:
        return "number"
    if "int" in text:
        return "int"
    if "bool" in text:
        return "bool"
    return "str"


def _method_option_kinds() -> dict[str, str]:
    """Every option of every registered method (read from their typed option dataclasses) with its kind."""
    import dataclasses

    from ..solvers import available_methods, get_method

    kinds: dict[str, str] = {}
    for name in available_methods():
        for f in dataclasses.fields(get_method(name).Options):
            kinds.setdefault(f.name, _option_kind(f.type))
    return kinds


#: the options of the methods, from their dataclasses (``ep.solvers.TaylorOptions`` ...): flags and TOML keys
METHOD_OPTIONS = _method_option_kinds()

#: what each TOML key of ``simulate`` holds (checked when the file is read; nothing is coerced)
_TOML_KINDS = {
    "body": {
        "inertia": "inertia",
        "masses": "numbers",
        "positions": "points",
        "name": "str",
        "allow_unphysical": "bool",
    },
    "initial": {"omega": "numbers", "m": "numbers", "quaternion": "numbers", "gibbs": "numbers"},
    "time": {"t_end": "number", "samples": "int"},
    "method": {"name": "str", **METHOD_OPTIONS},
    "output": {"file": "str", "json": "bool"},
    "torque": {
        "gravity": "numbers",
        "mass": "number",
        "center_of_mass": "numbers",
        "gravity_gradient": "number",
        "body_torque": "numbers",
        "space_torque": "numbers",
    },
    "compute": {"workers": "int"},
}
_TOML_KEYS = {sec: set(keys) for sec, keys in _TOML_KINDS.items()}


def _show(v) -> str:
    """A TOML value as the user wrote it (``true``, ``"abc"``, ``[[1, 2], [3]]``), shortened."""
    try:
        s = json.dumps(v)
    except (TypeError, ValueError):
        s = str(v)
    return s if len(s) <= 80 else s[:77] + "..."


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _toml_value(kind: str, v, where: str):
    """Check one TOML value against its ``kind``; return it (a 3x3 inertia flattened)."""
    if kind == "str":
        if not isinstance(v, str):
            raise UsageError(f"{where} must be a string, got {_show(v)}")
    elif kind == "bool":
        if not isinstance(v, bool):
            raise UsageError(f"{where} must be true or false, got {_show(v)}")
    elif kind == "number":
        if not _is_number(v):
            raise UsageError(f"{where} must be a number, got {_show(v)}")
    elif kind == "int":
        if isinstance(v, bool) or not isinstance(v, int):
            raise UsageError(f"{where} must be an integer, got {_show(v)}")
    elif kind == "numbers":
        if not isinstance(v, list) or not all(_is_number(x) for x in v):
            raise UsageError(f"{where} must be a list of numbers, got {_show(v)}")
    elif kind == "points":
        if not isinstance(v, list) or not all(
            isinstance(row, list) and len(row) == 3 and all(_is_number(x) for x in row) for row in v
        ):
            raise UsageError(f"{where} must be a list of points [x, y, z] (three numbers each), got {_show(v)}")
    elif kind == "inertia":
        if isinstance(v, list) and v and all(isinstance(row, list) for row in v):
            if len(v) != 3 or not all(len(row) == 3 and all(_is_number(x) for x in row) for row in v):
                raise UsageError(
                    f"{where} must be 3 numbers (principal moments), 9 numbers or a 3x3 table of "
                    f"numbers, got {_show(v)}"
                )
            return [x for row in v for x in row]
        if not isinstance(v, list) or not all(_is_number(x) for x in v):
            raise UsageError(
                f"{where} must be 3 numbers (principal moments), 9 numbers or a 3x3 table of numbers, got {_show(v)}"
            )
    else:  # pragma: no cover - table above is closed
        raise AssertionError(kind)
    return v


def _config_from_toml(cfg: dict, path: str, src: dict | None = None) -> dict:
    """Flatten and check a ``simulate`` TOML file: ``{"section.key": value}``.

    ``src`` (if given) receives, for each key, the name used in messages
    (``"run.toml: [method] order"``).
    """
    out: dict = {}
    for section, body in cfg.items():
        if section not in _TOML_KEYS:
            raise UsageError(f"{path}: unknown section [{section}]; known: {', '.join(sorted(_TOML_KEYS))}")
        if not isinstance(body, dict):
            raise UsageError(f"{path}: [{section}] must be a table")
        unknown = set(body) - _TOML_KEYS[section]
        if unknown:
            raise UsageError(
                f"{path}: unknown key(s) {', '.join(sorted(unknown))} in [{section}]; known: {', '.join(sorted(_TOML_KEYS[section]))}"
            )
        for k, v in body.items():
            where = f"{path}: [{section}] {k}"
            out[f"{section}.{k}"] = _toml_value(_TOML_KINDS[section][k], v, where)
            if src is not None:
                src[f"{section}.{k}"] = where
    # a file name in the file is relative to the file, not to the working directory
    if isinstance(out.get("output.file"), str) and out["output.file"].strip() and not os.path.isabs(out["output.file"]):
        out["output.file"] = os.path.join(os.path.dirname(os.path.abspath(path)), out["output.file"])
    return out


# ---------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------
#: command-line flag of each configuration key (the name used in messages when the value came from a flag)
_FLAGS = {
    "body.inertia": "--inertia",
    "body.allow_unphysical": "--allow-unphysical",
    "initial.omega": "--omega",
    "initial.m": "--m",
    "initial.quaternion": "--quaternion",
    "initial.gibbs": "--gibbs",
    "time.t_end": "--t-end",
    "time.samples": "--samples",
    "method.name": "--method",
    **{f"method.{k}": "--" + k.replace("_", "-") for k in METHOD_OPTIONS},
    "output.file": "--out",
    "torque.gravity": "--gravity",
    "torque.mass": "--mass",
    "torque.center_of_mass": "--com",
    "torque.gravity_gradient": "--gravity-gradient",
    "torque.body_torque": "--body-torque",
    "torque.space_torque": "--space-torque",
    "compute.workers": "--workers",
}


def _namer(src: dict):
    """``name(key)``: the flag or ``file: [section] key`` a value came from."""

    def name(key: str) -> str:
        if key in src:
            return src[key]
        section, _, k = key.partition(".")
        return _FLAGS.get(key, f"[{section}] {k}")

    return name


def _pair(name, k1: str, k2: str) -> tuple[str, str, str]:
    """Names of two keys for one message: ``(prefix, a, b)``; the file is said once when both come from it."""
    a, b = name(k1), name(k2)
    fa, _, ra = a.rpartition(": ")
    fb, _, rb = b.rpartition(": ")
    if fa and fa == fb:
        return f"{fa}: ", ra, rb
    return "", a, b


@contextlib.contextmanager
def _naming_target(target):
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
                reason = exc.strerror or _message(exc)
                raise (
                    OSError(exc.errno, f"cannot write {target}: {reason}")
                    if exc.errno is not None
                    else OSError(f"cannot write {target}: {reason}")
                ) from exc
        raise


def _build_body(cfg, name=None):
    from ..model.body import RigidBody

    name = name or _namer({})
    label = cfg.get("body.name")
    if "body.masses" in cfg or "body.positions" in cfg:
        if "body.inertia" in cfg:
            pre, a, b = _pair(name, "body.inertia", "body.masses" if "body.masses" in cfg else "body.positions")
            raise UsageError(f"{pre}give either {a} or [body] masses and positions, not both")
        if "body.masses" not in cfg or "body.positions" not in cfg:
            raise UsageError("a point-mass body needs both [body] masses and [body] positions")
        masses, positions = cfg["body.masses"], cfg["body.positions"]
        if len(masses) != len(positions):
            pre, a, b = _pair(name, "body.masses", "body.positions")
            raise UsageError(
                f"{pre}{a} has {len(masses)} entries but {b} has {len(positions)} points; give one mass per point"
            )
        return RigidBody.from_particles(masses, positions, name=label)
    if "body.inertia" not in cfg:
        raise UsageError("no body given: use --inertia I1,I2,I3 (or nine numbers) or a TOML file with [body]")
    return RigidBody(
        inertia_from(cfg["body.inertia"], name("body.inertia")),
        name=label,
        allow_unphysical=bool(cfg.get("body.allow_unphysical", False)),
    )


def _number(value, name: str, *, positive: bool = False) -> float:
    """One finite number (a flag's text or a TOML number); ``positive``: > 0, else >= 0."""
    try:
        x = float(str(value).strip()) if isinstance(value, str) else float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{name}: {value!r} is not a number") from None
    if not math.isfinite(x) or (x <= 0 if positive else x < 0):
        raise UsageError(f"{name} must be a finite number {'> 0' if positive else '>= 0'}, got {value!r}")
    return x


def _build_torques(cfg, name=None) -> list:
    """The torques of ``[torque]`` / the torque flags, in the order gravity, gravity gradient, body, space.

    A heavy top needs the centre of mass (``--com``); the mass defaults to 1 and
    the gravitational acceleration to (0, 0, -9.81).
    """
    from ..model.torques import STANDARD_GRAVITY, BodyTorque, Gravity, GravityGradient, SpaceTorque, Torque

    name = name or _namer({})
    torques: list[Torque] = []
    if "torque.center_of_mass" in cfg:
        com = _floats(cfg["torque.center_of_mass"], name("torque.center_of_mass"), (3,))
        mass = _number(cfg["torque.mass"], name("torque.mass"), positive=True) if "torque.mass" in cfg else 1.0
        g = (
            _floats(cfg["torque.gravity"], name("torque.gravity"), (3,))
            if "torque.gravity" in cfg
            else [0.0, 0.0, -STANDARD_GRAVITY]
        )
        torques.append(Gravity(mass, com, g))
    else:
        for key in ("torque.mass", "torque.gravity"):
            if key in cfg:
                raise UsageError(
                    f"{name(key)} needs the centre of mass of the heavy top: "
                    f"{_FLAGS['torque.center_of_mass']} CX,CY,CZ (body frame, from the fixed point) "
                    "or [torque] center_of_mass"
                )
    if "torque.gravity_gradient" in cfg:
        torques.append(GravityGradient(_number(cfg["torque.gravity_gradient"], name("torque.gravity_gradient"))))
    if "torque.body_torque" in cfg:
        torques.append(BodyTorque(_floats(cfg["torque.body_torque"], name("torque.body_torque"), (3,))))
    if "torque.space_torque" in cfg:
        torques.append(SpaceTorque(_floats(cfg["torque.space_torque"], name("torque.space_torque"), (3,))))
    return torques


def _method_options(cfg, name=None, method: str | None = None) -> dict:
    """The method options given as flags or in ``[method]``, checked against the method's option dataclass.

    Values are converted by the option's kind (numbers, integers, names); the
    dataclass validates them (its errors name the option). An option of
    another method is an error that lists the chosen method's options.
    """
    import dataclasses

    from ..solvers import get_method

    name = name or _namer({})
    allowed = None
    if method is not None:
        allowed = {f.name for f in dataclasses.fields(get_method(method).Options)}
    opts = {}
    for key, kind in METHOD_OPTIONS.items():
        k = f"method.{key}"
        if cfg.get(k) is None:
            continue
        value = cfg[k]
        if kind == "number":
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise UsageError(f"{name(k)}: {cfg[k]!r} is not a number") from None
            if key in ("tol", "dt", "rtol", "atol") and not (math.isfinite(value) and value > 0):
                raise UsageError(f"{name(k)} must be a positive number, got {cfg[k]!r}")
            if not math.isfinite(value):
                raise UsageError(f"{name(k)} must be a finite number, got {cfg[k]!r}")
        elif kind == "int":
            if isinstance(value, str):
                try:
                    value = int(value)
                except ValueError:
                    raise UsageError(f"{name(k)}: {cfg[k]!r} is not an integer") from None
        else:
            value = str(value)
        if allowed is not None and key not in allowed:
            have = ", ".join(_FLAGS[f"method.{a}"] for a in sorted(allowed)) or "none"
            raise UsageError(f"{name(k)} is not an option of method {method!r} (its options: {have})")
        opts[key] = value
    return opts


#: most output times of one run (a float64 time axis has 2**53 distinct integers; far beyond any disk)
MAX_SAMPLES = 10**13

#: bytes per sample and body of an in-memory run: q, omega, their copies in the Trajectory and the derived
#: quantities written to a file (M, m, energy, Gibbs vector), float64
_BYTES_PER_SAMPLE = 8 * (4 + 3) * 4 + 8 * (3 + 3 + 1 + 3)


def _memory_needed(samples: int, batch_shape) -> float:
    bodies = int(np.prod(batch_shape)) if batch_shape else 1
    return float(samples) * bodies * _BYTES_PER_SAMPLE


def _memory_available() -> float | None:
    """Available memory in bytes (None where the system does not say)."""
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return None


def _torque_records(model) -> list[dict]:
    return [tq.to_dict() for tq in model.torques]


def _state_json(traj, drift) -> dict:
    i = int(np.argmax(np.abs(traj.t)))  # the state at T (T < 0: backwards)
    q = traj.quaternion[..., i, :]
    sing = bool(q[0] == 0)
    return {
        "t": float(traj.t[i]),
        "quaternion": q.tolist(),
        "omega": traj.omega[..., i, :].tolist(),
        "gibbs": None if sing else (q[1:] / q[0]).tolist(),
        "m": traj.m[..., i, :].tolist(),
        "energy": float(traj.energy[..., i]),
        "method": traj.method,
        "drift": {k: float(v) for k, v in drift.items()},
        "torque": _torque_records(traj.model),
        "integrals": {k: float(v[..., i]) for k, v in traj.integrals().items()},
    }


#: output samples above which ``simulate`` works in chunks (and shows a progress bar on a terminal)
CHUNKED_SAMPLES = 5000

#: a stepping method expected to take more steps than this runs in chunks with a progress bar, whatever the samples
LONG_RUN_STEPS = 100_000
CHUNKS = 50


def _solve_in_chunks(model, t, omega0, m0, q0, method, opts, progress, keep: bool = True):
    """``solve`` over increasing output times, in chunks, with a progress bar on a terminal.

    The chunking depends only on the number of samples (never on whether a
    terminal is attached), so a run gives the same numbers everywhere. The
    closed form evaluates every chunk from the initial state (identical to one
    call); stepping methods continue each chunk from the last state of the
    previous one, as :func:`eulerpoisson.io.stream.solve_to_file` does.

    ``keep=False`` (nothing is written): only the first and the last sample
    are kept and the drift of the integrals is accumulated chunk by chunk,
    so memory does not grow with the samples; returns ``(trajectory of those
    two samples, drift)``.
    """
    from ..io.stream import ProgressDisplay, solve_from
    from ..model.drift import DriftAccumulator
    from ..solvers import get_method, solve
    from ..trajectory import Trajectory

    closed_form = get_method(method).order is None
    long_run = False
    if not closed_form and omega0 is not None and t.size > 2:
        # a stepping method turns the body by a few radians per step at most: a long run shows progress too
        rate = float(np.max(np.linalg.norm(np.atleast_2d(omega0), axis=-1)))
        long_run = rate * float(np.max(np.abs(t))) / (8 * np.pi) > LONG_RUN_STEPS
    if t.size < CHUNKED_SAMPLES and not long_run:
        tr = solve(model, t, omega0=omega0, m0=m0, attitude0=q0, method=method, **opts)
        return tr if keep else (tr, tr.drift())
    acc = None if keep else DriftAccumulator(model)
    pieces = [p for p in np.array_split(np.arange(t.size), min(CHUNKS, t.size)) if p.size]
    qs: list[np.ndarray] = []
    ws: list[np.ndarray] = []
    wall = 0.0
    first = None
    qs_end_index = 0  # the last output time of the previous chunk (a stepping method continues from it)
    from ..util.jit import whole_run

    # one choice of compiled kernels or NumPy for the whole run, not per chunk (the same numbers as one call)
    with ProgressDisplay(progress, t.size, f"{method}: solving") as bar, whole_run(n_times=t.size):
        done = 0
        for idx in pieces:
            if closed_form or first is None:
                tr = solve(model, t[idx], omega0=omega0, m0=m0, attitude0=q0, method=method, **opts)
            else:
                # the time-dependent torques are shifted to the chunk's start (solve_from)
                tr = solve_from(
                    model, t[idx], t[qs_end_index], qs[-1][..., -1, :], ws[-1][..., -1, :], method=method, **opts
                )
            first = tr if first is None else first
            if acc is not None:
                acc.update(tr.t, tr.quaternion, tr.omega)
                if len(qs) > 1:  # keep the first chunk's first sample and the last chunk only
                    qs.pop()
                    ws.pop()
            qs.append(tr.quaternion if acc is None or not qs else tr.quaternion[..., -1:, :])
            ws.append(tr.omega if acc is None or not ws else tr.omega[..., -1:, :])
            qs_end_index = idx[-1]
            wall += tr.stats.get("wall_time", 0.0)
            done += idx.size
            bar.update(done)
    assert first is not None  # there is at least one piece
    stats = dict(first.stats, wall_time=wall, chunks=len(pieces))
    if acc is not None:
        ends = Trajectory(
            t[[0, -1]],
            np.concatenate([qs[0][..., :1, :], qs[-1][..., -1:, :]], axis=-2),
            np.concatenate([ws[0][..., :1, :], ws[-1][..., -1:, :]], axis=-2),
            first.body,
            method,
            first.options,
            stats,
            torque=list(model.torques),
        )
        return ends, acc.result()
    return Trajectory(
        t,
        np.concatenate(qs, axis=-2),
        np.concatenate(ws, axis=-2),
        first.body,
        method,
        first.options,
        stats,
        torque=list(model.torques),
    )


def cmd_simulate(args) -> int:
    from ..attitude.core import quaternion_from_gibbs
    from ..model.equations import Model
    from ..solvers import available_methods
    from ..solvers.registry import check_supported

    cfg: dict = {}
    src: dict = {}
    if args.config is not None:
        cfg.update(_config_from_toml(_load_toml(args.config), args.config, src))
        # a file that contradicts itself is an error even when a flag would replace both values
        file_name = _namer(src)
        for k1, k2, what in (
            ("initial.omega", "initial.m", "exactly one of"),
            ("initial.quaternion", "initial.gibbs", "at most one of"),
            ("body.inertia", "body.masses", "either"),
            ("body.inertia", "body.positions", "either"),
        ):
            if k1 in cfg and k2 in cfg:
                pre, a, b = _pair(file_name, k1, k2)
                raise UsageError(f"{pre}give {what} {a} {'or' if what == 'either' else 'and'} {b}, not both")
    given = {
        key: getattr(args, attr)
        for attr, key in (
            ("inertia", "body.inertia"),
            ("omega", "initial.omega"),
            ("m", "initial.m"),
            ("quaternion", "initial.quaternion"),
            ("gibbs", "initial.gibbs"),
            ("t_end", "time.t_end"),
            ("samples", "time.samples"),
            ("method", "method.name"),
            ("allow_unphysical", "body.allow_unphysical"),
            *((opt, f"method.{opt}") for opt in METHOD_OPTIONS),
            ("out", "output.file"),
            ("gravity", "torque.gravity"),
            ("mass", "torque.mass"),
            ("com", "torque.center_of_mass"),
            ("gravity_gradient", "torque.gravity_gradient"),
            ("body_torque", "torque.body_torque"),
            ("space_torque", "torque.space_torque"),
            ("workers", "compute.workers"),
        )
        if getattr(args, attr, None) is not None
    }
    # two flags that say the same thing differently are an error; a flag replaces what the file says
    if "initial.omega" in given and "initial.m" in given:
        raise UsageError(
            "give exactly one of --omega and --m (the initial body angular velocity or the angular momentum), not both"
        )
    if "initial.quaternion" in given and "initial.gibbs" in given:
        raise UsageError("give at most one of --quaternion and --gibbs (the initial attitude), not both")
    replaces = {
        "initial.omega": ("initial.m",),
        "initial.m": ("initial.omega",),
        "initial.quaternion": ("initial.gibbs",),
        "initial.gibbs": ("initial.quaternion",),
        "body.inertia": ("body.masses", "body.positions"),
    }
    for key, v in given.items():
        for other in replaces.get(key, ()):
            cfg.pop(other, None)
            src.pop(other, None)
        cfg[key] = v
        src[key] = _FLAGS[key]
    name = _namer(src)

    body = _build_body(cfg, name)
    if "initial.omega" in cfg and "initial.m" in cfg:
        pre, a, b = _pair(name, "initial.omega", "initial.m")
        raise UsageError(f"{pre}give exactly one of {a} and {b}, not both")
    if "initial.omega" not in cfg and "initial.m" not in cfg:
        raise UsageError(
            "give exactly one initial condition: --omega W1,W2,W3 (body angular velocity) or --m (angular momentum)"
        )
    omega0 = m0 = None
    if "initial.omega" in cfg:
        omega0 = _floats(cfg["initial.omega"], name("initial.omega"), (3,))
    else:
        m0 = _floats(cfg["initial.m"], name("initial.m"), (3,))
    if "initial.quaternion" in cfg and "initial.gibbs" in cfg:
        pre, a, b = _pair(name, "initial.quaternion", "initial.gibbs")
        raise UsageError(f"{pre}give at most one of {a} and {b}, not both")
    q0 = None
    if "initial.quaternion" in cfg:
        q0 = np.array(_floats(cfg["initial.quaternion"], name("initial.quaternion"), (4,)))
        nrm = float(np.linalg.norm(q0))
        if abs(nrm - 1.0) > UNIT_QUATERNION_TOLERANCE:
            raise UsageError(
                f"{name('initial.quaternion')} must be a unit quaternion w,x,y,z (norm 1 within {UNIT_QUATERNION_TOLERANCE:g}); its norm is {nrm:.9g}"
            )
        q0 = q0 / nrm
    elif "initial.gibbs" in cfg:
        q0 = quaternion_from_gibbs(_floats(cfg["initial.gibbs"], name("initial.gibbs"), (3,)))
    if "time.t_end" not in cfg:
        raise UsageError("give the final time with --t-end T")
    try:
        t_end = float(cfg["time.t_end"])
    except (TypeError, ValueError):
        raise UsageError(f"{name('time.t_end')}: {cfg['time.t_end']!r} is not a number") from None
    if not math.isfinite(t_end):
        raise UsageError(
            f"{name('time.t_end')} must be a finite number (negative: backwards in time), got {cfg['time.t_end']!r}"
        )
    samples = cfg.get("time.samples", 1001)
    if isinstance(samples, str):
        try:
            samples = int(samples.strip())
        except ValueError:
            raise UsageError(f"{name('time.samples')} must be an integer >= 2, got {samples!r}") from None
    if samples < 2:
        raise UsageError(f"{name('time.samples')} must be an integer >= 2, got {samples}")
    if samples > MAX_SAMPLES:
        raise UsageError(
            f"{name('time.samples')} = {samples} is more than {MAX_SAMPLES:.3g} output times, which no "
            f"file or memory holds (a .zarr store of 1e8 samples is about 11 GB)"
        )
    out_name = cfg.get("output.file")
    if not (isinstance(out_name, str) and out_name.endswith(".zarr")):
        # a run written to NetCDF is held in memory; one written nowhere keeps its ends and the times only
        need = _memory_needed(samples, body.batch_shape) if out_name is not None else 16.0 * samples
        free = _memory_available()
        if free is not None and need > free:
            raise UsageError(
                f"{name('time.samples')} = {samples} needs about {need / 2**30:.3g} GiB in memory, more than the "
                f"{free / 2**30:.3g} GiB available; stream it to disk instead: --out run.zarr"
            )
    torques = _build_torques(cfg, name)
    model = Model(body, torques)
    # the closed form runs the free body (and the Lagrange top); under a torque the default is taylor
    method = cfg.get("method.name", "exact" if model.is_free else "taylor")
    if method not in available_methods():
        raise UsageError(
            f"{name('method.name')}: unknown method {method!r}; available: {', '.join(available_methods())}"
        )
    check_supported(method, model)  # UnsupportedModelError (one line, exit 2) names the methods that can
    opts = _method_options(cfg, name, method)
    workers = cfg.get("compute.workers")
    if workers is not None:
        try:
            workers = int(str(workers).strip())
        except ValueError:
            workers = 0
        if workers < 1:
            raise UsageError(
                f"{name('compute.workers')} must be a whole number of threads >= 1, got {cfg['compute.workers']!r}"
            )
        opts["workers"] = workers  # a keyword of solve, solve_from and solve_to_file, not a method option
    out = cfg.get("output.file")
    check_file_name(out, name("output.file"))
    as_json = bool(args.json or cfg.get("output.json", False))
    progress = False if (args.quiet or as_json) else None
    if out is not None and not str(out).endswith((".nc", ".nc4", ".netcdf", ".zarr")):
        raise UsageError(f"{name('output.file')} {out!r}: use a .nc (NetCDF) or .zarr (streamed) file name")
    if out is not None:
        # one policy for outputs: nothing replaced without --overwrite, never an input or another kind of file
        from ..io.outputs import OutputLock, check_output

        zarr_out = str(out).endswith(".zarr")
        check_output(
            out, "trajectory-store" if zarr_out else "netcdf", overwrite=bool(args.overwrite), inputs=[args.config]
        )
    if out is not None and str(out).endswith(".zarr"):
        # long runs stream to disk chunk by chunk (atomic, resumable); the state at T is read back from the file
        from ..io.stream import partial_store, solve_to_file

        if partial_store(out).exists() and not args.overwrite and not args.quiet and not as_json:
            print(
                f"resuming the interrupted run to {out} from its finished chunks (--overwrite starts afresh)",
                file=sys.stderr,
            )
        start = time.perf_counter()
        with OutputLock(out), _naming_target(out):
            try:
                solve_to_file(
                    model,
                    (0.0, t_end, samples),
                    out,
                    omega0=omega0,
                    m0=m0,
                    attitude0=q0,
                    method=method,
                    progress=progress,
                    resume=not args.overwrite,
                    overwrite=bool(args.overwrite),
                    **opts,
                )
            except KeyboardInterrupt:
                print(
                    f"eulerpoisson: interrupted; the finished chunks of {out} are kept: run the same command "
                    f"again to resume",
                    file=sys.stderr,
                )
                raise
            except EulerPoissonError as exc:
                raise type(exc)(
                    str(exc)
                    .replace("pass overwrite=True", "run again with --overwrite")
                    .replace("overwrite=True", "--overwrite")
                ) from exc
        from ..trajectory import Trajectory

        store = Trajectory.open(out)  # lazy: only the two samples below are read
        traj = store[[0, len(store) - 1]]
        traj.stats["wall_time"] = time.perf_counter() - start
    else:
        t = np.linspace(0.0, t_end, samples)
        if out is None:  # nothing is written: keep the ends and the drift only (bounded memory)
            traj, drift = _solve_in_chunks(model, t, omega0, m0, q0, method, opts, progress, keep=False)
        else:
            traj = _solve_in_chunks(model, t, omega0, m0, q0, method, opts, progress)
            with OutputLock(out):
                traj.to_netcdf(out)
    if out is not None:
        drift = traj.drift()
    if as_json:
        print(json.dumps(_state_json(traj, drift)))
    elif not args.quiet:
        s = _state_json(traj, drift)
        print(f"{traj.method}: {samples} samples to t = {t_end:g}, wall time {traj.stats.get('wall_time', 0.0):.3g} s")
        if not model.is_free:
            print(f"  torque        {model.describe()}")
        print(f"  quaternion(T) = {np.round(s['quaternion'], 12).tolist()}")
        print(f"  omega(T)      = {np.round(s['omega'], 12).tolist()}")
        print(f"  energy        = {s['energy']:.15g}" + ("" if model.is_free else "  (kinetic + potential)"))
        print("  relative drift: " + ", ".join(f"{k} {v:.2e}" for k, v in drift.items()))
        if out is not None:
            print(f"  wrote {out}")
    return 0


# ---------------------------------------------------------------------------
# other commands
# ---------------------------------------------------------------------------
def cmd_audit(args) -> int:
    from ..paper.audit import run_audit, write_report

    check_file_name(args.out, "--out")
    if args.out is not None:
        from ..io.outputs import check_output

        check_output(args.out, "file", overwrite=bool(args.overwrite))  # before the 25 s of the audit
    report = run_audit()
    if args.out is not None:
        from ..io.outputs import OutputLock

        with OutputLock(args.out):
            write_report(report, args.format, args.out)
        if not args.quiet:
            print(f"wrote {args.out}")
    else:
        text = {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[args.format]()
        print(text)
    return 0


def _read_traj(path):
    """The trajectory in ``path``: NetCDF-4 or NetCDF-3 (in memory), or a .zarr store (read lazily)."""
    from ..io.read import file_format
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
        msg = _message(exc)
        if str(path) in msg:
            raise
        raise EulerPoissonError(f"{path}: not a valid eulerpoisson trajectory file: {msg}") from exc


def cmd_plot(args) -> int:
    check_file_name(args.out, "--out")
    out = args.out if args.out is not None else f"{Path(args.file).stem}_{args.kind}.png"
    if args.kind == "atlas":
        from ..io.outputs import file_kind
        from ..sweep.runner import load_sweep, plot_atlas

        if not os.path.exists(args.file):
            raise UsageError(f"{args.file}: no such sweep store (make one with 'eulerpoisson sweep sweep.toml')")
        if file_kind(args.file) != "sweep-store":
            raise UsageError(
                f"{args.file}: --kind atlas draws a sweep store (made by 'eulerpoisson sweep'), and this "
                f"is not one; a trajectory has the kinds omega, invariants, polhode, gibbs, attitude, apex"
            )
        plot_atlas(load_sweep(args.file), out)
    else:
        from ..viz import plots

        traj = _read_traj(args.file)
        plots.plot(traj, args.kind, out=out)
    if not args.quiet:
        print(f"wrote {out}")
    return 0


def _fps(text) -> float:
    lo, hi = FPS_RANGE
    try:
        fps = float(text)
    except (TypeError, ValueError):
        raise UsageError(f"--fps: {text!r} is not a number (frames per second, {lo:g} to {hi:g})") from None
    if not (math.isfinite(fps) and lo <= fps <= hi):
        raise UsageError(f"--fps must be between {lo:g} and {hi:g} frames per second, got {text!r}")
    return int(fps) if fps.is_integer() else fps


def cmd_animate(args) -> int:
    from ..viz.animate import FORMATS, animate, default_duration

    check_file_name(args.out, "--out")
    ext = Path(args.out).suffix.lower().lstrip(".")
    if ext not in FORMATS and ext != "htm":
        raise UsageError(
            f"--out {args.out!r}: unsupported file extension; use .html (self-contained page), .gif or .mp4"
        )
    video = ext in ("gif", "mp4")
    if args.fps is not None and not video:
        raise UsageError(
            "--fps applies to .gif and .mp4 movies only (an HTML page animates at the browser's frame rate)"
        )
    fps = _fps(args.fps) if args.fps is not None else 30
    traj = _read_traj(args.file)
    if video:
        if getattr(traj, "lazy", False):  # a store: its ends (the times of a stream are monotonic)
            ends = traj[[0, len(traj) - 1]] if len(traj) else traj.head()
            span = float(np.max(ends.t) - np.min(ends.t))
        else:
            span = float(np.max(traj.t) - np.min(traj.t))
        nframes = int(round(fps * default_duration(span)))
        if nframes > MAX_FRAMES:
            dur = default_duration(span)
            raise UsageError(
                f"--fps {args.fps}: a {dur:g} s movie would have {nframes} frames, more than {MAX_FRAMES}; "
                f"use --fps {int(MAX_FRAMES // dur)} or less"
            )
    animate(traj, args.out, fps=fps)
    if not args.quiet:
        print(f"wrote {args.out}")
    return 0


def _info_store(args, traj) -> int:
    """``info`` of a .zarr store: its metadata and its first and last samples, nothing else is read."""
    b = traj.body
    lines = [
        f"{args.file}: eulerpoisson trajectory (Zarr store, read lazily: {traj.chunk} samples per chunk)",
        f"  method      {traj.method} {json.dumps(traj.options) if traj.options else ''}".rstrip(),
        f"  torque      {traj.model.describe()}",
    ]
    if len(traj) == 0:
        lines.append("  samples     0 (no output times)")
        lines.append(
            f"  body        {b!r}" if not traj.batch_shape else f"  bodies      batch of shape {traj.batch_shape}"
        )
        print("\n".join(lines))
        return 0
    first, last = traj.head(), traj.tail()
    lines.append(f"  samples     {len(traj)}, t from {float(first.t[0]):.6g} to {float(last.t[0]):.6g}")
    lines.append(f"  variables   {', '.join(traj.variables)}")
    if traj.batch_shape:
        lines.append(f"  bodies      batch of shape {traj.batch_shape}")
    else:
        lines.append(f"  body        {b!r}")
        lines.append(
            f"  energy      {float(first.energy[0]):.15g}" + ("" if traj.model.is_free else " (kinetic + potential)")
        )
        lines.append(f"  m           {np.round(first.m[0], 12).tolist()}")
    drift = traj.drift_endpoints()
    lines.append(
        "  drift       "
        + ", ".join(f"{k} {np.max(v):.2e}" for k, v in drift.items())
        + " (last sample against the first)"
    )
    print("\n".join(lines))
    return 0


# ---------------------------------------------------------------------------
# info of an unfinished (interrupted) .zarr run
# ---------------------------------------------------------------------------
def _partial_run_of(path) -> tuple[Path, Path, bool] | None:
    """``(target, work folder, named)`` of the unfinished stream to ``path``, or None.

    ``path`` is the destination of a ``simulate --out X.zarr`` run (its work
    folder is ``.X.zarr.partial`` beside it), or that work folder or the
    partial store inside it (``named``: the user asked about the partial run itself).
    """
    p = Path(path)
    if not p.name:
        return None
    for work in ((p.parent,) if p.name == "store.zarr" else ()) + (p,):
        if work.name.startswith(".") and work.name.endswith(".partial") and len(work.name) > 9 and work.is_dir():
            return work.with_name(work.name[1 : -len(".partial")]), work, True
    work = p.with_name(f".{p.name}.partial")
    return (p, work, False) if work.is_dir() else None


def _num(x) -> str:
    """A float as the shortest text that reads back to it bit for bit (``1`` rather than ``1.0``)."""
    r = repr(float(x))
    return r[:-2] if r.endswith(".0") else r


def _resume_command(target: str, fp: dict) -> str | None:
    """The ``simulate`` command that resumes the stream recorded by fingerprint ``fp``, or None.

    The command is rebuilt from the recorded arguments and checked by running
    them through the code of ``simulate`` itself (body, torques, method
    options, initial state): it is returned only if it gives the very same
    fingerprint, i.e. if it resumes the run rather than being refused.
    """
    import inspect

    from ..io.stream import TIME_VARIABLES, solve_to_file, torque_fingerprint
    from ..model.body import RigidBody
    from ..model.equations import Model
    from ..solvers import get_method, make_problem

    known = {
        "version",
        "method",
        "options",
        "inertia",
        "positions",
        "q0",
        "omega0",
        "times",
        "chunk",
        "n",
        "variables",
        "torque",
    }
    try:
        chunk = inspect.signature(solve_to_file).parameters["chunk"].default
        if set(fp) - known or fp.get("positions") is not None or fp["chunk"] != chunk:
            return None  # a point-mass body, another chunk or other variables: not a 'simulate' run
        if list(fp["variables"]) != list(TIME_VARIABLES):
            return None
        t0, t_end, samples = fp["times"]["grid"]
        if float(t0) != 0.0:
            return None
        inertia = np.array(fp["inertia"], dtype=float)
        cfg: dict = {}
        flags: list[str] = []
        diag = inertia.shape == (3, 3) and np.all(inertia == np.diag(np.diag(inertia)))
        cfg["body.inertia"] = ",".join(_num(v) for v in (np.diag(inertia) if diag else inertia.ravel()))
        flags += ["--inertia", cfg["body.inertia"]]
        try:
            RigidBody(inertia_from(cfg["body.inertia"]))
        except EulerPoissonError:
            cfg["body.allow_unphysical"] = True
            flags.append("--allow-unphysical")
        cfg["initial.omega"] = ",".join(_num(v) for v in fp["omega0"])
        flags += ["--omega", cfg["initial.omega"]]
        if list(fp["q0"]) != [1.0, 0.0, 0.0, 0.0]:
            cfg["initial.quaternion"] = ",".join(_num(v) for v in fp["q0"])
            flags += ["--quaternion", cfg["initial.quaternion"]]
        flags += ["--t-end", _num(t_end), "--samples", str(int(samples))]
        keys = {
            "gravity": (("torque.center_of_mass", "center_of_mass"), ("torque.mass", "mass"), ("torque.gravity", "g")),
            "gravity_gradient": (("torque.gravity_gradient", "mean_motion"),),
            "body_torque": (("torque.body_torque", "tau"),),
            "space_torque": (("torque.space_torque", "tau"),),
        }
        for rec in fp.get("torque", []):
            for key, field in keys[rec["kind"]]:
                v = rec[field]
                cfg[key] = ",".join(_num(x) for x in v) if isinstance(v, list) else _num(v)
                flags += [_FLAGS[key], cfg[key]]
        model = Model(_build_body(cfg), _build_torques(cfg))
        method = fp["method"]
        if method != ("exact" if model.is_free else "taylor"):
            flags += ["--method", method]
        cls = get_method(method)

        def config(opts):
            return json.loads(json.dumps(cls(**opts).config, default=float, sort_keys=True))

        defaults = config({})
        for k, v in sorted(fp["options"].items()):
            if defaults.get(k) != v:
                if k not in METHOD_OPTIONS or v is None or isinstance(v, (dict, list)):
                    return None
                cfg[f"method.{k}"] = _num(v) if isinstance(v, float) else str(v)
                flags += [_FLAGS[f"method.{k}"], cfg[f"method.{k}"]]
        q0 = None
        if "initial.quaternion" in cfg:  # as simulate does: normalized
            q0 = np.array(_floats(cfg["initial.quaternion"], "--quaternion", (4,)))
            q0 = q0 / float(np.linalg.norm(q0))
        problem = make_problem(
            model, np.array([0.0]), omega0=_floats(cfg["initial.omega"], "--omega", (3,)), attitude0=q0
        )
        mine = {
            "version": fp["version"],
            "method": method,
            "options": config(_method_options(cfg, None, method)),
            "inertia": np.asarray(problem.body.inertia).tolist(),
            "positions": None,
            "q0": problem.q0.tolist(),
            "omega0": problem.omega0.tolist(),
            "times": {"grid": [0.0, float(_num(t_end)), int(samples)]},
            "chunk": chunk,
            "n": int(samples),
            "variables": list(TIME_VARIABLES),
        }
        if not model.is_free:
            mine["torque"] = torque_fingerprint(model)
        if json.loads(json.dumps(mine, default=float, sort_keys=True)) != fp:
            return None
    except Exception:  # noqa: BLE001 - anything unexpected: no command rather than a wrong one
        return None
    import shlex

    return shlex.join(["eulerpoisson", "simulate", *flags, "--out", str(target)])


def _info_partial(args, target: Path, work: Path) -> int:
    """``info`` of an unfinished stream: how far it got, up to what time, and how to resume it."""
    from ..io.outputs import pid_alive
    from ..io.stream import TimeGrid

    try:
        with open(work / "state.json", encoding="utf-8") as fh:
            fp = json.load(fh)
    except (OSError, ValueError):
        print(
            f"{args.file}: an unfinished run to {target} that stopped before its first chunk (while its store "
            f"was being created): nothing was computed; the next run to {target} starts afresh"
        )
        return 0
    try:
        n, chunk = int(fp["n"]), int(fp["chunk"])
        fp["times"]["grid" if "grid" in fp["times"] else "array"]
    except (TypeError, KeyError):  # not a trajectory stream: a sweep (or a newer format)
        finished = [f for f in (work / "done").iterdir() if f.name.isdigit()] if (work / "done").is_dir() else []
        print(
            f"{args.file}: an unfinished sweep (or another unfinished result) to {target}, not a trajectory: "
            f"{len(finished)} chunk(s) finished; run the command that wrote it again to resume it "
            f"('eulerpoisson sweep CONFIG --out {target}')"
        )
        return 0
    nchunks = max(1, -(-n // chunk))
    done_dir = work / "done"
    done = (
        sorted(k for k in (int(f.name) for f in done_dir.iterdir() if f.name.isdigit()) if k < nchunks)
        if done_dir.is_dir()
        else []
    )
    samples_done = sum(min(chunk, n - k * chunk) for k in done)
    prefix = 0
    while prefix < len(done) and done[prefix] == prefix:
        prefix += 1
    pid = 0
    lock = target.with_name(f".{target.name}.lock")
    try:
        pid = int(lock.read_text().strip() or "0")
    except (OSError, ValueError):
        pass
    running = bool(pid) and pid != os.getpid() and pid_alive(pid)
    state = f"being written now (process {pid})" if running else "interrupted"
    lines = [
        f"{args.file}: unfinished run to {target} ({state}): {len(done)} of {nchunks} chunks finished, "
        f"{samples_done} of {n} samples ({100.0 * samples_done / n:.3g}%)"
        if n
        else f"{args.file}: unfinished run to {target} ({state}): no output times"
    ]

    def times(idx):
        grid = fp.get("times", {}).get("grid")
        if grid is not None:
            g = TimeGrid(float(grid[0]), float(grid[1]), int(grid[2]))
            return [float(g[i : i + 1][0]) for i in idx]
        from ..io.read import zarr_group

        tarr = zarr_group(work / "store.zarr")["time"]
        return [float(tarr[i]) for i in idx]

    try:
        if prefix:
            last = min(n, prefix * chunk) - 1
            ta, tb = times([0, last])
            lines.append(
                f"  finished    samples 0 to {last}: t from {ta:.6g} to {tb:.6g}"
                + (f" (and {len(done) - prefix} chunk(s) further on)" if len(done) > prefix else "")
            )
        elif done:
            lines.append(
                f"  finished    chunk(s) {', '.join(map(str, done[:8]))}{' ...' if len(done) > 8 else ''}"
                f" ({chunk} samples each)"
            )
        else:
            lines.append("  finished    nothing yet")
        if n:
            tn = times([n - 1])[0]
            lines.append(f"  run         {n} samples to t = {tn:.6g}, {chunk} per chunk")
    except Exception:  # noqa: BLE001 - the times are a courtesy: the counts above are what matters
        pass
    lines.append(f"  method      {fp.get('method', '?')}")
    try:
        from ..model.body import RigidBody
        from ..model.equations import Model
        from ..model.torques import torque_from_dict

        body = (
            RigidBody(np.array(fp["inertia"], dtype=float), allow_unphysical=True)
            if fp.get("positions") is None
            else None
        )
        if body is not None:
            lines.append(f"  body        {body!r}")
            lines.append(f"  torque      {Model(body, [torque_from_dict(r) for r in fp.get('torque', [])]).describe()}")
    except Exception:  # noqa: BLE001
        pass
    lines.append(
        f"  store       {work / 'store.zarr'}: the finished chunks (xarray.open_zarr reads it; unfinished "
        "samples are NaN)"
    )
    if running:
        lines.append("  resume      not now: wait for the running process to finish (or stop it with Ctrl-C)")
    else:
        cmd = _resume_command(str(target), fp)
        lines.append(
            f"  resume      {cmd}"
            if cmd
            else f"  resume      run the command that wrote it again ('eulerpoisson simulate ... --out {target}', "
            "or solve_to_file(..., resume=True) with the same arguments)"
        )
    print("\n".join(lines))
    return 0


def cmd_info(args) -> int:
    check_file_name(args.file, "trajectory file")
    partial = _partial_run_of(args.file)
    if partial is not None and (partial[2] or not os.path.exists(args.file)):
        return _info_partial(args, partial[0], partial[1])
    traj = _read_traj(args.file)
    if partial is not None:  # a finished file, and an unfinished run to replace it (simulate --overwrite)
        print(
            f"{args.file}: note: an unfinished run to replace it is kept in {partial[1]} "
            f"('eulerpoisson info {partial[1] / 'store.zarr'}' says how far it got)"
        )
    if getattr(traj, "lazy", False):
        return _info_store(args, traj)
    b = traj.body
    lines = [
        f"{args.file}: eulerpoisson trajectory",
        f"  method      {traj.method} {json.dumps(traj.options) if traj.options else ''}".rstrip(),
        f"  torque      {traj.model.describe()}",
    ]
    if len(traj.t) == 0:  # a valid file with no output times: nothing to measure
        lines.append("  samples     0 (no output times)")
        lines.append(
            f"  body        {b!r}" if not traj.batch_shape else f"  bodies      batch of shape {traj.batch_shape}"
        )
        print("\n".join(lines))
        return 0
    lines.append(f"  samples     {len(traj.t)}, t from {traj.t.min():.6g} to {traj.t.max():.6g}")
    if traj.batch_shape:
        lines.append(f"  bodies      batch of shape {traj.batch_shape}")
    else:
        lines.append(f"  body        {b!r}")
        lines.append(
            f"  energy      {float(traj.energy[0]):.15g}" + ("" if traj.model.is_free else " (kinetic + potential)")
        )
        lines.append(f"  m           {np.round(traj.m[0], 12).tolist()}")
    lines.append("  drift       " + ", ".join(f"{k} {np.max(v):.2e}" for k, v in traj.drift().items()))
    print("\n".join(lines))
    return 0


def cmd_sweep(args) -> int:
    from ..sweep.runner import load_config, run_sweep

    check_file_name(args.config, "sweep file")
    check_file_name(args.out, "--out")
    if not os.path.exists(args.config):
        raise UsageError(f"sweep file {args.config!r} does not exist (see examples/sweep.toml)")
    if not os.path.isfile(args.config):
        raise UsageError(f"sweep file {args.config!r} is not a file")
    try:
        cfg = load_config(args.config)
    except UnicodeDecodeError as exc:
        raise UsageError(
            f"{args.config}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at position {exc.start}); "
            "a TOML file must be UTF-8"
        ) from None
    from ..io.outputs import OutputLock, check_output

    target = args.out if args.out is not None else cfg.path
    check_output(target, "sweep-store", overwrite=bool(args.overwrite), inputs=[args.config])
    try:
        with OutputLock(target), _naming_target(target):
            path = run_sweep(
                cfg,
                path=args.out,
                scheduler=args.scheduler,
                workers=args.workers,
                progress=False if args.quiet else None,
                overwrite=args.overwrite,
            )
    except (EulerPoissonError, OSError) as exc:
        # the library speaks of its keyword argument; on the command line it is a flag
        msg = str(exc)
        if "overwrite=True" in msg:
            raise EulerPoissonError(
                msg.replace("pass overwrite=True", "run again with --overwrite").replace(
                    "overwrite=True", "--overwrite"
                )
            ) from exc
        raise
    if not args.quiet:
        print(f"wrote {path}")
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    check_file_name(args.out, "--out")
    return run_demo(args.out, quiet=args.quiet)


# ---------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    from .. import __version__
    from ..solvers import available_methods, get_method

    p = _Parser(
        prog="eulerpoisson",
        description="Rigid-body rotation, free (exact, in the Gibbs rotation vector n = k tan(alpha/2)) and "
        "under torque: solvers, the paper's audit, files and pictures.",
        epilog="Run 'eulerpoisson COMMAND --help' for a command's options and examples.",
    )
    p.add_argument("--version", action="version", version=f"eulerpoisson {__version__}")
    p.add_argument(
        "--debug",
        action="store_true",
        help="show tracebacks and warnings instead of one-line errors (accepted anywhere on the line)",
    )
    sub = p.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")

    ex = argparse.RawDescriptionHelpFormatter
    s = sub.add_parser(
        "simulate",
        help="solve the motion of a body and print or save it",
        formatter_class=ex,
        description="Solve the motion of a rigid body, free or under torque, from an initial state.",
        epilog=(
            "examples:\n"
            "  eulerpoisson simulate --inertia 3,5,8 --omega 0,0.4,0.001 --t-end 50 --json\n"
            "  eulerpoisson simulate --inertia 1,2,3 --omega 1,0.1,0.5 --t-end 100 --method taylor --tol 1e-15 --out run.nc\n"
            "  eulerpoisson simulate run.toml --t-end 20     # flags override the file\n"
            "  eulerpoisson simulate --inertia 1,1,0.5 --omega 0,0,10 --gibbs 0.577,0,0 --com 0,0,0.25 --mass 1 \\\n"
            "      --gravity 0,0,-9.81 --t-end 15 --out top.nc     # a heavy top (taylor by default)\n"
            "  eulerpoisson plot top.nc --kind apex --out top_apex.png\n"
            "  eulerpoisson simulate examples/heavy_top.toml --t-end 5   # the same top from a file ([torque])\n"
            "  eulerpoisson simulate --inertia 1,2,3 --omega 0,0.001,0.001 --gravity-gradient 0.001 --t-end 6000 --json\n\n"
            "TOML file sections: [body] inertia=[...] | masses=[...], positions=[[...]...]; name\n"
            "  [initial] omega=[...] | m=[...]; quaternion=[w,x,y,z] | gibbs=[...]\n"
            "  [time] t_end, samples   [method] name, tol, dt, scheme, order, integrator, rtol, atol\n"
            "  [output] file, json\n"
            "  [torque] center_of_mass=[...], mass, gravity=[...]; gravity_gradient; body_torque=[...]; space_torque=[...]\n\n"
            "Torques: a heavy top is --com (centre of mass, body frame, from the fixed point; the inertia is about\n"
            "the fixed point) with --mass (default 1) and --gravity (default 0,0,-9.81); --gravity-gradient NU is a\n"
            "circular orbit of mean motion NU; --body-torque / --space-torque are constant torques. They add up.\n"
            "Under a torque the default method is taylor; rk and symplectic run them too (see --method)."
        ),
    )
    s.add_argument("config", nargs="?", help="optional TOML file describing the run")
    s.add_argument("--inertia", help="principal moments I1,I2,I3 or nine numbers of a full tensor (row-major)")
    s.add_argument("--omega", help="initial body angular velocity W1,W2,W3")
    s.add_argument("--m", help="initial spatial angular momentum m1,m2,m3 (instead of --omega)")
    s.add_argument("--quaternion", help="initial attitude w,x,y,z (unit, scalar first); default identity")
    s.add_argument("--gibbs", help="initial attitude as the Gibbs vector n1,n2,n3")
    s.add_argument("--t-end", dest="t_end", help="final time T (negative: the motion backwards from t = 0)")
    s.add_argument(
        "--allow-unphysical",
        dest="allow_unphysical",
        action="store_true",
        default=None,
        help="accept moments that violate the triangle inequality (e.g. 3,5,9: no mass distribution has them)",
    )
    s.add_argument("--samples", type=str, help="number of output times in [0, T] (default 1001)")
    s.add_argument(
        "--method", help="solution method: exact, taylor, symplectic, rk (default exact; taylor under a torque)"
    )
    for opt in METHOD_OPTIONS:  # every option of every method, read from the option dataclasses
        owners = "; ".join(
            f"{m}: default {get_method(m).options[opt]}" for m in available_methods() if opt in get_method(m).options
        )
        s.add_argument(
            "--" + opt.replace("_", "-"), dest=opt, metavar=opt.upper(), help=f"method option {opt} ({owners})"
        )
    s.add_argument(
        "--com",
        metavar="CX,CY,CZ",
        help="heavy top: centre of mass in the body frame, from the fixed point (the inertia is about it)",
    )
    s.add_argument("--mass", metavar="M", help="heavy top: mass M > 0 (default 1; needs --com)")
    s.add_argument(
        "--gravity",
        metavar="GX,GY,GZ",
        help="heavy top: gravitational acceleration, space frame (default 0,0,-9.81; needs --com)",
    )
    s.add_argument(
        "--gravity-gradient",
        dest="gravity_gradient",
        metavar="NU",
        help="gravity-gradient torque of a circular orbit with mean motion NU >= 0 (rad per time unit)",
    )
    s.add_argument("--body-torque", dest="body_torque", metavar="TX,TY,TZ", help="constant torque in the body frame")
    s.add_argument("--space-torque", dest="space_torque", metavar="TX,TY,TZ", help="constant torque in the space frame")
    s.add_argument("--out", help="write the trajectory to this NetCDF (.nc) file or stream it to a Zarr (.zarr) store")
    s.add_argument(
        "--json",
        action="store_true",
        help="print the state at T, the torques, the integrals at T and their drift as one JSON object",
    )
    s.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an existing output of the same kind (an interrupted .zarr run resumes without it)",
    )
    s.add_argument(
        "-j",
        "--workers",
        metavar="N",
        help="threads that solve a batch of bodies (default: $EULERPOISSON_WORKERS, else every core; "
        "1: one thread); the results do not depend on it",
    )
    s.add_argument("--quiet", action="store_true", help="print nothing but errors")
    s.set_defaults(func=cmd_simulate)

    a = sub.add_parser(
        "audit",
        help="derive the paper's equations with SymPy and report which are confirmed",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson audit\n  eulerpoisson audit --format json --out audit.json\n  eulerpoisson audit --format tex --out audit.tex",
    )
    a.add_argument("--format", choices=["md", "json", "tex"], default="md", help="report format (default md)")
    a.add_argument("--out", help="write the report to this file instead of printing it")
    a.add_argument(
        "--overwrite", action="store_true", help="replace an existing report file (never a file of another kind)"
    )
    a.add_argument("--quiet", action="store_true")
    a.set_defaults(func=cmd_audit)

    pl = sub.add_parser(
        "plot",
        help="draw a figure from a trajectory file",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson plot run.nc --kind omega --out omega.png\n  eulerpoisson plot run.nc --kind polhode --out polhode.pdf\n"
        "  eulerpoisson plot top.nc --kind apex --out apex.png   # a top: its axis on the unit sphere\n"
        "  eulerpoisson plot long.zarr --kind omega --out omega.png   # a streamed run: min/max per pixel column\n\n"
        "Long runs (more than 20000 samples, and every .zarr store) are decimated: time series are drawn as\n"
        "the min/max of the samples in each pixel column, the 3-D pictures from evenly strided samples.",
    )
    pl.add_argument(
        "file",
        help="trajectory written by 'simulate --out': a NetCDF file (version 4 or 3) or a .zarr "
        "store, read chunk by chunk (or a sweep store for --kind atlas)",
    )
    pl.add_argument(
        "--kind", required=True, choices=["omega", "invariants", "polhode", "gibbs", "attitude", "apex", "atlas"]
    )
    pl.add_argument("--out", help="figure file (.png, .svg or .pdf)")
    pl.add_argument("--quiet", action="store_true")
    pl.set_defaults(func=cmd_plot)

    an = sub.add_parser(
        "animate",
        help="animate the tumbling body (self-contained HTML, GIF or MP4)",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson animate run.nc --out movie.html\n  eulerpoisson animate run.nc --out movie.gif",
    )
    an.add_argument("file", help="trajectory file: NetCDF (version 4 or 3) or a .zarr store")
    an.add_argument("--out", required=True, help="movie.html, movie.gif or movie.mp4")
    an.add_argument(
        "--fps", help=f"frames per second of a .gif/.mp4 ({FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}, default 30)"
    )
    an.add_argument("--quiet", action="store_true")
    an.set_defaults(func=cmd_animate)

    sw = sub.add_parser(
        "sweep",
        help="a grid or random sweep over inertia ratios and initial states, on Dask, into Zarr",
        formatter_class=ex,
        epilog=(
            "examples:\n"
            "  eulerpoisson sweep examples/sweep.toml        # writes atlas.zarr (the file's [output] path)\n"
            "  eulerpoisson plot atlas.zarr --kind atlas --out atlas.png\n"
            "  eulerpoisson sweep examples/sweep.toml --scheduler serial --out atlas_serial.zarr   # one process\n\n"
            "A Dask cluster elsewhere is named on the command line only, never by a sweep file:\n"
            "--scheduler tcp://HOST:8786 (its scheduler's address; its workers need eulerpoisson installed).\n"
            "An interrupted sweep resumes where it stopped when run again."
        ),
    )
    sw.add_argument("config", help="TOML file describing the sweep (see examples/sweep.toml)")
    sw.add_argument("--out", help="Zarr store (default: [output] path of the file)")
    sw.add_argument("--scheduler", help="'local' (default, an embedded cluster), 'serial', or tcp://HOST:PORT")
    sw.add_argument(
        "-j",
        "--workers",
        type=int,
        metavar="N",
        help="worker processes of the local cluster, or threads with --scheduler serial "
        "(default: [compute] workers, else every core); the results do not depend on it",
    )
    sw.add_argument("--overwrite", action="store_true", help="replace a store made with another configuration")
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=cmd_sweep)

    i = sub.add_parser(
        "info",
        help="describe a trajectory file",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson info run.nc\n  eulerpoisson info long.zarr   # a store: only its "
        "metadata and its first and last samples are read",
    )
    i.add_argument("file", help="trajectory file: NetCDF (version 4 or 3) or a .zarr store")
    i.set_defaults(func=cmd_info)

    d = sub.add_parser(
        "demo",
        help="the showcase: the tennis-racket effect, a heavy top, figures, animation and audit",
        epilog="example:\n  eulerpoisson demo --out out",
        formatter_class=ex,
    )
    d.add_argument("--out", default="out", help="output folder (default out/)")
    d.add_argument("--quiet", action="store_true")
    d.set_defaults(func=cmd_demo)

    from .oracle import add_commands  # validate, cases (issue 14)

    add_commands(sub)
    from .fit import add_commands as add_fit_command  # fit (issue 13)

    add_fit_command(sub)
    from .warmup import add_commands as add_warmup_command  # warmup (issue 15, cold start)

    add_warmup_command(sub)
    return p


# ---------------------------------------------------------------------------
# argv pre-processing
# ---------------------------------------------------------------------------
def _value_options(parser: argparse.ArgumentParser) -> tuple[set[str], set[str]]:
    """Long options that take a value, and all option strings, of ``parser`` and its subcommands."""
    takes: set[str] = set()
    every: set[str] = set()
    stack = [parser]
    while stack:
        p = stack.pop()
        for action in p._actions:
            every.update(action.option_strings)
            if action.option_strings and action.nargs != 0:
                takes.update(o for o in action.option_strings if o.startswith("--"))
            if isinstance(action, argparse._SubParsersAction):
                stack.extend(action.choices.values())
    return takes, every


def _prepare_argv(argv: list[str], parser: argparse.ArgumentParser) -> list[str]:
    """Drop ``--debug`` (accepted anywhere) and glue values that begin with '-' to their option.

    argparse reads ``--omega -1,0.1,0.5`` as two options; ``--omega=-1,0.1,0.5``
    is what the user meant. A value is glued to a value-taking long option (or
    an abbreviation of one) when it begins with a single '-' and is not itself
    a known option.
    """
    takes, every = _value_options(parser)
    out: list[str] = []
    i = 0
    while i < len(argv):
        tok = argv[i]
        if tok == "--":
            out.extend(argv[i:])
            break
        if tok == "--debug":
            i += 1
            continue
        if (
            tok.startswith("--")
            and "=" not in tok
            and len(tok) > 2
            and i + 1 < len(argv)
            and any(o.startswith(tok) for o in takes)
        ):
            nxt = argv[i + 1]
            if nxt.startswith("-") and not nxt.startswith("--") and nxt not in every and len(nxt) > 1:
                out.append(f"{tok}={nxt}")
                i += 2
                continue
        out.append(tok)
        i += 1
    return out


def _message(exc: BaseException) -> str:
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


def _error_line(exc: BaseException) -> str:
    msg = _message(exc)
    if isinstance(exc, UsageError):
        return f"eulerpoisson: error: {msg}"  # every error line starts the same way
    if isinstance(exc, MemoryError):
        msg = f"out of memory: {msg}" if msg != type(exc).__name__ else "out of memory"
    elif isinstance(exc, OverflowError) and "overflow" not in msg.lower():
        msg = f"numerical overflow: {msg}"
    elif not isinstance(
        exc, (EulerPoissonError, ValueError, TypeError, OSError, ArithmeticError, LookupError, ImportError)
    ):
        msg = f"{type(exc).__name__}: {msg}"  # unexpected: say what kind of failure it was
    return f"eulerpoisson: error: {msg}"


@contextlib.contextmanager
def _quiet_warnings(enabled: bool):
    """Silence Python warnings here and in worker processes started meanwhile (when ``enabled``)."""
    if not enabled:
        yield
        return
    old = os.environ.get("PYTHONWARNINGS")
    os.environ["PYTHONWARNINGS"] = "ignore"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        if old is None:
            os.environ.pop("PYTHONWARNINGS", None)
        else:
            os.environ["PYTHONWARNINGS"] = old


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``eulerpoisson`` command; returns the exit status.

    Bad input, and any failure of a command, prints one line
    ``eulerpoisson: error: ...`` (or the usage message) to stderr and returns
    2; ``--debug`` anywhere on the command line shows the traceback (and
    Python warnings) instead.

    Examples
    --------
    >>> from eulerpoisson.cli import main
    >>> main(["simulate", "--inertia", "1,2,2.5", "--omega", "1,0.1,0.5", "--t-end", "1", "--json"])
    {"t": 1.0, "quaternion": [0.849693475..., 0.454793915..., 0.133837061..., 0.230805400...],
     ..., "method": "exact", ...}
    0
    """
    argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    try:
        with _quiet_warnings(not debug):
            parser = build_parser()
            args = parser.parse_args(_prepare_argv(argv, parser))
            if not getattr(args, "command", None):
                parser.print_help()
                return EXIT_USAGE
            return int(args.func(args) or 0)
    except SystemExit as exc:  # --help / --version
        return int(exc.code or 0) if isinstance(exc.code, int) else 0
    except KeyboardInterrupt:
        print("eulerpoisson: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader closed the pipe (``eulerpoisson info run.nc | head``): not an error
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):  # pragma: no cover - stdout without a file descriptor
            pass
        return 0
    except Exception as exc:  # noqa: BLE001 - the command line never shows a traceback without --debug
        if debug:
            raise
        print(_error_line(exc), file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
