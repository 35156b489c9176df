"""Independent reference solutions for tests (plain scipy, no eulerpoisson code)."""

import numpy as np
from scipy.integrate import solve_ivp


def _qmul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.array(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ]
    )


def reference_motion(inertia, omega0, q0, t, rtol=1e-13, atol=1e-13):
    """Euler's equations I dW/dt = (I W) x W and dq/dt = q (x) (0, W)/2 by DOP853.

    inertia: (3,) or (3, 3); omega0: (3,); q0: (4,); t: (T,) sorted or not,
    any sign. Returns (q (T, 4), omega (T, 3)).
    """
    I = np.asarray(inertia, float)
    if I.ndim == 1:
        I = np.diag(I)
    Iinv = np.linalg.inv(I)

    def f(_, y):
        q, w = y[:4], y[4:]
        M = I @ w
        return np.concatenate([0.5 * _qmul(q, np.concatenate([[0.0], w])), Iinv @ np.cross(M, w)])

    t = np.asarray(t, float)
    y0 = np.concatenate([q0, omega0])
    out = np.empty((t.size, 7))
    for sign in (1.0, -1.0):
        sel = (t > 0) if sign > 0 else (t < 0)
        out[t == 0] = y0
        if not np.any(sel):
            continue
        ts = t[sel]
        order = np.argsort(sign * ts)
        tt = ts[order]
        sol = solve_ivp(f, (0.0, tt[-1]), y0, method="DOP853", t_eval=tt, rtol=rtol, atol=atol)
        res = np.empty((tt.size, 7))
        res[order] = sol.y.T
        out[sel] = res
    q = out[:, :4] / np.linalg.norm(out[:, :4], axis=1, keepdims=True)
    return q, out[:, 4:]


def quaternion_distance(q1, q2):
    """Angle of the rotation between attitudes given as quaternions (..., 4); sign-insensitive."""
    q1 = np.asarray(q1, float)
    q2 = np.asarray(q2, float)
    w = np.sum(q1 * q2, axis=-1)
    v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
    return 2 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))
