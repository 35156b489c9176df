"""Finite inputs whose products leave float64: an error naming them, not a silent NaN or a different motion."""

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.errors import EulerPoissonError, InvalidInputError
from eulerpoisson.model.torque_base import check_torque_scales, scaled_norms, torque_bound
from eulerpoisson.solvers.exact.lagrange import lagrange_top_motion

T = np.linspace(0.0, 1.0, 3)
TOP = {"A": 1.0, "C": 0.5, "mass": 1.0, "ell": 0.3, "g": [0.0, 0.0, -9.81], "q0": [1.0, 0, 0, 0], "w0": [0.1, 0, 20.0]}


def _top(**change):
    a = {**TOP, "t": T, **change}
    return lagrange_top_motion(a["A"], a["C"], a["mass"], a["ell"], a["g"], a["q0"], a["w0"], a["t"])


@pytest.mark.parametrize(
    "change, match",
    [
        # |g| beyond 1.3e154: its plain norm overflowed and the top silently became a free one
        ({"g": [0.0, 0.0, -1e160]}, r"W \|t\| = 5\.48e\+79 .* exceeds 2\^48"),
        ({"g": [0.0, 0.0, -1e300]}, r"exceeds 2\^48"),
        ({"mass": 1e300, "g": [0.0, 0.0, -1e10]}, r"mass \* \|g\| \* \|ell\| overflows float64"),
        ({"w0": [0.1, 0.0, 1e300]}, r"squared frequency .* overflows float64"),
        ({"t": np.array([0.0, 1e300])}, r"\|t\| = 1e\+300\) exceeds 2\^48"),
    ],
)
def test_lagrange_top_refuses_what_float64_cannot_follow(change, match):
    with pytest.raises(InvalidInputError, match=match):
        _top(**change)


def test_lagrange_top_just_inside_the_range_is_unchanged():
    """The checks leave an ordinary top's values as they were (bit for bit: the same code after them)."""
    q, w = _top()
    ref = ep.solve(
        ep.RigidBody([1.0, 1.0, 0.5]), T, omega0=TOP["w0"], torque=ep.torques.Gravity(1.0, [0, 0, 0.3]), method="exact"
    )
    np.testing.assert_allclose(q, ref.quaternion, rtol=0, atol=1e-13)
    np.testing.assert_allclose(w, ref.omega, rtol=0, atol=1e-12)


def test_torque_bound_and_scaled_norms():
    np.testing.assert_allclose(scaled_norms([[3e200, 4e200, 0.0], [0.0, 0.0, 0.0]]), [5e200, 0.0], rtol=1e-15)
    # |mu c x g| <= |[mu c]x|_F |g| = sqrt(2) |mu c| |g|: an upper bound
    assert torque_bound(ep.torques.Gravity(2.0, [0.0, 0.0, 0.5], [0.0, 0.0, -10.0]), 1.0) == pytest.approx(10 * 2**0.5)
    assert torque_bound(ep.torques.Gravity(1e300, [0.0, 0.0, 1e300]), 1.0) == np.inf
    assert torque_bound(ep.torques.GravityGradient(1e200), 1.0) == np.inf
    assert torque_bound(ep.torques.CallableTorque(lambda t, q, w: np.zeros(3)), 1.0) is None
    check_torque_scales([ep.torques.Gravity(1.0, [0.0, 0.0, 0.1])], 2.0)  # a finite one passes


@pytest.mark.parametrize("method", ["rk", "taylor", "exact", "symplectic", "rk4"])
@pytest.mark.parametrize(
    "torque, name",
    [(ep.torques.Gravity(1e300, [0.0, 0.0, 1e300]), "Gravity"), (ep.torques.GravityGradient(1e200), "GravityGradient")],
)
def test_solve_refuses_a_torque_that_overflows(method, torque, name):
    """Before: rk stepped on a NaN torque until max_steps (hours), taylor blamed "quaternion contains NaN"."""
    with pytest.raises(InvalidInputError, match=rf"torque {name} overflows float64"):
        ep.solve([1.0, 1.0, 0.5], [0.0, 1.0], omega0=[0.0, 0.2, 20.0], torque=torque, method=method)


