"""Long stores read fast and unfinished ones described (issue 12, items 5 and 7, and ``info`` of a partial run).

* ``plot`` of a long ``.zarr`` store was bound by decoding its chunks through
  zarr, one at a time: chunks of the layout we write are now read from their
  files and decoded in several threads (:class:`_DirectChunks`,
  :func:`ordered_map`), and the min/max envelope is reduced piece by piece in
  those threads. These tests check that what is read is what zarr reads, bit
  for bit (partial chunks, strides, batches, unwritten chunks, other codecs),
  and that the pictures do not go through zarr for the chunks; no timing is
  asserted (benchmarks/bench_plot_long.py measures).
* ``info`` of an interrupted ``simulate --out X.zarr`` said "no such file"
  (or failed on the NaN of the partial store): it says how far the run got,
  up to what time, and the command that resumes it — which does resume it.
"""

import json
import re
import shlex
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

zarr = pytest.importorskip("zarr")

import eulerpoisson as ep  # noqa: E402
from _limits import HANG_GUARD_S  # noqa: E402
from eulerpoisson.cli import main  # noqa: E402
from eulerpoisson.io import read as R  # noqa: E402
from eulerpoisson.io.stream import TimeGrid, partial_store, solve_to_file  # noqa: E402

EXE = str(Path(sys.executable).with_name("eulerpoisson"))
I123, W0 = [1.0, 2.0, 3.0], [1.0, 0.1, 0.5]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    path = tmp_path_factory.mktemp("st") / "s.zarr"
    solve_to_file(I123, (0.0, 50.0, 25_013), path, omega0=W0, chunk=3_000, progress=False)  # a short last chunk
    return path


# ---------------------------------------------------------------------------
# the direct chunk reader
# ---------------------------------------------------------------------------
def _zarr_read(path, name, a, b, step, axis=0):
    g = zarr.open_group(str(path), mode="r")
    sl = (slice(None), slice(a, b, step)) if axis else slice(a, b, step)
    return np.asarray(g[name][sl])


def test_direct_reads_equal_zarr_reads(store):
    lz = ep.Trajectory.open(store)
    rng = np.random.default_rng(5)
    T = len(lz)
    for name in ("time", "quaternion", "omega", "M", "m", "energy", "gibbs"):
        arr = lz.t if name == "time" else lz.stored(name)
        assert isinstance(R._DirectChunks.of(arr._arr, 0), R._DirectChunks), name
        cases = [
            (0, T, 1),
            (0, 3000, 1),
            (2999, 3001, 1),
            (24_000, T, 1),
            (5, T, 7),
            (0, T, 3001),
            (T - 1, T, 1),
            (10, 10, 1),
        ]
        cases += [(int(a), int(a + rng.integers(0, 9000)), int(rng.integers(1, 50))) for a in rng.integers(0, T, 20)]
        for a, b, step in cases:
            b = min(b, T)
            got = arr.read(a, b, step)
            ref = _zarr_read(store, name, a, b, step)
            assert got.dtype == ref.dtype and got.shape == ref.shape
            np.testing.assert_array_equal(got, ref)


def test_pictures_of_a_store_read_its_chunks_without_zarr(store, monkeypatch):
    """The decoding is ours (threads in parallel): zarr's array reads are not used for the chunks."""
    pytest.importorskip("matplotlib")
    from eulerpoisson.viz import plots

    lz = ep.Trajectory.open(store)
    calls = []
    real = zarr.Array.__getitem__

    def spy(self, sel):
        calls.append(self.path)
        return real(self, sel)

    monkeypatch.setattr(zarr.Array, "__getitem__", spy)
    for kind in ("omega", "invariants", "attitude"):
        plots.plot(lz, kind)
    assert not any(c in ("omega", "m", "energy", "quaternion", "time") for c in calls), calls


