r"""The one solve engine: every route to a solution goes through :func:`iter_solve`.

:func:`~eulerpoisson.solve` (memory), the NetCDF and Zarr writers
(:func:`~eulerpoisson.io.stream.solve_to_file`, ``eulerpoisson simulate
--out``), the command line's ``--json`` without a file and the sweeps are
*sinks* fed by one generator. It validates the problem once (the method and
its options, the bodies, the initial state, the torques), makes the method's
batch-wide choices once for the whole run (:meth:`~.Method.for_batch`: the
compiled kernels or NumPy, a default step, the SIMD-lane kernel), and then
yields the solution one *segment* of output times after the other.

Segments
    The output times ``t[0:n]`` are cut into segments by :func:`plan_segments`,
    a function of the run alone (the number of output times, the method, the
    rate of the fastest body and the last time), never of the route: the
    same run is cut the same way in memory, in a NetCDF file, in a Zarr store
    (whatever its own storage chunk) and in a sweep, so every route gives the
    same bits. A closed-form method (``order is None``: ``exact``) evaluates
    every segment from the initial state at :math:`t = 0`; a stepping method
    continues each segment from the last state of the previous one
    (:func:`continue_from`: the model is autonomous, or its time-dependent
    torques are shifted, :meth:`~eulerpoisson.Model.shifted`). A run of at
    most :data:`SEGMENT` output times that turns its fastest body less than
    :data:`SEGMENT_TURNS` radians is one segment: then a stepping method
    integrates it in one piece, exactly as before segments existed.

Quaternion signs
    :math:`q` and :math:`-q` are the same attitude; the engine makes the
    sign continuous in time within a segment (as a
    :class:`~eulerpoisson.trajectory.Trajectory` does) and across the
    boundaries of segments, and continues a stepping method from the stored
    (sign-continuous) state, so a resumed run continues from what it reads
    back, bit for bit.

Examples
--------
>>> import numpy as np
>>> from eulerpoisson.solvers.engine import iter_solve
>>> pieces = list(iter_solve([1.0, 2.0, 3.0], np.linspace(0.0, 10.0, 11), omega0=[1.0, 0.1, 0.5]))
>>> [(p.start, p.stop) for p in pieces]
[(0, 11)]
>>> pieces[0].trajectory.omega.shape
(11, 3)

References
----------
Paper eq. 1.4-1.5 (the equations solved) and 1.23.1 (the solution as the
exponential of the Hamiltonian vector field, which a segment continues).
"""

from __future__ import annotations

import math
import numbers
import time as _time
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidInputError
from ..model.equations import Model
from ..model.torque_base import check_torque_scales
from ..trajectory import Trajectory
from .parallel import check_workers, solve_batch
from .problem import Problem, make_problem
from .registry import Method, MethodOptions, check_supported, get_method

if TYPE_CHECKING:
    from ..attitude.core import AttitudeLike
    from ..model.body import RigidBody
    from ..model.torques import TorqueLike

__all__ = [
    "SEGMENT",
    "SEGMENT_TURNS",
    "TimeGrid",
    "as_time_source",
    "read_times",
    "Segment",
    "SolveRun",
    "plan_segments",
    "iter_solve",
    "collect",
    "continue_from",
    "configure_method",
    "default_method",
    "evaluate",
]

#: most output times in one segment (a segment in memory with the derived variables of a file takes about
#: 1.3 kB a sample: some 65 MB)
SEGMENT = 50_000

#: most (body, output time) samples in one segment: a batch of many bodies is cut into shorter segments, so a
#: segment's memory stays bounded
SEGMENT_SAMPLES = 500_000

#: a stepping method's segment turns its fastest body by at most about this many radians (long runs with few
#: output times are cut too, so that they show progress and a resumed run loses little)
SEGMENT_TURNS = 8 * math.pi * 100_000

#: most segments a run is cut into for its length in radians alone
MAX_TURN_SEGMENTS = 50


