"""Registry-driven tests: every registered integrator (all methods but ``exact``).

Truth is an independent plain-scipy DOP853 solution at rtol = atol = 1e-13
(tests/_reference.py) and, where available, the closed form.

Per method, driven only by its class attributes (``refine``, ``order``) and
the instance's ``nominal_order()`` when it has one (the order may depend on
the options, e.g. the symplectic scheme):

* ``refine == "dt"``: the observed order of convergence, the log2 of the
  error ratio of two consecutive halvings of ``dt`` in the asymptotic range,
  matches the nominal order within 0.6.
* ``refine == "tol"``: error decreases monotonically as ``tol`` decreases and
  is tolerance proportional, error ~ tol**a with 0.6 <= a <= 1.5 (adaptive
  integrators are not expected to track ``tol`` more closely than that).
* a fast spinning body (|Omega| = 40, 64 turns, 64 passages through the
  rotation angle pi, hundreds of chart changes for chart-based methods)
  keeps E and m to method-appropriate tolerances and stays on the truth;
* negative and unsorted output times;
* batches give the results of solving each body alone;
* an unknown option and a non-positive refine value raise.
"""

import numpy as np
import pytest

from _reference import quaternion_distance, reference_motion
from eulerpoisson import InvalidInputError, RigidBody
from eulerpoisson.solvers import available_methods, get_method, solve

METHODS = [m for m in available_methods() if m != "exact"]

I_ASYM = np.array([1.0, 2.0, 3.0])
W0 = np.array([1.0, 0.3, 0.6])


def nominal_order(name, **options):
    """The convention: an instance method ``nominal_order()`` if present, else the class attribute ``order``."""
    cls = get_method(name)
    inst = cls(**options)
    f = getattr(inst, "nominal_order", None)
    return f() if callable(f) else cls.order


def accuracy_option(name, level):
    """Options giving a rotation of ``level`` rad per step (dt methods) or tol = ``level`` (tol methods)."""
    cls = get_method(name)
    return {cls.refine: level} if cls.refine else {}


def error(tr, q_ref, w_ref):
    """Max over output times of attitude angle error + relative angular velocity error."""
    dq = quaternion_distance(tr.quaternion, q_ref)
    dw = np.linalg.norm(tr.omega - w_ref, axis=-1) / np.linalg.norm(w_ref, axis=-1)
    return float(np.max(dq + dw))


@pytest.mark.parametrize("name", METHODS)
def test_observed_order_matches_nominal(name):
    cls = get_method(name)
    if cls.refine is None:
        pytest.skip(f"{name} has no accuracy option")
    t = np.array([0.0, 2.0, 4.0])
    q_ref, w_ref = reference_motion(I_ASYM, W0, np.array([1.0, 0, 0, 0]), t)
    if cls.refine == "dt":
        p = nominal_order(name)
        errs = []
        dt = 0.4
        while True:
            errs.append(error(solve(I_ASYM, t, omega0=W0, method=name, dt=dt), q_ref, w_ref))
            if errs[-1] < 1e-9 or len(errs) == 6:
                break
            dt /= 2
        usable = [e for e in errs if e > 1e-11]
        assert len(usable) >= 2, (name, errs)
        slope = np.log2(usable[-2] / usable[-1])
        assert abs(slope - p) <= 0.6, (name, p, slope, errs)
    else:
        tols = [1e-5, 1e-7, 1e-9, 1e-11]
        errs = [error(solve(I_ASYM, t, omega0=W0, method=name, tol=tol), q_ref, w_ref) for tol in tols]
        assert all(a > b for a, b in zip(errs, errs[1:])), (name, errs)
        a = np.polyfit(np.log10(tols), np.log10(errs), 1)[0]
        assert 0.6 <= a <= 1.5, (name, a, errs)
        assert errs[-1] < 1e-8


FAST_W0 = 40.0 * np.array([0.3, 0.2, 0.93]) / np.linalg.norm([0.3, 0.2, 0.93])
FAST_T = np.linspace(0.0, 10.0, 401)


def _fast_reference_motion():
    return reference_motion(I_ASYM, FAST_W0, np.array([1.0, 0, 0, 0]), FAST_T, rtol=1e-11, atol=1e-11)


@pytest.fixture(scope="module")
def fast_reference(run_once):
    # computed once per test run (``run_once`` of tests/conftest.py): the tests that use it (one per method) may
    # run on different pytest-xdist workers
    q_ref, w_ref = run_once("test_integrators-fast_reference", _fast_reference_motion)
    # the true motion passes through alpha = pi (w = 0) once per turn: 64 times here
    q_cont = q_ref * np.concatenate([[1.0], np.cumprod(np.sign(np.sum(q_ref[1:] * q_ref[:-1], -1)))])[:, None]
    assert np.sum(np.diff(np.sign(q_cont[:, 0])) != 0) >= 60
    return q_ref, w_ref


