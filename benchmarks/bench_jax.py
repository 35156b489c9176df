"""The exact motion in JAX (``eulerpoisson.jax.exact_motion``): throughput on the CPU and on a GPU.

Runs unchanged wherever JAX runs; the device is JAX's default (``JAX_PLATFORMS=cpu`` forces the
CPU). Rows (each recorded with the device's name):

* ``jax_exact_float64`` / ``jax_exact_float32``: ``E`` evaluations (bodies x times) of the exact
  motion, attitude and rates, in chunks of ``B`` bodies x ``T`` times through one jitted function
  (moments uniform in [1, 1.9], random directions of Omega0 and random initial attitudes: every
  regime mixed in each chunk); evaluations per second after compilation, and the compile time.
  The issue's goal on one H100-class GPU: ``E = 1e8`` at >= 1e9 /s in float64.
* ``numba_exact`` (CPU only): the same bodies through the package's compiled kernel
  (``solvers.exact.motion.exact_motion(..., compiled=True)``, principal frame, one thread), the
  CPU reference the JAX CPU row is compared with (goal: JAX within 3x).
* ``float32_error``: the float32 path's attitude error (rad) and relative rate error against the
  float64 path on the bodies of one chunk at t in [0, 100].

    .venv/bin/python benchmarks/bench_jax.py                   # CPU: 1e6 evaluations, one thread
    .venv/bin/python benchmarks/bench_jax.py --evaluations 1e8 # GPU (the issue's size)
    .venv/bin/python benchmarks/run.py --only jax              # through the benchmark runner

On a machine without a GPU the GPU rows are written as ``pending``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))


def _single_thread_cpu():
    """One XLA CPU thread (set before jax is imported) for the per-core comparison."""
    flags = os.environ.get("XLA_FLAGS", "")
    if "intra_op_parallelism_threads" not in flags:
        os.environ["XLA_FLAGS"] = (flags + " --xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1").strip()


def bodies(n: int, seed: int = 20261127):
    """Moments (n, 3) uniform in [1, 1.9], Omega0 (n, 3) of random direction and length 1.12, unit q0 (n, 4)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    mom = rng.uniform(1.0, 1.9, (n, 3))
    w = rng.standard_normal((n, 3))
    w *= 1.1224972160321824 / np.linalg.norm(w, axis=1, keepdims=True)
    q = rng.standard_normal((n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return mom, w, q


def _device():
    import jax

    d = jax.devices()[0]
    return {"platform": d.platform, "device": getattr(d, "device_kind", str(d)), "jax": jax.__version__}


def jax_rate(evaluations: int, dtype_name: str, *, chunk_bodies: int, chunk_times: int, t_end: float = 100.0):
    """Evaluations per second of the jitted exact motion over ``evaluations`` (body, time) pairs."""
    import jax
    import jax.numpy as jnp
    import numpy as np

    from eulerpoisson.jax import exact_motion

    dtype = jnp.float64 if dtype_name == "float64" else jnp.float32
    mom, w, q = bodies(chunk_bodies)
    t = np.linspace(0.0, t_end, chunk_times)
    with jax.enable_x64(True):

        @jax.jit
        def chunk(mom, q, w, t):
            qq, ww = exact_motion(mom[:, None, :], q[:, None, :], w[:, None, :], t[None, :], dtype=dtype)
            return qq, ww

        args = [jnp.asarray(a, dtype=dtype) for a in (mom, q, w, t)]
        t0 = time.perf_counter()
        out = chunk(*args)
        jax.block_until_ready(out)
        compile_s = time.perf_counter() - t0  # compilation + one chunk
        per_chunk = chunk_bodies * chunk_times
        n_chunks = max(1, int(round(evaluations / per_chunk)))
        # shift the times of each chunk so no result is reused
        t0 = time.perf_counter()
        for k in range(n_chunks):
            out = chunk(args[0], args[1], args[2], args[3] + k * 0.5)
        jax.block_until_ready(out)
        seconds = time.perf_counter() - t0
        qq = np.asarray(out[0])
    assert np.all(np.isfinite(qq)), "non-finite results"
    done = n_chunks * per_chunk
    return {
        "evaluations": done,
        "seconds": seconds,
        "rate_per_s": done / seconds,
        "compile_and_first_chunk_s": compile_s,
        "chunk": [chunk_bodies, chunk_times],
        "dtype": dtype_name,
    }


def numba_rate(evaluations: int, *, chunk_bodies: int, chunk_times: int, t_end: float = 100.0):
    """The package's compiled kernel on the same bodies (principal frame; attitude and momentum), one thread."""
    import numpy as np

    from eulerpoisson.solvers.exact.motion import exact_motion

    mom, w, _ = bodies(chunk_bodies)
    t = np.linspace(0.0, t_end, chunk_times)
    exact_motion(mom[:4], mom[:4] * w[:4], t[:4], compiled=True)  # load / compile
    n_chunks = max(1, int(round(evaluations / (chunk_bodies * chunk_times))))
    t0 = time.perf_counter()
    for k in range(n_chunks):
        exact_motion(mom, mom * w, t + k * 0.5, compiled=True)
    seconds = time.perf_counter() - t0
    done = n_chunks * chunk_bodies * chunk_times
    return {"evaluations": done, "seconds": seconds, "rate_per_s": done / seconds}


def float32_error(n: int = 2000, t_end: float = 100.0, samples: int = 11):
    """Attitude (rad) and relative rate errors of float32 against float64 on ``n`` bodies at ``samples`` times."""
    import jax
    import jax.numpy as jnp
    import numpy as np

    from eulerpoisson.jax import exact_motion

    mom, w, q = bodies(n, seed=7)
    t = np.linspace(0.0, t_end, samples)
    rows = {}
    with jax.enable_x64(True):
        q64, w64 = (np.asarray(a) for a in exact_motion(mom[:, None], q[:, None], w[:, None], t[None, :]))
        q32, w32 = (
            np.asarray(a, dtype=np.float64)
            for a in exact_motion(mom[:, None], q[:, None], w[:, None], t[None, :], dtype=jnp.float32)
        )
    dot = np.clip(np.abs(np.sum(q64 * q32, axis=-1)) / np.linalg.norm(q32, axis=-1), 0.0, 1.0)
    ang = 2.0 * np.arccos(dot)
    rel = np.linalg.norm(w32 - w64, axis=-1) / np.linalg.norm(w64, axis=-1)
    for k, tk in enumerate(t):
        if tk in (0.0, 10.0, 100.0) or k == samples - 1:
            rows[f"t={tk:g}"] = {"attitude_rad_max": float(ang[:, k].max()), "rate_rel_max": float(rel[:, k].max())}
    return rows


def agreement(n: int = 2000):
    """Largest attitude (rad) and relative rate differences of the JAX float64 path (on its device) against the
    NumPy closed form, over the standard cases and ``n`` random bodies at t in [0, 100]."""
    import jax
    import numpy as np

    import eulerpoisson as ep
    from eulerpoisson.jax import exact_motion
    from eulerpoisson.oracle import reference_cases

    def angle(a, b):
        w = np.abs(np.sum(a * b, axis=-1))
        v = a[..., :1] * b[..., 1:] - b[..., :1] * a[..., 1:] - np.cross(a[..., 1:], b[..., 1:])
        return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), w)

    att, rate, per_phase = 0.0, 0.0, 0.0
    with jax.enable_x64(True):
        for case in reference_cases().values():
            t = case.t[:: max(1, case.t.size // 200)]
            q, w = (
                np.asarray(a)
                for a in exact_motion(case.inertia_array, np.array(case.quaternion0), np.array(case.omega0), t)
            )
            ref = ep.solve(case.inertia_array, t, omega0=case.omega0, attitude0=case.quaternion0, method="exact")
            err = angle(q, ref.quaternion)
            att = max(att, float(err.max()))
            # the phase's conditioning: an ulp of a frequency is eps |Omega| t rad at time t
            phase = np.maximum(1.0, np.linalg.norm(case.omega0) * np.abs(t))
            per_phase = max(per_phase, float((err / phase).max()))
            scale = np.maximum(np.linalg.norm(ref.omega, axis=-1), 1e-300)
            rate = max(rate, float((np.linalg.norm(w - ref.omega, axis=-1) / scale).max()))
        mom, w0, q0 = bodies(n, seed=11)
        t = np.linspace(0.0, 100.0, 5)
        q, w = (np.asarray(a) for a in exact_motion(mom[:, None], q0[:, None], w0[:, None], t[None, :]))
    ref = ep.solve(ep.RigidBody(mom), t, omega0=w0, attitude0=q0, method="exact")
    rq, rw = np.asarray(ref.quaternion), np.asarray(ref.omega)
    att_r = float(angle(q, rq).max())
    rate_r = float((np.linalg.norm(w - rw, axis=-1) / np.linalg.norm(rw, axis=-1)).max())
    return {
        "standard_cases": {
            "attitude_rad_max": att,
            "rate_rel_max": rate,
            # the largest error per radian of phase |Omega| t (at least 1): the long runs' share of eps |Omega| t
            "attitude_rad_per_phase_rad_max": per_phase,
        },
        f"random_bodies_{n}": {"attitude_rad_max": att_r, "rate_rel_max": rate_r},
    }


def run(quick: bool = False, log=print, evaluations: float | None = None, rates_only: bool = False) -> dict:
    """All rows; ``evaluations`` defaults to 1e8 on a GPU and 1e6 on the CPU (1e4 with ``quick``);
    ``rates_only``: the two rates alone (not the agreement and float32 rows, which compile programs of their
    own: for a short lease of a GPU)."""
    import _common as C

    dev = _device()
    gpu = dev["platform"] == "gpu"
    E = int(evaluations or (1e4 if quick else (1e8 if gpu else 1e6)))
    B, T = (20_000, 500) if gpu else (1000, 100)
    if quick:
        B, T = 100, 10
    rows = {}
    for name in ("float64", "float32"):
        r = jax_rate(E, name, chunk_bodies=B, chunk_times=T)
        r.update(dev)
        rows[f"jax_exact_{name}"] = r
        log(
            f"jax exact {name} on {dev['device']}: {r['rate_per_s']:.3g} /s over {r['evaluations']:.3g} "
            f"(compile + first chunk {r['compile_and_first_chunk_s']:.2f} s)"
        )
    if not gpu:
        r = numba_rate(E, chunk_bodies=B, chunk_times=T)
        rows["numba_exact"] = r
        ratio = r["rate_per_s"] / rows["jax_exact_float64"]["rate_per_s"]
        rows["jax_cpu_slowdown_vs_numba"] = ratio
        log(f"numba exact kernel: {r['rate_per_s']:.3g} /s; JAX float64 on the CPU takes {ratio:.2f}x its time")
        rows["gpu"] = "pending: no GPU at hand (run this script on one: see benchmarks/README.md)"
    if rates_only:
        rows["agreement_float64_vs_numpy"] = rows["float32_error"] = "not measured in this run (--rates-only)"
        return C.envelope("jax", quick=quick, command=C.command_line(), machine=C.machine_info(), results=rows)
    rows["agreement_float64_vs_numpy"] = agreement(100 if quick else 2000)
    log(f"float64 vs the NumPy path: {rows['agreement_float64_vs_numpy']}")
    rows["float32_error"] = float32_error(200 if quick else 2000)
    log(f"float32 vs float64: {rows['float32_error']}")
    return C.envelope("jax", quick=quick, command=C.command_line(), machine=C.machine_info(), results=rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--evaluations", type=float, default=None, help="evaluations per row (default 1e8 GPU, 1e6 CPU)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument(
        "--rates-only", action="store_true", help="the two rates alone (no agreement or float32-error rows)"
    )
    ap.add_argument("--out", type=Path, default=HERE / "results", help="folder for jax.json (default: results/)")
    ap.add_argument("--name", default=None, help="file name (default jax.json on the CPU, jax_gpu.json on a GPU)")
    args = ap.parse_args(argv)
    import _common as C

    payload = run(args.quick, evaluations=args.evaluations, rates_only=args.rates_only)
    gpu = payload["results"]["jax_exact_float64"]["platform"] == "gpu"
    name = args.name or ("jax_gpu.json" if gpu else "jax.json")
    C.write_json(args.out / name, payload)
    print(f"wrote {args.out / name}")


if __name__ == "__main__":
    if os.environ.get("JAX_PLATFORMS", "") == "cpu" or "--cpu-one-thread" in sys.argv:
        _single_thread_cpu()
        sys.argv = [a for a in sys.argv if a != "--cpu-one-thread"]
    main()
