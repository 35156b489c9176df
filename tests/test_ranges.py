"""Inputs at the edges of what float64 can answer: clear errors instead of silent guesses or hangs.

Each case here was once a silent wrong answer, a raw ``OverflowError``/``ZeroDivisionError`` or a
run that never ended; every error is checked by its message.
"""

from __future__ import annotations

import numpy as np
import pytest

from eulerpoisson import RigidBody, solve
from eulerpoisson.attitude import Attitude, euler_from_quaternion, quaternion_from_euler
from eulerpoisson.errors import EulerPoissonError, InvalidInputError, SingularChartError
from eulerpoisson.model.formulations import formulation
from eulerpoisson.solvers.exact.method import MAX_PHASE

I123 = [1.0, 2.0, 3.0]
W0 = np.array([1.0, 0.1, 0.5])


# ---------------------------------------------------------------------------
# exact: the phase of the motion must be determined by float64
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("w0, t", [([1e40, 0.1, 0.5], 1.0), ([1.0, 0.1, 0.5], 1e18), ([1.0, 0.1, 0.5], -1e20)])
def test_exact_refuses_times_beyond_the_phase_range(w0, t):
    with pytest.raises(InvalidInputError, match=r"exact: \|omega0\| \|t\| = .* exceeds 2\^48"):
        solve(I123, [0.0, t], omega0=w0)


def test_exact_range_limit_is_where_documented():
    speed = float(np.linalg.norm(W0))
    ok = 0.9 * MAX_PHASE / speed
    tr = solve(I123, [ok], omega0=W0)  # inside: an answer on the orbit (energy and |M| kept)
    E0 = 0.5 * np.dot(W0 * I123, W0)
    assert abs(tr.energy[0] / E0 - 1) < 1e-12
    with pytest.raises(InvalidInputError, match=r"body \(1,\)"):
        solve(I123, [1.2 * MAX_PHASE / speed], omega0=[W0 * 0.5, W0])


# ---------------------------------------------------------------------------
# symplectic and rk: step budgets, checked before the run
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "method, kw, match",
    [
        (
            "symplectic",
            dict(t=[0.0, 1.0], dt=1e-300),
            r"symplectic: reaching \|t\| = 1 needs about 1e\+300 steps, more than max_steps",
        ),
        ("symplectic", dict(t=[0.0, 1e300]), r"symplectic: reaching \|t\| = 1e\+300 needs"),
        ("symplectic", dict(t=[0.0, 1.0], omega0=[1e300, 0.0, 0.0]), r"symplectic: .* needs about inf steps"),
        (
            "symplectic",
            dict(t=[-3.0, 4.0], dt=0.5, max_steps=13),
            r"reaching \|t\| = 7 needs about 14 steps, more than max_steps=13",
        ),
        (
            "rk",
            dict(t=[0.0, 1e300]),
            r"rk: reaching \|t\| = 1e\+300 needs about .* steps, more than max_steps=10000000",
        ),
        ("rk", dict(t=[0.0, 1.0], omega0=[1e200, 1e200, 0.0]), r"rk: .* needs about inf steps"),
    ],
)
def test_step_budget_is_checked_before_the_run(method, kw, match):
    kw = dict(kw)
    t = kw.pop("t")
    w0 = kw.pop("omega0", W0)
    with pytest.raises(InvalidInputError, match=match):
        solve(I123, t, omega0=w0, method=method, **kw)


def test_symplectic_within_budget_runs_and_bad_budget_values():
    tr = solve(I123, [-3.0, 4.0], omega0=W0, method="symplectic", dt=0.5, max_steps=14)
    assert tr.stats["steps"] == 14
    for bad in (0, 2.5, True, "10"):
        with pytest.raises(InvalidInputError, match="symplectic: max_steps must be an integer >= 1"):
            solve(I123, [1.0], omega0=W0, method="symplectic", max_steps=bad)


def test_rk_step_budget_during_the_run():
    with pytest.raises(EulerPoissonError, match=r"rk: max_steps=10 exhausted \(160 evaluations"):
        solve(I123, [0.0, 100.0], omega0=W0, method="rk", max_steps=10)
    # a generous budget changes nothing
    a = solve(I123, [0.0, 5.0], omega0=W0, method="rk")
    b = solve(I123, [0.0, 5.0], omega0=W0, method="rk", max_steps=10_000)
    np.testing.assert_array_equal(a.quaternion, b.quaternion)
    assert "_nfev_body" not in a.stats
    for bad in (0, True, 1.5):
        with pytest.raises(InvalidInputError, match="rk: max_steps must be an integer >= 1"):
            solve(I123, [1.0], omega0=W0, method="rk", max_steps=bad)


