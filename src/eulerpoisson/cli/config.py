"""The configuration of ``eulerpoisson simulate``: its TOML schema and the merge with the flags.

A TOML file is checked and flattened to ``{"section.key": value}``; the
flags replace what the file says; the body, the torques and the method
options are built from the merged configuration, with messages that name
the flag or the ``file: [section] key`` each value came from.

The torque flags and the ``[torque]`` keys are those of the registered
torques (:data:`eulerpoisson.torques.TORQUES`, each class's
:attr:`~eulerpoisson.torques.Torque.cli`): a new torque class with a ``cli``
gets its flags, its TOML keys and its place in :func:`build_torques` with no
edit here, as the method options come from the methods' option dataclasses.
"""

from __future__ import annotations

import json
import math
import os

from ..model.torques import TORQUES, Torque, TorqueParam
from .common import UsageError, inertia_from, parse_floats

__all__ = [
    "METHOD_OPTIONS",
    "FLAGS",
    "config_from_toml",
    "namer",
    "pair",
    "build_body",
    "build_torques",
    "method_options",
    "torque_params",
    "torque_toml_keys",
    "sync_torque_keys",
]


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


def torque_params() -> list[tuple[type, TorqueParam]]:
    """``(torque class, TorqueParam)`` of every command-line parameter of every registered torque.

    In the order of :data:`~eulerpoisson.torques.TORQUES` and, within a class,
    of its :attr:`~eulerpoisson.torques.Torque.cli`: the order of the flags in
    ``simulate --help``.

    Examples
    --------
    >>> from eulerpoisson.cli.config import torque_params
    >>> [p.flag for _, p in torque_params()][:4]
    ['--com', '--mass', '--gravity', '--gravity-gradient']
    """
    return [(cls, p) for cls in TORQUES.values() for p in cls.cli]


def torque_toml_keys() -> str:
    """The keys of ``[torque]`` as ``simulate --help`` lists them: a class's keys joined by commas, classes by ``;``.

    Examples
    --------
    >>> from eulerpoisson.cli.config import torque_toml_keys
    >>> torque_toml_keys().split("; ")[:2]
    ['center_of_mass=[...], mass, gravity=[...]', 'gravity_gradient']
    """
    return "; ".join(
        ", ".join(p.toml_key + ("=[...]" if p.toml_kind == "numbers" else "") for p in cls.cli)
        for cls in TORQUES.values()
        if cls.cli
    )


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
    # the parameters of the registered torques (sync_torque_keys brings it up to date with TORQUES)
    "torque": {p.toml_key: p.toml_kind for _, p in torque_params()},
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


def config_from_toml(cfg: dict, path: str, src: dict | None = None) -> dict:
    """Flatten and check a ``simulate`` TOML file: ``{"section.key": value}``.

    ``src`` (if given) receives, for each key, the name used in messages
    (``"run.toml: [method] order"``).
    """
    sync_torque_keys()
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


#: command-line flag of each configuration key (the name used in messages when the value came from a flag)
FLAGS = {
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
    **{f"torque.{p.toml_key}": p.flag for _, p in torque_params()},
    "compute.workers": "--workers",
}


def sync_torque_keys() -> None:
    """Bring :data:`FLAGS` and the ``[torque]`` keys of the TOML schema up to date with the torque registry.

    A torque registered after this module was imported
    (:func:`eulerpoisson.torques.register_torque`) gets its flags and keys;
    one removed from the registry loses them. ``simulate`` calls it when it
    builds its parser and reads its configuration.

    Examples
    --------
    >>> from eulerpoisson.cli.config import FLAGS, sync_torque_keys
    >>> sync_torque_keys()
    >>> FLAGS["torque.magnetic_field"]
    '--magnetic-field'
    """
    params = torque_params()
    flags = {f"torque.{p.toml_key}": p.flag for _, p in params}
    for key in [k for k in FLAGS if k.startswith("torque.") and k not in flags]:
        del FLAGS[key]
    FLAGS.update(flags)
    _TOML_KINDS["torque"] = {p.toml_key: p.toml_kind for _, p in params}
    _TOML_KEYS["torque"] = set(_TOML_KINDS["torque"])


def namer(src: dict):
    """``name(key)``: the flag or ``file: [section] key`` a value came from."""

    def name(key: str) -> str:
        if key in src:
            return src[key]
        section, _, k = key.partition(".")
        return FLAGS.get(key, f"[{section}] {k}")

    return name


