"""Every route gives the same bits (issue 21): ``ep.solve``, a NetCDF file, a Zarr store, ``--json`` and a sweep
cell all run the one engine (:mod:`eulerpoisson.solvers.engine`), whatever the route's own chunking.

Each method runs a problem long enough to be cut into several segments (a stepping method continues each from
the last state of the previous one), and the routes are compared bit for bit, quaternion signs included.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import eulerpoisson as ep
from eulerpoisson.io.stream import solve_to_file
from eulerpoisson.solvers import engine
from eulerpoisson.solvers.engine import plan_segments, prepare_run

pytest.importorskip("zarr")
xr = pytest.importorskip("xarray")

I = [1.0, 2.0, 3.0]
W0 = [1.0, 0.1, 0.5]

#: (method, options, torque flags of the CLI) for one problem per method; every method in the registry
CASES = {
    "exact": ({}, None),
    "rk": ({}, None),
    "taylor": ({}, None),
    "symplectic": ({"dt": 0.01}, None),
    "rk4": ({"dt": 0.05}, None),
}


#: segments of this many output times in these tests (the engine's own is 50 000): every route is cut into
#: several segments at a small cost; the rule is the same, and it is the rule that every route must follow
SEGMENT = 300


@pytest.fixture(autouse=True)
def small_segments(monkeypatch):
    monkeypatch.setattr(engine, "SEGMENT", SEGMENT)


def _bits(a):
    return np.ascontiguousarray(a).view(np.uint64)


def _same_bits(a, b, what):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    assert np.array_equal(_bits(a), _bits(b)), f"{what}: {np.max(np.abs(a - b))} apart"


def test_the_cases_cover_every_method():
    assert set(CASES) == set(ep.available_methods())


@pytest.mark.parametrize("method", sorted(CASES))
def test_solve_and_zarr_give_the_same_bits(tmp_path, method):
    opts, _ = CASES[method]
    n = SEGMENT + SEGMENT // 5  # two segments for a stepping method
    t_end = 12.0 if method in ("rk", "rk4") else 60.0
    tr = ep.solve(I, np.linspace(0.0, t_end, n), omega0=W0, method=method, **opts)
    if method != "exact":
        assert tr.stats["segments"] == 2
    # a Zarr store with storage chunks that do not line up with the segments
    path = solve_to_file(
        I, (0.0, t_end, n), tmp_path / "r.zarr", omega0=W0, method=method, chunk=77, progress=False, **opts
    )
    ds = xr.open_zarr(str(path))
    _same_bits(ds["time"].values, tr.t, "time")
    _same_bits(ds["quaternion"].values, tr.quaternion, f"{method}: quaternion")
    _same_bits(ds["omega"].values, tr.omega, f"{method}: omega")


def test_a_resumed_stepping_run_is_the_same_bits(tmp_path):
    """Interrupted in the second segment, resumed: the store equals one uninterrupted solve."""
    n, t_end = 2 * SEGMENT + 600, 40.0
    ref = ep.solve(I, np.linspace(0.0, t_end, n), omega0=W0, method="taylor")

    class Stop:
        def __call__(self, done, total):
            if done >= SEGMENT + 150:
                raise KeyboardInterrupt

    path = tmp_path / "r.zarr"
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(I, (0.0, t_end, n), path, omega0=W0, method="taylor", chunk=100, progress=Stop())
    solve_to_file(I, (0.0, t_end, n), path, omega0=W0, method="taylor", chunk=100, progress=False, resume=True)
    ds = xr.open_zarr(str(path))
    _same_bits(ds["quaternion"].values, ref.quaternion, "quaternion")
    _same_bits(ds["omega"].values, ref.omega, "omega")


def test_segments_are_a_function_of_the_run_alone():
    run = prepare_run(I, np.linspace(0.0, 10.0, 3 * SEGMENT), omega0=W0, method="taylor")
    turns = float(np.linalg.norm(W0)) * 10.0
    assert run.bounds == plan_segments(3 * SEGMENT, closed_form=False, monotonic=True, turns=turns)
    assert [b - a for a, b in run.bounds] == [SEGMENT] * 3
    # a batch of many bodies is cut into shorter segments (bounded memory), the same in every route
    many = prepare_run(np.tile(I, (1000, 1)), np.linspace(0.0, 1.0, 5_000), omega0=W0, method="taylor")
    assert max(b - a for a, b in many.bounds) <= engine.SEGMENT_SAMPLES // 1000
    # the closed form is one piece in memory (its times are independent of each other)
    exact = prepare_run(I, np.linspace(0.0, 10.0, 3 * SEGMENT), omega0=W0, in_memory=True)
    assert exact.bounds == [(0, 3 * SEGMENT)] and exact.method_name == "exact"


def test_default_method_is_the_most_accurate_that_runs_the_model():
    assert ep.solve(I, [0.0, 1.0], omega0=W0).method == "exact"
    grav = ep.torques.GravityGradient(0.1)
    assert ep.solve(I, [0.0, 1.0], omega0=W0, torque=grav).method == "taylor"
    top = ep.torques.Gravity(1.0, [0.0, 0.0, 0.1])
    assert ep.solve([1.0, 1.0, 0.5], [0.0, 1.0], omega0=[0.0, 0.2, 20.0], torque=top).method == "exact"

    def damping(t, q, w):
        return -0.01 * w

    assert ep.solve(I, [0.0, 1.0], omega0=W0, torque=damping).method == "rk"


def test_non_monotonic_times_cannot_be_written_by_a_stepping_method(tmp_path):
    t = np.array([0.0, 2.0, 1.0])
    ep.solve(I, t, omega0=W0, method="taylor")  # in memory: integrated from 0 both ways, one piece
    with pytest.raises(ep.InvalidInputError, match="strictly monotonic"):
        solve_to_file(I, t, tmp_path / "x.zarr", omega0=W0, method="taylor", progress=False)


def test_json_of_the_store_matches(tmp_path):
    """The state written in a store's attributes round-trips through JSON (finite values only)."""
    path = solve_to_file(I, (0.0, 5.0, 11), tmp_path / "r.zarr", omega0=W0, progress=False)
    stats = json.loads(xr.open_zarr(str(path)).attrs["stats"])
    assert stats["chunks"] == 1


