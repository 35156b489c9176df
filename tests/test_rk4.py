"""``method="rk4"`` and the shared fixed-step driver (:mod:`eulerpoisson.solvers.stepper`).

* order 4 against the closed form (free body), agreement with ``rk`` at tol 1e-12 under torque
  (a heavy asymmetric top and a Python callable);
* negative, unsorted and repeated output times;
* option validation, ``max_steps``, a non-finite state;
* the driver's step plan (full steps of dt, a last shorter one landing on each output) and the
  property it is built for: splitting the output times into two calls, the second continued from
  the last state of the first, gives the same bits as one call.
"""

import numpy as np
import pytest

import eulerpoisson as ep
from _reference import quaternion_distance
from eulerpoisson import EulerPoissonError, InvalidInputError
from eulerpoisson.solvers import Problem, available_methods, get_method, make_problem, methods_supporting
from eulerpoisson.solvers.rk4 import RK4, RK4Options, RK4Stepper
from eulerpoisson.solvers.stepper import Stepper, StepState, run_fixed_step, step_plan
from eulerpoisson.torques import Gravity, UnrecordedTorque

I_ASYM = np.array([1.0, 2.0, 3.0])
W0 = np.array([1.0, 0.3, 0.6])
I_FULL = np.array([[2.0, 0.1, 0.05], [0.1, 1.5, -0.2], [0.05, -0.2, 1.2]])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])


def error(tr, q_ref, w_ref):
    return float(np.max(quaternion_distance(tr.quaternion, q_ref)) + np.max(np.abs(tr.omega - w_ref)))


def damping(t, q, omega):
    """A time-dependent Python torque, vectorized over the batch."""
    return -0.1 * omega + 0.05 * np.cos(t) * q[..., 1:]


def test_registered_with_its_attributes():
    assert "rk4" in available_methods()
    cls = get_method("rk4")
    assert cls is RK4 and cls.order == 4 and cls.refine == "dt" and cls.negative_times
    assert "Runge-Kutta 4" in cls.description
    assert cls().config == {"dt": 0.005, "max_steps": 10_000_000}
    assert RK4(RK4Options(dt=0.02)).config["dt"] == 0.02
    assert "rk4" in methods_supporting(ep.Model(I_ASYM, damping))


def test_order_four_against_the_closed_form():
    t = np.array([0.0, 2.0, 4.0])
    ex = ep.solve(I_ASYM, t, omega0=W0, attitude0=Q0)
    errs = [
        error(ep.solve(I_ASYM, t, omega0=W0, attitude0=Q0, method="rk4", dt=dt), ex.quaternion, ex.omega)
        for dt in (0.05, 0.025)
    ]
    assert errs[1] < 1e-7
    assert 16.0 - 1.5 < errs[0] / errs[1] < 16.0 + 1.5, errs


@pytest.mark.parametrize("torque", [Gravity(1.3, [0.1, -0.2, 0.4]), damping], ids=["heavy_top", "callable"])
def test_agrees_with_rk_under_torque(torque):
    t = np.array([0.0, 0.6, -0.5, 1.0])
    w0 = [0.7, -1.1, 2.0]
    ref = ep.solve(I_FULL, t, omega0=w0, attitude0=Q0, torque=torque, method="rk", tol=1e-12)
    tr = ep.solve(I_FULL, t, omega0=w0, attitude0=Q0, torque=torque, method="rk4", dt=0.005)
    assert error(tr, ref.quaternion, ref.omega) < 1e-9


def test_negative_unsorted_and_repeated_times():
    t = np.array([1.5, -2.0, 0.0, -0.5, 3.0, -2.0])
    ex = ep.solve(I_FULL, t, omega0=W0, attitude0=Q0)
    tr = ep.solve(I_FULL, t, omega0=W0, attitude0=Q0, method="rk4", dt=0.01)
    assert error(tr, ex.quaternion, ex.omega) < 1e-8
    np.testing.assert_array_equal(tr.omega[2], W0)  # t = 0: the initial state, no step
    np.testing.assert_array_equal(tr.omega[1], tr.omega[5])
    # both branches from t = 0: 300 steps forward (0 -> 1.5 -> 3), 200 backward (0 -> -0.5 -> -2)
    assert tr.stats["steps"] == 500 and tr.stats["evaluations"] == 2000


def test_batch_gives_the_bits_of_each_body_alone(rng):
    inertia = np.array([[1.0, 2.0, 2.5], [3.0, 2.0, 1.5], [1.0, 1.0, 1.8], [2.0, 1.2, 1.5]])  # 4 bodies
    w0 = rng.normal(size=(4, 3))
    q0 = rng.normal(size=(4, 4))
    q0 /= np.linalg.norm(q0, axis=-1, keepdims=True)
    t = np.array([0.0, 0.7, -0.4])
    tr = ep.solve(inertia, t, omega0=w0, attitude0=q0, torque=damping, method="rk4", dt=0.05)
    for i in range(4):
        one = ep.solve(inertia[i], t, omega0=w0[i], attitude0=q0[i], torque=damping, method="rk4", dt=0.05)
        np.testing.assert_array_equal(tr.quaternion[i], one.quaternion)
        np.testing.assert_array_equal(tr.omega[i], one.omega)


