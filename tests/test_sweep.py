"""Parameter sweeps: configuration, the per-point physics, Dask vs serial, interruption and resume, plots."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from _limits import HANG_GUARD_S

pytest.importorskip("zarr")
pytest.importorskip("xarray")
distributed = pytest.importorskip("distributed")

from _reference import quaternion_distance, reference_motion  # noqa: E402
from eulerpoisson.errors import EulerPoissonError, InvalidInputError  # noqa: E402
from eulerpoisson.sweep import compute_points, load_config, load_sweep, plot_atlas, run_sweep  # noqa: E402
from eulerpoisson.sweep import runner as sweep  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def config(tmp_path, **changes):
    cfg = {
        "sweep": {"kind": "grid"},
        "inertia": {"I1": 1.0, "I2": [1.6, 2.0, 2.4], "I3": 3.0},
        "momentum": {
            "polar": {"start": 10.0, "stop": 170.0, "num": 5},
            "azimuth": {"start": 0.0, "stop": 360.0, "num": 7},
        },
        "output": {"path": str(tmp_path / "atlas.zarr"), "chunk": 16},
        "compute": {"T": 20.0, "delta": 1e-6, "scheduler": "serial"},
    }
    for key, val in changes.items():
        sec, k = key.split("__")
        if val is None:
            cfg[sec].pop(k, None)
        else:
            cfg[sec][k] = val
    return cfg


def same(a, b):
    for v in ("half_period", "k2", "sensitivity", "status", "M0", "I1", "I2", "I3"):
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


@pytest.fixture(scope="module")
def cluster():
    """Two worker processes, started the way run_sweep(scheduler='local') starts them."""
    with sweep._local_cluster(2) as c:
        yield c


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted serial sweep (the reference)."""
    tmp = tmp_path_factory.mktemp("ref")
    path = run_sweep(config(tmp), progress=False)
    return load_sweep(path)


# ---------------------------------------------------------------------------
# configuration
# ---------------------------------------------------------------------------
def test_example_file_is_valid():
    cfg = load_config(ROOT / "examples" / "sweep.toml")
    assert cfg.kind == "grid" and cfg.scheduler == "local" and cfg.workers == 2
    assert cfg.n_points == 91 * 181
    assert cfg.axis_names == ["I1", "I2", "I3", "polar", "azimuth"]


@pytest.mark.parametrize(
    "changes, match",
    [
        ({"sweep__kind": "lattice"}, r"\[sweep\] kind must be 'grid' or 'random'"),
        ({"sweep__samples": 10}, r"\[sweep\] samples is only used with kind = 'random'"),
        ({"sweep__kind": "random"}, r"\[sweep\] samples is required"),
        ({"inertia__I1": None}, r"\[inertia\] I1 is required"),
        ({"inertia__I3": None}, r"\[inertia\] I3 is required"),
        ({"inertia__ratio21": 2.0}, r"\[inertia\] give either I2, I3 or ratio21, ratio31"),
        ({"inertia__I2": {"start": 1.0, "stop": 2.0, "num": 0}}, r"\[inertia\] I2.num must be an integer >= 1"),
        ({"inertia__I2": {"start": 1.0, "stop": 2.0}}, r"\[inertia\] I2: a grid range needs 'num'"),
        ({"inertia__I2": {"stop": 2.0, "num": 3}}, r"\[inertia\] I2: a range needs 'start'"),
        ({"inertia__I2": {"start": 1.0, "stop": 2.0, "num": 3, "step": 1}}, r"\[inertia\] I2: unknown key\(s\) step"),
        ({"inertia__I2": -1.0}, r"\[inertia\] I2 must be > 0"),
        ({"inertia__I2": []}, r"\[inertia\] I2: the list of values is empty"),
        ({"inertia__I2": "two"}, r"\[inertia\] I2 must be a number"),
        ({"inertia__I2": {"start": 0.0, "stop": 2.0, "num": 3, "log": True}}, r"\[inertia\] I2.start must be > 0"),
        ({"momentum__polar": 200.0}, r"\[momentum\] polar must lie in \[0, 180\]"),
        ({"momentum__azimuth": None}, r"\[momentum\] azimuth is required"),
        ({"momentum__magnitude": 0.0}, r"\[momentum\] magnitude must be > 0"),
        ({"momentum__degrees": "yes"}, r"\[momentum\] degrees must be true or false"),
        ({"output__chunk": 0}, r"\[output\] chunk must be an integer >= 1"),
        ({"output__path": ""}, r"\[output\] path must be a non-empty string"),
        ({"compute__T": -1.0}, r"\[compute\] T must be > 0"),
        ({"compute__T": float("inf")}, r"\[compute\] T must be finite"),
        ({"compute__delta": 0.5}, r"\[compute\] delta must be a small angle"),
        ({"compute__scheduler": "cloud"}, r"\[compute\] scheduler must be 'local', 'serial' or"),
        ({"compute__workers": 0}, r"\[compute\] workers must be an integer >= 1"),
        ({"compute__method": "nope"}, r"\[compute\] method: unknown method 'nope'"),
        ({"compute__speed": 1}, r"unknown key\(s\) speed in \[compute\]"),
    ],
)
def test_config_errors_name_the_key(tmp_path, changes, match):
    with pytest.raises(InvalidInputError, match=match):
        load_config(config(tmp_path, **changes))


