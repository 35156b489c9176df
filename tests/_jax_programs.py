"""Compiled JAX programs shared by the JAX test files: each is compiled once per test session.

Almost all the time of the JAX tests is XLA compiling the closed form of the free rigid body (about
10 s of CPU a program, its forward derivatives 30 s, its reverse ones 40 s): every new jit wrapper,
input shape or dtype compiles it again. The test files therefore take their derivatives of
``eulerpoisson.jax.exact_motion`` from the few programs here, built once (``functools.cache``) and
always called at the same shapes: one body (inertia (3,) or (3, 3)) at ``T_FORWARD`` or ``T_REVERSE``
times (shorter time arrays are padded with zeros and the results cut back). A Jacobian column is one
``jvp`` call of the one forward program (``jax.jacfwd`` is ``jvp`` mapped over the basis), a row one
``vjp`` call of the one reverse program (``jax.jacrev`` and ``jax.grad`` are ``vjp`` of the basis and of
ones). Under ``make test`` (``--dist loadgroup``, tests/conftest.py) test_jax_exact.py and
test_jax_derivatives.py, which share these programs, run on one pytest-xdist worker.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from eulerpoisson.jax.exact import exact_motion

#: times of a forward-derivative call
T_FORWARD = 7
#: times of a reverse-derivative call
T_REVERSE = 3


def _padded(t, n: int) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size > n:
        raise ValueError(f"t must have shape (k,) with k <= {n}, got {t.shape}")
    return np.concatenate([t, np.zeros(n - t.size)])


def _f64(xs):
    return tuple(jnp.asarray(np.asarray(x, dtype=float), jnp.float64) for x in xs)


@functools.cache
def _forward():
    return jax.jit(lambda args, tans: jax.jvp(exact_motion, args, tans))


@functools.cache
def _reverse():
    def pullback(args, cotangents):
        _, vjp = jax.vjp(exact_motion, *args)
        return vjp(cotangents)

    return jax.jit(pullback)


def jvp(inertia, q0, w0, t, d_inertia, d_q0, d_w0, d_t):
    """``jax.jvp`` of ``exact_motion`` (float64): ``(q, w, dq, dw)`` as NumPy arrays, ``t`` of shape (k <= T_FORWARD,)."""
    k = len(t)
    with jax.enable_x64(True):
        args = _f64((inertia, q0, w0, _padded(t, T_FORWARD)))
        tans = _f64((d_inertia, d_q0, d_w0, _padded(d_t, T_FORWARD)))
        (q, w), (dq, dw) = _forward()(args, tans)
    return np.asarray(q)[:k], np.asarray(w)[:k], np.asarray(dq)[:k], np.asarray(dw)[:k]


def vjp(inertia, q0, w0, t, ct_q, ct_w):
    """``jax.vjp`` of ``exact_motion`` (float64) pulling back the cotangents ``(ct_q, ct_w)`` of shapes
    (T_REVERSE, 4) and (T_REVERSE, 3): the NumPy arrays ``(d_inertia, d_q0, d_w0, d_t)``."""
    if np.shape(t) != (T_REVERSE,):
        raise ValueError(f"t must have shape ({T_REVERSE},), got {np.shape(t)}")
    with jax.enable_x64(True):
        out = _reverse()(_f64((inertia, q0, w0, t)), _f64((ct_q, ct_w)))
    return tuple(np.asarray(a) for a in out)


def jacrev(inertia, q0, w0, t):
    """``jax.jacrev`` of ``exact_motion`` with respect to every input, one ``vjp`` per output entry:
    ``[output][input]`` arrays of shapes output shape + input shape (as ``jax.jacrev`` returns)."""
    n = len(t)
    rows = []
    for shape in ((n, 4), (n, 3)):
        cols = [[] for _ in range(4)]
        for flat in range(int(np.prod(shape))):
            ct = [np.zeros((n, 4)), np.zeros((n, 3))]
            ct[len(rows)][np.unravel_index(flat, shape)] = 1.0
            for k, g in enumerate(vjp(inertia, q0, w0, t, *ct)):
                cols[k].append(g)
        rows.append([np.stack(c).reshape(shape + c[0].shape) for c in cols])
    return rows
