"""The fit's Jacobian (variational equations) against high-precision central differences.

The residuals are recomputed here in mpmath from their definitions, on the
motion of ``tests/_torque_reference.py`` (an independent 30-digit Taylor
integrator that shares no code with eulerpoisson), for parameters moved by
+-1e-10; the analytic Jacobian must agree to 1e-8 relative, column by column.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from _torque_reference import reference_motion_mp
from eulerpoisson.estimation.data import observation_set
from eulerpoisson.estimation.residuals import FitState, Layout, evaluate, inertia_matrix

DPS = 30
H = mpmath.mpf("1e-10")


def _qmul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return [
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ]


def _exp(theta):
    a = mpmath.sqrt(sum(x * x for x in theta))
    if a == 0:
        return [mpmath.mpf(1), mpmath.mpf(0), mpmath.mpf(0), mpmath.mpf(0)]
    s = mpmath.sin(a / 2) / a
    return [mpmath.cos(a / 2)] + [s * x for x in theta]


def _log(q):
    if q[0] < 0:
        q = [-x for x in q]
    s = mpmath.sqrt(q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    a = 2 * mpmath.atan2(s, q[0])
    return [x * a / s for x in q[1:]]


def _rot(q):
    w, x, y, z = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def _mv(A, v):
    return [sum(A[i][j] * v[j] for j in range(3)) for i in range(3)]


def _tangent(d):
    d = [float(x) for x in d]
    helper = [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0]
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(d, e1)


def _residuals_mp(obs, q0, w0, I):
    """Whitened residuals, in the order of evaluate(): attitude, rate, direction rows."""
    tau = obs.t - obs.t[0]
    qs, ws = reference_motion_mp(I, q0, w0, tau, dps=DPS)
    out = []
    for k, i in enumerate(obs.att_idx):
        qo = [mpmath.mpf(float(x)) for x in obs.att_q[k]]
        r = _log(_qmul([qo[0], -qo[1], -qo[2], -qo[3]], qs[i]))
        out += [x / obs.att_sigma[k] for x in r]
    for k, i in enumerate(obs.om_idx):
        w = ws[i]
        if obs.omega_frame == "space":
            w = _mv(_rot(qs[i]), w)
        out += [(w[a] - obs.om_value[k, a]) / obs.om_sigma[k, a] for a in range(3)]
    for k, i in enumerate(obs.ax_idx):
        d = _mv(_rot(qs[i]), [mpmath.mpf(float(x)) for x in obs.axis])
        for e in _tangent(obs.ax_dir[k]):
            out.append(sum(mpmath.mpf(float(e[a])) * d[a] for a in range(3)) / obs.ax_sigma[k])
    return out


def _case(frame, mode, rng):
    t = np.array([0.0, 0.4, 1.1, 1.7, 2.5, 3.2])
    n = t.size
    qobs = rng.standard_normal((n, 4))
    qobs /= np.linalg.norm(qobs, axis=1, keepdims=True)
    wobs = rng.standard_normal((n, 3))
    d = rng.standard_normal((n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    qobs[1] = np.nan
    wobs[2] = np.nan
    obs = observation_set(
        t,
        attitude=qobs,
        attitude_sigma=0.03,
        omega=wobs,
        omega_sigma=[0.02, 0.05, 0.1],
        omega_frame=frame,
        axis=[0.3, -0.2, 0.9],
        axis_direction=d,
        axis_sigma=np.linspace(0.01, 0.02, n),
    )
    layout = Layout(True, mode)
    p = np.array([0.27, 0.34]) if mode == "given" else np.array([0.27, 0.34, 0.02, -0.015, 0.03])
    q0 = np.array([0.8, 0.3, -0.4, 0.33])
    q0 /= np.linalg.norm(q0)
    return obs, layout, FitState(q0, np.array([0.7, -1.2, 0.9]), p)


@pytest.mark.parametrize("frame,mode", [("body", "fit"), ("space", "given")])
def test_jacobian_matches_high_precision_differences(frame, mode):
    rng = np.random.default_rng(7)
    obs, layout, state = _case(frame, mode, rng)
    ev = evaluate(layout, obs, state)
    mp = mpmath.mp
    with mp.workdps(DPS + 10):
        q0 = [mpmath.mpf(float(x)) for x in state.q0]
        w0 = [mpmath.mpf(float(x)) for x in state.omega0]
        p0 = [mpmath.mpf(float(x)) for x in state.inertia_params]

        def inertia_mp(p):
            if mode == "given":
                return [[p[0], 0, 0], [0, p[1], 0], [0, 0, 1 - p[0] - p[1]]]
            return [[p[0], p[2], p[3]], [p[2], p[1], p[4]], [p[3], p[4], 1 - p[0] - p[1]]]

        base = _residuals_mp(obs, q0, w0, [[mpmath.mpf(x) for x in row] for row in inertia_mp(p0)])
        # the residuals themselves first: the double-precision ones agree with the reference
        assert np.max(np.abs(np.array([float(x) for x in base]) - ev.residuals)) < 1e-11
        cols = []
        for j in range(layout.n_params):
            vals = []
            for sgn in (1, -1):
                dq, dw, dp = [0, 0, 0], [0, 0, 0], [0] * len(p0)
                if j < 3:
                    dq[j] = sgn * H
                elif j < 6:
                    dw[j - 3] = sgn * H
                else:
                    dp[j - 6] = sgn * H
                q = _qmul(q0, _exp([mpmath.mpf(x) for x in dq]))
                w = [w0[a] + dw[a] for a in range(3)]
                p = [p0[a] + dp[a] for a in range(len(p0))]
                vals.append(_residuals_mp(obs, q, w, inertia_mp(p)))
            cols.append([float((a - b) / (2 * H)) for a, b in zip(*vals)])
    fd = np.array(cols).T
    assert fd.shape == ev.jacobian.shape
    for j, name in enumerate(layout.names):
        err = np.linalg.norm(ev.jacobian[:, j] - fd[:, j]) / np.linalg.norm(fd[:, j])
        assert err < 1e-8, (name, err)
    # and the check can fail: a wrong sign in one column is seen
    wrong = ev.jacobian.copy()
    wrong[:, 0] *= -1
    assert np.linalg.norm(wrong[:, 0] - fd[:, 0]) / np.linalg.norm(fd[:, 0]) > 1.0
    I, _ = inertia_matrix(layout, state.inertia_params)
    assert np.isclose(np.trace(I), 1.0)
