"""The description of a sweep: its TOML (or dict) schema, validated by :func:`load_config` into a
:class:`SweepConfig`, and the parameter points of a grid or random sweep.

What a sweep computes and the layout of its store are described in :mod:`eulerpoisson.sweep.runner`.

TOML schema
-----------
.. code-block:: toml

    [sweep]
    kind = "grid"              # "grid" (Cartesian product of all axes) or "random"
    samples = 10000            # random only: number of points
    seed = 0                   # random only

    [inertia]                  # principal moments, body frame = principal frame
    I1 = 1.0                   # a number, a list of numbers, or a range
    I2 = {start = 1.1, stop = 2.9, num = 19}   # range; add log = true for geometric spacing
    I3 = 3.0
    # instead of I2/I3: ratio21 = I2/I1 and ratio31 = I3/I1 (same value forms)
    allow_unphysical = false   # true: run even when no body is physical (triangle inequality; NaN results)

    [momentum]                 # direction of the initial BODY angular momentum M0
    polar = {start = 0.0, stop = 180.0, num = 91}     # angle from principal axis 3
    azimuth = {start = 0.0, stop = 360.0, num = 181}  # from axis 1 towards axis 2
    magnitude = 1.0            # |M0| > 0
    degrees = true             # angles in degrees (default) or radians

    [output]
    path = "atlas.zarr"        # a .zarr store in the folder of this file (--out writes elsewhere)
    chunk = 256                # points per task (and per Zarr chunk)

    [compute]
    T = 50.0                   # time of the attitude sensitivity, > 0
    delta = 1e-6               # perturbation angle of M0 (radians), 0 < delta < 0.1
    scheduler = "local"        # "local" | "serial" | "tcp://HOST:PORT"
    workers = 2                # LocalCluster worker processes (default: CPU count)
    method = "exact"           # solve method for the attitudes

For ``kind = "grid"`` a range needs ``num`` (>= 1); for ``kind = "random"``
a range is sampled uniformly (log-uniformly with ``log = true``), a list by
uniform choice, and the directions uniformly on the sphere (the cosine of the
polar angle uniform) within the polar and azimuth ranges. Required keys:
``[inertia] I1`` and either ``I2, I3`` or ``ratio21, ratio31``;
``[momentum] polar, azimuth``; ``[output] path``; ``[compute] T``
(``[sweep]`` may be left out for a grid); every other key has the default
shown. Unknown sections or keys are errors, and every error names the
section and key.

Where a file writes: ``[output] path`` of a sweep *file* is read in the
folder of the file (``examples/sweep.toml`` with ``path = "atlas.zarr"``
writes ``examples/atlas.zarr``) and must stay inside it: an absolute path
elsewhere or a ``..`` that leaves the folder is refused (a file from
elsewhere cannot choose where your results go; name another place with
``--out`` or ``run_sweep(..., path=)``), and it must end in ``.zarr``.

Sizes are checked before anything is allocated: at most
:data:`MAX_AXIS_VALUES` values on one grid axis and :data:`MAX_POINTS`
points in a sweep. A sweep in which no body is physical (principal
moments violating the triangle inequality :math:`I_i + I_j \\ge I_k`, e.g.
``I = (1, 2, 5)``: every result would be NaN) is refused unless
``[inertia] allow_unphysical = true`` (``--allow-unphysical``,
``allow_unphysical=True``); in a sweep that mixes both kinds, the bodies
that are not physical get status 3 and NaN results.
"""

from __future__ import annotations

import copy
import math
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidInputError

__all__ = ["SweepConfig", "load_config", "is_remote", "check_physical", "MAX_POINTS", "MAX_AXIS_VALUES"]

