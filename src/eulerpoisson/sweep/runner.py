r"""Parameter sweeps: the stability atlas of the tennis-racket effect, with Dask.

A sweep evaluates, at every point of a grid (or of a random sample) of
inertia tensors and directions of the initial body angular momentum,

* the **flip half-period** :math:`T_{1/2} = 2K(k)/\lambda`, the time between
  consecutive flips of the momentum components that change sign
  (:func:`~eulerpoisson.analysis.tennis_racket_half_period`); it is infinite
  on the separatrix :math:`L^2 = 2EI_2` and undefined (NaN) for a symmetric
  body. For a momentum exactly along the smallest or largest axis (a
  permanent rotation) it is the limit value :math:`\pi/\lambda`;
* the Jacobi parameter :math:`k^2` of the polhode
  (:func:`~eulerpoisson.analysis.elliptic_parameters`);
* an **attitude sensitivity**: with :math:`\mathbf u` the unit direction of
  the initial body momentum :math:`\mathbf M_0 = L\mathbf u` (attitude the
  identity) and :math:`\mathbf e_\theta,\mathbf e_\varphi` the polar and
  azimuthal unit tangents of the sphere at :math:`\mathbf u`, the initial
  states :math:`L(\cos\delta\,\mathbf u + \sin\delta\,\mathbf e)` differ
  from :math:`\mathbf M_0` by the angle :math:`\delta`; the sensitivity is

  .. math:: S = \max_{\mathbf e\in\{\mathbf e_\theta, \mathbf e_\varphi\}}
            \frac{\angle\big(R(T;\mathbf M_0),\, R(T;\mathbf M_0^{\mathbf e})\big)}{\delta},

  the rotation angle between the two attitudes at time :math:`T` over
  :math:`\delta` (a finite-difference estimate of the growth of attitude
  errors; it grows linearly in :math:`T` away from the separatrix and
  peaks on it).

The work is split into chunks of ``chunk`` points; each chunk is one task.
Tasks run on a Dask cluster — an embedded :class:`distributed.LocalCluster`
by default, an existing scheduler given by its address
``"tcp://HOST:PORT"``, or ``"serial"`` (plain loop, no Dask: the
reference). The client writes every finished chunk to a Zarr store and then
records it as done, so an interrupted sweep (Ctrl-C, a crash, a kill)
restarts where it stopped: rerunning the same sweep computes only the
missing chunks. Results do not depend on the scheduler: each point is
computed by the same code on the same chunk of inputs, so serial and
distributed sweeps agree bit for bit.

Store layout
------------
Work happens in ``.NAME.partial/`` next to the output path (the store is
``.NAME.partial/store.zarr``; marker files ``.NAME.partial/done/CHUNK``);
when every chunk is done the store is renamed to the output path. The store
holds, along a ``point`` dimension, the parameters ``I1, I2, I3`` (principal
moments), ``polar, azimuth`` (degrees or radians, as configured), ``M0``
(``point, axis``), the results ``half_period, k2, sensitivity`` and
``status`` (0 regular, 1 on the separatrix, 2 symmetric body, 3 not a
physical body: triangle inequality violated), and along a ``chunk``
dimension the bookkeeping ``chunk_count`` (how many times the chunk was
computed and written: 1 after any number of interruptions and resumes),
``chunk_time`` (UNIX time of the write) and ``chunk_seconds`` (compute time).
The attribute ``sweep_config`` is the normalized configuration (JSON);
``sweep_grid`` the grid axes. :func:`load_sweep` reshapes a grid sweep to
its axes.

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

    [momentum]                 # direction of the initial BODY angular momentum M0
    polar = {start = 0.0, stop = 180.0, num = 91}     # angle from principal axis 3
    azimuth = {start = 0.0, stop = 360.0, num = 181}  # from axis 1 towards axis 2
    magnitude = 1.0            # |M0| > 0
    degrees = true             # angles in degrees (default) or radians

    [output]
    path = "atlas.zarr"        # relative to the current folder
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

References
----------
L. D. Landau and E. M. Lifshitz, *Mechanics*, §37 (the periods). M. S.
Ashbaugh, C. C. Chicone and R. H. Cushman, "The twisting tennis racket",
J. Dyn. Diff. Eq. 3 (1991) 67-85.
"""

from __future__ import annotations

import copy
import json
import logging
import math
import numbers
import os
import shutil
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    import xarray as xr

from ..errors import EulerPoissonError, InvalidInputError, require
from ..io.stream import (
    ProgressDisplay,
    check_replaceable,
    done_chunks,
    mark_done,
    quiet_zarr,
    replace_dir,
    work_dir,
    write_json_atomic,
)

__all__ = [
    "SweepConfig",
    "load_config",
    "compute_points",
    "run_sweep",
    "load_sweep",
    "plot_atlas",
    "STATUS",
]

#: meaning of the ``status`` codes
STATUS = {0: "regular", 1: "separatrix", 2: "symmetric body", 3: "not a physical body"}

