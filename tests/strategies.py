"""Shared Hypothesis strategies for eulerpoisson tests.

In the style of jaxlie's ``tests/utils.py``: every strategy draws a batch
shape and a seed from Hypothesis and builds the arrays with a seeded numpy
generator, so examples are cheap, reproducible and shrink on the shape and
on the sample *kind*.

Batch shapes are ``()``, ``(1,)``, ``(5,)`` and ``(2, 3)``
(:data:`BATCH_SHAPES`). Attitude samples come in kinds (:data:`ATTITUDE_KINDS`):

``"uniform"``
    Haar-uniform rotations (normalized Gaussian quaternions).
``"near_identity"``
    Rotation angle about ``1e-8`` (:data:`NEAR_IDENTITY_ANGLE`), random axis.
``"near_pi"``
    Rotation angle ``pi -/+ ~1e-7`` (:data:`NEAR_PI_OFFSET`), *both sides*:
    the quaternion scalar part ``w`` has either sign, so the Gibbs vector is
    huge (``|n| ~ 2e7``) and points along ``+k`` or ``-k``.
``"mixed"``
    Each batch element independently one of the three above.

Everything is generated independently of the code under test: quaternions
from ``(cos(a/2), k sin(a/2))``, Gibbs vectors as ``k tan(a/2)``, matrices
from Rodrigues' formula (paper eq. 1.7).

The strategies are plain functions returning Hypothesis strategies, so they
compose: ``@given(q=quaternions(kind="near_pi"), shape=...)``. Pass
``shape=`` to fix a batch shape (e.g. to draw two broadcast-compatible
samples), or leave it ``None`` to draw one.
"""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

__all__ = [
    "BATCH_SHAPES",
    "ATTITUDE_KINDS",
    "INERTIA_KINDS",
    "OMEGA_KINDS",
    "NEAR_IDENTITY_ANGLE",
    "NEAR_PI_OFFSET",
    "EULER_SEQUENCES",
    "batch_shapes",
    "attitude_kinds",
    "rngs",
    "axis_angles",
    "quaternions",
    "gibbs_vectors",
    "rotation_matrices",
    "rotvecs",
    "mrps",
    "euler_angles",
    "euler_sequences",
    "principal_moments",
    "inertia_tensors",
    "angular_velocities",
    "random_rotation_matrices",
    "rodrigues_matrix",
]

BATCH_SHAPES: tuple[tuple[int, ...], ...] = ((), (1,), (5,), (2, 3))
ATTITUDE_KINDS = ("uniform", "near_identity", "near_pi", "mixed")
INERTIA_KINDS = ("asymmetric", "prolate", "oblate", "sphere", "planar", "near_symmetric")
OMEGA_KINDS = ("uniform", "small", "near_axis", "near_separatrix")
NEAR_IDENTITY_ANGLE = 1e-8
NEAR_PI_OFFSET = 1e-7
EULER_SEQUENCES = tuple(a + b + c for a in "xyz" for b in "xyz" for c in "xyz" if a != b and b != c) + tuple(
    (a + b + c).upper() for a in "xyz" for b in "xyz" for c in "xyz" if a != b and b != c
)


def batch_shapes() -> st.SearchStrategy[tuple[int, ...]]:
    """One of :data:`BATCH_SHAPES` (shrinks towards ``()``)."""
    return st.sampled_from(BATCH_SHAPES)


def attitude_kinds() -> st.SearchStrategy[str]:
    """One of :data:`ATTITUDE_KINDS`."""
    return st.sampled_from(ATTITUDE_KINDS)


def euler_sequences() -> st.SearchStrategy[str]:
    """One of the 24 scipy sequence strings (12 extrinsic, 12 intrinsic)."""
    return st.sampled_from(EULER_SEQUENCES)


def rngs() -> st.SearchStrategy[np.random.Generator]:
    """A seeded :class:`numpy.random.Generator` (the seed is what Hypothesis shrinks)."""
    return st.integers(0, 2**32 - 1).map(np.random.default_rng)


