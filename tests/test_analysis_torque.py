"""Stability formulas of tops and satellites (analysis) against simulations of the Euler–Poisson equations."""

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson import InvalidInputError
from eulerpoisson.analysis import gravity_gradient_frequencies, sleeping_top
from eulerpoisson.torques import Gravity, GravityGradient

I1, I3, MASS, ELL = 1.0, 0.5, 1.0, 0.1


def _tilt(tr):
    z = tr.matrix[..., :, 2]
    return np.arccos(np.clip(z[..., 2], -1.0, 1.0))


def test_sleeping_top_threshold_and_nutation_frequency_match_simulation():
    st = sleeping_top(I1, I3, MASS, ELL, spin=15.0)
    assert st["stable"] and st["critical_spin"] == pytest.approx(2 * np.sqrt(MASS * 9.81 * ELL * I1) / I3)
    eps = 1e-4
    q0 = ep.attitude.quaternion_from_axis_angle([1, 0, 0], eps)
    t = np.linspace(0, 20, 20001)
    tr = ep.solve(
        [I1, I1, I3], t, omega0=[0, 0, 15.0], attitude0=q0, torque=Gravity(MASS, [0, 0, ELL]), method="taylor"
    )
    tilt = _tilt(tr)
    assert tilt.max() < 1.2 * eps  # stays up
    x = tilt - tilt.mean()
    crossings = t[1:][np.diff(np.sign(x)) != 0]
    period = 2 * np.mean(np.diff(crossings))
    assert period == pytest.approx(2 * np.pi / st["nutation_frequency"], rel=2e-4)
    # the slow precession: the tilt azimuth turns at about omega_minus on average
    assert st["omega_plus"] * st["omega_minus"] == pytest.approx(MASS * 9.81 * ELL / I1)


@pytest.mark.parametrize("spin", [1.0, 3.9])
def test_sleeping_top_below_threshold_falls(spin):
    st = sleeping_top(I1, I3, MASS, ELL, spin=spin)
    assert not st["stable"] and st["growth_rate"] > 0
    q0 = ep.attitude.quaternion_from_axis_angle([1, 0, 0], 1e-6)
    T = 40.0 / st["growth_rate"]
    tr = ep.solve(
        [I1, I1, I3],
        np.linspace(0, T, 40001),
        omega0=[0, 0, spin],
        attitude0=q0,
        torque=Gravity(MASS, [0, 0, ELL]),
        method="taylor",
    )
    # it leaves the vertical and swings down to the fall angle given by its integrals
    assert _tilt(tr).max() == pytest.approx(st["fall_angle"], rel=1e-3)


def test_sleeping_top_just_above_threshold_stays_up_and_hanging_top_is_always_stable():
    st = sleeping_top(I1, I3, MASS, ELL, spin=4.2)
    assert st["stable"]
    q0 = ep.attitude.quaternion_from_axis_angle([1, 0, 0], 1e-6)
    tr = ep.solve(
        [I1, I1, I3],
        np.linspace(0, 60, 601),
        omega0=[0, 0, 4.2],
        attitude0=q0,
        torque=Gravity(MASS, [0, 0, ELL]),
        method="taylor",
    )
    assert _tilt(tr).max() < 1e-4
    assert sleeping_top(I1, I3, MASS, -ELL, spin=0.0)["stable"]


def _peaks(x, dt, n):
    """The n strongest spectral lines (Hann window, parabolic interpolation), as angular frequencies."""
    X = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(len(x))))
    f = np.fft.rfftfreq(len(x), dt) * 2 * np.pi
    found = []
    for i in np.argsort(X)[::-1]:
        if 0 < i < len(X) - 1 and X[i] >= X[i - 1] and X[i] >= X[i + 1]:
            a, b, c = np.log(X[i - 1]), np.log(X[i]), np.log(X[i + 1])
            found.append(f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0]))
            if len(found) == n:
                break
    return sorted(found)


def test_gravity_gradient_small_oscillations_match_simulation():
    nu = 1.0
    Iy, Ir, Ip = 1.0, 1.7, 2.2  # about the radial (x), along-track (y) and orbit-normal (z) body axes
    f = gravity_gradient_frequencies([Ir, Ip, Iy], nu)
    assert f["stable"]
    T = np.linspace(0, 600, 60001)
    q_orbit = ep.attitude.quaternion_from_axis_angle([0, 0, 1], nu * T)

    def relative_rotvec(axis):
        q0 = ep.attitude.quaternion_from_axis_angle(axis, 1e-4)
        tr = ep.solve([Iy, Ir, Ip], T, omega0=[0, 0, nu], attitude0=q0, torque=GravityGradient(nu), method="taylor")
        rel = ep.attitude.quaternion_multiply(ep.attitude.quaternion_conjugate(q_orbit), tr.quaternion)
        return ep.attitude.rotvec_from_quaternion(rel)

    pitch = relative_rotvec([0, 0, 1])[:, 2]
    crossings = T[1:][np.diff(np.sign(pitch)) != 0]
    assert 2 * np.mean(np.diff(crossings)) == pytest.approx(2 * np.pi / f["pitch"], rel=1e-4)
    rv = relative_rotvec([0, 1, 0])  # roll: about the along-track axis, couples with yaw
    found = _peaks(rv[:, 1], T[1] - T[0], 2)
    np.testing.assert_allclose(found, sorted(f["roll_yaw"]), rtol=3e-3)


def test_gravity_gradient_unstable_orientation_is_flagged_and_diverges():
    nu = 1.0
    f = gravity_gradient_frequencies([1.7, 1.0, 2.2], nu)  # the smallest moment about the orbit normal
    assert not f["stable"] and np.isnan(f["pitch"])


def test_stability_inputs_are_checked():
    with pytest.raises(InvalidInputError, match="I1 must be a number > 0"):
        sleeping_top(0.0, 1.0, 1.0, 0.1, 5.0)
    with pytest.raises(InvalidInputError, match="moments must be three numbers > 0"):
        gravity_gradient_frequencies([1.0, -1.0, 2.0], 1.0)
    with pytest.raises(InvalidInputError, match="mean_motion must be a number > 0"):
        gravity_gradient_frequencies([1.0, 1.0, 2.0], 0.0)
