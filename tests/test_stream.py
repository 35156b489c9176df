"""Streaming long solutions to Zarr: values, bounded memory, atomicity, interruption and resume."""

import dataclasses
import json
import tracemalloc

import numpy as np
import pytest

pytest.importorskip("zarr")
xr = pytest.importorskip("xarray")

from eulerpoisson import RigidBody  # noqa: E402
from eulerpoisson.errors import EulerPoissonError, InvalidInputError  # noqa: E402
from eulerpoisson.io.stream import TIME_VARIABLES, TimeGrid, partial_store, solve_to_file  # noqa: E402
from eulerpoisson.solvers import Method, MethodOptions, MethodResult, register_method, solve  # noqa: E402
from eulerpoisson.solvers.registry import _REGISTRY  # noqa: E402

I123 = [1.0, 2.0, 3.0]
W0 = [0.3, 1.0, 0.2]  # near the middle axis: flips, a good test of quaternion signs
TIME_VARS = ("quaternion", "omega", "M", "m", "energy", "gibbs")


# ---------------------------------------------------------------------------
# a fixed-step RK4 method, registered only while a test uses it
# ---------------------------------------------------------------------------
def _qmul(p, q):
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        -1,
    )


@dataclasses.dataclass(frozen=True)
class _RK4Options(MethodOptions):
    method = "_test_rk4"
    dt: float = 0.01


class _RK4(Method):
    """Classical RK4 on (q, Omega), output to output with steps <= dt (test-only)."""

    name = "_test_rk4"
    Options = _RK4Options
    order = 4
    refine = "dt"

    def run(self, p):
        I = p.inertia
        Iinv = np.linalg.inv(I)

        def f(q, w):
            M = np.einsum("...ij,...j->...i", I, w)
            dw = np.einsum("...ij,...j->...i", Iinv, np.cross(M, w))
            dq = 0.5 * _qmul(q, np.concatenate([np.zeros(w.shape[:-1] + (1,)), w], -1))
            return dq, dw

        B, T = p.batch_shape, p.t.size
        qo, wo = np.empty(B + (T, 4)), np.empty(B + (T, 3))
        for sign in (1.0, -1.0):
            idx = np.nonzero(sign * p.t >= 0)[0]
            idx = idx[np.argsort(sign * p.t[idx], kind="stable")]
            q, w, t = p.q0.copy(), p.omega0.copy(), 0.0
            for i in idx:
                n = int(np.ceil(abs(p.t[i] - t) / self.config["dt"]))
                h = (p.t[i] - t) / n if n else 0.0
                for _ in range(n):
                    k1 = f(q, w)
                    k2 = f(q + h / 2 * k1[0], w + h / 2 * k1[1])
                    k3 = f(q + h / 2 * k2[0], w + h / 2 * k2[1])
                    k4 = f(q + h * k3[0], w + h * k3[1])
                    q = q + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
                    w = w + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
                t = p.t[i]
                qo[..., i, :], wo[..., i, :] = q, w
        return MethodResult(q=qo, omega=wo, stats={"steps": 1})


@pytest.fixture
def rk4():
    register_method(_RK4)
    yield _RK4.name
    _REGISTRY.pop(_RK4.name, None)


def _qdist(q1, q2):
    w = np.sum(q1 * q2, -1)
    v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
    return 2 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))


def _open(path):
    return xr.open_zarr(str(path), consolidated=None)


