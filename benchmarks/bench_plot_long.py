"""Pictures and files of long runs (issue 12, items 5, 7, 10): a stand-alone measurement, not part of ``make bench``.

    .venv/bin/python benchmarks/bench_plot_long.py [--samples 10000000] [--dir /tmp/plot_long] [--gif]
        [--kinds omega,invariants] [--repeat 3]

Streams a free body (I = 1, 2, 3, Omega0 = (1, 0.1, 0.5), t in [0, 1e5])
with the closed form to a Zarr store (reused when it is already there), then
times ``info`` (metadata and the first/last samples), every ``plot --kind``
on the store (decimated: min/max per pixel column of the time series, the
3-D pictures from evenly strided samples of at most 1e7 samples read), each
in a fresh process so that the peak resident memory is the picture's own, and
with ``--gif`` a 600-frame GIF (30 fps, 20 s) of the tennis racket. Prints a
table of the wall time, the CPU time (user + system, all threads: the chunks
are decoded in parallel, so it exceeds the wall time on several cores) and
the peak resident memory; with ``--repeat N`` the fastest of N runs (a shared
machine is noisy). Nothing is written under ``benchmarks/results``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
PY = sys.executable

_ONE = r"""
import resource, sys, time
t0 = time.perf_counter()
import eulerpoisson as ep
from eulerpoisson.viz import plots
t1 = time.perf_counter()
r0 = resource.getrusage(resource.RUSAGE_SELF)
lz = ep.Trajectory.open(sys.argv[1])
plots.plot(lz, sys.argv[2], out=sys.argv[3])
t2 = time.perf_counter()
r = resource.getrusage(resource.RUSAGE_SELF)
cpu = r.ru_utime + r.ru_stime - r0.ru_utime - r0.ru_stime
print(f"{t2 - t1:.2f} {r.ru_maxrss / 1024:.0f} {cpu:.2f}")
"""

_GIF = r"""
import resource, sys, time
import numpy as np
import eulerpoisson as ep
from eulerpoisson.viz.animate import animate
tr = ep.solve([3, 5, 8], np.linspace(0, 200, 4001), omega0=[0, 0.4, 0.00125])
t0 = time.perf_counter()
animate(tr, sys.argv[1], fps=30, duration=20)
print(f"{time.perf_counter() - t0:.2f} {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}")
"""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--dir", default="/tmp/eulerpoisson_plot_long")
    ap.add_argument("--gif", action="store_true", help="also time a 600-frame GIF")
    ap.add_argument(
        "--kinds",
        default="omega,invariants,polhode,gibbs,attitude,apex",
        help="comma-separated picture kinds to time (default: all)",
    )
    ap.add_argument("--repeat", type=int, default=1, help="runs of each picture; the fastest is shown")
    args = ap.parse_args(argv)
    d = Path(args.dir)
    d.mkdir(parents=True, exist_ok=True)
    store = d / f"free_{args.samples}.zarr"
    if not store.exists():
        from eulerpoisson.io.stream import solve_to_file

        t0 = time.perf_counter()
        solve_to_file([1.0, 2.0, 3.0], (0.0, 1e5, args.samples), store, omega0=[1.0, 0.1, 0.5], progress=False)
        print(f"store of {args.samples:,} samples written in {time.perf_counter() - t0:.1f} s: {store}")
    rows = []
    t0 = time.perf_counter()
    subprocess.run([PY, "-m", "eulerpoisson", "info", str(store)], check=True, capture_output=True) if (
        HERE.parent / "src" / "eulerpoisson" / "__main__.py"
    ).exists() else subprocess.run(
        [str(Path(PY).parent / "eulerpoisson"), "info", str(store)], check=True, capture_output=True
    )
    rows.append(("info (whole command)", time.perf_counter() - t0, None, None))
    for kind in [k for k in args.kinds.split(",") if k]:
        best = None
        for _ in range(max(1, args.repeat)):
            out = subprocess.run(
                [PY, "-c", _ONE, str(store), kind, str(d / f"{kind}.png")], check=True, capture_output=True, text=True
            ).stdout.split()
            if best is None or float(out[0]) < best[0]:
                best = (float(out[0]), float(out[1]), float(out[2]))
        rows.append((f"plot --kind {kind}", best[0], best[1], best[2]))
    if args.gif:
        out = subprocess.run(
            [PY, "-c", _GIF, str(d / "racket.gif")], check=True, capture_output=True, text=True
        ).stdout.split()
        rows.append(("GIF, 600 frames 640x480", float(out[0]), float(out[1]), None))
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        cpus = os.cpu_count()
    print(f"\n{args.samples:,} samples ({store}), {cpus} CPUs")
    print(f"{'what':28s} {'seconds':>8s} {'CPU s':>7s} {'peak RSS MB':>12s}")
    for what, sec, mb, cpu in rows:
        print(f"{what:28s} {sec:8.2f} {'' if cpu is None else f'{cpu:7.2f}'} {'' if mb is None else f'{mb:12.0f}'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
