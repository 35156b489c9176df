"""Input checks of eulerpoisson.jax on concrete (eager) values: each error is raised before anything is
compiled (the programs of exact_motion and integrate are not built here; the one call that runs integrate
uses the cheap stand-in free flow)."""

import functools

import numpy as np
import pytest

jax = pytest.importorskip("jax")
jnp = pytest.importorskip("jax.numpy")

from eulerpoisson.errors import InvalidInertiaError, InvalidInputError  # noqa: E402
from eulerpoisson.jax import exact_motion, integrate  # noqa: E402
from eulerpoisson.jax.exact import MAX_PHASE, check_phase, normalized  # noqa: E402
from eulerpoisson.jax.splitting import rk4_free_flow  # noqa: E402

I3 = [1.0, 2.0, 3.0]
Q0 = [1.0, 0.0, 0.0, 0.0]
W0 = [1.0, 0.1, 0.5]
T = [0.0, 1.0]
NAN = np.nan


@pytest.mark.parametrize(
    ("args", "kwargs", "exc", "match"),
    [
        ((I3, Q0, [1e300, 0.1, 0.5], T), {}, InvalidInputError, r"omega0 is too large: \|omega0\| = 1e\+300"),
        ((I3, Q0, [1e200, 1e200, 0.5], T), {}, InvalidInputError, "omega0 is too large"),
        ((I3, Q0, [1e10, 0.0, 0.0], [0.0, 1e5]), {}, InvalidInputError, r"\|omega0\| \|t\| = 1e\+15 exceeds 2\^48"),
        ((I3, Q0, W0, [0.0, 1e300]), {}, InvalidInputError, r"\|omega0\| \|t\| = 1\.\d+e\+300 exceeds 2\^48"),
        (([1e200, 1e200, 1e200], Q0, [1e150, 0.0, 0.0], T), {}, InvalidInputError, "angular momentum .* overflows"),
        ((I3, Q0, [1e39, 0.1, 0.5], T), {"dtype": jnp.float32}, InvalidInputError, "omega0 overflows float32"),
        ((I3, Q0, W0, [0.0, 1e39]), {"dtype": jnp.float32}, InvalidInputError, "t overflows float32"),
        (([1e39, 2e39, 3e39], Q0, W0, T), {"dtype": jnp.float32}, InvalidInertiaError, "inertia overflows float32"),
        ((I3, Q0, [NAN, 0.1, 0.5], T), {"dtype": jnp.float32}, InvalidInputError, "omega0 must be finite"),
    ],
)
@pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
def test_exact_motion_refuses_values_it_cannot_compute(args, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        exact_motion(*args, **kwargs)


def test_exact_motion_empty_times_and_batches_give_empty_results():
    q, w = exact_motion(I3, Q0, W0, [])
    assert q.shape == (0, 4) and w.shape == (0, 3)
    q, w = exact_motion(I3, Q0, np.zeros((0, 3)), np.zeros((5, 1)))
    assert q.shape == (5, 0, 4) and w.shape == (5, 0, 3)


def test_normalized_scales_huge_and_tiny_quaternions_exactly():
    with jax.enable_x64(True):
        # (|q|^2 overflows, |q|^2 underflows; subnormals are not tried: XLA flushes them to zero)
        q = np.array([[1e300, 1e300, 0.0, 0.0], [3e-200, 0.0, 4e-200, 0.0], [0.3, -0.4, 0.5, 0.1]])
        got = np.asarray(normalized(q))
        want = np.array([[2**-0.5, 2**-0.5, 0.0, 0.0], [0.6, 0.0, 0.8, 0.0]])
        np.testing.assert_allclose(got[:2], want, rtol=0, atol=1e-15)
        # ordinary quaternions: the same bits as the unscaled quotient
        plain = q[2] / np.sqrt(np.sum(q[2] * q[2]))
        np.testing.assert_array_equal(got[2], np.asarray(jnp.asarray(q[2]) / jnp.sqrt(jnp.sum(jnp.asarray(q[2]) ** 2))))
        np.testing.assert_allclose(got[2], plain, rtol=1e-15)


def test_check_phase_is_elementwise_and_names_the_quantity():
    # a fast body at a short time and a slow body at a long one are both within range
    check_phase(np.array([[1e6, 0.0, 0.0], [1e-6, 0.0, 0.0]]), np.array([1.0, 1e15]))
    check_phase(np.zeros(3), np.array([1e300]))  # at rest: no phase
    with pytest.raises(InvalidInputError, match=r"\|omega0\| \|h\| = 3e\+14 exceeds 2\^48"):
        check_phase(np.array([0.0, 3.0, 0.0]), np.array(1e14), "h")
    check_phase(np.array([0.0, 1.0, 0.0]), np.array(0.9 * MAX_PHASE))


TOP_ARGS = (I3, Q0, [0.0, 0.2, 20.0], 0.5, 10)


@pytest.mark.parametrize(
    ("args", "kwargs", "exc", "match"),
    [
        ((I3, Q0, [NAN, 0.0, 20.0], 0.5, 10), {}, InvalidInputError, "omega0 must be finite"),
        ((I3, Q0, W0, NAN, 10), {}, InvalidInputError, "t_end must be finite"),
        ((I3, Q0, W0, np.inf, 10), {}, InvalidInputError, "t_end must be finite"),
        ((I3, Q0, W0, 1.0, 10), {"t0": NAN}, InvalidInputError, "t0 must be finite"),
        (([1.0, -1.0, 0.5], Q0, W0, 0.5, 10), {}, InvalidInertiaError, "positive definite"),
        (([1.0, NAN, 0.5], Q0, W0, 0.5, 10), {}, InvalidInertiaError, "inertia must be finite"),
        (
            ([[1.0, 0.3, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.5]], Q0, W0, 1.0, 20),
            {},
            InvalidInertiaError,
            r"not symmetric: max \|I - I\^T\| / max \|I\| = 0\.12",
        ),
        ((np.diag([1.0, -1.0, 2.0]), Q0, W0, 1.0, 20), {}, InvalidInertiaError, r"eigenvalues"),
        ((I3, [0.0, 0.0, 0.0, 0.0], W0, 0.5, 10), {}, InvalidInputError, "quaternion0 must be a non-zero"),
        ((I3, [1.0, NAN, 0.0, 0.0], W0, 0.5, 10), {}, InvalidInputError, "quaternion0 must be finite"),
        ((I3, [2.0**-1070, 0.0, 0.0, 0.0], W0, 0.5, 10), {}, InvalidInputError, "subnormal"),
        (
            (np.ones((2, 3)), Q0, np.ones((3, 3)), 0.5, 10),
            {},
            InvalidInputError,
            r"batch shapes of inertia \(2,\), quaternion0 \(\), omega0 \(3,\), t_end \(\) and t0 \(\) do not broadcast",
        ),
        ((I3, Q0, W0, np.ones(4), 10), {"t0": np.zeros(3)}, InvalidInputError, "do not broadcast"),
        ((I3, Q0, W0, 1e300, 10), {}, InvalidInputError, r"step h = \(t_end - t0\) / n_steps: \|omega0\| \|h\|"),
        ((I3, Q0, [0.0, 0.0, 1e300], 0.5, 10), {}, InvalidInputError, "omega0 is too large"),
        ((I3, Q0, W0, 1e308, 10), {"t0": -1e308}, InvalidInputError, "t_end - t0 overflows float64"),
        ((I3, Q0, W0, 1e39, 10), {"dtype": jnp.float32}, InvalidInputError, "t_end overflows float32"),
        ((I3, Q0, W0, 3e38, 10), {"t0": -3e38, "dtype": jnp.float32}, InvalidInputError, "overflows float32"),
    ],
)
@pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
def test_integrate_checks_concrete_values_like_exact_motion(args, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        integrate(*args, **kwargs)


def test_traced_inputs_are_only_shape_checked():
    # (jax.eval_shape traces without compiling: the values are abstract, a NaN cannot be seen)
    with jax.enable_x64(True):
        out = jax.eval_shape(lambda w: exact_motion(I3, Q0, w, T), jnp.array([NAN, 0.1, 0.5]))
        assert out[0].shape == (2, 4)
        with pytest.raises(InvalidInputError, match="omega0 must have shape"):
            jax.eval_shape(lambda w: exact_motion(I3, Q0, w, T), jnp.zeros(2))


def test_booleans_are_not_numbers():
    """As ep.solve: omega0=[True, False, True] or A=True is an error naming the argument, not 1.0 and 0.0."""
    from eulerpoisson.jax import lagrange_top_motion

    with pytest.raises(InvalidInputError, match=r"omega0 must be a real array, got dtype bool"):
        exact_motion([1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0], [True, False, True], [0.0, 1.0])
    with pytest.raises(InvalidInputError, match=r"A must be a real array, got dtype bool"):
        lagrange_top_motion(True, 0.5, 1.0, 0.3, [0, 0, -9.81], [1, 0, 0, 0], [0.1, 0.0, 20.0], [0.0, 1.0])


def test_integrate_refuses_torque_parameters_that_overflow_together():
    """As ep.solve: a Gravity of mass 1e300 at 1e300 is an error before anything runs (it gave NaN)."""
    import eulerpoisson as ep

    top = ep.torques.Gravity(1e300, [0.0, 0.0, 1e300])
    with pytest.raises(InvalidInputError, match="torque Gravity overflows float64"):
        integrate([1.0, 1.0, 0.5], [1.0, 0.0, 0.0, 0.0], [0.0, 0.2, 20.0], 0.5, 10, top)
    with pytest.raises(InvalidInputError, match="torque GravityGradient overflows float64"):
        integrate([1.0, 1.0, 0.5], [1.0, 0.0, 0.0, 0.0], [0.0, 0.2, 20.0], 0.5, 10, [ep.torques.GravityGradient(1e200)])


def test_integrate_refuses_jax_torques_that_are_not_finite():
    """Torques built in eulerpoisson.jax.torques: a non-finite parameter, or parameters that overflow together
    (an infinite torque at the initial state), are errors with concrete values; traced ones are not checked."""
    from eulerpoisson.jax import torques as jt

    args = ([1.0, 1.0, 0.5], [1.0, 0.0, 0.0, 0.0], [0.0, 0.2, 20.0], 0.5, 4)
    with pytest.raises(InvalidInputError, match="torque Gravity: its value at the initial state is not finite"):
        integrate(*args, jt.Gravity(1e300, [0.0, 0.3, 1e300]), order=2)
    with pytest.raises(InvalidInputError, match="torque Gravity: a parameter is not finite"):
        integrate(*args, jt.Gravity(np.nan, [0.0, 0.0, 0.1]), order=2)
    overflowing_sum = jt.BodyTorque([1e308, 0.0, 0.0]) + jt.BodyTorque([1e308, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="torque TorqueSum: its value at the initial state is not finite"):
        integrate(*args, overflowing_sum, order=2)
    # a finite torque passes (the checks come before the free flow is chosen: the stand-in flow of
    # tests/test_jax_splitting.py, which compiles in a fraction of a second, where the exact one takes seconds)
    flow = functools.partial(rk4_free_flow, substeps=4)
    t, q, w = integrate(*args, jt.Gravity(1.0, [0.0, 0.0, 0.1]), order=2, _free_flow=flow)
    assert np.isfinite(np.asarray(w)).all() and np.isfinite(np.asarray(q)).all()

    def last_rate(mass):  # traced parameters: not checked (shapes only)
        return integrate(*args, jt.Gravity(mass, [0.0, 0.0, 0.1]), order=2)[2][-1, 2]

    with jax.enable_x64(True):
        assert jax.eval_shape(last_rate, jnp.array(np.nan)).shape == ()