_FORMAT_VERSION = 1
_SCHEMA = {
    "sweep": {"kind", "samples", "seed"},
    "inertia": {"I1", "I2", "I3", "ratio21", "ratio31"},
    "momentum": {"polar", "azimuth", "magnitude", "degrees"},
    "output": {"path", "chunk"},
    "compute": {"T", "delta", "scheduler", "workers", "method"},
}
_REQUIRED = {"inertia": (), "momentum": ("polar", "azimuth"), "output": ("path",), "compute": ("T",)}
_RANGE_KEYS = {"start", "stop", "num", "log"}
_TOL = 1e-12  # same relative tolerance as RigidBody's degeneracy checks


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


def _integer(v, where: str, minimum: int) -> int:
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
            num = _integer(v["num"], f"{where}.num", 1)
        else:
            num = _integer(v["num"], f"{where}.num", 1) if "num" in v else None
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
        return int(np.prod([len(v) for v in self.grid_axes.values()]))

    def fingerprint(self) -> dict:
        """What determines the results (not where or how they are computed)."""
        return {
            "format": _FORMAT_VERSION,
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


def _check_scheduler(s, where: str) -> str:
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


def is_remote(scheduler: str) -> bool:
    """Whether ``scheduler`` is the address of a cluster (tcp:// or tls://), not one started here."""
    return scheduler.startswith(("tcp://", "tls://"))


def load_config(source: str | os.PathLike[str] | dict[str, Any]) -> SweepConfig:
    """Read and validate a sweep description.

    Parameters
    ----------
    source : str, Path or dict
        A TOML file or the parsed dictionary (same structure).

    Returns
    -------
    SweepConfig

    Raises
    ------
    FileNotFoundError
        No such file.
    InvalidInputError
        Invalid TOML, an unknown section or key, a missing key, a value of
        the wrong type or out of range; the message names ``[section] key``.

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
    >>> try:
    ...     load_config({"inertia": {"I1": 1.0}})
    ... except ValueError as err:
    ...     print(err)
    <dict>: missing section [momentum]
    """
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
        name = str(p)

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
        samples = _integer(sw["samples"], f"{name}: [sweep] samples", 1)
        seed = _integer(sw.get("seed", 0), f"{name}: [sweep] seed", 0)
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

    out = cfg["output"]
    path = out["path"]
    if not isinstance(path, str) or not path.strip():
        raise InvalidInputError(f"{name}: [output] path must be a non-empty string, got {path!r}")
    chunk = _integer(out.get("chunk", 256), f"{name}: [output] chunk", 1)

    co = cfg["compute"]
    T = _real(co["T"], f"{name}: [compute] T", positive=True)
    delta = _real(co.get("delta", 1e-6), f"{name}: [compute] delta", positive=True)
    if not delta < 0.1:
        raise InvalidInputError(
            f"{name}: [compute] delta must be a small angle in radians, 0 < delta < 0.1, got {delta!r}"
        )
    scheduler = _check_scheduler(co.get("scheduler", "local"), f"{name}: [compute] scheduler")
    workers = co.get("workers")
    if workers is not None:
        workers = _integer(workers, f"{name}: [compute] workers", 1)
    method = co.get("method", "exact")
    if not isinstance(method, str):
        raise InvalidInputError(f"{name}: [compute] method must be a method name, got {method!r}")
    from ..solvers import available_methods

    if method not in available_methods():
        raise InvalidInputError(
            f"{name}: [compute] method: unknown method {method!r}; available: {', '.join(available_methods())}"
        )
    return SweepConfig(
        kind=kind,
        samples=samples,
        seed=seed,
        inertia=inertia,
        polar=polar,
        azimuth=azimuth,
        magnitude=magnitude,
        degrees=degrees,
        path=path,
        chunk=chunk,
        T=T,
        delta=delta,
        scheduler=scheduler,
        workers=workers,
        method=method,
        source=name,
    )


# ---------------------------------------------------------------------------
# the parameter points
# ---------------------------------------------------------------------------
def _moments_from_axes(cfg: SweepConfig, vals: dict) -> np.ndarray:
    I1 = vals["I1"]
    if "ratio21" in vals:
        I2, I3 = vals["ratio21"] * I1, vals["ratio31"] * I1
    else:
        I2, I3 = vals["I2"], vals["I3"]
    return np.stack(np.broadcast_arrays(I1, I2, I3), -1).astype(float)


def _direction(polar, azimuth, degrees: bool) -> np.ndarray:
    th = np.deg2rad(polar) if degrees else np.asarray(polar, float)
    ph = np.deg2rad(azimuth) if degrees else np.asarray(azimuth, float)
    return np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)


def _grid_points(cfg: SweepConfig, a: int, b: int) -> dict:
    axes = cfg.grid_axes
    shape = tuple(len(v) for v in axes.values())
    idx = np.unravel_index(np.arange(a, b), shape)
    vals = {name: axes[name][i] for name, i in zip(axes, idx)}
    return vals


def _random_points(cfg: SweepConfig) -> dict:
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