def test_config_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_config(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[sweep\nkind = 1")
    with pytest.raises(InvalidInputError, match="invalid TOML"):
        load_config(bad)
    extra = tmp_path / "extra.toml"
    extra.write_text("[plot]\nx = 1\n")
    with pytest.raises(InvalidInputError, match=r"unknown section \[plot\]"):
        load_config(extra)
    nosec = tmp_path / "nosec.toml"
    nosec.write_text('[sweep]\nkind = "grid"\n')
    with pytest.raises(InvalidInputError, match=r"missing section \[inertia\]"):
        load_config(nosec)


def test_ratios_and_log_ranges(tmp_path):
    cfg = load_config(
        config(
            tmp_path,
            inertia__I2=None,
            inertia__I3=None,
            inertia__I1=2.0,
            inertia__ratio21={"start": 1.2, "stop": 1.8, "num": 4, "log": True},
            inertia__ratio31=1.9,
            momentum__polar=90.0,
            momentum__azimuth=[30.0, 60.0],
        )
    )
    assert cfg.axis_names == ["I1", "ratio21", "ratio31", "polar", "azimuth"]
    np.testing.assert_allclose(cfg.grid_axes["ratio21"], np.geomspace(1.2, 1.8, 4))
    ds = load_sweep(run_sweep(cfg, progress=False))
    assert dict(ds["half_period"].sizes) == {"ratio21": 4, "azimuth": 2}
    np.testing.assert_allclose(ds["I2"].values, 2.0 * np.geomspace(1.2, 1.8, 4)[:, None] * np.ones(2))
    np.testing.assert_allclose(ds["I3"].values, 3.8)


# ---------------------------------------------------------------------------
# the physics of one chunk, against independent integrations
# ---------------------------------------------------------------------------
def _flip_half_period_by_integration(I, M0):
    """Mean time between sign changes of Omega_2 over a few periods (DOP853, interpolated roots)."""
    w0 = M0 / I
    t = np.linspace(0.0, 60.0, 60001)
    _, w = reference_motion(I, w0, np.array([1.0, 0, 0, 0]), t)
    s = w[:, 1]
    i = np.nonzero(np.sign(s[:-1]) * np.sign(s[1:]) < 0)[0]
    roots = t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i])
    return np.mean(np.diff(roots))


