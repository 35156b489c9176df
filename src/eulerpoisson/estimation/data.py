r"""Observations of a tumbling body, checked and arranged for the fit.

Three kinds of observation, each at any subset of the times ``t`` (a row of
NaN is a missing observation):

``attitude``
    Unit quaternions (w, x, y, z), body to space, or anything
    :class:`~eulerpoisson.Attitude` accepts (an ``Attitude``, a scipy
    ``Rotation``). Standard deviation ``attitude_sigma`` (radians) of the
    small rotation error about each axis: scalar or per time.
``omega``
    Angular velocity in the body frame (``omega_frame="body"``, the default)
    or in space (``"space"``). ``omega_sigma``: scalar, per time ``(N,)`` or
    per component ``(N, 3)`` (or ``(3,)``).
``axis_direction``
    The space direction (unit vector) of the body axis ``axis``, e.g. a spin
    axis or the line of sight of an instrument. ``axis_sigma`` (radians):
    scalar or per time, the error of the direction in each of the two
    directions across it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..attitude.core import Attitude, quaternion_from_scipy
from ..errors import FitInputError, InvalidInputError
from ..util.validate import as_float_array

__all__ = [
    "ObservationSet",
    "observation_set",
    "quaternion_array",
    "FitInputError",
    "READINGS",
    "reading_hint",
    "POOR_FIT_CHI2",
]

#: norm tolerance of observed unit quaternions and directions (as everywhere in the package)
UNIT_TOL = 1e-6

#: other readings of the same numbers (:meth:`ObservationSet.reread`): scalar-last quaternions, their conjugates
#: (space to body), the rates in the other frame, the rates in degrees per unit of t
READINGS = ("xyzw", "conjugate", "space", "body", "deg")


@dataclass(frozen=True)
class ObservationSet:
    """The observations, validated: rows of each kind where it is present.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Strictly increasing times.
    att_idx, att_q, att_sigma : ndarray
        Indices into ``t``, unit quaternions (Na, 4), sigma (Na,).
    om_idx, om_value, om_sigma : ndarray
        Indices, angular velocities (No, 3), sigmas (No, 3).
    omega_frame : str
    ax_idx, ax_dir, ax_sigma : ndarray
        Indices, unit directions (Nx, 3), sigmas (Nx,).
    axis : ndarray or None, shape (3,)
        The body axis (unit).
    sigma_given : dict
        For each kind present, whether its standard deviation was given
        (otherwise it is estimated from the residuals).
    """

    t: np.ndarray
    att_idx: np.ndarray
    att_q: np.ndarray
    att_sigma: np.ndarray
    om_idx: np.ndarray
    om_value: np.ndarray
    om_sigma: np.ndarray
    omega_frame: str
    ax_idx: np.ndarray
    ax_dir: np.ndarray
    ax_sigma: np.ndarray
    axis: np.ndarray | None
    sigma_given: dict

    @property
    def n_residuals(self) -> int:
        """Number of scalar residuals: 3 per attitude, 3 per rate, 2 per direction."""
        return 3 * len(self.att_idx) + 3 * len(self.om_idx) + 2 * len(self.ax_idx)

    @property
    def kinds(self) -> tuple[str, ...]:
        """The kinds present, among ``attitude``, ``omega``, ``axis``."""
        out = []
        if len(self.att_idx):
            out.append("attitude")
        if len(self.om_idx):
            out.append("omega")
        if len(self.ax_idx):
            out.append("axis")
        return tuple(out)

    @property
    def attitude_observed(self) -> bool:
        """Whether the data constrain the attitude at all (else it is not fitted)."""
        return bool(len(self.att_idx) or len(self.ax_idx) or (len(self.om_idx) and self.omega_frame == "space"))

    def with_sigmas(self, scale: dict) -> ObservationSet:
        """A copy with each kind's sigmas multiplied by ``scale[kind]``."""
        from dataclasses import replace

        return replace(
            self,
            att_sigma=self.att_sigma * scale.get("attitude", 1.0),
            om_sigma=self.om_sigma * scale.get("omega", 1.0),
            ax_sigma=self.ax_sigma * scale.get("axis", 1.0),
        )

    def readings(self) -> tuple[str, ...]:
        """The other readings of these numbers that :meth:`reread` gives, among :data:`READINGS`."""
        out = []
        if len(self.att_idx):
            out += ["xyzw", "conjugate"]
        if len(self.om_idx):
            out += ["space" if self.omega_frame == "body" else "body", "deg"]
        return tuple(out)

    def reread(self, reading: str) -> ObservationSet:
        """The same numbers read another way (sigmas follow their observations).

        ``"xyzw"``: the quaternions were scalar last (x, y, z, w);
        ``"conjugate"``: they were the inverse rotations (space to body);
        ``"space"``/``"body"``: the rates were in that frame; ``"deg"``: the
        rates (and their sigmas) were in degrees per unit of ``t``.
        """
        from dataclasses import replace

        if reading not in self.readings():
            raise FitInputError(f"reading must be one of {', '.join(self.readings())}; got {reading!r}")
        if reading == "xyzw":
            return replace(self, att_q=self.att_q[:, [3, 0, 1, 2]])
        if reading == "conjugate":
            return replace(self, att_q=self.att_q * np.array([1.0, -1.0, -1.0, -1.0]))
        if reading == "deg":
            k = np.pi / 180.0
            return replace(self, om_value=self.om_value * k, om_sigma=self.om_sigma * k)
        return replace(self, omega_frame=reading)

    def window(self, t_end: float) -> ObservationSet:
        """The observations at times up to ``t_end`` (the times array itself is kept)."""
        from dataclasses import replace

        a = self.t[self.att_idx] <= t_end
        o = self.t[self.om_idx] <= t_end
        x = self.t[self.ax_idx] <= t_end
        return replace(
            self,
            att_idx=self.att_idx[a],
            att_q=self.att_q[a],
            att_sigma=self.att_sigma[a],
            om_idx=self.om_idx[o],
            om_value=self.om_value[o],
            om_sigma=self.om_sigma[o],
            ax_idx=self.ax_idx[x],
            ax_dir=self.ax_dir[x],
            ax_sigma=self.ax_sigma[x],
        )