# ---------------------------------------------------------------------------
# the computation of one chunk
# ---------------------------------------------------------------------------
def _classify(I: np.ndarray) -> np.ndarray:
    """Status 0 (asymmetric, physical), 2 (symmetric) or 3 (not a physical body) per row of I (m, 3)."""
    s = np.sort(I, -1)
    tol = _TOL * np.sum(np.abs(s), -1)
    bad = (s[:, 0] <= 0) | (s[:, 0] + s[:, 1] - s[:, 2] < -tol)
    sym = (s[:, 1] - s[:, 0] <= tol) | (s[:, 2] - s[:, 1] <= tol)
    return np.where(bad, 3, np.where(sym, 2, 0)).astype(np.int8)


def _rotation_angle(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    w = np.sum(q1 * q2, -1)
    v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))


def compute_points(
    inertia: ArrayLike,
    M0: ArrayLike,
    *,
    T: float,
    delta: float = 1e-6,
    method: str = "exact",
    workers: int | None = None,
) -> dict[str, Any]:
    r"""Flip half-period, :math:`k^2`, attitude sensitivity and status of a batch of points.

    Parameters
    ----------
    inertia : array_like, shape (P, 3)
        Principal moments (any order; rows that are not physical bodies get
        NaN results and status 3).
    M0 : array_like, shape (P, 3)
        Initial body angular momenta (principal frame), nonzero.
    T : float
        Time of the sensitivity, > 0.
    delta : float
        Perturbation angle of the momentum direction (radians).
    method : str
        Method used to compute the attitudes at ``T``.
    workers : int or None
        Threads of the solve, as for :func:`~eulerpoisson.solve` (the
        results do not depend on it).

    Returns
    -------
    dict of ndarray
        ``half_period`` (P,) (inf on the separatrix, NaN for symmetric or
        non-physical bodies), ``k2`` (P,), ``sensitivity`` (P,) (NaN for
        non-physical bodies), ``status`` (P,) int8 (see :data:`STATUS`).

    Raises
    ------
    InvalidInputError
        Bad shapes, non-finite values, a zero momentum, ``T <= 0`` or
        ``delta`` outside (0, 0.1).

    Notes
    -----
    Pure function of its inputs: the same chunk gives the same bits on any
    worker.

    Examples
    --------
    >>> import numpy as np
    >>> from eulerpoisson.sweep import compute_points
    >>> inertia = [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [2.0, 2.0, 3.0]]
    >>> M0 = [[0.1, 0.0, 1.0], [0.0, 1.0, 0.1], [0.0, 1.0, 0.1]]    # near axis 3, near axis 2, a symmetric body
    >>> out = compute_points(inertia, M0, T=10.0)
    >>> print(np.round(out["half_period"], 6), out["status"])
    [ 9.496682 24.50238        nan] [0 0 2]
    """
    from scipy.special import ellipkm1

    from ..analysis import elliptic_parameters
    from ..model.body import RigidBody
    from ..solvers import solve
    from ..util.validate import as_float_array, as_scalar

    I = as_float_array(inertia, "inertia", (3,)).reshape(-1, 3)
    M = as_float_array(M0, "M0", (3,)).reshape(-1, 3)
    if I.shape != M.shape:
        raise InvalidInputError(f"inertia and M0 must have the same shape (P, 3), got {I.shape} and {M.shape}")
    T = as_scalar(T, "T", positive=True)
    delta = as_scalar(delta, "delta", positive=True)
    if not delta < 0.1:
        raise InvalidInputError(f"delta must be a small angle in radians, 0 < delta < 0.1, got {delta!r}")
    L = np.linalg.norm(M, axis=-1)
    if np.any(L == 0):
        raise InvalidInputError("M0 contains a zero angular momentum (a body at rest has no flips)")
    P = I.shape[0]
    status = _classify(I)
    k2 = np.full(P, np.nan)
    k2c = np.full(P, np.nan)
    lam = np.full(P, np.nan)
    for i in np.nonzero(status == 0)[0]:
        try:
            par = elliptic_parameters(I[i], M[i])
        except InvalidInputError:  # exactly on the separatrix
            status[i], k2[i], k2c[i], lam[i] = 1, 1.0, 0.0, 1.0
            continue
        k2[i], k2c[i], lam[i] = par["k2"], par["k2c"], par["lam"]
    # tennis_racket_half_period = 2 K(k) / lambda, evaluated for the whole chunk at once (same bits)
    with np.errstate(divide="ignore"):
        half = 2.0 * ellipkm1(k2c) / lam
    status[(status == 0) & ~np.isfinite(half)] = 1

    sens = np.full(P, np.nan)
    ok = np.nonzero(status != 3)[0]
    if ok.size:
        Iv, Mv, Lv = I[ok], M[ok], L[ok]
        u = Mv / Lv[:, None]
        th = np.arccos(np.clip(u[:, 2], -1.0, 1.0))
        ph = np.arctan2(u[:, 1], u[:, 0])
        e_th = np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)], -1)
        e_ph = np.stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)], -1)
        c, s = math.cos(delta), math.sin(delta)
        Ms = np.concatenate([Mv, Lv[:, None] * (c * u + s * e_th), Lv[:, None] * (c * u + s * e_ph)])
        Is = np.concatenate([Iv, Iv, Iv])
        # full (diagonal) tensors: a (3, 3) array of moments would read as one tensor
        tr = solve(RigidBody(Is[:, :, None] * np.eye(3)), [T], omega0=Ms / Is, method=method, workers=workers)
        q = tr.quaternion[:, 0, :].reshape(3, ok.size, 4)
        ang = np.maximum(_rotation_angle(q[0], q[1]), _rotation_angle(q[0], q[2]))
        sens[ok] = ang / delta
    return {"half_period": half, "k2": k2, "sensitivity": sens, "status": status}


