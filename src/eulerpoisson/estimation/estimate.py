r"""``ep.fit``: the torque-free body behind observations of its rotation.

The search
    Every start (:mod:`~eulerpoisson.estimation.starts`) is carried through a
    continuation in time: Levenberg–Marquardt (:mod:`~eulerpoisson.estimation.lm`)
    first on the earliest observations, where a wrong inertia has not yet
    moved the motion far, then on windows twice as long, up to all of them.
    The starts race: after each window, those whose :math:`\chi^2` is more
    than 100 times the best are dropped, and those that reached the same
    state are merged.

Equivalent optima
    Evenly spaced samples alias: a motion turning one more time between
    samples (about an axis that barely moves, e.g. a nearly spherical body)
    can fit as well as the slow one. Among optima within
    :math:`\Delta\chi^2 < 1` of the best, the slowest (smallest
    :math:`|\boldsymbol\Omega_0|`) is reported, and the summary says how
    many fit equally well.
    The distinct optima are kept with their :math:`\chi^2`; the best is the
    answer. With ``principal_axes="fit"`` a diagonal fit comes first and seeds
    the full one.

Weights
    Each residual is divided by its standard deviation. A kind whose standard
    deviation is not given gets one estimated from its residuals at the
    optimum, :math:`\hat\sigma^2 = \sum r^2 / (n(1 - p/N))` (``n`` residuals of
    that kind out of ``N``, ``p`` unknowns): from a first search with unit
    sigmas, then again at the optimum of the search proper until it settles.

Poor fits
    A fit whose reduced :math:`\chi^2` exceeds :data:`POOR_FIT_CHI2` (100)
    is refused (:class:`~eulerpoisson.errors.PoorFitError`) unless
    ``accept_poor_fit=True``. When the fit is poor (reduced :math:`\chi^2`
    above 10, or an estimated sigma large against the data: above about a
    degree, or 2% of the rates), the other readings of the same numbers are
    tried, each from one start with a short search: scalar-last quaternions,
    their conjugates (space to body), the rates in the other frame, the rates
    in degrees. One whose :math:`\chi^2` with the same sigmas is 100 times
    smaller, in all or in one kind of observation, makes the fit poor too,
    and ``convention_hint`` names it with the flag of the command line.
    Rates alone in degrees are not told apart (a nearly spherical body fits
    them).

Uncertainties
    :math:`C = (J^\mathsf TJ)^{-1}` of the whitened Jacobian at the optimum, the
    Cramér–Rao bound of Gaussian errors, calibrated in the tests on data from
    an independent integrator. The attitude's three entries are a body-frame
    rotation (radians) about the fitted attitude.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InvalidInputError, PoorFitError
from ..numerics.quaternion import CONJUGATE, qmul
from .data import POOR_FIT_CHI2, FitInputError, observation_set, quaternion_array, reading_hint
from .lm import LMOutcome, levenberg_marquardt
from .residuals import FitState, Layout, evaluate, inertia_matrix, inertia_valid, log_quaternion
from .result import FitResult, LocalOptimum
from .starts import params_of
from .starts import starts as make_starts

if TYPE_CHECKING:
    from ..attitude.core import AttitudeLike
    from ..model.body import RigidBody

__all__ = ["fit", "POOR_FIT_CHI2"]

PRINCIPAL_AXES = ("given", "fit")


def _fixed_inertia(inertia):
    from ..model.body import RigidBody

    body = RigidBody(inertia) if not hasattr(inertia, "inertia") else inertia
    I = np.asarray(body.inertia, dtype=float)
    if I.shape != (3, 3):
        raise FitInputError(f"inertia must describe one body (3 moments or a 3x3 tensor); got shape {I.shape}")
    return I / np.trace(I)


def _windows(obs, n_params):
    rows = np.unique(np.concatenate([obs.att_idx, obs.om_idx, obs.ax_idx]))
    per_row = max(1, obs.n_residuals // max(len(rows), 1))
    first = max(int(np.ceil(2.5 * n_params / per_row)) + 2, 6)
    ends = []
    n = first
    while n < len(rows):
        ends.append(obs.t[rows[n - 1]])
        n *= 2
    ends.append(obs.t[rows[-1]])
    return ends


#: standard deviation of the prior that holds the inertia near its start on the short windows
PRIOR_SIGMA = 0.03


def _same(a: LocalOptimum, b: LocalOptimum) -> bool:
    if abs(a.chi2 - b.chi2) > 1e-6 * (1.0 + min(a.chi2, b.chi2)):
        return False
    ang = np.linalg.norm(log_quaternion(qmul(a.q0 * CONJUGATE, b.q0)))
    scale = 1.0 + np.linalg.norm(a.omega0)
    return bool(
        np.abs(a.inertia - b.inertia).max() < 1e-4 and np.abs(a.omega0 - b.omega0).max() < 1e-4 * scale and ang < 1e-4
    )


#: after each window but the last, a start is dropped when its chi2 exceeds RACE_FACTOR times the best one's
#: (relative, so that the units of the sigmas do not matter; a fit to noise cannot beat the truth by 100x)
RACE_FACTOR = 100.0

#: optima within this chi2 of the best (at least; 1e-9 relative) fit the data equally well
EQUIVALENT_CHI2 = 1.0


def _close(a, b, tol=1e-3) -> bool:
    """Two states of the search that have reached the same place (to merge them)."""
    ang = np.linalg.norm(log_quaternion(qmul(a.q0 * CONJUGATE, b.q0)))
    scale = 1.0 + np.linalg.norm(a.omega0)
    dp = np.abs(a.inertia_params - b.inertia_params).max() if len(a.inertia_params) else 0.0
    return bool(ang < tol and np.abs(a.omega0 - b.omega0).max() < tol * scale and dp < tol)


def _race(layout, obs, starts, ends, max_iter):
    """Carry all starts through the windows together, dropping the clearly worse and merging the equal."""
    live = [(s, (s.inertia_params.copy(), PRIOR_SIGMA)) for s in starts]
    results: list[tuple[LMOutcome, tuple]] = []
    for j, t_end in enumerate(ends):
        final = j == len(ends) - 1
        sub = obs if final else obs.window(t_end)
        results = []
        for state, prior in live:
            try:
                out = levenberg_marquardt(
                    layout,
                    sub,
                    state,
                    max_iter=max_iter if final else 40,
                    rtol=1e-12 if final else 1e-6,
                    prior=None if final else prior,
                )
            except FloatingPointError:
                continue
            results.append((out, prior))
        if final or not results:
            break
        best = min(o.evaluation.chi2 for o, _ in results)
        keep = RACE_FACTOR * max(best, 1e-300)
        merged: list[tuple[LMOutcome, tuple]] = []
        for o, p in sorted(results, key=lambda r: r[0].evaluation.chi2):
            if o.evaluation.chi2 <= keep and not any(_close(o.state, m[0].state) for m in merged):
                merged.append((o, p))
        live = [(o.state, p) for o, p in merged]
    return [o for o, _ in results]


def _search(layout, obs, starts, max_iter=200, direct=False):
    ends = _windows(obs, layout.n_params)
    outs = _race(layout, obs, starts, ends, max_iter)
    if direct:
        # starts the caller trusts: also straight to all the data
        outs += _race(layout, obs, starts, ends[-1:], max_iter)
    found: list[tuple] = []
    for out in sorted(outs, key=lambda o: o.evaluation.chi2):
        I, _ = inertia_matrix(layout, out.state.inertia_params)
        opt = LocalOptimum(out.evaluation.chi2, I, out.state.q0, out.state.omega0, out.converged)
        if not any(_same(opt, f[0]) for f in found):
            found.append((opt, out))
    return found


#: an estimated sigma is at least this fraction of the observations' own scale (a perfect fit has none)
SIGMA_FLOOR = 1e-12


def _sigma_scales(layout, obs, ev):
    """Per kind, the factor that makes the whitened residuals of that kind unit variance."""
    n_total = len(ev.residuals)
    frac = max(1.0 - layout.n_params / n_total, 1e-3)
    scales = {}
    start = 0
    kinds = (
        ("attitude", 3 * len(obs.att_idx), obs.att_sigma, 1.0),
        (
            "omega",
            3 * len(obs.om_idx),
            obs.om_sigma,
            float(np.median(np.linalg.norm(obs.om_value, axis=1))) if len(obs.om_idx) else 1.0,
        ),
        ("axis", 2 * len(obs.ax_idx), obs.ax_sigma, 1.0),
    )
    for kind, n, sig, ref in kinds:
        if n:
            r = ev.residuals[start : start + n]
            if not obs.sigma_given.get(kind, False):
                current = float(np.median(sig))
                floor = SIGMA_FLOOR * (ref if ref > 0 else 1.0) / current
                scales[kind] = max(float(np.sqrt(r @ r / (n * frac))), floor)
            start += n
    return scales


def fit(
    t: ArrayLike,
    *,
    attitude: AttitudeLike | None = None,
    attitude_sigma: ArrayLike | None = None,
    omega: ArrayLike | None = None,
    omega_sigma: ArrayLike | None = None,
    omega_frame: str = "body",
    axis: ArrayLike | None = None,
    axis_direction: ArrayLike | None = None,
    axis_sigma: ArrayLike | None = None,
    inertia: RigidBody | ArrayLike | None = None,
    principal_axes: str = "given",
    initial: Mapping[str, ArrayLike] | None = None,
    max_iter: int = 200,
    accept_poor_fit: bool = False,
) -> FitResult:
    r"""Fit a torque-free rigid body to observations of its rotation: inertia ratios and the initial state.

    Parameters
    ----------
    t : array_like, shape (N,)
        Observation times, strictly increasing; the epoch of the fitted
        state is ``t[0]``.
    attitude : array_like, shape (N, 4), Attitude or scipy Rotation, optional
        Observed attitudes, unit quaternions (w, x, y, z) body to space;
        rows of NaN are missing.
    attitude_sigma : float or array_like, shape (N,), optional
        Standard deviation (radians) of the attitude error about each axis.
        Not given: estimated from the residuals.
    omega : array_like, shape (N, 3), optional
        Observed angular velocity (NaN rows missing), in the frame ``omega_frame``.
    omega_sigma : float or array_like, shape (N,), (3,) or (N, 3), optional
        Its standard deviation. Not given: estimated from the residuals.
    omega_frame : {"body", "space"}
        Frame of ``omega``.
    axis : array_like, shape (3,), optional
        A body axis whose space direction is observed in ``axis_direction``.
    axis_direction : array_like, shape (N, 3), optional
        Observed unit directions of ``axis`` in space (NaN rows missing).
    axis_sigma : float or array_like, shape (N,), optional
        Standard deviation (radians) of the direction across it, in each of
        two directions. Not given: estimated from the residuals.
    inertia : array_like or RigidBody, optional
        Fix the inertia (moments or a tensor, in the observations' body
        frame; only its ratios matter): then only the state is fitted.
    principal_axes : {"given", "fit"}
        ``"given"``: the inertia is diagonal in the observations' body frame
        (two unknowns); ``"fit"``: a full tensor (five unknowns), whose
        principal axes are reported.
    initial : dict, optional
        An extra start: ``inertia`` (3x3 or 3 moments), ``omega0``,
        ``attitude0`` (a quaternion); with it, only this start is used.
    max_iter : int
        Levenberg–Marquardt iterations of the final stage, 1 or more.
    accept_poor_fit : bool
        Return a poor fit (``result.poor_fit``, with ``result.convention_hint``)
        instead of raising :class:`~eulerpoisson.errors.PoorFitError`.

    Returns
    -------
    FitResult

    Raises
    ------
    FitInputError
        Bad observations (unsorted or duplicate times, wrong shapes, non-unit
        quaternions, a wrong frame...), an unknown ``principal_axes``, fewer
        residuals than unknowns, or no start that could be carried to an
        optimum.
    PoorFitError
        A poor fit (a :class:`FitInputError`): the reduced chi2 is above
        :data:`POOR_FIT_CHI2` (100), or another reading of the same numbers
        fits far better (see the module notes); the message names it, and
        ``err.result`` holds the fit. Not with ``accept_poor_fit=True``.
    TypeError
        Non-numeric input.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> body = ep.RigidBody([0.25, 0.33, 0.42])
    >>> t = np.linspace(0.0, 20.0, 81)
    >>> tr = ep.solve(body, t, omega0=[0.1, 0.2, 1.0])
    >>> res = ep.fit(t, attitude=tr.quaternion, attitude_sigma=1e-3, omega=tr.omega, omega_sigma=1e-3)
    >>> np.round(np.diag(res.inertia), 6)
    array([0.25, 0.33, 0.42])

    Space-frame rates given as body rates: refused, naming the reading that fits.

    >>> w_space = np.einsum("kab,kb->ka", tr.matrix, tr.omega)                # space-frame rates
    >>> try:
    ...     ep.fit(t, attitude=tr.quaternion, attitude_sigma=1e-3, omega=w_space, omega_sigma=1e-3)
    ... except ep.estimation.PoorFitError as err:
    ...     print(err)
    poor fit: the angular velocities look space-frame: read so, the data fit far better (...); pass omega_frame='space' (command line: --omega-frame space); or pass accept_poor_fit=True to keep this fit

    References
    ----------
    D. W. Marquardt, J. SIAM 11 (1963) 431-441 (the search). Kaasalainen,
    A&A 376 (2001) 302 (spin states of tumbling asteroids).
    """
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)):
        raise TypeError(f"max_iter must be a positive integer (1 or more), got {type(max_iter).__name__} {max_iter!r}")
    if max_iter < 1:
        raise FitInputError(
            f"max_iter must be a positive integer (1 or more Levenberg-Marquardt iterations), got {max_iter}"
        )
    max_iter = int(max_iter)
    if not isinstance(accept_poor_fit, (bool, np.bool_)):
        raise TypeError(f"accept_poor_fit must be True or False, got {type(accept_poor_fit).__name__}")
    obs = observation_set(
        t,
        attitude=attitude,
        attitude_sigma=attitude_sigma,
        omega=omega,
        omega_sigma=omega_sigma,
        omega_frame=omega_frame,
        axis=axis,
        axis_direction=axis_direction,
        axis_sigma=axis_sigma,
    )
    if principal_axes not in PRINCIPAL_AXES:
        raise FitInputError(f"principal_axes must be 'given' or 'fit'; got {principal_axes!r}")
    if inertia is not None:
        layout = Layout(obs.attitude_observed, "fixed", _fixed_inertia(inertia))
    else:
        layout = Layout(obs.attitude_observed, principal_axes)
    if obs.n_residuals <= layout.n_params:
        raise FitInputError(
            f"too few observations: {obs.n_residuals} residuals for {layout.n_params} unknowns "
            f"({', '.join(layout.names)}); give more observations or fix the inertia"
        )
    estimated = {}
    if not all(obs.sigma_given.get(k, False) for k in obs.kinds):
        # kinds without sigma: a first search with unit sigmas gives their scale, so that the search proper
        # (its race and its prior on short windows) sees residuals of about one per observation
        pre_layout = Layout(layout.fit_attitude, "given") if layout.inertia_mode == "fit" else layout
        pre_starts = [_initial_state(initial, pre_layout, obs)] if initial is not None else make_starts(obs, pre_layout)
        pre = _search(pre_layout, obs, pre_starts, max_iter, direct=initial is not None)
        if pre:
            scales = _sigma_scales(pre_layout, obs, pre[0][1].evaluation)
            obs = obs.with_sigmas(scales)
            estimated = dict(scales)
    if initial is not None:
        start_list = [_initial_state(initial, layout, obs)]
    elif layout.inertia_mode == "fit":
        diag = Layout(layout.fit_attitude, "given")
        first = _search(diag, obs, make_starts(obs, diag))
        seeds = [inertia_matrix(diag, f[1].state.inertia_params)[0] for f in first[:3]]
        start_list = make_starts(obs, layout, extra_inertias=seeds)
    else:
        start_list = make_starts(obs, layout)
    found = _search(layout, obs, start_list, max_iter, direct=initial is not None)
    if not found:
        raise FitInputError("no start could be carried to an optimum (the motion could not be integrated)")
    for _ in range(3):
        scales = _sigma_scales(layout, obs, found[0][1].evaluation)
        if not scales or all(abs(s - 1.0) < 1e-3 for s in scales.values()):
            break
        obs = obs.with_sigmas(scales)
        for k, s in scales.items():
            estimated[k] = estimated.get(k, 1.0) * s
        refined = []
        best_chi2 = found[0][0].chi2
        for opt, out in found:
            if opt.chi2 <= RACE_FACTOR * max(best_chi2, 1e-300):
                again = levenberg_marquardt(layout, obs, out.state, max_iter=max_iter)
            else:  # far worse: re-weighed, not refitted
                again = LMOutcome(out.state, evaluate(layout, obs, out.state), 0, out.converged)
            I, _ = inertia_matrix(layout, again.state.inertia_params)
            refined.append(
                (LocalOptimum(again.evaluation.chi2, I, again.state.q0, again.state.omega0, again.converged), again)
            )
        found = sorted(refined, key=lambda f: f[0].chi2)
    found, n_equivalent = _prefer_slowest(found)
    best = found[0][1]
    final = evaluate(layout, obs, best.state)
    dof = len(final.residuals) - layout.n_params
    reduced = float(final.chi2 / dof) if dof > 0 else float("nan")
    reading = None
    if _suspect(obs, reduced, estimated):
        reading = _better_reading(layout, obs, best.state, final)
    hint = None if reading is None else reading_hint(reading[0], reduced, reading[1], detail=reading[2])
    poor = bool(reduced > POOR_FIT_CHI2 or reading is not None)
    res = FitResult.from_search(
        layout,
        obs,
        best,
        final,
        [f[0] for f in found],
        estimated,
        len(start_list),
        n_equivalent,
        diagnosis={
            "poor_fit": poor,
            "convention_hint": hint,
            "better_reading": None if reading is None else reading[0],
            "_better_reading_fit": None if reading is None else reading[1:],
        },
    )
    if poor and not accept_poor_fit:
        if hint:
            why = hint
        else:
            why = f"reduced chi2 = {reduced:.4g} > {POOR_FIT_CHI2:g}: check the data's conventions and sigmas"
        raise PoorFitError(f"poor fit: {why}; or pass accept_poor_fit=True to keep this fit", res)
    return res


#: the other readings of the data are tried when the reduced chi2 exceeds this...
TRY_READINGS_CHI2 = 10.0
#: ... or an estimated sigma is large: an angle's above this (radians, about 1 degree), a rate's above this
#: fraction of the median observed rate (a wrong reading leaves residuals of the size of the signal)
LARGE_ANGLE_SIGMA = 0.02
LARGE_RATE_SIGMA = 0.02
#: another reading fits far better when its chi2, with the same sigmas, is below this fraction of the fit's
#: (residuals ten times smaller)
FAR_BETTER = 0.01
#: Levenberg-Marquardt iterations of the short fit of another reading
READING_ITER = 30


def _suspect(obs, reduced, estimated) -> bool:
    """Whether the fit is poor enough to try the other readings of the data."""
    if reduced > TRY_READINGS_CHI2:
        return True
    scale = {"attitude": obs.att_sigma, "axis": obs.ax_sigma, "omega": obs.om_sigma}
    for kind in estimated:
        sig = float(np.median(scale[kind]))
        if kind == "omega":
            ref = float(np.median(np.linalg.norm(obs.om_value, axis=1)))
            if ref > 0 and sig > LARGE_RATE_SIGMA * ref:
                return True
        elif sig > LARGE_ANGLE_SIGMA:
            return True
    return False


def _kind_chi2(obs, residuals) -> dict:
    """The chi2 of each kind of observation (the whitened residuals are attitude, omega, axis in this order)."""
    out, start = {}, 0
    for kind, n in (("attitude", 3 * len(obs.att_idx)), ("omega", 3 * len(obs.om_idx)), ("axis", 2 * len(obs.ax_idx))):
        if n:
            r = residuals[start : start + n]
            out[kind] = float(r @ r)
            start += n
    return out


#: the kinds of observation as the hints name them
KIND_NAMES = {"attitude": "attitude", "omega": "angular-velocity", "axis": "axis-direction"}


def _better_reading(layout, obs, state, final):
    """The reading of the data that fits far better than ``final``: (reading, reduced chi2, detail) or None.

    Each reading gets one start (the inertia from the data, the rate and attitude guessed from them, else
    the fit's) and a short search; the sigmas are those of the fit, so that the chi2 compare. Far better:
    the chi2 falls below :data:`FAR_BETTER` of the fit's, in all or in one kind of observation while no
    other kind gets more than twice worse (a sigma estimated from a wrong reading can hide one kind).
    """
    from .starts import attitude_guesses, inertia_from_data, omega_guess

    before = _kind_chi2(obs, final.residuals)
    best = None
    for reading in obs.readings():
        other = obs.reread(reading)
        lay = Layout(other.attitude_observed, layout.inertia_mode, layout.fixed_inertia)
        if lay.inertia_mode == "fixed":
            I, p = layout.fixed_inertia, np.zeros(0)
        else:
            I = inertia_from_data(other, lay.inertia_mode)
            if I is None:
                I = inertia_matrix(layout, state.inertia_params)[0]
            p = params_of(lay.inertia_mode, I)
        w = omega_guess(other, other.att_q[0] if len(other.att_idx) else None)
        if w is None:
            w = state.omega0
        first = [FitState(q, np.array(w, dtype=float), p) for q in attitude_guesses(other, lay, I, w)]
        outs = _race(lay, other, first, _windows(other, lay.n_params), READING_ITER)
        outs = [o for o in outs if np.isfinite(o.evaluation.chi2)]
        if not outs:
            continue
        out = min(outs, key=lambda o: o.evaluation.chi2)
        after = _kind_chi2(other, out.evaluation.residuals)
        gain = {k: before[k] / max(after[k], 1e-300) for k in before}
        total = sum(before.values()) / max(out.evaluation.chi2, 1e-300)
        kind = max(gain, key=lambda k: gain[k])
        far = total > 1.0 / FAR_BETTER or (gain[kind] > 1.0 / FAR_BETTER and min(gain.values()) > 0.5)
        if far and (best is None or total > best[0]):
            dof = len(out.evaluation.residuals) - lay.n_params
            detail = f"{KIND_NAMES[kind]} residuals {np.sqrt(gain[kind]):.3g} times smaller"
            best = (total, reading, out.evaluation.chi2 / dof if dof > 0 else float("nan"), detail)
    return None if best is None else best[1:]


def _prefer_slowest(found):
    """Put first, among the optima that fit as well as the best, the one with the slowest rate."""
    best = found[0][0].chi2
    limit = best + max(EQUIVALENT_CHI2, 1e-9 * best)
    eq = [f for f in found if f[0].chi2 <= limit]
    slow = min(eq, key=lambda f: float(np.linalg.norm(f[0].omega0)))
    rest = [f for f in found if f is not slow]
    return [slow] + rest, len(eq)


def _initial_state(initial, layout, obs):
    from ..attitude.core import as_quaternion

    if not isinstance(initial, dict):
        raise TypeError(f"initial must be a dict with inertia, omega0 and attitude0; got {type(initial).__name__}")
    unknown = set(initial) - {"inertia", "omega0", "attitude0"}
    if unknown:
        raise FitInputError(f"initial has unknown keys {sorted(unknown)}; expected inertia, omega0, attitude0")
    I = initial.get("inertia")
    if layout.inertia_mode == "fixed":
        if I is not None:
            raise FitInputError("initial has an inertia, but inertia= fixes it: give one or the other")
        p = np.zeros(0)
    else:
        if I is None:
            raise FitInputError("initial needs 'inertia' when the inertia is fitted")
        I = np.asarray(I, dtype=float)
        I = np.diag(I) if I.shape == (3,) else I
        if I.shape != (3, 3) or not inertia_valid(I / np.trace(I)):
            raise FitInputError(f"initial inertia must be a physical 3x3 tensor or 3 moments; got {I.tolist()}")
        p = params_of(layout.inertia_mode, I)
    w = initial.get("omega0")
    if w is None:
        raise FitInputError("initial needs 'omega0'")
    w = np.asarray(w, dtype=float)
    if w.shape != (3,) or not np.all(np.isfinite(w)):
        raise FitInputError(f"initial omega0 must be 3 finite numbers; got {w.tolist()}")
    q = initial.get("attitude0", [1.0, 0.0, 0.0, 0.0])
    try:
        q = as_quaternion(quaternion_array(q), "initial attitude0")
    except InvalidInputError as exc:
        raise FitInputError(str(exc)) from None
    if q.shape != (4,):
        raise FitInputError(f"initial attitude0 must be one attitude (4 quaternion components); got shape {q.shape}")
    return FitState(q / np.linalg.norm(q), w, p)
