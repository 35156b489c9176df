r"""The standard suite of reference trajectories: exact free motions a simulator should reproduce.

Each :class:`ReferenceCase` is an initial state, an inertia and output times;
its samples are the closed-form motion (``ep.solve(..., method="exact")``,
a few ulps at any time). :func:`write_cases` writes them as CSV and NetCDF
with a README and a JSON index (the ``eulerpoisson cases`` command).

The suite: the tennis racket (I = 3, 5, 8) on both sides of the separatrix
and at :math:`1-k^2 = 10^{-6}`; a full non-diagonal tensor; a symmetric top;
a fast spin; a long run to :math:`t = 10^4`; a sphere; a body spun exactly
about each principal axis (the intermediate one is unstable: any simulator's
error grows exponentially there, the exact motion stays a uniform rotation).

References
----------
L. D. Landau and E. M. Lifshitz, *Mechanics*, §§35-37.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..errors import EulerPoissonError, InvalidInputError
from .runs import CSV_HEADER

if TYPE_CHECKING:
    from ..trajectory import Trajectory

__all__ = [
    "ReferenceCase",
    "reference_cases",
    "reference_case",
    "write_cases",
    "CASE_NAMES",
    "conformance_cases",
    "CONFORMANCE_CASE_NAMES",
    "CONFORMANCE_PERIODS",
]


@dataclass(frozen=True)
class ReferenceCase:
    """One reference trajectory of the suite.

    Attributes
    ----------
    name : str
    description : str
    inertia : tuple
        Principal moments (3 numbers) or a 3x3 tensor (3 rows) in the body frame.
    omega0 : tuple
        Initial body angular velocity.
    quaternion0 : tuple
        Initial attitude (w, x, y, z), body to space.
    t_end : float
        Last output time (the first is 0).
    samples : int
        Number of equally spaced output times.

    Notes
    -----
    :attr:`t`, :attr:`quaternion` and :attr:`omega` (shapes (T,), (T, 4),
    (T, 3)) are computed on first access.

    Examples
    --------
    >>> from eulerpoisson.oracle import reference_case
    >>> case = reference_case("symmetric_top")
    >>> type(case).__name__, case.inertia, case.samples
    ('ReferenceCase', (1.0, 1.0, 1.5), 3001)
    >>> case.t.shape, case.quaternion.shape
    ((3001,), (3001, 4))
    """

    name: str
    description: str
    inertia: tuple
    omega0: tuple
    quaternion0: tuple
    t_end: float
    samples: int
    flips: bool = False

    @property
    def inertia_array(self) -> NDArray[np.float64]:
        """The inertia as an array, shape (3,) or (3, 3)."""
        return np.array(self.inertia, dtype=float)

    @cached_property
    def trajectory(self) -> Trajectory:
        """The exact motion (a :class:`~eulerpoisson.Trajectory`)."""
        from ..solvers import solve

        t = np.linspace(0.0, self.t_end, self.samples)
        return solve(self.inertia_array, t, omega0=self.omega0, attitude0=self.quaternion0, method="exact")

    @property
    def t(self) -> NDArray[np.float64]:
        """Output times, shape (T,)."""
        return self.trajectory.t

    @property
    def quaternion(self) -> NDArray[np.float64]:
        """Attitudes (w, x, y, z), body to space, shape (T, 4)."""
        return self.trajectory.quaternion

    @property
    def omega(self) -> NDArray[np.float64]:
        """Body angular velocities, shape (T, 3)."""
        return self.trajectory.omega

    def inertia_flag(self) -> str:
        """The ``--inertia`` value of this case (3 or 9 comma-separated numbers)."""
        return ",".join(repr(float(x)) for x in np.ravel(self.inertia))

    def to_dict(self) -> dict:
        """Initial state and settings (no samples), JSON-able."""
        return {
            "name": self.name,
            "description": self.description,
            "inertia": np.array(self.inertia, float).tolist(),
            "omega0": list(map(float, self.omega0)),
            "quaternion0": list(map(float, self.quaternion0)),
            "t_end": float(self.t_end),
            "samples": int(self.samples),
            "flips": self.flips,
        }

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write ``t,qw,qx,qy,qz,wx,wy,wz`` with 17 significant digits (round-trips float64)."""
        from ..io.atomic import atomic_path

        data = np.column_stack([self.t, self.quaternion, self.omega])
        with atomic_path(path) as tmp:
            np.savetxt(tmp, data, delimiter=",", header=",".join(CSV_HEADER), comments="", fmt="%.17g")

    def to_netcdf(self, path: str | os.PathLike[str]) -> None:
        """Write the exact trajectory as an eulerpoisson NetCDF file (needs the ``io`` extra)."""
        self.trajectory.to_netcdf(path)


