"""What a user tries first (issue: the command line says what the API can; API ergonomics)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import eulerpoisson as ep
from _reference import quaternion_distance
from eulerpoisson import InvalidInputError
from eulerpoisson.torques import GravityGradient


def test_initial_attitude_as_attitude_rotation_quaternion_or_gibbs():
    rv = [0.1, -0.2, 0.3]
    q = ep.Attitude.from_rotvec(rv).as_quaternion()
    ref = ep.solve([1, 2, 3], [1.0], omega0=[1, 0.1, 0.5], attitude0=q)
    for a0 in (ep.Attitude.from_rotvec(rv), Rotation.from_rotvec(rv)):
        tr = ep.solve([1, 2, 3], [1.0], omega0=[1, 0.1, 0.5], attitude0=a0)
        assert quaternion_distance(tr.quaternion, ref.quaternion) < 1e-15
    tr = ep.solve([1, 2, 3], [1.0], omega0=[1, 0.1, 0.5], gibbs0=ep.Attitude.from_rotvec(rv).as_gibbs())
    assert quaternion_distance(tr.quaternion, ref.quaternion) < 1e-15
    with pytest.raises(TypeError, match="at most one of attitude0 and gibbs0"):
        ep.solve([1, 2, 3], [1.0], omega0=[1, 0, 0], attitude0=q, gibbs0=[0, 0, 0])


def test_one_unit_tolerance_for_quaternions_float32_accepted():
    q = ep.Attitude.from_rotvec([0.1, 0.2, 0.3]).as_quaternion().astype(np.float32).astype(float)
    assert 1e-9 < abs(np.linalg.norm(q) - 1) < ep.attitude.UNIT_QUATERNION_TOLERANCE
    tr = ep.solve([1, 2, 3], [0.0], omega0=[1, 0, 0], attitude0=q)
    assert abs(np.linalg.norm(tr.quaternion[0]) - 1) < 1e-15
    with pytest.raises(InvalidInputError, match="norm 1 within 1e-06; its norm is 1.00001"):
        ep.solve([1, 2, 3], [0.0], omega0=[1, 0, 0], attitude0=q * 1.00001)


def test_misspelled_keyword_is_an_argument_of_solve():
    with pytest.raises(
        TypeError, match=r"solve\(\) got an unexpected keyword argument 'omgea0' \(did you mean 'omega0'\?\)"
    ):
        ep.solve([1, 2, 3], [1.0], omgea0=[1, 0, 0])
    with pytest.raises(TypeError, match="method 'exact' has no option 'tol' \\(an option of rk, taylor\\)"):
        ep.solve([1, 2, 3], [1.0], omega0=[1, 0, 0], tol=1e-9)


def test_trajectory_indexing_selection_and_evaluation():
    t = np.linspace(0, 10, 11)
    tr = ep.solve([1, 2, 3], t, omega0=[1, 0.1, 0.5])
    assert len(tr[3]) == 1 and tr[3].t[0] == 3.0 and len(tr[::2]) == 6
    np.testing.assert_array_equal(tr[-1].quaternion[0], tr.quaternion[-1])
    np.testing.assert_array_equal(tr.sel(t=4.0).omega[0], tr.omega[4])
    assert tr.sel(t=[4.2, 6.9], method="nearest").t.tolist() == [4.0, 7.0]
    with pytest.raises(KeyError, match="t = 4.5 is not an output time"):
        tr.sel(t=4.5)
    with pytest.raises(TypeError, match="indexed by sample"):
        tr[1.5]
    # tr(t): the closed form at any time, the same motion
    mid = tr([2.5, 7.25, -1.0])
    ref = ep.solve([1, 2, 3], [2.5, 7.25, -1.0], omega0=[1, 0.1, 0.5])
    assert np.max(quaternion_distance(mid.quaternion, ref.quaternion)) < 1e-14
    # from a later first sample, and under a time-dependent torque (the phase of the orbit continues)
    gg = ep.solve(
        [1, 1.7, 2.2], np.linspace(0, 6, 7), omega0=[0.1, 0, 0.5], torque=GravityGradient(0.7), method="taylor"
    )
    late = gg[2:]
    ev = late([3.5, 6.0])
    assert quaternion_distance(ev.quaternion[-1], gg.quaternion[-1]) < 1e-12
    assert ev.model.torques[0].to_dict() == {"kind": "gravity_gradient", "mean_motion": 0.7}


def test_modules_as_attributes_and_a_clean_namespace():
    assert ep.plots.__name__ == "eulerpoisson.viz.plots"
    assert ep.analysis.sleeping_top
    assert "PackageNotFoundError" not in dir(ep)
    assert "plots" in dir(ep)
    with pytest.raises(AttributeError, match="has no attribute 'nothing'"):
        ep.nothing  # noqa: B018


def test_trajectory_plot_method(tmp_path):
    pytest.importorskip("matplotlib")
    tr = ep.solve([1, 2, 3], np.linspace(0, 5, 51), omega0=[1, 0.1, 0.5])
    fig = tr.plot("polhode", out=tmp_path / "p.png")
    assert (tmp_path / "p.png").stat().st_size > 1000 and fig is not None


def test_taylor_in_long_double_and_mpmath_rounds_once_to_the_closed_form():
    w0 = np.array([1.0, 0.1, 0.5])
    ref = ep.solve([1, 2, 3], [10.0], omega0=w0)
    for opts in ({"precision": "longdouble", "tol": 2e-19}, {"precision": "mpmath", "dps": 30, "tol": 1e-28}):
        tr = ep.solve([1, 2, 3], [10.0], omega0=w0, method="taylor", **opts)
        assert tr.stats["precision"] == opts["precision"]
        assert np.max(np.abs(tr.quaternion - ref.quaternion)) <= 5e-16
    with pytest.raises(InvalidInputError, match="precision must be one of float64, longdouble, mpmath"):
        ep.solve([1, 2, 3], [1.0], omega0=w0, method="taylor", precision="quad")
    with pytest.raises(InvalidInputError, match="precision='longdouble' is for the free body"):
        ep.solve([1, 2, 3], [1.0], omega0=w0, method="taylor", precision="longdouble", torque=GravityGradient(0.1))


def test_long_double_input_is_kept_or_its_rounding_said():
    w0 = np.array([1.0, 0.1, 0.5], dtype=np.longdouble) + np.longdouble(1e-18)
    with pytest.warns(UserWarning, match="given in long double; method 'exact' computes in float64"):
        ep.solve([1, 2, 3], [1.0], omega0=w0)
    tr = ep.solve([1, 2, 3], [0.0, 1.0], omega0=w0, method="taylor", precision="longdouble", tol=2e-19)
    assert tr.stats["precision"] == "longdouble"


def test_precision_from_the_command_line(capsys):
    from eulerpoisson.cli import main

    code = main(
        [
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0.1,0.5",
            "--t-end",
            "5",
            "--method",
            "taylor",
            "--precision",
            "longdouble",
            "--tol",
            "2e-19",
            "--json",
        ]
    )
    out, err = capsys.readouterr()
    assert code == 0, err
    import json

    ref = ep.solve([1, 2, 3], [5.0], omega0=[1, 0.1, 0.5])
    assert np.max(np.abs(np.array(json.loads(out)["quaternion"]) - ref.quaternion[-1])) <= 5e-16
