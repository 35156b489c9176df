"""Bodies under torque: every method x every torque, against an independent high-precision reference.

Truth is ``tests/_torque_reference.py``: a Taylor integrator in mpmath at 40
digits that shares no code with eulerpoisson (its own torque formulas,
recurrences and integrals).
"""

import functools
import math

import numpy as np
import pytest

import eulerpoisson as ep
from _reference import quaternion_distance
from _torque_reference import kovalevskaya_integral, reference_motion
from eulerpoisson import InvalidInputError, UnsupportedModelError
from eulerpoisson.solvers import available_methods, get_method
from eulerpoisson.solvers.registry import methods_supporting
from eulerpoisson.torques import BodyTorque, CallableTorque, Gravity, GravityGradient, SpaceTorque

G = (0.0, 0.0, -9.81)
I_FULL = np.array([[2.0, 0.1, 0.05], [0.1, 1.5, -0.2], [0.05, -0.2, 1.2]])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
W0 = np.array([0.7, -1.1, 2.0])


def _gravity_ref(mass, c, g=G):
    return dict(gravity=[(mass, list(c), list(g))])


# name: (inertia, q0, omega0, torque, reference kwargs)
CASES = {
    "lagrange": (
        [1.0, 1.0, 0.5],
        Q0,
        np.array([0.3, -0.2, 12.0]),
        Gravity(1.0, [0, 0, 0.1]),
        _gravity_ref(1.0, [0, 0, 0.1]),
    ),
    "asymmetric_full_tensor": (I_FULL, Q0, W0, Gravity(1.3, [0.1, -0.2, 0.4]), _gravity_ref(1.3, [0.1, -0.2, 0.4])),
    "kovalevskaya": (
        [2.0, 2.0, 1.0],
        Q0,
        np.array([0.4, 1.1, -0.5]),
        Gravity(0.2, [0.5, 0.0, 0.0]),
        _gravity_ref(0.2, [0.5, 0.0, 0.0]),
    ),
    "gravity_gradient": (I_FULL, Q0, W0, GravityGradient(0.9), dict(gravity_gradient=0.9)),
    "body_torque": (I_FULL, Q0, W0, BodyTorque([0.3, -0.1, 0.2]), dict(body_torque=[0.3, -0.1, 0.2])),
    "space_torque": (I_FULL, Q0, W0, SpaceTorque([0.3, -0.1, 0.2]), dict(space_torque=[0.3, -0.1, 0.2])),
}


@pytest.fixture(scope="module")
def reference(run_once):
    """``reference(name, t_end=10.0)``: the high-precision reference of ``CASES[name]`` at ``t_end``, memoised for
    the whole test run (``run_once`` of tests/conftest.py): the tests that share one may run on different
    pytest-xdist workers."""

    def reference_(name, t_end=10.0):
        inertia, q0, w0, _, ref = CASES[name]
        return run_once(
            f"test_torques-reference-{name}-{t_end!r}", lambda: reference_motion(inertia, q0, w0, [t_end], **ref)
        )

    return reference_


def _errors(tr, qr, wr):
    dq = float(quaternion_distance(tr.quaternion[-1], qr[-1]))
    dw = float(np.max(np.abs(tr.omega[-1] - wr[-1])) / np.max(np.abs(wr[-1])))
    return dq, dw


@pytest.mark.parametrize("name", list(CASES))
def test_taylor_agrees_with_high_precision_reference_at_t10(name, reference):
    inertia, q0, w0, torque, _ = CASES[name]
    qr, wr = reference(name)
    tr = ep.solve(inertia, [0.0, 10.0], omega0=w0, attitude0=q0, torque=torque, method="taylor", tol=1e-15)
    dq, dw = _errors(tr, qr, wr)
    assert dq <= 1e-12 and dw <= 1e-12, (name, dq, dw)


@pytest.mark.parametrize("name", list(CASES))
def test_rk_dop853_agrees_with_reference_at_t10(name, reference):
    inertia, q0, w0, torque, _ = CASES[name]
    qr, wr = reference(name)
    tr = ep.solve(
        inertia, [0.0, 10.0], omega0=w0, attitude0=q0, torque=torque, method="rk", integrator="DOP853", tol=1e-13
    )
    dq, dw = _errors(tr, qr, wr)
    assert dq <= 1e-9 and dw <= 1e-9, (name, dq, dw)