@pytest.mark.parametrize("name", METHODS)
def test_fast_spin_through_hundreds_of_chart_crossings(name, fast_reference):
    cls = get_method(name)
    q_ref, w_ref = fast_reference
    t = FAST_T
    w0 = FAST_W0
    if cls.refine == "dt":
        # 0.2 rad per step; energy/momentum errors O(0.2**p) per unit of rotation, or
        # per chart change for the Gibbs-chart Gauss methods (see symplectic docs)
        opts = {"dt": 0.2 / 40.0}
        p = nominal_order(name)
        tol_cons = 5e-3 * 0.2 ** (p - 4) if p < 4 else 5e-3
    elif cls.refine == "tol":
        opts = {"tol": 1e-10}
        tol_cons = 1e-6
    else:
        opts, tol_cons = {}, 1e-6
    tr = solve(I_ASYM, t, omega0=w0, method=name, **opts)
    d = tr.drift()
    assert d["energy"] < tol_cons, (name, d)
    assert max(d["m_x"], d["m_y"], d["m_z"]) < tol_cons, (name, d)
    assert error(tr, q_ref, w_ref) < 100 * tol_cons, (name, error(tr, q_ref, w_ref))
    changes = tr.stats.get("chart_changes", 0)
    if changes:  # chart-based: about 4 re-centrings per turn at |n| = 1
        assert changes >= 200, (name, changes)


@pytest.mark.parametrize("name", METHODS)
def test_backward_and_unsorted_times(name):
    t = np.array([1.5, -2.0, 0.0, -0.5, 3.0, -2.0])  # unsorted, with a repeated time
    body = RigidBody([[2.0, 0.3, 0.0], [0.3, 1.5, 0.1], [0.0, 0.1, 2.5]])
    q0 = np.array([0.5, 0.5, -0.5, 0.5])
    w0 = np.array([0.7, -1.1, 0.4])
    tu, inv = np.unique(t, return_inverse=True)
    q_ref, w_ref = reference_motion(body.inertia, w0, q0, tu)
    q_ref, w_ref = q_ref[inv], w_ref[inv]
    cls = get_method(name)
    opts = {"dt": 0.01} if cls.refine == "dt" else accuracy_option(name, 1e-11)
    tr = solve(body, t, omega0=w0, attitude0=q0, method=name, **opts)
    assert error(tr, q_ref, w_ref) < 1e-6
    assert abs(abs(tr.quaternion[2] @ q0) - 1.0) < 1e-15  # t = 0 is the initial state (up to sign)
    np.testing.assert_allclose(tr.omega[2], w0, atol=1e-14)


@pytest.mark.parametrize("name", METHODS)
def test_batch_equals_bodies_alone(name, rng):
    inertia = np.stack([[1.0, 2.0, 2.5], [3.0, 2.0, 1.5], [1.0, 1.0, 1.8]])[:, None, :] * np.ones((3, 2, 1))
    w0 = rng.normal(size=(3, 2, 3))
    q0 = rng.normal(size=(3, 2, 4))
    q0 /= np.linalg.norm(q0, axis=-1, keepdims=True)
    t = np.array([0.0, 0.7, -0.4, 2.0])
    cls = get_method(name)
    opts = {"dt": 0.05} if cls.refine == "dt" else accuracy_option(name, 1e-9)
    tr = solve(inertia, t, omega0=w0, attitude0=q0, method=name, **opts)
    assert tr.quaternion.shape == (3, 2, 4, 4) and tr.omega.shape == (3, 2, 4, 3)
    for i in range(3):
        for j in range(2):
            one = solve(inertia[i, j], t, omega0=w0[i, j], attitude0=q0[i, j], method=name, **opts)
            np.testing.assert_allclose(tr.quaternion[i, j], one.quaternion, rtol=0, atol=1e-13)
            np.testing.assert_allclose(tr.omega[i, j], one.omega, rtol=0, atol=1e-13)


@pytest.mark.parametrize("name", METHODS)
def test_unknown_option_and_bad_accuracy_value(name):
    with pytest.raises(TypeError, match="unexpected keyword argument .no_such_option."):
        solve(I_ASYM, [0.0, 1.0], omega0=W0, method=name, no_such_option=1)
    refine = get_method(name).refine
    if refine:
        with pytest.raises(InvalidInputError, match=refine):
            solve(I_ASYM, [0.0, 1.0], omega0=W0, method=name, **{refine: -1.0})


@pytest.mark.parametrize("name", METHODS)
def test_agrees_with_closed_form(name):
    t = np.array([0.0, 1.0, -2.5, 7.0])
    ex = solve(I_ASYM, t, omega0=W0, method="exact")
    cls = get_method(name)
    opts = {"dt": 0.01} if cls.refine == "dt" else accuracy_option(name, 1e-12)
    tr = solve(I_ASYM, t, omega0=W0, method=name, **opts)
    assert error(tr, ex.quaternion, ex.omega) < 1e-6