def test_unwritten_chunks_read_as_nan_like_zarr(tmp_path):
    class Stop:
        def __call__(self, done, total):
            if done >= 2_000:
                raise KeyboardInterrupt

    path = tmp_path / "p.zarr"
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(I123, (0.0, 5.0, 5_000), path, omega0=W0, chunk=1_000, progress=Stop())
    g = zarr.open_group(str(partial_store(path)), mode="r")
    direct = R._DirectChunks.of(g["omega"], 0)
    got = direct.read(500, 5_000, 3)
    np.testing.assert_array_equal(got, np.asarray(g["omega"][500:5_000:3]))
    assert np.all(np.isfinite(got[: (2_000 - 500 + 2) // 3])) and np.all(np.isnan(got[-10:]))


def test_batched_store_reads_equal_zarr(tmp_path):
    path = tmp_path / "b.zarr"
    solve_to_file(
        [[1.0, 2.0, 3.0], [2.0, 3.0, 4.0]],
        (0.0, 5.0, 2_500),
        path,
        omega0=[[1.0, 0.1, 0.5], [0.2, 1.0, 0.3]],
        chunk=700,
        progress=False,
    )
    lz = ep.Trajectory.open(path)
    assert lz.batch_shape == (2,)
    for a, b, step in ((0, 2_500, 1), (650, 1_450, 3), (2_499, 2_500, 1)):
        got = lz.omega.read(a, b, step)
        assert got.shape == (2, len(range(a, b, step)), 3)
        np.testing.assert_array_equal(got, _zarr_read(path, "omega", a, b, step, axis=1))
    mem = ep.solve(
        [[1.0, 2.0, 3.0], [2.0, 3.0, 4.0]], np.linspace(0.0, 5.0, 2_500), omega0=[[1.0, 0.1, 0.5], [0.2, 1.0, 0.3]]
    )
    np.testing.assert_array_equal(lz.load().omega, mem.omega)


@pytest.mark.parametrize("codecs", ["none", "blosc", "sharded"])
def test_other_layouts_are_read_by_zarr(tmp_path, codecs):
    """Only our layout is read directly; uncompressed chunks too, anything else through zarr (same values)."""
    from zarr.codecs import BloscCodec

    x = np.random.default_rng(1).normal(size=(1_000, 3))
    kw = {"none": {"compressors": None}, "blosc": {"compressors": [BloscCodec()]}, "sharded": {"shards": (400, 3)}}[
        codecs
    ]
    arr = zarr.create_array(
        str(tmp_path / "a.zarr"), shape=x.shape, chunks=(100, 3), dtype="f8", fill_value=np.nan, **kw
    )
    arr[...] = x
    direct = R._DirectChunks.of(arr, 0)
    assert (direct is not None) == (codecs == "none")
    sa = R.StoredArray(arr, ())
    np.testing.assert_array_equal(sa.read(37, 999, 4), x[37:999:4])


def test_a_damaged_chunk_is_left_to_zarr(store, tmp_path):
    import shutil

    path = tmp_path / "d.zarr"
    shutil.copytree(store, path)
    chunk = path / "omega" / "c" / "2" / "0"
    chunk.write_bytes(chunk.read_bytes()[:100])
    g = zarr.open_group(str(path), mode="r")
    direct = R._DirectChunks.of(g["omega"], 0)
    with pytest.raises(R._NotDirect):
        direct.read(6_000, 6_010)
    np.testing.assert_array_equal(direct.read(0, 10), np.asarray(g["omega"][0:10]))  # the others still read
    with pytest.raises(Exception):  # noqa: B017 - zarr says what is wrong with it; its exception type is its own
        R.StoredArray(g["omega"], ()).read(6_000, 6_010)


def test_grid_times_are_the_time_grid_bit_for_bit():
    rng = np.random.default_rng(2)
    for t0, t1, n in ((0.0, 1e5, 10**8), (-3.3, 7.1, 1001), (5.0, -2.0, 17), (0.0, 1.0, 2), (1e10, 1e10 + 1, 10**7)):
        g = TimeGrid(t0, t1, n)
        for _ in range(100):
            a = int(rng.integers(0, n))
            b = int(rng.integers(a, min(n, a + 200_000) + 1))
            s = int(rng.integers(1, 5))
            np.testing.assert_array_equal(R._grid_times(g, a, b, s), g[a:b:s])
        if n < 10**6:
            np.testing.assert_array_equal(R._grid_times(g, 0, n, 1), np.linspace(t0, t1, n))


def test_ordered_map_keeps_the_order_bounds_the_work_and_raises():
    running, peak, lock = [0], [0], threading.Lock()

    def f(i):
        with lock:
            running[0] += 1
            peak[0] = max(peak[0], running[0])
        time.sleep(0.002 * (i % 3))
        with lock:
            running[0] -= 1
        if i == 37:
            raise ValueError("piece 37")
        return i * i

    got = []
    with pytest.raises(ValueError, match="piece 37"):
        for v in R.ordered_map(f, range(100), workers=3):
            got.append(v)
    assert got == [i * i for i in range(37)] and peak[0] <= 3
    started = []
    gen = R.ordered_map(lambda i: started.append(i) or i, range(10**6), workers=2)
    assert [next(gen) for _ in range(5)] == list(range(5))
    gen.close()
    assert len(started) <= 5 + 3  # what was not started is cancelled: memory stays bounded


def test_envelope_pieces_in_any_order_and_threads_equal_one_pass():
    from eulerpoisson.viz.decimate import MinMaxEnvelope

    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.0, 10.0, 50_000))
    t[1000:1100] = t[1000]  # repeated times
    t = np.concatenate([t[:20_000], t[30_000:]])  # a gap: empty columns
    y = rng.normal(size=(t.size, 3))
    y[::97, 1] = np.nan
    y[5000:5400, 2] = np.nan  # a column all NaN for one series
    one = MinMaxEnvelope(0.0, 10.0, 3, nbins=333)
    one.add(t, y)
    pieces = MinMaxEnvelope(0.0, 10.0, 3, nbins=333)
    cuts = np.unique(rng.integers(0, t.size, 40))
    parts = [pieces.reduce(a, b) for a, b in zip(np.split(t, cuts), np.split(y, cuts))]
    for i in rng.permutation(len(parts)):
        pieces.merge(parts[i])
    brute = MinMaxEnvelope(0.0, 10.0, 3, nbins=333)
    order = rng.permutation(t.size)  # any order: the binning sample by sample
    brute.add(t[order], [y[order, j] for j in range(3)])
    for env in (pieces, brute):
        np.testing.assert_array_equal(env.count, one.count)
        np.testing.assert_array_equal(env.lo, one.lo)
        np.testing.assert_array_equal(env.hi, one.hi)
    x1, y1 = one.points()
    col = one.bins_of(t)
    for c in np.unique(col)[::7]:  # tight: the extremes of the samples in the column
        sel = y[col == c]
        k = int(np.flatnonzero(np.unique(col) == c)[0])
        for j in range(3):
            if np.all(np.isnan(sel[:, j])):
                assert np.isnan(y1[2 * k : 2 * k + 2, j]).all()
            else:
                assert np.nanmin(y1[2 * k : 2 * k + 2, j]) == np.nanmin(sel[:, j])
                assert np.nanmax(y1[2 * k : 2 * k + 2, j]) == np.nanmax(sel[:, j])


def test_invariants_of_a_store_equal_those_of_the_run_in_memory(store):
    pytest.importorskip("matplotlib")
    from eulerpoisson.viz import plots

    lz = ep.Trajectory.open(store)
    mem = lz.load()
    a, b = plots.plot(lz, "invariants"), plots.plot(mem, "invariants")
    la = {ln.get_label(): ln for ln in a.axes[0].get_lines()}
    lb = {ln.get_label(): ln for ln in b.axes[0].get_lines()}
    eps = np.finfo(float).eps
    for key in ("E", "|m|", "m₁", "m₂", "m₃"):
        ya, yb = np.asarray(la[key].get_ydata()), np.asarray(lb[key].get_ydata())
        np.testing.assert_array_equal(la[key].get_xdata(), lb[key].get_xdata())
        # the store's m and E were computed by the writer; in memory they are recomputed: round-off apart
        assert np.max(np.abs(ya - yb)) <= 64 * eps


# ---------------------------------------------------------------------------
# info of an unfinished run
# ---------------------------------------------------------------------------
class _Stop:
    def __init__(self, after):
        self.after = after

    def __call__(self, done, total):
        if done >= self.after:
            raise KeyboardInterrupt


def _resume_line(out: str) -> str:
    m = re.search(r"^  resume      (eulerpoisson simulate .*)$", out, flags=re.M)
    assert m, out
    return m.group(1)


@pytest.mark.parametrize("case", ["free", "top"])
def test_info_of_an_interrupted_store_says_how_far_and_how_to_resume(capsys, tmp_path, monkeypatch, case):
    from eulerpoisson.model.body import RigidBody
    from eulerpoisson.model.equations import Model
    from eulerpoisson.model.torques import Gravity

    monkeypatch.chdir(tmp_path)
    n = 250_001
    if case == "free":
        model, kw = ep.RigidBody(I123), dict(omega0=W0)
        t_end = 100.0
    else:  # a heavy top, backwards in time, a tilted start and a method option
        q0 = np.array([0.8, 0.36, -0.48, 0.0])
        model = Model(RigidBody([1.0, 1.0, 0.5]), [Gravity(1.0, [0.0, 0.0, 0.25], [0.0, 0.0, -9.81])])
        kw = dict(omega0=[0.1, 0.0, 10.0], attitude0=q0 / np.linalg.norm(q0), method="taylor", tol=1e-13)
        t_end = -2.0
    # what 'simulate --out r.zarr' does (the CLI's default chunk of 100 000), stopped after 2 of 3 chunks
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(model, (0.0, t_end, n), "r.zarr", progress=_Stop(200_000), **kw)
    assert not Path("r.zarr").exists()
    for name in ("r.zarr", ".r.zarr.partial/store.zarr", ".r.zarr.partial"):
        code, out, err = run(capsys, "info", name)
        assert code == 0, err
        assert out.startswith(
            f"{name}: unfinished run to r.zarr (interrupted): 2 of 3 chunks finished, 200000 of {n} samples"
        ), out
        grid = TimeGrid(0.0, t_end, n)
        assert f"samples 0 to 199999: t from 0 to {grid[199_999:200_000][0]:.6g}" in out
        assert ("Gravity(" in out) == (case == "top") and ".r.zarr.partial/store.zarr" in out
    cmd = _resume_line(out)
    argv = shlex.split(cmd)
    assert argv[:2] == ["eulerpoisson", "simulate"] and argv[-2:] == ["--out", "r.zarr"]
    # the command resumes the run (it would be refused with other arguments) and finishes it
    code, out, err = run(capsys, *argv[1:], "--json")
    assert code == 0, err
    ref = ep.solve(model, [0.0, t_end], **kw)
    state = json.loads(out)
    assert state["t"] == t_end
    np.testing.assert_allclose(state["omega"], ref.omega[-1], rtol=0, atol=1e-9)
    assert not Path(".r.zarr.partial").exists()
    code, out, err = run(capsys, "info", "r.zarr")
    assert code == 0 and f"samples     {n}," in out


def test_info_of_a_killed_simulate(capsys, tmp_path):
    """A real 'simulate' killed (SIGKILL) between chunks: info describes it, its resume command finishes it."""
    store = tmp_path / "k.zarr"
    argv = [
        EXE,
        "simulate",
        "--inertia",
        "1,2,3",
        "--omega",
        "1,0.1,0.5",
        "--t-end",
        "2000",
        "--samples",
        "4000000",
        "--method",
        "taylor",
        "--out",
        str(store),
    ]
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    done = tmp_path / ".k.zarr.partial" / "done"
    try:
        for _ in range(int(HANG_GUARD_S / 0.05)):  # polls: a guard against a hang, not a timing
            if (done.exists() and len(list(done.iterdir())) >= 2) or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert proc.poll() is None, "the run ended before it could be killed"
        code, out, err = run(capsys, "info", store)
        assert code == 0 and "being written now" in out and f"(process {proc.pid})" in out
        assert "resume      not now" in out
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=HANG_GUARD_S)
    code, out, err = run(capsys, "info", store)
    assert code == 0, err
    m = re.match(
        rf"{re.escape(str(store))}: unfinished run to {re.escape(str(store))} \(interrupted\): "
        r"(\d+) of 40 chunks finished, (\d+) of 4000000 samples",
        out,
    )
    assert m and int(m.group(1)) >= 2 and int(m.group(2)) == 100_000 * int(m.group(1)), out
    cmd = _resume_line(out)
    assert cmd == shlex.join(["eulerpoisson", *argv[1:]])  # the very command that was killed
    # (resuming 4e6 taylor samples takes a while: test_outputs_policy resumes such a run)