def _cases() -> list[ReferenceCase]:
    racket = (3.0, 5.0, 8.0)
    ident = (1.0, 0.0, 0.0, 0.0)
    # 1 - k^2 = 40 e^2 / (1.6 + 40 e^2) for omega0 = (0, 0.4, e): 1e-6 exactly (to round-off) at
    e = 2e-4 / np.sqrt(1.0 - 1e-6)
    q_tilt = tuple(np.array([np.cos(0.35), 0.6 * np.sin(0.35), -0.48 * np.sin(0.35), 0.64 * np.sin(0.35)]).tolist())
    return [
        ReferenceCase(
            "tennis_racket_circulating_1",
            "flat racket spun near its intermediate axis; momentum circulates "
            "about the axis of the smallest moment (L^2 < 2 E I2); 1 - k^2 = 1e-4",
            racket,
            (0.004, 0.4, 0.0),
            ident,
            200.0,
            2001,
            True,
        ),
        ReferenceCase(
            "tennis_racket_circulating_3",
            "the same racket on the other side of the separatrix: momentum "
            "circulates about the axis of the largest moment (L^2 > 2 E I2); 1 - k^2 = 4e-4",
            racket,
            (0.0, 0.4, 0.004),
            ident,
            200.0,
            2001,
            True,
        ),
        ReferenceCase(
            "tennis_racket_separatrix",
            "the racket at 1 - k^2 = 1e-6 from the separatrix: flips every 82.94 s",
            racket,
            (0.0, 0.4, float(e)),
            ident,
            300.0,
            3001,
            True,
        ),
        ReferenceCase(
            "full_tensor",
            "a full non-diagonal inertia tensor, a tilted initial attitude",
            ((2.0, 0.1, 0.0), (0.1, 1.5, -0.2), (0.0, -0.2, 1.2)),
            (0.7, -1.1, 2.0),
            q_tilt,
            20.0,
            2001,
        ),
        ReferenceCase(
            "symmetric_top",
            "a symmetric top (I1 = I2): a uniform precession",
            (1.0, 1.0, 1.5),
            (0.3, 0.2, 1.0),
            q_tilt,
            30.0,
            3001,
        ),
        ReferenceCase(
            "fast_spin",
            "a fast spin, |Omega| = 100 rad/s, nearly about the axis of the largest moment",
            (1.0, 2.0, 3.0),
            (1.0, 0.5, 100.0),
            ident,
            10.0,
            10001,
        ),
        ReferenceCase("long_run", "a long run to t = 1e4", (1.0, 2.0, 3.0), (1.0, 0.1, 0.5), ident, 1.0e4, 10001, True),
        ReferenceCase(
            "sphere",
            "a spherical body: Omega constant, a uniform rotation",
            (2.0, 2.0, 2.0),
            (0.3, -0.4, 1.2),
            q_tilt,
            20.0,
            2001,
        ),
        ReferenceCase(
            "principal_axis_1",
            "the racket spun exactly about its axis of smallest moment (stable)",
            racket,
            (0.5, 0.0, 0.0),
            ident,
            100.0,
            1001,
        ),
        ReferenceCase(
            "principal_axis_2",
            "the racket spun exactly about its intermediate axis (unstable: a "
            "uniform rotation that any round-off destroys)",
            racket,
            (0.0, 0.5, 0.0),
            ident,
            100.0,
            1001,
        ),
        ReferenceCase(
            "principal_axis_3",
            "the racket spun exactly about its axis of largest moment (stable)",
            racket,
            (0.0, 0.0, 0.5),
            ident,
            100.0,
            1001,
        ),
    ]


