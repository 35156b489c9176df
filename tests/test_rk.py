"""The scipy ``solve_ivp`` baseline (``method="rk"``) against the independent DOP853 reference."""

import numpy as np
import pytest

from _reference import quaternion_distance, reference_motion
from eulerpoisson import InvalidInputError
from eulerpoisson.solvers import solve
from eulerpoisson.solvers.rk.method import INTEGRATORS, RK

BODY = [[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]]  # full tensor
Q0 = np.array([0.5, 0.5, -0.5, 0.5])
W0 = np.array([0.9, -1.3, 0.5])
T = np.array([4.0, -3.0, 0.0, 1.0, 12.0, 12.0])  # unsorted, negative, repeated


@pytest.fixture(scope="module")
def reference():
    tu, inv = np.unique(T, return_inverse=True)
    q, w = reference_motion(BODY, W0, Q0, tu)
    return q[inv], w[inv]


@pytest.mark.parametrize("formulation", ["quaternion", "gibbs"])
def test_agrees_with_reference(formulation, reference):
    q_ref, w_ref = reference
    tr = solve(BODY, T, omega0=W0, attitude0=Q0, method="rk", formulation=formulation, tol=1e-12)
    assert np.max(quaternion_distance(tr.quaternion, q_ref)) < 1e-9
    assert np.max(np.abs(tr.omega - w_ref)) < 1e-9
    assert abs(abs(tr.quaternion[2] @ Q0) - 1.0) < 1e-15  # t = 0 is the initial state (up to sign)
    np.testing.assert_allclose(tr.omega[2], W0, atol=1e-15)
    if formulation == "gibbs":
        assert tr.stats["chart_changes"] >= 6  # about 4 per turn, 15 time units at |Omega| ~ 1.6
    else:
        assert tr.stats["chart_changes"] == 0


@pytest.mark.parametrize("integrator", sorted(INTEGRATORS))
def test_every_scipy_integrator_works(integrator, reference):
    q_ref, w_ref = reference
    for formulation in ("quaternion", "gibbs"):
        tr = solve(
            BODY, T, omega0=W0, attitude0=Q0, method="rk", integrator=integrator, formulation=formulation, tol=1e-8
        )
        assert tr.stats["integrator"] == integrator and tr.stats["nfev"] > 0
        err = max(np.max(quaternion_distance(tr.quaternion, q_ref)), np.max(np.abs(tr.omega - w_ref)))
        assert err < 1e-4, (integrator, formulation, err)


def test_explicit_rtol_atol_are_used(reference):
    q_ref, _ = reference
    loose = solve(BODY, T, omega0=W0, attitude0=Q0, method="rk", rtol=1e-4, atol=1e-4)
    tight = solve(BODY, T, omega0=W0, attitude0=Q0, method="rk", rtol=1e-12, atol=1e-12)
    e_loose = np.max(quaternion_distance(loose.quaternion, q_ref))
    e_tight = np.max(quaternion_distance(tight.quaternion, q_ref))
    assert e_tight < 1e-9 < 1e-6 < e_loose
    assert loose.stats["nfev"] < tight.stats["nfev"]


def test_formulations_agree_through_many_chart_changes():
    w0 = 25.0 * np.array([0.3, 0.2, 0.93])
    t = np.linspace(-4.0, 4.0, 81)
    a = solve([1.0, 2.0, 3.0], t, omega0=w0, method="rk", formulation="quaternion", tol=1e-12)
    b = solve([1.0, 2.0, 3.0], t, omega0=w0, method="rk", formulation="gibbs", tol=1e-12)
    assert b.stats["chart_changes"] > 100
    assert np.max(quaternion_distance(a.quaternion, b.quaternion)) < 1e-8
    assert b.drift()["energy"] < 1e-9 and max(b.drift()[k] for k in ("m_x", "m_y", "m_z")) < 1e-9


@pytest.mark.parametrize("threshold", [0.3, 5.0])
def test_chart_threshold(threshold, reference):
    q_ref, _ = reference
    tr = solve(BODY, T, omega0=W0, attitude0=Q0, method="rk", formulation="gibbs", tol=1e-11, chart_threshold=threshold)
    assert np.max(quaternion_distance(tr.quaternion, q_ref)) < 1e-8


def test_only_zero_time_and_rest():
    tr = solve(BODY, [0.0, 0.0], omega0=W0, attitude0=Q0, method="rk", formulation="gibbs")
    np.testing.assert_allclose(np.abs(tr.quaternion @ Q0), 1.0, atol=1e-15)
    tr = solve(BODY, [-1.0, 2.0], omega0=[0.0, 0.0, 0.0], attitude0=Q0, method="rk")
    np.testing.assert_allclose(np.abs(tr.quaternion @ Q0), 1.0, atol=1e-15)


def test_nominal_order():
    assert RK().nominal_order() == 8 == RK.order
    assert RK(integrator="RK45").nominal_order() == 5
    assert RK(integrator="RK23").nominal_order() == 3


@pytest.mark.parametrize(
    "opts,match",
    [
        ({"integrator": "Euler"}, "unknown integrator 'Euler'"),
        ({"integrator": "dop853"}, "unknown integrator"),
        ({"formulation": "euler-angles"}, "unknown formulation"),
        ({"tol": 0.0}, "tol must be"),
        ({"tol": float("inf")}, "tol must be"),
        ({"rtol": -1e-3}, "rtol must be"),
        ({"atol": "small"}, "atol must be"),
        ({"chart_threshold": 0.0}, "chart_threshold must be > 0"),
        ({"chart_threshold": -2.0}, "chart_threshold"),
    ],
)
def test_bad_options(opts, match):
    with pytest.raises(InvalidInputError, match=match):
        solve(BODY, [0.0, 1.0], omega0=W0, method="rk", **opts)