def test_half_period_and_sensitivity_against_integration():
    I = np.array([[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [2.0, 2.5, 4.0]])
    th, ph = np.deg2rad([30.0, 70.0, 120.0]), np.deg2rad([40.0, 80.0, 200.0])
    M = 1.3 * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    T, delta = 7.0, 1e-4
    res = compute_points(I, M, T=T, delta=delta)
    assert res["status"].tolist() == [0, 0, 0]
    for i in range(3):
        ref = _flip_half_period_by_integration(I[i], M[i])
        assert abs(res["half_period"][i] - ref) < 1e-7 * ref
        # sensitivity: the same two perturbations, integrated independently
        u = M[i] / np.linalg.norm(M[i])
        e_th = np.array([np.cos(th[i]) * np.cos(ph[i]), np.cos(th[i]) * np.sin(ph[i]), -np.sin(th[i])])
        e_ph = np.array([-np.sin(ph[i]), np.cos(ph[i]), 0.0])
        q = [
            reference_motion(I[i], m / I[i], np.array([1.0, 0, 0, 0]), [T])[0][0]
            for m in (
                M[i],
                1.3 * (np.cos(delta) * u + np.sin(delta) * e_th),
                1.3 * (np.cos(delta) * u + np.sin(delta) * e_ph),
            )
        ]
        ref_s = max(quaternion_distance(q[0], q[1]), quaternion_distance(q[0], q[2])) / delta
        assert abs(res["sensitivity"][i] - ref_s) < 1e-6 * ref_s


def test_half_period_is_the_analysis_function_bit_for_bit(rng):
    from eulerpoisson.analysis import elliptic_parameters, tennis_racket_half_period

    I = np.sort(rng.uniform(1.0, 2.0, (40, 3)), -1)
    M = rng.standard_normal((40, 3))
    res = compute_points(I, M, T=1.0)
    for i in range(40):
        assert res["half_period"][i] == tennis_racket_half_period(I[i], M[i])
        assert res["k2"][i] == elliptic_parameters(I[i], M[i])["k2"]


def test_status_codes():
    I = np.array([[1.0, 2.0, 3.0], [1.0, 2.0, 2.0], [1.0, 1.0, 3.0], [2.0, 3.0, 4.0], [1.0, 2.0, 3.0]])
    M = np.array([[0.0, 1.0, 0.0], [1.0, 0.5, 0.2], [1.0, 0.5, 0.2], [0.3, 0.2, 1.0], [1.0, 0.0, 0.0]])
    res = compute_points(I, M, T=5.0)
    # separatrix (M along the middle axis), symmetric, not physical, regular, permanent rotation
    assert res["status"].tolist() == [1, 2, 3, 0, 0]
    assert np.isinf(res["half_period"][0])
    assert np.isnan(res["half_period"][1]) and np.isfinite(res["sensitivity"][1])
    assert np.all(np.isnan([res[k][2] for k in ("half_period", "k2", "sensitivity")]))
    # permanent rotation about the smallest axis: the small-oscillation limit pi/lambda, k^2 = 0
    lam = np.sqrt((2.0 - 1.0) * (3.0 - 1.0) / (2.0 * 3.0))
    assert res["k2"][4] == 0.0
    assert abs(res["half_period"][4] - np.pi / lam) < 1e-13 * np.pi / lam


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(M0=[[0.0, 0.0, 0.0]]), "zero angular momentum"),
        (dict(M0=[[1.0, 0.0]]), r"M0 must have shape \(\.\.\., 3\)"),
        (dict(M0=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), "same shape"),
        (dict(T=0.0), "T must be > 0"),
        (dict(delta=0.2), "delta must be a small angle"),
        (dict(inertia=[[1.0, np.nan, 3.0]]), "inertia contains NaN"),
    ],
)
def test_compute_points_errors(kwargs, match):
    args = dict(inertia=[[1.0, 2.0, 3.0]], M0=[[1.0, 0.2, 0.1]], T=1.0, delta=1e-6)
    args.update(kwargs)
    with pytest.raises(InvalidInputError, match=match):
        compute_points(args.pop("inertia"), args.pop("M0"), **args)


def test_grid_atlas_structure(reference):
    ds = reference
    assert dict(ds["half_period"].sizes) == {"I2": 3, "polar": 5, "azimuth": 7}
    assert ds["chunk_count"].values.tolist() == [1] * 7  # 105 points in chunks of 16
    # the stored M0 is the configured direction and magnitude
    th, ph = np.deg2rad(ds["polar"].values), np.deg2rad(ds["azimuth"].values)
    M = ds["M0"].sel(I2=2.0).values
    np.testing.assert_allclose(M[..., 2], np.cos(th)[:, None] * np.ones(7), atol=1e-15)
    np.testing.assert_allclose(M[..., 0], np.sin(th)[:, None] * np.cos(ph), atol=1e-15)
    # each point equals compute_points on that point alone
    sub = ds.isel(I2=1, polar=2, azimuth=1)
    one = compute_points([[1.0, 2.0, 3.0]], [sub["M0"].values], T=20.0, delta=1e-6)
    assert one["half_period"][0] == sub["half_period"].item()
    assert abs(one["sensitivity"][0] - sub["sensitivity"].item()) <= 1e-9 * one["sensitivity"][0]