@pytest.mark.parametrize("name", ["lagrange", "gravity_gradient", "space_torque"])
def test_rk_gibbs_charts_see_the_full_attitude(name, reference):
    """In charts R = R_c R(n) the torque must use R_c too (no left invariance under torque)."""
    inertia, q0, w0, torque, _ = CASES[name]
    qr, wr = reference(name)
    tr = ep.solve(inertia, [10.0], omega0=w0, attitude0=q0, torque=torque, method="rk", formulation="gibbs", tol=1e-13)
    assert tr.stats["chart_changes"] > 0
    dq, dw = _errors(tr, qr, wr)
    assert dq <= 1e-9 and dw <= 1e-9, (name, dq, dw)


@pytest.mark.parametrize("scheme,order", [("exact_splitting", 2), ("exact_splitting4", 4)])
@pytest.mark.parametrize("name", ["asymmetric_full_tensor", "gravity_gradient", "space_torque"])
def test_exact_splitting_converges_at_its_order(name, scheme, order, reference):
    inertia, q0, w0, torque, _ = CASES[name]
    t_end = 2.0
    qr, wr = reference(name, t_end)
    errs = []
    for dt in (0.02, 0.01, 0.005):
        tr = ep.solve(
            inertia, [t_end], omega0=w0, attitude0=q0, torque=torque, method="symplectic", scheme=scheme, dt=dt
        )
        errs.append(sum(_errors(tr, qr, wr)))
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(slopes - order) < 0.3), (errs, slopes)


def test_exact_splitting_energy_bounded_over_a_million_steps():
    """Heavy asymmetric top: the energy error oscillates without drift over 10^6 steps (symplectic)."""
    inertia, q0, w0, torque, _ = CASES["asymmetric_full_tensor"]
    t = np.linspace(0.0, 20000.0, 2001)
    tr = ep.solve(
        inertia, t, omega0=w0, attitude0=q0, torque=torque, method="symplectic", scheme="exact_splitting", dt=0.02
    )
    assert tr.stats["steps"] == 1_000_000
    E = tr.energy
    scale = tr.kinetic_energy[0] + abs(tr.potential_energy[0])
    err = np.abs(E - E[0]) / scale
    first, last = err[: len(err) // 10].max(), err[-len(err) // 10 :].max()
    assert err.max() < 1e-3
    assert last < 2.0 * first, (first, last)  # no secular growth
    # the vertical angular momentum is conserved by both flows: round-off only
    assert tr.drift()["m_vertical"] < 1e-10


def test_taylor_kovalevskaya_and_energy_over_t1000():
    inertia, q0, w0, torque, _ = CASES["kovalevskaya"]
    t = np.linspace(0.0, 1000.0, 101)
    tr = ep.solve(inertia, t, omega0=w0, attitude0=q0, torque=torque, method="taylor", tol=1e-15)
    vals = tr.integrals()
    assert set(vals) >= {"energy", "m_vertical", "kovalevskaya"}
    d = tr.drift()
    assert d["kovalevskaya"] < 1e-12 and d["energy"] < 1e-12, d
    # the package's integral is the reference's (an independent formula)
    K_ref = float(kovalevskaya_integral(np.diag(inertia), tr.quaternion[0], tr.omega[0], 0.2, [0.5, 0, 0], G))
    assert vals["kovalevskaya"][0] == pytest.approx(K_ref, rel=1e-13)


def test_lagrange_top_integrals_and_jacobi_integral():
    inertia, q0, w0, torque, _ = CASES["lagrange"]
    tr = ep.solve(inertia, np.linspace(0, 20, 41), omega0=w0, attitude0=q0, torque=torque, method="taylor")
    d = tr.drift()
    assert set(d) == {"energy", "m_vertical", "M3"}
    assert max(d.values()) < 1e-12
    inertia, q0, w0, torque, _ = CASES["gravity_gradient"]
    tr = ep.solve(inertia, np.linspace(0, 20, 41), omega0=w0, attitude0=q0, torque=torque, method="taylor")
    d = tr.drift()
    assert set(d) == {"jacobi"} and d["jacobi"] < 1e-12
    # the energy itself is not conserved (time-dependent potential): the check can fail
    E = tr.energy
    assert np.max(np.abs(E - E[0])) > 1e-3


def test_goryachev_chaplygin_on_its_level_only():
    inertia = [4.0, 4.0, 1.0]
    torque = Gravity(0.3, [0.7, 0.0, 0.0])
    # area integral m . g = 0: q0 = (w, x, y, 0), Omega0 = 2 (x, y, 0) (see tests/_torque_reference.py)
    q0 = np.array([0.8, 0.36, 0.48, 0.0])
    w0 = 2.0 * np.array([0.36, 0.48, 0.0])
    tr = ep.solve(inertia, np.linspace(0, 30, 31), omega0=w0, attitude0=q0, torque=torque, method="taylor")
    assert abs(tr.integrals()["m_vertical"][0]) < 1e-14
    assert tr.drift()["goryachev_chaplygin"] < 1e-12
    tr = ep.solve(inertia, [0, 1], omega0=[0.3, 0.2, 0.9], attitude0=q0, torque=torque, method="taylor")
    assert "goryachev_chaplygin" not in tr.integrals()


def test_constant_space_torque_integral_and_body_torque_from_rest():
    inertia, q0, w0, torque, _ = CASES["space_torque"]
    tr = ep.solve(inertia, np.linspace(0, 10, 11), omega0=w0, attitude0=q0, torque=torque, method="taylor")
    assert max(tr.drift().values()) < 1e-12
    # from rest about a principal axis: Omega = tau t / I exactly
    tr = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 2.5], omega0=[0, 0, 0], torque=BodyTorque([0, 0.6, 0]), method="taylor")
    np.testing.assert_allclose(tr.omega[:, 1], 0.6 * np.array([0, 1, 2.5]) / 2.0, rtol=1e-15, atol=1e-16)