def _array(x, name, tail=(), **kw) -> np.ndarray:
    """:func:`as_float_array`, its InvalidInputError raised as FitInputError."""
    try:
        return as_float_array(x, name, tail, **kw)
    except FitInputError:
        raise
    except InvalidInputError as exc:
        raise FitInputError(str(exc)) from None


def _times(t) -> np.ndarray:
    t = _array(t, "t")
    if t.ndim != 1:
        raise FitInputError(f"t must be a 1-D array of observation times, shape (N,); got shape {t.shape}")
    if t.size < 2:
        raise FitInputError(f"t must hold at least 2 observation times; got {t.size}")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.flatnonzero(d <= 0)[0])
        what = "duplicate" if d[i] == 0 else "unsorted"
        raise FitInputError(
            f"t must be strictly increasing: {what} times at rows {i} and {i + 1} "
            f"(t = {t[i]!r}, {t[i + 1]!r}); sort the observations and merge duplicates"
        )
    return t


def _rows(x, name, n, width) -> np.ndarray:
    a = _array(x, name, allow_nonfinite=True)
    if a.shape != (n, width):
        raise FitInputError(f"{name} must have shape ({n}, {width}) (one row per time in t); got shape {a.shape}")
    if np.any(np.isinf(a)):
        raise FitInputError(f"{name} contains infinite values (use NaN for a missing observation)")
    part = np.isnan(a).any(axis=1) & ~np.isnan(a).all(axis=1)
    if np.any(part):
        i = int(np.flatnonzero(part)[0])
        raise FitInputError(
            f"{name} row {i} is partly NaN ({a[i].tolist()}): a missing observation is a whole row of NaN"
        )
    return a


