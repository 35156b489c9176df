"""Property tests of the torques and the model over batch shapes and near-identity / near-pi attitudes."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import eulerpoisson as ep
from eulerpoisson.torques import BodyTorque, Gravity, GravityGradient, SpaceTorque
from strategies import batch_shapes, inertia_tensors, quaternions, rngs


def _torques(rng, shape):
    return [
        Gravity(rng.uniform(0.5, 2.0, shape), rng.normal(size=shape + (3,)), rng.normal(size=shape + (3,))),
        GravityGradient(rng.uniform(0.0, 2.0, shape)),
        BodyTorque(rng.normal(size=shape + (3,))),
        SpaceTorque(rng.normal(size=shape + (3,))),
    ]


@settings(max_examples=40, deadline=None)
@given(shape=batch_shapes(), rng=rngs(), data=st.data())
def test_batched_model_equals_its_elements(shape, rng, data):
    """torque, potential, energy and the vector field of a batch are those of each element."""
    q = data.draw(quaternions(shape=shape))
    inertia = data.draw(inertia_tensors(shape=shape))
    w = rng.normal(size=shape + (3,))
    t = float(rng.uniform(-5, 5))
    torques = _torques(rng, shape)
    model = ep.Model(ep.RigidBody(inertia, allow_unphysical=True), torques)
    tau = model.torque(t, q, w)
    U = model.potential(t, q)
    qd, wd = model.rhs(t, q, w)
    assert tau.shape == shape + (3,) and U.shape == shape and qd.shape == shape + (4,)
    for idx in np.ndindex(*shape):
        one = model.element(idx)
        np.testing.assert_allclose(one.torque(t, q[idx], w[idx]), tau[idx], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(one.potential(t, q[idx]), U[idx], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(one.rhs(t, q[idx], w[idx])[1], wd[idx], rtol=1e-11, atol=1e-11)


@settings(max_examples=40, deadline=None)
@given(rng=rngs(), q=quaternions(shape=()))
def test_potential_torque_is_minus_the_gradient_of_the_potential(rng, q):
    """tau . e = -dU/ds of R exp(s [e]x), near the identity and near a half turn as anywhere."""
    inertia = np.diag(rng.uniform(1.0, 2.0, 3))
    for torque in _torques(rng, ())[:2]:
        model = ep.Model(inertia, torque)
        t = float(rng.uniform(0, 3))
        tau = model.torque(t, q, np.zeros(3))
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            dq = ep.attitude.quaternion_from_rotvec(e)
            up = model.potential(t, ep.attitude.quaternion_multiply(q, dq))
            down = model.potential(t, ep.attitude.quaternion_multiply(q, ep.attitude.quaternion_conjugate(dq)))
            scale = 1.0 + abs(float(model.potential(t, q)))
            assert abs((up - down) / (2 * h) + tau[k]) <= 1e-6 * scale