#: version of the store format (part of a sweep's fingerprint)
FORMAT_VERSION = 1
#: most points of one sweep (a store of 1e10 points is about a terabyte, and each point is solved three times)
MAX_POINTS = 10**10
#: most values of one grid axis (the axes are kept in memory and in the store's attributes)
MAX_AXIS_VALUES = 10**6
_SCHEMA = {
    "sweep": {"kind", "samples", "seed"},
    "inertia": {"I1", "I2", "I3", "ratio21", "ratio31", "allow_unphysical"},
    "momentum": {"polar", "azimuth", "magnitude", "degrees"},
    "output": {"path", "chunk"},
    "compute": {"T", "delta", "scheduler", "workers", "method"},
}
_REQUIRED = {"inertia": (), "momentum": ("polar", "azimuth"), "output": ("path",), "compute": ("T",)}
_RANGE_KEYS = {"start", "stop", "num", "log"}


# ---------------------------------------------------------------------------
# configuration
# ---------------------------------------------------------------------------
def _real(v, where: str, *, positive=False) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise InvalidInputError(f"{where} must be a number, got {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise InvalidInputError(f"{where} must be finite, got {v!r}")
    if positive and not x > 0:
        raise InvalidInputError(f"{where} must be > 0, got {v!r}")
    return x


def integer(v, where: str, minimum: int) -> int:
    if isinstance(v, bool) or not isinstance(v, numbers.Integral):
        raise InvalidInputError(f"{where} must be an integer >= {minimum}, got {v!r}")
    if v < minimum:
        raise InvalidInputError(f"{where} must be an integer >= {minimum}, got {v}")
    return int(v)


def _axis_spec(v, where: str, kind: str, positive: bool) -> dict:
    """Normalize a number / list / range table to {'values': [...]} or {'range': ...}."""
    if isinstance(v, dict):
        unknown = set(v) - _RANGE_KEYS
        if unknown:
            raise InvalidInputError(
                f"{where}: unknown key(s) {', '.join(sorted(unknown))} in a range; known: start, stop, num, log"
            )
        for key in ("start", "stop"):
            if key not in v:
                raise InvalidInputError(f"{where}: a range needs {key!r} (start, stop, num)")
        start = _real(v["start"], f"{where}.start", positive=positive)
        stop = _real(v["stop"], f"{where}.stop", positive=positive)
        log = v.get("log", False)
        if not isinstance(log, bool):
            raise InvalidInputError(f"{where}.log must be true or false, got {log!r}")
        num: int | None
        if kind == "grid":
            if "num" not in v:
                raise InvalidInputError(f"{where}: a grid range needs 'num' (the number of values)")
            num = integer(v["num"], f"{where}.num", 1)
            if num > MAX_AXIS_VALUES:
                raise InvalidInputError(
                    f"{where}.num = {num} is more than {MAX_AXIS_VALUES:,} values on one axis of a grid; "
                    "use fewer values, or kind = 'random' with samples"
                )
        else:
            num = integer(v["num"], f"{where}.num", 1) if "num" in v else None
        if log and (start <= 0 or stop <= 0):
            raise InvalidInputError(f"{where}: a log range needs start and stop > 0, got {start!r}, {stop!r}")
        return {"range": {"start": start, "stop": stop, "num": num, "log": log}}
    if isinstance(v, list):
        if not v:
            raise InvalidInputError(f"{where}: the list of values is empty")
        return {"values": [_real(x, f"{where}[{i}]", positive=positive) for i, x in enumerate(v)]}
    return {"values": [_real(v, where, positive=positive)]}


def _grid_values(spec: dict) -> np.ndarray:
    if "values" in spec:
        return np.asarray(spec["values"], float)
    r = spec["range"]
    f = np.geomspace if r["log"] else np.linspace
    return f(r["start"], r["stop"], r["num"])


def _axis_size(spec: dict) -> int:
    """Number of values of a grid axis (without computing them)."""
    return len(spec["values"]) if "values" in spec else int(spec["range"]["num"])


@dataclass(frozen=True)
class SweepConfig:
    """A validated sweep description (see the module docstring for the TOML schema).

    Attributes
    ----------
    kind : str
        ``"grid"`` or ``"random"``.
    samples, seed : int or None
        Random sweeps only.
    inertia : dict
        Axis name (``I1`` and ``I2, I3`` or ``ratio21, ratio31``) -> normalized spec.
    polar, azimuth : dict
        Normalized specs of the momentum direction.
    magnitude : float
    degrees : bool
    path : str
    chunk : int
    T, delta : float
    scheduler : str
    workers : int or None
    method : str
    allow_unphysical : bool
        Whether a sweep in which no body is physical (triangle inequality violated) runs (status 3,
        NaN results) instead of being refused; not part of the fingerprint (it changes no result).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_config
    >>> cfg = load_config({"inertia": {"I1": 1.0, "I2": 2.0, "I3": 2.5},
    ...                    "momentum": {"polar": [10.0, 80.0], "azimuth": 0.0},
    ...                    "output": {"path": "atlas.zarr"}, "compute": {"T": 10.0, "scheduler": "serial"}})
    >>> type(cfg).__name__, cfg.kind, cfg.T, cfg.scheduler, cfg.chunk
    ('SweepConfig', 'grid', 10.0, 'serial', 256)
    """

    kind: str
    inertia: dict
    polar: dict
    azimuth: dict
    path: str
    T: float
    samples: int | None = None
    seed: int | None = None
    magnitude: float = 1.0
    degrees: bool = True
    chunk: int = 256
    delta: float = 1e-6
    scheduler: str = "local"
    workers: int | None = None
    method: str = "exact"
    allow_unphysical: bool = False
    source: str = field(default="<dict>", compare=False)

    # -- derived --------------------------------------------------------
    @property
    def axis_names(self) -> list[str]:
        """The sweep's axes, in point order (the last varies fastest)."""
        return list(self.inertia) + ["polar", "azimuth"]

    @property
    def grid_axes(self) -> dict[str, np.ndarray]:
        """Axis values of a grid sweep."""
        specs = {**self.inertia, "polar": self.polar, "azimuth": self.azimuth}
        return {name: _grid_values(specs[name]) for name in self.axis_names}

    @property
    def n_points(self) -> int:
        if self.kind == "random":
            assert self.samples is not None  # required for kind = 'random'
            return int(self.samples)
        specs = {**self.inertia, "polar": self.polar, "azimuth": self.azimuth}
        return math.prod(_axis_size(specs[name]) for name in self.axis_names)

    def fingerprint(self) -> dict:
        """What determines the results (not where or how they are computed)."""
        return {
            "format": FORMAT_VERSION,
            "kind": self.kind,
            "samples": self.samples,
            "seed": self.seed,
            "inertia": self.inertia,
            "polar": self.polar,
            "azimuth": self.azimuth,
            "magnitude": self.magnitude,
            "degrees": self.degrees,
            "chunk": self.chunk,
            "T": self.T,
            "delta": self.delta,
            "method": self.method,
        }

    def replace(self, **changes) -> SweepConfig:
        d = {k: copy.deepcopy(getattr(self, k)) for k in self.__dataclass_fields__}
        d.update(changes)
        return SweepConfig(**d)


def check_scheduler(s, where: str) -> str:
    import re

    if not isinstance(s, str) or not (s in ("local", "serial") or s.startswith(("tcp://", "tls://"))):
        raise InvalidInputError(
            f"{where} must be 'local', 'serial' or a scheduler address 'tcp://HOST:PORT', got {s!r}"
        )
    if s.startswith(("tcp://", "tls://")) and not re.fullmatch(r"(tcp|tls)://(\[[0-9a-fA-F:.]+\]|[^:/\s]+):\d{1,5}", s):
        raise InvalidInputError(
            f"{where} {s!r} must name a host and a port: 'tcp://HOST:PORT' (e.g. tcp://127.0.0.1:8786)"
        )
    return s


def check_store_name(value: str, where: str) -> None:
    """A sweep writes a Zarr store: its name ends in ``.zarr`` (and holds no control character).

    Raises
    ------
    InvalidInputError
        As said; the message names ``where``.
    """
    if any(ord(c) < 32 or ord(c) == 127 for c in value):
        raise InvalidInputError(f"{where} {value!r}: a file name must not contain control characters (newline, tab)")
    p = Path(value)
    if p.suffix != ".zarr" or not p.stem:
        raise InvalidInputError(
            f"{where} {value!r}: a sweep writes a Zarr store: name it NAME.zarr (e.g. "
            f"{(p.stem or 'atlas') + '.zarr'!r})"
        )


def _path_in_folder(value: str, file: Path, name: str) -> str:
    """``[output] path`` of a sweep file: read in the file's folder, refused when it leaves the folder."""
    folder = os.path.dirname(str(file))
    base = os.path.abspath(folder or os.curdir)
    norm = os.path.normpath(value)
    full = norm if os.path.isabs(norm) else os.path.normpath(os.path.join(base, norm))
    try:
        rel = os.path.relpath(full, base)
    except ValueError:  # another drive (Windows)
        rel = os.pardir
    if rel == os.curdir or rel == os.pardir or rel.startswith(os.pardir + os.sep):
        raise InvalidInputError(
            f"{name}: [output] path {value!r} is outside the folder of the sweep file ({base}): a file writes only "
            "inside its own folder; name another place on the command line with --out (path= in run_sweep)"
        )
    check_store_name(value, f"{name}: [output] path")
    return full if os.path.isabs(norm) else os.path.join(folder, norm)


def _interval(spec: dict) -> tuple[float, float]:
    """Smallest and largest value an axis can take (a list or a range)."""
    if "values" in spec:
        return float(min(spec["values"])), float(max(spec["values"]))
    r = spec["range"]
    return min(r["start"], r["stop"]), max(r["start"], r["stop"])


#: grids of at most this many bodies are checked body by body
_ENUMERATE_BODIES = 2**20


def check_physical(cfg: SweepConfig) -> None:
    """Refuse a sweep in which no body is physical, unless ``cfg.allow_unphysical``.

    Principal moments are those of a mass distribution only when they
    satisfy the triangle inequalities :math:`I_i + I_j \\ge I_k`; a body
    that violates them gets status 3 and NaN results, so a sweep of such
    bodies only would compute nothing. A sweep that mixes both kinds runs
    (its summary counts the points of each status). A grid of up to
    2**20 bodies is checked body by body; a random
    sweep (or a larger grid) over the box of its axes, exactly: the margin
    :math:`I_1 + I_2 + I_3 - 2\\max I` is concave and piecewise linear, so
    its largest value in the box is at a point whose coordinates are
    bounds of the axes.

    Parameters
    ----------
    cfg : SweepConfig

    Raises
    ------
    InvalidInertiaError
        As said; the message gives a body of the sweep.

    Examples
    --------
    >>> from eulerpoisson.sweep import load_config
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": [5.0, 6.0]}, "momentum": {"polar": 45.0, "azimuth": 0.0},
    ...        "output": {"path": "u.zarr"}, "compute": {"T": 1.0}}
    >>> try:
    ...     load_config(cfg)
    ... except ValueError as err:
    ...     print(str(err)[:78])
    <dict>: [inertia] no body of the sweep is physical: all 2 violate the triangle
    >>> load_config(cfg, allow_unphysical=True).allow_unphysical
    True
    """
    if cfg.allow_unphysical:
        return
    import itertools

    from ..errors import InvalidInertiaError
    from .points import classify

    names = list(cfg.inertia)
    total = math.prod(_axis_size(cfg.inertia[k]) for k in names) if cfg.kind == "grid" else None
    if total is not None and total <= _ENUMERATE_BODIES:
        grids = np.meshgrid(*(_grid_values(cfg.inertia[k]) for k in names), indexing="ij")
        I = moments_from_axes(cfg, {k: g.ravel() for k, g in zip(names, grids)})
        how_many = "the body of the sweep is not physical: it" if total == 1 else f"all {total} violate"
    else:
        bounds = {k: _interval(cfg.inertia[k]) for k in names}
        if "ratio21" in bounds:  # the triangle inequalities do not depend on the scale I1
            bounds["I1"] = (1.0, 1.0)
        values = sorted({x for b in bounds.values() for x in b})
        inside = [[v for v in values if bounds[k][0] <= v <= bounds[k][1]] for k in names]
        corners = np.array(list(itertools.product(*inside)))
        I = moments_from_axes(cfg, {k: corners[:, i] for i, k in enumerate(names)})
        how_many = "the ranges of its axes hold only bodies that violate"
    status = classify(I)
    if np.any(status != 3):
        return
    example = "(" + ", ".join(f"{x:.6g}" for x in I[0]) + ")"
    what = "it" if total == 1 else "them"
    raise InvalidInertiaError(
        f"{cfg.source}: [inertia] no body of the sweep is physical: {how_many} the triangle inequality, e.g. "
        f"I = {example} (one moment exceeds the sum of the other two: no mass distribution has these moments), "
        f"so every result would be NaN; to sweep {what} anyway (status 3), pass allow_unphysical=True "
        "(in a sweep file: [inertia] allow_unphysical = true)"
    )


def is_remote(scheduler: str) -> bool:
    """Whether ``scheduler`` is the address of a cluster (tcp:// or tls://), not one started here."""
    return scheduler.startswith(("tcp://", "tls://"))


def load_config(
    source: str | os.PathLike[str] | dict[str, Any],
    *,
    path: str | os.PathLike[str] | None = None,
    allow_unphysical: bool | None = None,
) -> SweepConfig:
    """Read and validate a sweep description.

    Parameters
    ----------
    source : str, Path or dict
        A TOML file or the parsed dictionary (same structure). The
        ``[output] path`` of a file is read in the file's folder and must
        stay inside it and end in ``.zarr``; that of a dictionary is used
        as it is.
    path : str or Path, optional
        The output store, chosen by the caller: replaces ``[output] path``
        (which is then not checked).
    allow_unphysical : bool, optional
        Replaces ``[inertia] allow_unphysical`` (default false): whether a
        sweep in which no body is physical runs (status 3, NaN results)
        instead of being refused.

    Returns
    -------
    SweepConfig

    Raises
    ------
    FileNotFoundError
        No such file.
    InvalidInputError
        Invalid TOML, an unknown section or key, a missing key, a value of
        the wrong type or out of range, more than :data:`MAX_POINTS` points
        or :data:`MAX_AXIS_VALUES` values on a grid axis, an ``[output]
        path`` of a file outside its folder or not ending in ``.zarr``; the
        message names ``[section] key``.
    InvalidInertiaError
        No body of the sweep is physical and ``allow_unphysical`` is false
        (see :func:`check_physical`).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_config
    >>> toml = ["[inertia]", "I1 = 1.0", "I2 = {start = 1.5, stop = 2.5, num = 3}", "I3 = 3.0",
    ...         "[momentum]", "polar = 45.0", "azimuth = 30.0",
    ...         "[output]", 'path = "atlas.zarr"', "[compute]", "T = 20.0"]
    >>> with open("sweep.toml", "w") as fh:
    ...     for line in toml:
    ...         print(line, file=fh)
    >>> cfg = load_config("sweep.toml")
    >>> cfg.inertia["I2"], cfg.path
    ({'range': {'start': 1.5, 'stop': 2.5, 'num': 3, 'log': False}}, 'atlas.zarr')
    >>> import os
    >>> os.makedirs("sweeps", exist_ok=True)
    >>> with open("sweeps/escape.toml", "w") as fh:
    ...     for line in toml:
    ...         print(line.replace('"atlas.zarr"', '"../../atlas.zarr"'), file=fh)
    >>> try:
    ...     load_config("sweeps/escape.toml")
    ... except ValueError as err:
    ...     print(str(err)[:75])
    sweeps/escape.toml: [output] path '../../atlas.zarr' is outside the folder
    >>> load_config("sweeps/escape.toml", path="mine.zarr").path
    'mine.zarr'
    >>> try:
    ...     load_config({"inertia": {"I1": 1.0}})
    ... except ValueError as err:
    ...     print(err)
    <dict>: missing section [momentum]
    """
    file: Path | None = None
    if isinstance(source, dict):
        cfg, name = source, "<dict>"
    else:
        import tomllib

        p = Path(source)
        if not p.is_file():
            raise FileNotFoundError(f"sweep file {str(p)!r} does not exist")
        try:
            with open(p, "rb") as fh:
                cfg = tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise InvalidInputError(f"{p}: invalid TOML: {exc}") from None
        except RecursionError:
            raise InvalidInputError(f"{p}: invalid TOML: nested too deeply (a sweep file has two levels)") from None
        name, file = str(p), p

    for sec, body in cfg.items():
        if sec not in _SCHEMA:
            raise InvalidInputError(f"{name}: unknown section [{sec}]; known: {', '.join(sorted(_SCHEMA))}")
        if not isinstance(body, dict):
            raise InvalidInputError(f"{name}: [{sec}] must be a table")
        unknown = set(body) - _SCHEMA[sec]
        if unknown:
            raise InvalidInputError(
                f"{name}: unknown key(s) {', '.join(sorted(unknown))} in [{sec}]; known: {', '.join(sorted(_SCHEMA[sec]))}"
            )
    for sec, keys in _REQUIRED.items():
        if sec not in cfg:
            raise InvalidInputError(f"{name}: missing section [{sec}]")
        for key in keys:
            if key not in cfg[sec]:
                raise InvalidInputError(f"{name}: [{sec}] {key} is required")

    sw = cfg.get("sweep", {})
    kind = sw.get("kind", "grid")
    if kind not in ("grid", "random"):
        raise InvalidInputError(f"{name}: [sweep] kind must be 'grid' or 'random', got {kind!r}")
    samples = seed = None
    if kind == "random":
        if "samples" not in sw:
            raise InvalidInputError(f"{name}: [sweep] samples is required for kind = 'random'")
        samples = integer(sw["samples"], f"{name}: [sweep] samples", 1)
        seed = integer(sw.get("seed", 0), f"{name}: [sweep] seed", 0)
    else:
        for key in ("samples", "seed"):
            if key in sw:
                raise InvalidInputError(f"{name}: [sweep] {key} is only used with kind = 'random'")

    inn = cfg["inertia"]
    if "I1" not in inn:
        raise InvalidInputError(f"{name}: [inertia] I1 is required")
    moments = {"I2", "I3"} & set(inn)
    ratios = {"ratio21", "ratio31"} & set(inn)
    if moments and ratios:
        raise InvalidInputError(f"{name}: [inertia] give either I2, I3 or ratio21, ratio31, not both")
    names = ["I1", "ratio21", "ratio31"] if ratios else ["I1", "I2", "I3"]
    for key in names:
        if key not in inn:
            raise InvalidInputError(f"{name}: [inertia] {key} is required")
    inertia = {key: _axis_spec(inn[key], f"{name}: [inertia] {key}", kind, True) for key in names}
    allow = inn.get("allow_unphysical", False)
    if not isinstance(allow, bool):
        raise InvalidInputError(f"{name}: [inertia] allow_unphysical must be true or false, got {allow!r}")
    if allow_unphysical is not None:
        allow = bool(allow_unphysical)

    mo = cfg["momentum"]
    degrees = mo.get("degrees", True)
    if not isinstance(degrees, bool):
        raise InvalidInputError(f"{name}: [momentum] degrees must be true or false, got {degrees!r}")
    polar = _axis_spec(mo["polar"], f"{name}: [momentum] polar", kind, False)
    azimuth = _axis_spec(mo["azimuth"], f"{name}: [momentum] azimuth", kind, False)
    top = 180.0 if degrees else math.pi
    for v in _grid_values(polar) if "values" in polar else [polar["range"]["start"], polar["range"]["stop"]]:
        if not (0.0 <= v <= top):
            raise InvalidInputError(f"{name}: [momentum] polar must lie in [0, {top:g}], got {v!r}")
    magnitude = _real(mo.get("magnitude", 1.0), f"{name}: [momentum] magnitude", positive=True)

    if kind == "random":
        assert samples is not None
        n_points = samples
    else:
        n_points = math.prod(_axis_size(s) for s in (*inertia.values(), polar, azimuth))
    if n_points > MAX_POINTS:
        what = "[sweep] samples" if kind == "random" else "the grid"
        raise InvalidInputError(
            f"{name}: {what} has {n_points:.3g} points, more than {MAX_POINTS:,} (a store of about "
            f"{n_points * 113 / 1e12:.3g} TB, and each point is solved three times); sweep fewer points"
        )

    out = cfg["output"]
    given = out["path"]
    if not isinstance(given, str) or not given.strip():
        raise InvalidInputError(f"{name}: [output] path must be a non-empty string, got {given!r}")
    if path is not None:
        given = os.fspath(path)  # the caller's choice: the file's path is not used
    elif file is not None:
        given = _path_in_folder(given, file, name)
    chunk = integer(out.get("chunk", 256), f"{name}: [output] chunk", 1)

    co = cfg["compute"]
    T = _real(co["T"], f"{name}: [compute] T", positive=True)
    delta = _real(co.get("delta", 1e-6), f"{name}: [compute] delta", positive=True)
    if not delta < 0.1:
        raise InvalidInputError(
            f"{name}: [compute] delta must be a small angle in radians, 0 < delta < 0.1, got {delta!r}"
        )
    scheduler = check_scheduler(co.get("scheduler", "local"), f"{name}: [compute] scheduler")
    workers = co.get("workers")
    if workers is not None:
        workers = integer(workers, f"{name}: [compute] workers", 1)
    method = co.get("method", "exact")
    if not isinstance(method, str):
        raise InvalidInputError(f"{name}: [compute] method must be a method name, got {method!r}")
    from ..solvers import available_methods

    if method not in available_methods():
        raise InvalidInputError(
            f"{name}: [compute] method: unknown method {method!r}; available: {', '.join(available_methods())}"
        )
    config = SweepConfig(
        kind=kind,
        samples=samples,
        seed=seed,
        inertia=inertia,
        polar=polar,
        azimuth=azimuth,
        magnitude=magnitude,
        degrees=degrees,
        path=given,
        chunk=chunk,
        T=T,
        delta=delta,
        scheduler=scheduler,
        workers=workers,
        method=method,
        allow_unphysical=allow,
        source=name,
    )
    check_physical(config)
    return config


# ---------------------------------------------------------------------------
# the parameter points
# ---------------------------------------------------------------------------
def moments_from_axes(cfg: SweepConfig, vals: dict) -> np.ndarray:
    I1 = vals["I1"]
    if "ratio21" in vals:
        I2, I3 = vals["ratio21"] * I1, vals["ratio31"] * I1
    else:
        I2, I3 = vals["I2"], vals["I3"]
    return np.stack(np.broadcast_arrays(I1, I2, I3), -1).astype(float)


def direction(polar, azimuth, degrees: bool) -> np.ndarray:
    th = np.deg2rad(polar) if degrees else np.asarray(polar, float)
    ph = np.deg2rad(azimuth) if degrees else np.asarray(azimuth, float)
    return np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)


