r"""A run against the exact motion: attitude and rate errors, invariant drift, flips, conventions, a verdict.

The exact motion starts from the run's first sample (attitude and body
rate) and is evaluated in closed form (``ep.solve(..., method="exact")``,
a few ulps at any time) at every sample time. The attitude error is the
angle of :math:`q_\mathrm{ref}^{-1}\otimes q`,
:math:`2\,\mathrm{atan2}(|\mathbf v|, |w|)`; the rate error is
:math:`|\boldsymbol\Omega-\boldsymbol\Omega_\mathrm{ref}|/\max_t|\boldsymbol\Omega_\mathrm{ref}|`;
the drifts are those of the run itself, :math:`|E(t)-E(t_0)|/|E(t_0)|` and
:math:`|\mathbf m(t)-\mathbf m(t_0)|/|\mathbf m(t_0)|` with the given inertia.

A body whose angular momentum passes within about 25 degrees of the
intermediate principal axis (the tennis racket) flips: the intermediate
component of :math:`\boldsymbol\Omega` in the principal frame changes sign
every :math:`2K(k)/\lambda`. The reference flips are located on the closed
form to round-off (Brent's method), the run's by linear interpolation
between its samples.

References
----------
L. D. Landau and E. M. Lifshitz, *Mechanics*, §37 (the free asymmetric top).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError
from .runs import QUATERNION_ORDERS, Conventions, RawRun, all_conventions, normalize_run

__all__ = ["ValidationReport", "compare_run", "ROUNDOFF", "CONVENTION_ERROR", "NEAR_INTERMEDIATE"]

#: an attitude error below this (rad) is round-off: the run is the exact motion
ROUNDOFF = 1e-9
#: an attitude error above this (rad) early in a run suggests a convention mismatch
CONVENTION_ERROR = 0.05
#: flips are reported when the momentum comes within this fraction of |M| to the intermediate axis
NEAR_INTERMEDIATE = 0.9
#: most samples used to look for a convention mismatch
_DETECT_SAMPLES = 20000
#: most flips of a run that are located
_MAX_FLIPS = 100_000

#: the default of ValidationReport's series (typed Any: compare_run always gives arrays)
_NOT_GIVEN: Any = None


@dataclass(frozen=True, eq=False)
class ValidationReport:
    """The result of validating a run against the exact free motion.

    Attributes
    ----------
    source : str
        The run's file (or ``"arrays"``).
    samples : int
    t_start, t_end : float
    inertia : list
        The inertia used (3 moments or a 3x3 tensor).
    conventions : Conventions
        The conventions the run was read in.
    max_attitude_error : float
        Largest angle (rad) between the run's attitude and the exact one.
    max_attitude_error_time : float
        The time of that largest error.
    max_omega_error : float
        Largest :math:`|\\Omega-\\Omega_\\mathrm{ref}|/\\max|\\Omega_\\mathrm{ref}|`.
    energy_drift, momentum_drift : float
        Largest relative change of the run's energy and spatial angular momentum.
    flip_times : tuple of float or None
        The exact flip times in the run's span (None: the body is not spun near its intermediate axis).
    flip_times_run : tuple of float or None
        The run's flips.
    flip_time_errors : tuple of float or None
        Run minus exact, for each exact flip (the nearest run flip); NaN where the run has no flip.
    tolerance : float or None
        The attitude tolerance (rad) judged against.
    exceeded_at : float or None
        The first time the attitude error exceeds ``tolerance``.
    verdict : str
        ``"pass"``/``"fail"`` (with a tolerance: fail when the attitude error exceeds it, or when a
        convention mismatch is detected), ``"round-off"``/``"differs"`` (without).
    message : str
        One sentence with the verdict.
    convention_hint : str or None
        The likely convention mismatch, named, with the flags that read the run correctly.
    suggested_conventions : Conventions or None
        The conventions of the hint.
    warnings : tuple of str
    t, attitude_error, omega_error, energy_error, momentum_error : ndarray, shape (T,)
        The series (not in :meth:`to_dict`).

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.oracle import run_from_arrays, validate
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 10.0, 101), omega0=[1.0, 0.1, 0.5], method="rk", tol=1e-8)
    >>> rep = validate(run_from_arrays(tr.t, tr.quaternion, tr.omega), [1.0, 2.0, 2.5], tolerance=1e-5)
    >>> rep.verdict, rep.samples, bool(rep.max_attitude_error < 1e-5)
    ('pass', 101, True)
    >>> sorted(rep.to_dict())[:5]
    ['convention_hint', 'conventions', 'energy_drift', 'exceeded_at', 'flip_time_errors']
    """

    source: str
    samples: int
    t_start: float
    t_end: float
    inertia: list
    conventions: Conventions
    max_attitude_error: float
    max_attitude_error_time: float
    max_omega_error: float
    energy_drift: float
    momentum_drift: float
    flip_times: tuple | None
    flip_times_run: tuple | None
    flip_time_errors: tuple | None
    tolerance: float | None
    exceeded_at: float | None
    verdict: str
    message: str
    convention_hint: str | None = None
    suggested_conventions: Conventions | None = None
    warnings: tuple = ()
    # the series: compare_run always gives them (the default is None)
    t: np.ndarray = field(default=_NOT_GIVEN, repr=False)
    attitude_error: np.ndarray = field(default=_NOT_GIVEN, repr=False)
    omega_error: np.ndarray = field(default=_NOT_GIVEN, repr=False)
    energy_error: np.ndarray = field(default=_NOT_GIVEN, repr=False)
    momentum_error: np.ndarray = field(default=_NOT_GIVEN, repr=False)

    @property
    def passed(self) -> bool:
        """True unless a tolerance was given and exceeded."""
        return self.verdict != "fail"

    def to_dict(self) -> dict:
        """The report as a JSON-able dict (no series)."""

        def fl(x):
            return None if x is None else [float(v) if np.isfinite(v) else None for v in x]

        return {
            "source": self.source,
            "samples": self.samples,
            "t_start": self.t_start,
            "t_end": self.t_end,
            "inertia": self.inertia,
            "conventions": self.conventions.to_dict(),
            "max_attitude_error": self.max_attitude_error,
            "max_attitude_error_time": self.max_attitude_error_time,
            "max_omega_error": self.max_omega_error,
            "energy_drift": self.energy_drift,
            "momentum_drift": self.momentum_drift,
            "flip_times": fl(self.flip_times),
            "flip_times_run": fl(self.flip_times_run),
            "flip_time_errors": fl(self.flip_time_errors),
            "tolerance": self.tolerance,
            "exceeded_at": self.exceeded_at,
            "verdict": self.verdict,
            "message": self.message,
            "convention_hint": self.convention_hint,
            "suggested_conventions": None
            if self.suggested_conventions is None
            else self.suggested_conventions.to_dict(),
            "warnings": list(self.warnings),
        }


def _angle(q1, q2):
    """Angle of the rotation q1^-1 q2 (unit quaternions, (..., 4)), sign-insensitive, accurate near 0."""
    w = np.sum(q1 * q2, axis=-1)
    v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))


def _reference(body, t, q, w):
    from ..solvers import solve

    return solve(body, t - t[0], omega0=w[0], attitude0=q[0], method="exact")


def _errors(body, t, q, w):
    ref = _reference(body, t, q, w)
    att = _angle(ref.quaternion, q)
    scale = float(np.max(np.linalg.norm(ref.omega, axis=-1)))
    om = np.linalg.norm(w - ref.omega, axis=-1) / (scale if scale > 0 else 1.0)
    return ref, att, om


def _drifts(body, q, w):
    from ..attitude.core import matrix_from_unit_quaternion

    I = body.inertia
    M = w @ I.T
    E = 0.5 * np.sum(w * M, axis=-1)
    m = np.einsum("tij,tj->ti", matrix_from_unit_quaternion(q), M)
    e0 = abs(E[0])
    m0 = float(np.linalg.norm(m[0]))
    de = np.abs(E - E[0]) / (e0 if e0 > 0 else 1.0)
    dm = np.linalg.norm(m - m[0], axis=-1) / (m0 if m0 > 0 else 1.0)
    return de, dm


def _intermediate(body, w0):
    """(index of the intermediate axis in the principal frame, principal axes) if the body flips, else None."""
    ev = np.asarray(body.principal_moments, float)
    P = np.asarray(body.principal_axes, float)
    o = np.argsort(ev)
    I1, I2, I3 = ev[o]
    if not (I2 - I1 > 1e-9 * I3 and I3 - I2 > 1e-9 * I3):
        return None
    M = (P.T @ (body.inertia @ w0))[o]
    L2 = float(np.sum(M * M))
    if L2 == 0:
        return None
    Is = np.array([I1, I2, I3])
    d2 = float(np.sum(M**2 * (I2 / Is - 1.0)))
    if d2 > 0:
        m2max = float(np.sum(M**2 * (1.0 - I1 / Is))) * I2 / (I2 - I1)
    elif d2 < 0:
        m2max = float(np.sum(M**2 * (I3 / Is - 1.0))) * I2 / (I3 - I2)
    else:
        m2max = L2
    if min(1.0, m2max / L2) < NEAR_INTERMEDIATE**2:
        return None
    return int(o[1]), P


def _sign_changes(t, y):
    """Times where y changes sign between consecutive nonzero samples, by linear interpolation; and brackets."""
    nz = np.nonzero(y != 0)[0]
    i, j = nz[:-1], nz[1:]
    keep = np.sign(y[i]) != np.sign(y[j])
    i, j = i[keep], j[keep]
    roots = t[i] - y[i] * (t[j] - t[i]) / (y[j] - y[i])
    return roots, i, j


def _bracketed_roots(g, a, b, ga, gb):
    """Roots of ``g`` (vectorized over arrays of times) in brackets [a, b] with g(a) g(b) < 0: Illinois iteration.

    All brackets are refined together, one vectorized evaluation of ``g`` per step; each stops at a zero
    or at a bracket of a few ulps.
    """
    a, b, ga, gb = (np.array(x, dtype=float) for x in (a, b, ga, gb))
    if a.size == 0:
        return a
    xtol = 4 * np.finfo(float).eps * np.maximum(np.maximum(np.abs(a), np.abs(b)), 1.0)
    active = np.ones(a.shape, bool)
    for _ in range(200):
        if not active.any():
            break
        idx = np.nonzero(active)[0]
        A, B, GA, GB = a[idx], b[idx], ga[idx], gb[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            c = B - GB * (B - A) / (GB - GA)
        lo, hi = np.minimum(A, B), np.maximum(A, B)
        bad = ~np.isfinite(c) | (c <= lo) | (c >= hi)
        c = np.where(bad, 0.5 * (A + B), c)
        gc = g(c)
        flip = np.sign(gc) != np.sign(GB)
        a[idx] = np.where(flip, B, A)
        ga[idx] = np.where(flip, GB, 0.5 * GA)
        b[idx], gb[idx] = c, gc
        done = (gc == 0) | (np.abs(b[idx] - a[idx]) <= xtol[idx])
        active[idx[done]] = False
    return b


def _flips(body, t, q, w, ref, axis, P):
    from ..solvers import solve

    comp = P[:, axis]
    y_ref = ref.omega @ comp
    t0 = t[0]

    def f(tt):
        return solve(body, np.asarray(tt) - t0, omega0=w[0], attitude0=q[0], method="exact").omega @ comp

    _, i, j = _sign_changes(t, y_ref)
    i, j = i[:_MAX_FLIPS], j[:_MAX_FLIPS]
    exact = _bracketed_roots(f, t[i], t[j], y_ref[i], y_ref[j])
    # the run's flips: roots of y_ref(t) + e(t), e = y_run - y_ref interpolated linearly between samples
    # (e is small and smooth for any decent run: round-off for an exact one, unlike y_run interpolated)
    y_run = w @ comp
    e = y_run - y_ref
    _, i, j = _sign_changes(t, y_run)
    i, j = i[:_MAX_FLIPS], j[:_MAX_FLIPS]
    run = _bracketed_roots(lambda tt: f(tt) + np.interp(tt, t, e), t[i], t[j], y_run[i], y_run[j])
    errors = [float(run[np.argmin(np.abs(run - tf))] - tf) if run.size else float("nan") for tf in exact]
    return tuple(float(x) for x in exact), tuple(float(x) for x in run), tuple(errors)


def _fitted_inertia(t, q, w):
    """The symmetric tensor (up to scale) whose energy and spatial momentum the run conserves best.

    Returns (tensor as a 6-vector s = (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) of unit norm, residual, next singular
    value, the matrix A) or None.
    """
    from ..attitude.core import matrix_from_unit_quaternion

    n = t.size
    idx = np.unique(np.linspace(0, n - 1, min(n, 2000)).astype(int))
    W = w[idx]
    R = matrix_from_unit_quaternion(q[idx])
    x, y, z = W[:, 0], W[:, 1], W[:, 2]
    zero = np.zeros_like(x)
    B = np.stack(
        [
            np.stack([x, zero, zero, y, z, zero], -1),
            np.stack([zero, y, zero, x, zero, z], -1),
            np.stack([zero, zero, z, zero, x, y], -1),
        ],
        axis=1,
    )  # I W = B s, (N, 3, 6)
    Mspace = np.einsum("nij,njk->nik", R, B)  # m = R B s
    rows_m = (Mspace[1:] - Mspace[0]).reshape(-1, 6)
    Q = np.stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z], -1)  # W.I W = Q s
    rows_e = Q[1:] - Q[0]
    scale = float(np.max(np.sum(W * W, -1)))
    if scale == 0:
        return None
    A = np.concatenate([rows_m, rows_e]) / scale
    if A.shape[0] < 6:
        return None
    A = A / np.sqrt(A.shape[0])  # root-mean-square residuals
    _, sv, vt = np.linalg.svd(A, full_matrices=False)
    return vt[-1], sv[-1], sv[-2], A


def _six(I):
    return np.array([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])


def _inertia_warning(body, t, q, w) -> str | None:
    fit = _fitted_inertia(t, q, w)
    if fit is None:
        return None
    s, res, nxt, A = fit
    g = _six(body.inertia)
    g = g / np.linalg.norm(g)
    res_given = float(np.linalg.norm(A @ g))
    # a unique fit (the run excites every direction of the tensor) that is far better than the given inertia
    if not (nxt > 1e-4 and nxt > 100 * res and res_given > 1e-6 and res_given > 100 * res):
        return None
    s = s * np.sign(s[:3].sum())
    tr_given = float(np.trace(body.inertia))
    s = s * tr_given / s[:3].sum()
    T = np.array([[s[0], s[3], s[4]], [s[3], s[1], s[5]], [s[4], s[5], s[2]]])
    if np.linalg.norm(T - body.inertia) <= 1e-3 * np.linalg.norm(body.inertia):
        return None
    shown = (
        np.round(np.diag(T), 4).tolist()
        if np.allclose(T, np.diag(np.diag(T)), atol=1e-6 * tr_given)
        else np.round(T, 4).tolist()
    )
    return (
        f"the run's energy and angular momentum are conserved as those of an inertia close to {shown} "
        f"(scaled to the trace of the given one), not of the given inertia: check --inertia"
    )


def _hint(stated: Conventions, best: Conventions, label_order: str) -> str:
    parts, flags = [], []
    so = stated.quaternion_order or label_order
    if best.quaternion_order != so:
        if best.quaternion_order == "xyzw":
            parts.append("the quaternions look scalar-last (x, y, z, w)")
        else:
            parts.append("the quaternions look scalar-first (w, x, y, z)")
        flags.append(f"--quaternion-order {best.quaternion_order}")
    if best.omega_frame != stated.omega_frame:
        parts.append(f"the angular velocities look {best.omega_frame}-frame")
        flags.append(f"--omega-frame {best.omega_frame}")
    if best.attitude_convention != stated.attitude_convention:
        parts.append(f"the attitudes look {best.attitude_convention} (the conjugate quaternion)")
        flags.append(f"--attitude-convention {best.attitude_convention}")
    return "; ".join(parts) + ": rerun with " + " ".join(flags)


def _detect(raw: RawRun, body, stated: Conventions, att: np.ndarray):
    """A reading of the run that is far better than the stated one early on, or None.

    ``att`` is the stated reading's error: the larger of the attitude error (rad) and the relative rate
    error (a space-frame rate read as a body rate leaves the attitude right when the body starts at the
    identity; the rate is then wrong).
    """
    n = min(len(raw), _DETECT_SAMPLES)
    bad = np.nonzero(att[:n] > CONVENTION_ERROR)[0]
    if bad.size == 0:
        return None
    t = raw.t
    k = int(bad[0])
    horizon = t[0] + 10.0 * (t[k] - t[0])
    end = int(np.searchsorted(t, horizon, side="right"))
    end = max(min(end, n), k + 1)
    sub = raw.head(end)
    so = stated.quaternion_order or raw.label_order
    best, best_err = None, float("inf")
    for conv in all_conventions(raw):
        if (conv.quaternion_order, conv.omega_frame, conv.attitude_convention) == (
            so,
            stated.omega_frame,
            stated.attitude_convention,
        ):
            continue
        try:
            tt, qq, ww = normalize_run(sub, conv)
            _, a, o = _errors(body, tt, qq, ww)
            a = np.maximum(a, o)
        except InvalidInputError:
            continue
        err = float(np.max(a))
        if err < CONVENTION_ERROR and err < 0.05 * float(np.max(att[:end])) and (best is None or err < best_err * 0.5):
            best, best_err = conv, err
    return best


def compare_run(
    raw: RawRun,
    inertia: ArrayLike | None = None,
    *,
    conventions: Conventions | None = None,
    tolerance: float | None = None,
    detect: bool = True,
) -> ValidationReport:
    """Validate a run against the exact free motion from its first sample.

    Parameters
    ----------
    raw : RawRun
        The run (:func:`~eulerpoisson.oracle.read_run`, :func:`~eulerpoisson.oracle.run_from_arrays`).
    inertia : array_like, shape (3,) or (3, 3), or RigidBody, optional
        The body's inertia in the run's body frame; default: the one the file states.
    conventions : Conventions, optional
        How to read the run (default: as its names say, body-frame rates, body to space).
    tolerance : float, optional
        Attitude tolerance (rad); sets ``verdict`` to ``"pass"`` or ``"fail"``.
    detect : bool
        Look for a likely convention mismatch when the error is large early on.

    Returns
    -------
    ValidationReport

    Raises
    ------
    InvalidInputError
        No inertia, a bad inertia (:class:`~eulerpoisson.InvalidInertiaError`),
        quaternions far from unit norm, a tolerance that is not a positive number.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.oracle import Conventions, compare_run, run_from_arrays
    >>> tr = ep.solve([1.0, 2.0, 2.5], np.linspace(0.0, 10.0, 101), omega0=[1.0, 0.1, 0.5])
    >>> xyzw = tr.quaternion[:, [1, 2, 3, 0]]                          # a run written scalar last
    >>> raw = run_from_arrays(tr.t, xyzw, tr.omega, quaternion_order="xyzw")
    >>> rep = compare_run(raw, [1.0, 2.0, 2.5], conventions=Conventions(quaternion_order="xyzw"), tolerance=1e-9)
    >>> rep.verdict
    'pass'
    """
    from ..model.body import RigidBody

    conv = conventions or Conventions()
    if inertia is None:
        inertia = raw.inertia
    if inertia is None:
        raise InvalidInputError(
            f"{raw.source}: give the inertia (--inertia I1,I2,I3 or nine numbers); the run does not state it"
        )
    body = inertia if isinstance(inertia, RigidBody) else RigidBody(np.asarray(inertia, float))
    if body.batch_shape:
        raise InvalidInputError(f"one body, please: got a batch of shape {body.batch_shape}")
    if tolerance is not None:
        if (
            isinstance(tolerance, bool)
            or not isinstance(tolerance, (int, float, np.integer, np.floating))
            or not (np.isfinite(tolerance) and tolerance > 0)
        ):
            raise InvalidInputError(f"tolerance must be a positive number of radians, got {tolerance!r}")
        tolerance = float(tolerance)
    t, q, w = normalize_run(raw, conv)
    ref, att, om = _errors(body, t, q, w)
    de, dm = _drifts(body, q, w)
    flips = (None, None, None)
    inter = _intermediate(body, w[0])
    if inter is not None:
        flips = _flips(body, t, q, w, ref, *inter)
    warns = []
    best = _detect(raw, body, conv, np.maximum(att, om)) if detect else None
    hint = _hint(conv, best, raw.label_order) if best is not None else None
    if hint is None:
        wi = _inertia_warning(body, t, q, w)
        if wi:
            warns.append(wi)
    if flips[0] is not None and flips[1] is not None and len(flips[0]) != len(flips[1]):
        warns.append(f"the run flips {len(flips[1])} time(s), the exact motion {len(flips[0])} time(s)")
    k = int(np.argmax(att))
    mx = float(att[k])
    exceeded = None
    if tolerance is not None:
        over = np.nonzero(att > tolerance)[0]
        exceeded = float(t[over[0]]) if over.size else None
        verdict = "fail" if (over.size or hint) else "pass"
        if over.size:
            msg = (
                f"the attitude error first exceeds {tolerance:g} rad at t = {exceeded:.6g} (max {mx:.3g} rad at "
                f"t = {t[k]:.6g})"
            )
        else:
            msg = f"the attitude error stays within {tolerance:g} rad (max {mx:.3g} rad)"
            if hint:
                msg += f" but the angular velocity is off by up to {float(np.max(om)):.3g} (relative)"
    elif mx <= ROUNDOFF and not hint:
        verdict, msg = "round-off", f"the run is the exact motion to round-off (max attitude error {mx:.3g} rad)"
    else:
        verdict, msg = (
            "differs",
            (
                f"the run differs from the exact motion by up to {mx:.3g} rad at t = {t[k]:.6g} "
                f"(angular velocity: {float(np.max(om)):.3g} relative)"
            ),
        )
    if hint:
        msg += f"; {hint}"
    order = conv.quaternion_order or raw.label_order
    I = body.inertia
    inertia_out = np.diag(I).tolist() if np.all(I == np.diag(np.diag(I))) else I.tolist()
    return ValidationReport(
        source=raw.source,
        samples=int(t.size),
        t_start=float(t[0]),
        t_end=float(t[-1]),
        inertia=inertia_out,
        conventions=Conventions(
            order if order in QUATERNION_ORDERS else None, conv.omega_frame, conv.attitude_convention
        ),
        max_attitude_error=mx,
        max_attitude_error_time=float(t[k]),
        max_omega_error=float(np.max(om)),
        energy_drift=float(np.max(de)),
        momentum_drift=float(np.max(dm)),
        flip_times=flips[0],
        flip_times_run=flips[1],
        flip_time_errors=flips[2],
        tolerance=tolerance,
        exceeded_at=exceeded,
        verdict=verdict,
        message=msg,
        convention_hint=hint,
        suggested_conventions=best,
        warnings=tuple(warns),
        t=t,
        attitude_error=att,
        omega_error=om,
        energy_error=de,
        momentum_error=dm,
    )