def test_rk_gibbs_without_chart_changes_fails_with_a_hint():
    # a threshold of 1e300 squares to inf (no OverflowError): |n| then blows up at the half turn
    with pytest.raises(
        EulerPoissonError, match=r"rk: solve_ivp .* failed: .*formulation='gibbs'.*chart_threshold=1e\+300"
    ):
        solve(I123, [0.0, 10.0], omega0=W0, method="rk", formulation="gibbs", chart_threshold=1e300)


# ---------------------------------------------------------------------------
# flags are booleans; batch shapes that do not broadcast are named
# ---------------------------------------------------------------------------
def test_boolean_flags_refuse_truthy_strings():
    with pytest.raises(TypeError, match=r"degrees must be True or False, got 'no' \(str\)"):
        quaternion_from_euler("xyz", [1.0, 2.0, 3.0], degrees="no")
    with pytest.raises(TypeError, match="degrees must be True or False, got 1"):
        euler_from_quaternion("xyz", [1.0, 0, 0, 0], degrees=1)
    a = Attitude.from_euler("xyz", [10.0, 20.0, 30.0], degrees=np.bool_(True))
    np.testing.assert_allclose(a.as_euler("xyz", degrees=True), [10.0, 20.0, 30.0], atol=1e-12)
    with pytest.raises(TypeError, match="canonical must be True or False"):
        a.as_quaternion(canonical="yes")
    with pytest.raises(TypeError, match="inverse must be True or False"):
        a.apply([1.0, 0.0, 0.0], inverse=None)


@pytest.mark.parametrize("which", ["omega0", "m0"])
def test_solve_names_the_shapes_that_do_not_broadcast(which):
    with pytest.raises(
        InvalidInputError, match=rf"batch shapes do not broadcast: body \(\) .*{which} \(2,\) .*attitude0 \(3,\)"
    ):
        solve(I123, [0.0, 1.0], **{which: [[1.0, 2.0, 3.0]] * 2}, attitude0=[[1.0, 0, 0, 0]] * 3)
    body = RigidBody(np.array([I123] * 4))
    with pytest.raises(InvalidInputError, match=r"body \(4,\) \(inertia \(4, 3, 3\)\)"):
        solve(body, [0.0, 1.0], **{which: [[1.0, 2.0, 3.0]] * 3})


# ---------------------------------------------------------------------------
# Gibbs formulations near the half turn
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["canonical", "momentum", "velocity", "geodesic"])
def test_gibbs_formulations_refuse_n_beyond_1e50(name):
    f = formulation(name, I123)
    s = np.r_[1e160, 5e159, 0.0, 0.3, 1.0, 0.2]
    for call in (f.hamiltonian, f.vector_field, f.to_common, f.omega):
        with pytest.raises(
            SingularChartError, match=rf"state of the '{name}' formulation: \|n\| = 1.12e\+160 exceeds 1e\+50"
        ):
            call(s)
    # the attitude of such a state is still available (the conversions take any finite n)
    q = f.quaternion(s)
    assert abs(q[0]) < 1e-159
    with pytest.raises(SingularChartError, match="exceeds 1e\\+50"):
        f.from_common([1e-60, 1.0, 0.0, 0.0], [1.0, 0.1, 0.5])