def pair(name, k1: str, k2: str) -> tuple[str, str, str]:
    """Names of two keys for one message: ``(prefix, a, b)``; the file is said once when both come from it."""
    a, b = name(k1), name(k2)
    fa, _, ra = a.rpartition(": ")
    fb, _, rb = b.rpartition(": ")
    if fa and fa == fb:
        return f"{fa}: ", ra, rb
    return "", a, b


def build_body(cfg, name=None):
    from ..model.body import RigidBody

    name = name or namer({})
    label = cfg.get("body.name")
    if "body.masses" in cfg or "body.positions" in cfg:
        if "body.inertia" in cfg:
            pre, a, b = pair(name, "body.inertia", "body.masses" if "body.masses" in cfg else "body.positions")
            raise UsageError(f"{pre}give either {a} or [body] masses and positions, not both")
        if "body.masses" not in cfg or "body.positions" not in cfg:
            raise UsageError("a point-mass body needs both [body] masses and [body] positions")
        masses, positions = cfg["body.masses"], cfg["body.positions"]
        if len(masses) != len(positions):
            pre, a, b = pair(name, "body.masses", "body.positions")
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


#: how :func:`build_torques` names a required parameter left out, where the class's own words are kept
#: (``(kind, parameter)``: (what, a note after the flag)); other parameters are named from their class
_NEEDED = {
    ("gravity", "center_of_mass"): ("the centre of mass of the heavy top", " (body frame, from the fixed point)"),
}


def _param_value(p: TorqueParam, value, where: str):
    """The value of a torque parameter from a flag's text or a TOML value, checked by its kind."""
    if p.kind == "vector3":
        return parse_floats(value, where, (3,))
    return _number(value, where, positive=p.kind == "positive")


def build_torques(cfg, name=None) -> list:
    """The torques of ``[torque]`` / the torque flags, in the order of the torque registry.

    Each registered torque with command-line parameters (:attr:`~eulerpoisson.torques.Torque.cli`)
    is built (:meth:`~eulerpoisson.torques.Torque.from_params`) when any of
    its parameters is given: gravity, gravity gradient, body, space, magnetic
    dipole. A parameter given without a required one of its torque is an
    error naming both: a heavy top needs the centre of mass (``--com``); the
    mass defaults to 1 and the gravitational acceleration to (0, 0, -9.81).

    Raises
    ------
    UsageError
        A value that is not what its parameter takes, or a required parameter left out
        (the message names the flag or the ``file: [torque] key`` of the value).

    Examples
    --------
    >>> from eulerpoisson.cli.config import build_torques
    >>> build_torques({"torque.center_of_mass": "0,0,0.1", "torque.body_torque": [0.0, 0.0, 1.0]})
    [Gravity(mass=1.0, center_of_mass=[0.0, 0.0, 0.1], g=[0.0, 0.0, -9.81]), BodyTorque(tau=[0.0, 0.0, 1.0])]
    """
    sync_torque_keys()
    name = name or namer({})
    torques: list[Torque] = []
    for cls in TORQUES.values():
        given = [p for p in cls.cli if f"torque.{p.toml_key}" in cfg]
        if not given:
            continue
        missing = [p for p in cls.cli if p.required and p not in given]
        if missing:
            need = missing[0]
            what, note = _NEEDED.get(
                (cls.kind, need.name),
                (f"the {need.name.replace('_', ' ')} of the {cls.kind.replace('_', ' ')} torque", ""),
            )
            raise UsageError(
                f"{name(f'torque.{given[0].toml_key}')} needs {what}: {need.flag} {need.metavar}{note} "
                f"or [torque] {need.toml_key}"
            )
        values = {p.name: _param_value(p, cfg[f"torque.{p.toml_key}"], name(f"torque.{p.toml_key}")) for p in given}
        torques.append(cls.from_params(values))
    return torques


def method_options(cfg, name=None, method: str | None = None) -> dict:
    """The method options given as flags or in ``[method]``, checked against the method's option dataclass.

    Values are converted by the option's kind (numbers, integers, names); the
    dataclass validates them (its errors name the option). An option of
    another method is an error that lists the chosen method's options.
    """
    import dataclasses

    from ..solvers import get_method

    name = name or namer({})
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
            have = ", ".join(FLAGS[f"method.{a}"] for a in sorted(allowed)) or "none"
            raise UsageError(f"{name(k)} is not an option of method {method!r} (its options: {have})")
        opts[key] = value
    return opts
