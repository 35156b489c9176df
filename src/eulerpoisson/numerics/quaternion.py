r"""The Hamilton product of quaternions: the one copy every module uses.

Quaternions are scalar first, :math:`q = (w, x, y, z)`, with the Hamilton
product

.. math::
    p\otimes q = \big(p_wq_w - \mathbf p\cdot\mathbf q,\;
                 p_w\mathbf q + q_w\mathbf p + \mathbf p\times\mathbf q\big).

:func:`qmul_components` is the formula itself on scalars or arrays (and is
what the numba kernels compile, so that compiled and numpy paths agree bit
for bit); :func:`qmul` and :func:`qmul_first` apply it to arrays stored
component last ``(..., 4)`` and component first ``(4, ...)``.
"""

from __future__ import annotations

import numpy as np

from ..util.jit import jitable

__all__ = ["qmul_components", "qmul", "qmul_first", "rotate_inverse", "CONJUGATE"]

#: multiply a quaternion by this to conjugate it
CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])


@jitable
def qmul_components(pw, px, py, pz, qw, qx, qy, qz):
    r"""Hamilton product :math:`p\otimes q` of quaternions given by their components.

    Parameters
    ----------
    pw, px, py, pz, qw, qx, qy, qz : float or ndarray
        Components (broadcast against each other).

    Returns
    -------
    tuple of four floats or ndarrays
        :math:`(w, x, y, z)` of the product, each expression evaluated in a
        fixed order (the compiled kernels rely on it).
    """
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


def qmul(p, q):
    r"""Hamilton product of quaternion arrays stored component last.

    Parameters
    ----------
    p, q : ndarray, shape (..., 4)
        Broadcast against each other; no validation (see
        :func:`eulerpoisson.attitude.quaternion_multiply` for the checked
        public version).

    Returns
    -------
    ndarray, shape (..., 4)
    """
    p = np.asarray(p)
    q = np.asarray(q)
    return np.stack(qmul_components(*np.moveaxis(p, -1, 0), *np.moveaxis(q, -1, 0)), -1)


def qmul_first(p, q):
    r"""Hamilton product of quaternion arrays stored component first.

    Parameters
    ----------
    p, q : ndarray, shape (4, ...)
        Broadcast against each other (complex and object arrays work too).

    Returns
    -------
    ndarray, shape (4, ...)
    """
    shape = np.broadcast_shapes(np.shape(p), np.shape(q))
    out = np.empty(shape, dtype=np.result_type(p, q))
    out[0], out[1], out[2], out[3] = qmul_components(p[0], p[1], p[2], p[3], q[0], q[1], q[2], q[3])
    return out


@jitable
def rotate_inverse(qw, qx, qy, qz, s0, s1, s2):
    r""":math:`R(q)^T\mathbf s`, the space vector ``s`` seen in the body frame, for a unit quaternion.

    .. math:: R^T\mathbf s = \mathbf s + 2\big(w\,\mathbf c - \mathbf v\times\mathbf c\big),
              \qquad \mathbf c = \mathbf s\times\mathbf v,\ \ q = (w, \mathbf v).

    Scalars in, a tuple of three out (compiled inline into the kernels).
    """
    cx = s1 * qz - s2 * qy
    cy = s2 * qx - s0 * qz
    cz = s0 * qy - s1 * qx
    dx = qy * cz - qz * cy
    dy = qz * cx - qx * cz
    dz = qx * cy - qy * cx
    return s0 + 2.0 * (qw * cx - dx), s1 + 2.0 * (qw * cy - dy), s2 + 2.0 * (qw * cz - dz)
