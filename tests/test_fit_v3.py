"""``fit`` says when its data are read wrong (issue 22, items 7, 12 and 17).

- (7) A fit far from its data is refused (``PoorFitError``, exit 2 with one line) unless ``accept_poor_fit``
  (``--accept-poor-fit``); when another reading of the same numbers (scalar-last quaternions, their
  conjugates, the rates in the other frame or in degrees) fits far better, the line names the flag.
- (12) ``max_iter=0`` is refused; a CSV that is not UTF-8 is named, with what to do (``fit`` and ``validate``).
- (17) Sigmas come out in the unit of the flag that takes them: degrees for attitudes, the rates' unit for rates.

The data are made by ``ep.solve`` with a known body and Gaussian noise.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.attitude.core import matrix_from_unit_quaternion
from eulerpoisson.cli.commands import main
from eulerpoisson.errors import FitInputError, InvalidInputError, PoorFitError
from eulerpoisson.estimation.residuals import exp_quaternion
from eulerpoisson.io.observations import read_observations
from eulerpoisson.numerics.quaternion import qmul

MOMENTS = np.array([0.25, 0.33, 0.42])
SIGMA_ATT = 2e-3  # rad
SIGMA_OM = 2e-3  # rad per unit of t


def _data(seed=3):
    t = np.linspace(0.0, 30.0, 46)
    a0 = np.array([0.9, 0.1, -0.3, 0.2])
    tr = ep.solve(MOMENTS, t, omega0=[0.06, 0.04, 0.2], attitude0=a0 / np.linalg.norm(a0))
    rng = np.random.default_rng(seed)
    q = qmul(tr.quaternion, exp_quaternion(SIGMA_ATT * rng.standard_normal((t.size, 3))))
    w = tr.omega + SIGMA_OM * rng.standard_normal((t.size, 3))
    return t, q, w


T, Q, W = _data()
W_SPACE = np.einsum("kab,kb->ka", matrix_from_unit_quaternion(Q), W)

#: the same numbers written another way, and what fit names
MISREAD = {
    "space": (dict(attitude=Q, omega=W_SPACE), "omega_frame='space'", "--omega-frame space"),
    "xyzw": (dict(attitude=Q[:, [1, 2, 3, 0]], omega=W), r"reorder them to \(w, x, y, z\)", "--quaternion-order xyzw"),
    "conjugate": (dict(attitude=Q * [1, -1, -1, -1], omega=W), "conjugate them", "--attitude-convention space-to-body"),
    "deg": (dict(attitude=Q, omega=np.degrees(W)), r"multiply them by pi/180", "--omega-unit deg"),
}


def _sigmas(reading):
    return dict(attitude_sigma=SIGMA_ATT, omega_sigma=SIGMA_OM * (180 / np.pi if reading == "deg" else 1.0))


def _quick(reading):
    """Rates read in degrees turn 57 times faster: one start near the data keeps the search short."""
    if reading != "deg":
        return {}
    return {"initial": {"inertia": [0.3, 0.33, 0.37], "omega0": np.degrees(W[0]), "attitude0": Q[0]}}


# ----------------------------------------------------------------------------------------------------------
# (12) max_iter


def test_max_iter_zero_is_refused_naming_the_range():
    with pytest.raises(FitInputError, match=r"max_iter must be a positive integer \(1 or more .*\), got 0"):
        ep.fit(T, attitude=Q, attitude_sigma=SIGMA_ATT, max_iter=0)


def test_max_iter_one_is_accepted():
    res = ep.fit(T, attitude=Q, attitude_sigma=SIGMA_ATT, omega=W, omega_sigma=SIGMA_OM, max_iter=1)
    assert isinstance(res, ep.estimation.FitResult)


# ----------------------------------------------------------------------------------------------------------
# (7) the API


@pytest.fixture(scope="module")
def right_fit():
    """The data read right, sigmas given."""
    return ep.fit(T, attitude=Q, omega=W, **_sigmas("ok"))


def test_right_data_fit_well_and_say_nothing(right_fit):
    res = right_fit
    assert not res.poor_fit and res.convention_hint is None and res.better_reading is None
    assert np.allclose(res.principal_moments, MOMENTS, atol=5e-3)
    d = res.as_dict()
    assert d["poor_fit"] is False and d["convention_hint"] is None


def test_noisy_data_with_estimated_sigmas_are_not_misread():
    rng = np.random.default_rng(11)
    q = qmul(Q, exp_quaternion(0.04 * rng.standard_normal((T.size, 3))))
    res = ep.fit(T, attitude=q, omega=W + 0.02 * rng.standard_normal(W.shape))
    assert not res.poor_fit and res.convention_hint is None


@pytest.mark.parametrize("reading", list(MISREAD))
def test_a_misread_fit_is_refused_naming_the_reading(reading):
    data, api, flag = MISREAD[reading]
    with pytest.raises(PoorFitError, match=rf"^poor fit: .*far better.*{api}.*{flag}.*accept_poor_fit=True") as err:
        ep.fit(T, **data, **_sigmas(reading), **_quick(reading))
    assert "\n" not in str(err.value)
    assert err.value.result.better_reading == reading and err.value.result.poor_fit


def test_accept_poor_fit_returns_the_result_with_the_hint():
    data, _, flag = MISREAD["space"]
    res = ep.fit(T, **data, **_sigmas("space"), accept_poor_fit=True)
    assert res.poor_fit and res.better_reading == "space" and res.reduced_chi2 > 100
    assert "omega_frame='space'" in res.convention_hint and flag in res.convention_hint
    assert "POOR FIT" in res.summary() and res.convention_hint in res.summary()
    assert res.as_dict()["convention_hint"] == res.convention_hint
    # read right, the same numbers fit
    good = ep.fit(T, **data, omega_frame="space", **_sigmas("space"))
    assert not good.poor_fit and np.allclose(good.principal_moments, MOMENTS, atol=5e-3)


def test_a_misread_is_found_with_estimated_sigmas_too():
    """Estimated sigmas make any reduced chi2 about 1: the other reading still fits far better."""
    data, _, flag = MISREAD["space"]
    with pytest.raises(PoorFitError, match=rf"angular velocities look space-frame.*{flag}"):
        ep.fit(T, **data)


def test_an_absurd_chi2_is_refused_and_accepted_on_request():
    with pytest.raises(PoorFitError, match=r"^poor fit: reduced chi2 = [0-9.e+]+ > 100: check the data's"):
        ep.fit(T, attitude=Q, attitude_sigma=SIGMA_ATT / 30, omega=W, omega_sigma=SIGMA_OM / 30)
    res = ep.fit(T, attitude=Q, attitude_sigma=SIGMA_ATT / 30, omega=W, omega_sigma=SIGMA_OM / 30, accept_poor_fit=True)
    assert res.poor_fit and res.convention_hint is None and res.reduced_chi2 > 100
    assert "POOR FIT: reduced chi2" in res.summary()


def test_poor_fit_error_is_a_fit_input_error():
    assert issubclass(PoorFitError, FitInputError) and ep.estimation.PoorFitError is PoorFitError


def test_accept_poor_fit_must_be_a_bool():
    with pytest.raises(TypeError, match="accept_poor_fit must be True or False"):
        ep.fit(T, attitude=Q, accept_poor_fit="yes")


# ----------------------------------------------------------------------------------------------------------
# (7) the command line


def _csv(path, t, q, w, header="t,qw,qx,qy,qz,wx,wy,wz"):
    rows = [header] + [",".join(f"{x:.17g}" for x in (ti, *qi, *wi)) for ti, qi, wi in zip(t, q, w)]
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


SIG_ARGS = ("--sigma-attitude", str(float(np.degrees(SIGMA_ATT))), "--sigma-omega", str(SIGMA_OM))


@pytest.mark.parametrize("reading", ["space", "xyzw", "conjugate", pytest.param("deg", marks=pytest.mark.slow)])
def test_cli_names_the_flag_and_exits_2_then_the_flag_fits(capsys, tmp_path, reading):
    data, _, flag = MISREAD[reading]
    n = 12 if reading == "deg" else T.size  # rates in degrees: 57 times the turns to follow, fewer of them
    path = _csv(tmp_path / "obs.csv", T[:n], data["attitude"][:n], data["omega"][:n])
    sig = SIG_ARGS
    if reading == "deg":
        sig = SIG_ARGS[:3] + (str(float(np.degrees(SIGMA_OM))),)  # --sigma-omega in the unit of the rates
    code, out, err = run(capsys, "fit", path, *sig)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("eulerpoisson: error: ")
    assert f"rerun with {flag}" in err and "--accept-poor-fit" in err and "obs.csv" in err
    code, out, err = run(capsys, "fit", path, *sig, *flag.split(), "--json")
    assert code == 0, err
    d = json.loads(out)
    assert not d["poor_fit"] and np.allclose(d["principal_moments"], MOMENTS, atol=2e-2 if n < T.size else 5e-3)


def test_cli_accept_poor_fit_prints_the_hint_and_exits_0(capsys, tmp_path):
    path = _csv(tmp_path / "obs.csv", T, Q, W_SPACE)
    code, out, err = run(capsys, "fit", path, *SIG_ARGS, "--accept-poor-fit")
    assert code == 0, err
    assert "POOR FIT" in out and "rerun with --omega-frame space" in out
    code, out, err = run(capsys, "fit", path, *SIG_ARGS, "--accept-poor-fit", "--json")
    d = json.loads(out)
    assert d["poor_fit"] is True and "--omega-frame space" in d["convention_hint"]


def test_cli_absurd_chi2_exits_2_naming_the_sigmas(capsys, tmp_path):
    path = _csv(tmp_path / "obs.csv", T, Q, W)
    code, out, err = run(capsys, "fit", path, "--sigma-attitude", "0.001", "--sigma-omega", "1e-5")
    assert code == 2 and err.count("\n") == 1
    assert "reduced chi2 =" in err and "> 100" in err and "--sigma-attitude" in err and "--accept-poor-fit" in err
    code, out, err = run(capsys, "fit", path, "--sigma-attitude", "0.001", "--sigma-omega", "1e-5", "--accept-poor-fit")
    assert code == 0 and "POOR FIT: reduced chi2" in out


def test_toml_states_the_reading(tmp_path):
    _csv(tmp_path / "obs.csv", T, Q[:, [1, 2, 3, 0]] * [-1, -1, -1, 1], np.degrees(W))
    (tmp_path / "obs.toml").write_text(
        '[observations]\nfile = "obs.csv"\nquaternion_order = "xyzw"\nattitude_convention = "space-to-body"\n'
        'omega_unit = "deg"\n'
    )
    obs = read_observations(tmp_path / "obs.toml")
    assert np.allclose(obs.attitude, Q) and np.allclose(obs.omega, W)
    with pytest.raises(InvalidInputError, match=r"omega_unit must be one of 'rad', 'deg', got 'grad'"):
        read_observations(tmp_path / "obs.csv", omega_unit="grad")


def test_quaternion_order_is_the_file_order_of_the_columns(tmp_path):
    # columns labelled in another order: xyzw reads them in the order of the file
    path = _csv(tmp_path / "obs.csv", T, Q[:, [1, 2, 3, 0]], W, header="t,qx,qy,qz,qw,wx,wy,wz")
    assert np.allclose(read_observations(path).attitude, Q)  # by the names
    assert np.allclose(read_observations(path, quaternion_order="xyzw").attitude, Q)
    with pytest.raises(InvalidInputError, match=r"quaternion_order='xyzw' is given, but .* has no quaternions"):
        read_observations(_csv(tmp_path / "w.csv", T, np.zeros((T.size, 0)), W, header="t,wx,wy,wz"),
                          quaternion_order="xyzw")  # fmt: skip


# ----------------------------------------------------------------------------------------------------------
# (17) one unit per flag, in and out


def test_cli_sigma_out_in_the_unit_of_the_flag(capsys, tmp_path):
    path = _csv(tmp_path / "obs.csv", T, Q, W)
    code, out, err = run(capsys, "fit", path, "--sigma-attitude", "0.1146", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["sigma"]["attitude"] == pytest.approx(0.1146, rel=1e-12) and d["sigma_units"]["attitude"] == "deg"
    assert d["sigma_units"]["omega"] == "rad per unit of t"
    assert d["sigma"]["omega"] == pytest.approx(SIGMA_OM, rel=0.2)  # estimated, in the rates' unit
    code, out, err = run(capsys, "fit", path, "--sigma-attitude", "0.1146")
    assert "sigma given: attitude 0.115 deg" in out
    assert "sigma estimated from the residuals: omega 0.00" in out and "rad per unit of t" in out
    # attitudes estimated: in degrees too (about 0.1146 deg of noise)
    code, out, err = run(capsys, "fit", path, "--sigma-omega", repr(SIGMA_OM), "--json")
    d = json.loads(out)
    assert d["sigma_units"]["attitude"] == "deg" and d["sigma"]["attitude"] == pytest.approx(0.1146, rel=0.2)
    # rates in degrees: their sigma in and out in degrees per unit of t
    deg = _csv(tmp_path / "deg.csv", T, Q, np.degrees(W))
    code, out, err = run(capsys, "fit", deg, "--omega-unit", "deg", "--sigma-omega", "0.1146", "--json")
    d = json.loads(out)
    assert (
        code == 0 and d["sigma"]["omega"] == pytest.approx(0.1146) and d["sigma_units"]["omega"] == "deg per unit of t"
    )


def test_api_sigma_units_are_stated(right_fit):
    res = right_fit
    d = res.as_dict()
    assert d["sigma"] == {"attitude": SIGMA_ATT, "omega": SIGMA_OM}
    assert d["sigma_units"] == {"attitude": "rad", "omega": "rad per unit of t"}
    values, units = res.sigma_in(angle_unit="deg")
    assert values["attitude"] == pytest.approx(np.degrees(SIGMA_ATT)) and units["attitude"] == "deg"
    assert "attitude 0.002 rad" in res.summary()
    with pytest.raises(ValueError, match="angle_unit must be 'rad' or 'deg'"):
        res.sigma_in(angle_unit="grad")


# ----------------------------------------------------------------------------------------------------------
# (12) files that are not UTF-8


def _latin1(path):
    path.write_bytes("t,qw,qx,qy,qz,wx,wy,wz\n# sonde \u00e9t\u00e9\n0,1,0,0,0,0,0,1\n".encode("latin-1"))
    return str(path)


def test_fit_of_a_non_utf8_csv_names_the_file_and_what_to_do(capsys, tmp_path):
    path = _latin1(tmp_path / "obs.csv")
    with pytest.raises(InvalidInputError, match=r"obs\.csv: not UTF-8 text .*save it as UTF-8"):
        read_observations(path)
    code, out, err = run(capsys, "fit", path)
    assert code == 2 and err.count("\n") == 1 and "obs.csv" in err and "save it as UTF-8" in err


def test_validate_of_a_non_utf8_csv_names_the_file_and_what_to_do(capsys, tmp_path):
    path = _latin1(tmp_path / "run.csv")
    code, out, err = run(capsys, "validate", path, "--inertia", "1,2,2.5")
    assert code == 2 and err.count("\n") == 1
    assert "run.csv: not UTF-8 text" in err and "save it as UTF-8" in err and "codec" not in err