# ---------------------------------------------------------------------------
# output times
# ---------------------------------------------------------------------------
class TimeGrid:
    r"""``n`` equally spaced times from ``t0`` to ``t1`` (inclusive), generated on demand.

    Behaves as a read-only 1-D float64 sequence: ``len(grid)`` and
    ``grid[a:b]`` (an ndarray computed on the fly, equal bit for bit to
    ``numpy.linspace(t0, t1, n)[a:b]``). Nothing of size ``n`` is ever
    allocated.

    Parameters
    ----------
    t0, t1 : float
        First and last time (finite; ``t1 < t0`` runs backwards).
    n : int
        Number of times, >= 1.

    Raises
    ------
    InvalidInputError
        Non-finite ``t0``/``t1`` or ``n < 1``.
    TypeError
        Non-numeric arguments or a non-integer ``n``.

    Examples
    --------
    >>> g = TimeGrid(0.0, 1.0, 5)
    >>> len(g), g[1:3].tolist()
    (5, [0.25, 0.5])
    """

    def __init__(self, t0, t1, n) -> None:  # float, float, int: anything else is refused below
        for name, v in (("t0", t0), ("t1", t1)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise TypeError(f"t: {name} must be a real number, got {type(v).__name__} {v!r}")
            if not np.isfinite(v):  # type: ignore[call-overload]  # mypy types no numbers.Real as a float
                raise InvalidInputError(f"t: {name} must be finite, got {v!r}")
        if isinstance(n, bool) or not isinstance(n, numbers.Integral):
            if isinstance(n, numbers.Real) and float(n) == int(n):  # type: ignore[call-overload]
                n = int(n)  # type: ignore[call-overload]
            else:
                raise TypeError(f"t: the number of samples n must be an integer, got {n!r}")
        if n < 1:
            raise InvalidInputError(f"t: the number of samples n must be >= 1, got {n}")
        self.t0, self.t1, self.n = float(t0), float(t1), int(n)
        div = self.n - 1
        self._delta = self.t1 - self.t0
        self._step = self._delta / div if div > 0 else np.nan

    def __len__(self) -> int:
        return self.n

    @property
    def shape(self) -> tuple[int]:
        return (self.n,)

    @overload
    def __getitem__(self, idx: slice) -> NDArray[np.float64]: ...
    @overload
    def __getitem__(self, idx: int | np.integer) -> float: ...
    @overload
    def __getitem__(self, idx: ArrayLike) -> float | NDArray[np.float64]: ...
    def __getitem__(self, idx: int | slice | ArrayLike) -> float | NDArray[np.float64]:
        if isinstance(idx, slice):
            a, b, s = idx.indices(self.n)
            i = np.arange(a, b, s, dtype=np.float64)
        else:
            i = np.asarray(idx)
            if not np.issubdtype(i.dtype, np.integer):
                raise TypeError(f"TimeGrid indices must be integers or slices, got {idx!r}")
            i = np.where(i < 0, i + self.n, i)
            if np.any((i < 0) | (i >= self.n)):
                raise IndexError(f"TimeGrid index out of range for n = {self.n}")
            i = i.astype(np.float64)
        if self.n == 1:
            y = i * self._delta
        elif self._step == 0:  # denormal step, as numpy.linspace
            y = i / (self.n - 1) * self._delta
        else:
            y = i * self._step
        y = y + self.t0
        if self.n > 1:
            y = np.where(i == self.n - 1, self.t1, y)
        return y if y.ndim else float(y)

    def __repr__(self) -> str:
        return f"TimeGrid({self.t0!r}, {self.t1!r}, {self.n})"


def as_time_source(t: Any, allow_empty: bool = False) -> Any:
    """Output times as a source the engine reads segment by segment: a :class:`TimeGrid` or a 1-D array-like.

    A ``tuple`` of three numbers is ``(t0, t1, n)``; a list, a number or an array is a list of times; any
    object with ``len`` (or ``shape``) and slicing (a ``numpy.memmap``, a Zarr or HDF5 array) is read lazily.

    Raises
    ------
    InvalidInputError
        A tuple of another length, a shape that is not 1-D, no times.
    TypeError
        A string.
    """
    if isinstance(t, TimeGrid):
        return t
    if isinstance(t, tuple):
        if len(t) != 3:
            raise InvalidInputError(
                f"t: a tuple is read as (t0, t1, n), got a tuple of length {len(t)}; "
                "pass a list or an array for explicit times"
            )
        return TimeGrid(*t)
    if isinstance(t, (str, bytes)):
        raise TypeError(f"t must be numeric: (t0, t1, n), a TimeGrid or a 1-D array of times, got the string {t!r}")
    if isinstance(t, (list, numbers.Real)) or not hasattr(t, "__getitem__"):
        t = np.atleast_1d(np.asarray(t))
    shape = getattr(t, "shape", None)
    if shape is None:
        shape = (len(t),)
    if len(shape) != 1:
        raise InvalidInputError(f"t must be a 1-D array of output times, got shape {tuple(shape)}")
    if shape[0] < 1 and not allow_empty:
        raise InvalidInputError("t is empty: give at least one output time")
    return t


def read_times(src: Any, a: int, b: int) -> NDArray[np.float64]:
    """The output times ``src[a:b]`` as a checked float64 array (NaN/inf refused, naming the slice)."""
    from ..util.validate import as_float_array

    name = "t" if a == 0 and b >= len(src) else f"t[{a}:{b}]"
    if isinstance(src, np.ndarray) and src.dtype == np.float64 and src.ndim == 1:
        out = src[a:b]
        if not np.all(np.isfinite(out)):
            as_float_array(out, name)  # raises, naming the times
        return out
    return as_float_array(np.asarray(src[a:b]), name).reshape(-1)


# ---------------------------------------------------------------------------
# configuration: the method, its options, the problem (once per run)
# ---------------------------------------------------------------------------
#: the keyword arguments of :func:`~eulerpoisson.solve` itself
SOLVE_ARGUMENTS = ("omega0", "m0", "attitude0", "gibbs0", "torque", "method", "workers")


def configure_method(
    method: str | MethodOptions | None, options: dict[str, Any], caller: str = "solve"
) -> tuple[str | None, Method | None]:
    """``(name, configured method)`` from a method name or typed options and keyword options.

    ``None`` (the default method) is resolved later, from the model (:func:`default_method`): then the
    options are checked once the method is known.

    Raises
    ------
    TypeError
        An unknown keyword (with the closest name) or an option of another method.
    InvalidInputError
        An unknown method.
    """
    if method is None:
        check_keywords(None, options, caller)  # a keyword that no method has is an error at once
        return None, None
    if isinstance(method, MethodOptions):
        cls = get_method(method.method)
        check_keywords(cls, options, caller)
        return method.method, cls(method, **options)
    cls = get_method(method)
    check_keywords(cls, options, caller)
    return method, cls(**options)


def default_method(model: Model) -> str:
    """The method a model gets when none is named: the most accurate one that can run it.

    The closed form (``exact``) for the free body and the Lagrange top; otherwise ``taylor`` when it can
    run the model (polynomial torques), else the first registered method that can.

    Raises
    ------
    UnsupportedModelError
        No registered method can run the model.
    """
    from .registry import methods_supporting

    for name in ("exact", "taylor"):
        try:
            cls = get_method(name)
        except InvalidInputError:  # pragma: no cover - unregistered by a plug-in
            continue
        if cls.supports(model) is None:
            return name
    able = methods_supporting(model)
    if able:
        return able[0]
    check_supported("exact", model)  # raises, naming the reason
    raise AssertionError("unreachable")  # pragma: no cover


def check_keywords(cls: type[Method] | None, options: dict[str, Any], caller: str = "solve") -> None:
    """An unknown keyword is an error of ``caller`` (with the closest name), an option of another method is named so.

    ``cls`` None (the method is chosen later): only keywords that no method has are errors.

    Raises
    ------
    TypeError
        As described.
    """
    import difflib

    from .registry import available_methods

    if not options:
        return
    every = {name: set(get_method(name).options) for name in available_methods()}
    own = set(cls.options) if cls is not None else set().union(*every.values())
    for key in options:
        if key in own:
            continue
        owners = sorted(name for name, opts in every.items() if key in opts)
        if owners and cls is not None:
            have = ", ".join(sorted(own)) or "none"
            raise TypeError(
                f"method {cls.name!r} has no option {key!r} (an option of {', '.join(owners)}); its options: {have}"
            )
        known = list(SOLVE_ARGUMENTS) + sorted(own)
        close = difflib.get_close_matches(key, known + sorted(set().union(*every.values())), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        which = f"method {cls.name!r}" if cls is not None else "the methods"
        raise TypeError(
            f"{caller}() got an unexpected keyword argument {key!r}{hint}; arguments: "
            f"{', '.join(SOLVE_ARGUMENTS)}, and the options of {which}: "
            f"{', '.join(sorted(own)) or 'none'}"
        )


# ---------------------------------------------------------------------------
# segments
# ---------------------------------------------------------------------------
def plan_segments(
    n: int, *, closed_form: bool, monotonic: bool, turns: float = 0.0, bodies: int = 1
) -> list[tuple[int, int]]:
    """Bounds ``[(a, b), ...]`` of the segments of a run of ``n`` output times (see the module notes).

    Parameters
    ----------
    n : int
        Output times.
    closed_form : bool
        The method evaluates any time from the initial state (segments only bound the memory).
    monotonic : bool
        The times are strictly monotonic (a stepping method can continue from one segment to the next;
        otherwise it integrates the run in one piece).
    turns : float
        Radians that the fastest body turns over the run, :math:`|\\Omega_0|_\\max \\max|t|` (stepping methods).
    bodies : int
        Bodies in the batch: a segment holds at most :data:`SEGMENT_SAMPLES` (body, time) samples.

    Examples
    --------
    >>> plan_segments(120_000, closed_form=True, monotonic=True)
    [(0, 40000), (40000, 80000), (80000, 120000)]
    >>> plan_segments(1001, closed_form=False, monotonic=True, turns=1e3)
    [(0, 1001)]
    """
    if n <= 0:
        return []
    per = max(1, min(SEGMENT, SEGMENT_SAMPLES // max(1, bodies)))
    k = -(-n // per)
    if not closed_form:
        if not monotonic:
            return [(0, n)]
        if math.isfinite(turns) and turns > SEGMENT_TURNS:
            k = max(k, min(MAX_TURN_SEGMENTS, n - 1, int(turns // SEGMENT_TURNS) + 1))
        elif not math.isfinite(turns):
            k = max(k, min(MAX_TURN_SEGMENTS, n - 1))
    k = max(1, min(k, n))
    return [((i * n) // k, ((i + 1) * n) // k) for i in range(k)]


@dataclass
class Segment:
    """One segment of a run: output times ``t[start:stop]`` and the motion there (plain data).

    Attributes
    ----------
    start, stop : int
        Indices of its output times in the run.
    trajectory : Trajectory
        The motion at those times (absolute times, the run's model; quaternion signs continuous with the
        previous segment).
    wall_time : float
        Seconds spent on it.
    """

    start: int
    stop: int
    trajectory: Trajectory
    wall_time: float = 0.0


@dataclass
class SolveRun:
    """A run prepared once: the checked problem, the method planned for the whole batch, its segments.

    Built by :func:`prepare_run`; :meth:`segments` yields the solution (see the module notes).

    Attributes
    ----------
    method_name : str
    method : Method
        The configured method with its batch-wide choices made (:meth:`~.Method.for_batch`).
    problem : Problem
        The initial value problem at the first segment's times (bodies, initial state at t = 0, model).
    model : Model
    times : TimeGrid or array_like
        The output times (read segment by segment).
    n : int
        Number of output times.
    closed_form : bool
    bounds : list of (int, int)
        The segments.
    workers : int or None
    """

    method_name: str
    method: Method
    problem: Problem
    model: Model
    times: Any
    n: int
    closed_form: bool
    bounds: list[tuple[int, int]]
    workers: int | None = None

    @property
    def options(self) -> dict[str, Any]:
        """The method's options (as recorded in trajectories and files)."""
        return dict(self.method.config)

    def segment_index(self, sample: int) -> int:
        """The segment that holds output time ``sample``."""
        for i, (a, b) in enumerate(self.bounds):
            if a <= sample < b:
                return i
        raise IndexError(f"output time {sample} is not in this run of {self.n}")

    def solve_segment(
        self,
        i: int,
        state: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None,
        tc: NDArray[np.float64] | None = None,
    ) -> Segment:
        """Segment ``i``: from the initial state (``state`` None) or continued from ``(t, q, omega)``.

        ``state`` is the last state of the previous segment: a stepping method continues from it, and the
        quaternion signs are made continuous with it (a closed-form method evaluates the segment from the
        initial state). ``tc``: the segment's output times when already read.
        """
        from ..util.jit import run_shape, whole_run

        a, b = self.bounds[i]
        if tc is None:
            tc = read_times(self.times, a, b)
        start = _time.perf_counter()
        # one choice of compiled kernels or NumPy for the whole run (the same numbers as one call; a run that is
        # itself part of a larger one keeps the larger one's size)
        with whole_run(*run_shape(0, self.n)):
            if self.closed_form or state is None:
                problem = self.problem if i == 0 and self.problem.t.shape == tc.shape else _with_times(self.problem, tc)
                tr = self._solve(problem)
            else:
                tr = continue_from(self, tc, *state)
        if state is not None:
            # keep the quaternion sign continuous across the boundary
            prev_q = state[1]
            q = tr.quaternion
            sgn = np.where(np.sum(prev_q * q[..., 0, :], -1) < 0, -1.0, 1.0)
            if np.any(sgn < 0):
                tr.quaternion = q * sgn[..., None, None]
        return Segment(a, b, tr, _time.perf_counter() - start)

    def _solve(self, problem: Problem, model: Model | None = None) -> Trajectory:
        """The planned method on ``problem``, as a trajectory of ``model`` (default: the run's)."""
        res = solve_batch(self.method, problem, self.workers)
        model = self.model if model is None else model
        return Trajectory(
            t=problem.t,
            quaternion=res.q,
            omega=res.omega,
            body=problem.body,
            torque=model.torques,
            method=self.method_name,
            options=dict(self.method.config),
            stats=dict(res.stats),
            _prepared=res.prepared,
        )

    def segments(
        self,
        first: int = 0,
        state: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> Iterator[Segment]:
        """The segments from ``first`` on; a stepping method continues from ``state`` (needed when ``first > 0``).

        Raises
        ------
        InvalidInputError
            Times that are not strictly monotonic where a stepping method continues (checked as they are read).
        """
        if first > 0 and state is None and not self.closed_form:
            raise InvalidInputError(
                "a stepping method continues a run from the state before its segment: give state=(t, q, omega)"
            )
        direction = 0
        for i in range(first, len(self.bounds)):
            a, b = self.bounds[i]
            tc = read_times(self.times, a, b)
            if not self.closed_form and len(self.bounds) > 1:
                direction = _check_monotonic(tc, a, state, direction)
            seg = self.solve_segment(i, state, tc)
            tr = seg.trajectory
            if tr.t.size:
                state = state_of(tr)
            yield seg


def _with_times(problem: Problem, t: NDArray[np.float64]) -> Problem:
    import dataclasses

    return dataclasses.replace(problem, t=t)


def _check_monotonic(tc: NDArray[np.float64], a: int, state, direction: int) -> int:
    """The direction of time (+1 or -1) of the times ``tc`` that start at index ``a``, continuing ``state``.

    Raises
    ------
    InvalidInputError
        The times are not strictly monotonic in that direction.
    """
    full = tc if state is None else np.concatenate([[state[0]], tc])
    if full.size < 2:
        return direction
    d = np.diff(full)
    if not direction:
        direction = 1 if d[0] > 0 else -1
    if not np.all(d * direction > 0):
        raise InvalidInputError(
            f"t must be strictly monotonic for a stepping method (checked near index {a}); "
            "sort the times or use method='exact'"
        )
    return direction


def prepare_run(
    body: RigidBody | Model | ArrayLike,
    t: Any,
    *,
    omega0: ArrayLike | None = None,
    m0: ArrayLike | None = None,
    attitude0: AttitudeLike | None = None,
    gibbs0: ArrayLike | None = None,
    torque: TorqueLike = None,
    method: str | MethodOptions | None = None,
    workers: int | None = None,
    in_memory: bool = False,
    stacklevel: int = 3,
    caller: str = "solve",
    **options: Any,
) -> SolveRun:
    """Check everything once and plan the run (see :func:`iter_solve` for the arguments).

    ``in_memory``: the run is collected in memory (:func:`collect`), so a closed-form method evaluates it
    in one call (the same bits as segment by segment: its times are independent of each other).

    Raises
    ------
    TypeError, InvalidInputError, UnsupportedModelError, InvalidInertiaError
        As :func:`~eulerpoisson.solve`.
    """
    check_workers(workers)
    name, m = configure_method(method, options, caller)
    src = as_time_source(t, allow_empty=in_memory)
    n = len(src)
    whole = isinstance(src, np.ndarray) and n <= SEGMENT
    t_first = read_times(src, 0, n if whole else min(n, SEGMENT))
    problem = make_problem(body, t_first, omega0=omega0, m0=m0, attitude0=attitude0, gibbs0=gibbs0, torque=torque)
    if problem.model.torques:
        # parameters that overflow together: an error here, not a NaN torque that each method reports its own way
        check_torque_scales(problem.model.torques, float(np.max(problem.model.body.principal_moments)))
    if name is None:
        name = default_method(problem.model)
        cls = get_method(name)
        check_keywords(cls, options, caller)
        m = cls(**options)
    assert m is not None
    check_supported(m, problem.model)  # the configured method: its options count (a free-body-only scheme)
    if problem.extended and m.config.get("precision", "float64") == "float64":
        warnings.warn(
            f"the initial state is given in long double; method {name!r} computes in float64 and rounds it "
            f"(method='taylor' with precision='longdouble' keeps it)",
            stacklevel=stacklevel,
        )
    cls = type(m)
    closed_form = cls.order is None
    in_array = isinstance(src, np.ndarray) and src.ndim == 1
    tt = t_first if whole else (read_times(src, 0, n) if in_array else None)
    if not cls.negative_times:
        if np.any((tt if tt is not None else t_first) < 0):
            raise InvalidInputError(f"method {name!r} cannot run backwards in time; got negative times in t")
    B = int(np.prod(problem.batch_shape, dtype=int))
    if (in_memory and closed_form) or n == 0:
        bounds = [(0, n)]  # (no output times: the method still checks the problem, and a trajectory of T = 0)
    elif closed_form:
        bounds = plan_segments(n, closed_form=True, monotonic=True, bodies=B)
    else:
        if tt is not None:
            d = np.diff(tt)
            monotonic = bool(np.all(d > 0) or np.all(d < 0))
            tmax = float(np.max(np.abs(tt))) if n else 0.0
        else:
            monotonic = True  # a lazy source: checked segment by segment as it is read
            tmax = max(abs(float(read_times(src, 0, 1)[0])), abs(float(read_times(src, n - 1, n)[0])))
        if not monotonic and not in_memory:
            raise InvalidInputError(
                "t must be strictly monotonic for a stepping method that writes its run segment by segment; "
                "sort the times or use method='exact'"
            )
        with np.errstate(over="ignore", invalid="ignore"):
            w = problem.omega0.reshape(-1, 3)
            rate = float(np.max(np.sqrt(np.sum(w * w, axis=-1)))) if w.size else 0.0
        bounds = plan_segments(n, closed_form=False, monotonic=monotonic, turns=rate * tmax, bodies=B)
    if len(bounds) == 1 and problem.t.shape[0] != n:
        problem = _with_times(problem, read_times(src, 0, n))
    from ..util.jit import run_shape, whole_run

    with whole_run(*run_shape(0, n)):
        planned = m.for_batch(problem)
    return SolveRun(
        method_name=name,
        method=planned,
        problem=problem,
        model=problem.model,
        times=src,
        n=n,
        closed_form=closed_form,
        bounds=bounds,
        workers=workers,
    )


def iter_solve(
    body: RigidBody | Model | ArrayLike,
    t: Any,
    *,
    omega0: ArrayLike | None = None,
    m0: ArrayLike | None = None,
    attitude0: AttitudeLike | None = None,
    gibbs0: ArrayLike | None = None,
    torque: TorqueLike = None,
    method: str | MethodOptions | None = None,
    workers: int | None = None,
    **options: Any,
) -> Iterator[Segment]:
    r"""The motion, one segment of output times after the other (the engine behind every route).

    Parameters
    ----------
    body, omega0, m0, attitude0, gibbs0, torque, workers, **options
        As for :func:`~eulerpoisson.solve`.
    t : array_like, tuple (t0, t1, n) or TimeGrid
        Output times; a :class:`TimeGrid` (or a tuple) and array-likes that slice (memory maps, Zarr arrays)
        are read segment by segment.
    method : str, MethodOptions or None
        None: the most accurate method that can run the model (:func:`default_method`).

    Yields
    ------
    Segment
        ``start``, ``stop`` and the :class:`~eulerpoisson.trajectory.Trajectory` of the segment.

    Raises
    ------
    TypeError, InvalidInputError, UnsupportedModelError, InvalidInertiaError
        As :func:`~eulerpoisson.solve`, before the first segment is solved.
    """
    run = prepare_run(
        body,
        t,
        omega0=omega0,
        m0=m0,
        attitude0=attitude0,
        gibbs0=gibbs0,
        torque=torque,
        method=method,
        workers=workers,
        **options,
    )
    return run.segments()


def collect(run: SolveRun, pieces: Sequence[Segment] | Iterator[Segment] | None = None) -> Trajectory:
    """The memory sink: the segments of ``run`` as one :class:`~eulerpoisson.trajectory.Trajectory`.

    ``stats``: those of the method (one segment), or over the segments the totals of the method's
    additive counters and the largest of the other numbers, with ``segments``; ``wall_time`` in seconds.
    """
    start = _time.perf_counter()
    parts = list(run.segments() if pieces is None else pieces)
    if len(parts) == 1:
        tr = parts[0].trajectory
        tr.stats = {"wall_time": 0.0, **tr.stats}
        tr.stats["wall_time"] = _time.perf_counter() - start
        return tr
    trs = [p.trajectory for p in parts]
    stats = merge_stats(run.method, [tr.stats for tr in trs])
    stats["segments"] = len(parts)
    out = Trajectory(
        t=np.concatenate([tr.t for tr in trs]),
        quaternion=np.concatenate([tr.quaternion for tr in trs], axis=-2),
        omega=np.concatenate([tr.omega for tr in trs], axis=-2),
        body=trs[0].body,
        torque=run.model.torques,
        method=run.method_name,
        options=run.options,
        stats={"wall_time": 0.0, **stats},
        _prepared=True,
    )
    out.stats["wall_time"] = _time.perf_counter() - start
    return out


def merge_stats(method: Method, parts: list[dict]) -> dict:
    """Counters over segments: the method's additive ones summed, other numbers the largest, the rest the first's."""
    out: dict = {}
    for st in parts:
        for k, v in st.items():
            if k == "wall_time":
                continue
            if k not in out:
                out[k] = v
            elif isinstance(v, numbers.Number) and not isinstance(v, bool):
                out[k] = out[k] + v if k in method.additive_stats or k == "steps" else max(out[k], v)
    return out


# ---------------------------------------------------------------------------
# continuing from a later state
# ---------------------------------------------------------------------------
def continue_from(
    run: SolveRun,
    t: NDArray[np.float64],
    t_start: float,
    q_start: NDArray[np.float64],
    omega_start: NDArray[np.float64],
) -> Trajectory:
    r"""The run's motion at the absolute times ``t`` continued from its state ``(q_start, omega_start)`` at ``t_start``.

    The model is autonomous unless a torque depends on time, so the method
    solves :math:`s = t - t_\mathrm{start}` from that state; time-dependent
    torques are shifted (:meth:`~eulerpoisson.Model.shifted`: a gravity
    gradient turns the space frame by :math:`\varphi = \nu t_\mathrm{start}`,
    and the other torques are seen from that frame). The result is a
    trajectory of the original model at the absolute times.
    """
    from ..numerics.quaternion import qmul

    model = run.model
    if model.is_autonomous or t_start == 0.0:
        problem = make_problem(model, t - t_start, omega0=omega_start, attitude0=q_start)
        tr = run._solve(problem)
        tr.t = t
        return tr
    shifted, phi = model.shifted(t_start)
    turned = bool(np.any(phi != 0))
    q0 = np.asarray(q_start, dtype=float)
    if turned:
        q0 = qmul(rotation_z(phi) * np.array([1.0, -1.0, -1.0, -1.0]), q0)
    problem = make_problem(shifted, t - t_start, omega0=omega_start, attitude0=q0)
    tr = run._solve(problem, shifted)
    q = tr.quaternion
    if turned:
        q = qmul(rotation_z(phi)[..., None, :], q)
    return Trajectory(t, q, tr.omega, model.body, tr.method, tr.options, tr.stats, torque=list(model.torques))


def rotation_z(phi: ArrayLike) -> NDArray[np.float64]:
    """Quaternions (..., 4) of the rotations by ``phi`` about the space z axis."""
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.cos(phi / 2), np.zeros_like(phi), np.zeros_like(phi), np.sin(phi / 2)], -1)


def state_of(tr: Trajectory) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """The state ``(t, q, omega)`` at a trajectory's last output time (where a stepping method continues)."""
    return float(tr.t[-1]), tr.quaternion[..., -1, :], tr.omega[..., -1, :]


def evaluate(tr: Trajectory, t: ArrayLike, **options: Any) -> Trajectory:
    r"""A trajectory's motion at any times ``t``, from its nearest stored samples (``tr(t)``).

    A closed form evaluates the motion at every requested time from one
    stored sample (the one nearest to the middle of the times; exact to
    round-off, the model being autonomous or shifted), in one call; a
    stepping method integrates the short way from the stored sample nearest
    to each time (ties: the earlier sample) with the
    trajectory's method and options, so the result has the trajectory's own
    error at the sample plus that of one short integration, and a time far
    outside the stored range is a continuation from the end sample. A
    trajectory whose method is not registered (read from another program's
    file) is continued by the default method of its model.

    Parameters
    ----------
    tr : Trajectory
    t : float or array_like, shape (T,)
        Any times, any order.
    **options
        Override the method's options.

    Returns
    -------
    Trajectory
        At the times ``t`` (in the order given), of the trajectory's model and body.

    Raises
    ------
    InvalidInputError
        An empty trajectory (it has no state), NaN or infinite times.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> tr = ep.solve([1.0, 2.0, 3.0], np.linspace(0.0, 10.0, 11), omega0=[1.0, 0.1, 0.5], method="taylor")
    >>> mid = tr([2.5, 7.25])
    >>> ref = ep.solve([1.0, 2.0, 3.0], [2.5, 7.25], omega0=[1.0, 0.1, 0.5])
    >>> bool(np.max(np.abs(mid.omega - ref.omega)) < 1e-12)
    True
    """
    from ..util.validate import as_float_array
    from .registry import available_methods

    if tr.t.size == 0:
        raise InvalidInputError("a trajectory with no output times cannot be evaluated: it has no state")
    times = np.atleast_1d(as_float_array(t, "t"))
    if times.ndim != 1:
        raise InvalidInputError(f"t must be a scalar or a 1-D array of times, got shape {times.shape}")
    known = tr.method in available_methods()
    method = tr.method if known else default_method(tr.model)
    opts = {**(tr.options if known else {}), **options}
    # the nearest stored sample of every time (ties: the earlier one)
    order = np.argsort(tr.t, kind="stable")
    ts = tr.t[order]
    pos = np.clip(np.searchsorted(ts, times), 0, ts.size - 1)
    left = np.clip(pos - 1, 0, ts.size - 1)
    near = np.where(np.abs(ts[left] - times) <= np.abs(ts[pos] - times), left, pos)
    anchor = order[near]
    if get_method(method).order is None:
        # a closed form has no error that grows with the distance: one evaluation from one sample (the one
        # nearest to the middle of the times) serves every time
        anchor = np.full_like(anchor, anchor[np.argsort(times, kind="stable")[times.size // 2]])
    bshape = tr.batch_shape
    q = np.empty(bshape + (times.size, 4))
    w = np.empty(bshape + (times.size, 3))
    stats: list[dict] = []
    run = None
    for i in np.unique(anchor):
        sel = np.flatnonzero(anchor == i)
        tt = times[sel]
        run = prepare_run(
            tr.model,
            tt,
            omega0=tr.omega[..., i, :],
            attitude0=tr.quaternion[..., i, :],
            method=method,
            in_memory=True,
            caller="Trajectory.__call__",
            **opts,
        )
        # forwards and backwards from the sample: each side in order (a stepping method runs each way once)
        t0 = float(tr.t[i])
        part = continue_from(run, tt, t0, run.problem.q0, run.problem.omega0)
        q[..., sel, :] = part.quaternion
        w[..., sel, :] = part.omega
        stats.append(part.stats)
    assert run is not None
    return Trajectory(
        times,
        q,
        w,
        tr.body,
        method,
        dict(run.method.config),
        merge_stats(run.method, stats),
        torque=list(tr.model.torques),
    )