def test_atlas_peaks_at_the_separatrix(tmp_path):
    cfg = config(
        tmp_path,
        inertia__I2=2.0,
        output__chunk=64,
        momentum__polar={"start": 0.0, "stop": 180.0, "num": 13},
        momentum__azimuth={"start": 0.0, "stop": 345.0, "num": 24},
    )
    ds = load_sweep(run_sweep(cfg, progress=False))
    hp = ds["half_period"]
    i, j = np.unravel_index(int(np.nanargmax(hp.values)), hp.shape)
    # M along +-axis 2 is the unstable permanent rotation
    assert ds["polar"].values[i] == 90.0 and ds["azimuth"].values[j] in (90.0, 270.0)
    s = ds["sensitivity"].values
    assert np.nanargmax(s) in np.ravel_multi_index(([6, 6], [6, 18]), s.shape)


# ---------------------------------------------------------------------------
# Dask: same bits as serial; resume after a kill
# ---------------------------------------------------------------------------
def test_local_cluster_equals_serial_exactly(tmp_path, cluster, reference):
    calls = []
    path = run_sweep(
        config(tmp_path),
        path=tmp_path / "dask.zarr",
        scheduler=cluster.scheduler_address,
        progress=lambda d, n: calls.append((d, n)),
    )
    same(load_sweep(path), reference)
    assert calls[-1] == (105, 105)
    # a Client given directly works the same
    with distributed.Client(cluster, set_as_default=False) as client:
        path2 = run_sweep(config(tmp_path), path=tmp_path / "client.zarr", client=client, progress=False)
    same(load_sweep(path2), reference)


def test_scheduler_local_starts_and_stops_its_own_cluster(tmp_path, monkeypatch, reference):
    """scheduler='local': run_sweep starts the cluster and closes it (threads here, to start fast)."""
    import logging

    made = []

    def threads_cluster(workers):
        c = distributed.LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=False, dashboard_address=":0", silence_logs=logging.ERROR
        )
        made.append(c)
        return c

    monkeypatch.setattr(sweep, "_local_cluster", threads_cluster)
    ds = load_sweep(run_sweep(config(tmp_path), scheduler="local", workers=2, progress=False))
    same(ds, reference)
    assert len(made) == 1 and len(made[0].workers) == 0 and made[0].status.name == "closed"


def test_random_sweep(tmp_path, cluster):
    cfg = config(
        tmp_path,
        sweep__kind="random",
        sweep__samples=300,
        sweep__seed=5,
        inertia__I2={"start": 1.5, "stop": 2.5},
        momentum__polar={"start": 0.0, "stop": 180.0},
        momentum__azimuth={"start": 0.0, "stop": 360.0},
        output__chunk=64,
    )
    a = load_sweep(run_sweep(cfg, path=tmp_path / "r1.zarr", progress=False))
    b = load_sweep(run_sweep(cfg, path=tmp_path / "r2.zarr", scheduler=cluster.scheduler_address, progress=False))
    same(a, b)
    assert a.sizes["point"] == 300
    assert np.all((a["I2"] >= 1.5) & (a["I2"] <= 2.5))
    assert abs(float(np.cos(np.deg2rad(a["polar"])).mean())) < 0.1  # uniform on the sphere
    np.testing.assert_allclose(np.linalg.norm(a["M0"].values, axis=-1), 1.0, rtol=1e-15)
    other = load_config(
        config(
            tmp_path, sweep__kind="random", sweep__samples=300, sweep__seed=6, inertia__I2={"start": 1.5, "stop": 2.5}
        )
    )
    c = load_sweep(run_sweep(other, path=tmp_path / "r3.zarr", progress=False))
    assert not np.array_equal(a["I2"].values, c["I2"].values)


