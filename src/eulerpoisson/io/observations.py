r"""Observation files for spin-state estimation (:func:`eulerpoisson.fit`).

:func:`read_observations` reads measured attitudes, angular velocities and
directions of a body axis at a set of times, checks them, and returns an
:class:`Observations`; ``Observations.fit_kwargs()`` gives the keyword
arguments of ``ep.fit``. Three formats, chosen by the file's extension:

``.csv``
    A table of numbers, one row per time (columns below).
``.nc``
    A NetCDF file (version 4 or 3) with a dimension ``t`` (variables below).
``.toml``
    A table ``[observations]`` naming a ``.csv`` or ``.nc`` file and settings
    (below).

Conventions: quaternions are scalar first ``(w, x, y, z)`` with
``x_space = R x_body``; :math:`\boldsymbol\Omega` is the body angular
velocity and :math:`\boldsymbol\omega = R\boldsymbol\Omega` the space one;
angles are in radians except where a name ends in ``_deg``; rates are in
radians per unit of ``t`` (degrees with ``omega_unit="deg"``, their sigmas
too). Files written in other conventions are read with ``quaternion_order``,
``attitude_convention`` and ``omega_unit`` (``fit`` names the one to use when
another reading of the numbers fits far better).

CSV columns
-----------
A header row of column names is required; lines whose first non-blank
character is ``#`` (comments) and blank lines are skipped anywhere. Cells are
numbers; an empty cell or ``nan`` is a missing value. The columns (names are
case sensitive; the case of ``SEQ`` says intrinsic or extrinsic):

=============================================  ===============================================================
column(s)                                      meaning
=============================================  ===============================================================
``t``                                          time (required), finite and strictly increasing
``qw, qx, qy, qz``                             attitude as a unit quaternion, scalar first (norm 1 to 1e-6,
                                               renormalized)
``euler_SEQ_1, euler_SEQ_2, euler_SEQ_3``      attitude as Euler angles in degrees, ``SEQ`` an axis sequence
                                               as in scipy: upper case intrinsic (``euler_ZXZ_1``), lower
                                               case extrinsic (``euler_zxz_1``); not together with ``qw..qz``
``wx, wy, wz``                                 angular velocity, body frame (:math:`\boldsymbol\Omega`) unless
                                               ``omega_frame="space"`` (:math:`\boldsymbol\omega`)
``ax, ay, az``                                 direction in space of the body axis ``axis`` (a unit vector,
                                               norm 1 to 1e-6, renormalized); needs ``axis=``
``sigma_attitude_deg``                         standard deviation of the attitude, degrees, per row
``sigma_omega``                                standard deviation of each component of the angular velocity,
                                               per row
``sigma_wx, sigma_wy, sigma_wz``               the same per component (not together with ``sigma_omega``)
``sigma_axis_deg``                             standard deviation of the axis direction, degrees, per row
=============================================  ===============================================================

At least one of the groups ``qw..qz`` / ``euler_SEQ_*``, ``wx..wz``,
``ax..az`` must be present, and each group is all of its columns or none. In a
row a quaternion, a set of Euler angles, an angular velocity or an axis
direction is given whole or missing whole. A sigma must be positive and finite
where its observation is given (it is ignored, and stored as NaN, where the
observation is missing). Other columns (a second clock, notes) are ignored
and not read (:attr:`Observations.ignored` names them), except a name that
looks like a misspelt one of these: another case (``Qw``), or an unknown name
beginning with ``sigma`` or ``euler``, is an error.

Example::

    # tumbling probe, star tracker + gyro
    t,qw,qx,qy,qz,wx,wy,wz,sigma_attitude_deg
    0.0,1,0,0,0,0.10,0.02,0.50,0.05
    0.5,0.9689,0.0125,0.0081,0.2470,0.10,0.03,0.49,0.05
    1.0,,,,,0.09,0.04,0.49,

NetCDF variables
----------------
The dimension ``t`` with its coordinate variable ``t`` (the times), and

==========================================  =================================================================
variable                                    meaning
==========================================  =================================================================
``q`` or ``attitude`` (t, 4)                unit quaternions, scalar first; NaN rows missing
``omega`` (t, 3)                            angular velocity; attribute ``frame`` = ``"body"`` or ``"space"``
``axis_direction`` (t, 3)                   space direction of a body axis; attribute ``axis`` (3 numbers)
``attitude_sigma`` or ``q_sigma``           () or (t,); radians, or degrees with attribute ``units = "deg"``
``omega_sigma``                             (), (t,) or (t, 3)
``axis_sigma`` or ``axis_direction_sigma``  () or (t,); radians, or degrees with attribute ``units = "deg"``
==========================================  =================================================================

and the optional global attribute ``principal_axes`` (``"given"`` or ``"fit"``).
Other variables are ignored, except a name that looks like a misspelt one of
these (another case, or an unknown name with ``sigma`` in it): an error.

TOML settings
-------------
::

    [observations]
    file = "obs.csv"            # required; relative to the TOML file's folder
    sigma_attitude_deg = 0.05   # optional, as the keyword arguments of read_observations
    sigma_omega = 0.01
    sigma_axis_deg = 0.5
    omega_frame = "body"        # "body" or "space"
    axis = [0, 0, 1]            # the body axis of ax, ay, az
    principal_axes = "given"    # "given" or "fit"
    quaternion_order = "wxyz"   # the quaternion columns in file order: "wxyz" or "xyzw" (scalar last)
    attitude_convention = "body-to-space"  # or "space-to-body" (the conjugate quaternions)
    omega_unit = "rad"          # "rad" or "deg": wx, wy, wz and their sigmas per unit of t

Other top-level tables are left to their readers; an unknown key in
``[observations]`` is an error.

Precedence: a keyword argument of :func:`read_observations` (a command-line
flag) overrides the TOML setting of the same name, and a scalar sigma given
either way replaces the file's sigma column or variable. A frame, an axis or a
``principal_axes`` stated by a NetCDF file must agree with the settings: a
contradiction is an error, never a silent choice. When nothing states the
frame of ``omega`` it is ``"body"``.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import numbers
import os
import re
from dataclasses import dataclass
from dataclasses import field as dataclass_field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..attitude.core import UNIT_QUATERNION_TOLERANCE
from ..errors import InvalidInputError, require

__all__ = [
    "Observations",
    "read_observations",
    "CSV_COLUMNS",
    "UNIT_TOLERANCE",
    "QUATERNION_ORDERS",
    "ATTITUDE_CONVENTIONS",
    "OMEGA_UNITS",
]

#: largest relative deviation of the norm of a quaternion or a direction from 1 that is accepted (and removed)
UNIT_TOLERANCE = UNIT_QUATERNION_TOLERANCE  # 1e-6, as for every unit quaternion the package accepts

_Q_COLS = ("qw", "qx", "qy", "qz")
_W_COLS = ("wx", "wy", "wz")
_A_COLS = ("ax", "ay", "az")
_SW_COLS = ("sigma_wx", "sigma_wy", "sigma_wz")
_EULER_RE = re.compile(r"^euler_([A-Za-z]{3})_([123])$")

#: every CSV column name, in the order of the module notes (``SEQ``: a 3-letter axis sequence)
CSV_COLUMNS = (
    ("t",)
    + _Q_COLS
    + ("euler_SEQ_1", "euler_SEQ_2", "euler_SEQ_3")
    + _W_COLS
    + _A_COLS
    + ("sigma_attitude_deg", "sigma_omega")
    + _SW_COLS
    + ("sigma_axis_deg",)
)
_FIXED_COLS = frozenset(c for c in CSV_COLUMNS if "SEQ" not in c)

_FRAMES = ("body", "space")
_PRINCIPAL = ("given", "fit")
_TOML_KEYS = (
    "file",
    "sigma_attitude_deg",
    "sigma_omega",
    "sigma_axis_deg",
    "omega_frame",
    "axis",
    "principal_axes",
    "quaternion_order",
    "attitude_convention",
    "omega_unit",
)
#: the readings of the numbers (what ``fit`` suggests when another one fits far better)
QUATERNION_ORDERS = ("wxyz", "xyzw")
ATTITUDE_CONVENTIONS = ("body-to-space", "space-to-body")
OMEGA_UNITS = ("rad", "deg")

_NC_ATTITUDE = ("q", "attitude")
_NC_ATTITUDE_SIGMA = ("attitude_sigma", "q_sigma")
_NC_AXIS_SIGMA = ("axis_sigma", "axis_direction_sigma")
_NC_VARIABLES = _NC_ATTITUDE + ("omega", "axis_direction") + _NC_ATTITUDE_SIGMA + ("omega_sigma",) + _NC_AXIS_SIGMA
_DEG_UNITS = ("deg", "degree", "degrees")
_RAD_UNITS = ("rad", "radian", "radians")


# ---------------------------------------------------------------------------
# the result
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False, repr=False)
class Observations:
    """Observations of a rotating rigid body at the times ``t``.

    Made by :func:`read_observations`; the arrays are read-only. Missing
    values are NaN: a whole row of ``attitude``, ``omega`` or
    ``axis_direction``. A sigma array holds NaN where its
    observation is missing.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Times, float64, finite and strictly increasing.
    attitude : ndarray, shape (N, 4), or None
        Unit quaternions ``(w, x, y, z)`` with ``x_space = R x_body``.
    attitude_sigma : ndarray, shape (N,), float or None
        Standard deviation of the attitude, radians.
    omega : ndarray, shape (N, 3), or None
        Angular velocity, radians per unit of ``t``, in ``omega_frame``.
    omega_sigma : ndarray, shape (N,) or (N, 3), float or None
        Standard deviation of each component of ``omega``.
    omega_frame : str
        ``"body"`` (:math:`\\boldsymbol\\Omega`) or ``"space"``
        (:math:`\\boldsymbol\\omega = R\\boldsymbol\\Omega`).
    axis : ndarray, shape (3,), or None
        Unit vector of the body axis whose space direction is observed.
    axis_direction : ndarray, shape (N, 3), or None
        Unit vectors in space: ``R @ axis`` as measured.
    axis_sigma : ndarray, shape (N,), float or None
        Standard deviation of the axis direction, radians.
    principal_axes : str or None
        ``"given"`` (the body frame of the data is the principal-axis frame),
        ``"fit"`` (estimate its orientation) or None (not said).
    source : str
        The path that was read.
    ignored : tuple of str
        Columns (CSV) or variables (NetCDF) of the file that are not
        observations and were not read, e.g. a second clock.
    files : tuple of str
        Every file read: ``source`` and, for a TOML file, the data file it
        names (inputs, never to be overwritten by an output).
    """

    t: np.ndarray
    attitude: np.ndarray | None = None
    attitude_sigma: np.ndarray | float | None = None
    omega: np.ndarray | None = None
    omega_sigma: np.ndarray | float | None = None
    omega_frame: str = "body"
    axis: np.ndarray | None = None
    axis_direction: np.ndarray | None = None
    axis_sigma: np.ndarray | float | None = None
    principal_axes: str | None = None
    source: str = ""
    ignored: tuple[str, ...] = ()
    files: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def __repr__(self) -> str:
        parts = [f"source={self.source!r}", f"N={len(self)}"]
        for name in ("attitude", "omega", "axis_direction"):
            v = getattr(self, name)
            if v is not None:
                given = int(np.count_nonzero(np.any(np.isfinite(v), axis=1)))
                parts.append(f"{name}: {given} given")
        if self.omega is not None:
            parts.append(f"omega_frame={self.omega_frame!r}")
        if self.axis is not None:
            parts.append(f"axis={self.axis.tolist()}")
        if self.principal_axes is not None:
            parts.append(f"principal_axes={self.principal_axes!r}")
        return "Observations(" + ", ".join(parts) + ")"

    def fit_kwargs(self) -> dict:
        """Keyword arguments for ``ep.fit``: ``ep.fit(**obs.fit_kwargs(), ...)``.

        Returns
        -------
        dict
            ``t``, ``attitude``, ``attitude_sigma``, ``omega``,
            ``omega_sigma``, ``omega_frame``, ``axis``, ``axis_direction``,
            ``axis_sigma`` in this order, leaving out those that are None, and
            ``principal_axes`` when it is not None. Arrays are writable copies.
        """
        out = {}
        for name in (
            "t",
            "attitude",
            "attitude_sigma",
            "omega",
            "omega_sigma",
            "omega_frame",
            "axis",
            "axis_direction",
            "axis_sigma",
            "principal_axes",
        ):
            v = getattr(self, name)
            if v is None:
                continue
            out[name] = v.copy() if isinstance(v, np.ndarray) else v
        return out


# ---------------------------------------------------------------------------
# settings (keyword arguments and the TOML table)
# ---------------------------------------------------------------------------
def _positive(value, name: str) -> float:
    """A positive finite real number (not a bool, not a string)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidInputError(f"{name} must be a positive number, got {type(value).__name__} {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise InvalidInputError(f"{name} must be positive and finite, got {value!r}")
    return v


def _frame(value, name: str) -> str:
    if isinstance(value, np.str_):
        value = str(value)
    if not isinstance(value, str) or value not in _FRAMES:
        raise InvalidInputError(f"{name} must be 'body' or 'space', got {value!r}")
    return value


def _choice(value, name: str, allowed: tuple) -> str:
    if isinstance(value, np.str_):
        value = str(value)
    if not isinstance(value, str) or value not in allowed:
        raise InvalidInputError(f"{name} must be one of {', '.join(repr(a) for a in allowed)}, got {value!r}")
    return value


def _principal(value, name: str) -> str:
    if isinstance(value, np.str_):
        value = str(value)
    if not isinstance(value, str) or value not in _PRINCIPAL:
        raise InvalidInputError(f"{name} must be 'given' or 'fit', got {value!r}")
    return value


def _unit_axis(value, name: str) -> np.ndarray:
    """A body axis: three finite numbers, not all zero; returned normalized."""
    if isinstance(value, (str, bytes)):
        raise InvalidInputError(f"{name} must be three numbers (a body axis), got the string {value!r}")
    try:
        a = np.asarray(value)
    except Exception:  # ragged nested lists
        raise InvalidInputError(f"{name} must be three numbers (a body axis), got {value!r}") from None
    if a.dtype == bool or not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise InvalidInputError(f"{name} must be three numbers (a body axis), got {value!r}")
    a = a.astype(np.float64)
    if a.shape != (3,):
        raise InvalidInputError(f"{name} must be three numbers (a body axis), got shape {a.shape}: {value!r}")
    if not np.all(np.isfinite(a)):
        raise InvalidInputError(f"{name} must be finite, got {a.tolist()}")
    n = float(np.linalg.norm(a))
    if not n > 0 or not math.isfinite(n):
        raise InvalidInputError(f"{name} must be a nonzero vector, got {a.tolist()}")
    return a / n


@dataclass
class _Settings:
    sigma_attitude_deg: float | None = None
    sigma_omega: float | None = None
    sigma_axis_deg: float | None = None
    omega_frame: str | None = None
    axis: np.ndarray | None = None
    principal_axes: str | None = None
    quaternion_order: str | None = None
    attitude_convention: str | None = None
    omega_unit: str | None = None
    # where each came from, for messages ("omega_frame=" or "obs.toml: [observations] omega_frame")
    origin: dict = dataclass_field(default_factory=dict)


def _read_toml(p: Path, shown: str) -> tuple[Path, _Settings]:
    import tomllib

    try:
        with open(p, "rb") as fh:
            cfg = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise InvalidInputError(f"{shown}: invalid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise InvalidInputError(
            f"{shown}: not UTF-8 text ({exc.reason} at byte {exc.start}); a TOML file must be UTF-8: save it as UTF-8"
        ) from None
    except RecursionError:
        raise InvalidInputError(f"{shown}: invalid TOML: nested too deeply") from None
    except OSError as exc:
        raise InvalidInputError(f"{shown}: cannot read the file: {exc.strerror or exc}") from None
    if "observations" not in cfg:
        raise InvalidInputError(
            f"{shown}: no [observations] table; an observations TOML file has [observations] with the keys "
            f"{', '.join(_TOML_KEYS)} (file required)"
        )
    obs = cfg["observations"]
    if not isinstance(obs, dict):
        raise InvalidInputError(f"{shown}: 'observations' must be a table [observations], got {obs!r}")
    unknown = [k for k in obs if k not in _TOML_KEYS]
    if unknown:
        raise InvalidInputError(
            f"{shown}: unknown key {unknown[0]!r} in [observations]; allowed keys: {', '.join(_TOML_KEYS)}"
        )
    if "file" not in obs:
        raise InvalidInputError(f"{shown}: [observations] file is required (the .csv or .nc file of the data)")
    name = obs["file"]
    if not isinstance(name, str) or not name.strip():
        raise InvalidInputError(f"{shown}: [observations] file must be a file name (a non-empty string), got {name!r}")
    data = Path(name)
    if not data.is_absolute():
        data = p.parent / data
    if data.suffix.lower() not in (".csv", ".nc"):
        raise InvalidInputError(
            f"{shown}: [observations] file = {name!r} must be a .csv or .nc file, got extension {data.suffix!r}"
        )
    s = _Settings(origin={})
    where = f"{shown}: [observations] "
    for key in ("sigma_attitude_deg", "sigma_omega", "sigma_axis_deg"):
        if key in obs:
            setattr(s, key, _positive(obs[key], where + key))
            s.origin[key] = where + key
    if "omega_frame" in obs:
        s.omega_frame = _frame(obs["omega_frame"], where + "omega_frame")
        s.origin["omega_frame"] = where + "omega_frame"
    if "axis" in obs:
        s.axis = _unit_axis(obs["axis"], where + "axis")
        s.origin["axis"] = where + "axis"
    if "principal_axes" in obs:
        s.principal_axes = _principal(obs["principal_axes"], where + "principal_axes")
        s.origin["principal_axes"] = where + "principal_axes"
    for key, allowed in (
        ("quaternion_order", QUATERNION_ORDERS),
        ("attitude_convention", ATTITUDE_CONVENTIONS),
        ("omega_unit", OMEGA_UNITS),
    ):
        if key in obs:
            setattr(s, key, _choice(obs[key], where + key, allowed))
            s.origin[key] = where + key
    return data, s


# ---------------------------------------------------------------------------
# raw data from a file: values as read (NaN missing) with names for messages
# ---------------------------------------------------------------------------
@dataclass
class _Block:
    """An (N, k) block of a file (or a scalar for a NetCDF sigma) with the names of its parts."""

    values: np.ndarray | float
    labels: tuple  # per component: "column 'qx'" or "variable 'q' component 1"
    what: str  # the group: "columns qw, qx, qy, qz" or "variable 'q'"
    scale: float = 1.0  # to radians (sigmas in degrees)
    unit: str = ""  # shown after values in messages


@dataclass
class _Raw:
    file: str
    places: list  # per row: "line 7" / "t index 6"
    t: np.ndarray
    t_label: str
    attitude: _Block | None = None
    euler_seq: str | None = None
    euler: _Block | None = None
    omega: _Block | None = None
    axis_direction: _Block | None = None
    attitude_sigma: _Block | None = None
    omega_sigma: _Block | None = None
    axis_sigma: _Block | None = None
    omega_frame: str | None = None  # stated by the file
    q_file_order: tuple = (0, 1, 2, 3)  # the columns of ``attitude`` in the order of the file
    axis: np.ndarray | None = None
    principal_axes: str | None = None
    ignored: tuple = ()


def _number(cell: str) -> float:
    if cell == "":
        return math.nan
    if "_" in cell:  # float("1_0") is 10.0 in Python; not a number in a data file
        raise ValueError(cell)
    return float(cell)


def _read_csv(p: Path, shown: str) -> _Raw:
    try:
        with open(p, encoding="utf-8-sig") as fh:  # universal newlines: the text has "\n" only
            text = fh.read()
    except UnicodeDecodeError as exc:
        raise InvalidInputError(
            f"{shown}: not UTF-8 text ({exc.reason} at byte {exc.start}); a CSV observations file must be UTF-8: "
            f"save it as UTF-8 (e.g. iconv -f latin1 -t utf-8 {shown} > {Path(shown).stem}-utf8.csv)"
        ) from None
    except OSError as exc:
        raise InvalidInputError(f"{shown}: cannot read the file: {exc.strerror or exc}") from None

    header = None
    header_line = 0
    rows: list[list[str]] = []
    lines: list[int] = []
    for lineno, line in enumerate(text.split("\n"), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        try:
            fields = [f.strip() for f in next(csv.reader([line], strict=True))]
        except csv.Error as exc:
            raise InvalidInputError(f"{shown}, line {lineno}: not a CSV row: {exc}") from None
        if header is None:
            header, header_line = fields, lineno
            continue
        if len(fields) != len(header):
            raise InvalidInputError(
                f"{shown}, line {lineno}: {len(fields)} cells, but the header (line {header_line}) has "
                f"{len(header)} columns"
            )
        rows.append(fields)
        lines.append(lineno)
    if header is None:
        raise InvalidInputError(
            f"{shown}: no header row (the file is empty or only comments); columns: {', '.join(CSV_COLUMNS)}"
        )

    # --- the header
    index: dict[str, int] = {}
    euler: dict[str, dict[int, str]] = {}
    ignored: list[str] = []
    for j, name in enumerate(header):
        if name == "":
            raise InvalidInputError(f"{shown}, line {header_line}: column {j + 1} of the header has no name")
        if name in index:
            raise InvalidInputError(f"{shown}, line {header_line}: column {name!r} appears twice in the header")
        index[name] = j
        m = _EULER_RE.match(name)
        if m:
            euler.setdefault(m.group(1), {})[int(m.group(2))] = name
        elif name not in _FIXED_COLS:
            low = name.lower()
            if low in _FIXED_COLS:
                hint = f"did you mean {low!r}? names are case sensitive"
            elif low.startswith("euler"):
                hint = "Euler angle columns are euler_SEQ_1, euler_SEQ_2, euler_SEQ_3, e.g. euler_ZXZ_1"
            elif low.startswith("sigma"):
                hint = "sigma columns are sigma_attitude_deg, sigma_omega, sigma_wx, sigma_wy, sigma_wz, sigma_axis_deg"
            else:
                ignored.append(name)  # another column (a second clock, notes): not ours, not read
                continue
            raise InvalidInputError(
                f"{shown}, line {header_line}: unknown column {name!r} ({hint}); "
                f"known columns: {', '.join(CSV_COLUMNS)}"
            )
    if "t" not in index:
        raise InvalidInputError(
            f"{shown}: no column 't' (the times) in the header (line {header_line}); columns: {', '.join(header)}"
        )

    def group(cols, desc):
        have = [c for c in cols if c in index]
        if have and len(have) != len(cols):
            missing = [c for c in cols if c not in index]
            raise InvalidInputError(
                f"{shown}: column{'s' if len(have) > 1 else ''} {', '.join(have)} without {', '.join(missing)}: "
                f"{desc} needs all of {', '.join(cols)}"
            )
        return bool(have)

    has_q = group(_Q_COLS, "the attitude quaternion")
    has_w = group(_W_COLS, "the angular velocity")
    has_a = group(_A_COLS, "the axis direction")
    has_sw = group(_SW_COLS, "the per-component sigma of the angular velocity")
    seq = None
    if len(euler) > 1:
        raise InvalidInputError(
            f"{shown}: Euler angles in more than one sequence ({', '.join(sorted(euler))}); give one attitude"
        )
    if euler:
        ((seq, parts),) = euler.items()
        cols = tuple(f"euler_{seq}_{k}" for k in (1, 2, 3))
        group(cols, f"the Euler angles in sequence {seq!r}")
        from ..attitude.core import parse_seq

        try:
            parse_seq(seq)
        except InvalidInputError as exc:
            raise InvalidInputError(f"{shown}: column {cols[0]!r}: invalid Euler sequence: {exc}") from None
    if has_q and seq is not None:
        raise InvalidInputError(
            f"{shown}: both quaternion columns (qw, qx, qy, qz) and Euler angle columns (euler_{seq}_*): "
            "give the attitude once"
        )
    if not (has_q or seq or has_w or has_a):
        raise InvalidInputError(
            f"{shown}: no observation columns (only {', '.join(header)}); give at least one of qw, qx, qy, qz "
            "(or euler_SEQ_1, euler_SEQ_2, euler_SEQ_3), wx, wy, wz, or ax, ay, az"
        )
    if "sigma_omega" in index and has_sw:
        raise InvalidInputError(f"{shown}: both sigma_omega and sigma_wx, sigma_wy, sigma_wz; give one of them")
    for cols, needs, has in (
        (("sigma_attitude_deg",), "an attitude (qw..qz or euler_SEQ_*)", has_q or seq),
        (("sigma_omega",), "wx, wy, wz", has_w),
        (_SW_COLS, "wx, wy, wz", has_w),
        (("sigma_axis_deg",), "ax, ay, az", has_a),
    ):
        if cols[0] in index and not has:
            raise InvalidInputError(f"{shown}: column {cols[0]} without {needs}: a sigma needs its observation")
    if not rows:
        raise InvalidInputError(f"{shown}: no data rows after the header (line {header_line})")

    # --- the numbers
    n = len(rows)

    def column(name) -> np.ndarray:
        j = index[name]
        out = np.empty(n)
        for i, row in enumerate(rows):
            try:
                out[i] = _number(row[j])
            except ValueError:
                raise InvalidInputError(
                    f"{shown}, line {lines[i]}, column {name!r}: {row[j]!r} is not a number "
                    "(leave the cell empty or write nan for a missing value)"
                ) from None
        return out

    def block(cols, what, scale=1.0, unit=""):
        return _Block(
            np.stack([column(c) for c in cols], axis=1), tuple(f"column {c!r}" for c in cols), what, scale, unit
        )

    raw = _Raw(
        file=shown, places=[f"line {k}" for k in lines], t=column("t"), t_label="column 't'", ignored=tuple(ignored)
    )
    if has_q:
        raw.attitude = block(_Q_COLS, "columns qw, qx, qy, qz")
        raw.q_file_order = tuple(sorted(range(4), key=lambda k: index[_Q_COLS[k]]))
    if seq is not None:
        cols = tuple(f"euler_{seq}_{k}" for k in (1, 2, 3))
        raw.euler_seq = seq
        raw.euler = block(cols, "columns " + ", ".join(cols), unit=" deg")
    if has_w:
        raw.omega = block(_W_COLS, "columns wx, wy, wz")
    if has_a:
        raw.axis_direction = block(_A_COLS, "columns ax, ay, az")
    deg = math.pi / 180.0
    if "sigma_attitude_deg" in index:
        raw.attitude_sigma = block(("sigma_attitude_deg",), "column 'sigma_attitude_deg'", deg, " deg")
    if "sigma_omega" in index:
        raw.omega_sigma = block(("sigma_omega",), "column 'sigma_omega'")
    if has_sw:
        raw.omega_sigma = block(_SW_COLS, "columns sigma_wx, sigma_wy, sigma_wz")
    if "sigma_axis_deg" in index:
        raw.axis_sigma = block(("sigma_axis_deg",), "column 'sigma_axis_deg'", deg, " deg")
    return raw


def _read_netcdf(p: Path, shown: str) -> _Raw:
    xr = require("xarray", "io")
    from .formats import netcdf_engine

    try:
        ds = xr.load_dataset(p, engine=netcdf_engine(p), decode_times=False, decode_timedelta=False)
    except Exception as exc:
        raise InvalidInputError(f"{shown}: not a readable NetCDF file: {exc}") from None
    if "t" not in ds.dims:
        raise InvalidInputError(
            f"{shown}: no dimension 't' (the times of the observations); dimensions: "
            f"{', '.join(map(str, ds.dims)) or 'none'}"
        )
    if "t" not in ds.coords:
        raise InvalidInputError(f"{shown}: the dimension 't' has no coordinate variable 't' holding the times")
    ignored = []
    for v in map(str, ds.data_vars):
        if v in _NC_VARIABLES:
            continue
        low = v.lower()
        if low in _NC_VARIABLES or "sigma" in low:
            raise InvalidInputError(
                f"{shown}: unknown variable {v!r} (a misspelt name?); known variables: t (coordinate), "
                f"{', '.join(_NC_VARIABLES)}"
            )
        ignored.append(v)

    def numeric(name, var) -> np.ndarray:
        a = np.asarray(var.values)
        if a.dtype == bool or not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
            raise InvalidInputError(f"{shown}: variable {name!r} must be numeric, got dtype {a.dtype}")
        return a.astype(np.float64)

    t_var = ds["t"]
    if t_var.dims != ("t",):
        raise InvalidInputError(f"{shown}: coordinate 't' must have the dimension (t,), got {t_var.dims}")
    t = numeric("t", t_var)
    n = t.shape[0]
    if n == 0:
        raise InvalidInputError(f"{shown}: the dimension 't' is empty (no observations)")

    def one_of(names):
        have = [v for v in names if v in ds.data_vars]
        if len(have) > 1:
            raise InvalidInputError(f"{shown}: both variables {have[0]!r} and {have[1]!r}; give one of them")
        return have[0] if have else None

    def vector(name, k) -> _Block:
        var = ds[name]
        if var.ndim != 2 or var.dims[0] != "t" or var.shape[1] != k:
            raise InvalidInputError(
                f"{shown}: variable {name!r} must have dimensions (t, {k}), got {var.dims} with shape {var.shape}"
            )
        return _Block(
            numeric(name, var), tuple(f"variable {name!r} component {c}" for c in range(k)), f"variable {name!r}"
        )

    def angle_scale(name, var) -> tuple[float, str]:
        units = var.attrs.get("units")
        if units is None:
            return 1.0, " rad"
        u = str(units).strip().lower()
        if u in _DEG_UNITS:
            return math.pi / 180.0, " deg"
        if u in _RAD_UNITS:
            return 1.0, " rad"
        raise InvalidInputError(f"{shown}: variable {name!r}: units {units!r} must be 'rad' or 'deg'")

    def sigma(name, per_component, angle) -> _Block:
        var = ds[name]
        scale, unit = angle_scale(name, var) if angle else (1.0, "")
        if var.ndim == 0:
            return _Block(float(numeric(name, var)), (f"variable {name!r}",), f"variable {name!r}", scale, unit)
        ok = var.dims[0] == "t" and (var.ndim == 1 or (per_component and var.ndim == 2 and var.shape[1] == 3))
        if not ok:
            want = "(t,) or (t, 3)" if per_component else "(t,)"
            raise InvalidInputError(
                f"{shown}: variable {name!r} must be a scalar or have dimensions {want}, got {var.dims} "
                f"with shape {var.shape}"
            )
        vals = numeric(name, var)
        if vals.ndim == 1:
            return _Block(vals[:, None], (f"variable {name!r}",), f"variable {name!r}", scale, unit)
        return _Block(
            vals, tuple(f"variable {name!r} component {c}" for c in range(3)), f"variable {name!r}", scale, unit
        )

    raw = _Raw(
        file=shown, places=[f"t index {i}" for i in range(n)], t=t, t_label="coordinate 't'", ignored=tuple(ignored)
    )
    qname = one_of(_NC_ATTITUDE)
    if qname:
        raw.attitude = vector(qname, 4)
    if "omega" in ds.data_vars:
        raw.omega = vector("omega", 3)
        if "frame" in ds["omega"].attrs:
            raw.omega_frame = _frame(ds["omega"].attrs["frame"], f"{shown}: attribute 'frame' of variable 'omega'")
    if "axis_direction" in ds.data_vars:
        raw.axis_direction = vector("axis_direction", 3)
        if "axis" in ds["axis_direction"].attrs:
            raw.axis = _unit_axis(
                ds["axis_direction"].attrs["axis"], f"{shown}: attribute 'axis' of variable 'axis_direction'"
            )
    if raw.attitude is None and raw.omega is None and raw.axis_direction is None:
        raise InvalidInputError(
            f"{shown}: no observation variables; give at least one of q (or attitude), omega, axis_direction"
        )
    for names, obs, angle, per_component, field in (
        (_NC_ATTITUDE_SIGMA, raw.attitude, True, False, "attitude_sigma"),
        (("omega_sigma",), raw.omega, False, True, "omega_sigma"),
        (_NC_AXIS_SIGMA, raw.axis_direction, True, False, "axis_sigma"),
    ):
        name = one_of(names)
        if name is None:
            continue
        if obs is None:
            raise InvalidInputError(
                f"{shown}: variable {name!r} without its observation: a sigma needs its observation"
            )
        setattr(raw, field, sigma(name, per_component, angle))
    if "principal_axes" in ds.attrs:
        raw.principal_axes = _principal(ds.attrs["principal_axes"], f"{shown}: global attribute 'principal_axes'")
    return raw


# ---------------------------------------------------------------------------
# checks common to the formats
# ---------------------------------------------------------------------------
def _check_times(raw: _Raw) -> np.ndarray:
    t = raw.t
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        what = "missing" if np.isnan(t[i]) else f"{float(t[i])!r}, not finite"
        raise InvalidInputError(
            f"{raw.file}, {raw.places[i]}, {raw.t_label}: the time is {what}; every row needs a finite time"
        )
    d = np.diff(t)
    bad = ~(d > 0)
    if bad.any():
        i = int(np.argmax(bad)) + 1
        if t[i] == t[i - 1]:
            raise InvalidInputError(
                f"{raw.file}, {raw.places[i]}: duplicate time t = {float(t[i])!r} (also at {raw.places[i - 1]}); "
                "times must be strictly increasing"
            )
        raise InvalidInputError(
            f"{raw.file}, {raw.places[i]}: time t = {float(t[i])!r} is before t = {float(t[i - 1])!r} "
            f"at {raw.places[i - 1]}; "
            "times must be strictly increasing (sort the rows)"
        )
    return t


def _check_finite_or_missing(raw: _Raw, b: _Block) -> None:
    assert isinstance(b.values, np.ndarray)  # an (N, k) block: only a sigma can be a scalar
    inf = np.isinf(b.values)
    if inf.any():
        i, k = np.argwhere(inf)[0]
        raise InvalidInputError(
            f"{raw.file}, {raw.places[i]}, {b.labels[k]}: value {float(b.values[i, k])!r} is not finite "
            "(leave it empty or NaN for a missing value)"
        )


def _whole_rows(raw: _Raw, b: _Block, what: str) -> np.ndarray:
    """Rows given whole (True) or missing whole (False); a partly given row is an error."""
    _check_finite_or_missing(raw, b)
    assert isinstance(b.values, np.ndarray)  # (checked there)
    given = np.isfinite(b.values)
    full = given.all(axis=1)
    partial = given.any(axis=1) & ~full
    if partial.any():
        i = int(np.argmax(partial))
        missing = [b.labels[k] for k in range(b.values.shape[1]) if not given[i, k]]
        raise InvalidInputError(
            f"{raw.file}, {raw.places[i]}: {what} is partly missing ({', '.join(missing)} empty/NaN, the rest "
            f"given in {b.what}); give all of it or none"
        )
    return full


def _unit_rows(raw: _Raw, b: _Block, what: str, noun: str) -> np.ndarray:
    full = _whole_rows(raw, b, what)
    v = b.values
    assert isinstance(v, np.ndarray)  # (checked there)
    out = np.full_like(v, np.nan)
    if full.any():
        rows = v[full]
        norm = np.linalg.norm(rows, axis=1)
        bad = ~(np.abs(norm - 1.0) <= UNIT_TOLERANCE)
        if bad.any():
            j = int(np.argmax(bad))
            i = int(np.flatnonzero(full)[j])
            if norm[j] == 0:
                raise InvalidInputError(
                    f"{raw.file}, {raw.places[i]}: {what} is the zero vector ({b.what}); a {noun} must have norm 1"
                )
            raise InvalidInputError(
                f"{raw.file}, {raw.places[i]}: {what} {v[i].tolist()} has norm {norm[j]:.10g}, not 1 "
                f"(tolerance {UNIT_TOLERANCE:g}); a {noun} must have norm 1 ({b.what})"
            )
        out[full] = rows / norm[:, None]
    return out


def _sigma(raw: _Raw, b: _Block, given: np.ndarray):
    """The file's sigma of an observation, checked where the observation is ``given`` (N,), in radians for
    angles; NaN where the observation is missing."""
    if np.ndim(b.values) == 0:  # a NetCDF scalar
        v = float(b.values)
        if not (math.isfinite(v) and v > 0):
            raise InvalidInputError(f"{raw.file}, {b.what}: a sigma must be positive and finite, got {v!r}{b.unit}")
        return v * b.scale
    vals = b.values  # (N, 1) or (N, 3)
    assert isinstance(vals, np.ndarray)  # the scalar returned above
    need = np.broadcast_to(given[:, None], vals.shape)
    bad = need & ~(np.isfinite(vals) & (vals > 0))
    if bad.any():
        i, k = np.argwhere(bad)[0]
        value = float(vals[i, k])
        what = "missing" if np.isnan(value) else f"{value!r}{b.unit}"
        raise InvalidInputError(
            f"{raw.file}, {raw.places[i]}, {b.labels[k]}: sigma is {what}; a sigma must be positive and finite "
            "where its observation is given"
        )
    out = np.where(need, vals * b.scale, np.nan)
    return out[:, 0] if out.shape[1] == 1 else out


def _frozen(a):
    if isinstance(a, np.ndarray):
        a = np.ascontiguousarray(a, dtype=np.float64)
        a.flags.writeable = False
    return a


def _assemble(raw: _Raw, s: _Settings, source: str) -> Observations:
    origin = s.origin or {}
    t = _check_times(raw)

    def said(key, value):
        """How ``key`` was set: ``omega_frame='space'`` or ``obs.toml: [observations] omega_frame = 'space'``."""
        return f"{origin[key]} = {value}" if key in origin else f"{key}={value}"

    attitude = None
    att_given = None
    if s.quaternion_order is not None and raw.attitude is None:
        raise InvalidInputError(
            f"{said('quaternion_order', repr(s.quaternion_order))} is given, but {raw.file} has no quaternions"
        )
    if raw.attitude is not None:
        if s.quaternion_order is not None:
            assert isinstance(raw.attitude.values, np.ndarray)  # (N, 4)
            order = list(raw.q_file_order)
            if s.quaternion_order == "xyzw":
                order = [order[k] for k in (3, 0, 1, 2)]
            raw.attitude.values = raw.attitude.values[:, order]
            raw.attitude.labels = tuple(raw.attitude.labels[k] for k in order)
        attitude = _unit_rows(raw, raw.attitude, "the quaternion", "unit quaternion")
        att_given = np.isfinite(attitude[:, 0])
    elif raw.euler is not None:
        from ..attitude.core import quaternion_from_euler

        att_given = _whole_rows(raw, raw.euler, f"the Euler angles ({raw.euler_seq})")
        attitude = np.full((t.shape[0], 4), np.nan)
        if att_given.any():
            assert raw.euler_seq is not None and isinstance(raw.euler.values, np.ndarray)  # read with the angles
            attitude[att_given] = quaternion_from_euler(raw.euler_seq, raw.euler.values[att_given], degrees=True)

    if s.attitude_convention is not None and attitude is None:
        raise InvalidInputError(
            f"{said('attitude_convention', repr(s.attitude_convention))} is given, but {raw.file} has no attitude"
        )
    if attitude is not None and s.attitude_convention == "space-to-body":
        attitude = attitude * np.array([1.0, -1.0, -1.0, -1.0])

    omega = None
    om_given = None
    if raw.omega is not None:
        om_given = _whole_rows(raw, raw.omega, "the angular velocity")
        omega = raw.omega.values
    if s.omega_unit is not None and omega is None:
        raise InvalidInputError(f"{said('omega_unit', repr(s.omega_unit))} is given, but {raw.file} has no rates")
    rate = math.pi / 180.0 if s.omega_unit == "deg" else 1.0  # to radians per unit of t
    if omega is not None and rate != 1.0:
        omega = omega * rate

    axis_direction = None
    if raw.axis_direction is not None:
        axis_direction = _unit_rows(raw, raw.axis_direction, "the axis direction", "direction")

    # settings against the file
    for key, has in (
        ("sigma_attitude_deg", attitude is not None),
        ("sigma_omega", omega is not None),
        ("sigma_axis_deg", axis_direction is not None),
    ):
        if getattr(s, key) is not None and not has:
            obs = {
                "sigma_attitude_deg": "attitude",
                "sigma_omega": "angular velocity",
                "sigma_axis_deg": "axis direction",
            }[key]
            raise InvalidInputError(f"{said(key, repr(getattr(s, key)))} is given, but {raw.file} has no {obs}")

    if raw.omega_frame is not None and s.omega_frame is not None and raw.omega_frame != s.omega_frame:
        raise InvalidInputError(
            f"{said('omega_frame', repr(s.omega_frame))} contradicts {raw.file}, where omega has "
            f"frame = {raw.omega_frame!r}"
        )
    frame = s.omega_frame or raw.omega_frame or "body"

    axis = None
    if raw.axis_direction is not None and axis_direction is not None:  # (the one is read from the other)
        if (
            raw.axis is not None
            and s.axis is not None
            and not np.allclose(raw.axis, s.axis, rtol=0, atol=UNIT_TOLERANCE)
        ):
            raise InvalidInputError(
                f"{said('axis', s.axis.tolist())} contradicts {raw.file}, where axis_direction has "
                f"axis = {raw.axis.tolist()}"
            )
        axis = s.axis if s.axis is not None else raw.axis
        if axis is None:
            raise InvalidInputError(
                f"{raw.file}: {raw.axis_direction.what} give the space direction of a body axis, but not which "
                "axis: pass axis=(x, y, z) (--axis, or axis = [x, y, z] in the TOML file)"
            )
    elif s.axis is not None:
        raise InvalidInputError(
            f"{said('axis', s.axis.tolist())} is given, but {raw.file} has no axis direction "
            "(columns ax, ay, az or variable axis_direction)"
        )

    if raw.principal_axes is not None and s.principal_axes is not None and raw.principal_axes != s.principal_axes:
        raise InvalidInputError(
            f"{said('principal_axes', repr(s.principal_axes))} contradicts {raw.file}, whose "
            f"attribute principal_axes = {raw.principal_axes!r}"
        )
    principal = s.principal_axes or raw.principal_axes

    deg = math.pi / 180.0
    attitude_sigma = omega_sigma = axis_sigma = None
    if attitude is not None:
        if s.sigma_attitude_deg is not None:
            attitude_sigma = s.sigma_attitude_deg * deg
        elif raw.attitude_sigma is not None:
            assert att_given is not None  # set with attitude
            attitude_sigma = _sigma(raw, raw.attitude_sigma, att_given)
    if omega is not None:
        if s.sigma_omega is not None:
            omega_sigma = s.sigma_omega * rate
        elif raw.omega_sigma is not None:
            assert om_given is not None  # set with omega
            omega_sigma = _sigma(raw, raw.omega_sigma, om_given) * rate
    if axis_direction is not None:
        if s.sigma_axis_deg is not None:
            axis_sigma = s.sigma_axis_deg * deg
        elif raw.axis_sigma is not None:
            axis_sigma = _sigma(raw, raw.axis_sigma, np.isfinite(axis_direction[:, 0]))

    return Observations(
        t=_frozen(t),
        attitude=_frozen(attitude),
        attitude_sigma=_frozen(attitude_sigma),
        omega=_frozen(omega),
        omega_sigma=_frozen(omega_sigma),
        omega_frame=frame,
        axis=_frozen(axis),
        axis_direction=_frozen(axis_direction),
        axis_sigma=_frozen(axis_sigma),
        principal_axes=principal,
        source=source,
        ignored=raw.ignored,
    )


# ---------------------------------------------------------------------------
# the entry point
# ---------------------------------------------------------------------------
def read_observations(
    path: str | os.PathLike[str],
    *,
    sigma_attitude_deg: float | None = None,
    sigma_omega: float | None = None,
    sigma_axis_deg: float | None = None,
    omega_frame: str | None = None,
    axis: ArrayLike | None = None,
    quaternion_order: str | None = None,
    attitude_convention: str | None = None,
    omega_unit: str | None = None,
) -> Observations:
    """Read an observations file (``.csv``, ``.nc`` or ``.toml``; see the module notes for the columns).

    Parameters
    ----------
    path : str or os.PathLike
        The file. Its extension chooses the format (case insensitive).
    sigma_attitude_deg : float, optional, keyword-only
        Standard deviation of every attitude, degrees; replaces the file's
        ``sigma_attitude_deg`` column (or ``attitude_sigma`` variable) and the
        TOML setting.
    sigma_omega : float, optional, keyword-only
        Standard deviation of every angular-velocity component, in the unit
        of the rates (``omega_unit``: radians per unit of ``t`` by default);
        replaces the file's sigma and the TOML setting.
    sigma_axis_deg : float, optional, keyword-only
        Standard deviation of every axis direction, degrees; replaces the
        file's sigma and the TOML setting.
    omega_frame : {"body", "space"}, optional, keyword-only
        The frame of ``wx, wy, wz`` (``omega``). Default: the TOML setting, the
        NetCDF attribute ``frame``, else ``"body"``.
    axis : array_like, shape (3,), optional, keyword-only
        The body axis whose space direction ``ax, ay, az`` gives; normalized.
        Required with those columns unless the TOML file or the NetCDF
        attribute ``axis`` gives it.
    quaternion_order : {"wxyz", "xyzw"}, optional, keyword-only
        What the four quaternion columns hold, in the order they appear in
        the file (NetCDF: the four components): scalar first or scalar last
        (x, y, z, w). Default: as the column names say (NetCDF: scalar first).
    attitude_convention : {"body-to-space", "space-to-body"}, optional, keyword-only
        What the attitudes rotate; ``"space-to-body"``: they are conjugated.
        Default ``"body-to-space"`` (``x_space = R x_body``).
    omega_unit : {"rad", "deg"}, optional, keyword-only
        Unit of ``wx, wy, wz`` and of their sigmas (``sigma_omega``, the file's
        sigma): radians (default) or degrees per unit of ``t``; degrees are
        converted to radians.

    Returns
    -------
    Observations
        Checked, with quaternions and directions renormalized, Euler angles
        converted to quaternions and degrees to radians.

    Raises
    ------
    InvalidInputError
        Each naming the file and, where there is one, the line (CSV) or time
        index (NetCDF) and the column or variable: no such file or an
        unreadable one; an unknown extension; for CSV a missing header or
        ``t`` column, an unknown column, a partial column group (``qw, qx``
        without ``qy, qz``), both quaternion and Euler columns, no observation
        column, a row with the wrong number of cells, a cell that is not a
        number; a time that is missing, not finite, repeated or out of order;
        a quaternion or axis direction whose norm is not 1 to within
        :data:`UNIT_TOLERANCE` (or zero); a quaternion, Euler angles, an
        angular velocity or an axis direction given in part; an infinite value;
        a sigma that is not positive and finite where its observation is
        given, or a sigma without its observation; an axis direction without
        an axis, an axis without axis directions; ``omega_frame`` other than
        ``"body"``/``"space"``; a NetCDF frame, axis or ``principal_axes``
        that contradicts the settings; for TOML invalid TOML, no
        ``[observations]`` table or no ``file``, an unknown key (naming the
        allowed ones) or a value of the wrong type.
    MissingDependencyError
        xarray is missing for a ``.nc`` file (extra ``io``).

    Notes
    -----
    The number of observations is not checked here: ``ep.fit`` says when
    there are too few for what it estimates.

    Examples
    --------
    >>> obs = read_observations("obs.csv", sigma_attitude_deg=0.1)  # doctest: +SKIP
    >>> fit = ep.fit(**obs.fit_kwargs())  # doctest: +SKIP
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise InvalidInputError(f"path must be a file name (str or os.PathLike), got {type(path).__name__} {path!r}")
    shown = os.fsdecode(path)
    if not shown.strip():
        raise InvalidInputError("path: empty file name")
    s = _Settings(origin={})
    if sigma_attitude_deg is not None:
        s.sigma_attitude_deg = _positive(sigma_attitude_deg, "sigma_attitude_deg")
    if sigma_omega is not None:
        s.sigma_omega = _positive(sigma_omega, "sigma_omega")
    if sigma_axis_deg is not None:
        s.sigma_axis_deg = _positive(sigma_axis_deg, "sigma_axis_deg")
    if omega_frame is not None:
        s.omega_frame = _frame(omega_frame, "omega_frame")
    if axis is not None:
        s.axis = _unit_axis(axis, "axis")
    for key, value, allowed in (
        ("quaternion_order", quaternion_order, QUATERNION_ORDERS),
        ("attitude_convention", attitude_convention, ATTITUDE_CONVENTIONS),
        ("omega_unit", omega_unit, OMEGA_UNITS),
    ):
        if value is not None:
            setattr(s, key, _choice(value, key, allowed))

    p = Path(shown)
    ext = p.suffix.lower()
    if ext not in (".csv", ".nc", ".toml"):
        raise InvalidInputError(
            f"{shown}: unknown observations file extension {p.suffix!r}; expected .csv, .nc or .toml"
        )
    _check_file(p, shown)
    data, data_shown = p, shown
    if ext == ".toml":
        data, t_set = _read_toml(p, shown)
        data_shown = str(data)
        _check_file(data, f"{data_shown} (the file of {shown})")
        # keyword arguments override the TOML settings
        for key in (
            "sigma_attitude_deg",
            "sigma_omega",
            "sigma_axis_deg",
            "omega_frame",
            "axis",
            "quaternion_order",
            "attitude_convention",
            "omega_unit",
        ):
            if getattr(s, key) is not None:
                t_set.origin.pop(key, None)
                setattr(t_set, key, getattr(s, key))
        s = t_set
    raw = _read_csv(data, data_shown) if data.suffix.lower() == ".csv" else _read_netcdf(data, data_shown)
    files = (str(p),) if data == p else (str(p), str(data))
    return dataclasses.replace(_assemble(raw, s, shown), files=files)


def _check_file(p: Path, shown: str) -> None:
    if not p.exists():
        raise InvalidInputError(f"{shown}: no such file")
    if not p.is_file():
        raise InvalidInputError(f"{shown}: not a file (a folder?); expected an observations file")
