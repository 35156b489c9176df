r"""Batches of bodies solved in threads: ``solve(..., workers=)`` (private to the driver).

The compiled kernels of the methods release the GIL (numba ``nogil=True``),
so threads of one process solve the chunks of a batch at the same time. This
module is the one place where a batch is split, solved in threads and put
back together; the methods know nothing of it beyond two hooks of
:class:`~eulerpoisson.solvers.registry.Method` (:meth:`~.Method.for_batch`
and :meth:`~.Method.work_estimate`) and two class attributes
(:attr:`~.Method.threads`, :attr:`~.Method.additive_stats`).

How many threads (:func:`resolve_workers`)
    ``workers`` of :func:`~eulerpoisson.solve`, an integer >= 1 (1: the
    calling thread only, no pool); when None (the default) the environment
    variable ``EULERPOISSON_WORKERS`` (an integer >= 1), else every core
    this process may use (``os.process_cpu_count()`` on Python 3.13+, the
    CPU affinity mask before, so ``taskset`` and container CPU sets are
    respected).

When (:func:`plan_chunks`)
    A batch stays on the calling thread when it has fewer than
    :data:`MIN_BODIES` bodies or when the method estimates less than
    :data:`MIN_WORK` seconds of work (:meth:`~.Method.work_estimate`):
    handing chunks to threads costs some 0.1 ms, and the Python part of a
    method (its set-up, small NumPy calls) runs one thread at a time, so
    small problems (one body at many times, a few hundred bodies at one
    time) gain nothing. Methods whose bodies are stepped in Python (``rk``:
    scipy's ``solve_ivp``; ``taylor`` in long double, mpmath or without
    numba) set :attr:`~.Method.threads` to False and always run on one
    thread. A solve started from a thread that is solving a chunk (a
    callable of the user's, say) stays on that thread.

How (:func:`solve_batch`)
    The method makes its batch-wide choices once, on the whole problem
    (:meth:`~.Method.for_batch`: the default step of ``symplectic``, taken
    from the fastest body; the SIMD-lane or one-body kernel of ``taylor``,
    chosen by the size of the batch). The flattened batch is cut into
    contiguous chunks of whole multiples of :data:`CHUNK_ALIGN` bodies (the
    lane groups of the kernels: 16 bodies for ``taylor`` and the
    splittings, 8 for Gauss, so that every lane group holds the same bodies
    whatever the chunks), from one per thread up to :data:`CHUNKS_PER_WORKER`
    per thread while each keeps :data:`MIN_CHUNK_WORK` seconds of work
    (bodies differ in cost, e.g. fast spinners take more Taylor steps, and
    smaller chunks keep every thread busy to the end). Every chunk is a
    :class:`~eulerpoisson.solvers.problem.Problem` of its own (the same
    bodies, torque parameters and initial states, sliced, never
    recomputed). The calling thread and ``workers - 1`` threads of a pool
    kept for the process (a :class:`~concurrent.futures.ThreadPoolExecutor`,
    grown on demand, started afresh in a forked child; the caller's context
    variables, e.g. NumPy's ``errstate``, copied in) take the chunks one
    after the other until none is left. Each thread then does to its chunk
    what the :class:`~eulerpoisson.trajectory.Trajectory` does to a
    solver's output (checks, normalization, sign continuity in time: body
    by body, so the same bits) and copies it into the batch's arrays, so
    that the calling thread is left with almost nothing to do alone (at
    10^6 samples the trajectory's work is about 15 % of an exact solve:
    done once on the calling thread, it would cap the speed-up at about 6).

Same bits for any number of workers
    A body's result depends only on its own data: the kernels treat the
    bodies independently (a converged SIMD lane is frozen while the others
    iterate, a finished one takes the next body), and every choice that
    depends on the batch as a whole is made once by :meth:`~.Method.for_batch`.
    So the quaternions and angular velocities are identical, bit for bit,
    for every ``workers`` (``tests/test_workers.py`` checks it for
    ``exact``, ``taylor`` and ``symplectic``, free and under torque).

Errors
    When a chunk fails (in the method or in the trajectory's checks), no
    further chunk is taken and, once the running ones are done, the whole
    batch is solved again on the calling thread: the error raised (its
    type, its message, the body it names) is exactly the one ``workers=1``
    raises. Most errors are found before any work; for the others (a Taylor
    ``max_steps`` exhausted) this costs up to one single-threaded solve
    more. A ``KeyboardInterrupt`` stops the taking of chunks and is raised
    at once (the chunks being solved finish in the background).

Statistics
    ``wall_time`` (set by :func:`~eulerpoisson.solve`) is the elapsed time
    from the start of the solution to the finished trajectory, whatever the
    threads. The counters over bodies
    (:attr:`~.Method.additive_stats`: ``evaluations``, Taylor's ``steps``
    and ``chart_changes``, ...) are summed over the chunks; every other
    number is the largest over the chunks (``steps_max``, ``iterations``,
    the symplectic ``steps``, which every body shares, ...); other values
    (names, flags) are the first chunk's. ``threads``: the number of threads
    that solved the batch (1 when it stayed on the calling thread).
"""

