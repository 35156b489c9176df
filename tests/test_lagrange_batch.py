"""Batches of distinct Lagrange tops: recognized in one vectorized pass, solved as each top alone.

``Model.lagrange_top`` used to loop over the elements of a batch in Python (about 0.2 ms per top,
twice per solve); it is now vectorized. Each element must give the same bits as the top alone (the
exact method's results do not depend on the batch), and a batch with one element that is not a
Lagrange top is not one.
"""

from __future__ import annotations

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.attitude import matrix_from_quaternion
from eulerpoisson.errors import UnsupportedModelError
from eulerpoisson.torques import Gravity


def _tilted_tops(n, seed=3):
    """Symmetric bodies (A, A, C) turned by random rotations, centres of mass on the turned axis."""
    rng = np.random.default_rng(seed)
    A = rng.uniform(1.0, 2.0, n)
    C = A * rng.uniform(0.3, 1.9, n)  # oblate and prolate, within the triangle inequality C <= 2A
    qr = rng.normal(size=(n, 4))
    R = matrix_from_quaternion(qr / np.linalg.norm(qr, axis=-1, keepdims=True))
    diag = np.stack([A, A, C], -1)[:, :, None] * np.eye(3)
    inertia = R @ diag @ np.swapaxes(R, -1, -2)
    com = np.einsum("bij,j->bi", R, [0.0, 0.0, 1.0]) * rng.uniform(0.05, 0.3, n)[:, None]
    mass = rng.uniform(0.5, 2.0, n)
    w0 = np.stack([rng.normal(0, 1, n), rng.normal(0, 1, n), rng.uniform(5, 30, n)], -1)
    return inertia, com, mass, w0


def test_batched_lagrange_top_equals_each_element():
    inertia, com, mass, _ = _tilted_tops(40)
    # spheres and an axis-aligned top among them
    inertia[3] = 1.7 * np.eye(3)
    inertia[4] = np.diag([2.0, 2.0, 1.0])
    com[4] = [0.0, 0.0, -0.2]
    model = ep.Model(ep.RigidBody(inertia), Gravity(mass, com))
    lt = model.lagrange_top()
    assert lt is not None
    assert lt.A.shape == lt.C.shape == lt.mass.shape == lt.ell.shape == (40,)
    assert lt.g.shape == (40, 3) and lt.frame.shape == (40, 3, 3)
    for i in range(40):
        one = ep.Model(ep.RigidBody(inertia[i]), Gravity(mass[i], com[i])).lagrange_top()
        for field in lt._fields:
            np.testing.assert_array_equal(getattr(lt, field)[i], getattr(one, field), err_msg=f"{field} of top {i}")
    # the frame is a rotation taking e3 to the centre-of-mass direction, and I = F diag(A, A, C) F^T
    F = lt.frame
    np.testing.assert_allclose(F @ np.swapaxes(F, -1, -2), np.broadcast_to(np.eye(3), F.shape), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(F), 1.0, atol=1e-14)
    np.testing.assert_allclose(F[..., 2] * lt.ell[:, None], com, atol=1e-15)
    diag = np.stack([lt.A, lt.A, lt.C], -1)[:, :, None] * np.eye(3)
    np.testing.assert_allclose(F @ diag @ np.swapaxes(F, -1, -2), inertia, atol=1e-13)


def test_a_batch_with_one_asymmetric_body_is_not_a_lagrange_top():
    inertia, com, mass, w0 = _tilted_tops(8)
    inertia[5] = np.diag([1.0, 2.0, 3.0])
    model = ep.Model(ep.RigidBody(inertia), Gravity(mass, com))
    assert model.lagrange_top() is None
    with pytest.raises(UnsupportedModelError, match="Lagrange top"):
        ep.solve(model, [1.0], omega0=w0, method="exact")
    com2 = com.copy()
    com2[2] = 0.0  # centre of mass at the fixed point: not a top
    assert ep.Model(ep.RigidBody(_tilted_tops(8)[0]), Gravity(mass, com2)).lagrange_top() is None


@pytest.mark.parametrize("workers", [1, 2])
def test_batch_of_tops_solves_as_each_top_alone(workers):
    inertia, com, mass, w0 = _tilted_tops(37)
    t = np.linspace(-2.0, 3.0, 6)
    tr = ep.solve(ep.RigidBody(inertia), t, omega0=w0, torque=Gravity(mass, com), method="exact", workers=workers)
    assert tr.stats["model"] == "lagrange top"
    for i in (0, 11, 36):
        one = ep.solve(ep.RigidBody(inertia[i]), t, omega0=w0[i], torque=Gravity(mass[i], com[i]), method="exact")
        np.testing.assert_array_equal(one.quaternion, tr.quaternion[i])
        np.testing.assert_array_equal(one.omega, tr.omega[i])