#: the names of the cases, in the suite's order
CASE_NAMES = tuple(c.name for c in _cases())


def _conformance_cases() -> list[ReferenceCase]:
    racket = (3.0, 5.0, 8.0)
    ident = (1.0, 0.0, 0.0, 0.0)
    # omega0 = (0, a, e): 1 - k^2 = e^2 / (a^2 / 4 + e^2) for this racket; 1e-4 at a = 24 rad/s
    e = 12.0 * np.sqrt(1e-4 / (1.0 - 1e-4))
    q_tilt = tuple(np.array([np.cos(0.35), 0.6 * np.sin(0.35), -0.48 * np.sin(0.35), 0.64 * np.sin(0.35)]).tolist())
    w_sphere = 2.0 * np.pi * np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    return [
        ReferenceCase(
            "racket_near_separatrix",
            "the tennis racket (I = 3, 5, 8) spun at 24 rad/s near its intermediate axis, 1 - k^2 = 1e-4: "
            "it flips every 1.0 s",
            racket,
            (0.0, 24.0, float(e)),
            ident,
            10.0,
            2001,
            True,
        ),
        ReferenceCase(
            "spin_largest_axis",
            "the racket spun at 2 pi rad/s near its axis of largest moment (stable): a wobble of period 1.0 s",
            racket,
            (0.3, 0.3, 2.0 * np.pi),
            ident,
            10.0,
            2001,
        ),
        ReferenceCase(
            "spin_smallest_axis",
            "the racket spun at 4 pi rad/s near its axis of smallest moment (stable): a wobble of period 1.0 s",
            racket,
            (4.0 * np.pi, 0.3, 0.3),
            ident,
            10.0,
            2001,
        ),
        ReferenceCase(
            "symmetric_precession",
            "a symmetric top (I = 2, 2, 3) spun at 4 pi rad/s about its axis, tilted: Omega precesses "
            "in the body once a second",
            (2.0, 2.0, 3.0),
            (1.0, 0.0, 4.0 * np.pi),
            q_tilt,
            10.0,
            2001,
        ),
        ReferenceCase(
            "fast_flat_spinner",
            "a flat body (I = 1, 1.05, 2) spun at 150 rad/s about its axis of largest moment, wobbling "
            "every 0.044 s (past the 100 rad/s some engines clamp to)",
            (1.0, 1.05, 2.0),
            (3.0, 0.0, 150.0),
            ident,
            0.5,
            2001,
        ),
        ReferenceCase(
            "nearly_spherical",
            "a nearly spherical body (I = 1, 1.02, 1.04) turning once a second (|Omega| = 2 pi rad/s), tilted",
            (1.0, 1.02, 1.04),
            tuple(float(x) for x in w_sphere),
            q_tilt,
            10.0,
            2001,
        ),
        ReferenceCase(
            "full_tensor_tilted",
            "a full inertia tensor whose principal axes are not the body axes, tilted, |Omega| = 25 rad/s: "
            "Omega(t) has a period of 1.0 s",
            ((2.0, 0.1, 0.0), (0.1, 1.5, -0.2), (0.0, -0.2, 1.2)),
            (7.44, -11.69, 21.26),
            q_tilt,
            10.0,
            2001,
        ),
    ]


#: the cases of the conformance report (:mod:`eulerpoisson.oracle.conformance`), each with periods near 1 s
CONFORMANCE_CASE_NAMES = tuple(c.name for c in _conformance_cases())
#: what a case's natural period is: ``"flip"`` (2K/lambda, between flips), ``"momentum"`` (4K/lambda, of
#: Omega(t)), ``"precession"`` (of Omega about the symmetry axis, in the body) or ``"rotation"`` (2 pi/|Omega|)
CONFORMANCE_PERIODS = {
    "racket_near_separatrix": "flip",
    "spin_largest_axis": "momentum",
    "spin_smallest_axis": "momentum",
    "symmetric_precession": "precession",
    "fast_flat_spinner": "momentum",
    "nearly_spherical": "rotation",
    "full_tensor_tilted": "momentum",
}