def test_batches_of_bodies_and_torque_parameters_equal_one_by_one():
    masses = np.array([0.5, 1.0, 2.0])
    coms = np.array([[0, 0, 0.1], [0.05, 0, 0.2], [0, -0.1, 0.3]])
    top = Gravity(masses, coms)
    w0 = np.array([[0.1, 0.2, 5.0], [0.3, 0.0, 4.0], [0.0, 0.5, 6.0]])
    t = np.array([0.0, 0.7, 1.5, -0.4])
    for method, opts in (("taylor", {}), ("rk", {}), ("symplectic", {"dt": 0.01})):
        batch = ep.solve([1.0, 1.2, 0.6], t, omega0=w0, torque=top, method=method, **opts)
        assert batch.quaternion.shape == (3, 4, 4)
        for b in range(3):
            one = ep.solve([1.0, 1.2, 0.6], t, omega0=w0[b], torque=Gravity(masses[b], coms[b]), method=method, **opts)
            np.testing.assert_array_equal(batch.quaternion[b], one.quaternion)
            np.testing.assert_array_equal(batch.omega[b], one.omega)


def test_negative_times_run_backwards_under_torque():
    inertia, q0, w0, torque, _ = CASES["asymmetric_full_tensor"]
    fwd = ep.solve(inertia, [1.5], omega0=w0, attitude0=q0, torque=torque, method="taylor")
    back = ep.solve(inertia, [-1.5], omega0=fwd.omega[-1], attitude0=fwd.quaternion[-1], torque=torque, method="taylor")
    assert quaternion_distance(back.quaternion[-1], q0) < 1e-13
    np.testing.assert_allclose(back.omega[-1], w0, atol=1e-13)


def test_callable_torque_runs_with_rk_and_matches_the_builtin():
    g = np.array(G)
    c = np.array([0.1, -0.2, 0.4])

    def heavy(t, q, omega):
        w, v = q[..., :1], q[..., 1:]
        # R^T g for unit q: g + 2 w (g x v) + 2 v x (v x g)
        gb = g + 2 * w * np.cross(g, v) + 2 * np.cross(v, np.cross(v, g))
        return np.cross(1.3 * c, gb)

    inertia, q0, w0, torque, _ = CASES["asymmetric_full_tensor"]
    a = ep.solve(inertia, [3.0], omega0=w0, attitude0=q0, torque=heavy, method="rk", tol=1e-13)
    b = ep.solve(inertia, [3.0], omega0=w0, attitude0=q0, torque=torque, method="rk", tol=1e-13)
    assert quaternion_distance(a.quaternion[-1], b.quaternion[-1]) < 1e-10
    assert isinstance(a.model.torques[0], CallableTorque)


