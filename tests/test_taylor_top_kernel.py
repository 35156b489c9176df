"""The Taylor kernel of one Poisson vector (the heavy top) against the general kernel and a 40-digit reference.

Gravity alone, or with a constant body torque, takes the specialized kernel of
``solvers/taylor/torque.py`` (one Poisson vector, no orbit), in the body's
principal frame (three Cauchy products for the angular velocity); adding a zero
space torque gives the same motion with two Poisson vectors, which takes the
general kernel in the body frame: the two are independent implementations of
the same recurrences and must agree to round-off, and so must the specialized
kernel run in the body frame of a full tensor (``integrate_polynomial`` called
directly). The attitude is also checked against the mpmath reference of
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
def test_top_kernel_in_the_body_frame_agrees_with_the_principal_frame(with_body_torque):
    from eulerpoisson.solvers.taylor.torque import integrate_polynomial

    mass, com, tau = 1.3, [0.1, -0.2, 0.4], [0.3, -0.1, 0.2]
    top = [Gravity(mass, com)] + ([BodyTorque(tau)] if with_body_torque else [])
    t = np.array([0.0, 0.7, -1.3, 3.0])
    tr = _solve(I_FULL, Q0, W0, top, t)  # rotated into the principal frame and back
    data = ep.Model(I_FULL, top).polynomial().flatten(())
    assert data.S.shape == (1, 1, 3)  # one Poisson vector: the specialized kernel, here with a full tensor
    q, w, stats, status = integrate_polynomial(
        I_FULL[None], Q0[None], W0[None], data, t, tol=EPS, order=20, dt=None, max_steps=10**6
    )
    assert status.tolist() == [0] and stats["steps"] > 0
    for i in range(t.size):
        assert _angle(q[0, i], tr.quaternion[i]) < 1e-12
    np.testing.assert_allclose(w[0], tr.omega, rtol=0, atol=1e-12 * float(np.max(np.abs(tr.omega))))


@pytest.mark.parametrize("with_body_torque", [False, True])
def test_heavy_top_against_40_digit_reference(with_body_torque):
    mass, com, tau = 1.3, [0.1, -0.2, 0.4], [0.3, -0.1, 0.2]
    torque = [Gravity(mass, com)] + ([BodyTorque(tau)] if with_body_torque else [])
    ref = {"gravity": [(mass, com, [0.0, 0.0, -ep.torques.STANDARD_GRAVITY])]}
    if with_body_torque:
        ref["body_torque"] = tau
    t = [2.5, 5.0]
    qr, wr = reference_motion(I_FULL, Q0, W0, t, **ref)
    tr = _solve(I_FULL, Q0, W0, torque, t)
    for i in range(len(t)):
        assert _angle(tr.quaternion[i], np.asarray(qr[i], dtype=float)) < 1e-13
    np.testing.assert_allclose(tr.omega, np.asarray(wr, dtype=float), rtol=0, atol=1e-13 * np.max(np.abs(wr)))