def conformance_cases() -> dict[str, ReferenceCase]:
    """The cases of the conformance report, by name (new objects at every call).

    Returns
    -------
    dict of str to ReferenceCase

    Examples
    --------
    >>> from eulerpoisson.oracle.cases import conformance_cases
    >>> cases = conformance_cases()
    >>> len(cases), cases["racket_near_separatrix"].omega0[:2]
    (7, (0.0, 24.0))
    """
    return {c.name: c for c in _conformance_cases()}


def reference_cases() -> dict[str, ReferenceCase]:
    """The suite, by name (a new dict of new cases at every call; samples computed on first access).

    Returns
    -------
    dict of str to ReferenceCase

    Examples
    --------
    >>> from eulerpoisson.oracle import reference_cases
    >>> case = reference_cases()["tennis_racket_separatrix"]
    >>> case.quaternion.shape, case.omega.shape
    ((3001, 4), (3001, 3))
    """
    return {c.name: c for c in _cases()}


def reference_case(name: str) -> ReferenceCase:
    """One case of the suite by name.

    Raises
    ------
    InvalidInputError
        An unknown name (the message lists the names).

    Examples
    --------
    >>> from eulerpoisson.oracle import reference_case
    >>> reference_case("sphere").description
    'a spherical body: Omega constant, a uniform rotation'
    >>> try:
    ...     reference_case("cube")
    ... except ValueError as err:
    ...     print(err)
    unknown reference case 'cube'; cases: tennis_racket_circulating_1, ...
    """
    cases = reference_cases()
    if name not in cases:
        raise InvalidInputError(f"unknown reference case {name!r}; cases: {', '.join(CASE_NAMES)}")
    return cases[name]