def test_injected_interrupt_then_resume_recomputes_nothing(tmp_path, monkeypatch, reference):
    cfg = config(tmp_path)
    real = sweep._compute_chunk
    count = {"n": 0}

    def flaky(*args):
        if count["n"] == 3:
            raise KeyboardInterrupt
        count["n"] += 1
        return real(*args)

    monkeypatch.setattr(sweep, "_compute_chunk", flaky)
    with pytest.raises(KeyboardInterrupt) as info:
        run_sweep(cfg, progress=False)
    assert any("rerun the sweep to resume" in n for n in info.value.__notes__)
    out = Path(cfg["output"]["path"])
    assert not out.exists()
    part = load_sweep(out.parent / ".atlas.zarr.partial" / "store.zarr")
    assert part["chunk_count"].values.tolist() == [1, 1, 1, 0, 0, 0, 0]
    before = part["chunk_time"].values[:3].copy()
    with pytest.raises(FileNotFoundError, match="unfinished sweep"):
        load_sweep(out)
    monkeypatch.setattr(sweep, "_compute_chunk", real)
    ds = load_sweep(run_sweep(cfg, progress=False))
    assert ds["chunk_count"].values.tolist() == [1] * 7
    np.testing.assert_array_equal(ds["chunk_time"].values[:3], before)
    same(ds, reference)
    # the finished store is not recomputed either
    run_sweep(cfg, progress=False)
    np.testing.assert_array_equal(load_sweep(out)["chunk_time"].values, ds["chunk_time"].values)


