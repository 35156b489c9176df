r"""Quaternion products in JAX (scalar-first ``(w, x, y, z)``, Hamilton's product), shared by the JAX modules.

.. math:: pq = (p_w q_w - \mathbf p\cdot\mathbf q,\; p_w\mathbf q + q_w\mathbf p + \mathbf p\times\mathbf q)
"""

from __future__ import annotations

import jax.numpy as jnp

__all__ = ["qconj", "qmul", "qmul_components"]


def qmul_components(pw, px, py, pz, qw, qx, qy, qz):
    """Hamilton's product of two quaternions given by components (arrays that broadcast); a 4-tuple.

    Examples
    --------
    >>> from eulerpoisson.jax.quaternion import qmul_components
    >>> [float(c) for c in qmul_components(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)]  # i j = k
    [0.0, 0.0, 0.0, 1.0]
    """
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


def qmul(p, q):
    """Hamilton's product of quaternion arrays ``p, q`` of shapes ``(..., 4)`` (broadcast).

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.quaternion import qmul
    >>> qmul(jnp.array([0.0, 0.0, 1.0, 0.0]), jnp.array([0.0, 0.0, 0.0, 1.0])).tolist()  # j k = i
    [0.0, 1.0, 0.0, 0.0]
    """
    return jnp.stack(qmul_components(*(p[..., k] for k in range(4)), *(q[..., k] for k in range(4))), -1)


def qconj(q):
    """The conjugate ``(w, -x, -y, -z)`` of quaternions ``(..., 4)``.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from eulerpoisson.jax.quaternion import qconj
    >>> qconj(jnp.array([1.0, 2.0, 3.0, 4.0])).tolist()
    [1.0, -2.0, -3.0, -4.0]
    """
    return q * jnp.asarray([1.0, -1.0, -1.0, -1.0], q.dtype)