# ---------------------------------------------------------------------------
# the command line: NetCDF, Zarr and --json alone give the bits of ep.solve
# ---------------------------------------------------------------------------
def _simulate(capsys, *argv):
    from eulerpoisson.cli import main

    code = main(["simulate", "--inertia", "1,2,3", "--omega", "1,0.1,0.5", *argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


@pytest.mark.parametrize("method", sorted(CASES))
def test_simulate_routes_give_the_bits_of_solve(tmp_path, capsys, method):
    opts, _ = CASES[method]
    n = SEGMENT + 200  # two segments for a stepping method, in every route
    t_end = 60.0 if method in ("exact", "taylor") else 12.0
    flags = ["--t-end", str(t_end), "--samples", str(n), "--method", method]
    for k, v in opts.items():
        flags += [f"--{k}", str(v)]
    ref = ep.solve(I, np.linspace(0.0, t_end, n), omega0=W0, method=method, **opts)
    states = {
        "json": _simulate(capsys, *flags),
        "nc": _simulate(capsys, *flags, "--out", str(tmp_path / "r.nc")),
        "zarr": _simulate(capsys, *flags, "--out", str(tmp_path / "r.zarr")),
    }
    for route, st in states.items():
        _same_bits(st["quaternion"], ref.quaternion[-1], f"{method} via {route}: quaternion(T)")
        _same_bits(st["omega"], ref.omega[-1], f"{method} via {route}: omega(T)")
    nc = ep.Trajectory.open(tmp_path / "r.nc")
    _same_bits(nc.quaternion, ref.quaternion, f"{method}: the .nc file")
    zs = xr.open_zarr(str(tmp_path / "r.zarr"))
    _same_bits(zs["quaternion"].values, ref.quaternion, f"{method}: the .zarr store")
    _same_bits(zs["omega"].values, nc.omega, f"{method}: .zarr vs .nc")


def test_a_sweep_cell_is_the_motion_of_solve(tmp_path):
    """A sweep's sensitivity is computed from the attitudes of the engine: the same bits as from ep.solve."""
    from eulerpoisson.sweep import compute_points, load_sweep, run_sweep

    cfg = {
        "inertia": {"I1": 1.0, "I2": 2.0, "I3": 3.0},
        "momentum": {"polar": [30.0, 60.0], "azimuth": [0.0, 45.0]},
        "output": {"path": str(tmp_path / "s.zarr"), "chunk": 3},
        "compute": {"T": 10.0, "scheduler": "serial", "delta": 1e-6},
    }
    ds = load_sweep(run_sweep(cfg, progress=False))
    sens = ds["sensitivity"].values.reshape(-1)
    M0 = np.asarray(ds["M0"].values).reshape(-1, 3)
    Iv = np.tile([1.0, 2.0, 3.0], (M0.shape[0], 1))
    # the same cells recomputed: the attitudes at T of the three nearby momenta, from ep.solve
    np.testing.assert_array_equal(compute_points(Iv, M0, T=10.0, delta=1e-6)["sensitivity"], sens)
    L = np.linalg.norm(M0, axis=-1)
    u = M0 / L[:, None]
    th, ph = np.arccos(np.clip(u[:, 2], -1, 1)), np.arctan2(u[:, 1], u[:, 0])
    e_th = np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)], -1)
    e_ph = np.stack([-np.sin(ph), np.cos(ph), np.zeros_like(ph)], -1)
    c, s = np.cos(1e-6), np.sin(1e-6)
    Ms = np.concatenate([M0, L[:, None] * (c * u + s * e_th), L[:, None] * (c * u + s * e_ph)])
    Is = np.concatenate([Iv, Iv, Iv])
    q = ep.solve(ep.RigidBody(Is[:, :, None] * np.eye(3)), [10.0], omega0=Ms / Is).quaternion[:, 0, :]
    q = q.reshape(3, -1, 4)

    def angle(q1, q2):
        w = np.sum(q1 * q2, -1)
        v = q1[..., :1] * q2[..., 1:] - q2[..., :1] * q1[..., 1:] - np.cross(q1[..., 1:], q2[..., 1:])
        return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))

    _same_bits(np.maximum(angle(q[0], q[1]), angle(q[0], q[2])) / 1e-6, sens, "sweep sensitivity")


