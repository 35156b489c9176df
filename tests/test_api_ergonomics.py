"""What a user tries first (issue: the command line says what the API can; API ergonomics)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from _reference import quaternion_distance

import eulerpoisson as ep
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
    with pytest.raises(TypeError, match=r"solve\(\) got an unexpected keyword argument 'omgea0' \(did you mean 'omega0'\?\)"):
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
    gg = ep.solve([1, 1.7, 2.2], np.linspace(0, 6, 7), omega0=[0.1, 0, 0.5], torque=GravityGradient(0.7),
                  method="taylor")
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
