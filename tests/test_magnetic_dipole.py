"""MagneticDipoleTorque: tau = mu x R^T B(t), checked against independent computations.

- the torque and the potential against plain numpy formulas, and the torque as minus the gradient of the
  potential (finite differences);
- a symmetric body with its dipole on the symmetry axis in a constant field along z: ``rk`` on the class
  against ``rk`` on the same model written as a plain Python function, the high-precision reference of
  ``tests/_torque_reference.py`` (a constant field is a heavy top: mass 1, centre of mass mu, g = B), and
  ``taylor`` / ``symplectic`` (the torque is polynomial); the energy, m . B_hat and M3 are conserved;
- a turning field B(t): the class equals a hand-written CallableTorque;
- bad inputs, records, the command-line description.
"""

from __future__ import annotations

import numpy as np
import pytest

import _torque_reference as ref
import eulerpoisson as ep
from eulerpoisson.errors import InvalidInputError, UnsupportedModelError
from eulerpoisson.torques import CallableTorque, Gravity, MagneticDipoleTorque, Torque


def _matrix(q):
    """R(q) for unit quaternions (..., 4), scalar first, written out (independent of the package)."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def _unit(rng, shape):
    q = rng.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


# ---------------------------------------------------------------------------
# the formulas
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("batch", [(), (4,), (2, 3)])
def test_torque_and_potential_are_the_formulas(batch):
    rng = np.random.default_rng(len(batch))
    mu = rng.normal(size=batch + (3,))
    B = rng.normal(size=batch + (3,))
    tq = MagneticDipoleTorque(mu, B)
    assert tq.batch_shape == batch and tq.conservative and not tq.time_dependent and not tq.depends_on_omega
    q = _unit(rng, batch)
    R = _matrix(q)
    b = np.einsum("...ji,...j->...i", R, B)  # R^T B
    np.testing.assert_allclose(tq.evaluate(0.3, R, np.zeros(batch + (3,)), np.eye(3)), np.cross(mu, b), atol=1e-14)
    U = -np.sum(np.einsum("...ij,...j->...i", R, mu) * B, -1)
    np.testing.assert_allclose(tq.potential(0.3, R, np.eye(3)), U, atol=1e-14)
    # the model's torque goes through the same evaluate
    model = ep.Model([1.0, 2.0, 2.5], tq)
    np.testing.assert_allclose(model.torque(0.3, q, np.zeros(batch + (3,))), np.cross(mu, b), atol=1e-14)


def test_torque_is_minus_the_gradient_of_the_potential():
    """tau . e_k = -dU/ds of R exp(s [e_k]x): the sign of U = -(R mu) . B."""
    rng = np.random.default_rng(3)
    model = ep.Model([1.0, 2.0, 2.5], MagneticDipoleTorque(rng.normal(size=3), rng.normal(size=3)))
    for _ in range(5):
        q = _unit(rng, ())
        tau = model.torque(0.0, q, np.zeros(3))
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            dq = ep.attitude.quaternion_from_rotvec(e)
            up = model.potential(0.0, ep.attitude.quaternion_multiply(q, dq))
            down = model.potential(0.0, ep.attitude.quaternion_multiply(q, ep.attitude.quaternion_conjugate(dq)))
            assert abs((up - down) / (2 * h) + tau[k]) <= 1e-8


def test_polynomial_is_the_torque():
    """tau = L (R^T B) with L = [mu]x: what taylor and symplectic expand."""
    rng = np.random.default_rng(4)
    mu, B = rng.normal(size=3), rng.normal(size=3)
    p = MagneticDipoleTorque(mu, B).polynomial()
    assert p is not None and len(p.vectors) == 1 and not p.has_orbit
    R = _matrix(_unit(rng, ()))
    np.testing.assert_allclose(p.maps[0] @ (R.T @ p.vectors[0]), np.cross(mu, R.T @ B), atol=1e-15)


# ---------------------------------------------------------------------------
# motions
# ---------------------------------------------------------------------------
A_, C_ = 2.0, 1.0  # a symmetric body: I = diag(A, A, C)
MU = np.array([0.0, 0.0, 0.8])  # on the symmetry axis
BZ = np.array([0.0, 0.0, 1.5])  # the field along z
Q0 = np.array([np.cos(0.3), np.sin(0.3), 0.0, 0.0])  # tilted by 0.6 rad about x
W0 = np.array([0.2, -0.1, 3.0])
TIMES = np.linspace(0.0, 6.0, 13)


def _by_hand(mu, field):
    """The same torque as a plain function torque(t, q, omega) (field: a vector or a function of t)."""

    def magnetic(t, q, omega):
        B = np.asarray(field(t) if callable(field) else field, dtype=float)
        R = _matrix(q)
        return np.cross(mu, np.einsum("...ji,...j->...i", R, B))

    return magnetic


def test_symmetric_top_in_a_constant_field_against_a_plain_function():
    body = [A_, A_, C_]
    tr = ep.solve(body, TIMES, omega0=W0, attitude0=Q0, torque=MagneticDipoleTorque(MU, BZ), method="rk", tol=1e-13)
    hand = ep.solve(body, TIMES, omega0=W0, attitude0=Q0, torque=_by_hand(MU, BZ), method="rk", tol=1e-13)
    np.testing.assert_allclose(tr.omega, hand.omega, rtol=0, atol=1e-10)
    np.testing.assert_allclose(tr.quaternion, hand.quaternion, rtol=0, atol=1e-10)
    # the integrals: energy and m . B_hat (the model's), M3 (a Lagrange top)
    ints = tr.integrals()
    assert set(ints) == {"energy", "m_field"}
    for key in ("energy", "m_field"):
        assert np.max(np.abs(ints[key] - ints[key][0])) <= 1e-10 * max(1.0, abs(ints[key][0]))
    M3 = C_ * tr.omega[:, 2]
    assert np.max(np.abs(M3 - M3[0])) <= 1e-10
    np.testing.assert_allclose(ints["energy"], tr.energy, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(ints["m_field"], tr.m[:, 2], rtol=1e-14, atol=1e-14)


def test_constant_field_against_the_high_precision_reference():
    """A constant field is a heavy top with mass 1, centre of mass mu and g = B (tests/_torque_reference.py)."""
    rng = np.random.default_rng(8)
    inertia = np.array([1.0, 1.7, 2.2])
    mu, B = rng.normal(size=3), rng.normal(size=3)
    q0, w0 = _unit(rng, ()), rng.normal(size=3)
    t = np.linspace(0.0, 3.0, 7)
    q_ref, w_ref = ref.reference_motion(inertia, q0, w0, t, gravity=(1.0, mu, B), dps=25)
    model = ep.Model(inertia, MagneticDipoleTorque(mu, B))
    for method, opts, tol in (("rk", {"tol": 1e-13}, 1e-11), ("taylor", {}, 1e-13), ("symplectic", {}, 1e-5)):
        tr = ep.solve(model, t, omega0=w0, attitude0=q0, method=method, **opts)
        sign = np.sign(np.sum(tr.quaternion * q_ref, -1))[:, None]
        np.testing.assert_allclose(tr.omega, w_ref, rtol=0, atol=tol, err_msg=method)
        np.testing.assert_allclose(tr.quaternion * sign, q_ref, rtol=0, atol=tol, err_msg=method)
    # and the heavy top that it is, solved by the package, to rounding
    top = ep.solve(inertia, t, omega0=w0, attitude0=q0, torque=Gravity(1.0, mu, B), method="taylor")
    tr = ep.solve(model, t, omega0=w0, attitude0=q0, method="taylor")
    np.testing.assert_allclose(tr.omega, top.omega, rtol=0, atol=1e-12)


def test_energy_is_conserved_in_a_constant_field():
    rng = np.random.default_rng(12)
    tr = ep.solve(
        [1.0, 2.0, 2.5],
        np.linspace(0, 20, 41),
        omega0=rng.normal(size=3),
        attitude0=_unit(rng, ()),
        torque=MagneticDipoleTorque(rng.normal(size=3), rng.normal(size=3)),
        method="taylor",
    )
    drift = tr.drift()
    assert drift["energy"] <= 1e-12 and drift["m_field"] <= 1e-12


def test_turning_field_equals_a_hand_written_callable_torque():
    omega_b = 0.7

    def field(t):
        t = np.asarray(t, dtype=float)
        return 2.0 * np.stack([np.cos(omega_b * t), np.sin(omega_b * t), 0.3 + 0.0 * t], -1)

    mu = np.array([0.3, -0.2, 0.9])
    tq = MagneticDipoleTorque(mu, field)
    assert tq.time_dependent and not tq.conservative and tq.polynomial() is None
    hand = CallableTorque(_by_hand(mu, field))
    rng = np.random.default_rng(6)
    for _ in range(5):
        t = float(rng.uniform(0, 10))
        q = _unit(rng, (3,))
        w = rng.normal(size=(3, 3))
        a = ep.Model([1.0, 2.0, 2.5], tq).torque(t, q, w)
        b = ep.Model([1.0, 2.0, 2.5], hand).torque(t, q, w)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-14)
    t = np.linspace(0, 5, 11)
    x = ep.solve([1.0, 2.0, 2.5], t, omega0=W0, attitude0=Q0, torque=tq, method="rk", tol=1e-12)
    y = ep.solve([1.0, 2.0, 2.5], t, omega0=W0, attitude0=Q0, torque=hand, method="rk", tol=1e-12)
    np.testing.assert_allclose(x.omega, y.omega, rtol=0, atol=1e-10)
    np.testing.assert_allclose(x.quaternion, y.quaternion, rtol=0, atol=1e-10)
    assert x.integrals() == {}


def test_which_methods_run_it():
    const = ep.Model([1.0, 2.0, 2.5], MagneticDipoleTorque([0, 0, 1.0], [0, 1.0, 0]))
    turning = ep.Model([1.0, 2.0, 2.5], MagneticDipoleTorque([0, 0, 1.0], lambda t: [np.cos(t), np.sin(t), 0.0]))
    t = np.linspace(0, 1, 3)
    for method in ("rk", "taylor", "symplectic"):
        ep.solve(const, t, omega0=W0, method=method)
    ep.solve(turning, t, omega0=W0, method="rk")
    for method in ("taylor", "symplectic", "exact"):
        with pytest.raises(UnsupportedModelError):
            ep.solve(turning, t, omega0=W0, method=method)


# ---------------------------------------------------------------------------
# inputs, records, the command line
# ---------------------------------------------------------------------------
def test_bad_inputs_name_the_argument():
    with pytest.raises(InvalidInputError, match="dipole"):
        MagneticDipoleTorque([1.0, 2.0], [0.0, 0.0, 1.0])
    with pytest.raises(InvalidInputError, match="field"):
        MagneticDipoleTorque([1.0, 2.0, 3.0], [0.0, np.nan, 1.0])
    with pytest.raises(InvalidInputError, match="field"):
        MagneticDipoleTorque([1.0, 2.0, 3.0], np.ones((2, 2)))
    with pytest.raises(InvalidInputError, match="MagneticDipoleTorque.*do not broadcast: dipole .*, field "):
        MagneticDipoleTorque(np.ones((2, 3)), np.ones((3, 3)))
    with pytest.raises(TypeError, match="dipole"):
        MagneticDipoleTorque("north", [0.0, 0.0, 1.0])
    bad_shape = MagneticDipoleTorque([0, 0, 1.0], lambda t: [1.0, 2.0])
    with pytest.raises(InvalidInputError, match="magnetic field function.*shape"):
        bad_shape.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3))
    bad_value = MagneticDipoleTorque([0, 0, 1.0], lambda t: [np.inf, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="magnetic field function.*NaN or infinite"):
        bad_value.evaluate(0.0, np.eye(3), np.zeros(3), np.eye(3))
    with pytest.raises(NotImplementedError, match="no potential"):
        bad_value.potential(0.0, np.eye(3), np.eye(3))


def test_record_round_trip_and_unrecorded_callable_field():
    import json

    from eulerpoisson.io.stream import torque_fingerprint

    tq = MagneticDipoleTorque([[0.0, 0.0, 1.0], [0.1, 0.0, 0.0]], [0.0, 2e-5, 3e-5])
    rec = tq.to_dict()
    assert rec == {"kind": "magnetic_dipole", "dipole": [[0.0, 0.0, 1.0], [0.1, 0.0, 0.0]], "field": [0.0, 2e-5, 3e-5]}
    back = Torque.from_dict(json.loads(json.dumps(rec)))
    assert isinstance(back, MagneticDipoleTorque) and back.to_dict() == rec and back.batch_shape == (2,)

    def earth(t):
        return [0.0, 0.0, 3e-5]

    turning = MagneticDipoleTorque([0.0, 0.0, 1.0], earth)
    assert repr(turning) == "MagneticDipoleTorque(dipole=[0.0, 0.0, 1.0], field='earth')"
    fp = torque_fingerprint(ep.Model([1.0, 2.0, 2.5], [turning, tq[1]]))
    assert fp[0] == {"kind": "unrecorded", "description": repr(turning)} and fp[1]["kind"] == "magnetic_dipole"


def test_batch_elements():
    tq = MagneticDipoleTorque(np.eye(3), [0.0, 0.0, 1.0])
    model = ep.Model([1.0, 2.0, 2.5], tq)
    assert model.batch_shape == (3,)
    one = model.element((1,))
    assert one.torques[0].to_dict() == {"kind": "magnetic_dipole", "dipole": [0.0, 1.0, 0.0], "field": [0.0, 0.0, 1.0]}
    turning = MagneticDipoleTorque(np.eye(3), lambda t: [0.0, 0.0, 1.0])
    assert turning.batch_shape == (3,) and np.array_equal(turning[2].dipole, [0.0, 0.0, 1.0])


def test_from_params_and_cli_description():
    tq = MagneticDipoleTorque.from_params({"magnetic_dipole": [0.0, 0.0, 1.0], "magnetic_field": [1e-5, 0.0, 0.0]})
    assert tq.to_dict() == {"kind": "magnetic_dipole", "dipole": [0.0, 0.0, 1.0], "field": [1e-5, 0.0, 0.0]}
    assert [(p.flag, p.toml_key, p.metavar, p.units) for p in MagneticDipoleTorque.cli] == [
        ("--magnetic-dipole", "magnetic_dipole", "MX,MY,MZ", "A m2"),
        ("--magnetic-field", "magnetic_field", "BX,BY,BZ", "T"),
    ]
    with pytest.raises(
        InvalidInputError, match="needs field: --magnetic-field BX,BY,BZ or \\[torque\\] magnetic_field"
    ):
        MagneticDipoleTorque.from_params({"dipole": [0.0, 0.0, 1.0]})


def test_shift_of_a_callable_field():
    """Seen from t_start in a frame turned by -phi: B'(s) = R_z(-phi) B(s + t_start)."""

    def field(t):
        t = np.asarray(t, dtype=float)
        return np.stack([np.cos(t), np.sin(t), 0.5 + 0.0 * t], -1)

    tq = MagneticDipoleTorque([0.2, 0.0, 1.0], field)
    phi = np.asarray(0.4)
    s = 1.3
    shifted = tq.shifted(10.0, phi)
    assert shifted.field.__name__ == "field" and shifted.time_dependent
    c, sn = np.cos(-0.4), np.sin(-0.4)
    Rz = np.array([[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(shifted.field_at(s), Rz @ field(s + 10.0), atol=1e-15)
    np.testing.assert_allclose(tq.shifted(10.0, 0.0).field_at(s), field(s + 10.0), atol=0)
    const = MagneticDipoleTorque([0.2, 0.0, 1.0], [1.0, 0.0, 0.0])
    assert const.shifted(10.0, 0.0) is const
    np.testing.assert_allclose(const.shifted(10.0, phi).field, Rz @ [1.0, 0.0, 0.0], atol=1e-15)