TORQUES = {
    "gravity": Gravity(1.0, [0.0, 0.0, 0.1]),
    "gravity_asymmetric": Gravity(1.0, [0.1, 0.0, 0.1]),
    "gravity_gradient": GravityGradient(0.5),
    "body_torque": BodyTorque([0.1, 0.0, 0.0]),
    "space_torque": SpaceTorque([0.0, 0.1, 0.0]),
    "callable": lambda t, q, omega: np.zeros_like(omega),
    "sum": [Gravity(1.0, [0.1, 0.0, 0.1]), BodyTorque([0.1, 0.0, 0.0])],
}


def _every_torque_problem(tname):
    """(torque, inertia, omega0) of :func:`test_every_method_handles_or_refuses_every_torque`."""
    return TORQUES[tname], ([1.0, 1.0, 0.5] if tname == "gravity" else [1.0, 1.5, 0.8]), [0.2, 0.1, 3.0]


@functools.cache
def _every_torque_rk_reference(tname):
    """The attitude at t = 1 by rk at tol = 1e-12: once per torque, not once per method."""
    torque, inertia, w0 = _every_torque_problem(tname)
    return ep.solve(inertia, [0.0, 1.0], omega0=w0, torque=torque, method="rk", tol=1e-12).quaternion[-1].copy()


@pytest.mark.parametrize("method", available_methods())
@pytest.mark.parametrize("tname", list(TORQUES))
def test_every_method_handles_or_refuses_every_torque(method, tname):
    """Each method x torque pair either runs (and agrees with rk) or refuses by a clear error naming the able."""
    torque, inertia, w0 = _every_torque_problem(tname)
    model = ep.Model(inertia, torque)
    reason = get_method(method).supports(model)
    if reason is not None:
        with pytest.raises(
            UnsupportedModelError, match=rf"method '{method}' cannot run this model: .*methods that can: .*rk"
        ):
            ep.solve(inertia, [0.0, 1.0], omega0=w0, torque=torque, method=method)
        return
    tr = ep.solve(inertia, [0.0, 1.0], omega0=w0, torque=torque, method=method)
    tol = 1e-5 if method == "symplectic" else 1e-9
    assert quaternion_distance(tr.quaternion[-1], _every_torque_rk_reference(tname)) < tol
    assert method in methods_supporting(model)


def test_symplectic_free_body_schemes_refuse_torque():
    with pytest.raises(UnsupportedModelError, match="scheme 'gauss4' solves the free body only.*exact_splitting"):
        ep.solve([1, 2, 3], [1.0], omega0=[1, 0, 0], torque=GravityGradient(0.1), method="symplectic", scheme="gauss4")


def test_exact_splitting_without_torque_is_the_closed_form():
    t = np.array([0.0, 3.0, -2.0])
    a = ep.solve(I_FULL, t, omega0=W0, attitude0=Q0, method="symplectic", scheme="exact_splitting", dt=0.5)
    b = ep.solve(I_FULL, t, omega0=W0, attitude0=Q0)
    assert np.max(quaternion_distance(a.quaternion, b.quaternion)) < 1e-13
    np.testing.assert_allclose(a.omega, b.omega, atol=1e-13)