def test_rk_stops_at_the_first_non_finite_right_hand_side():
    """A finite torque whose I^-1 tau overflows: rk stops at once instead of shrinking its steps for hours."""
    big = ep.torques.CallableTorque(lambda t, q, w: np.full(np.shape(w), 1e308))
    with pytest.raises(EulerPoissonError, match=r"rk: the right-hand side is not finite at t = 0"):
        ep.solve([1.0, 1.0, 0.5], [0.0, 1.0], omega0=[0.0, 0.2, 2.0], torque=big, method="rk")


@pytest.mark.parametrize(
    "change, match",
    [
        ({"g": [0.0, 0.0, -1e160]}, r"exceeds 2\^48"),
        ({"mass": 1e300, "g": [0.0, 0.0, -1e10]}, r"mass \* \|g\| \* \|ell\| overflows float64"),
        ({"w0": [0.1, 0.0, 1e300]}, r"squared frequency .* overflows float64"),
    ],
)
def test_jax_lagrange_top_refuses_the_same_before_compiling(change, match):
    pytest.importorskip("jax", reason="jax is not installed: pip install 'eulerpoisson[jax]'")
    from eulerpoisson.jax import lagrange_top_motion as jax_top

    a = {**TOP, "t": T, **change}
    with pytest.raises(InvalidInputError, match=match):
        jax_top(a["A"], a["C"], a["mass"], a["ell"], a["g"], a["q0"], a["w0"], a["t"])


def test_gibbs_maps_refuse_a_result_that_overflows():
    """Before: NaN entries (matrix_from_conversion) and inf rates for finite n, where the siblings raised."""
    from eulerpoisson.attitude import gibbs_rate_from_omega, matrix_from_conversion, matrix_from_gibbs

    with pytest.raises(InvalidInputError, match=r"matrix_from_conversion overflows float64 .*max \|n\| = 1e\+200"):
        matrix_from_conversion([1e200, 0.0, 0.0])
    np.testing.assert_allclose(matrix_from_gibbs([1e200, 0.0, 0.0]), np.diag([1.0, -1.0, -1.0]), atol=1e-15)
    with pytest.raises(InvalidInputError, match=r"gibbs_rate_from_omega overflows float64"):
        gibbs_rate_from_omega([1e200, 1e200, 0.0], [1.0, 0.0, 0.0])
    n = [0.1, 0.2, 0.3]  # ordinary values unchanged
    np.testing.assert_allclose(matrix_from_conversion(n), matrix_from_gibbs(n), rtol=0, atol=1e-15)


def test_exact_phase_message_names_the_quantity():
    """|omega0| beyond 1e154 is reported as itself (its square overflowed: it said inf), a heavy top's rate as such."""
    with pytest.raises(InvalidInputError, match=r"exact: \|omega0\| \|t\| = 1e\+300 exceeds 2\^48"):
        ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1e300, 0.1, 0.5], method="exact")
    top = ep.torques.Gravity(1.0, [0.0, 0.0, 0.3], [0.0, 0.0, -1e100])
    with pytest.raises(
        InvalidInputError, match=r"exact: \(\|omega0\| \+ sqrt\(mass \|g\| \|ell\| / A\)\) \|t\| = 5\.48e\+49"
    ):
        ep.solve(ep.RigidBody([1.0, 1.0, 0.5]), [0.0, 1.0], omega0=[0.0, 0.2, 20.0], torque=top, method="exact")


@pytest.mark.parametrize("angle", [1e-140, 1e-160, 1e-170, 1e-250, 1e-300])
def test_tiny_angles_keep_their_axis_and_size(angle):
    """Below 1e-154 the squares of the vector part are subnormal: the axis was not unit, then the angle 0."""
    from eulerpoisson.attitude import axis_angle_from_quaternion, quaternion_from_rotvec

    k0 = np.array([0.48, -0.6, 0.64])  # a unit axis
    q = quaternion_from_rotvec(angle * k0)
    k, a = axis_angle_from_quaternion(q)
    np.testing.assert_allclose(k, k0, rtol=0, atol=4e-16)
    assert a == pytest.approx(angle, rel=4e-16)
    assert ep.Attitude(q).magnitude() == pytest.approx(angle, rel=4e-16)
    assert ep.Attitude(q).angle_to(ep.Attitude([1.0, 0.0, 0.0, 0.0])) == pytest.approx(angle, rel=4e-16)