def _unit(rng, shape):
    v = rng.standard_normal(shape + (3,))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _angles(rng, shape, kind):
    """Rotation angles (not reduced) for one kind."""
    if kind == "uniform":
        # angle distribution of a Haar rotation, from a Gaussian quaternion
        q = rng.standard_normal(shape + (4,))
        return 2.0 * np.arctan2(np.linalg.norm(q[..., 1:], axis=-1), q[..., 0])
    if kind == "near_identity":
        return NEAR_IDENTITY_ANGLE * rng.uniform(0.5, 2.0, shape) * rng.choice([-1.0, 1.0], shape)
    if kind == "near_pi":
        side = rng.choice([-1.0, 1.0], shape)
        return np.pi + side * NEAR_PI_OFFSET * rng.uniform(0.5, 2.0, shape)
    if kind == "mixed":
        pick = rng.integers(0, 3, shape)
        out = np.empty(shape)
        for i, k in enumerate(("uniform", "near_identity", "near_pi")):
            out = np.where(pick == i, _angles(rng, shape, k), out)
        return out
    raise ValueError(f"unknown attitude kind {kind!r}")


@st.composite
def _axis_angle_draw(draw, shape, kind):
    shape = draw(batch_shapes()) if shape is None else tuple(shape)
    kind = draw(attitude_kinds()) if kind is None else kind
    rng = draw(rngs())
    return _unit(rng, shape), _angles(rng, shape, kind)


def axis_angles(shape=None, kind=None) -> st.SearchStrategy[tuple[np.ndarray, np.ndarray]]:
    """``(axis, angle)``: unit axes (..., 3) and angles (...).

    Angles are *not* reduced: near the identity they have either sign and
    near pi they lie on either side of pi (in ``(pi - 2e-7, pi + 2e-7)``).
    """
    return _axis_angle_draw(shape, kind)


def _quat(axis, angle):
    return np.concatenate([np.cos(angle / 2)[..., None], axis * np.sin(angle / 2)[..., None]], -1)


@st.composite
def _quaternion_draw(draw, shape, kind, random_sign):
    axis, angle = draw(axis_angles(shape, kind))
    q = _quat(axis, angle)
    if random_sign:
        rng = draw(rngs())
        q = q * rng.choice([-1.0, 1.0], q.shape[:-1])[..., None]
    return q


def quaternions(shape=None, kind=None, random_sign=True) -> st.SearchStrategy[np.ndarray]:
    """Unit scalar-first quaternions (..., 4); random overall sign unless ``random_sign=False``."""
    return _quaternion_draw(shape, kind, random_sign)


def gibbs_vectors(shape=None, kind=None) -> st.SearchStrategy[np.ndarray]:
    """Gibbs vectors ``k tan(a/2)`` (..., 3); ``|n| ~ 2e7`` for ``near_pi``, ``~5e-9`` near identity."""
    return axis_angles(shape, kind).map(lambda ka: ka[0] * np.tan(ka[1] / 2)[..., None])


def rodrigues_matrix(axis, angle) -> np.ndarray:
    """Rotation matrix of paper eq. 1.7 (independent reference implementation)."""
    axis = np.asarray(axis, float)
    angle = np.asarray(angle, float)
    c, s = np.cos(angle)[..., None, None], np.sin(angle)[..., None, None]
    kx, ky, kz = axis[..., 0], axis[..., 1], axis[..., 2]
    o = np.zeros_like(kx)
    K = np.stack([np.stack([o, -kz, ky], -1), np.stack([kz, o, -kx], -1), np.stack([-ky, kx, o], -1)], -2)
    return c * np.eye(3) + (1 - c) * axis[..., :, None] * axis[..., None, :] + s * K


def rotation_matrices(shape=None, kind=None) -> st.SearchStrategy[np.ndarray]:
    """Rotation matrices (..., 3, 3) from Rodrigues' formula (paper eq. 1.7)."""
    return axis_angles(shape, kind).map(lambda ka: rodrigues_matrix(*ka))