from __future__ import annotations

import contextvars
import itertools
import math
import numbers
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import InvalidInputError
from ..model.equations import Model
from ..trajectory import stored_attitudes
from ..util.env import env_value
from .problem import Problem
from .registry import Method, MethodResult

__all__ = [
    "ENV_WORKERS",
    "MIN_BODIES",
    "MIN_WORK",
    "CHUNK_ALIGN",
    "CHUNKS_PER_WORKER",
    "available_cores",
    "check_workers",
    "resolve_workers",
    "plan_chunks",
    "take",
    "solve_batch",
]

#: environment variable giving the default number of threads (an integer >= 1)
ENV_WORKERS = "EULERPOISSON_WORKERS"
#: smallest batch (bodies) solved in threads
MIN_BODIES = 32
#: smallest estimated work (seconds on one core, :meth:`Method.work_estimate`) solved in threads
MIN_WORK = 0.01
#: smallest estimated work of one chunk (seconds): more chunks than threads only above it
MIN_CHUNK_WORK = 0.005
#: chunks hold whole multiples of this many bodies (the SIMD lane groups of the kernels: 16 and 8)
CHUNK_ALIGN = 16
#: at most this many chunks per thread (load balance)
CHUNKS_PER_WORKER = 8


def available_cores() -> int:
    """The number of cores this process may use (its CPU affinity), at least 1."""
    count = getattr(os, "process_cpu_count", None)  # Python 3.13+
    if count is not None:
        n = count()
    else:
        try:
            n = len(os.sched_getaffinity(0))
        except (AttributeError, OSError):  # pragma: no cover - not Linux
            n = os.cpu_count()
    return max(1, int(n or 1))


def check_workers(workers: object, name: str = "workers") -> int | None:
    """Validate a number of threads: an integer >= 1, -1 for every core (as scipy spells it), or None (the default).

    Raises
    ------
    TypeError
        Not an integer (a bool, a float such as 2.0 or 2.5, a string).
    InvalidInputError
        An integer below 1 other than -1.

    Examples
    --------
    >>> from eulerpoisson.solvers.parallel import check_workers, resolve_workers, available_cores
    >>> check_workers(2), check_workers(None), resolve_workers(-1) == available_cores()
    (2, None, True)
    """
    if workers is None:
        return None
    if isinstance(workers, (bool, np.bool_)) or not isinstance(workers, numbers.Integral):
        raise TypeError(
            f"{name} must be a whole number of threads >= 1, -1 or None for every core; "
            f"got {type(workers).__name__} {workers!r}"
        )
    if workers < 1 and workers != -1:
        raise InvalidInputError(f"{name} must be >= 1 (1: one thread), or -1 or None for every core; got {workers!r}")
    return int(workers)


def resolve_workers(workers: object = None) -> int:
    """The number of threads to use: ``workers``, else ``$EULERPOISSON_WORKERS``, else every core.

    Raises
    ------
    TypeError, InvalidInputError
        An invalid ``workers`` (see :func:`check_workers`) or environment variable.
    """
    n = check_workers(workers)
    if n is not None:
        return available_cores() if n == -1 else n
    env = (env_value(ENV_WORKERS) or "").strip()
    if env:
        try:
            value = int(env)
        except ValueError:
            value = None
        if value is None or (value < 1 and value != -1):
            raise InvalidInputError(
                f"the environment variable {ENV_WORKERS} must be a whole number of threads "
                f">= 1 (-1 or unset: every core); got {env!r}"
            )
        return available_cores() if value == -1 else value
    return available_cores()


