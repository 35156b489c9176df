"""ep.fit on synthetic data from an independent integrator: the truth within 3 sigma, calibrated sigmas.

The data come from scipy's DOP853 (rtol = atol = 1e-13) on Euler's equations
and the quaternion kinematics written here (no eulerpoisson code), for random
bodies in both regimes of motion (rotation about the long axis, LAM, and about
the short axis, SAM), near the separatrix, and a full inertia tensor fitted
with ``principal_axes="fit"``. Gaussian noise is added to the attitudes (a
body-frame rotation of standard deviation ``SA`` about each axis) and to the
body rates.

* From the default starts, the fit finds the optimum near the truth (its chi2
  is no larger than that of a fit started at the truth) and every parameter
  lies within 3 standard errors of the truth.
* Calibration: over 250 noisy copies of each case (fits started at the truth,
  which is what calibration is about), the fraction of each parameter within
  one standard error of the truth is 0.68 +- 0.06. These fits go from the truth straight to all the data:
  the search's continuation over growing windows, for starts far off, is skipped (three quarters of a
  fit's time from the truth; both routes reach the same optimum, checked on the data of the first test:
  over the 1,000 datasets the standardized errors agree to 1e-5). The 1,000 fits (about 20 s of CPU) are
  computed once per test run in parts that the pytest-xdist workers share out (the same datasets and
  numbers as in one piece).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import eulerpoisson as ep
from eulerpoisson.estimation import estimate as fit_search

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX: each worker computes the parts it needs
    fcntl = None

SA = 2e-3  # attitude noise, rad
SW = 2e-3  # rate noise, rad / time unit
N_CALIBRATION = 250


def _rhs(t, y, I, Iinv):
    w, q = y[:3], y[3:]
    wd = Iinv @ np.cross(I @ w, w)
    qd = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
    return np.concatenate([wd, qd])


def _truth_motion(I, q0, w0, t):
    sol = solve_ivp(
        _rhs,
        (t[0], t[-1]),
        np.concatenate([w0, q0]),
        method="DOP853",
        t_eval=t,
        rtol=1e-13,
        atol=1e-13,
        args=(I, np.linalg.inv(I)),
    )
    assert sol.success
    q = sol.y[3:].T
    return q / np.linalg.norm(q, axis=1, keepdims=True), sol.y[:3].T


def _qmul(p, q):
    return (
        np.stack(
            [
                p[..., 0] * q[..., 0] - np.sum(p[..., 1:] * q[..., 1:], -1),
                *(p[..., :1] * q[..., 1:] + q[..., :1] * p[..., 1:] + np.cross(p[..., 1:], q[..., 1:])).T,
            ],
            -1,
        )
        if p.ndim == 1
        else np.concatenate(
            [
                (p[..., 0] * q[..., 0] - np.sum(p[..., 1:] * q[..., 1:], -1))[..., None],
                p[..., :1] * q[..., 1:] + q[..., :1] * p[..., 1:] + np.cross(p[..., 1:], q[..., 1:]),
            ],
            -1,
        )
    )


def _noisy(q, w, rng):
    rv = SA * rng.standard_normal((len(q), 3))
    dq = Rotation.from_rotvec(rv).as_quat(scalar_first=True)
    return _qmul(q, dq), w + SW * rng.standard_normal(w.shape)


def _case(name):
    """(inertia in the observation frame, q0, omega0, times, principal_axes) of each case."""
    rng = np.random.default_rng({"lam": 11, "sam": 12, "separatrix": 13, "full": 14}[name])
    q0 = Rotation.random(random_state=rng).as_quat(scalar_first=True)
    if name == "lam":
        I = np.diag([0.21, 0.37, 0.42])
        w0 = np.array([1.0, 0.25, -0.2])
    elif name == "sam":
        I = np.diag([0.24, 0.33, 0.43])
        w0 = np.array([0.15, -0.25, 1.0])
    elif name == "separatrix":
        I = np.diag([0.22, 0.34, 0.44])
        # L^2 - 2E I2 small: a motion close to the intermediate-axis separatrix (SAM side)
        a, b, c = np.diag(I)
        w1 = 0.62
        w3 = np.sqrt(a * (b - a) * w1**2 / (c * (c - b)) * 1.03)  # 3 % above the separatrix
        w0 = np.array([w1, 0.9, w3])
    else:
        R = Rotation.random(random_state=rng).as_matrix()
        I = R @ np.diag([0.23, 0.35, 0.42]) @ R.T
        w0 = R @ np.array([0.2, 0.3, 1.0])
    t = np.linspace(0.0, 30.0, 100)
    return I, q0, w0, t, "fit" if name == "full" else "given"


CASES = ("lam", "sam", "separatrix", "full")


@pytest.fixture(scope="module")
def truths():
    out = {}
    for name in CASES:
        I, q0, w0, t, axes = _case(name)
        q, w = _truth_motion(I, q0, w0, t)
        out[name] = (I, q0, w0, t, axes, q, w)
    return out


def _regime(I, w):
    ev = np.linalg.eigvalsh(I)
    M = I @ w
    return (M @ M - (w @ M) * ev[1]) / (M @ M)


def test_cases_cover_both_regimes_and_the_separatrix(truths):
    r = {n: _regime(truths[n][0], truths[n][2]) for n in CASES}
    assert r["lam"] < -0.05 and r["sam"] > 0.05
    assert 0 < r["separatrix"] < 0.01


def _param_truth(name, I, q0, w0, res):
    """Standardized errors (fit - truth)/stderr of every fitted parameter."""
    I = I / np.trace(I)
    z = {}
    e = res.attitude_error(q0)
    for i, c in enumerate("xyz"):
        z[f"attitude0_{c}"] = e[i] / res.stderr[f"attitude0_{c}"]
        z[f"omega0_{c}"] = (res.omega0[i] - w0[i]) / res.stderr[f"omega0_{c}"]
    idx = {"I_xx": (0, 0), "I_yy": (1, 1), "I_xy": (0, 1), "I_xz": (0, 2), "I_yz": (1, 2)}
    for n in res.parameter_names:
        if n in idx:
            z[n] = (res.inertia[idx[n]] - I[idx[n]]) / res.stderr[n]
    return z


def _fit_at_truth(truth, qo, wo, straight=False):
    """``ep.fit`` of one noisy copy started at the truth; ``straight``: without the continuation over growing
    windows (the search's route for starts far off: the start goes straight to all the data, as ``fit`` also
    does with a given start, and the optimum is the same from the truth)."""
    I, q0, w0, t, axes, q, w = truth
    start = {"inertia": I / np.trace(I), "omega0": w0, "attitude0": q0}
    race = fit_search._race  # carries the starts through the windows ``ends``: more than one is the continuation

    def straight_race(layout, obs, starts, ends, max_iter):
        return [] if len(ends) > 1 else race(layout, obs, starts, ends, max_iter)

    with pytest.MonkeyPatch.context() as mp:
        if straight:
            mp.setattr(fit_search, "_race", straight_race)
        return ep.fit(t, attitude=qo, attitude_sigma=SA, omega=wo, omega_sigma=SW, principal_axes=axes, initial=start)


@pytest.mark.parametrize("name", CASES)
def test_default_starts_find_the_truth_within_3_sigma(truths, name):
    I, q0, w0, t, axes, q, w = truths[name]
    rng = np.random.default_rng(100)
    qo, wo = _noisy(q, w, rng)
    res = ep.fit(t, attitude=qo, attitude_sigma=SA, omega=wo, omega_sigma=SW, principal_axes=axes)
    at_truth = _fit_at_truth(truths[name], qo, wo)
    assert res.chi2 <= at_truth.chi2 * (1 + 1e-9) + 1e-9
    z = _param_truth(name, I, q0, w0, res)
    assert len(z) == len(res.parameter_names)
    assert max(abs(v) for v in z.values()) < 3.0, z
    assert 0.7 < res.reduced_chi2 < 1.3
    assert res.converged and res.determined
    # the calibration's fits (straight from the truth to all the data) reach the optimum of the whole search
    straight = _fit_at_truth(truths[name], qo, wo, straight=True)
    assert abs(straight.chi2 - at_truth.chi2) <= 1e-9 * at_truth.chi2
    z_truth, z_straight = _param_truth(name, I, q0, w0, at_truth), _param_truth(name, I, q0, w0, straight)
    assert z_straight.keys() == z_truth.keys()
    assert max(abs(z_straight[k] - z_truth[k]) for k in z_truth) < 1e-4
    for k in straight.parameter_names:
        assert straight.stderr[k] == pytest.approx(at_truth.stderr[k], rel=1e-6)


#: the calibration fits of a case are computed in this many parts (units of work), which the pytest-xdist
#: workers share out: a worker takes a part that no other worker is computing, and the results (the same
#: numbers whoever computes them) are kept in the run's temporary folder
PARTS = 2


def _datasets(name, truths, stop=N_CALIBRATION):
    """The first ``stop`` of the N_CALIBRATION noisy copies of case ``name`` (drawn in order from one generator:
    the same in every part)."""
    I, q0, w0, t, axes, q, w = truths[name]
    rng = np.random.default_rng(2024 + CASES.index(name))
    return [_noisy(q, w, rng) for _ in range(min(stop, N_CALIBRATION))]


def _fit_part(name, part, truths):
    """Standardized errors and reduced chi2 of the fits (started at the truth) of part ``part`` of case ``name``."""
    I, q0, w0, t, axes, q, w = truths[name]
    size = -(-N_CALIBRATION // PARTS)
    z, chi2 = {}, []
    for qo, wo in _datasets(name, truths, (part + 1) * size)[part * size :]:
        res = _fit_at_truth(truths[name], qo, wo, straight=True)
        for k, v in _param_truth(name, I, q0, w0, res).items():
            z.setdefault(k, []).append(v)
        chi2.append(res.reduced_chi2)
    return {**{f"z_{k}": np.array(v) for k, v in z.items()}, "chi2": np.array(chi2)}


def _run_folder(tmp_path_factory):
    """The temporary folder of this test run, common to every pytest-xdist worker."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="module")
