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


def qmul_floats(p, q):
    """The Hamilton product of two 4-sequences of floats, as a tuple (plain Python: for right-hand sides that
    scipy calls many times, where NumPy's small-array calls cost more than the arithmetic)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
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
    (a, b, c), (d, e, g), (h, k, m) = I.tolist()
    (ia, ib, ic), (id_, ie, ig), (ih, ik, im) = Iinv.tolist()

    def f(_, y):
        # in plain floats (about 5x faster than with NumPy's small-array calls): M = I w, I dw/dt = M x w,
        # dq/dt = q (x) (0, w) / 2
        qw, qx, qy, qz, w0, w1, w2 = y.tolist()
        M0, M1, M2 = a * w0 + b * w1 + c * w2, d * w0 + e * w1 + g * w2, h * w0 + k * w1 + m * w2
        c0, c1, c2 = M1 * w2 - M2 * w1, M2 * w0 - M0 * w2, M0 * w1 - M1 * w0
        return np.array(
            [
                0.5 * (-qx * w0 - qy * w1 - qz * w2),
                0.5 * (qw * w0 + qy * w2 - qz * w1),
                0.5 * (qw * w1 - qx * w2 + qz * w0),
                0.5 * (qw * w2 + qx * w1 - qy * w0),
                ia * c0 + ib * c1 + ic * c2,
                id_ * c0 + ie * c1 + ig * c2,
                ih * c0 + ik * c1 + im * c2,
            ]
        )

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