def rotvecs(shape=None, kind=None) -> st.SearchStrategy[np.ndarray]:
    """scipy-style rotation vectors ``a k`` (..., 3) with ``|a|`` up to ``pi + 2e-7``."""
    return axis_angles(shape, kind).map(lambda ka: ka[0] * ka[1][..., None])


def mrps(shape=None, kind=None) -> st.SearchStrategy[np.ndarray]:
    """Modified Rodrigues parameters ``k tan(a/4)`` (..., 3); ``|p|`` slightly above 1 happens near pi."""
    return axis_angles(shape, kind).map(lambda ka: ka[0] * np.tan(ka[1] / 4)[..., None])


@st.composite
def _euler_draw(draw, shape, seq):
    shape = draw(batch_shapes()) if shape is None else tuple(shape)
    seq = draw(euler_sequences()) if seq is None else seq
    rng = draw(rngs())
    a = rng.uniform(-np.pi, np.pi, shape + (3,))
    if seq[0].lower() == seq[2].lower():
        a[..., 1] = rng.uniform(0, np.pi, shape)
    else:
        a[..., 1] = rng.uniform(-np.pi / 2, np.pi / 2, shape)
    return seq, a


def euler_angles(shape=None, seq=None) -> st.SearchStrategy[tuple[str, np.ndarray]]:
    """``(seq, angles)``: a sequence and angles (..., 3) in the canonical ranges (generic, not at gimbal lock)."""
    return _euler_draw(shape, seq)


def random_rotation_matrices(rng: np.random.Generator, shape=()) -> np.ndarray:
    """Haar-random rotation matrices (..., 3, 3) with det +1 (QR of a Gaussian matrix)."""
    shape = tuple(shape)
    Q, Rr = np.linalg.qr(rng.standard_normal(shape + (3, 3)))
    Q = Q * np.sign(np.diagonal(Rr, axis1=-2, axis2=-1))[..., None, :]
    return Q * np.sign(np.linalg.det(Q))[..., None, None]


def _moments(rng, shape, kind):
    a = rng.uniform(0.5, 3.0, shape)
    b = rng.uniform(0.5, 3.0, shape)
    if kind == "asymmetric":
        # I1 < I2 < I3 < I1 + I2, every gap at least 10 % of I1
        i2 = a * rng.uniform(1.1, 2.0, shape)
        return np.stack([a, i2, i2 + a * rng.uniform(0.1, 0.9, shape)], -1)
    if kind == "prolate":  # rod-like: unique moment smallest
        return np.stack([a, a, a * rng.uniform(0.1, 0.9, shape)], -1)
    if kind == "oblate":  # disk-like: unique moment largest, <= 2a
        return np.stack([a, a, a * rng.uniform(1.1, 2.0, shape)], -1)
    if kind == "sphere":
        return np.stack([a, a, a], -1)
    if kind == "planar":  # I3 = I1 + I2 exactly
        return np.stack([a, b, a + b], -1)
    if kind == "near_symmetric":  # two moments 1e-8 apart (a thin separatrix region)
        return np.stack([a, a * (1 + 1e-8), a * rng.uniform(1.2, 1.8, shape)], -1)
    raise ValueError(f"unknown inertia kind {kind!r}")


@st.composite
def _moments_draw(draw, shape, kind, sort):
    shape = draw(batch_shapes()) if shape is None else tuple(shape)
    kind = draw(st.sampled_from(INERTIA_KINDS)) if kind is None else kind
    rng = draw(rngs())
    m = _moments(rng, shape, kind)
    if sort:
        return np.sort(m, -1)
    perm = rng.permutation(3)
    return m[..., perm]


def principal_moments(shape=None, kind=None, sort=False) -> st.SearchStrategy[np.ndarray]:
    """Physical principal moments (..., 3) of one of :data:`INERTIA_KINDS`.

    Values in about [0.05, 6]; in random order unless ``sort=True``. All
    satisfy the triangle inequalities (``planar`` as an exact equality).
    """
    return _moments_draw(shape, kind, sort)