def _compute_chunk(inertia, M0, T, delta, method, run_points=0, workers=None):
    """One task: ``compute_points`` plus its wall time (module-level, so Dask can ship it by reference).

    ``run_points``: the points of the whole sweep (each is solved three times), from which the compiled
    kernels or NumPy are chosen, the same for every chunk. ``workers``: threads of the solve; Dask tasks
    pass 1 (Dask's workers already use the cores).
    """
    from ..util.jit import whole_run

    start = _time.perf_counter()
    with whole_run(n_bodies=3 * int(run_points)):
        out = compute_points(inertia, M0, T=T, delta=delta, method=method, workers=workers)
    out["seconds"] = _time.perf_counter() - start
    return out


# ---------------------------------------------------------------------------
# running a sweep
# ---------------------------------------------------------------------------
_RESULTS: dict[str, tuple[str, dict[str, Any]]] = {
    "half_period": (
        "f8",
        {"long_name": "flip half-period 2K(k)/lambda (time between flips); inf on the separatrix", "units": "s"},
    ),
    "k2": ("f8", {"long_name": "Jacobi parameter k^2 of the polhode", "units": "1"}),
    "sensitivity": (
        "f8",
        {
            "long_name": "attitude sensitivity: rotation angle between the attitudes at T of "
            "initial momenta differing by delta, divided by delta",
            "units": "1",
        },
    ),
    "status": (
        "i1",
        {
            "long_name": "0 regular, 1 separatrix, 2 symmetric body, 3 not a physical body",
            "units": "1",
            "flag_values": [0, 1, 2, 3],
            "flag_meanings": "regular separatrix symmetric_body not_physical",
        },
    ),
}


def _create_store(zarr, store: Path, cfg: SweepConfig) -> None:
    n, chunk = cfg.n_points, cfg.chunk
    nchunks = -(-n // chunk)
    ang_units = "degree" if cfg.degrees else "rad"
    from .. import __version__

    g = zarr.open_group(str(store), mode="w")
    g.attrs.update(
        {
            "title": f"eulerpoisson sweep: tennis-racket stability atlas ({cfg.kind})",
            "Conventions": "CF-1.10",
            "eulerpoisson_version": __version__,
            "sweep_format_version": _FORMAT_VERSION,
            "sweep_config": json.dumps(cfg.fingerprint(), sort_keys=True),
            "sweep_kind": cfg.kind,
            "sweep_grid": json.dumps({k: v.tolist() for k, v in cfg.grid_axes.items()}) if cfg.kind == "grid" else "{}",
            "sweep_axes": json.dumps(cfg.axis_names),
            "n_points": n,
            "chunk": chunk,
            "T": cfg.T,
            "delta": cfg.delta,
            "method": cfg.method,
            "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} started by eulerpoisson {__version__}",
        }
    )

    def arr(name, dims, shape, chunks, dtype, attrs, fill):
        a = g.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill, dimension_names=dims)
        a.attrs.update(attrs)
        return a

    c = min(chunk, n)
    params = {
        "I1": {"long_name": "principal moment of inertia I1", "units": "kg m2"},
        "I2": {"long_name": "principal moment of inertia I2", "units": "kg m2"},
        "I3": {"long_name": "principal moment of inertia I3", "units": "kg m2"},
        "polar": {"long_name": "polar angle of M0 from principal axis 3", "units": ang_units},
        "azimuth": {"long_name": "azimuth of M0 from axis 1 towards axis 2", "units": ang_units},
    }
    for name, attrs in params.items():
        arr(name, ["point"], (n,), (c,), "f8", attrs, np.nan)
    arr(
        "M0",
        ["point", "axis"],
        (n, 3),
        (c, 3),
        "f8",
        {"long_name": "initial body angular momentum (principal frame)", "units": "kg m2 s-1"},
        np.nan,
    )
    ax = arr("axis", ["axis"], (3,), (3,), "<U1", {}, "")
    ax[...] = np.array(["x", "y", "z"])
    for name, (dtype, attrs) in _RESULTS.items():
        arr(name, ["point"], (n,), (c,), dtype, attrs, np.nan if dtype == "f8" else -1)
    arr("chunk_count", ["chunk"], (nchunks,), (1,), "i4", {"long_name": "times this chunk was computed and written"}, 0)
    arr(
        "chunk_time",
        ["chunk"],
        (nchunks,),
        (1,),
        "f8",
        {"long_name": "time the chunk was written", "units": "seconds since 1970-01-01 00:00:00 UTC"},
        np.nan,
    )
    arr(
        "chunk_seconds",
        ["chunk"],
        (nchunks,),
        (1,),
        "f8",
        {"long_name": "compute time of the chunk", "units": "s"},
        np.nan,
    )

    # the parameters of every point, written once, in slabs of whole chunks (<= ~2.6e5 points)
    if cfg.kind == "random":
        vals = _random_points(cfg)
    slab = chunk * max(1, 262_144 // chunk)
    for a in range(0, n, slab):
        b = min(n, a + slab)
        v = _grid_points(cfg, a, b) if cfg.kind == "grid" else {key: x[a:b] for key, x in vals.items()}
        I = _moments_from_axes(cfg, v)
        for i, name in enumerate(("I1", "I2", "I3")):
            g[name][a:b] = I[:, i]
        g["polar"][a:b] = v["polar"]
        g["azimuth"][a:b] = v["azimuth"]
        g["M0"][a:b] = cfg.magnitude * _direction(v["polar"], v["azimuth"], cfg.degrees)


def _local_cluster(workers):
    distributed = require("distributed", "dask")
    n = workers or os.cpu_count() or 1
    # everything on the loopback interface: no scheduler or dashboard port open to the network
    return distributed.LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        silence_logs=logging.ERROR,
    )


