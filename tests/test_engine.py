"""The one solve engine (issue 21): configuration once, segments, continuation, evaluation of a trajectory."""

from __future__ import annotations

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.solvers import get_method
from eulerpoisson.solvers.engine import continue_from, default_method, evaluate, plan_segments, prepare_run

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]


def test_a_method_is_asked_with_its_options():
    """``supports`` of a configured method sees its options: a free-body scheme is refused before any work."""
    model = ep.Model(I, ep.torques.BodyTorque([0.0, 0.0, 0.1]))
    cls = get_method("symplectic")
    assert cls.supports(model) is None  # some scheme runs it
    assert cls(scheme="exact_splitting4").supports(model) is None
    assert "solves the free body only" in cls(scheme="gauss4").supports(model)
    with pytest.raises(ep.UnsupportedModelError, match="scheme 'gauss4' solves the free body only"):
        ep.solve(model, [0.0, 1.0], omega0=W0, method="symplectic", scheme="gauss4")


def test_default_method_rule():
    assert default_method(ep.Model(I)) == "exact"
    assert default_method(ep.Model([1.0, 1.0, 0.5], ep.torques.Gravity(1.0, [0.0, 0.0, 0.1]))) == "exact"
    assert default_method(ep.Model(I, ep.torques.GravityGradient(0.1))) == "taylor"
    assert default_method(ep.Model(I, lambda t, q, w: -0.01 * w)) == "rk"


def test_unknown_keyword_is_refused_before_the_method_is_chosen():
    with pytest.raises(
        TypeError, match=r"solve\(\) got an unexpected keyword argument 'tolerance'.*options of the methods: .*\btol\b"
    ):
        ep.solve(I, [0.0, 1.0], omega0=W0, tolerance=1e-9)


@pytest.mark.parametrize("n, k", [(1, 1), (50_000, 1), (50_001, 2), (150_000, 3)])
def test_plan_segments_by_samples(n, k):
    bounds = plan_segments(n, closed_form=False, monotonic=True)
    assert len(bounds) == k and bounds[0][0] == 0 and bounds[-1][1] == n
    assert all(b0[1] == b1[0] for b0, b1 in zip(bounds, bounds[1:]))


def test_plan_segments_by_turns_and_order():
    assert plan_segments(11, closed_form=False, monotonic=True, turns=1e9) == plan_segments(
        11, closed_form=False, monotonic=True, turns=2e9
    )
    assert len(plan_segments(11, closed_form=False, monotonic=True, turns=1e9)) == 10  # at most n - 1
    assert plan_segments(10, closed_form=False, monotonic=False, turns=1e9) == [(0, 10)]
    assert plan_segments(0, closed_form=True, monotonic=True) == []


def test_continue_from_a_sample_is_the_motion():
    """Continuing the exact method from a later state (a segment boundary) gives the motion there."""
    t = np.linspace(0.0, 20.0, 21)
    ref = ep.solve(I, t, omega0=W0)
    run = prepare_run(I, t[10:], omega0=W0, method="exact", in_memory=True)
    part = continue_from(run, t[10:], float(t[9]), ref.quaternion[9], ref.omega[9])
    np.testing.assert_allclose(part.omega, ref.omega[10:], atol=1e-13)
    assert np.max(np.abs(np.abs(np.sum(part.quaternion * ref.quaternion[10:], -1)) - 1)) < 1e-13


@pytest.mark.parametrize("method", ["exact", "taylor", "rk"])
def test_calling_a_trajectory_evaluates_near_its_samples(method):
    """tr(t) continues from the nearest stored sample: inside, outside and between samples."""
    t = np.linspace(0.0, 10.0, 11)
    tr = ep.solve(I, t, omega0=W0, method=method)
    want = np.array([-0.5, 2.25, 7.7, 10.0, 13.0])
    got = tr(want)
    ref = ep.solve(I, want, omega0=W0)
    tol = 1e-12 if method != "rk" else 1e-8
    np.testing.assert_allclose(got.omega, ref.omega, atol=tol)
    assert got.method == method and got.t.tolist() == want.tolist()
    # a stored time comes back as stored (the nearest sample is itself: no integration)
    same = tr([4.0])
    np.testing.assert_array_equal(same.omega[0], tr.omega[4])


def test_calling_evaluates_from_the_nearest_sample_not_from_the_start():
    """A trajectory whose first sample was edited: a time near the end does not see the edit."""
    t = np.linspace(0.0, 10.0, 11)
    tr = ep.solve(I, t, omega0=W0, method="taylor")
    tr.omega[0] = [5.0, 5.0, 5.0]  # a wrong first sample: re-integration from t[0] would carry it
    late = evaluate(tr, [9.5])
    ref = ep.solve(I, [9.5], omega0=W0)
    np.testing.assert_allclose(late.omega, ref.omega, atol=1e-12)


def test_calling_an_empty_trajectory_is_an_error():
    tr = ep.solve(I, [], omega0=W0)
    assert tr.t.size == 0
    with pytest.raises(ep.InvalidInputError, match="no output times cannot be evaluated"):
        tr([1.0])


def test_a_selection_keeps_the_signs_of_the_whole_trajectory():
    """Indexing never flips a quaternion (continuity is the whole run's, not the selection's)."""
    t = np.linspace(0.0, 40.0, 4001)
    tr = ep.solve(I, t, omega0=W0)
    ends = tr[[0, -1]]
    np.testing.assert_array_equal(ends.quaternion, tr.quaternion[[0, -1]])