@pytest.mark.parametrize("name", ["canonical", "momentum", "velocity", "geodesic"])
def test_gibbs_formulations_near_the_half_turn_lose_only_what_the_chart_loses(name):
    """Energy of states delta rad from the half turn (|n| = 2/delta) through the Gibbs variables:
    relative error within 4 eps |n|, the conditioning of the chart there (measured: eps |n| / 10)."""
    f = formulation(name, I123)
    E = 0.5 * np.dot(W0 * I123, W0)
    for delta in (1e-2, 1e-4, 1e-6, 1e-8, 1e-10):
        q = np.array([delta / 2.0, 0.6, 0.0, 0.8])
        q /= np.linalg.norm(q)
        s = f.from_common(q, W0)
        nn = np.linalg.norm(s[:3])
        assert 1.9 / delta < nn < 2.1 / delta
        err = abs(f.hamiltonian(s) / E - 1)
        assert err <= 4 * np.finfo(float).eps * nn, (delta, err)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda at, A: at.quaternion_multiply([[1.0, 0, 0, 0]] * 2, [[1.0, 0, 0, 0]] * 3), r"p \(2, 4\), q \(3, 4\)"),
        (lambda at, A: at.gibbs_compose([[0, 0, 1.0]] * 2, [[0, 0, 1.0]] * 3), r"n1 \(2, 3\), n2 \(3, 3\)"),
        (lambda at, A: at.gibbs_rate_from_omega([[0, 0, 1.0]] * 2, [[0, 0, 1.0]] * 3), r"n \(2, 3\), omega \(3, 3\)"),
        (lambda at, A: at.omega_from_gibbs_rate([[0, 0, 1.0]] * 2, [[0, 0, 1.0]] * 3), r"n \(2, 3\), ndot \(3, 3\)"),
        (lambda at, A: at.gibbs_chart([[1.0, 0, 0, 0]] * 2, [[1.0, 0, 0, 0]] * 3), r"q \(2, 4\), reference \(3, 4\)"),
        (
            lambda at, A: at.quaternion_from_chart([[1.0, 0, 0, 0]] * 2, [[0, 0, 1.0]] * 3),
            r"reference \(2, 4\), n \(3, 3\)",
        ),
        (lambda at, A: A.identity(2) * A.identity(3), r"self \(2, 4\), other \(3, 4\)"),
        (lambda at, A: A.identity(2).angle_to(A.identity(3)), r"self \(2, 4\), other \(3, 4\)"),
    ],
)
def test_attitude_functions_name_the_shapes_that_do_not_broadcast(call, match):
    import eulerpoisson.attitude as at

    with pytest.raises(InvalidInputError, match="batch shapes do not broadcast: " + match):
        call(at, Attitude)


def test_batch_shapes_of_the_factories():
    assert Attitude.identity((2, 3)).as_quaternion().shape == (2, 3, 4)
    assert Attitude.random(np.int64(5), rng=0).as_quaternion().shape == (5, 4)
    with pytest.raises(TypeError, match="shape must be an int or a tuple of ints, got 2.5"):
        Attitude.identity(2.5)
    with pytest.raises(TypeError, match="shape must be an int or a tuple of ints, got True"):
        Attitude.random(True)
    with pytest.raises(InvalidInputError, match=r"shape entries must be >= 0, got \(2, -1\)"):
        Attitude.random((2, -1))


@pytest.mark.parametrize("key, value", [("tol", 2.0), ("tol", 1e-30), ("rtol", 1.0), ("rtol", 1e-15)])
def test_rk_relative_tolerances_scipy_would_change_are_refused(key, value):
    with pytest.raises(InvalidInputError, match=rf"rk: {key} must be in \[2.22e-14, 1\)"):
        solve(I123, [1.0], omega0=W0, method="rk", **{key: value})
    solve(I123, [1.0], omega0=W0, method="rk", tol=1e-13)  # the smallest tolerance of the benchmarks


@pytest.mark.parametrize("eps_axis", [1e-60, 1e-81, 1e-90, 1e-99])
def test_exact_near_the_separatrix_where_delta_underflows(eps_axis):
    """Spin about the middle axis with a 1e-60..1e-99 perturbation (1 - k^2 down to 1e-198): R_J of
    the regime-B integral once lost 10% to an underflow of (p-x)(p-y)(p-z) and d^2 (0.11 rad of
    attitude error); the attitude is a plain rotation about axis 2 at rate 1 until the flip."""
    t = np.array([-5.0, 1.0, 2.0, 5.0])
    tr = solve(I123, t, omega0=[eps_axis, 1.0, eps_axis])
    q = tr.quaternion
    ref = np.stack([np.cos(t / 2), 0 * t, np.sin(t / 2), 0 * t], axis=-1)
    dist = np.minimum(np.linalg.norm(q - ref, axis=-1), np.linalg.norm(q + ref, axis=-1))  # q and -q: one rotation
    assert np.max(dist) < 1e-15


def test_carlson_rj_with_underflowing_products():
    mpmath = pytest.importorskip("mpmath")
    from eulerpoisson.numerics.elliptic import rj_core

    for m1 in (1e-100, 1e-162, 1e-180, 1e-199, 1e-250, 1e-300):
        v = rj_core(np.array([0.0]), np.array([m1]), np.array([1.0]), np.array([0.25 * m1]))[0]
        ref = float(mpmath.elliprj(0, m1, 1, 0.25 * m1))
        assert abs(v / ref - 1) < 4 * np.finfo(float).eps, m1
