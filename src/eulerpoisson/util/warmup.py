"""Compile every numba kernel into its on-disk cache: ``eulerpoisson warmup`` (issue 15, cold start).

numba compiles a kernel on its first call and keeps the machine code in a
cache on disk (``cache=True``: the ``__pycache__`` folders next to the
sources, or ``$NUMBA_CACHE_DIR``); a later process loads it in well under a
second instead of compiling it again (seconds to half a minute per kernel,
a minute or two of CPU time for all of them; ``jobs`` processes at a time). :func:`warmup` runs every kernel group
once on a tiny problem, with the argument types the package passes in real
runs, so that the first real run of any method finds its kernels compiled.
``make demo`` runs it; after ``pip install`` run ``eulerpoisson warmup``
once.

Small problems need none of this: they are solved by the NumPy twins of the
kernels without importing numba (:func:`eulerpoisson.util.jit.use_compiled`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

__all__ = ["GROUPS", "WarmupGroup", "group_names", "warmup"]


@dataclass(frozen=True)
class WarmupGroup:
    """A group of kernels compiled together: a name, what it serves, the function that runs them once."""

    name: str
    title: str
    run: Callable[[], list]  # runs the kernels once; returns the dispatchers (for their cache statistics)


def _t(n=3):
    return np.linspace(0.0, 1.0, n)


def _exact():
    from ..solvers.exact import kernels as K
    from ..solvers.exact.motion import exact_constants, exact_motion

    inertia = np.array([[1.0, 2.0, 3.0]])
    M0 = np.array([[1.0, 0.2, 1.5]])
    exact_motion(inertia, M0, _t(), compiled=True)
    exact_constants(inertia, M0)
    return [K.motion_kernel, K.constants_kernel]


def _lagrange():
    from ..solvers.exact import lagrange_kernels as LK
    from ..solvers.exact.lagrange import lagrange_top_motion

    lagrange_top_motion(
        1.0,
        0.5,
        1.0,
        0.25,
        [0.0, 0.0, -9.81],
        [0.96592583, 0.25881905, 0.0, 0.0],
        [0.0, 0.0, 10.0],
        _t(),
        compiled=True,
    )
    return [LK.heavy_top_kernel]


def _taylor():
    from ..solvers.taylor import kernels as K
    from ..solvers.taylor.method import integrate_principal

    m = np.array([[1.0, 2.0, 3.0]] * K.LANES_MIN_BODIES)
    w = np.array([[1.0, 0.1, 0.5]] * K.LANES_MIN_BODIES)
    integrate_principal(m[:1], w[:1], _t(), lanes=False)  # one body after the other
    integrate_principal(m, w, _t(), lanes=True)  # SIMD lanes
    return [K.nb_integrate, K.nb_integrate_lanes]


def _taylor_torque():
    from ..solvers import solve
    from ..solvers.taylor import torque as TQ
    from ..torques import Gravity

    solve(
        [1.0, 2.0, 3.0], _t(), omega0=[1.0, 0.1, 0.5], torque=Gravity(1.0, [0.1, 0.0, 0.3]), method="taylor", workers=1
    )
    return [TQ.integrate_body]


def _symplectic():
    from ..solvers import solve
    from ..solvers.symplectic import kernels as K

    for scheme in ("splitting", "gauss2", "gauss4", "gauss6"):  # Gauss: one specialization per number of stages
        solve([1.0, 2.0, 3.0], _t(), omega0=[1.0, 0.1, 0.5], method="symplectic", scheme=scheme, workers=1)
    return [K.nb_splitting, K.nb_gauss]


def _exact_splitting():
    from ..solvers import solve
    from ..solvers.symplectic import exact_splitting as ES
    from ..torques import Gravity

    solve(
        [1.0, 2.0, 3.0],
        _t(),
        omega0=[1.0, 0.1, 0.5],
        torque=Gravity(1.0, [0.1, 0.0, 0.3]),
        method="symplectic",
        scheme="exact_splitting",
        workers=1,
    )
    return [ES.split_body]


def _fit():
    from ..estimation import variational as V

    V.propagate(np.diag([1.0, 2.0, 3.0]), np.array([1.0, 0.1, 0.5]), np.zeros((2, 3, 3)), _t())
    return [V.propagate_numba]


def _plots():
    from ..viz import plots as P

    n = 20_001  # the compiled chart search runs for long series only
    t = np.linspace(0.0, 1.0, n)
    q = np.zeros((n, 4))
    q[:, 0] = np.cos(t)
    q[:, 3] = np.sin(t)
    P.chart_bounds(q, 1.0, 2.0)
    return list(P.CHART_KERNEL)


#: the kernel groups, in the order they are compiled
GROUPS: tuple[WarmupGroup, ...] = (
    WarmupGroup("exact", "closed form of the free body (solve method='exact', exact_motion, exact_constants)", _exact),
    WarmupGroup("lagrange", "closed form of the Lagrange top (method='exact' under Gravity)", _lagrange),
    WarmupGroup("taylor", "Taylor series of the free body (method='taylor'), one body and SIMD lanes", _taylor),
    WarmupGroup(
        "taylor-torque", "Taylor series under polynomial torques (method='taylor' with a torque)", _taylor_torque
    ),
    WarmupGroup("symplectic", "splitting and Gauss collocation of the free body (method='symplectic')", _symplectic),
    WarmupGroup(
        "exact-splitting", "exact splitting under torques (method='symplectic' with a torque)", _exact_splitting
    ),
    WarmupGroup("fit", "variational equations of ep.fit (eulerpoisson fit)", _fit),
    WarmupGroup("plots", "chart search of the Gibbs-vector plot of long runs", _plots),
)


def group_names() -> list[str]:
    """The names of the kernel groups."""
    return [g.name for g in GROUPS]


def _cache_counts(dispatchers) -> tuple[int, int]:
    """(signatures loaded from the cache, signatures compiled) of numba dispatchers."""
    hits = misses = 0
    for d in dispatchers:
        stats = getattr(d, "stats", None)
        if stats is None:
            continue
        hits += sum(stats.cache_hits.values())
        misses += sum(stats.cache_misses.values())
    return hits, misses


def _run_group(group: WarmupGroup) -> tuple[float, str, list[str]]:
    """Run one group: (seconds, how its kernels were made, their cache folders)."""
    start = time.perf_counter()
    dispatchers = group.run()
    dt = time.perf_counter() - start
    hits, misses = _cache_counts(dispatchers)
    how = "compiled" if misses else ("loaded from the cache" if hits else "ready")
    return dt, how, [str(d.stats.cache_path) for d in dispatchers if getattr(d, "stats", None) is not None]


#: the child process of a group when several run at once (``jobs > 1``): one JSON line
_CHILD = """
import json, sys
from eulerpoisson.util import jit, warmup as W
jit.activate()
dt, how, paths = W._run_group(next(g for g in W.GROUPS if g.name == sys.argv[1]))
print(json.dumps({"seconds": dt, "how": how, "paths": paths}))
"""


def _in_processes(groups, jobs, say):
    """Run the groups in ``jobs`` child processes at a time (numba compiles on one core per process)."""
    import json
    import subprocess
    import sys
    from concurrent.futures import ThreadPoolExecutor, as_completed

    def child(group):
        start = time.perf_counter()
        res = subprocess.run([sys.executable, "-c", _CHILD, group.name], capture_output=True, text=True)
        if res.returncode != 0:
            lines = [ln for ln in res.stderr.strip().splitlines() if ln.strip()]
            raise RuntimeError(
                f"warm-up of the kernel group {group.name!r} failed: "
                f"{lines[-1] if lines else 'exit status ' + str(res.returncode)}"
            )
        out = json.loads(res.stdout.strip().splitlines()[-1])
        return time.perf_counter() - start, out["how"], out["paths"]

    results = {}
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(child, g): g for g in groups}
        for f in as_completed(futures):
            g = futures[f]
            try:
                results[g.name] = f.result()
            except Exception as exc:  # noqa: BLE001 - reported, the other groups go on
                results[g.name] = exc
                say(f"  {g.name:<16s} FAILED: {exc}")
                continue
            dt, how, _ = results[g.name]
            say(f"  {g.name:<16s} {how:<22s} {dt:6.1f} s   {g.title}")
    return results


def warmup(
    only: str | Iterable[str] | None = None, *, say: Callable[[str], None] = print, jobs: int = 1
) -> dict[str, float]:
    """Compile (or load from the cache) the kernels of the groups ``only`` (default: every group).

    Parameters
    ----------
    only : iterable of str, optional
        Names from :data:`GROUPS` (:func:`group_names`).
    say : callable
        Receives one progress line per group, then the total.
    jobs : int
        Groups compiled at the same time, each in a process of its own (numba compiles on one core);
        1 (default): one after the other in this process.

    Returns
    -------
    dict
        Seconds per group (empty when numba is not in use).

    Raises
    ------
    InvalidInputError
        An unknown group name (the message lists them).
    EulerPoissonError
        Some group failed (after every other group ran; its progress line says why).
    """
    from ..errors import InvalidInputError
    from . import jit

    names = group_names()
    chosen = list(names) if only is None else list(dict.fromkeys(only))
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise InvalidInputError(
            f"unknown kernel group(s) {', '.join(map(repr, unknown))}; the groups are: {', '.join(names)}"
        )
    if not jit.USE_NUMBA:
        say(
            "numba is not in use (not installed, or EULERPOISSON_NO_NUMBA=1): nothing to compile; "
            "the NumPy implementations run"
        )
        return {}
    t0 = time.perf_counter()
    groups = [g for g in GROUPS if g.name in chosen]
    jobs = max(1, min(int(jobs), len(groups)))
    times: dict[str, float] = {}
    paths: list[str] = []
    failed: list[str] = []
    if jobs > 1:
        say(f"{len(groups)} kernel groups, {jobs} at a time (one process each)")
        for name, res in _in_processes(groups, jobs, say).items():
            if isinstance(res, Exception):
                failed.append(name)
                continue
            times[name] = res[0]
            paths += res[2]
    else:
        jit.activate()
        say(f"numba imported in {time.perf_counter() - t0:.1f} s")
        for group in groups:
            try:
                dt, how, where = _run_group(group)
            except Exception as exc:  # noqa: BLE001 - reported, the other groups go on
                failed.append(group.name)
                first = next((ln for ln in str(exc).splitlines() if ln.strip()), type(exc).__name__)
                say(f"  {group.name:<16s} FAILED: {type(exc).__name__}: {first}")
                continue
            times[group.name] = dt
            paths += where
            say(f"  {group.name:<16s} {how:<22s} {dt:6.1f} s   {group.title}")
    total = time.perf_counter() - t0
    say(f"{len(times)} kernel group(s) ready in {total:.1f} s" + (f" (cache: {paths[0]}, ...)" if paths else ""))
    if failed:
        from ..errors import EulerPoissonError

        raise EulerPoissonError(f"the warm-up of the kernel group(s) {', '.join(failed)} failed (see above)")
    return times
