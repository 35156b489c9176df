"""eulerpoisson as a reference oracle: validate any simulator's free rigid-body rotation against the exact motion.

- :mod:`.runs`: read a run (CSV, NetCDF, JSON) and put it in eulerpoisson's conventions;
- :mod:`.compare`: the comparison (:func:`validate`, :class:`ValidationReport`), convention-mismatch detection;
- :mod:`.cases`: the standard suite of reference trajectories;
- :mod:`.plot`: the error figure.

The command line: ``eulerpoisson validate`` and ``eulerpoisson cases``; a
test suite: :mod:`eulerpoisson.testing`.
"""

from __future__ import annotations

import os

from numpy.typing import ArrayLike

from .cases import CASE_NAMES, ReferenceCase, reference_case, reference_cases, write_cases
from .compare import ValidationReport, compare_run
from .plot import plot_report
from .runs import (
    ATTITUDE_CONVENTIONS,
    NORM_TOLERANCE,
    OMEGA_FRAMES,
    QUATERNION_ORDERS,
    Conventions,
    RawRun,
    normalize_run,
    read_run,
    run_from_arrays,
)

__all__ = [
    "validate",
    "ValidationReport",
    "compare_run",
    "Conventions",
    "RawRun",
    "read_run",
    "run_from_arrays",
    "normalize_run",
    "ReferenceCase",
    "reference_cases",
    "reference_case",
    "write_cases",
    "CASE_NAMES",
    "plot_report",
    "QUATERNION_ORDERS",
    "OMEGA_FRAMES",
    "ATTITUDE_CONVENTIONS",
    "NORM_TOLERANCE",
]


def validate(
    run: str | os.PathLike[str] | RawRun,
    inertia: ArrayLike | None = None,
    *,
    quaternion_order: str | None = None,
    omega_frame: str = "body",
    attitude_convention: str = "body-to-space",
    tolerance: float | None = None,
    detect: bool = True,
) -> ValidationReport:
    """Validate a run (a file or a :class:`RawRun`) against the exact free motion from its first sample.

    Parameters
    ----------
    run : str, os.PathLike or RawRun
        A CSV/NetCDF/JSON file (:func:`read_run`) or a run made by :func:`run_from_arrays`.
    inertia : array_like, shape (3,) or (3, 3), optional
        The body's inertia in the run's body frame (default: the one an eulerpoisson NetCDF file states).
    quaternion_order : {"wxyz", "xyzw"} or None
        The order of the quaternion columns (None: as the file's column names say).
    omega_frame : {"body", "space"}
    attitude_convention : {"body-to-space", "space-to-body"}
    tolerance : float, optional
        Attitude tolerance in radians: the verdict is ``"pass"`` or ``"fail"``.
    detect : bool
        Name a likely convention mismatch when the error is O(1) early on.

    Returns
    -------
    ValidationReport

    Raises
    ------
    InvalidInputError
        Unreadable run, missing columns, non-monotone times, quaternions far from unit norm, bad inertia.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.oracle import run_from_arrays, validate
    >>> tr = ep.solve([3.0, 5.0, 8.0], np.linspace(0, 100, 501), omega0=[0.004, 0.4, 0.0])
    >>> rep = validate(run_from_arrays(tr.t, tr.quaternion, tr.omega), [3.0, 5.0, 8.0], tolerance=1e-9)
    >>> rep.verdict, rep.max_attitude_error < 1e-12, len(rep.flip_times)
    ('pass', True, 2)
    """
    raw = run if isinstance(run, RawRun) else read_run(os.fspath(run))
    conv = Conventions(quaternion_order, omega_frame, attitude_convention)
    return compare_run(raw, inertia, conventions=conv, tolerance=tolerance, detect=detect)