@pytest.mark.parametrize(
    "options, error_type, match",
    [
        ({"dt": 0.0}, InvalidInputError, r"rk4: dt must be a finite number > 0, got 0\.0"),
        ({"dt": -0.1}, InvalidInputError, r"rk4: dt must be a finite number > 0"),
        ({"dt": float("inf")}, InvalidInputError, r"rk4: dt must be a finite number > 0"),
        ({"dt": "0.1"}, InvalidInputError, r"rk4: dt must be a positive number, got '0\.1'"),
        ({"dt": True}, InvalidInputError, r"rk4: dt must be a positive number"),
        ({"max_steps": 0}, InvalidInputError, r"rk4: max_steps must be an integer >= 1, got 0"),
        ({"max_steps": 10.0}, InvalidInputError, r"rk4: max_steps must be an integer >= 1"),
        ({"tol": 1e-9}, TypeError, r"tol"),
    ],
)
def test_bad_options(options, error_type, match):
    with pytest.raises(error_type, match=match):
        ep.solve(I_ASYM, [0.0, 1.0], omega0=W0, method="rk4", **options)


def test_max_steps_exhausted_before_the_first_step():
    ep.solve(I_ASYM, [1.0, -1.0], omega0=W0, method="rk4", dt=0.01, max_steps=200)  # exactly enough
    with pytest.raises(EulerPoissonError, match=r"rk4: the output times need 200 steps .*max_steps=199"):
        ep.solve(I_ASYM, [1.0, -1.0], omega0=W0, method="rk4", dt=0.01, max_steps=199)
    with pytest.raises(EulerPoissonError, match=r"need inf steps .*max_steps=10000000"):
        ep.solve(I_ASYM, [1e300], omega0=W0, method="rk4", dt=1e-300)


def test_non_finite_state_stops_the_run():
    with pytest.raises(EulerPoissonError, match=r"rk4: the state became non-finite at t = .*smaller dt"):
        ep.solve(I_ASYM, [10.0], omega0=[1e120, 2e120, 3e120], method="rk4", dt=1.0)


def test_unrecorded_torque_is_refused():
    reason = RK4.supports(ep.Model(I_ASYM, UnrecordedTorque("CallableTorque('f')")))
    assert reason is not None and "not recorded" in reason


# ---------------------------------------------------------------------------
# the driver
# ---------------------------------------------------------------------------
class Recorder(Stepper):
    """Records the (t, h) of every step; the state does not move."""

    name = "recorder"

    def __init__(self):
        self.steps = []

    def step(self, state, t, h):
        self.steps.append((t, h))
        return state


def test_full_steps_then_a_last_shorter_one_landing_on_each_output():
    p = make_problem(I_ASYM, [0.25, -0.1, 0.3, 0.25], omega0=W0)
    rec = Recorder()
    res = run_fixed_step(rec, p, 0.1, 100)
    assert res.stats == {"dt": 0.1, "steps": 5, "evaluations": 0}
    expect = [(0.0, 0.1), (0.1, 0.1), (0.2, 0.25 - 0.2), (0.25, 0.3 - 0.25), (0.0, -0.1)]
    np.testing.assert_allclose(rec.steps, expect, rtol=0, atol=1e-15)
    assert step_plan(p.t, 0.1) == ([[0, 3, 2], [1]], 5.0)
    # an interval that is a multiple of dt up to rounding: that many full steps, no sliver
    assert step_plan(np.array([0.3]), 0.1)[1] == 3.0
    assert step_plan(np.array([1.0]), 0.1)[1] == 10.0


def test_driver_refuses_a_bad_dt():
    p = make_problem(I_ASYM, [1.0], omega0=W0)
    with pytest.raises(InvalidInputError, match=r"rk4: dt must be a finite number > 0"):
        run_fixed_step(RK4Stepper(), p, float("nan"), 100)


def test_stepper_base_has_no_dense_output():
    p = make_problem(I_ASYM, [1.0], omega0=W0)
    st = Stepper().init(p)
    assert isinstance(st, StepState) and st.q.shape == (1, 4) and st.omega.shape == (1, 3) and st.aux is None
    with pytest.raises(NotImplementedError, match="no dense output"):
        Stepper().interpolate(st, st, 0.0, 0.1, 0.5)


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["forward", "backward"])
def test_splitting_the_output_times_gives_the_same_bits(sign):
    """The reason for the driver's design: later outputs continue from the state at the previous output."""
    model = ep.Model(I_FULL, [damping, Gravity(1.3, [0.1, -0.2, 0.4])])  # time-dependent: t0 matters
    w0 = np.array([[0.7, -1.1, 2.0], [0.2, 0.5, -1.0]])
    t = sign * np.array([0.37, 1.0, 1.73, 2.2])
    stepper = RK4Stepper()
    whole = run_fixed_step(stepper, make_problem(model, t, omega0=w0, attitude0=Q0), 0.03, 10_000)
    first = run_fixed_step(stepper, make_problem(model, t[:2], omega0=w0, attitude0=Q0), 0.03, 10_000)
    # continue from the state at t[1] (a Problem made directly: make_problem would renormalize q0)
    cont = Problem(model=model, q0=first.q[:, -1], omega0=first.omega[:, -1], t=t[2:])
    second = run_fixed_step(stepper, cont, 0.03, 10_000, t0=float(t[1]))
    np.testing.assert_array_equal(np.concatenate([first.q, second.q], axis=1), whole.q)
    np.testing.assert_array_equal(np.concatenate([first.omega, second.omega], axis=1), whole.omega)
    assert first.stats["steps"] + second.stats["steps"] == whole.stats["steps"]