def plan_chunks(n_bodies: int, workers: int, work: float) -> list[tuple[int, int]] | None:
    """Bounds ``(start, stop)`` of the chunks of a flattened batch, or None to stay on one thread.

    None when ``workers`` is 1, the batch has fewer than :data:`MIN_BODIES`
    bodies or ``work`` (estimated seconds on one core) is below
    :data:`MIN_WORK`. Otherwise contiguous chunks of whole multiples of
    :data:`CHUNK_ALIGN` bodies (the last one takes the rest), between
    ``workers`` and ``CHUNKS_PER_WORKER * workers`` of them while each keeps
    about :data:`MIN_CHUNK_WORK` seconds of work, as even as the alignment allows.
    """
    if workers <= 1 or n_bodies < max(MIN_BODIES, 2) or not work >= MIN_WORK:
        return None
    units = -(-n_bodies // CHUNK_ALIGN)
    by_work = int(min(work, 1e6) / MIN_CHUNK_WORK) if MIN_CHUNK_WORK > 0 else units
    n = min(units, CHUNKS_PER_WORKER * workers, max(workers, by_work))
    if n < 2:
        return None
    cuts = [min(n_bodies, (i * units // n) * CHUNK_ALIGN) for i in range(n + 1)]
    return [(a, b) for a, b in zip(cuts[:-1], cuts[1:]) if b > a]


# ---------------------------------------------------------------------------
# a chunk of a problem
# ---------------------------------------------------------------------------
def _sub_index(shape: tuple[int, ...], index: tuple) -> tuple:
    """Index into an array of batch ``shape`` (right-aligned, broadcasting) from an index of the full batch."""
    k = len(shape)
    tail = index[len(index) - k :] if k else ()
    return tuple(
        (slice(None) if isinstance(i, slice) else np.zeros_like(i)) if n == 1 else i for i, n in zip(tail, shape)
    )


def take(problem: Problem, start: int, stop: int) -> Problem:
    """Bodies ``start:stop`` of the flattened batch of ``problem``, as a problem of batch shape ``(stop - start,)``.

    Everything is sliced from ``problem``, never recomputed (the principal
    moments and axes of the bodies are those of the whole batch); shared
    parameters (a single body, a torque without batch axes) stay shared.
    """
    shape = problem.batch_shape
    index: tuple
    if len(shape) == 1:
        index = (slice(start, stop),)
    else:
        index = np.unravel_index(np.arange(start, stop), shape)
    model = problem.model
    body = model.body
    if body.batch_shape:
        body = body[_sub_index(body.batch_shape, index)]
    torques = [tq[_sub_index(tq.batch_shape, index)] if tq.batch_shape else tq for tq in model.torques]
    extended = {k: v.reshape((-1,) + v.shape[len(shape) :])[start:stop] for k, v in problem.extended.items()}
    return Problem(
        model=Model(body, torques),
        q0=problem.q0.reshape(-1, 4)[start:stop],
        omega0=problem.omega0.reshape(-1, 3)[start:stop],
        t=problem.t,
        extended=extended,
    )


def _merge_stats(method: Method, parts: list[dict]) -> dict:
    """The statistics of a batch from those of its chunks (see the module docstring)."""
    out: dict = {}
    for part in parts:
        for key, val in part.items():
            if key not in out:
                out[key] = val
            elif isinstance(val, numbers.Number) and not isinstance(val, bool):
                out[key] = out[key] + val if key in method.additive_stats else max(out[key], val)
    return out


# one pool for the process, grown on demand: starting threads at every call would cost about 0.1 ms each
_POOL: ThreadPoolExecutor | None = None
_POOL_SIZE = 0
_POOL_LOCK = threading.Lock()
#: ``running``: this thread is solving a chunk (a solve started from there stays on the thread)
_STATE = threading.local()


def _pool(n: int) -> ThreadPoolExecutor:
    """The process's pool, with at least ``n`` threads."""
    global _POOL, _POOL_SIZE
    with _POOL_LOCK:
        if _POOL is None or _POOL_SIZE < n:
            old = _POOL
            _POOL = ThreadPoolExecutor(max_workers=n, thread_name_prefix="eulerpoisson")
            _POOL_SIZE = n
            if old is not None:
                old.shutdown(wait=False)  # its queued work still runs; its threads then end
        return _POOL


def _forget_pool() -> None:
    """In a forked child the pool's threads do not exist: start afresh."""
    global _POOL, _POOL_SIZE, _POOL_LOCK
    _POOL, _POOL_SIZE, _POOL_LOCK = None, 0, threading.Lock()


if hasattr(os, "register_at_fork"):  # pragma: no branch - POSIX
    os.register_at_fork(after_in_child=_forget_pool)


def _run_threads(method: Method, problem: Problem, bounds: list[tuple[int, int]], n_threads: int) -> MethodResult:
    """Solve the chunks ``bounds`` of ``problem`` on ``n_threads`` threads: the calling one and pool threads.

    Each thread takes the next chunk not taken until none is left. It does
    to its chunk what the trajectory does to a solver's output (checks,
    normalization, sign continuity) and copies it into the batch's arrays
    itself (NumPy releases the GIL for that), so nothing but the statistics
    is left to join. The first error stops the taking of chunks and is
    raised once every thread is done.
    """
    shape = problem.batch_shape
    B = int(np.prod(shape, dtype=int))
    T = problem.t.shape[0]
    q = np.empty((B, T, 4))
    w = np.empty((B, T, 3))
    stats: list = [None] * len(bounds)
    taken = itertools.count()  # next() is atomic under the GIL
    failed: list = []

    def solve_chunk(a, b):
        res = method.run(take(problem, a, b))
        qc = res.q.reshape(b - a, T, 4)
        wc = res.omega.reshape(b - a, T, 3)
        q[a:b] = stored_attitudes(problem.t, qc, wc)
        w[a:b] = wc
        return res.stats

    def runner():
        before = getattr(_STATE, "running", False)
        _STATE.running = True
        try:
            while not failed:
                i = next(taken)
                if i >= len(bounds):
                    return
                try:
                    stats[i] = solve_chunk(*bounds[i])
                except Exception as exc:  # handed to the calling thread
                    failed.append(exc)
        finally:
            _STATE.running = before

    futures = []
    if n_threads > 1:
        pool = _pool(n_threads - 1)
        futures = [pool.submit(contextvars.copy_context().run, runner) for _ in range(n_threads - 1)]
    try:
        runner()
        for f in futures:
            if not f.cancel():  # a runner not started yet (its thread busy elsewhere) is not waited for
                f.result()
    except BaseException:  # KeyboardInterrupt: stop the others taking chunks, do not wait for them
        failed.append(None)
        raise
    if failed:
        raise failed[0]
    return MethodResult(
        q=q.reshape(shape + (T, 4)), omega=w.reshape(shape + (T, 3)), stats=_merge_stats(method, stats), prepared=True
    )


def solve_batch(method: Method, problem: Problem, workers: int | None = None) -> MethodResult:
    """Solve ``problem`` with ``method``, in threads over chunks of bodies when that pays off.

    ``workers``: as :func:`resolve_workers`. The result's ``stats`` get
    ``threads`` (the number of threads that ran). See the module docstring.
    """
    n_workers = resolve_workers(workers)
    B = math.prod(problem.batch_shape)
    bounds = None
    if method.threads and n_workers > 1 and B >= MIN_BODIES and not getattr(_STATE, "running", False):
        bounds = plan_chunks(B, n_workers, method.work_estimate(problem))
    if bounds is None:
        res = method.run(problem)
        res.stats = {**res.stats, "threads": 1}
        return res
    planned = method.for_batch(problem)
    n_threads = min(n_workers, len(bounds))
    try:
        res = _run_threads(planned, problem, bounds, n_threads)
    except Exception:
        # the error of workers=1, exactly (type, message, the body it names)
        res = method.run(problem)  # normally raises; if not (it should not happen), its result is as good
        res.stats = {**res.stats, "threads": 1}
        return res
    res.stats["threads"] = n_threads
    return res
