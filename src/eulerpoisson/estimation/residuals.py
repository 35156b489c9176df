r"""The fit's unknowns, its weighted residuals and their Jacobian (from the variational equations).

Unknowns
    The attitude at the epoch :math:`t_0` as a body-frame rotation
    :math:`\boldsymbol\theta` about a reference :math:`q_\mathrm{ref}`,
    :math:`q_0 = q_\mathrm{ref}\otimes\exp(\boldsymbol\theta/2)` (the fit
    re-centres :math:`q_\mathrm{ref}` after every step, so the Jacobian is
    always taken at :math:`\boldsymbol\theta = 0`); the body angular velocity
    :math:`\boldsymbol\Omega_0`; the inertia with trace 1, diagonal
    (``I_xx, I_yy``; :math:`I_{zz} = 1 - I_{xx} - I_{yy}`) or full
    (``I_xx, I_yy, I_xy, I_xz, I_yz``).

Residuals, each divided by its standard deviation
    attitude: :math:`\mathbf r = \log(q_\mathrm{obs}^{-1}\otimes q(t))`, the
    body-frame rotation vector from the observed attitude to the model's;
    rate: :math:`\boldsymbol\Omega(t) - \boldsymbol\Omega_\mathrm{obs}` or
    :math:`R(t)\boldsymbol\Omega(t) - \boldsymbol\omega_\mathrm{obs}`;
    direction: the components of :math:`R(t)\mathbf a` along two unit vectors
    :math:`\mathbf e_1, \mathbf e_2` across the observed direction (the
    angular offsets, to first order).

Jacobian
    With :math:`R(t) = R_0R_\mathrm{rel}(t)`, a change :math:`\mathrm d\boldsymbol\theta`
    turns :math:`R(t)` into :math:`R(t)(1 + [R_\mathrm{rel}^\mathsf T\mathrm d\boldsymbol\theta]_\times)`;
    a change of :math:`\boldsymbol\Omega_0` or of the inertia into
    :math:`R(t)(1 + [\boldsymbol\eta_j\mathrm dp_j]_\times)` and
    :math:`\boldsymbol\Omega + \delta\boldsymbol\Omega_j\mathrm dp_j`
    (:mod:`~eulerpoisson.estimation.variational`). A body-frame rotation
    :math:`\boldsymbol\delta` changes the attitude residual by
    :math:`J_r^{-1}(\mathbf r)\boldsymbol\delta` (the inverse right Jacobian of
    SO(3)), the space rate by :math:`R(\boldsymbol\delta\times\boldsymbol\Omega)`
    and the direction by :math:`R(\boldsymbol\delta\times\mathbf a)`.

References
----------
J. Solà, J. Deray and D. Atchuthan, "A micro Lie theory for state estimation
in robotics", arXiv:1812.01537 (2018), eq. 144 (the right Jacobian of SO(3)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion
from ..numerics.quaternion import CONJUGATE, qmul
from .data import ObservationSet
from .variational import propagate

__all__ = ["FitState", "Layout", "inertia_matrix", "inertia_valid", "evaluate", "exp_quaternion", "log_quaternion"]

_DIAG = np.array([np.diag([1.0, 0.0, -1.0]), np.diag([0.0, 1.0, -1.0])])
_OFF = np.zeros((3, 3, 3))
for _k, (_i, _j) in enumerate(((0, 1), (0, 2), (1, 2))):
    _OFF[_k, _i, _j] = _OFF[_k, _j, _i] = 1.0
_FULL = np.concatenate([_DIAG, _OFF])

INERTIA_NAMES = {"given": ("I_xx", "I_yy"), "fit": ("I_xx", "I_yy", "I_xy", "I_xz", "I_yz"), "fixed": ()}


@dataclass(frozen=True)
class Layout:
    """Which unknowns are fitted: the attitude (or not) and the inertia (``given``, ``fit`` or ``fixed``)."""

    fit_attitude: bool
    inertia_mode: str
    fixed_inertia: np.ndarray | None = None

    @property
    def names(self) -> tuple[str, ...]:
        att = ("attitude0_x", "attitude0_y", "attitude0_z") if self.fit_attitude else ()
        return att + ("omega0_x", "omega0_y", "omega0_z") + INERTIA_NAMES[self.inertia_mode]

    @property
    def n_params(self) -> int:
        return len(self.names)

    @property
    def n_attitude(self) -> int:
        return 3 if self.fit_attitude else 0


@dataclass(frozen=True)
class FitState:
    """A point of the search: attitude and angular velocity at the epoch, inertia parameters."""

    q0: np.ndarray
    omega0: np.ndarray
    inertia_params: np.ndarray


def inertia_matrix(layout: Layout, p) -> tuple[np.ndarray, np.ndarray]:
    """The trace-1 inertia tensor and its derivatives (Q, 3, 3) with respect to the inertia parameters."""
    p = np.asarray(p, dtype=float)
    if layout.inertia_mode == "fixed":
        assert layout.fixed_inertia is not None  # a fixed layout carries its tensor
        return layout.fixed_inertia, np.zeros((0, 3, 3))
    if layout.inertia_mode == "given":
        return np.diag([p[0], p[1], 1.0 - p[0] - p[1]]), _DIAG
    I = np.array([[p[0], p[2], p[3]], [p[2], p[1], p[4]], [p[3], p[4], 1.0 - p[0] - p[1]]])
    return I, _FULL


def inertia_valid(I, margin: float = 1e-9) -> bool:
    """Symmetric positive definite with the triangle inequalities (each moment at most the sum of the others)."""
    if not np.all(np.isfinite(I)):
        return False
    ev = np.linalg.eigvalsh(I)
    return bool(ev[0] > margin and ev[2] <= ev[0] + ev[1] + margin)


def exp_quaternion(theta) -> np.ndarray:
    r"""Unit quaternion of a rotation vector, :math:`(\cos\frac{|\theta|}{2}, \sin\frac{|\theta|}{2}\hat\theta)` (shape (..., 4))."""
    theta = np.asarray(theta, dtype=float)
    a = np.linalg.norm(theta, axis=-1)
    return np.concatenate([np.cos(a / 2)[..., None], (0.5 * np.sinc(a / (2 * np.pi)))[..., None] * theta], -1)


def log_quaternion(q) -> np.ndarray:
    """Rotation vector (angle in [0, pi]) of unit quaternions (..., 4); the sign of q does not matter."""
    q = np.where(q[..., :1] < 0, -q, q)
    s = np.linalg.norm(q[..., 1:], axis=-1)
    a = 2.0 * np.arctan2(s, q[..., 0])
    return q[..., 1:] * (2.0 / np.sinc(a / (2 * np.pi)))[..., None]


def _skew(v):
    z = np.zeros(v.shape[:-1])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], -1),
            np.stack([v[..., 2], z, -v[..., 0]], -1),
            np.stack([-v[..., 1], v[..., 0], z], -1),
        ],
        -2,
    )


def _jr_inv(r):
    r"""Inverse right Jacobian of SO(3), :math:`1 + \tfrac12[\mathbf r]_\times + c(\theta)[\mathbf r]_\times^2` (shape (..., 3, 3))."""
    th = np.linalg.norm(r, axis=-1)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = 1.0 / ths**2 - (1.0 + np.cos(ths)) / (2.0 * ths * np.sin(ths))
    c = np.where(small, 1.0 / 12.0 + th**2 / 720.0, c)
    S = _skew(r)
    return np.eye(3) + 0.5 * S + c[..., None, None] * (S @ S)


def _tangent_basis(d):
    """Two unit vectors across each unit vector d (shape (N, 2, 3))."""
    helper = np.where(np.abs(d[:, :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(d, e1)
    return np.stack([e1, e2], 1)


@dataclass
class Evaluation:
    """Residuals (whitened) and Jacobian at a state, with the model's values at the observed times."""

    residuals: np.ndarray
    jacobian: np.ndarray | None
    chi2: float
    rows: np.ndarray
    quaternion: np.ndarray
    omega: np.ndarray


