"""Tumbling periods P_psi, P_phi (analysis.tumbling_periods) and their inverse against simulations.

The truth is measured, not computed from the closed forms: the period of Omega(t) from the up-crossings of
its intermediate component, and the mean precession rate of each principal axis about the spatial momentum m
from the unwrapped azimuth of the axis about m between two crossings a whole number of periods apart (the
periodic part of the azimuth then cancels exactly). Two integrators: an independent DOP853 integration of
dR/dt = R[Omega]x, I dOmega/dt = (I Omega) x Omega (scipy only), and ep.solve(method="exact").
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import eulerpoisson as ep
from eulerpoisson.analysis import flip_times, momentum_period, spin_states_from_periods, tumbling_periods
from eulerpoisson.errors import InvalidInertiaError, InvalidInputError

# (inertia, M0, mode): moderately excited LAM and SAM, and both sides of the separatrix (1 - k^2 ~ 1e-6)
CASES = {
    "LAM": ((1.0, 2.0, 2.5), (1.0, 0.3, 0.2), "LAM"),
    "SAM": ((1.0, 2.0, 2.5), (0.2, 0.3, 1.0), "SAM"),
    "LAM-near-separatrix": ((1.0, 2.0, 3.0), (2e-3, 1.0, 1e-3), "LAM"),
    "SAM-near-separatrix": ((1.0, 2.0, 3.0), (1e-3, 1.0, 2e-3), "SAM"),
}


def _azimuths(axes, m):
    """Unwrapped azimuth about m of spatial directions axes (T, 3)."""
    mh = m / np.linalg.norm(m)
    u = np.cross(mh, [0.3, 0.5, 0.7])
    u /= np.linalg.norm(u)
    v = np.cross(mh, u)
    return np.unwrap(np.arctan2(axes @ v, axes @ u))


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def measure_dop853(I, M0, n_periods):
    """(period of Omega, mean precession rates of the three axes about m) by DOP853, rtol 1e-12."""
    I, M0 = np.asarray(I, float), np.asarray(M0, float)
    mid = int(np.argsort(I)[1])

    def f(_, y):
        R, W = y[:9].reshape(3, 3), y[9:]
        return np.concatenate([(R @ _hat(W)).ravel(), np.cross(I * W, W) / I])

    def up(_, y):  # the intermediate component goes as sn: one up-crossing per period, in both modes
        return y[9 + mid]

    up.direction = 1.0
    t_end = (n_periods + 1.2) * momentum_period(I, M0)  # only the span of the run
    sol = solve_ivp(
        f,
        (0.0, t_end),
        np.concatenate([np.eye(3).ravel(), M0 / I]),
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        events=up,
        dense_output=True,
    )
    te = sol.t_events[0]
    n = len(te) - 1
    assert n >= n_periods
    t = np.linspace(te[0], te[-1], 400 * n + 1)
    R = sol.sol(t)[:9].T.reshape(-1, 3, 3)
    rates = [np.diff(_azimuths(R[:, :, ax], M0)[[0, -1]])[0] / (te[-1] - te[0]) for ax in range(3)]
    return (te[-1] - te[0]) / n, np.array(rates)


def measure_exact(I, M0, n_periods):
    """The same measurements on ep.solve(method="exact") (crossings located by flip_times)."""
    I, M0 = np.asarray(I, float), np.asarray(M0, float)
    mid = int(np.argsort(I)[1])
    body = ep.RigidBody(I, allow_unphysical=True)
    T = momentum_period(I, M0)
    tr = ep.solve(body, np.linspace(0.0, (n_periods + 1.2) * T, 200 * (n_periods + 2)), omega0=M0 / I, method="exact")
    flips = flip_times(tr, component=mid)  # every half period
    n = (len(flips) - 1) // 2
    t0, t1 = flips[0], flips[2 * n]
    tr = ep.solve(body, np.linspace(t0, t1, 400 * n + 1), omega0=M0 / I, method="exact")
    m = tr.m[0]
    rates = [np.diff(_azimuths(tr.matrix[:, :, ax], m)[[0, -1]])[0] / (t1 - t0) for ax in range(3)]
    return (t1 - t0) / n, np.array(rates)


def _expected_rates(p):
    return 2 * np.pi / p["P_axes"]


@pytest.mark.parametrize("case", list(CASES))
def test_periods_against_dop853(case):
    I, M0, mode = CASES[case]
    p = tumbling_periods(I, M0)
    assert p["mode"] == mode
    P, rates = measure_dop853(I, M0, 4 if "separatrix" in case else 8)
    assert P == pytest.approx(p["P_omega"], rel=1e-9)
    assert p["P_psi"] == p["P_omega"] and p["P_theta"] == 0.5 * p["P_omega"]
    np.testing.assert_allclose(rates, _expected_rates(p), rtol=1e-9)
    # the circulation axis precesses at 2 pi / P_phi; the two others at 2 pi (1/P_phi +- 1/P_psi)
    c = p["axis"]
    assert c == (0 if mode == "LAM" else 2)
    assert rates[c] == pytest.approx(2 * np.pi / p["P_phi"], rel=1e-9)
    sign = 1.0 if mode == "LAM" else -1.0
    for ax in {0, 1, 2} - {c}:
        assert rates[ax] == pytest.approx(2 * np.pi * (1 / p["P_phi"] + sign / p["P_psi"]), rel=1e-9)
    assert rates[0] == pytest.approx(2 * np.pi / p["P_long"], rel=1e-9)  # axis 0 has the least moment


@pytest.mark.parametrize("case", ["LAM", "SAM", "SAM-near-separatrix"])
def test_periods_against_exact_solver(case):
    I, M0, _ = CASES[case]
    p = tumbling_periods(I, M0)
    P, rates = measure_exact(I, M0, 10)
    assert P == pytest.approx(p["P_omega"], rel=1e-9)
    np.testing.assert_allclose(rates, _expected_rates(p), rtol=1e-9)


def test_omega0_any_order_and_batch():
    I, M0, _ = CASES["SAM"]
    p = tumbling_periods(I, M0)
    q = tumbling_periods(I, omega0=np.asarray(M0) / I)
    for key in ("P_omega", "P_phi", "P_long", "E_over_E0"):
        assert q[key] == pytest.approx(p[key], rel=1e-15)
    perm = [2, 0, 1]
    r = tumbling_periods(np.asarray(I)[perm], np.asarray(M0)[perm])
    assert r["P_phi"] == pytest.approx(p["P_phi"], rel=1e-14) and r["P_long"] == pytest.approx(p["P_long"], rel=1e-14)
    np.testing.assert_allclose(r["P_axes"], p["P_axes"][perm], rtol=1e-14)
    assert r["axis"] == 0  # the largest moment is first in this order
    b = tumbling_periods([I, (1.0, 2.0, 3.0)], [M0, CASES["LAM-near-separatrix"][1]])
    assert b["P_phi"].shape == (2,) and b["P_axes"].shape == (2, 3) and list(b["mode"]) == ["SAM", "LAM"]
    assert b["P_phi"][0] == p["P_phi"]


def test_limits_and_energy_measure():
    I1, I2, I3 = 1.0, 2.0, 2.5
    L = 1.3
    # nearly relaxed SAM: the long axis turns at L/I3, the short axis precesses at L/I3 + polhode rate
    p = tumbling_periods([I1, I2, I3], [1e-5, 1e-5, L])
    wp = L / I3 * np.sqrt((I3 - I1) * (I3 - I2) / (I1 * I2))
    assert 2 * np.pi / p["P_long"] == pytest.approx(L / I3, rel=1e-9)
    assert 2 * np.pi / p["P_phi"] == pytest.approx(L / I3 + wp, rel=1e-9)
    assert p["E_over_E0"] == pytest.approx(1.0, abs=1e-9)
    # nearly pure long-axis spin: the short axis turns at L/I1
    p = tumbling_periods([I1, I2, I3], [L, 1e-5, 1e-5])
    assert 2 * np.pi / p["P_axes"][2] == pytest.approx(L / I1, rel=1e-9)
    assert p["E_over_E0"] == pytest.approx(I3 / I1, rel=1e-9)
    # at the separatrix the precession rate tends to L/I2 (both sides), slowly: the gap goes as 1/K(k)
    for side in ([1.0, 2.0], [2.0, 1.0]):
        gaps = []
        for eps in (1e-8, 1e-150):
            p = tumbling_periods([I1, I2, I3], [side[0] * eps, L, side[1] * eps])
            assert p["E_over_E0"] == pytest.approx(I3 / I2, rel=1e-12)
            gaps.append(abs(2 * np.pi / p["P_phi"] / (L / I2) - 1) * p["P_omega"])
        assert gaps[1] == pytest.approx(gaps[0], rel=1e-3)  # gap * P_omega (prop. to K) tends to a constant


def test_precession_rate_against_mpmath_pi():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 30
    for I, M0, mode in CASES.values():
        p = tumbling_periods(I, M0)
        I1, I2, I3 = (mp.mpf(x) for x in I)
        M = [mp.mpf(x) for x in M0]
        L2 = sum(x * x for x in M)
        E2 = sum(x * x / i for x, i in zip(M, (I1, I2, I3)))
        L = mp.sqrt(L2)
        if mode == "SAM":
            k2 = (I2 - I1) * (E2 * I3 - L2) / ((I3 - I2) * (L2 - E2 * I1))
            N = I3 * (I2 - I1) / (I1 * (I3 - I2))
            frac = mp.ellippi(-N, k2) / mp.ellipk(k2)
        else:
            k2 = (I3 - I2) * (L2 - E2 * I1) / ((I2 - I1) * (E2 * I3 - L2))
            N = I1 * (I3 - I2) / (I3 * (I2 - I1))
            frac = 1 - mp.ellippi(-N, k2) / mp.ellipk(k2)
        nu = L / I3 + L * (I3 - I1) / (I1 * I3) * frac
        assert p["P_phi"] == pytest.approx(float(2 * mp.pi / nu), rel=1e-13)


# --- the inverse ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", list(CASES))
def test_inverse_family_contains_the_truth_and_reproduces_the_periods(case):
    I, M0, mode = CASES[case]
    p = tumbling_periods(I, M0)
    a0, b0 = p["I1_I3"], p["I2_I3"]
    a = np.array([0.5 * a0, 0.8 * a0, a0, a0 + 0.5 * (b0 - a0)])
    fam = spin_states_from_periods(p["P_psi"], p["P_phi"], mode, I1_I3=a, I2_I3=b0)
    assert fam["valid"][2]
    # the member with the true inertia ratios is the true state
    assert fam["E_over_E0"][2] == pytest.approx(p["E_over_E0"], rel=1e-10)
    assert fam["L_over_I3"][2] == pytest.approx(p["L_over_I3"], rel=1e-10)
    assert fam["k2"][2] == pytest.approx(p["k2"], rel=1e-9)
    # every member reproduces both periods (in the given mode)
    for i in np.flatnonzero(fam["valid"]):
        q = tumbling_periods([fam["I1_I3"][i], fam["I2_I3"][i], 1.0], fam["M0"][i])
        assert q["mode"] == mode
        assert q["P_psi"] == pytest.approx(p["P_psi"], rel=1e-10)
        assert q["P_phi"] == pytest.approx(p["P_phi"], rel=1e-10)
        assert q["E_over_E0"] == pytest.approx(fam["E_over_E0"][i], rel=1e-10)


def test_inverse_is_a_two_parameter_family():
    I, M0, mode = CASES["LAM"]
    p = tumbling_periods(I, M0)
    a = np.linspace(0.1, 0.7, 7)[:, None]
    b = np.linspace(0.75, 0.95, 5)[None, :]
    fam = spin_states_from_periods(p["P_psi"], p["P_phi"], mode, I1_I3=a, I2_I3=b)
    assert fam["E_over_E0"].shape == (7, 5) and fam["M0"].shape == (7, 5, 3)
    # a member exists where the period ratio is below its value R0 at the relaxed (k -> 0) state
    s = np.sqrt((1 - a) * (b - a) / b)
    np.testing.assert_array_equal(fam["valid"], p["P_phi"] / p["P_psi"] < s / (1 - s))
    assert fam["valid"].sum() >= 15  # members with different inertia ratios and the same two periods
    for idx in zip(*np.nonzero(fam["valid"])):
        q = tumbling_periods([fam["I1_I3"][idx], fam["I2_I3"][idx], 1.0], fam["M0"][idx])
        assert q["P_psi"] == pytest.approx(p["P_psi"], rel=1e-10)
        assert q["P_phi"] == pytest.approx(p["P_phi"], rel=1e-10)
    assert np.all(np.isnan(fam["E_over_E0"][~fam["valid"]]))
    # SAM needs P_phi < P_psi: none is consistent otherwise
    assert not spin_states_from_periods(5.0, 6.0, "SAM", I1_I3=a, I2_I3=b)["valid"].any()


def test_inverse_apophis():
    # Pravec et al. (2014): SAM, P_psi = 263 h, P_phi = 27.38 h, I1/I3 = 0.61, I2/I3 = 0.965 -> E/E0 = 1.024;
    # the strongest lightcurve period 30.56 h is the long axis's, (1/P_phi - 1/P_psi)^-1
    fam = spin_states_from_periods(263.0, 27.38, "sam", I1_I3=0.61, I2_I3=0.965)
    assert fam["valid"] and fam["E_over_E0"] == pytest.approx(1.024, abs=2e-3)
    q = tumbling_periods([0.61, 0.965, 1.0], fam["M0"])
    assert q["P_long"] == pytest.approx(30.56, abs=0.01)


# --- errors --------------------------------------------------------------------------------------------------------


def test_tumbling_periods_errors():
    with pytest.raises(InvalidInputError, match="three distinct principal moments"):
        tumbling_periods([1.0, 2.0, 2.0], [1.0, 0.1, 0.1])
    with pytest.raises(InvalidInputError, match="M0 must be a nonzero vector"):
        tumbling_periods([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="omega0 must be a nonzero vector"):
        tumbling_periods([1.0, 2.0, 3.0], omega0=[0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="separatrix"):
        tumbling_periods([1.0, 2.0, 3.0], [0.0, 1.0, 0.0])
    with pytest.raises(InvalidInputError, match="separatrix"):  # exactly L^2 = 2 E I2 off the axis
        tumbling_periods([2.0, 3.0, 6.0], [1.0, 0.0, 1.0])
    with pytest.raises(InvalidInputError, match=r"M0 must have shape \(\.\.\., 3\)"):
        tumbling_periods([1.0, 2.0, 3.0], [1.0, 2.0])
    with pytest.raises(InvalidInputError, match=r"inertia must have shape \(\.\.\., 3\)"):
        tumbling_periods([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(InvalidInputError, match="M0 contains NaN"):
        tumbling_periods([1.0, 2.0, 3.0], [1.0, np.nan, 0.0])
    with pytest.raises(InvalidInputError, match="inertia contains NaN"):
        tumbling_periods([1.0, np.nan, 3.0], [1.0, 0.0, 0.0])
    with pytest.raises(InvalidInertiaError, match="inertia"):
        tumbling_periods([-1.0, 2.0, 3.0], [1.0, 0.1, 0.0])
    with pytest.raises(InvalidInputError, match="batch shapes do not broadcast"):
        tumbling_periods([[1.0, 2.0, 3.0]] * 2, [[1.0, 0.1, 0.0]] * 3)
    with pytest.raises(InvalidInputError, match=r"body \(1,\): .*separatrix"):
        tumbling_periods([1.0, 2.0, 3.0], [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(TypeError, match="exactly one of M0"):
        tumbling_periods([1.0, 2.0, 3.0])
    with pytest.raises(TypeError, match="exactly one of M0"):
        tumbling_periods([1.0, 2.0, 3.0], [1.0, 0.0, 0.1], omega0=[1.0, 0.0, 0.1])


def test_spin_states_from_periods_errors():
    ok = dict(I1_I3=0.5, I2_I3=0.8)
    with pytest.raises(InvalidInputError, match="P_psi must be > 0"):
        spin_states_from_periods(0.0, 1.0, "SAM", **ok)
    with pytest.raises(InvalidInputError, match="P_phi must be finite"):
        spin_states_from_periods(2.0, np.nan, "SAM", **ok)
    with pytest.raises(InvalidInputError, match='mode must be "LAM"'):
        spin_states_from_periods(2.0, 1.0, "NPA", **ok)
    with pytest.raises(TypeError, match="mode must be the string"):
        spin_states_from_periods(2.0, 1.0, 1, **ok)
    with pytest.raises(InvalidInputError, match="0 < I1_I3 < I2_I3 < 1"):
        spin_states_from_periods(2.0, 1.0, "SAM", I1_I3=0.8, I2_I3=0.5)
    with pytest.raises(InvalidInputError, match=r"0 < I1_I3 < I2_I3 < 1.*at index \(1,\)"):
        spin_states_from_periods(2.0, 1.0, "SAM", I1_I3=[0.5, 0.6], I2_I3=[0.8, 1.0])
    with pytest.raises(InvalidInputError, match="I2_I3 contains NaN"):
        spin_states_from_periods(2.0, 1.0, "SAM", I1_I3=0.5, I2_I3=np.nan)
    with pytest.raises(InvalidInputError, match="must broadcast together"):
        spin_states_from_periods(2.0, 1.0, "SAM", I1_I3=[0.1, 0.2], I2_I3=[0.5, 0.6, 0.7])
    with pytest.raises(TypeError):
        spin_states_from_periods(2.0, 1.0, "SAM", 0.5, 0.8)  # the family parameters are keyword-only