def test_messages_name_what_is_wrong(tmp_path):
    """A bool max_steps is not an integer; a folder of the output path that is a file is named as such."""
    from eulerpoisson.io.atomic import write_error

    with pytest.raises(TypeError, match="max_steps must be an integer, got bool True"):
        ep.solve([1.0, 2.0, 3.0], [0.0, 1.0], omega0=[1.0, 0.1, 0.5], method="taylor", max_steps=True)
    (tmp_path / "notes.txt").write_text("mine")
    dest = tmp_path / "notes.txt" / "sub" / "run.nc"
    err = write_error(dest, FileExistsError(17, "File exists", str(tmp_path / "notes.txt")))
    assert isinstance(err, FileExistsError)
    assert str(err).endswith(f"cannot write {dest}: {tmp_path / 'notes.txt'} is a file, not a folder")
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_plot_and_sweep_outputs_say_what_is_wrong(tmp_path, capsys):
    """plot --out p.jpg names the flag (not the library's out=); sweep --out onto a file says a store is a folder."""
    from eulerpoisson.cli.commands import main

    run = tmp_path / "run.nc"
    assert main(["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", "--t-end", "1", "--out", str(run)]) == 0
    capsys.readouterr()
    assert main(["plot", str(run), "--kind", "omega", "--out", str(tmp_path / "p.jpg")]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "unsupported file extension '.jpg'; use one of .png" in err and "out=" not in err
    mine = tmp_path / "mycode.py"
    mine.write_text("print(1)")
    cfg = tmp_path / "sweep.toml"
    cfg.write_text(
        "[sweep]\nkind = 'grid'\n[inertia]\nI1 = 1.0\nI2 = 2.0\nI3 = 3.0\n"
        "[momentum]\npolar = {start = 10.0, stop = 170.0, num = 3}\nazimuth = {start = 0.0, stop = 90.0, num = 2}\n"
        "degrees = true\n[output]\npath = 'x.zarr'\n[compute]\nT = 1.0\nscheduler = 'serial'\n"
    )
    code = main(["sweep", str(cfg), "--out", str(mine), "--overwrite"])
    err = capsys.readouterr().err
    assert code == 2 and "it is a file, not a Zarr store (a folder) of ours" in err, err
    assert mine.read_text() == "print(1)"


@pytest.mark.parametrize("compiled", [True, False, "python"])
def test_exact_motion_refuses_phases_float64_cannot_place(compiled):
    """exact_motion (public, unlike the solver's unchecked core): |Omega0||t| beyond 2^48, or Omega0 = M0/I
    overflowing, is an error on every path (the compiled and NumPy paths gave NaN, the plain-Python one a raw
    'math domain error')."""
    from eulerpoisson.solvers.exact.motion import exact_motion

    with pytest.raises(InvalidInputError, match=r"exact_motion: \|Omega0\| \|t\| = 5e\+299 exceeds 2\^48"):
        exact_motion([1.0, 2.0, 3.0], [0.0, 1e300, 0.0], [1.0], compiled=compiled)
    with pytest.raises(InvalidInputError, match=r"Omega0 = M0 / I overflows float64 \(body \(1,\)\)"):
        exact_motion(
            [[1.0, 2.0, 3.0], [1e-300, 1.0, 1.0]], [[0.0, 1.0, 0.0], [1e10, 0.0, 0.0]], [1.0], compiled=compiled
        )
    with pytest.raises(InvalidInputError, match=r"exceeds 2\^48"):
        exact_motion([1.0, 2.0, 3.0], [0.0, 1.0, 0.5], [2.0**49], compiled=compiled)
    M, q = exact_motion([1.0, 2.0, 3.0], [0.0, 1.0, 0.5], [0.0, 1e10], compiled=compiled)  # inside the range
    assert np.isfinite(M).all() and np.isfinite(q).all()