def run_sweep(
    config: SweepConfig | str | os.PathLike[str] | dict[str, Any],
    *,
    path: str | os.PathLike[str] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: bool | Callable[[int, int], object] | None = None,
    overwrite: bool = False,
) -> Path:
    """Run (or resume) a sweep and write its Zarr store.

    Parameters
    ----------
    config : SweepConfig, str, Path or dict
        The sweep (a TOML file is read with :func:`load_config`).
    path : str or Path, optional
        Output store; default ``[output] path``.
    scheduler : str, optional
        ``"local"`` (an embedded :class:`distributed.LocalCluster`),
        ``"serial"`` (no Dask) or ``"tcp://HOST:PORT"`` (an existing
        cluster); default ``[compute] scheduler``.
    workers : int, optional
        Worker processes of the local cluster (each solves with one
        thread), or threads of the ``"serial"`` scheduler (``solve(...,
        workers=)``); default ``[compute] workers``, else the CPU count. The
        results do not depend on it.
    client : distributed.Client, optional
        Use this client (overrides ``scheduler``).
    progress : None, bool or callable
        ``None``: a progress bar on a terminal, quiet otherwise;
        ``True``/``False``; or ``progress(done_points, total_points)``.
    overwrite : bool
        Discard an existing result or a partial sweep made with a different
        configuration.

    Returns
    -------
    Path
        The finished store (also when it was already complete: nothing is
        recomputed then).

    Raises
    ------
    InvalidInputError
        Invalid configuration or scheduler.
    FileExistsError
        ``path`` holds a different sweep (or something else) and
        ``overwrite`` is False.
    EulerPoissonError
        A partial sweep with a different configuration is in the way.
    MissingDependencyError
        zarr (or dask/distributed for a cluster) is not installed (extra ``dask``).
    KeyboardInterrupt
        Propagated after the finished chunks are recorded; rerun to resume.

    Notes
    -----
    Finished chunks are written by the client (so remote workers need no
    shared file system) and then recorded by a marker; a rerun skips them.
    Workers of a remote cluster need eulerpoisson installed (the task is
    :func:`compute_points`, shipped by reference).

    The local cluster starts worker *processes* (spawned): a script that
    calls ``run_sweep(..., scheduler="local")`` must do so under
    ``if __name__ == "__main__":``, as for any :mod:`multiprocessing` code
    (the ``eulerpoisson`` command needs nothing).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, plot_atlas, run_sweep
    >>> if __name__ == "__main__":                                  # doctest: +SKIP
    ...     path = run_sweep("examples/sweep.toml", scheduler="local", workers=4)
    ...     plot_atlas(load_sweep(path), "atlas.png")

    >>> import numpy as np
    >>> from eulerpoisson.sweep import load_sweep, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0},
    ...        "momentum": {"polar": [30.0, 60.0], "azimuth": [0.0, 45.0]},
    ...        "output": {"path": "demo.zarr", "chunk": 2}, "compute": {"T": 10.0, "scheduler": "serial"}}
    >>> path = run_sweep(cfg, progress=False)
    >>> path.name
    'demo.zarr'
    >>> print(np.round(load_sweep(path)["half_period"].values, 6))
    [[132.062275  12.438453]
     [  6.469547   8.917193]]
    """
    zarr = require("zarr", "dask")
    cfg = config if isinstance(config, SweepConfig) else load_config(config)
    if scheduler is None and client is None and is_remote(cfg.scheduler):
        raise InvalidInputError(
            f"the sweep file names the scheduler {cfg.scheduler!r}; a file never connects to a cluster on its own: "
            f"give it explicitly (run_sweep(..., scheduler={cfg.scheduler!r}) or --scheduler {cfg.scheduler})"
        )
    scheduler = _check_scheduler(scheduler if scheduler is not None else cfg.scheduler, "scheduler")
    if workers is not None:
        workers = _integer(workers, "workers", 1)
    else:
        workers = cfg.workers
    path = Path(path if path is not None else cfg.path)
    fp = cfg.fingerprint()
    fp_text = json.dumps(fp, sort_keys=True)

    if overwrite:
        check_replaceable(path)  # before any work, not after
    if path.exists():
        if not overwrite:
            try:
                with quiet_zarr():
                    same = zarr.open_group(str(path), mode="r").attrs.get("sweep_config") == fp_text
            except Exception:  # not a zarr store
                same = False
            if same:
                return path
            raise FileExistsError(
                f"{path} exists and holds a different sweep (or no sweep); pass overwrite=True to replace it"
            )

    work = work_dir(path)
    store = work / "store.zarr"
    done: set[int] = set()
    if work.exists():
        try:
            with open(work / "state.json", encoding="utf-8") as fh:
                old = json.load(fh)
        except (OSError, ValueError):
            old = None  # interrupted while the store was being created: nothing was computed
        if old == fp:
            done = done_chunks(work)
        elif old is None or overwrite:
            shutil.rmtree(work)
        else:
            raise EulerPoissonError(
                f"{work} holds a partial sweep with a different configuration; pass overwrite=True to discard it"
            )
    if not work.exists():
        (work / "done").mkdir(parents=True)
        with quiet_zarr():
            _create_store(zarr, store, cfg)
            zarr.consolidate_metadata(str(store))  # the partial store reads like the final one
        write_json_atomic(work / "state.json", fp)  # last: marks the store as complete and resumable

    with quiet_zarr():
        g = zarr.open_group(str(store), mode="r+")
        arrs = {
            name: g[name] for name in ("I1", "I2", "I3", "M0", *_RESULTS, "chunk_count", "chunk_seconds", "chunk_time")
        }
    n, chunk = cfg.n_points, cfg.chunk
    nchunks = -(-n // chunk)
    todo = [k for k in range(nchunks) if k not in done]

    def bounds(k):
        return k * chunk, min(n, (k + 1) * chunk)

    def inputs(k):
        a, b = bounds(k)
        with quiet_zarr():
            I = np.stack([np.asarray(arrs[name][a:b]) for name in ("I1", "I2", "I3")], -1)
            M = np.asarray(arrs["M0"][a:b])
        return I, M

    def write(k, res):
        a, b = bounds(k)
        with quiet_zarr():
            for name in _RESULTS:
                arrs[name][a:b] = res[name]
            arrs["chunk_count"][k] = int(arrs["chunk_count"][k]) + 1
            arrs["chunk_seconds"][k] = float(res["seconds"])
            arrs["chunk_time"][k] = _time.time()
        mark_done(work, k, {"seconds": float(res["seconds"])})

    n_done = sum(bounds(k)[1] - bounds(k)[0] for k in done)
    args = (cfg.T, cfg.delta, cfg.method, n)
    try:
        with ProgressDisplay(progress, n, f"sweep {path.name}") as bar:
            bar.update(n_done)
            if todo and client is None and scheduler == "serial":
                for k in todo:
                    I, M = inputs(k)
                    write(k, _compute_chunk(I, M, *args, workers))
                    n_done += bounds(k)[1] - bounds(k)[0]
                    bar.update(n_done)
            elif todo:
                n_done = _run_distributed(client, scheduler, workers, todo, inputs, write, args, bounds, bar, n_done)
    except KeyboardInterrupt as exc:
        exc.add_note(f"eulerpoisson: the finished chunks of the sweep are kept in {store}; rerun the sweep to resume")
        raise

    with quiet_zarr():
        g.attrs["history"] = f"{g.attrs.get('history', '')}; finished {datetime.now(UTC).isoformat(timespec='seconds')}"
        zarr.consolidate_metadata(str(store))
    replace_dir(store, path, overwrite)
    shutil.rmtree(work, ignore_errors=True)
    return path


def _run_distributed(client, scheduler, workers, todo, inputs, write, args, bounds, bar, n_done):
    distributed = require("distributed", "dask")
    import contextlib

    with contextlib.ExitStack() as stack:
        if client is None:
            if scheduler == "local":
                cluster = stack.enter_context(_local_cluster(workers))
                client = stack.enter_context(distributed.Client(cluster, set_as_default=False))
            else:
                try:
                    client = stack.enter_context(distributed.Client(scheduler, set_as_default=False))
                except OSError as exc:
                    raise EulerPoissonError(f"cannot connect to the Dask scheduler {scheduler}: {exc}") from exc
        nthreads = max(1, sum(client.nthreads().values()))
        window = 4 * nthreads  # tasks in flight: bounded, so huge sweeps need no huge graphs
        pending = iter(todo)
        keys = {}

        def submit_next():
            k = next(pending, None)
            if k is None:
                return None
            I, M = inputs(k)
            fut = client.submit(_compute_chunk, I, M, *args, 1, pure=False)
            keys[fut.key] = k
            return fut

        first = [f for f in (submit_next() for _ in range(window)) if f is not None]
        ac = distributed.as_completed(first, loop=client.loop, with_results=True)
        try:
            for fut, res in ac:
                k = keys.pop(fut.key)
                write(k, res)
                n_done += bounds(k)[1] - bounds(k)[0]
                bar.update(n_done)
                fut = submit_next()
                if fut is not None:
                    ac.add(fut)
        except BaseException:
            for f in list(ac.futures):
                f.cancel()
            raise
    return n_done


# ---------------------------------------------------------------------------
# reading and plotting
# ---------------------------------------------------------------------------
def load_sweep(path: str | os.PathLike[str], *, squeeze: bool = True) -> xr.Dataset:
    """Read a sweep store as an :class:`xarray.Dataset`.

    A grid sweep is reshaped to its axes (``I1, I2, I3`` or ``I1, ratio21,
    ratio31``, ``polar``, ``azimuth``) with the axis values as coordinates;
    with ``squeeze`` the axes of length 1 become scalar coordinates. A
    random sweep keeps the ``point`` dimension. The bookkeeping variables
    (``chunk_*``) keep their ``chunk`` dimension.

    Parameters
    ----------
    path : str or Path
        A finished store, or a partial one (``.NAME.partial/store.zarr``;
        unfinished points are NaN).
    squeeze : bool

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    FileNotFoundError
        No store there (the message says when a partial sweep exists).
    EulerPoissonError
        Not a sweep store.
    MissingDependencyError
        xarray or zarr missing.

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": [1.5, 2.0], "I3": 3.0}, "momentum": {"polar": 40.0, "azimuth": 20.0},
    ...        "output": {"path": "inertia_line.zarr"}, "compute": {"T": 5.0, "scheduler": "serial"}}
    >>> ds = load_sweep(run_sweep(cfg, progress=False))
    >>> dict(ds.sizes), sorted(ds.data_vars)[:4]
    ({'chunk': 1, 'I2': 2, 'axis': 3}, ['M0', 'chunk_count', 'chunk_seconds', 'chunk_time'])
    """
    xr = require("xarray", "io")
    require("zarr", "dask")
    p = Path(path)
    if not p.exists():
        work = work_dir(p)
        hint = (
            f"; an unfinished sweep is in {work / 'store.zarr'} (rerun the sweep to finish it)" if work.exists() else ""
        )
        raise FileNotFoundError(f"no sweep store at {p}{hint}")
    try:
        with quiet_zarr():
            ds = xr.open_zarr(str(p), consolidated=None).load()
    except Exception as exc:
        raise EulerPoissonError(f"{p} is not a readable Zarr store: {exc}") from exc
    if "sweep_config" not in ds.attrs or "half_period" not in ds:
        raise EulerPoissonError(f"{p} is not an eulerpoisson sweep store")
    if ds.attrs.get("sweep_kind") != "grid":
        return ds
    grid = json.loads(ds.attrs["sweep_grid"])
    names = list(grid)
    shape = tuple(len(v) for v in grid.values())
    coords: dict[str, tuple] = {name: (name, np.asarray(v, float)) for name, v in grid.items()}
    for name in ("polar", "azimuth"):
        coords[name] = (name, coords[name][1], dict(ds[name].attrs))
    data = {}
    for name, var in ds.data_vars.items():
        if "point" in var.dims:
            if name in coords:  # a grid axis: its coordinate says it all
                continue
            tail = var.dims[1:]
            data[name] = (tuple(names) + tail, var.values.reshape(shape + var.shape[1:]), dict(var.attrs))
        else:
            data[name] = var
    out = xr.Dataset(data, coords={**coords, "axis": ds["axis"].values}, attrs=dict(ds.attrs))
    if squeeze:
        out = out.squeeze([d for d, s in zip(names, shape) if s == 1])
    return out


def _middle_gap(I: np.ndarray, M: np.ndarray) -> np.ndarray:
    r""":math:`2EI_\mathrm{mid} - L^2` (zero on the separatrix), elementwise over (..., 3)."""
    mid = np.median(I, axis=-1)[..., None]
    return np.sum(M**2 * (mid / I - 1.0), -1)


def plot_atlas(
    ds: xr.Dataset,
    out: str | os.PathLike[str],
    *,
    variables: Sequence[str] = ("half_period", "sensitivity"),
    dpi: int = 150,
) -> Path:
    """Heat maps of a sweep: the flip half-period (and sensitivity) with the separatrix drawn.

    A grid sweep with two axes of length > 1 is drawn as a heat map over
    them — over the momentum sphere in (azimuth, polar), or over an
    inertia plane (e.g. ``I2``, ``I3``) — with a logarithmic colour scale;
    the separatrix :math:`2EI_2 = L^2` is drawn as a black line (infinite
    half-periods on it are grey) and non-physical or symmetric points are
    left blank. A random sweep with one body is drawn as a scatter plot in
    (azimuth, polar).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`load_sweep`.
    out : str or Path
        Figure file (.png, .pdf, .svg).
    variables : sequence of str
        Panels to draw (data variables of ``ds``).
    dpi : int

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    InvalidInputError
        Not a sweep dataset, an unknown variable, or a grid with other than
        two non-trivial axes (select a plane first, e.g. ``ds.isel(I2=0)``).
    MissingDependencyError
        matplotlib missing (extra ``plot``).

    Examples
    --------
    >>> from eulerpoisson.sweep import load_sweep, plot_atlas, run_sweep
    >>> cfg = {"inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0},
    ...        "momentum": {"polar": [30.0, 60.0, 90.0], "azimuth": [0.0, 45.0]},
    ...        "output": {"path": "sphere.zarr"}, "compute": {"T": 5.0, "scheduler": "serial"}}
    >>> plot_atlas(load_sweep(run_sweep(cfg, progress=False)), "atlas.png", dpi=40).name
    'atlas.png'
    """
    if not hasattr(ds, "data_vars") or "half_period" not in ds:
        raise InvalidInputError("plot_atlas needs a sweep dataset from load_sweep(path)")
    variables = [variables] if isinstance(variables, str) else list(variables)
    for v in variables:
        if v not in ds.data_vars:
            raise InvalidInputError(
                f"variables: {v!r} is not in the sweep; choose from {', '.join(map(str, ds.data_vars))}"
            )
    mpl = require("matplotlib", "plot")
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure

    ds = ds.squeeze()
    deg = ds["polar"].attrs.get("units", "degree") == "degree"
    alabel = "deg" if deg else "rad"
    names = {"half_period": "flip half-period", "sensitivity": "attitude sensitivity", "k2": "k^2"}
    fig = Figure(figsize=(5.5 * len(variables), 4.2))
    axes = fig.subplots(1, len(variables), squeeze=False)
    ref = ds["half_period"]
    I = np.stack([ds[k].broadcast_like(ref).transpose(*ref.dims).values for k in ("I1", "I2", "I3")], -1)
    M = ds["M0"].broadcast_like(ref).transpose(*ref.dims, "axis").values
    gap = np.where(ds["status"].broadcast_like(ref).transpose(*ref.dims).values == 3, np.nan, _middle_gap(I, M))
    if "point" in ds.dims:
        if not (np.ptp(I, axis=0) == 0).all():
            raise InvalidInputError("plot_atlas draws a random sweep only for one body (constant inertia)")
        x, y = ds["azimuth"].values, ds["polar"].values
        for ax, v in zip(axes[0], variables):
            z = ds[v].values.astype(float)
            good = np.isfinite(z) & (z > 0)
            sc = ax.scatter(x[good], y[good], c=z[good], s=6, norm=LogNorm(), cmap="viridis")
            ax.scatter(x[~good], y[~good], c="0.5", s=6)
            fig.colorbar(sc, ax=ax, label=names.get(v, v))
            ax.set_xlabel(f"azimuth of M0 ({alabel})")
            ax.set_ylabel(f"polar angle of M0 ({alabel})")
            ax.invert_yaxis()
            ax.set_title(names.get(v, v))
    else:
        dims = [str(d) for d in ds["half_period"].dims]
        if len(dims) != 2:
            raise InvalidInputError(
                f"plot_atlas draws a grid with exactly two axes of length > 1, this one has {dims}; "
                "select a plane first, e.g. ds.isel(I2=0)"
            )
        if set(dims) == {"polar", "azimuth"}:
            xd, yd = "azimuth", "polar"
        else:
            yd, xd = dims
        for ax, v in zip(axes[0], variables):
            z = ds[v].transpose(yd, xd).values.astype(float)
            zm = np.ma.masked_invalid(np.where(z > 0, z, np.nan))
            cmap = mpl.colormaps["viridis"].with_extremes(bad="white")
            xv, yv = ds[xd].values, ds[yd].values
            pc = ax.pcolormesh(xv, yv, zm, norm=LogNorm(), cmap=cmap, shading="nearest")
            inf = np.isinf(z)
            if inf.any():
                ax.pcolormesh(
                    xv, yv, np.ma.masked_where(~inf, np.ones_like(z)), cmap="Greys", vmin=0, vmax=2, shading="nearest"
                )
            gz = _as_plane(ds, gap, yd, xd)
            crosses = bool(np.nanmin(gz) < 0 < np.nanmax(gz)) if np.isfinite(gz).any() else False
            if crosses:
                ax.contour(xv, yv, np.ma.masked_invalid(gz), levels=[0.0], colors="k", linewidths=1.0)
            fig.colorbar(pc, ax=ax, label=names.get(v, v))
            ax.set_xlabel(f"{xd} ({alabel})" if xd in ("polar", "azimuth") else xd)
            ax.set_ylabel(f"{yd} ({alabel})" if yd in ("polar", "azimuth") else yd)
            if yd == "polar":
                ax.invert_yaxis()
            ax.set_title(names.get(v, v) + ("  (black: separatrix)" if crosses else ""))
    fig.suptitle(f"tennis-racket atlas, T = {ds.attrs.get('T', float('nan')):g}")
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    from ..io.atomic import atomic_path

    with atomic_path(out, suffix=out.suffix) as tmp:
        fig.savefig(tmp, dpi=dpi, format=out.suffix.lstrip(".") or "png")
    return out


def _as_plane(ds, values: np.ndarray, yd: str, xd: str) -> np.ndarray:
    """Values laid out like ``ds['half_period']`` (dims order) as a (yd, xd) array."""
    dims = list(ds["half_period"].dims)
    arr = np.asarray(values).reshape(ds["half_period"].shape)
    return np.transpose(arr, (dims.index(yd), dims.index(xd)))
