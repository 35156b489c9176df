r"""Where the search starts: guesses of the state and the inertia from the data, and a grid that covers both regimes.

From the data
    The body rate at the epoch from the first rate observation, or from the
    first two attitudes (:math:`\boldsymbol\Omega \approx \log(q_0^{-1}q_1)/\Delta t`,
    right when the body turns less than half a turn between them). The
    inertia from the conservation of the spatial angular momentum: wherever
    an attitude and a body rate are known together (observed, or the rate
    from consecutive attitudes), :math:`R_kI\boldsymbol\Omega_k = \mathbf m` for
    all :math:`k` is linear in the trace-1 inertia and :math:`\mathbf m`
    (least squares); with rates only, Euler's equations
    :math:`I\dot{\boldsymbol\Omega} = (I\boldsymbol\Omega)\times\boldsymbol\Omega`
    with differenced rates, also linear.

A grid
    Triaxial shapes (an elongated and a flattened one) with their axes in
    every order along the observation frame's axes: for the start's rate,
    these put the motion on both sides of the separatrix, rotating about
    the long axis (LAM) and about the short one (SAM). With a direction
    observed but no attitude, the attitude about that direction is
    ambiguous: four starts turned by quarter turns about it.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..attitude.core import matrix_from_unit_quaternion
from ..numerics.quaternion import CONJUGATE, qmul
from .data import ObservationSet
from .residuals import FitState, Layout, exp_quaternion, inertia_valid, log_quaternion
from .variational import propagate

__all__ = ["omega_guess", "inertia_from_data", "grid_inertias", "attitude_guesses", "regime"]

#: shapes of the grid, trace 1: elongated and flattened
SHAPES = ((0.2, 0.38, 0.42), (0.26, 0.3, 0.44))


def _paired_rates(obs: ObservationSet):
    """(R_k, Omega_k) pairs: observed together, or the rate from consecutive attitudes at their midpoints."""
    Rs, Ws = [], []
    if len(obs.att_idx) and len(obs.om_idx):
        common, ia, io = np.intersect1d(obs.att_idx, obs.om_idx, return_indices=True)
        if len(common) >= 3:
            R = matrix_from_unit_quaternion(obs.att_q[ia])
            W = obs.om_value[io]
            if obs.omega_frame == "space":
                W = np.einsum("kba,kb->ka", R, W)
            return R, W
    if len(obs.att_idx) >= 4:
        q = obs.att_q
        dt = np.diff(obs.t[obs.att_idx])
        rel = qmul(q[:-1] * CONJUGATE, q[1:])
        rv = log_quaternion(rel)
        mid = qmul(q[:-1], exp_quaternion(0.5 * rv))
        Ws = rv / dt[:, None]
        Rs = matrix_from_unit_quaternion(mid)
        return Rs, Ws
    return None


def omega_guess(obs: ObservationSet, q0=None) -> np.ndarray | None:
    """The body rate near the epoch from the data, or None."""
    if len(obs.om_idx):
        w = obs.om_value[0]
        if obs.omega_frame == "space" and q0 is not None:
            w = matrix_from_unit_quaternion(q0).T @ w
        # space rates and no attitude: the start's attitude is the identity, where body and space rates agree
        return w.copy()
    if len(obs.att_idx) >= 2:
        dt = obs.t[obs.att_idx[1]] - obs.t[obs.att_idx[0]]
        rel = qmul(obs.att_q[0] * CONJUGATE, obs.att_q[1])
        return log_quaternion(rel) / dt
    return None


def _design(mode):
    """Basis matrices B_j of the trace-1 tensor: I = B_0 + sum_j p_j B_j."""
    base = np.diag([0.0, 0.0, 1.0])
    if mode == "given":
        basis = [np.diag([1.0, 0.0, -1.0]), np.diag([0.0, 1.0, -1.0])]
    else:
        basis = [np.diag([1.0, 0.0, -1.0]), np.diag([0.0, 1.0, -1.0])]
        for i, j in ((0, 1), (0, 2), (1, 2)):
            m = np.zeros((3, 3))
            m[i, j] = m[j, i] = 1.0
            basis.append(m)
    return base, basis


def params_of(mode, I) -> np.ndarray:
    """Inertia parameters of a trace-1 tensor."""
    I = I / np.trace(I)
    if mode == "given":
        return np.array([I[0, 0], I[1, 1]])
    return np.array([I[0, 0], I[1, 1], I[0, 1], I[0, 2], I[1, 2]])


def inertia_from_data(obs: ObservationSet, mode: str) -> np.ndarray | None:
    """Trace-1 inertia from conservation of the spatial momentum (or Euler's equations); None if not possible."""
    if mode == "fixed":
        return None
    base, basis = _design(mode)
    npar = len(basis)
    pairs = _paired_rates(obs)
    if pairs is not None:
        R, W = pairs
        K = len(W)
        if K < npar + 3:
            return None
        # R_k (B0 + sum p_j B_j) W_k - m = 0  ->  [R_k B_j W_k, -1] [p; m] = -R_k B0 W_k
        A = np.zeros((K, 3, npar + 3))
        for j, B in enumerate(basis):
            A[:, :, j] = np.einsum("kab,bc,kc->ka", R, B, W)
        A[:, :, npar:] = -np.eye(3)
        b = -np.einsum("kab,bc,kc->ka", R, base, W)
        x = np.linalg.lstsq(A.reshape(-1, npar + 3), b.ravel(), rcond=None)[0]
        p = x[:npar]
    elif len(obs.om_idx) >= npar + 3 and obs.omega_frame == "body":
        W = obs.om_value
        t = obs.t[obs.om_idx]
        Wd = np.diff(W, axis=0) / np.diff(t)[:, None]
        Wm = 0.5 * (W[1:] + W[:-1])
        # I Wd - (I Wm) x Wm = 0, linear in I
        A = np.zeros((len(Wd), 3, npar))
        for j, B in enumerate(basis):
            A[:, :, j] = Wd @ B.T - np.cross(Wm @ B.T, Wm)
        b = -(Wd @ base.T - np.cross(Wm @ base.T, Wm))
        p = np.linalg.lstsq(A.reshape(-1, npar), b.ravel(), rcond=None)[0]
    else:
        return None
    I = base + np.tensordot(p, np.array(basis), 1)
    if not inertia_valid(I, 1e-6):
        # keep the axes, pull the moments back inside the physical region
        ev, V = np.linalg.eigh(0.5 * (I + I.T))
        ev = np.clip(ev, 0.05, None)
        ev = ev / ev.sum()
        ev = np.minimum(ev, 0.49)
        ev = ev / ev.sum()
        I = (V * ev) @ V.T
        if not inertia_valid(I, 1e-6):
            return None
    return I


def grid_inertias() -> list[np.ndarray]:
    """Diagonal trace-1 tensors: each shape of the grid with its axes in every order."""
    out = []
    for shape in SHAPES:
        for perm in itertools.permutations(range(3)):
            out.append(np.diag(np.array(shape)[list(perm)]))
    return out


def regime(I, omega) -> str:
    """``LAM`` (about the long axis, smallest moment) or ``SAM`` (short axis) for a motion, from :math:`L^2 - 2EI_2`."""
    ev, V = np.linalg.eigh(I)
    M = I @ omega
    L2 = M @ M
    twoE = omega @ M
    return "LAM" if L2 < twoE * ev[1] else "SAM"


def attitude_guesses(obs: ObservationSet, layout: Layout, I, omega0) -> list[np.ndarray]:
    """Attitudes at the epoch consistent with the first attitude-like observation and the start's motion."""
    if not layout.fit_attitude:
        return [np.array([1.0, 0.0, 0.0, 0.0])]
    first_att = obs.t[obs.att_idx[0]] if len(obs.att_idx) else np.inf
    first_ax = obs.t[obs.ax_idx[0]] if len(obs.ax_idx) else np.inf
    if not np.isfinite(min(first_att, first_ax)):
        return [np.array([1.0, 0.0, 0.0, 0.0])]
    tk = min(first_att, first_ax)
    try:
        qrel = propagate(I, omega0, np.zeros((0, 3, 3)), np.array([tk - obs.t[0]])).quaternion[0]
    except FloatingPointError:
        qrel = np.array([1.0, 0.0, 0.0, 0.0])
    if first_att <= first_ax:
        qk = obs.att_q[0]
        return [qmul(qk, qrel * CONJUGATE)]
    # a direction only: the rotation taking the body axis to it, then quarter turns about it
    a, d = obs.axis, obs.ax_dir[0]
    assert a is not None  # directions are observed, so is their body axis
    c = np.cross(a, d)
    s, cos = np.linalg.norm(c), float(a @ d)
    ang = np.arctan2(s, cos)
    if s < 1e-12:
        c = np.cross(a, [1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.cross(a, [0.0, 1.0, 0.0])
        s = np.linalg.norm(c)
    base = exp_quaternion(c / s * ang)  # space rotation taking a to d
    out = []
    for k in range(4):
        spin = exp_quaternion(d * (k * np.pi / 2))
        qk = qmul(spin, base)
        out.append(qmul(qk, qrel * CONJUGATE))
    return out


def starts(obs: ObservationSet, layout: Layout, *, extra_inertias=()) -> list[FitState]:
    """The starting states: data-driven and grid inertias, with attitude guesses for each."""
    mode = layout.inertia_mode
    inertias = []
    if mode == "fixed":
        inertias = [layout.fixed_inertia]
    else:
        inertias.extend(I for I in extra_inertias if I is not None)
        I_data = inertia_from_data(obs, mode)
        if I_data is not None:
            inertias.append(I_data)
        inertias.extend(grid_inertias())
    out = []
    q_first = obs.att_q[0] if len(obs.att_idx) else None
    w = omega_guess(obs, q_first)
    aliases = _aliases(obs, w) if w is not None and not len(obs.om_idx) else []
    for I in inertias:
        if w is None:
            ws = _omega_grid(obs)
        else:
            ws = [w] + aliases
        for w0 in ws:
            for q0 in attitude_guesses(obs, layout, I, w0):
                out.append(
                    FitState(q0, np.array(w0, dtype=float), params_of(mode, I) if mode != "fixed" else np.zeros(0))
                )
    return out


def _aliases(obs: ObservationSet, w) -> list[np.ndarray]:
    """Rates that turn the first two attitudes into each other with one more or one less turn.

    Consecutive attitudes show the shortest rotation between them; a body that
    turns more than half a turn between samples is seen aliased. These
    starts cover one extra turn either way.
    """
    dt = obs.t[obs.att_idx[1]] - obs.t[obs.att_idx[0]]
    phi = w * dt
    a = float(np.linalg.norm(phi))
    if a == 0.0:
        return []
    u = phi / a
    return [(a + 2.0 * np.pi * k) * u / dt for k in (1, -1)]


def _omega_grid(obs: ObservationSet):
    """Rates to try when the data give none: from the turning of the observed direction, with spins about it."""
    if len(obs.ax_idx) >= 2:
        d0, d1 = obs.ax_dir[0], obs.ax_dir[1]
        dt = obs.t[obs.ax_idx[1]] - obs.t[obs.ax_idx[0]]
        ang = np.arctan2(np.linalg.norm(np.cross(d0, d1)), d0 @ d1)
        rate = max(ang / dt, 1e-3)
        a = obs.axis
        assert a is not None  # directions are observed, so is their body axis
        perp = np.cross(a, [1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.cross(a, [0.0, 1.0, 0.0])
        perp /= np.linalg.norm(perp)
        return [rate * perp + s * rate * a for s in (0.0, 1.0, -1.0, 3.0, -3.0)]
    return [np.array([0.0, 0.0, 1.0])]
