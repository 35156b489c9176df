r"""What a fit returns: the body, the state at the epoch, their uncertainties, the residuals and the prediction."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..attitude.core import Attitude
from ..numerics.quaternion import CONJUGATE, qmul
from .data import POOR_FIT_CHI2, reading_hint
from .residuals import inertia_matrix, log_quaternion

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..attitude.core import AttitudeLike
    from ..model.body import RigidBody
    from ..trajectory import Trajectory
    from .data import ObservationSet

__all__ = ["FitResult", "LocalOptimum"]


@dataclass(frozen=True)
class LocalOptimum:
    """A distinct optimum the search reached: its :math:`\\chi^2`, inertia (trace 1), attitude and rate at the epoch.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> t = np.linspace(0.0, 10.0, 41)
    >>> truth = ep.solve([0.25, 0.33, 0.42], t, omega0=[0.1, 0.2, 1.0])
    >>> res = ep.fit(t, omega=truth.omega, omega_sigma=1e-3, inertia=[0.25, 0.33, 0.42])
    >>> best = res.local_optima[0]                                    # best first
    >>> type(best).__name__, bool(best.chi2 < 1e-12), best.converged
    ('LocalOptimum', True, True)
    >>> sorted(best.as_dict())
    ['attitude0', 'chi2', 'converged', 'inertia', 'omega0']
    """

    chi2: float
    inertia: np.ndarray
    q0: np.ndarray
    omega0: np.ndarray
    converged: bool

    def __post_init__(self):
        for name in ("inertia", "q0", "omega0"):
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    def as_dict(self) -> dict[str, Any]:
        return {
            "chi2": float(self.chi2),
            "inertia": self.inertia.tolist(),
            "attitude0": self.q0.tolist(),
            "omega0": self.omega0.tolist(),
            "converged": bool(self.converged),
        }


def _frozen(v):
    """Read-only copies: arrays not writeable, dicts as read-only mappings (nested), lists as tuples."""
    from types import MappingProxyType

    if isinstance(v, np.ndarray):
        v = v.copy()
        v.flags.writeable = False
        return v
    if isinstance(v, dict):
        return MappingProxyType({k: _frozen(x) for k, x in v.items()})
    if isinstance(v, list):
        return tuple(_frozen(x) for x in v)
    return v


def _finite_or_none(x):
    """A copy of nested dicts/lists with every non-finite float replaced by None (JSON has no NaN)."""
    if isinstance(x, Mapping):
        return {k: _finite_or_none(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite_or_none(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def _covariance(J):
    A = J.T @ J
    try:
        ev, V = np.linalg.eigh(A)
    except np.linalg.LinAlgError:  # pragma: no cover - non-finite Jacobian is refused earlier
        return np.full(A.shape, np.nan), False
    ok = ev[0] > 1e-13 * ev[-1] and ev[0] > 0
    if not ok:
        return np.full(A.shape, np.nan), False
    return (V / ev) @ V.T, True


class FitResult:
    r"""The torque-free body and spin state that best explain the observations (from :func:`eulerpoisson.fit`).

    Attributes
    ----------
    epoch : float
        Time of the fitted state, ``t[0]``.
    inertia : ndarray, shape (3, 3)
        Inertia tensor in the observations' body frame, trace 1 (free motion
        fixes only the ratios).
    attitude0 : Attitude
        Attitude at the epoch (body to space).
    omega0 : ndarray, shape (3,)
        Body angular velocity at the epoch.
    parameter_names : tuple of str
        Names of the fitted unknowns: ``attitude0_x/y/z`` (a body-frame
        rotation about ``attitude0``, radians; absent when the data do not see
        the attitude), ``omega0_x/y/z``, then ``I_xx, I_yy`` (and ``I_xy,
        I_xz, I_yz`` with ``principal_axes="fit"``); none of the inertia when
        it was fixed.
    parameters : dict
        Their values (the attitude entries are 0: the rotation is about the fitted attitude).
    covariance : ndarray, shape (P, P)
        Covariance of the unknowns (NaN when the data do not determine them all).
    stderr : dict
        Standard errors by name, with ``I_zz`` derived and, when the axes are
        fitted, the principal moments ``I_1 <= I_2 <= I_3``.
    chi2, dof, reduced_chi2 : float, int, float
        :math:`\sum r^2` of the whitened residuals, residuals minus unknowns, their ratio.
    residuals : dict
        Per kind present (``attitude``: body-frame rotation vectors, radians,
        shape (Na, 3); ``omega``: (No, 3); ``axis``: (Nx, 2) radians), with
        ``<kind>_t`` their times. Not divided by the sigmas.
    sigma : dict
        The standard deviations used (scalar summaries); ``sigma_estimated``
        names the kinds whose sigma was estimated from the residuals.
    local_optima : tuple of LocalOptimum
        Distinct optima found by the search, best first.
    poor_fit : bool
        The reduced chi2 is absurd (above
        :data:`~eulerpoisson.estimation.estimate.POOR_FIT_CHI2`, 100) or
        another reading of the data fits far better (``fit`` returns such a
        result only with ``accept_poor_fit=True``).
    convention_hint : str or None
        One line when another reading of the same numbers fits far better
        (scalar-last quaternions, their conjugates, the rates in the other
        frame or in degrees), naming what to do and the command-line flag.
    better_reading : str or None
        That reading: ``"xyzw"``, ``"conjugate"``, ``"space"``, ``"body"`` or ``"deg"``.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> t = np.linspace(0.0, 10.0, 41)
    >>> truth = ep.solve([0.25, 0.33, 0.42], t, omega0=[0.1, 0.2, 1.0])
    >>> res = ep.fit(t, omega=truth.omega, omega_sigma=1e-3, inertia=[0.25, 0.33, 0.42])
    >>> res.parameter_names
    ('omega0_x', 'omega0_y', 'omega0_z')
    >>> print(np.round(res.omega0, 6), res.converged)
    [0.1 0.2 1. ] True
    >>> print(np.round(res.principal_moments, 6))                    # trace 1
    [0.25 0.33 0.42]
    """

    # what from_search sets (read-only: arrays not writeable, dicts as mappings, lists as tuples)
    epoch: float
    inertia: NDArray[np.float64]
    principal_moments: NDArray[np.float64]
    principal_axes: NDArray[np.float64]
    attitude0: Attitude
    omega0: NDArray[np.float64]
    parameter_names: tuple[str, ...]
    parameters: Mapping[str, float]
    covariance: NDArray[np.float64]
    stderr: Mapping[str, float]
    determined: bool
    chi2: float
    dof: int
    reduced_chi2: float
    residuals: Mapping[str, NDArray[np.float64]]
    sigma: Mapping[str, float]
    sigma_estimated: tuple[str, ...]
    local_optima: tuple[LocalOptimum, ...]
    converged: bool
    n_starts: int
    n_equivalent: int
    poor_fit: bool
    convention_hint: str | None
    better_reading: str | None
    _better_reading_fit: tuple[float, str] | None
    principal_axes_mode: str
    observations: ObservationSet
    _model_q: NDArray[np.float64]
    _model_omega: NDArray[np.float64]
    _model_rows: NDArray[np.intp]

    def __init__(self, **kw: Any) -> None:
        for k, v in kw.items():
            object.__setattr__(self, k, _frozen(v))

    def __setattr__(self, name, value):
        raise AttributeError("FitResult is read-only")

    def __delattr__(self, name):
        raise AttributeError("FitResult is read-only")

    @classmethod
    def from_search(cls, layout, obs, best, final, optima, estimated, n_starts, n_equivalent=1, diagnosis=None):
        """The result of ``fit``'s search: the best optimum, its covariance and the other optima found.

        Made by ``fit`` from its internal state (the parameter layout, the observations, the optima of
        the starts); not meant to be called directly.
        """
        I, _ = inertia_matrix(layout, best.state.inertia_params)
        I = I / np.trace(I)
        J = final.jacobian
        cov, determined = _covariance(J)
        names = layout.names
        values = {n: 0.0 for n in names[: layout.n_attitude]}
        for i, n in enumerate(("omega0_x", "omega0_y", "omega0_z")):
            values[n] = float(best.state.omega0[i])
        for n, v in zip(names[layout.n_attitude + 3 :], best.state.inertia_params):
            values[n] = float(v)
        se = np.sqrt(np.diag(cov))
        stderr = {n: float(s) for n, s in zip(names, se)}
        if layout.inertia_mode != "fixed":
            ixx, iyy = names.index("I_xx"), names.index("I_yy")
            values["I_zz"] = float(I[2, 2])
            stderr["I_zz"] = float(np.sqrt(cov[ixx, ixx] + cov[iyy, iyy] + 2 * cov[ixx, iyy]))
        ev, V = np.linalg.eigh(I)
        V = V * np.where(np.linalg.det(V) < 0, -1.0, 1.0)
        if layout.inertia_mode == "fit":
            # first order: d lambda_i = v_i^T dI v_i
            _, dI = inertia_matrix(layout, best.state.inertia_params)
            G = np.einsum("ai,jab,bi->ij", V, dI, V)  # (3, Q)
            sl = slice(layout.n_attitude + 3, None)
            Cl = G @ cov[sl, sl] @ G.T
            for i in range(3):
                values[f"I_{i + 1}"] = float(ev[i])
                stderr[f"I_{i + 1}"] = float(np.sqrt(Cl[i, i]))
        residuals = {}
        start = 0
        res = final.residuals
        for kind, idx, width, sig in (
            ("attitude", obs.att_idx, 3, obs.att_sigma[:, None] if len(obs.att_idx) else None),
            ("omega", obs.om_idx, 3, obs.om_sigma),
            ("axis", obs.ax_idx, 2, obs.ax_sigma[:, None] if len(obs.ax_idx) else None),
        ):
            size = width * len(idx)
            if size:
                residuals[kind] = res[start : start + size].reshape(-1, width) * sig
                residuals[kind + "_t"] = obs.t[idx]
                start += size
        sigma = {}
        if len(obs.att_idx):
            sigma["attitude"] = float(np.median(obs.att_sigma))
        if len(obs.om_idx):
            sigma["omega"] = float(np.median(obs.om_sigma))
        if len(obs.ax_idx):
            sigma["axis"] = float(np.median(obs.ax_sigma))
        dof = len(res) - layout.n_params
        return cls(
            epoch=float(obs.t[0]),
            inertia=I,
            principal_moments=ev,
            principal_axes=V,
            attitude0=Attitude(best.state.q0),
            omega0=best.state.omega0.copy(),
            parameter_names=names,
            parameters=values,
            covariance=cov,
            stderr=stderr,
            determined=determined,
            chi2=float(final.chi2),
            dof=int(dof),
            reduced_chi2=float(final.chi2 / dof) if dof > 0 else float("nan"),
            residuals=residuals,
            sigma=sigma,
            sigma_estimated=tuple(sorted(estimated)),
            local_optima=list(optima),
            converged=bool(best.converged),
            n_starts=int(n_starts),
            principal_axes_mode=layout.inertia_mode,
            observations=obs,
            n_equivalent=int(n_equivalent),
            poor_fit=bool((diagnosis or {}).get("poor_fit", False)),
            convention_hint=(diagnosis or {}).get("convention_hint"),
            better_reading=(diagnosis or {}).get("better_reading"),
            _better_reading_fit=(diagnosis or {}).get("_better_reading_fit"),
            _model_q=final.quaternion,
            _model_omega=final.omega,
            _model_rows=final.rows,
        )

    # ------------------------------------------------------------------
    @property
    def body(self) -> RigidBody:
        """The fitted body, a :class:`~eulerpoisson.RigidBody` with the trace-1 tensor in the observations' frame."""
        from ..model.body import RigidBody

        return RigidBody(self.inertia, name="fitted body")

    @property
    def mode(self) -> str:
        """``LAM`` (rotation about the long axis) or ``SAM`` (short axis) of the fitted motion."""
        from .starts import regime

        return regime(self.inertia, self.omega0)

    def attitude_error(self, attitude: AttitudeLike) -> NDArray[np.float64]:
        """Body-frame rotation vector (radians) from ``attitude`` to the fitted ``attitude0`` (shape (3,))."""
        q = Attitude(attitude).as_quaternion() if not isinstance(attitude, Attitude) else attitude.as_quaternion()
        return log_quaternion(qmul(q * CONJUGATE, self.attitude0.as_quaternion()))

    def predict(self, t: ArrayLike, **options: Any) -> Trajectory:
        """The fitted motion at times ``t`` (any, before or after the epoch), a :class:`~eulerpoisson.Trajectory`.

        Solved in closed form (``method="exact"``) unless ``options`` say
        otherwise (they go to :func:`eulerpoisson.solve`).
        """
        from ..solvers import solve
        from ..trajectory import Trajectory
        from ..util.validate import as_float_array

        t = as_float_array(t, "t")
        scalar = t.ndim == 0
        t1 = np.atleast_1d(t)
        tr = solve(self.body, t1 - self.epoch, attitude0=self.attitude0.as_quaternion(), omega0=self.omega0, **options)
        out = Trajectory(t1, tr.quaternion, tr.omega, self.body, method=tr.method, options=tr.options, stats=tr.stats)
        return out[0] if scalar else out

    # ------------------------------------------------------------------
    def sigma_in(self, *, angle_unit: str = "rad", rate_unit: str = "rad") -> tuple[dict, dict]:
        """The standard deviations (:attr:`sigma`) in the given units, and the units: ``(values, units)``.

        Parameters
        ----------
        angle_unit : {"rad", "deg"}
            Of the attitude and axis sigmas.
        rate_unit : {"rad", "deg"}
            Of the angular-velocity sigma: radians or degrees per unit of ``t``.

        Raises
        ------
        ValueError
            Another unit.

        Examples
        --------
        >>> import numpy as np, eulerpoisson as ep
        >>> t = np.linspace(0.0, 10.0, 41)
        >>> truth = ep.solve([0.25, 0.33, 0.42], t, omega0=[0.1, 0.2, 1.0])
        >>> res = ep.fit(t, attitude=truth.quaternion, attitude_sigma=np.radians(0.5), omega=truth.omega,
        ...              omega_sigma=1e-3)
        >>> values, units = res.sigma_in(angle_unit="deg")
        >>> print(round(values["attitude"], 9), units["attitude"], values["omega"], units["omega"])
        0.5 deg 0.001 rad per unit of t
        """
        factor = {}
        for name, unit in (("angle_unit", angle_unit), ("rate_unit", rate_unit)):
            if unit not in ("rad", "deg"):
                raise ValueError(f"{name} must be 'rad' or 'deg', got {unit!r}")
            factor[name] = 1.0 if unit == "rad" else 180.0 / np.pi
        values, units = {}, {}
        for k, v in self.sigma.items():
            if k == "omega":
                values[k], units[k] = float(v) * factor["rate_unit"], f"{rate_unit} per unit of t"
            else:
                values[k], units[k] = float(v) * factor["angle_unit"], angle_unit
        return values, units

    def as_dict(self, *, angle_unit: str = "rad", rate_unit: str = "rad") -> dict[str, Any]:
        """Everything as plain Python (what :meth:`to_json` writes); NaN (undetermined) becomes None.

        ``sigma`` is in ``angle_unit`` (attitude, axis) and ``rate_unit`` (per unit of ``t``), as
        ``sigma_units`` says next to it (:meth:`sigma_in`); everything else in radians.
        """
        sigma, sigma_units = self.sigma_in(angle_unit=angle_unit, rate_unit=rate_unit)
        d = {
            "epoch": self.epoch,
            "inertia": self.inertia.tolist(),
            "principal_moments": self.principal_moments.tolist(),
            "principal_axes": self.principal_axes.tolist(),
            "attitude0": self.attitude0.as_quaternion().tolist(),
            "omega0": self.omega0.tolist(),
            "mode": self.mode,
            "parameters": dict(self.parameters),
            "stderr": dict(self.stderr),
            "parameter_names": list(self.parameter_names),
            "covariance": self.covariance.tolist(),
            "chi2": self.chi2,
            "dof": self.dof,
            "reduced_chi2": self.reduced_chi2,
            "sigma": sigma,
            "sigma_units": sigma_units,
            "sigma_estimated": list(self.sigma_estimated),
            "converged": self.converged,
            "poor_fit": self.poor_fit,
            "convention_hint": self.convention_hint,
            "principal_axes_mode": self.principal_axes_mode,
            "n_observations": {k: int(len(v)) for k, v in self.residuals.items() if not k.endswith("_t")},
            "local_optima": [o.as_dict() for o in self.local_optima],
            "rms_residuals": {
                k: float(np.sqrt(np.mean(np.asarray(v) ** 2)))
                for k, v in self.residuals.items()
                if not k.endswith("_t")
            },
        }
        return _finite_or_none(d)

    def to_json(
        self,
        path: str | os.PathLike[str] | None = None,
        *,
        indent: int = 2,
        angle_unit: str = "rad",
        rate_unit: str = "rad",
    ) -> str:
        """The result as JSON text (:meth:`as_dict`, the sigmas in these units); written atomically to ``path``."""
        text = json.dumps(self.as_dict(angle_unit=angle_unit, rate_unit=rate_unit), indent=indent, allow_nan=False)
        text += "\n"
        if path is not None:
            from ..io.atomic import atomic_write_text

            atomic_write_text(path, text)
        return text

    def summary(self, *, angle_unit: str = "rad", rate_unit: str = "rad", flag: str | None = None) -> str:
        """A readable table: the body, the state, their standard errors, and the fit's quality.

        The sigmas are shown in ``angle_unit`` and ``rate_unit`` (:meth:`sigma_in`), with their units;
        ``flag``: the command-line flag that gives the better reading, named instead of the API's advice.
        """
        sigma, sigma_units = self.sigma_in(angle_unit=angle_unit, rate_unit=rate_unit)
        lines = []
        kinds = ", ".join(f"{k} {len(v)}" for k, v in self.residuals.items() if not k.endswith("_t"))
        lines.append(f"fit of a torque-free body: observations {kinds}; epoch t0 = {self.epoch:g}")
        lines.append(
            f"  chi2 = {self.chi2:.6g}, dof = {self.dof}, reduced chi2 = {self.reduced_chi2:.4g}"
            + ("" if self.converged else "  (NOT converged)")
        )
        if self.sigma_estimated:
            lines.append(
                "  sigma estimated from the residuals: "
                + ", ".join(f"{k} {sigma[k]:.3g} {sigma_units[k]}" for k in self.sigma_estimated)
            )
        given = [k for k in sigma if k not in self.sigma_estimated]
        if given:
            lines.append("  sigma given: " + ", ".join(f"{k} {sigma[k]:.3g} {sigma_units[k]}" for k in given))
        if self.poor_fit:
            why = (
                f"reduced chi2 = {self.reduced_chi2:.4g} > {POOR_FIT_CHI2:g}"
                if self.reduced_chi2 > POOR_FIT_CHI2
                else "another reading of the data fits far better"
            )
            lines.append(f"  POOR FIT: {why}: the numbers below do not describe the data")
        if self.convention_hint:
            advice = self.reading_advice(flag) if flag is not None else None
            lines.append("  " + (advice or self.convention_hint))
        lines.append(f"  {'parameter':<14}{'value':>16}{'stderr':>14}")
        for n in list(self.parameter_names) + [k for k in ("I_zz", "I_1", "I_2", "I_3") if k in self.parameters]:
            lines.append(f"  {n:<14}{self.parameters[n]:>16.9g}{self.stderr[n]:>14.3g}")
        if not self.determined:
            lines.append(
                "  the data do not determine every unknown (singular normal matrix): fix the inertia or add data"
            )
        q = self.attitude0.as_quaternion()
        if "attitude0_x" in self.parameters:
            lines.append(
                "  attitude0 (w, x, y, z) = ("
                + ", ".join(f"{x:.9f}" for x in q)
                + ")"
                + "  [attitude0_x/y/z: rotation about it, rad]"
            )
        else:
            lines.append(
                "  attitude0: not seen by the data (body-frame rates only); predictions start from the identity"
            )
        lines.append(
            "  principal moments (trace 1) = ("
            + ", ".join(f"{x:.6f}" for x in self.principal_moments)
            + f"); motion: {self.mode}"
        )
        if self.n_equivalent > 1:
            lines.append(
                f"  {self.n_equivalent} optima fit the data equally well (delta chi2 < 1; evenly spaced "
                f"samples alias): the slowest motion is reported, see local_optima"
            )
        if len(self.local_optima) > 1:
            lines.append(
                f"  {len(self.local_optima)} distinct optima from {self.n_starts} starts (chi2): "
                + ", ".join(f"{o.chi2:.6g}" for o in self.local_optima[:6])
            )
        else:
            lines.append(f"  one optimum from {self.n_starts} starts")
        return "\n".join(lines)

    def reading_advice(self, flag: str) -> str | None:
        """:attr:`convention_hint` naming only the command-line ``flag`` that reads the data so; None without one."""
        if self.better_reading is None or self._better_reading_fit is None:
            return None
        better, detail = self._better_reading_fit
        return reading_hint(self.better_reading, self.reduced_chi2, better, detail=detail, flag=flag)

    def __repr__(self) -> str:
        return f"<FitResult chi2={self.chi2:.4g} dof={self.dof} moments={np.round(self.principal_moments, 6).tolist()}>"

    def _repr_html_(self) -> str:
        """A compact HTML table for notebooks: :func:`eulerpoisson.util.htmlrepr.fit_html`."""
        from ..util.htmlrepr import fit_html

        return fit_html(self)

    # ------------------------------------------------------------------
    def plot_residuals(self, ax: Axes | None = None) -> Figure:
        """Residuals over time, one panel per kind; returns the figure."""
        from .plots import plot_residuals

        return plot_residuals(self, ax=ax)

    def plot_fit(self) -> Figure:
        """Fitted (lines) against observed (dots) attitude and rate; returns the figure."""
        from .plots import plot_fit

        return plot_fit(self)

    def plot_polhode(self, ax: Axes | None = None) -> Figure:
        """The fitted polhode: the body angular momentum on its sphere, in the principal frame; returns the figure."""
        from .plots import plot_polhode

        return plot_polhode(self, ax=ax)

    def save_plots(self, directory: str | os.PathLike[str]) -> list[Path]:
        """Write ``residuals.png``, ``fit.png`` and ``polhode.png`` into ``directory``; returns their paths."""
        from .plots import save_plots

        return save_plots(self, directory)