def grid_points(cfg: SweepConfig, a: int, b: int) -> dict:
    axes = cfg.grid_axes
    shape = tuple(len(v) for v in axes.values())
    idx = np.unravel_index(np.arange(a, b), shape)
    vals = {name: axes[name][i] for name, i in zip(axes, idx)}
    return vals


def random_points(cfg: SweepConfig) -> dict:
    rng = np.random.default_rng(cfg.seed)
    n = cfg.samples
    assert n is not None  # required for kind = 'random'
    vals = {}
    for name in cfg.axis_names:
        spec = {**cfg.inertia, "polar": cfg.polar, "azimuth": cfg.azimuth}[name]
        if "values" in spec:
            v = np.asarray(spec["values"], float)
            vals[name] = v[rng.integers(0, v.size, n)] if v.size > 1 else np.full(n, v[0])
            continue
        r = spec["range"]
        u = rng.random(n)
        if name == "polar":  # uniform on the sphere: cos(polar) uniform
            s = (math.pi / 180.0) if cfg.degrees else 1.0
            c0, c1 = math.cos(r["start"] * s), math.cos(r["stop"] * s)
            vals[name] = np.arccos(np.clip(c0 + (c1 - c0) * u, -1.0, 1.0)) / s
        elif r["log"]:
            vals[name] = np.exp(math.log(r["start"]) + (math.log(r["stop"]) - math.log(r["start"])) * u)
        else:
            vals[name] = r["start"] + (r["stop"] - r["start"]) * u
    return vals