def quaternion_array(attitude):
    """Quaternions (w, x, y, z) of an :class:`~eulerpoisson.Attitude`, a scipy ``Rotation`` or an array (unchecked)."""
    if isinstance(attitude, Attitude):
        return attitude.as_quaternion()
    if type(attitude).__module__.startswith("scipy.spatial.transform"):
        return quaternion_from_scipy(attitude)
    return attitude


def _unit_rows(a, name, what) -> np.ndarray:
    """Rows of ``a`` normalized; NaN rows kept; a present row off unit norm by more than UNIT_TOL is an error."""
    ok = ~np.isnan(a[:, 0])
    nrm = np.linalg.norm(a[ok], axis=1)
    bad = np.flatnonzero(np.abs(nrm - 1.0) > UNIT_TOL)
    if bad.size:
        i = int(np.flatnonzero(ok)[bad[0]])
        raise FitInputError(f"{name} row {i} is not a {what} (norm {nrm[bad[0]]!r}; expected 1 within {UNIT_TOL:g})")
    a = a.copy()
    a[ok] /= nrm[:, None]
    return a


def _quaternions(attitude, n) -> np.ndarray:
    return _unit_rows(_rows(quaternion_array(attitude), "attitude", n, 4), "attitude", "unit quaternion")


def _sigma(sig, name, n, width, present) -> tuple[np.ndarray, bool]:
    """Sigmas broadcast to (n, width); True when given."""
    if sig is None:
        return np.ones((n, width)), False
    s = _array(sig, name, allow_nonfinite=True)
    if s.ndim == 0:
        s = np.full((n, width), float(s))
    elif s.shape == (n,):
        s = np.repeat(s[:, None], width, axis=1)
    elif width > 1 and s.shape == (width,):
        s = np.broadcast_to(s, (n, width)).copy()
    elif width > 1 and s.shape == (n, width):
        s = s.copy()
    else:
        shapes = f"a scalar or shape ({n},)" + (f", ({width},) or ({n}, {width})" if width > 1 else "")
        raise FitInputError(f"{name} must be {shapes}; got shape {s.shape}")
    used = s[present]
    if not np.all(np.isfinite(used)) or np.any(used <= 0):
        bad = ~(np.isfinite(used) & (used > 0))
        i = int(np.flatnonzero(present)[np.flatnonzero(bad.any(axis=1))[0]])
        raise FitInputError(
            f"{name} must be positive and finite where there is an observation; row {i} has {s[i].tolist()}"
        )
    return s, True