def test_model_torque_matches_definitions():
    rng = np.random.default_rng(3)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    w = rng.normal(size=(5, 3))
    R = ep.Attitude(q).as_matrix()
    c = np.array([0.1, 0.2, -0.3])
    m = ep.Model(I_FULL, Gravity(2.0, c))
    expect = np.cross(c, 2.0 * np.einsum("bji,j->bi", R, np.array(G)))
    np.testing.assert_allclose(m.torque(0.0, q, w), expect, atol=1e-14)
    gg = ep.Model(I_FULL, GravityGradient(0.3))
    r = np.einsum("bji,j->bi", R, [math.cos(0.3 * 2.0), math.sin(0.3 * 2.0), 0.0])
    np.testing.assert_allclose(gg.torque(2.0, q, w), 3 * 0.09 * np.cross(r, r @ I_FULL.T), atol=1e-14)
    # the potential's gradient is minus the torque: dU(R exp([e]x s))/ds = -tau . e
    for model in (m, gg):
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1e-6
            qe = ep.Attitude(q).as_quaternion()
            dq = ep.attitude.quaternion_from_rotvec(e)
            qp = ep.attitude.quaternion_multiply(qe, dq)
            qm = ep.attitude.quaternion_multiply(qe, ep.attitude.quaternion_conjugate(dq))
            dU = (model.potential(2.0, qp) - model.potential(2.0, qm)) / 2e-6
            np.testing.assert_allclose(dU, -model.torque(2.0, q, w)[:, k], rtol=1e-6, atol=1e-8)


def test_torque_records_round_trip_through_netcdf(tmp_path):
    torque = [
        Gravity(1.5, [0, 0.1, 0.2], [0, -9.8, 0]),
        GravityGradient(0.01),
        BodyTorque([1, 2, 3]),
        SpaceTorque([0, 0, 1]),
    ]
    tr = ep.solve(I_FULL, [0.0, 0.5], omega0=W0, torque=torque, method="rk")
    tr.to_netcdf(tmp_path / "run.nc")
    back = ep.Trajectory.from_netcdf(tmp_path / "run.nc")
    assert [t.to_dict() for t in back.model.torques] == [t.to_dict() for t in torque]
    np.testing.assert_array_equal(back.energy, tr.energy)
    # a callable cannot be saved as code: it is recorded by name and refused by methods that must evaluate it
    tr = ep.solve(I_FULL, [0.0, 0.5], omega0=W0, torque=lambda t, q, w: np.zeros_like(w), method="rk")
    tr.to_netcdf(tmp_path / "call.nc")
    back = ep.Trajectory.from_netcdf(tmp_path / "call.nc")
    assert back.model.torques[0].kind == "unrecorded"
    with pytest.raises(UnsupportedModelError, match="was not recorded"):
        ep.solve(back.model, [1.0], omega0=W0, method="rk")


def test_bad_torque_input_is_named():
    with pytest.raises(InvalidInputError, match="Gravity: mass must be > 0"):
        Gravity(0.0, [0, 0, 1])
    with pytest.raises(InvalidInputError, match=r"Gravity: center_of_mass must have shape \(\.\.\., 3\)"):
        Gravity(1.0, [0, 1])
    with pytest.raises(InvalidInputError, match="GravityGradient: mean_motion must be >= 0"):
        GravityGradient(-1.0)
    with pytest.raises(InvalidInputError, match="BodyTorque: tau contains NaN"):
        BodyTorque([np.nan, 0, 0])
    with pytest.raises(TypeError, match="torque must be a Torque"):
        ep.solve([1, 2, 3], [1.0], omega0=[1, 0, 0], torque="gravity")
    with pytest.raises(InvalidInputError, match="batch shapes of the body .* do not broadcast"):
        ep.Model(ep.RigidBody([[1, 2, 3], [1, 2, 3]]), Gravity([1.0, 2.0, 3.0], [0, 0, 1]))
    with pytest.raises(TypeError, match="either in the Model or as torque="):
        ep.solve(ep.Model([1, 2, 3], BodyTorque([1, 0, 0])), [1.0], omega0=[1, 0, 0], torque=BodyTorque([1, 0, 0]))

    def bad(t, q, omega):
        return np.zeros(2)

    with pytest.raises(InvalidInputError, match="returned shape"):
        ep.solve([1, 2, 3], [1.0], omega0=[1, 0, 0], torque=bad, method="rk")


def test_compose_initial_refuses_models_with_torque():
    from eulerpoisson.solvers import compose_initial, make_problem

    p = make_problem([1, 2, 3], [1.0], omega0=[1, 0, 0], torque=BodyTorque([1, 0, 0]))
    with pytest.raises(ValueError, match="free-body shortcut"):
        compose_initial(p, np.zeros((1, 4)))


