"""The tennis-racket (Dzhanibekov) effect: flip times against 2K(k)/lambda and a numeric integration."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from _reference import reference_motion
from eulerpoisson import RigidBody, solve
from eulerpoisson.analysis import elliptic_parameters, flip_times, momentum_period, tennis_racket_half_period
from eulerpoisson.errors import InvalidInertiaError, InvalidInputError


def numeric_flip_times(I, M0, t_end):
    """Sign changes of M2 by DOP853 with event location (independent of the package)."""
    I = np.asarray(I, float)

    def f(_, M):
        return np.cross(M, M / I)

    ev = lambda _, M: M[1]  # noqa: E731
    sol = solve_ivp(f, (0, t_end), M0, method="DOP853", rtol=1e-13, atol=1e-15, events=ev)
    return sol.t_events[0]


@pytest.mark.parametrize("inertia", [(3.0, 5.0, 9.0), (3.0, 5.0, 8.0)])
def test_flip_half_period(inertia):
    M0 = np.array([0.0, 2.0, 0.01])
    body = RigidBody(inertia, allow_unphysical=True)
    half = tennis_racket_half_period(inertia, M0)
    tr = solve(body, np.linspace(0.0, 4.2 * half, 3000), omega0=M0 / np.array(inertia))
    flips = flip_times(tr, component=1)
    assert len(flips) == 4
    np.testing.assert_allclose(np.diff(flips), half, rtol=1e-11)
    # the first flip is at K/lambda (M2 = M2max cn(lambda t) starts at its maximum)
    np.testing.assert_allclose(flips[0], half / 2, rtol=1e-11)
    ref = numeric_flip_times(inertia, M0, 4.2 * half)
    np.testing.assert_allclose(flips, ref, rtol=1e-9)


def test_half_period_against_mpmath():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    I1, I2, I3 = (mp.mpf(3), mp.mpf(5), mp.mpf(9))
    M = [mp.mpf(0), mp.mpf(2), mp.mpf("0.01")]
    L2 = sum(x * x for x in M)
    E2 = M[0] ** 2 / I1 + M[1] ** 2 / I2 + M[2] ** 2 / I3
    assert L2 > E2 * I2  # circulation about the axis of largest moment
    k2 = (I2 - I1) * (E2 * I3 - L2) / ((I3 - I2) * (L2 - E2 * I1))
    lam = mp.sqrt((I3 - I2) * (L2 - E2 * I1) / (I1 * I2 * I3))
    half = 2 * mp.ellipk(k2) / lam
    got = tennis_racket_half_period((3.0, 5.0, 9.0), (0.0, 2.0, 0.01))
    assert abs(got - float(half)) <= 1e-13 * float(half)
    p = elliptic_parameters((3.0, 5.0, 9.0), (0.0, 2.0, 0.01))
    assert abs(p["k2c"] - float(1 - k2)) <= 1e-13 * float(1 - k2)
    assert p["axis"] == 2


def test_period_of_M_matches_integration():
    I = (1.0, 2.0, 3.0)
    M0 = np.array([1.0, 0.2, 1.5])
    T = momentum_period(I, M0)
    q, w = reference_motion(I, M0 / np.array(I), [1.0, 0, 0, 0], [T])
    np.testing.assert_allclose(w[0] * I, M0, atol=1e-10)


def test_unphysical_needs_opt_in_and_analysis_errors():
    with pytest.raises(InvalidInertiaError, match="allow_unphysical=True"):
        RigidBody([3.0, 5.0, 9.0])
    with pytest.raises(InvalidInputError, match="distinct principal moments"):
        elliptic_parameters([2.0, 2.0, 3.0], [1.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="separatrix"):
        elliptic_parameters([1.0, 2.0, 3.0], [0.0, 1.0, 0.0])
    with pytest.raises(InvalidInputError, match="at rest"):
        elliptic_parameters([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])
    tr = solve(RigidBody.from_moments([[1.0, 2.0, 3.0]] * 2), [0.0, 1.0], omega0=[1.0, 0.0, 0.1])
    with pytest.raises(InvalidInputError, match="single-body"):
        flip_times(tr)