def calibration(truths, tmp_path_factory):
    """``get(names)``: per case, the standardized errors of every parameter over N_CALIBRATION noisy copies, and
    the reduced chi2 of each fit (computed once per test run, its parts shared out between the workers)."""
    folder = _run_folder(tmp_path_factory) / "fit-calibration"
    folder.mkdir(exist_ok=True)
    parts: dict = {}

    def unit(name, part, wait):
        """Part ``part`` of ``name``: read, or computed under its lock; None if another worker holds the lock."""
        path = folder / f"{name}-{part}.npz"
        with open(folder / f"{name}-{part}.lock", "w") as lock:
            if fcntl is not None:
                try:
                    fcntl.flock(lock, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
                except BlockingIOError:
                    return None  # being computed by another worker: take another part meanwhile
            if not path.exists():
                tmp = folder / f"{name}-{part}.tmp.npz"
                np.savez(tmp, **_fit_part(name, part, truths))
                os.replace(tmp, path)
        with np.load(path) as data:
            return {k: data[k] for k in data.files}

    def get(names):
        todo = [(n, p) for n in names for p in range(PARTS) if (n, p) not in parts]
        for wait in (False, True):  # first the parts no other worker is computing, then wait for the others
            for key in todo:
                if key not in parts and (got := unit(*key, wait)) is not None:
                    parts[key] = got
        out = {}
        for n in names:
            chunks = [parts[(n, p)] for p in range(PARTS)]
            z = {k[2:]: np.concatenate([c[k] for c in chunks]) for k in chunks[0] if k.startswith("z_")}
            out[n] = (z, np.concatenate([c["chi2"] for c in chunks]))
        return out

    return get


def test_uncertainties_are_calibrated(calibration):
    """Per parameter, over the 4 x 250 datasets: the fraction within 1 sigma is 0.68 +- 0.06, <z^2> is 1 +- 0.15."""
    pooled = {}
    for z, chi2 in calibration(CASES).values():
        assert len(chi2) == N_CALIBRATION
        for k, v in z.items():
            pooled.setdefault(k, []).extend(v)
    assert len(pooled) == 11  # attitude, rate, and the five inertia parameters of the full tensor
    for k, v in pooled.items():
        v = np.array(v)
        assert len(v) >= 200
        frac = np.mean(np.abs(v) < 1.0)
        assert abs(frac - 0.6827) < 0.06, (k, frac, len(v))
        assert abs(np.mean(v**2) - 1.0) < 0.15, (k, np.mean(v**2))


@pytest.mark.parametrize("name", CASES)
def test_uncertainties_are_calibrated_in_each_case(calibration, name):
    """Each case alone (250 datasets: binomial sd 0.03): within 1 sigma 0.68 +- 0.09, mean reduced chi2 1 +- 0.02."""
    z, chi2 = calibration([name])[name]
    assert len(chi2) == N_CALIBRATION
    for k, v in z.items():
        frac = np.mean(np.abs(v) < 1.0)
        assert abs(frac - 0.6827) < 0.09, (name, k, frac)
    assert abs(np.mean(chi2) - 1.0) < 0.02