def evaluate(
    layout: Layout, obs: ObservationSet, state: FitState, *, jacobian: bool = True, tol: float = 2.0**-52
) -> Evaluation:
    """Whitened residuals (attitude, then rate, then direction rows) and their Jacobian at ``state``.

    Raises
    ------
    FloatingPointError
        The motion could not be integrated (non-finite or too many steps).
    """
    I, dI = inertia_matrix(layout, state.inertia_params)
    rows = np.unique(np.concatenate([obs.att_idx, obs.om_idx, obs.ax_idx]))
    tau = obs.t[rows] - obs.t[0]
    s = propagate(I, state.omega0, dI, tau, tol=tol)
    q = qmul(state.q0, s.quaternion)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    na = layout.n_attitude
    P = layout.n_params
    parts_r, parts_j = [], []

    def pos(idx):
        return np.searchsorted(rows, idx)

    if len(obs.att_idx):
        k = pos(obs.att_idx)
        rel = qmul(obs.att_q * CONJUGATE, q[k])
        r = log_quaternion(rel)
        w = 1.0 / obs.att_sigma[:, None]
        parts_r.append((r * w).ravel())
        if jacobian:
            Ji = _jr_inv(r)
            Jb = np.zeros((len(k), 3, P))
            if na:
                Rrel = matrix_from_unit_quaternion(s.quaternion[k])
                Jb[:, :, :3] = Ji @ np.swapaxes(Rrel, -1, -2)
            Jb[:, :, na:] = Ji @ np.swapaxes(s.eta[k], -1, -2)
            parts_j.append((Jb * w[:, :, None]).reshape(-1, P))
    if len(obs.om_idx):
        k = pos(obs.om_idx)
        W = s.omega[k]
        if obs.omega_frame == "body":
            r = W - obs.om_value
        else:
            R = matrix_from_unit_quaternion(q[k])
            r = np.einsum("kab,kb->ka", R, W) - obs.om_value
        w = 1.0 / obs.om_sigma
        parts_r.append((r * w).ravel())
        if jacobian:
            Jb = np.zeros((len(k), 3, P))
            dW = np.swapaxes(s.domega[k], -1, -2)  # (K, 3, P-na)
            if obs.omega_frame == "body":
                Jb[:, :, na:] = dW
            else:
                mW = -_skew(W)  # delta x W = -W x delta
                Jb[:, :, na:] = R @ (dW + mW @ np.swapaxes(s.eta[k], -1, -2))
                if na:
                    Rrel = matrix_from_unit_quaternion(s.quaternion[k])
                    Jb[:, :, :3] = R @ mW @ np.swapaxes(Rrel, -1, -2)
            parts_j.append((Jb * w[:, :, None]).reshape(-1, P))
    if len(obs.ax_idx):
        k = pos(obs.ax_idx)
        R = matrix_from_unit_quaternion(q[k])
        E = _tangent_basis(obs.ax_dir)
        d = R @ obs.axis
        r = np.einsum("kab,kb->ka", E, d)
        w = 1.0 / obs.ax_sigma[:, None]
        parts_r.append((r * w).ravel())
        if jacobian:
            ER = E @ R @ (-_skew(obs.axis))  # (K, 2, 3): delta -> E R (delta x a)
            Jb = np.zeros((len(k), 2, P))
            Jb[:, :, na:] = ER @ np.swapaxes(s.eta[k], -1, -2)
            if na:
                Rrel = matrix_from_unit_quaternion(s.quaternion[k])
                Jb[:, :, :3] = ER @ np.swapaxes(Rrel, -1, -2)
            parts_j.append((Jb * w[:, :, None]).reshape(-1, P))
    res = np.concatenate(parts_r)
    jac = np.concatenate(parts_j) if jacobian else None
    return Evaluation(res, jac, float(res @ res), rows, q, s.omega)
