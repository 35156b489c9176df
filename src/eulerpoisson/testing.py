"""Test helpers for other projects: check a simulator's free rigid body against the exact motion in one line.

>>> import numpy as np
>>> from eulerpoisson.testing import assert_free_motion, reference_case
>>> case = reference_case("tennis_racket_separatrix")      # the exact motion, as arrays
>>> report = assert_free_motion(case.t, case.quaternion, case.omega, case.inertia, atol=1e-9)
>>> report.verdict
'pass'

In a physics engine's pytest suite::

    from eulerpoisson.testing import assert_free_motion

    def test_free_body_tumbles_correctly():
        t, q, omega = my_engine.simulate_free_body(inertia=[3, 5, 8], omega0=[0.004, 0.4, 0], t_end=200)
        assert_free_motion(t, q, omega, [3, 5, 8], atol=1e-3)      # q: (T, 4) w,x,y,z; omega: (T, 3) body frame

The exact motion starts from the first sample (attitude and rate); see
:func:`eulerpoisson.oracle.validate` for the full report.
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from .oracle.cases import CASE_NAMES, ReferenceCase, reference_case, reference_cases
from .oracle.compare import ValidationReport, compare_run
from .oracle.runs import Conventions, run_from_arrays

__all__ = ["assert_free_motion", "reference_cases", "reference_case", "ReferenceCase", "CASE_NAMES"]


def assert_free_motion(
    t: ArrayLike,
    q: ArrayLike,
    omega: ArrayLike,
    inertia: ArrayLike,
    *,
    atol: float,
    quaternion_order: str = "wxyz",
    omega_frame: str = "body",
    attitude_convention: str = "body-to-space",
    omega_rtol: float | None = None,
) -> ValidationReport:
    r"""Assert that sampled attitudes and rates are the exact free motion from the first sample, within ``atol``.

    Parameters
    ----------
    t : array_like, shape (T,)
        Strictly increasing times, T >= 2.
    q : array_like, shape (T, 4)
        Attitude quaternions (unit within 1e-3), in ``quaternion_order``.
    omega : array_like, shape (T, 3)
        Angular velocities in ``omega_frame``.
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments or the tensor in the body frame.
    atol : float
        Largest attitude error allowed (rad): the angle of :math:`q_\mathrm{ref}^{-1}q`.
    quaternion_order : {"wxyz", "xyzw"}
    omega_frame : {"body", "space"}
    attitude_convention : {"body-to-space", "space-to-body"}
    omega_rtol : float, optional
        Also require :math:`|\boldsymbol\Omega-\boldsymbol\Omega_\mathrm{ref}|/\max|\boldsymbol\Omega_\mathrm{ref}|`
        within this.

    Returns
    -------
    ValidationReport
        When the assertion holds.

    Raises
    ------
    AssertionError
        The attitude error exceeds ``atol`` (the message gives the first failing time, the error there, the
        largest error, and a likely convention mismatch when there is one), or the rate error ``omega_rtol``.
    InvalidInputError
        Bad input: shapes, fewer than 2 samples, NaN, times not strictly increasing, quaternions far from
        unit norm, a bad inertia or ``atol``.
    """
    raw = run_from_arrays(t, q, omega, quaternion_order=quaternion_order)
    rep = compare_run(
        raw, inertia, conventions=Conventions(quaternion_order, omega_frame, attitude_convention), tolerance=atol
    )
    hint = f"; {rep.convention_hint}" if rep.convention_hint else ""
    if rep.verdict == "fail":
        assert rep.exceeded_at is not None  # a failed verdict says when
        i = int(rep.t.searchsorted(rep.exceeded_at))
        raise AssertionError(
            f"not the exact free motion: the attitude error is {rep.attitude_error[i]:.3g} rad > atol = {atol:g} "
            f"first at t = {rep.exceeded_at:.9g} (sample {i}); largest {rep.max_attitude_error:.3g} rad at "
            f"t = {rep.max_attitude_error_time:.9g}{hint}"
        )
    if omega_rtol is not None and rep.max_omega_error > omega_rtol:
        i = int(rep.omega_error.__gt__(omega_rtol).argmax())
        raise AssertionError(
            f"not the exact free motion: the relative angular velocity error is {rep.omega_error[i]:.3g} > "
            f"omega_rtol = {omega_rtol:g} first at t = {rep.t[i]:.9g} (sample {i}); largest "
            f"{rep.max_omega_error:.3g}{hint}"
        )
    return rep
