"""The Taylor kernel of one Poisson vector (the heavy top) against the general kernel and a 40-digit reference.

Gravity alone, or with a constant body torque, takes the specialized kernel of
``solvers/taylor/torque.py`` (one Poisson vector, no orbit; for a diagonal
tensor its principal-frame variant, three Cauchy products for the angular
velocity); adding a zero space torque gives the same motion with two Poisson
vectors, which takes the general kernel: the kernels are independent
implementations of the same recurrences and must agree to round-off. The
attitude is also checked against the mpmath reference of
``tests/_torque_reference.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import eulerpoisson as ep
from _torque_reference import reference_motion
from eulerpoisson.torques import BodyTorque, Gravity, SpaceTorque

EPS = float(np.finfo(float).eps)
I_FULL = np.array([[2.0, 0.1, 0.05], [0.1, 1.5, -0.2], [0.05, -0.2, 1.2]])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
W0 = np.array([0.7, -1.1, 2.0])


@pytest.fixture(autouse=True)
def _compiled(monkeypatch):
    # the compiled kernels (where numba is installed) even for these small problems
    monkeypatch.setenv("EULERPOISSON_NUMPY_BELOW", "0")


def _angle(q, r):
    """Rotation angle between two attitudes (sign-insensitive, accurate for tiny angles)."""
    w = abs(float(np.dot(q, r)))
    v = q[0] * r[1:] - r[0] * q[1:] - np.cross(q[1:], r[1:])
    return 2.0 * float(np.arctan2(np.linalg.norm(v), w))


def _solve(inertia, q0, w0, torque, t):
    return ep.solve(inertia, t, omega0=w0, attitude0=q0, torque=torque, method="taylor", tol=EPS)


def _random_body(seed):
    rng = np.random.default_rng(seed)
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    inertia = rot @ np.diag(np.sort(rng.uniform(1.0, 2.0, 3))) @ rot.T
    inertia = 0.5 * (inertia + inertia.T)
    q0 = rng.normal(size=4)
    q0 /= np.linalg.norm(q0)
    w0 = rng.normal(size=3) * 2.0
    mass = float(rng.uniform(0.5, 2.0))
    com = rng.normal(size=3) * 0.3
    tau = rng.normal(size=3) * 0.3
    return inertia, q0, w0, mass, com, tau


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), with_body_torque=st.booleans())
def test_top_kernel_agrees_with_general_kernel(seed, with_body_torque):
    inertia, q0, w0, mass, com, tau = _random_body(seed)
    top = [Gravity(mass, com)] + ([BodyTorque(tau)] if with_body_torque else [])
    general = [*top, SpaceTorque([0.0, 0.0, 0.0])]
    t = np.array([0.0, 0.7, -1.3, 3.0])
    a = _solve(inertia, q0, w0, top, t)
    b = _solve(inertia, q0, w0, general, t)
    for i in range(t.size):
        assert _angle(a.quaternion[i], b.quaternion[i]) < 1e-12
    scale = max(1.0, float(np.max(np.abs(b.omega))))
    np.testing.assert_allclose(a.omega, b.omega, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("with_body_torque", [False, True])
def test_the_principal_frame_kernel_agrees_with_the_body_frame_kernel(with_body_torque):
    """A body given by its moments takes the principal-frame kernel (three Cauchy products for the angular
    velocity); the same body given as a turned full tensor, with its state, centre of mass and body torque
    turned alike, takes the body-frame kernel: the same motion to round-off."""
    from eulerpoisson.attitude.core import quaternion_from_rotation_matrix
    from eulerpoisson.numerics.quaternion import qmul

    D = np.array([1.1, 1.6, 2.3])
    P, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    P *= np.sign(np.linalg.det(P))  # a rotation: x_body = P x_principal
    qPc = quaternion_from_rotation_matrix(P) * np.array([1.0, -1.0, -1.0, -1.0])
    com, tau, w0 = np.array([0.1, -0.2, 0.4]), np.array([0.3, -0.1, 0.2]), np.array([0.7, -1.1, 2.0])
    t = np.array([0.0, 0.7, -1.3, 3.0])

    def top(R):
        return [Gravity(1.3, R @ com)] + ([BodyTorque(R @ tau)] if with_body_torque else [])

    a = _solve(D, Q0, w0, top(np.eye(3)), t)  # principal moments: the principal-frame kernel
    b = _solve(P @ np.diag(D) @ P.T, qmul(Q0, qPc), P @ w0, top(P), t)  # a full tensor: the body-frame kernel
    for i in range(t.size):
        assert _angle(qmul(a.quaternion[i], qPc), b.quaternion[i]) < 1e-12
    np.testing.assert_allclose(b.omega, a.omega @ P.T, rtol=0, atol=1e-12 * float(np.max(np.abs(a.omega))))


@pytest.mark.parametrize("inertia", [I_FULL, [1.1, 1.6, 2.3]], ids=["full-tensor", "principal-moments"])
@pytest.mark.parametrize("with_body_torque", [False, True])
def test_heavy_top_against_40_digit_reference(with_body_torque, inertia):
    tensor = np.diag(inertia) if np.ndim(inertia) == 1 else np.asarray(inertia)  # (the reference takes a tensor)
    mass, com, tau = 1.3, [0.1, -0.2, 0.4], [0.3, -0.1, 0.2]
    torque = [Gravity(mass, com)] + ([BodyTorque(tau)] if with_body_torque else [])
    ref = {"gravity": [(mass, com, [0.0, 0.0, -ep.torques.STANDARD_GRAVITY])]}
    if with_body_torque:
        ref["body_torque"] = tau
    t = [2.5, 5.0]
    qr, wr = reference_motion(tensor, Q0, W0, t, **ref)
    tr = _solve(inertia, Q0, W0, torque, t)
    for i in range(len(t)):
        assert _angle(tr.quaternion[i], np.asarray(qr[i], dtype=float)) < 1e-13
    np.testing.assert_allclose(tr.omega, np.asarray(wr, dtype=float), rtol=0, atol=1e-13 * np.max(np.abs(wr)))