@st.composite
def _tensor_draw(draw, shape, kind, frame, return_parts):
    shape = draw(batch_shapes()) if shape is None else tuple(shape)
    m = draw(principal_moments(shape, kind))
    frame = draw(st.sampled_from(["diagonal", "rotated"])) if frame is None else frame
    if frame == "diagonal":
        P = np.broadcast_to(np.eye(3), shape + (3, 3)).copy()
    elif frame == "rotated":
        P = random_rotation_matrices(draw(rngs()), shape)
    else:
        raise ValueError(f"unknown frame {frame!r}")
    I = P @ (m[..., :, None] * np.swapaxes(P, -1, -2))
    I = 0.5 * (I + np.swapaxes(I, -1, -2))
    return (I, m, P) if return_parts else I


def inertia_tensors(shape=None, kind=None, frame=None, return_parts=False):
    """Symmetric inertia tensors (..., 3, 3) ``P diag(m) P^T``.

    ``frame="diagonal"`` gives ``P = 1``, ``"rotated"`` a Haar-random
    rotation, ``None`` either. With ``return_parts=True`` the strategy gives
    ``(I, m, P)``.
    """
    return _tensor_draw(shape, kind, frame, return_parts)


@st.composite
def _omega_draw(draw, shape, kind, moments):
    if moments is not None:
        moments = np.asarray(moments, float)
        shape = moments.shape[:-1]
    elif shape is None:
        shape = draw(batch_shapes())
    shape = tuple(shape)
    kind = draw(st.sampled_from(OMEGA_KINDS if moments is not None else OMEGA_KINDS[:3])) if kind is None else kind
    rng = draw(rngs())
    if kind == "uniform":
        return rng.standard_normal(shape + (3,)) * rng.uniform(0.1, 3.0, shape)[..., None]
    if kind == "small":
        return 1e-8 * rng.standard_normal(shape + (3,))
    if kind == "near_axis":
        ax = rng.integers(0, 3, shape)
        w = 1e-6 * rng.standard_normal(shape + (3,))
        return w + np.eye(3)[ax] * rng.uniform(0.5, 2.0, shape)[..., None]
    if kind == "near_separatrix":
        if moments is None:
            raise ValueError("near_separatrix angular velocities need the principal moments")
        order = np.argsort(moments, -1)
        I = np.take_along_axis(moments, order, -1)
        I1, I2, I3 = I[..., 0], I[..., 1], I[..., 2]
        eps = 1e-6 * rng.uniform(0.5, 2.0, shape) * rng.choice([-1.0, 1.0], shape)
        D = I2 * (1 + eps)  # M^2 / (2E); the separatrix is D = I2
        w1 = rng.uniform(0.5, 1.5, shape) * rng.choice([-1.0, 1.0], shape)
        w2 = rng.uniform(0.0, 1.0, shape) * rng.choice([-1.0, 1.0], shape)
        w3sq = (I1 * (D - I1) * w1**2 + I2 * (D - I2) * w2**2) / (I3 * (I3 - D))
        w = np.stack([w1, w2, np.sqrt(np.maximum(w3sq, 0.0)) * rng.choice([-1.0, 1.0], shape)], -1)
        out = np.empty_like(w)
        np.put_along_axis(out, order, w, -1)
        return out
    raise ValueError(f"unknown angular velocity kind {kind!r}")


def angular_velocities(shape=None, kind=None, moments=None) -> st.SearchStrategy[np.ndarray]:
    """Body angular velocities (..., 3) of one of :data:`OMEGA_KINDS`.

    ``"near_separatrix"`` needs ``moments`` (..., 3) of an asymmetric body,
    given in the principal frame in any order: then
    ``M^2/(2E) = I_mid (1 +- ~1e-6)``, just inside or outside the separatrix.
    With ``moments`` given the batch shape is theirs.
    """
    return _omega_draw(shape, kind, moments)