def test_exact_lagrange_top_in_any_body_frame_agrees_with_reference_at_t10(reference):
    """The symmetry axis along a rotated direction of a full tensor: recognized, solved in closed form."""
    R0 = ep.Attitude.from_rotvec([0.3, -0.5, 0.2]).as_matrix()
    inertia = R0 @ np.diag([0.5, 1.0, 1.0]) @ R0.T
    c = R0 @ np.array([0.12, 0.0, 0.0])
    w0 = R0 @ np.array([15.0, 0.3, -0.2])
    qr, wr = reference_motion(inertia, Q0, w0, [10.0], **_gravity_ref(1.0, c))
    model = ep.Model(inertia, Gravity(1.0, c))
    assert model.lagrange_top() is not None
    tr = ep.solve(model, [0.0, 10.0], omega0=w0, attitude0=Q0, method="exact")
    dq, dw = _errors(tr, qr, wr)
    assert dq <= 1e-12 and dw <= 1e-12, (dq, dw)
    assert tr.stats["model"] == "lagrange top"
    inertia, q0, w0, torque, _ = CASES["lagrange"]
    qr, wr = reference("lagrange")
    tr = ep.solve(inertia, [0.0, 10.0], omega0=w0, attitude0=q0, torque=torque, method="exact")
    dq, dw = _errors(tr, qr, wr)
    assert dq <= 1e-12 and dw <= 1e-12, (dq, dw)


def test_exact_lagrange_batches_equal_one_by_one_and_other_tops_are_refused():
    masses = np.array([0.5, 1.0, 2.0])
    t = np.linspace(-2, 5, 8)
    batch = ep.solve([1.0, 1.0, 0.5], t, omega0=[0.1, 0.2, 10], torque=Gravity(masses, [0, 0, 0.1]), method="exact")
    for b in range(3):
        one = ep.solve(
            [1.0, 1.0, 0.5], t, omega0=[0.1, 0.2, 10], torque=Gravity(masses[b], [0, 0, 0.1]), method="exact"
        )
        np.testing.assert_allclose(batch.quaternion[b], one.quaternion, atol=1e-15)
    with pytest.raises(UnsupportedModelError, match="Lagrange top.*methods that can: rk, rk4, symplectic, taylor"):
        ep.solve([1.0, 1.0, 0.5], t, omega0=[0.1, 0.2, 10], torque=Gravity(1.0, [0.1, 0, 0.1]), method="exact")
    with pytest.raises(UnsupportedModelError, match="Lagrange top"):
        ep.solve([1.0, 1.2, 0.5], t, omega0=[0.1, 0.2, 10], torque=Gravity(1.0, [0, 0, 0.1]), method="exact")


@pytest.mark.parametrize("name", [m for m in available_methods() if get_method(m).refine])
def test_observed_order_under_torque_matches_nominal(name, reference):
    """Registry-driven: each method's accuracy knob on the heavy asymmetric top (the same rule as for the free body)."""
    cls = get_method(name)
    inertia, q0, w0, torque, _ = CASES["asymmetric_full_tensor"]
    t_end = 2.0
    qr, wr = reference("asymmetric_full_tensor", t_end)

    def err(**opts):
        tr = ep.solve(inertia, [t_end], omega0=w0, attitude0=q0, torque=torque, method=name, **opts)
        return sum(_errors(tr, qr, wr))

    if cls.refine == "dt":
        p = cls().nominal_order()
        errs = [err(dt=dt) for dt in (0.04, 0.02, 0.01)]
        slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
        assert np.all(np.abs(slopes - p) <= 0.6), (name, p, errs, slopes)
    else:
        errs = [err(tol=tol) for tol in (1e-6, 1e-8, 1e-10)]
        assert errs[0] > errs[1] > errs[2], errs
        a = np.log10(errs[0] / errs[2]) / 4
        assert 0.6 <= a <= 1.5, (name, errs)


def test_exact_lagrange_refuses_times_beyond_float64_phase():
    top = Gravity(1.0, [0, 0, 0.1])
    with pytest.raises(InvalidInputError, match="exceeds 2\\^48"):
        ep.solve([1, 1, 0.5], [1e20], omega0=[0, 0, 0], torque=top)  # a pendulum from rest: rate sqrt(mgl/A)