def observation_set(
    t,
    *,
    attitude=None,
    attitude_sigma=None,
    omega=None,
    omega_sigma=None,
    omega_frame="body",
    axis=None,
    axis_direction=None,
    axis_sigma=None,
) -> ObservationSet:
    """Check and arrange observations (see the module docstring).

    Raises
    ------
    FitInputError
        Unsorted or duplicate times, wrong shapes, non-unit quaternions or
        directions, partly missing rows, a wrong frame, sigmas that are not
        positive, an axis direction without an axis, no observation at all.
    TypeError
        Non-numeric input.
    """
    t = _times(t)
    n = t.size
    if omega_frame not in ("body", "space"):
        raise FitInputError(f"omega_frame must be 'body' or 'space'; got {omega_frame!r}")
    given = {}
    empty3 = np.zeros((0, 3))
    idx0 = np.zeros(0, dtype=np.intp)
    att_idx, att_q, att_s = idx0, np.zeros((0, 4)), np.zeros(0)
    if attitude is not None:
        q = _quaternions(attitude, n)
        present = ~np.isnan(q[:, 0])
        s, given["attitude"] = _sigma(attitude_sigma, "attitude_sigma", n, 1, present)
        att_idx, att_q, att_s = np.flatnonzero(present), q[present], s[present, 0]
    elif attitude_sigma is not None:
        raise FitInputError("attitude_sigma is given without attitude observations")
    om_idx, om_v, om_s = idx0, empty3, empty3
    if omega is not None:
        w = _rows(omega, "omega", n, 3)
        present = ~np.isnan(w[:, 0])
        s, given["omega"] = _sigma(omega_sigma, "omega_sigma", n, 3, present)
        om_idx, om_v, om_s = np.flatnonzero(present), w[present], s[present]
    elif omega_sigma is not None:
        raise FitInputError("omega_sigma is given without omega observations")
    ax_idx, ax_d, ax_s, a = idx0, empty3, np.zeros(0), None
    if axis_direction is not None:
        if axis is None:
            raise FitInputError("axis_direction is given without axis (the body axis whose space direction it is)")
        a = _array(axis, "axis", (3,))
        if a.shape != (3,) or not np.linalg.norm(a) > 0:
            raise FitInputError(f"axis must be a non-zero body vector of shape (3,); got {a.tolist()}")
        a = a / np.linalg.norm(a)
        d = _unit_rows(_rows(axis_direction, "axis_direction", n, 3), "axis_direction", "unit vector")
        present = ~np.isnan(d[:, 0])
        s, given["axis"] = _sigma(axis_sigma, "axis_sigma", n, 1, present)
        ax_idx, ax_d, ax_s = np.flatnonzero(present), d[present], s[present, 0]
    elif axis_sigma is not None:
        raise FitInputError("axis_sigma is given without axis_direction observations")
    elif axis is not None:
        raise FitInputError("axis is given without axis_direction observations")
    obs = ObservationSet(t, att_idx, att_q, att_s, om_idx, om_v, om_s, omega_frame, ax_idx, ax_d, ax_s, a, given)
    if not obs.kinds:
        raise FitInputError("no observations: give attitude, omega or axis_direction (rows of NaN are missing ones)")
    return obs


#: a reduced chi2 above this is absurd: ``fit`` refuses the result unless ``accept_poor_fit=True``
POOR_FIT_CHI2 = 100.0

#: per reading (:meth:`ObservationSet.reread`): what the data look like, what to do in the API, on the command line
READING_TEXT = {
    "xyzw": (
        "the quaternions look scalar-last (x, y, z, w)",
        "reorder them to (w, x, y, z)",
        "--quaternion-order xyzw",
    ),
    "conjugate": (
        "the attitudes look space-to-body (the conjugate quaternions)",
        "conjugate them",
        "--attitude-convention space-to-body",
    ),
    "space": ("the angular velocities look space-frame", "pass omega_frame='space'", "--omega-frame space"),
    "body": ("the angular velocities look body-frame", "pass omega_frame='body'", "--omega-frame body"),
    "deg": (
        "the angular velocities look like degrees per unit of t",
        "multiply them by pi/180",
        "--omega-unit deg",
    ),
}


def reading_hint(
    reading: str, reduced: float, better: float, *, detail: str | None = None, flag: str | None = None
) -> str:
    """One line: the data read as ``reading`` fit far better, and what to do (``flag``: only the command line's).

    ``reduced`` and ``better``: the reduced chi2 of the fit and of the other reading, with the same sigmas;
    ``detail``: what got better (default: the residuals, from the two).

    Examples
    --------
    >>> print(reading_hint("space", 4012.0, 0.98))
    the angular velocities look space-frame: read so, the data fit far better (residuals 64 times smaller, ...
    >>> print(reading_hint("space", 4012.0, 0.98, flag="--omega-frame space"))
    the angular velocities look space-frame: ... (..., reduced chi2 4012 -> 0.98): rerun with --omega-frame space
    """
    what, api, cli = READING_TEXT[reading]
    if detail is None:
        ratio = float(np.sqrt(reduced / better)) if better > 0 else float("inf")
        detail = f"residuals {ratio:.3g} times smaller"
    head = f"{what}: read so, the data fit far better ({detail}, reduced chi2 {reduced:.4g} -> {better:.4g})"
    if flag is not None:
        return f"{head}: rerun with {flag}"
    return f"{head}; {api} (command line: {cli})"
