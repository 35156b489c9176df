"""The quick lane of ``solve`` (one free body at a few times) and the exact method's plain-Python kernel.

Truths: the general path (``engine.prepare_run`` + ``collect``), field for field and bit for bit; the
compiled kernels, bit for bit, for the scalar kernel run as plain Python (in a fresh interpreter, where
numba is not active); the errors of the general path for invalid inputs.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import eulerpoisson as ep
from _limits import HANG_GUARD_S
from eulerpoisson.errors import InvalidInertiaError, InvalidInputError
from eulerpoisson.model.body import cached_body
from eulerpoisson.solvers import quick
from eulerpoisson.solvers.engine import collect, prepare_run
from eulerpoisson.util import jit
from strategies import angular_velocities, principal_moments, quaternions


def _general(body, t, **kw):
    """The general path of ``solve`` (what it ran before the quick lane)."""
    return collect(prepare_run(body, list(t) if isinstance(t, tuple) else t, in_memory=True, **kw))


def _same(a: ep.Trajectory, b: ep.Trajectory) -> None:
    for name in ("t", "quaternion", "omega"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y) and np.array_equal(np.signbit(x), np.signbit(y)), name
    assert a.method == b.method and a.options == b.options
    sa = {k: v for k, v in a.stats.items() if k != "wall_time"}
    sb = {k: v for k, v in b.stats.items() if k != "wall_time"}
    assert sa == sb and list(a.stats) == list(b.stats)
    assert np.array_equal(a.body.inertia, b.body.inertia) and a.model.torques == b.model.torques


CASES = [
    ("exact", {}),
    (None, {}),
    ("taylor", {}),
    ("taylor", {"tol": 1e-6}),
    ("symplectic", {"dt": 0.05}),
    ("rk", {"tol": 1e-8}),
    ("rk4", {"dt": 2.0}),  # a coarse step: the far time (t = 1e3) in 500 steps of the Python stepper
]


@pytest.mark.parametrize(("method", "options"), CASES)
@pytest.mark.parametrize(
    "t",
    [0.0, 3, [0.0], [0.0, 1.0, 2.5], (2.5, -1.0, 0.0, 2.5), np.array([4.0, -0.5]), [1e3], np.linspace(0.0, 20.0, 30)],
    ids=["zero", "int", "list1", "list", "tuple-unsorted", "array", "far", "30-times"],  # (30: exact's NumPy path)
)
def test_the_quick_lane_gives_the_general_result(method, options, t):
    kw = dict(omega0=[1.0, 0.1, 0.5], method=method, **options)
    got = quick.quick_solve([1.0, 2.0, 3.0], t, **kw)
    if got is None:  # a method that cannot run these times (backwards, unsorted): the general path decides
        assert method in ("rk4", "symplectic", "rk")
        return
    _same(got, _general([1.0, 2.0, 3.0], t, **kw))
    _same(ep.solve([1.0, 2.0, 3.0], t, **kw), got)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    moments=principal_moments(shape=()),
    data=st.data(),
    method=st.sampled_from(["exact", "taylor"]),
    kind=st.sampled_from(["list", "body", "array-omega", "attitude"]),
    times=st.lists(st.floats(-50.0, 50.0, allow_nan=False), min_size=1, max_size=6),
)
def test_quick_lane_matches_the_general_path(moments, data, method, kind, times):
    omega = data.draw(angular_velocities(moments=moments))
    body: object = [float(x) for x in moments] if kind == "list" else ep.RigidBody(moments)
    kw: dict = {"omega0": omega if kind == "array-omega" else omega.tolist(), "method": method}
    if kind == "attitude":
        kw["attitude0"] = data.draw(quaternions(shape=())).tolist()
    got = quick.quick_solve(body, times, **kw)
    assert got is not None
    _same(got, _general(body, times, **kw))


def test_a_full_tensor_and_a_diagonal_one_give_the_general_result():
    rot = ep.Attitude.from_quaternion(
        [np.cos(0.4), 0.3, np.sin(0.4) * 0.5, 0.2] / np.linalg.norm([np.cos(0.4), 0.3, np.sin(0.4) * 0.5, 0.2])
    ).as_matrix()
    for inertia in (np.diag([1.0, 2.0, 3.0]), rot @ np.diag([1.0, 2.0, 3.0]) @ rot.T):
        body = ep.RigidBody(inertia)
        for method in ("exact", "taylor"):
            kw = dict(omega0=[0.3, -1.0, 0.2], method=method)
            got = quick.quick_solve(body, [0.0, 0.7, 2.0], **kw)
            assert got is not None
            _same(got, _general(body, [0.0, 0.7, 2.0], **kw))


@pytest.mark.parametrize(
    "kw",
    [
        dict(omega0=[1.0, 0.1, 0.5], torque=ep.torques.Gravity(1.0, [0.0, 0.0, 0.1])),
        dict(m0=[1.0, 0.1, 0.5]),
        dict(omega0=[1.0, 0.1, 0.5], gibbs0=[0.1, 0.0, 0.0]),
        dict(omega0=[1.0, 0.1, 0.5], workers=1),
        dict(omega0=[1.0, np.nan, 0.5]),
        dict(omega0=[1.0, True, 0.5]),
        dict(omega0=np.array([1.0, 0.1, 0.5], dtype=np.longdouble)),
        dict(omega0=np.array([1.0, 0.1, 0.5], dtype=np.float32)),
        dict(omega0=[[1.0, 0.1, 0.5]]),
        dict(omega0=[1.0, 0.1, 0.5], method=ep.solvers.TaylorOptions(tol=1e-9)),
        dict(omega0=[1.0, 0.1, 0.5], method="taylor", tol=np.float32(1e-6)),
        dict(omega0=[1.0, 0.1, 0.5], method="taylor", tolerance=1e-6),
        dict(omega0=[1.0, 0.1, 0.5], tol=1e-6),
        dict(omega0=[1.0, 0.1, 0.5], method="nope"),
        dict(omega0=[1.0, 0.1, 0.5], attitude0=[1.0, 0.0, 0.0, 0.5]),
    ],
)
def test_calls_not_of_the_plain_kind_take_the_general_path(kw):
    assert quick.quick_solve([1.0, 2.0, 3.0], [0.0, 1.0], **kw) is None


@pytest.mark.parametrize(
    "body, t",
    [
        (ep.RigidBody([[1.0, 2.0, 3.0], [2.0, 2.0, 3.0]]), [0.0, 1.0]),  # a batch
        ([1.0, 2.0, 30.0], [0.0, 1.0]),  # not physical: the general path raises
        ([1.0, 2.0, 3.0], np.linspace(0.0, 1.0, quick.QUICK_MAX_TIMES + 1)),
        ([1.0, 2.0, 3.0], [0.0, np.inf]),
        ([1.0, 2.0, 3.0], []),
        ([1.0, 2.0, 3.0], np.array(1.0)),
        ([1.0, 2.0, 3.0], "1.0"),
        ([1.0, 2.0, 3.0], [[0.0, 1.0]]),
    ],
)
def test_bodies_and_times_not_of_the_plain_kind_take_the_general_path(body, t):
    assert quick.quick_solve(body, t, omega0=[1.0, 0.1, 0.5]) is None


def test_a_stepping_method_past_the_segment_length_takes_the_general_path():
    # |Omega| t beyond SEGMENT_TURNS: the general path cuts the run into segments
    w = [1e3, 0.0, 0.0]
    assert quick.quick_solve([1.0, 2.0, 3.0], [1e4], omega0=w, method="taylor") is None
    assert quick.quick_solve([1.0, 2.0, 3.0], [1e4], omega0=w, method="exact") is not None


@pytest.mark.parametrize(
    "body, t, kw, err, match",
    [
        ([1.0, 2.0, 30.0], [0.0, 1.0], dict(omega0=[1.0, 0.0, 0.0]), InvalidInertiaError, "triangle"),
        ([1.0, 2.0, 3.0], [0.0, np.nan], dict(omega0=[1.0, 0.0, 0.0]), InvalidInputError, "t contains NaN"),
        ([1.0, 2.0, 3.0], [0.0], dict(omega0=[1.0, np.inf, 0.0]), InvalidInputError, "omega0 contains NaN"),
        ([1.0, 2.0, 3.0], [0.0], dict(omega0=[1.0, 0.0, 0.0], method="taylor", tolerance=1.0), TypeError, "tol"),
        ([1.0, 2.0, 3.0], [0.0], dict(omega0=[1.0, 0.0, 0.0], method="taylor", tol=2.0), InvalidInputError, "tol"),
        (
            [1.0, 2.0, 3.0],
            [0.0],
            dict(omega0=[1.0, 0.0, 0.0], attitude0=[1.0, 0.0, 0.0, 0.5]),
            InvalidInputError,
            "unit quaternion",
        ),
    ],
)
def test_invalid_inputs_raise_the_general_errors(body, t, kw, err, match):
    with pytest.raises(err, match=match):
        ep.solve(body, t, **kw)


def test_cached_bodies_do_not_share_arrays():
    a = cached_body((1.0, 2.0, 3.0))
    a.inertia[0, 0] = 99.0
    a.principal_moments[0] = 99.0
    b = cached_body((1.0, 2.0, 3.0))
    assert b.inertia[0, 0] == 1.0 and b.principal_moments[0] == 1.0
    ref = ep.RigidBody([1.0, 2.0, 3.0])
    for name in ("inertia", "principal_moments", "principal_axes"):
        assert np.array_equal(getattr(b, name), getattr(ref, name))
    with pytest.raises(InvalidInertiaError, match="triangle"):
        cached_body((1.0, 2.0, 30.0))


def test_the_trajectory_body_is_the_users_body():
    body = ep.RigidBody([1.0, 2.0, 3.0])
    tr = ep.solve(body, [0.0, 1.0], omega0=[1.0, 0.1, 0.5])
    assert tr.body is body


# ---------------------------------------------------------------------------
# the exact method's plain-Python kernel (python_twins) against the compiled one
# ---------------------------------------------------------------------------
_TWIN_CASES = """
import numpy as np
rng = np.random.default_rng(7)
n = 120
I = np.sort(rng.uniform(0.3, 3.0, (n, 3)), axis=1)
I[:, 2] = np.minimum(I[:, 2], I[:, 0] + I[:, 1] - 1e-3)
I = rng.permuted(I, axis=1)
I[: n // 8, 1] = I[: n // 8, 0]                      # symmetric bodies
I[n // 8 : n // 8 + 4] = [2.0, 2.0, 2.0]             # spheres
M0 = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 3, (n, 1))
M0[n // 4 : n // 4 + 6, 1] = 0.0                     # on principal planes
M0[n // 4 + 6 : n // 4 + 10] = [[0.0, 1.5, 0.0]] * 4  # about the middle axis
k = n // 2                                            # near the separatrix: |M|^2/(2E) = I2 (1 +- d)
Is = np.sort(I[k : k + 6], axis=1)
I[k : k + 6] = Is
d = np.array([-1e-12, 1e-12, -1e-9, 1e-9, -1e-6, 1e-6])
r = np.sqrt(((Is[:, 1] - Is[:, 0]) / Is[:, 0]) / ((Is[:, 2] - Is[:, 1]) / Is[:, 2]))
M0[k : k + 6] = np.stack([np.ones(6), 1e-3 * np.ones(6), r * (1.0 + d)], axis=-1)
M0[-1] = 0.0                                         # at rest
M0[-2] = [1e-310, 2e-310, -3e-310]                    # subnormal momenta
M0[-3] = [1e6, -3e5, 2e6]                             # large ones (|Omega| t within 2^48)
t = np.concatenate([[0.0, 1e-9, 1e-3, 1.0, -3.0, 77.7, 1e4], rng.uniform(-500.0, 500.0, 6)])
"""


@pytest.mark.skipif(not jit.USE_NUMBA, reason="numba is not in use: there is no compiled kernel to compare with")
def test_the_plain_python_kernel_gives_the_compiled_numbers_bit_for_bit(tmp_path):
    """The scalar kernel as plain Python (a fresh interpreter: numba never imported) equals the lane kernel."""
    out = tmp_path / "twins.npz"
    code = (
        _TWIN_CASES
        + f"""
import json, sys
from eulerpoisson.solvers.exact.motion import exact_motion
M, q = exact_motion(I, M0, t, compiled="python")
np.savez({str(out)!r}, M=M, q=q)
print(json.dumps({{"numba": "numba" in sys.modules}}))
"""
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert res.returncode == 0, res.stderr[-3000:]
    assert json.loads(res.stdout.strip().splitlines()[-1]) == {"numba": False}
    ns: dict = {}
    exec(_TWIN_CASES, ns)  # the same bodies and times
    from eulerpoisson.solvers.exact.motion import exact_motion

    M, q = exact_motion(ns["I"], ns["M0"], ns["t"], compiled=True)
    got = np.load(out)
    assert np.isfinite(M).all() and np.isfinite(q).all()
    assert np.array_equal(got["M"], M) and np.array_equal(got["q"], q)
    assert np.array_equal(np.signbit(got["q"]), np.signbit(q))


def test_a_tiny_exact_solve_runs_the_plain_python_kernel_without_numba():
    code = """
import json, sys
import eulerpoisson as ep
tr = ep.solve([1.0, 2.0, 3.0], [0.0, 1.0, 5.0], omega0=[1.0, 0.1, 0.5])
print(json.dumps({"numba": "numba" in sys.modules, "compiled": tr.stats["compiled"],
                  "q": tr.quaternion.tolist(), "w": tr.omega.tolist()}))
"""
    env = {k: v for k, v in __import__("os").environ.items() if k != jit.ENV_NUMPY_BELOW}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_GUARD_S, env=env)
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["numba"] is False and out["compiled"] is False
    # the numbers of the NumPy reference to round-off (the plain-Python kernel is the compiled one's twin)
    from eulerpoisson.solvers.exact.motion import exact_motion

    M, q = exact_motion([1.0, 2.0, 3.0], [1.0, 0.2, 1.5], [0.0, 1.0, 5.0], compiled=False)
    got = np.array(out["q"])
    sign = np.where(np.sum(got * q, -1) < 0, -1.0, 1.0)[:, None]  # (the trajectory's signs are continuous)
    assert np.max(np.abs(got - sign * q)) < 1e-14
    assert np.max(np.abs(np.array(out["w"]) - M / [1.0, 2.0, 3.0])) < 1e-14


def test_exact_motion_refuses_an_unknown_path():
    from eulerpoisson.solvers.exact.motion import exact_motion

    with pytest.raises(InvalidInputError, match="compiled must be"):
        exact_motion([1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [0.0], compiled="fast")


def test_python_twins_reports_whether_the_twins_run():
    with jit.python_twins() as twins:
        assert twins is (not jit.numba_active())


def test_the_twins_call_each_other_directly():
    """Within python_twins a kernel's twin runs in a copy of its module's namespace whose lazy kernels are their
    direct twins and whose lazy intrinsics their Python twins (no LazyDispatcher call per helper; an intrinsic
    of compiled code only stays); a function writing a module global is left as it is."""
    code = """
import json
import numpy as np
from eulerpoisson.util import jit
from eulerpoisson.solvers.exact import kernels as K, motion

M, q = motion.exact_motion([1.0, 2.0, 3.0], [1.0, 0.2, 1.5], [0.0, 2.0], compiled="python")
twin = K.motion_kernel_scalar._twin
lazy = sorted(
    k for k, v in twin.__globals__.items()
    if isinstance(v, jit.LazyDispatcher) or (isinstance(v, jit.LazyIntrinsic) and v.python is not None)
)
print(json.dumps({"direct": twin is not K.motion_kernel_scalar.python, "lazy": lazy,
                  "module_untouched": isinstance(K.body_eval, jit.LazyDispatcher),
                  "writer_kept": jit._direct_twin(motion._kernels) is motion._kernels}))
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_GUARD_S)
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    if not jit.USE_NUMBA:  # (no lazy kernels: plain functions throughout)
        return
    assert out == {"direct": True, "lazy": [], "module_untouched": True, "writer_kept": True}