def _readme(cases, netcdf: bool) -> str:
    lines = [
        "# eulerpoisson reference cases",
        "",
        "Exact free rigid-body motions (closed form, a few ulps at any time), written by `eulerpoisson cases`.",
        "Validate a simulator by starting it from a case's initial state and running",
        "`eulerpoisson validate YOUR_RUN.csv --inertia ...` (the exact motion restarts from your run's first sample),",
        "or compare your samples with the files here directly.",
        "",
        "Conventions: `x_space = R x_body`; quaternions scalar first (w, x, y, z), Hamilton product, body to space;",
        "`wx, wy, wz` is the **body** angular velocity Omega (the space-frame rate is R Omega);",
        "E = Omega.I Omega / 2, m = R I Omega (constant).",
        "",
        "Columns of every CSV: `"
        + ",".join(CSV_HEADER)
        + "` (17 significant digits)."
        + (" Each `.nc` file holds the same trajectory with its body (`eulerpoisson info NAME.nc`)." if netcdf else ""),
        "",
        "| case | inertia | Omega(0) | q(0) (w,x,y,z) | t | samples | |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in cases:
        I = np.array(c.inertia, float)
        ishow = ", ".join(f"{x:g}" for x in I) if I.ndim == 1 else "; ".join(", ".join(f"{x:g}" for x in r) for r in I)
        lines.append(
            f"| `{c.name}` | {ishow} | {', '.join(f'{x:.17g}' for x in c.omega0)} | "
            f"{', '.join(f'{x:.17g}' for x in c.quaternion0)} | 0 to {c.t_end:g} | {c.samples} | "
            f"{c.description} |"
        )
    lines += ["", "Round trip (errors at round-off):", "", "```sh"]
    for c in cases[:2]:
        lines.append(f"eulerpoisson validate {c.name}.csv --inertia {c.inertia_flag()} --tolerance 1e-9")
    lines += [
        "```",
        "",
        "The same cases in Python: `eulerpoisson.testing.reference_cases()`;"
        " `eulerpoisson.testing.assert_free_motion(t, q, omega, inertia, atol=...)` checks a run in one line.",
        "",
    ]
    return "\n".join(lines)


def write_cases(out: str | os.PathLike[str], names: Sequence[str] | None = None, *, netcdf: bool = True) -> list[str]:
    """Write the suite into a folder: ``NAME.csv``, ``NAME.nc``, ``cases.json`` and ``README.md``.

    The files are written into a hidden folder next to ``out`` and moved
    into place at the end: a failure (a full disk, a missing dependency,
    Ctrl-C) leaves ``out`` as it was (no new empty folder). Into a folder of
    cases written before, the cases it lists that are not written again are
    removed (the index always lists what is there); other files are kept.

    Parameters
    ----------
    out : str or os.PathLike
        The folder (created if needed).
    names : sequence of str, optional
        Some cases only (default: all).
    netcdf : bool
        Also write NetCDF files (needs the ``io`` extra).

    Returns
    -------
    list of str
        The files written.

    Raises
    ------
    InvalidInputError
        An unknown case name; ``out`` is an existing file.
    OSError
        A file cannot be written: the message names ``out`` and what to do.

    Examples
    --------
    >>> from eulerpoisson.oracle import write_cases
    >>> import os
    >>> files = write_cases("cases", ["sphere"], netcdf=False)
    >>> sorted(os.path.basename(f) for f in files)
    ['README.md', 'cases.json', 'sphere.csv']
    """
    import shutil
    import tempfile

    from ..io.atomic import check_guard, write_error
    from ..io.outputs import mark_text

    out = os.fspath(out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise InvalidInputError(f"{out} is a file; give a folder for the reference cases")
    cases = reference_cases()
    chosen = list(cases.values()) if names is None else [reference_case(n) for n in names]
    target = os.path.abspath(out)
    try:
        os.makedirs(os.path.dirname(target), exist_ok=True)
        stage = tempfile.mkdtemp(prefix=f".{os.path.basename(target)}.", suffix=".partial", dir=os.path.dirname(target))
    except OSError as exc:
        raise write_error(out, exc) from exc
    try:
        try:
            staged = []
            for c in chosen:
                c.to_csv(os.path.join(stage, f"{c.name}.csv"))
                staged.append(f"{c.name}.csv")
                if netcdf:
                    c.to_netcdf(os.path.join(stage, f"{c.name}.nc"))
                    staged.append(f"{c.name}.nc")
            with open(os.path.join(stage, "cases.json"), "w", encoding="utf-8") as fh:
                json.dump([c.to_dict() for c in chosen], fh, indent=1)
            staged.append("cases.json")
            with open(os.path.join(stage, "README.md"), "w", encoding="utf-8") as fh:
                fh.write(mark_text(_readme(chosen, netcdf), "reference-cases", "md"))
            staged.append("README.md")
            check_guard(out)  # the output's claim (eulerpoisson cases): checked again before the move
            _publish(stage, target, staged)
        except EulerPoissonError:
            raise  # the claim's refusal (OutputError), a missing dependency: as they are
        except OSError as exc:
            cause: BaseException = exc  # the first error (a file written inside the hidden folder names it)
            while isinstance(cause.__cause__, OSError):
                cause = cause.__cause__
            raise write_error(out, cause if isinstance(cause, OSError) else exc) from exc
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return [os.path.join(out, f) for f in staged]


def _publish(stage: str, target: str, staged: list[str]) -> None:
    """Move the files written in ``stage`` into ``target``; remove the cases ``target`` listed and lost."""
    if not os.path.isdir(target):
        os.replace(stage, target)  # a new folder, all at once
        return
    stale: set[str] = set()
    try:
        with open(os.path.join(target, "cases.json"), encoding="utf-8") as fh:
            old = json.load(fh)
        stale = {
            f"{c['name']}{ext}"
            for c in old
            if isinstance(c, dict) and isinstance(c.get("name"), str)
            for ext in (".csv", ".nc")
        }
    except (OSError, ValueError, TypeError):
        pass  # not a folder of cases: only our new files are moved in
    for f in staged:
        os.replace(os.path.join(stage, f), os.path.join(target, f))
    for f in sorted(stale - set(staged)):
        if os.path.basename(f) == f and os.path.isfile(os.path.join(target, f)):
            os.unlink(os.path.join(target, f))