# ---------------------------------------------------------------------------
# the lazy time grid
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "t0, t1, n",
    [
        (0.0, 7.0, 1001),
        (-3.0, 11.5, 17),
        (5.0, -2.0, 400),
        (1.5, 1.5, 4),
        (0.0, 1e-310, 3),
        (2.0, 9.0, 1),
        (0.1, 0.7, 2),
    ],
)
def test_timegrid_is_linspace_bit_for_bit(t0, t1, n):
    g = TimeGrid(t0, t1, n)
    ref = np.linspace(t0, t1, n)
    assert len(g) == n and g.shape == (n,)
    np.testing.assert_array_equal(g[:], ref)
    np.testing.assert_array_equal(g[n // 3 : n - 1], ref[n // 3 : n - 1])
    np.testing.assert_array_equal(g[np.array([0, n - 1, -1])], ref[[0, n - 1, -1]])
    assert g[n - 1] == ref[-1] and g[0] == ref[0]


@pytest.mark.parametrize(
    "args, exc, match",
    [
        ((0.0, 1.0, 0), InvalidInputError, "n must be >= 1"),
        ((0.0, np.nan, 5), InvalidInputError, "t1 must be finite"),
        ((0.0, 1.0, 2.5), TypeError, "must be an integer"),
        (("0", 1.0, 5), TypeError, "t0 must be a real number"),
    ],
)
def test_timegrid_errors(args, exc, match):
    with pytest.raises(exc, match=match):
        TimeGrid(*args)
    with pytest.raises(IndexError, match="out of range"):
        TimeGrid(0.0, 1.0, 3)[np.array([3])]
    with pytest.raises(TypeError, match="integers or slices"):
        TimeGrid(0.0, 1.0, 3)[0.5]


# ---------------------------------------------------------------------------
# the closed form: identical to one solve call, same layout as Trajectory.to_xarray
# ---------------------------------------------------------------------------
def test_exact_stream_equals_direct_solve_and_layout(tmp_path):
    path = tmp_path / "run.zarr"
    out = solve_to_file(I123, (0.0, 40.0, 2001), path, omega0=W0, chunk=300, progress=False)
    assert out == path and path.is_dir()
    assert not (tmp_path / ".run.zarr.partial").exists()
    ds = _open(path)
    ref = solve(I123, np.linspace(0.0, 40.0, 2001), omega0=W0).to_xarray()
    assert set(ds.data_vars) == set(ref.data_vars)
    assert set(ds.coords) == set(ref.coords)
    for name in list(ref.data_vars) + list(ref.coords):
        assert ds[name].dims == ref[name].dims, name
        assert ds[name].attrs == ref[name].attrs, name
        assert ds[name].dtype == ref[name].dtype, name
    np.testing.assert_array_equal(ds["time"].values, ref["time"].values)
    for name in TIME_VARS:
        a, b = ds[name].values, ref[name].values
        if name == "gibbs":  # amplifies round-off near alpha = pi
            np.testing.assert_allclose(a, b, rtol=1e-11, atol=1e-12)
        else:
            np.testing.assert_allclose(a, b, rtol=0, atol=2e-15 * max(1.0, np.max(np.abs(b))))
    # sign-continuous quaternions across chunk boundaries
    q = ds["quaternion"].values
    assert np.all(np.sum(q[1:] * q[:-1], -1) > 0)
    keep = set(ref.attrs) - {"history", "stats"}
    assert {k: ds.attrs[k] for k in keep} == {k: ref.attrs[k] for k in keep}
    assert ds.attrs["T"] == 2001 and ds.attrs["stream_chunk"] == 300
    assert json.loads(ds.attrs["stats"])["chunks"] == 7


def test_batch_full_tensor_attitude_and_explicit_times(tmp_path, rng):
    A = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    inertia = np.stack([np.diag([1.0, 2.0, 3.0]), A @ np.diag([1.3, 2.1, 2.9]) @ A.T])
    inertia = 0.5 * (inertia + np.swapaxes(inertia, -1, -2))  # exactly symmetric, as RigidBody stores it
    w0 = rng.standard_normal((2, 3))
    q0 = rng.standard_normal(4)
    q0 /= np.linalg.norm(q0)
    t = np.concatenate([np.linspace(-5.0, 5.0, 250), [0.25, -1.0]])  # unsorted is fine for the closed form
    path = tmp_path / "batch.zarr"
    solve_to_file(RigidBody(inertia), t, path, omega0=w0, attitude0=q0, chunk=64, progress=False)
    ds = _open(path)
    tr = solve(inertia, t, omega0=w0, attitude0=q0)
    assert ds["quaternion"].dims == ("body", "time", "quat") and ds.sizes["body"] == 2
    assert np.max(_qdist(ds["quaternion"].values, tr.quaternion)) < 1e-13
    np.testing.assert_allclose(ds["omega"].values, tr.omega, atol=1e-14)
    np.testing.assert_allclose(ds["m"].values, tr.m, atol=1e-13)
    np.testing.assert_array_equal(ds["inertia"].values, inertia)
    assert json.loads(ds.attrs["batch_shape"]) == [2]


def test_long_run_streams_with_bounded_memory(tmp_path):
    """2.2e6 samples (~317 MB of output) in chunks of 5e4: the traced peak stays under 100 MB."""
    n, chunk = 2_200_000, 50_000
    full_bytes = n * 8 * (4 + 3 + 3 + 3 + 1 + 3 + 1)  # the time-dependent variables and the time
    assert full_bytes > 300e6
    path = tmp_path / "long.zarr"
    tracemalloc.start()
    try:
        solve_to_file(I123, (0.0, 2.0e4, n), path, omega0=W0, chunk=chunk, progress=False)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 100e6, f"peak traced memory {peak / 1e6:.1f} MB"
    import zarr

    g = zarr.open_group(str(path), mode="r")
    rng = np.random.default_rng(7)
    idx = np.sort(np.concatenate([rng.choice(n, 40, replace=False), [0, chunk - 1, chunk, n - 1]]))
    t = np.linspace(0.0, 2.0e4, n)[idx]
    np.testing.assert_array_equal(g["time"].get_coordinate_selection(idx), t)
    tr = solve(I123, t, omega0=W0)
    assert np.max(_qdist(g["quaternion"].get_orthogonal_selection((idx, slice(None))), tr.quaternion)) < 1e-12
    np.testing.assert_allclose(g["omega"].get_orthogonal_selection((idx, slice(None))), tr.omega, atol=1e-13)
    np.testing.assert_allclose(g["energy"].get_coordinate_selection(idx), tr.energy, rtol=1e-14)


# ---------------------------------------------------------------------------
# stepping methods: continue from the last state of each chunk
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("grid", [(0.0, 6.0, 121), (0.0, -6.0, 121), (1.0, 4.0, 61)])
def test_stepping_method_continues_chunks_consistently(tmp_path, rk4, grid):
    path = tmp_path / "rk.zarr"
    solve_to_file(I123, grid, path, omega0=W0, method=rk4, chunk=25, progress=False, dt=0.01)
    ds = _open(path)
    direct = solve(I123, np.linspace(*grid), omega0=W0, method=rk4, dt=0.01)
    # same integrator restarted at chunk boundaries: equal up to round-off
    assert np.max(_qdist(ds["quaternion"].values, direct.quaternion)) < 1e-12
    np.testing.assert_allclose(ds["omega"].values, direct.omega, atol=1e-12)
    # and a genuinely different (RK4) answer than the closed form, so the check above is not vacuous
    exact = solve(I123, np.linspace(*grid), omega0=W0)
    assert 1e-12 < np.max(np.abs(ds["omega"].values - exact.omega)) < 1e-5
    assert json.loads(ds.attrs["method_options"]) == {"dt": 0.01}


def test_stepping_method_needs_monotonic_times(tmp_path, rk4):
    t = np.concatenate([np.linspace(0, 1, 30), np.linspace(0.5, 2, 30)])
    with pytest.raises(InvalidInputError, match="strictly monotonic"):
        solve_to_file(I123, t, tmp_path / "x.zarr", omega0=W0, method=rk4, chunk=10, progress=False)
    with pytest.raises(InvalidInputError, match="strictly monotonic"):
        solve_to_file(I123, [0.0, 1.0, 1.0, 2.0], tmp_path / "y.zarr", omega0=W0, method=rk4, chunk=10, progress=False)


# ---------------------------------------------------------------------------
# interruption and resume
# ---------------------------------------------------------------------------
class _Stop:
    """A progress callback that presses Ctrl-C after ``after`` chunks."""

    def __init__(self, after_samples):
        self.after = after_samples
        self.calls = []

    def __call__(self, done, total):
        self.calls.append(done)
        if done >= self.after:
            raise KeyboardInterrupt


@pytest.mark.parametrize("method", ["exact", "stepper"])
def test_interrupt_keeps_chunks_and_resume_finishes(tmp_path, rk4, method):
    meth = rk4 if method == "stepper" else "exact"
    opts = {"dt": 0.02} if method == "stepper" else {}
    grid, chunk = (0.0, 12.0, 1000), 100
    ref_path = tmp_path / "ref.zarr"
    solve_to_file(I123, grid, ref_path, omega0=W0, method=meth, chunk=chunk, progress=False, **opts)
    path = tmp_path / "run.zarr"
    stop = _Stop(3 * chunk)
    with pytest.raises(KeyboardInterrupt) as info:
        solve_to_file(I123, grid, path, omega0=W0, method=meth, chunk=chunk, progress=stop, **opts)
    assert any("resume=True" in note for note in getattr(info.value, "__notes__", []))
    assert not path.exists()
    # the finished chunks are readable in the partial store; the rest is NaN
    part = _open(partial_store(path))
    ref = _open(ref_path)
    np.testing.assert_array_equal(part["omega"].values[: 3 * chunk], ref["omega"].values[: 3 * chunk])
    assert np.all(np.isnan(part["omega"].values[3 * chunk :]))
    # a plain rerun refuses to throw the work away
    with pytest.raises(EulerPoissonError, match="resume=True"):
        solve_to_file(I123, grid, path, omega0=W0, method=meth, chunk=chunk, progress=False, **opts)
    # a rerun with other arguments cannot resume it
    with pytest.raises(InvalidInputError, match="different arguments"):
        solve_to_file(
            I123, grid, path, omega0=[0.3, 1.0, 0.25], method=meth, chunk=chunk, progress=False, resume=True, **opts
        )
    calls = []
    solve_to_file(
        I123,
        grid,
        path,
        omega0=W0,
        method=meth,
        chunk=chunk,
        resume=True,
        progress=lambda d, tot: calls.append(d),
        **opts,
    )
    # only the 7 missing chunks were written (the engine recomputed their segment from its start, which is where
    # a stepping method continues: here the run is one segment)
    assert calls == list(range(3 * chunk, 1000 + 1, chunk))
    assert not (tmp_path / ".run.zarr.partial").exists()
    out = _open(path)
    for name in TIME_VARS:  # bit for bit the uninterrupted run (a stepper resumes from the stored state)
        np.testing.assert_array_equal(out[name].values, ref[name].values)
    # the counters add up over both sessions to those of one run, shared out over its 10 chunks (the test
    # stepper counts 1 "step" per solve, and the run is one segment; exact: 1000 evaluations)
    stats = json.loads(out.attrs["stats"])
    assert stats["chunks"] == 10
    assert (stats["steps"] == 1) if method == "stepper" else (stats["evaluations"] == 1000)


def test_overwrite_and_existing_output(tmp_path):
    path = tmp_path / "o.zarr"
    solve_to_file(I123, (0.0, 1.0, 11), path, omega0=W0, progress=False)
    with pytest.raises(FileExistsError, match="overwrite=True"):
        solve_to_file(I123, (0.0, 1.0, 11), path, omega0=W0, progress=False)
    solve_to_file(I123, (0.0, 2.0, 21), path, omega0=W0, progress=False, overwrite=True)
    assert _open(path).sizes["time"] == 21
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.zarr"]
    # overwrite replaces earlier results only, never a folder of something else
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("precious")
    with pytest.raises(FileExistsError, match="refusing to replace .*mine: it is a folder but not a Zarr store"):
        solve_to_file(I123, (0.0, 1.0, 11), other, omega0=W0, progress=False, overwrite=True)
    assert (other / "thesis.tex").read_text() == "precious"


def test_work_folder_without_state_is_discarded(tmp_path):
    """Killed while the empty store was being created: nothing finished, so nothing to resume."""
    work = tmp_path / ".w.zarr.partial"
    (work / "store.zarr").mkdir(parents=True)
    (work / "store.zarr" / "zarr.json").write_text("{")
    solve_to_file(I123, (0.0, 1.0, 11), tmp_path / "w.zarr", omega0=W0, progress=False)
    assert not work.exists() and _open(tmp_path / "w.zarr").sizes["time"] == 11
    # resume=True without any partial run simply runs
    solve_to_file(I123, (0.0, 1.0, 11), tmp_path / "w2.zarr", omega0=W0, progress=False, resume=True)
    assert _open(tmp_path / "w2.zarr").sizes["time"] == 11


def test_progress_bar(tmp_path, capsys):
    pytest.importorskip("rich")
    solve_to_file(I123, (0.0, 1.0, 50), tmp_path / "p.zarr", omega0=W0, chunk=10, progress=True)
    err = capsys.readouterr().err
    assert "p.zarr" in err and "50/50" in err
    solve_to_file(I123, (0.0, 1.0, 50), tmp_path / "q.zarr", omega0=W0, chunk=10)  # not a terminal: quiet
    assert capsys.readouterr().err == ""


def test_variables_subset(tmp_path):
    path = tmp_path / "v.zarr"
    solve_to_file(I123, (0.0, 3.0, 31), path, omega0=W0, variables=["energy"], progress=False)
    ds = _open(path)
    assert {v for v in ds.data_vars if "time" in ds[v].dims} == {"quaternion", "omega", "energy"}
    np.testing.assert_allclose(ds["energy"].values, 0.5 * np.sum(np.array(W0) ** 2 * I123), rtol=1e-14)


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        (dict(chunk=0), InvalidInputError, "chunk must be > 0"),
        (dict(chunk=2.5), InvalidInputError, "chunk must be an integer"),
        (dict(variables=["energy", "speed"]), InvalidInputError, "variables: unknown variable.*'speed'"),
        (dict(progress="yes"), TypeError, "progress must be"),
        (dict(t=(0.0, 1.0)), InvalidInputError, r"read as \(t0, t1, n\)"),
        (dict(t=np.zeros((2, 3))), InvalidInputError, "1-D array"),
        (dict(t=[]), InvalidInputError, "t is empty"),
        (dict(t=[0.0, np.nan]), InvalidInputError, "contains NaN"),
        (dict(method="nope"), InvalidInputError, "unknown method 'nope'"),
        (dict(bogus=1), TypeError, r"solve_to_file\(\) got an unexpected keyword argument 'bogus'"),
        (dict(omega0=None), TypeError, "exactly one of omega0"),
    ],
)
def test_bad_arguments(tmp_path, kwargs, exc, match):
    args = dict(t=(0.0, 1.0, 11), omega0=W0, progress=False)
    args.update(kwargs)
    t = args.pop("t")
    with pytest.raises(exc, match=match):
        solve_to_file(I123, t, tmp_path / "bad.zarr", **args)
    assert not (tmp_path / "bad.zarr").exists()


def test_time_variables_constant_matches_trajectory():
    from eulerpoisson.trajectory import Trajectory

    tr = Trajectory([0.0], [[1.0, 0, 0, 0]], [W0], RigidBody(I123))
    ds = tr.to_xarray()
    assert set(TIME_VARIABLES) == {v for v in ds.data_vars if "time" in ds[v].dims}