def test_info_of_runs_it_cannot_rebuild_or_that_never_started(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    # a library run with its own chunk: no 'simulate' command resumes it; info says what does
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(I123, (0.0, 10.0, 5_000), "lib.zarr", omega0=W0, chunk=1_000, progress=_Stop(3_000))
    code, out, err = run(capsys, "info", "lib.zarr")
    assert code == 0 and "3 of 5 chunks finished, 3000 of 5000 samples (60%)" in out
    assert "resume=True" in out and "resume      eulerpoisson simulate --" not in out
    # interrupted while the store was being created: nothing to resume
    work = tmp_path / ".new.zarr.partial"
    (work / "done").mkdir(parents=True)
    code, out, err = run(capsys, "info", "new.zarr")
    assert code == 0 and "stopped before its first chunk" in out
    # an unfinished sweep (its state is not a trajectory's): said so, not mistaken for a stream
    work = tmp_path / ".atlas.zarr.partial"
    (work / "done").mkdir(parents=True)
    (work / "state.json").write_text(json.dumps({"sweep": "a sweep's fingerprint", "version": 1}))
    for k in range(3):
        (work / "done" / f"{k:09d}").write_text("{}")
    code, out, err = run(capsys, "info", "atlas.zarr")
    assert code == 0 and "an unfinished sweep" in out and "3 chunk(s) finished" in out
    # a finished store and an unfinished run to replace it (simulate --overwrite)
    solve_to_file(I123, (0.0, 1.0, 11), "both.zarr", omega0=W0, progress=False)
    with pytest.raises(KeyboardInterrupt):
        solve_to_file(
            I123, (0.0, 10.0, 5_000), "both.zarr", omega0=W0, chunk=1_000, progress=_Stop(1_000), overwrite=True
        )
    code, out, err = run(capsys, "info", "both.zarr")
    assert code == 0 and "samples     11," in out and "an unfinished run to replace it" in out
    code, out, err = run(capsys, "info", ".both.zarr.partial/store.zarr")
    assert code == 0 and "1 of 5 chunks finished" in out
    # nothing at all is still a one-line error
    code, out, err = run(capsys, "info", "nothing.zarr")
    assert code == 2 and err.startswith("eulerpoisson: error: nothing.zarr: no such file") and err.count("\n") == 1


def test_column_starts_are_exactly_those_of_bins_of():
    """The column boundaries found by searchsorted and corrected are where bins_of changes, sample for sample."""
    from eulerpoisson.viz.decimate import MinMaxEnvelope

    rng = np.random.default_rng(0)
    for trial in range(1500):
        n = int(rng.integers(2, 3000))
        t0, t1 = sorted(rng.uniform(-1e3, 1e3, 2))
        if trial % 5 == 0:
            t1 = t0 + 1e-9  # columns narrower than the spacing of floats near t0
        nb = int(rng.integers(1, 500))
        env = MinMaxEnvelope(t0, t1, 1, nb)
        kind = trial % 4
        if kind == 0:
            t = rng.uniform(t0 - 1, t1 + 1, n)  # samples outside the range too
        elif kind == 1:
            t = np.linspace(t0, t1, n)
        elif kind == 2:
            t = np.round(rng.uniform(t0, t1, n), 1)  # many equal times
        else:
            t = t0 + (t1 - t0) * np.arange(n) / nb * 0.37  # times on the column edges
        t = np.sort(t)
        b = env.bins_of(t)
        np.testing.assert_array_equal(env._starts(t), np.concatenate([[0], np.flatnonzero(np.diff(b)) + 1]))