CHILD = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from eulerpoisson.sweep import runner as sweep

    flag = Path(sys.argv[2])
    real = sweep._compute_chunk
    calls = [0]

    def slow(*args):
        k = calls[0]
        calls[0] += 1
        if k >= 2:  # chunks 0 and 1 are written and recorded before this call
            (flag / f"sleeping-{k}").touch()
            time.sleep(60)
        return real(*args)

    sweep._compute_chunk = slow
    sweep.run_sweep(sweep.load_config(sys.argv[1]), scheduler="serial", progress=False)
    """
)


def test_killed_sweep_resumes_on_the_cluster(tmp_path, cluster, reference):
    cfg = config(tmp_path)
    toml = tmp_path / "sweep.toml"
    toml.write_text(
        "[inertia]\nI1 = 1.0\nI2 = [1.6, 2.0, 2.4]\nI3 = 3.0\n"
        "[momentum]\npolar = {start = 10.0, stop = 170.0, num = 5}\nazimuth = {start = 0.0, stop = 360.0, num = 7}\n"
        f"[output]\npath = {json.dumps(cfg['output']['path'])}\nchunk = 16\n"
        "[compute]\nT = 20.0\ndelta = 1e-6\n"
    )
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    proc = subprocess.Popen([sys.executable, str(script), str(toml), str(tmp_path)], cwd=tmp_path)
    try:
        deadline = time.monotonic() + HANG_GUARD_S  # a guard against a hang, not a timing
        while not (tmp_path / "sleeping-2").exists():
            assert proc.poll() is None, "the child sweep ended early"
            assert time.monotonic() < deadline
            time.sleep(0.05)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=HANG_GUARD_S)
    work = tmp_path / ".atlas.zarr.partial"
    assert sorted(p.name for p in (work / "done").iterdir()) == ["000000000", "000000001"]
    before = load_sweep(work / "store.zarr")["chunk_time"].values[:2].copy()
    ds = load_sweep(run_sweep(toml, scheduler=cluster.scheduler_address, progress=False))
    assert ds["chunk_count"].values.tolist() == [1] * 7
    np.testing.assert_array_equal(ds["chunk_time"].values[:2], before)
    same(ds, reference)


def test_unreachable_scheduler(tmp_path):
    import dask

    with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
        with pytest.raises(EulerPoissonError, match="cannot connect to the Dask scheduler"):
            run_sweep(config(tmp_path), scheduler="tcp://127.0.0.1:9", progress=False)


# ---------------------------------------------------------------------------
# existing outputs, bad arguments, reading
# ---------------------------------------------------------------------------
def test_existing_outputs(tmp_path, reference):
    cfg = config(tmp_path)
    path = run_sweep(cfg, progress=False)
    other = config(tmp_path, compute__T=21.0)
    with pytest.raises(FileExistsError, match="different sweep"):
        run_sweep(other, progress=False)
    ds = load_sweep(run_sweep(other, progress=False, overwrite=True))
    assert ds.attrs["T"] == 21.0
    assert not np.array_equal(ds["sensitivity"].values, reference["sensitivity"].values)
    junk = tmp_path / "junk"
    junk.mkdir()
    with pytest.raises(FileExistsError, match="different sweep"):
        run_sweep(cfg, path=junk, progress=False)
    with pytest.raises(EulerPoissonError, match="not an eulerpoisson sweep|not a readable Zarr"):
        load_sweep(junk)
    with pytest.raises(FileNotFoundError, match="no sweep store"):
        load_sweep(tmp_path / "nothing.zarr")
    assert path.exists()


def test_partial_with_other_config_is_protected(tmp_path, monkeypatch):
    def boom(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep, "_compute_chunk", boom)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(config(tmp_path), progress=False)
    monkeypatch.undo()
    with pytest.raises(EulerPoissonError, match="partial sweep with a different configuration"):
        run_sweep(config(tmp_path, compute__T=3.0), progress=False)
    ds = load_sweep(run_sweep(config(tmp_path, compute__T=3.0), progress=False, overwrite=True))
    assert ds.attrs["T"] == 3.0


def test_work_folder_without_state_is_discarded(tmp_path, reference):
    cfg = config(tmp_path)
    work = tmp_path / ".atlas.zarr.partial"
    (work / "done").mkdir(parents=True)
    (work / "done" / "000000003").write_text("{}")  # stale: no state.json, so nothing is trusted
    ds = load_sweep(run_sweep(cfg, progress=False))
    assert not work.exists()
    assert ds["chunk_count"].values.tolist() == [1] * 7
    same(ds, reference)


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        (dict(scheduler="mpi"), InvalidInputError, "scheduler must be 'local', 'serial' or"),
        (dict(workers=0), InvalidInputError, "workers must be an integer >= 1"),
        (dict(progress="loud"), TypeError, "progress must be"),
    ],
)
def test_run_sweep_bad_arguments(tmp_path, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        run_sweep(config(tmp_path), **kwargs)


# ---------------------------------------------------------------------------
# plots
# ---------------------------------------------------------------------------
def _is_png(path):
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_atlas(tmp_path, reference):
    out = plot_atlas(reference.isel(I2=1), tmp_path / "sphere.png", dpi=60)
    assert _is_png(out) and out.stat().st_size > 5_000
    out2 = plot_atlas(reference.isel(azimuth=2), tmp_path / "inertia.png", variables="half_period", dpi=60)
    assert _is_png(out2)
    with pytest.raises(InvalidInputError, match="exactly two axes"):
        plot_atlas(reference, tmp_path / "x.png")
    with pytest.raises(InvalidInputError, match="'speed' is not in the sweep"):
        plot_atlas(reference.isel(I2=1), tmp_path / "x.png", variables=["speed"])
    with pytest.raises(InvalidInputError, match="needs a sweep dataset"):
        plot_atlas({"a": 1}, tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_plot_random_atlas(tmp_path):
    cfg = config(
        tmp_path,
        sweep__kind="random",
        sweep__samples=80,
        inertia__I2=2.0,
        momentum__polar={"start": 0.0, "stop": 180.0},
        momentum__azimuth={"start": 0.0, "stop": 360.0},
    )
    ds = load_sweep(run_sweep(cfg, progress=False))
    assert _is_png(plot_atlas(ds, tmp_path / "random.png", dpi=60))
    cfg2 = config(
        tmp_path,
        sweep__kind="random",
        sweep__samples=20,
        inertia__I2={"start": 1.5, "stop": 2.5},
        momentum__polar={"start": 0.0, "stop": 180.0},
        momentum__azimuth={"start": 0.0, "stop": 360.0},
        output__path=str(tmp_path / "r2.zarr"),
    )
    with pytest.raises(InvalidInputError, match="only for one body"):
        plot_atlas(load_sweep(run_sweep(cfg2, progress=False)), tmp_path / "no.png")


def test_overwrite_never_deletes_a_folder_that_is_not_a_store(tmp_path, monkeypatch):
    target = tmp_path / "data"
    target.mkdir()
    (target / "notes.txt").write_text("keep me")

    def boom(*a, **k):  # the refusal must come before any work
        raise AssertionError("computed before refusing")

    monkeypatch.setattr(sweep, "_compute_chunk", boom)
    with pytest.raises(FileExistsError, match="refusing to replace .*data: it is a folder but not a Zarr store"):
        run_sweep(config(tmp_path, output__path=str(target)), progress=False, overwrite=True)
    assert (target / "notes.txt").read_text() == "keep me"