@pytest.mark.parametrize("method", ["taylor", "rk"])
def test_segments_continue_a_time_dependent_torque(monkeypatch, method):
    """Under a gravity gradient (a torque that turns with the orbit) a run in segments is the run in one piece
    (to the method's error): each segment continues with the torque shifted to its start (Model.shifted)."""
    from eulerpoisson.solvers import engine

    grav = [ep.torques.GravityGradient(0.5), ep.torques.Gravity(1.0, [0.0, 0.0, 0.1])]
    t = np.linspace(0.0, 20.0, 4001)
    monkeypatch.setattr(engine, "SEGMENT", 1000)
    cut = ep.solve(I, t, omega0=[0.3, 1.0, 0.2], torque=grav, method=method)
    assert cut.stats["segments"] == 5
    monkeypatch.setattr(engine, "SEGMENT", 10**6)
    one = ep.solve(I, t, omega0=[0.3, 1.0, 0.2], torque=grav, method=method)
    assert "segments" not in one.stats
    tol = 1e-11 if method == "taylor" else 1e-7
    np.testing.assert_allclose(cut.omega, one.omega, atol=tol)
    np.testing.assert_allclose(np.abs(np.sum(cut.quaternion * one.quaternion, -1)), 1.0, atol=tol)
    # and the signs are continuous across the boundaries
    assert np.all(np.sum(cut.quaternion[1:] * cut.quaternion[:-1], -1) > 0)
