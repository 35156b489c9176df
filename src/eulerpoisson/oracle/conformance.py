r"""The conformance report: physics engines held against the exact motion of a free rigid body.

For each engine x setting x case x step size (a *cell*), the engine's adapter
(:mod:`eulerpoisson.oracle.engines`) runs the case and returns what the engine
reports in its own conventions; the oracle reads that as a user's run
(:func:`~eulerpoisson.oracle.run_from_arrays`, :func:`~eulerpoisson.oracle.compare_run`:
the exact motion from the run's first sample, convention detection included) and
the cell keeps:

- the attitude error (the largest angle between the run's attitude and the exact
  one) up to 10 and up to 100 natural periods of the case (a flip period for the
  tennis racket, the period of :math:`\boldsymbol\Omega(t)` otherwise, see
  :data:`~eulerpoisson.oracle.cases.CONFORMANCE_PERIODS`);
- whether the flips happen, and the largest error of the flip times;
- the drift of the energy and of :math:`|\mathbf m|` (the spatial angular momentum)
  per 1000 periods (the slope of the relative drift, fitted over the run);
- the wall time per step (the stepping alone).

A run reaches 100 periods when the engine's step budget (:attr:`Engine.max_steps`)
allows, else 10, else as far as the budget goes. Each cell is written to its own
JSON file as soon as it is done, and a later run skips the cells found there
(resumable). :func:`write_report` writes the table (Markdown, CSV, JSON), a
work-precision figure per case, the engine versions and the machine.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import platform
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import InvalidInputError
from .cases import CONFORMANCE_CASE_NAMES, CONFORMANCE_PERIODS, ReferenceCase, conformance_cases, reference_cases
from .compare import compare_run
from .engines import ENGINE_NAMES, Engine, EngineRun, get_engine
from .engines.base import SamplePlan, sample_plan
from .runs import NORM_TOLERANCE, run_from_arrays

__all__ = [
    "DEFAULT_DTS",
    "TARGET_ERROR",
    "CELL_FORMAT",
    "conformance_case",
    "natural_period",
    "plan_cell",
    "evaluate_run",
    "cell_path",
    "run_cell",
    "run_matrix",
    "step_needed",
    "write_report",
    "machine_info",
    "markdown_table",
]

#: the step sizes of the report
DEFAULT_DTS = (1e-2, 1e-3, 1e-4)
#: the attitude error (rad) at 100 periods whose step size the report names
TARGET_ERROR = 1e-3
#: the windows (in natural periods) of the attitude errors
WINDOWS = (10, 100)
#: samples per natural period
SAMPLES_PER_PERIOD = 20
#: a run may exceed its step budget by this fraction to reach a window (periods of 1.0004 s, steps of 1e-3 s)
BUDGET_SLACK = 0.02
#: the version of a cell file (a cell of another version is computed again)
CELL_FORMAT = 1


def conformance_case(name: str) -> ReferenceCase:
    """A case of the report by name: a conformance case, or a case of ``eulerpoisson cases``.

    Raises
    ------
    InvalidInputError
        An unknown name (the message lists both suites).

    Examples
    --------
    >>> from eulerpoisson.oracle.conformance import conformance_case
    >>> conformance_case("racket_near_separatrix").inertia
    (3.0, 5.0, 8.0)
    """
    cases = conformance_cases()
    if name in cases:
        return cases[name]
    ref = reference_cases()
    if name in ref:
        return ref[name]
    raise InvalidInputError(
        f"case: unknown case {name!r}; conformance cases: {', '.join(CONFORMANCE_CASE_NAMES)}; "
        f"reference cases: {', '.join(ref)}"
    )


def natural_period(case: ReferenceCase) -> tuple[float, str]:
    """The case's natural period and its kind (see :data:`~eulerpoisson.oracle.cases.CONFORMANCE_PERIODS`).

    A case outside the conformance suite gets the period of :math:`\\boldsymbol\\Omega(t)` (4K/lambda) when its
    moments differ, that of the precession for a symmetric body, and 2 pi/|Omega| for a sphere.

    Examples
    --------
    >>> from eulerpoisson.oracle.conformance import conformance_case, natural_period
    >>> T, kind = natural_period(conformance_case("racket_near_separatrix"))
    >>> round(T, 3), kind
    (0.999, 'flip')
    >>> natural_period(conformance_case("symmetric_precession"))
    (1.0, 'precession')
    """
    from ..analysis import momentum_period
    from .engines.base import principal_frame

    moments, P = principal_frame(case.inertia)
    w = P.T @ np.asarray(case.omega0, float)
    spread = float(np.max(moments) - np.min(moments))
    order = np.sort(moments)
    kind = CONFORMANCE_PERIODS.get(case.name)
    if kind is None:
        if spread <= 1e-12 * float(np.max(moments)):
            kind = "rotation"
        elif min(order[1] - order[0], order[2] - order[1]) <= 1e-12 * float(np.max(moments)):
            kind = "precession"
        else:
            kind = "momentum"
    if kind == "rotation":
        return 2.0 * math.pi / float(np.linalg.norm(w)), kind
    if kind == "precession":
        # the axis whose moment differs (the other two are the closest pair)
        gaps = [abs(moments[(i + 1) % 3] - moments[(i + 2) % 3]) for i in range(3)]
        odd = int(np.argmin(gaps))
        i_eq = 0.5 * float(moments[(odd + 1) % 3] + moments[(odd + 2) % 3])
        rate = abs((float(moments[odd]) - i_eq) / i_eq * float(w[odd]))
        return 2.0 * math.pi / rate, kind
    T = momentum_period(moments, moments * w)
    return (0.5 * T, kind) if kind == "flip" else (T, kind)


def plan_cell(period: float, dt: float, max_steps: int) -> tuple[SamplePlan, float]:
    """The run of a cell: to 100 periods if ``max_steps`` allow (give or take 2 %), else 10, else as far as they go.

    Returns the plan and the periods it covers.

    Examples
    --------
    >>> from eulerpoisson.oracle.conformance import plan_cell
    >>> plan, periods = plan_cell(1.0, 1e-3, 200_000)
    >>> plan.steps, plan.samples, periods
    (100000, 2001, 100.0)
    >>> plan_cell(1.0, 1e-4, 200_000)[1]
    10.0
    """
    if not (max_steps >= 1):
        raise InvalidInputError(f"max_steps must be a positive number of steps, got {max_steps!r}")
    for n in sorted(WINDOWS, reverse=True):
        if n * period / dt <= max_steps * (1 + BUDGET_SLACK):
            t_end = n * period
            break
    else:
        t_end = max_steps * dt
    interval = min(period / SAMPLES_PER_PERIOD, t_end / 20)
    plan = sample_plan(dt, t_end * (1 - 1e-12), interval)
    return plan, plan.t_end / period


#: a quaternion whose norm leaves [1/this, this] is a diverged run (a norm that drifts less is normalized)
QUATERNION_NORM_RANGE = 1e3
#: a rate above this many times the largest rate the body can have is a diverged run
DIVERGED_RATE = 100.0


def _valid_prefix(run: EngineRun) -> tuple[int, str | None]:
    """How many leading samples are usable, and why the rest is not (None: all are).

    A sample is unusable when it is not finite, its quaternion's norm has left [1/1000, 1000] (a run that
    does not renormalize and blew up), or its
    rate exceeds :data:`DIVERGED_RATE` times the largest rate the body can have (the run blew up).
    """
    from .engines.base import principal_frame

    q, w = run.quaternion, run.omega
    finite = np.all(np.isfinite(q), axis=1) & np.all(np.isfinite(w), axis=1)
    moments = principal_frame(run.inertia)[0]
    w0 = float(np.linalg.norm(w[0])) if finite[0] else 0.0
    # |I Omega| is conserved: |Omega(t)| <= |Omega(0)| I_max / I_min, in any frame
    limit = DIVERGED_RATE * w0 * float(np.max(moments) / np.min(moments))
    with np.errstate(invalid="ignore", over="ignore"):
        nq = np.linalg.norm(q, axis=1)
        sane = (
            (np.linalg.norm(w, axis=1) <= limit) & (nq >= 1.0 / QUATERNION_NORM_RANGE) & (nq <= QUATERNION_NORM_RANGE)
        )
    good = finite & sane
    if good.all():
        return len(good), None
    k = int(np.argmin(good))
    return k, f"diverged at t = {float(run.t[k]):.6g}" + (" (NaN or inf)" if not finite[k] else "")


def _slope(t: np.ndarray, y: np.ndarray) -> float:
    if t.size < 3 or t[-1] <= t[0]:
        return float("nan")
    tc = t - t.mean()
    return float(np.sum(tc * (y - y.mean())) / np.sum(tc * tc))


def _finite(x) -> float | None:
    return float(x) if x is not None and np.isfinite(x) else None


def evaluate_run(run: EngineRun, case: ReferenceCase, period: float, source: str = "engine") -> dict:
    """The metrics of one engine run, read by the oracle as a user's run.

    Parameters
    ----------
    run : EngineRun
        What the adapter returned (the engine's conventions).
    case : ReferenceCase
        The case run.
    period : float
        Its natural period.
    source : str
        The run's name in messages.

    Returns
    -------
    dict
        ``status`` (``"ok"``; ``"diverged"``: the run blew up, the samples before are used; ``"failed"``:
        not two usable samples), ``message``, ``error_10``, ``error_100`` (rad, None when the run did not reach
        that far), ``max_error``, ``periods_run``, ``flip`` (None: the case does not flip; ``"yes"``,
        ``"no"`` or ``"RUN/EXACT"`` flips), ``flip_time_error`` (s), ``quaternion_norm_drift``, ``energy_drift_per_1000``,
        ``momentum_drift_per_1000``, ``energy_drift_max``, ``momentum_drift_max``, ``convention_hint``,
        ``conventions``.

    Examples
    --------
    >>> import numpy as np, eulerpoisson as ep
    >>> from eulerpoisson.oracle.conformance import conformance_case, evaluate_run
    >>> from eulerpoisson.oracle.engines import EngineRun
    >>> from eulerpoisson.oracle import Conventions
    >>> case = conformance_case("spin_largest_axis")
    >>> tr = ep.solve(case.inertia, np.linspace(0, 10, 201), omega0=case.omega0, method="exact")
    >>> run = EngineRun(tr.t, tr.quaternion, tr.omega, Conventions("wxyz"), case.inertia_array, 200, 0.0)
    >>> m = evaluate_run(run, case, 1.0)
    >>> m["status"], m["error_10"] < 1e-12, m["error_100"], m["flip"]
    ('ok', True, None, None)
    """
    n, why = _valid_prefix(run)
    status = "ok" if why is None else "diverged"
    out: dict = {
        "status": status,
        "message": why or "",
        "error_10": None,
        "error_100": None,
        "max_error": None,
        "periods_run": float(run.t[-1] / period),
        "flip": None,
        "flip_exact": None,
        "flip_run": None,
        "flip_time_error": None,
        "energy_drift_per_1000": None,
        "momentum_drift_per_1000": None,
        "energy_drift_max": None,
        "momentum_drift_max": None,
        "quaternion_norm_drift": None,
        "convention_hint": None,
        "conventions": run.conventions.to_dict(),
    }
    if n < 2:
        out["status"] = "failed"
        out["message"] = why or "fewer than 2 samples"
        return out
    conv = run.conventions
    q = run.quaternion[:n]
    norm_drift = float(np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0)))
    out["quaternion_norm_drift"] = norm_drift
    if norm_drift > NORM_TOLERANCE:  # an engine that does not renormalize: its attitude is the direction of q
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        note = f"quaternion norm drifts by {norm_drift:.2g} (not renormalized by the engine; normalized here)"
        out["message"] = f"{out['message']}; {note}" if out["message"] else note
    raw = run_from_arrays(run.t[:n], q, run.omega[:n], quaternion_order=conv.quaternion_order or "wxyz", source=source)
    rep = compare_run(raw, run.inertia, conventions=conv, detect=True)
    t, att = rep.t, rep.attitude_error
    for w in WINDOWS:
        if t[-1] >= w * period * (1 - 1e-9):
            out[f"error_{w}"] = float(np.max(att[t <= w * period * (1 + 1e-9)]))
    out["max_error"] = float(np.max(att))
    out["periods_run"] = float(t[-1] / period)
    if rep.flip_times is not None and rep.flip_times_run is not None and rep.flip_time_errors is not None:
        ne, nr = len(rep.flip_times), len(rep.flip_times_run)
        out["flip_exact"], out["flip_run"] = ne, nr
        out["flip"] = "yes" if ne == nr else ("no" if nr == 0 else f"{nr}/{ne}")
        errs = [abs(e) for e in rep.flip_time_errors if np.isfinite(e)]
        out["flip_time_error"] = max(errs) if errs and ne == nr else None
    out["energy_drift_per_1000"] = _finite(abs(_slope(t, rep.energy_error)) * 1000 * period)
    out["momentum_drift_per_1000"] = _finite(abs(_slope(t, rep.momentum_error)) * 1000 * period)
    out["energy_drift_max"] = float(rep.energy_drift)
    out["momentum_drift_max"] = float(rep.momentum_drift)
    out["convention_hint"] = rep.convention_hint
    return out


def cell_path(cells: str | os.PathLike[str], engine: str, setting: str, case: str, dt: float) -> str:
    """The file of a cell: ``CELLS/ENGINE__SETTING__CASE__dtDT.json``.

    Examples
    --------
    >>> from eulerpoisson.oracle.conformance import cell_path
    >>> cell_path("cells", "mujoco", "RK4", "racket_near_separatrix", 1e-3)
    'cells/mujoco__RK4__racket_near_separatrix__dt0.001.json'
    """
    return os.path.join(os.fspath(cells), f"{engine}__{setting}__{case}__dt{dt:g}.json")


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send what the engines print on standard output (Python's prints and C code's alike) to standard error.

    The report's own output (``--json``) stays alone on standard output.
    """
    with contextlib.redirect_stdout(sys.stderr):
        out, err = sys.__stdout__, sys.__stderr__
        saved = -1
        if out is not None and err is not None:
            try:
                out.flush()
                saved = os.dup(out.fileno())
            except (AttributeError, OSError, ValueError):  # no real file descriptors: Python's prints are moved
                saved = -1
        if saved < 0:
            yield
            return
        assert out is not None and err is not None  # (saved >= 0)
        try:
            os.dup2(err.fileno(), out.fileno())
            yield
        finally:
            with contextlib.suppress(OSError, ValueError):
                out.flush()
            os.dup2(saved, out.fileno())
            os.close(saved)


def _load_cell(path: str) -> dict | None:
    try:
        with open(path, encoding="utf-8") as fh:
            cell = json.load(fh)
    except (OSError, ValueError):
        return None
    return cell if isinstance(cell, dict) and cell.get("format") == CELL_FORMAT else None


def run_cell(
    engine: Engine,
    setting: str,
    case_name: str,
    dt: float,
    cells: str | os.PathLike[str],
    *,
    max_steps: int | None = None,
    redo: bool = False,
) -> tuple[dict, bool]:
    """Run one cell (or read it back when its file exists): ``(the cell, True when it was read back)``.

    An engine that raises while building or stepping gives a cell with ``status`` ``"error"`` and the
    exception's first line (kept like any cell: pass ``redo`` to try again).

    Raises
    ------
    InvalidInputError
        An unknown setting or case, a step that is not a positive number.
    """
    from ..io.atomic import atomic_write_text

    engine.check_setting(setting)
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise InvalidInputError(f"dt must be a positive number of seconds, got {dt!r}")
    case = conformance_case(case_name)
    path = cell_path(cells, engine.name, setting, case_name, dt)
    if not redo:
        old = _load_cell(path)
        if old is not None:
            return old, True
    period, kind = natural_period(case)
    budget = int(max_steps if max_steps is not None else engine.max_steps)
    if budget < 1:
        raise InvalidInputError(f"max_steps must be a positive number of steps, got {max_steps!r}")
    plan, _ = plan_cell(period, dt, budget)
    cell: dict = {
        "format": CELL_FORMAT,
        "engine": engine.name,
        "setting": setting,
        "case": case_name,
        "dt": float(dt),
        "version": engine.version(),
        "period": period,
        "period_kind": kind,
        "t_end": plan.t_end,
        "steps": plan.steps,
        "samples": plan.samples,
        "max_steps": budget,
    }
    t0 = time.perf_counter()
    try:
        with _stdout_to_stderr():
            run = engine.run(case, dt, setting, plan)
        cell["wall_per_step"] = run.wall_s / max(run.steps, 1)
        cell["notes"] = list(run.notes)
        cell.update(evaluate_run(run, case, period, source=f"{engine.name} {setting} {case_name} dt={dt:g}"))
    except Exception as exc:  # noqa: BLE001 - an engine's failure is a finding of the report, kept in its cell
        text = str(exc).strip().splitlines()
        cell.update({"status": "error", "message": f"{type(exc).__name__}: {text[0] if text else ''}"})
    cell["cell_wall_s"] = time.perf_counter() - t0
    os.makedirs(os.fspath(cells), exist_ok=True)
    atomic_write_text(path, json.dumps(_jsonable(cell), indent=1, allow_nan=False))
    return cell, False


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x) if np.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def machine_info() -> dict:
    """The machine the report ran on: platform, processor, cores, Python, NumPy, eulerpoisson."""
    from ..version import package_version

    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "platform": platform.platform(),
        "processor": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "eulerpoisson": package_version(),
    }


def run_matrix(
    engines: Sequence[str | Engine] | None = None,
    cases: Sequence[str] | None = None,
    dts: Sequence[float] = DEFAULT_DTS,
    cells: str | os.PathLike[str] = "conformance/cells",
    *,
    settings: Sequence[str] | None = None,
    max_steps: int | None = None,
    redo: bool = False,
    jobs: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict:
    """Run every cell engine x setting x case x step (skipping those done before): the report as a dict.

    Parameters
    ----------
    engines : sequence of str or Engine, optional
        Engine names or adapters (default: all); an engine that cannot run here is listed with its reason.
    cases : sequence of str, optional
        Case names (default: the conformance cases).
    dts : sequence of float
        Step sizes (s).
    cells : str or os.PathLike
        The folder of the cell files.
    settings : sequence of str, optional
        Only these settings (of the engines that have them).
    max_steps : int, optional
        The step budget of a run (default: each engine's).
    redo : bool
        Run the cells found in ``cells`` again.
    jobs : int
        Worker processes (one engine setting at a time each; their progress lines go to standard error).
    progress : callable, optional
        Called with one line per cell (with ``jobs`` > 1: given, the workers print their lines instead).

    Returns
    -------
    dict
        ``engines`` (name -> available, reason, version, settings, conventions, precision), ``cases``
        (name -> description, period, kind), ``dts``, ``cells`` (list), ``step_needed``, ``machine``,
        ``target_error``, ``wall_s``.

    Raises
    ------
    InvalidInputError
        An unknown engine, setting or case; a step that is not a positive number.
    """
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise InvalidInputError(f"jobs must be a positive number of processes, got {jobs!r}")
    names = list(engines) if engines else list(ENGINE_NAMES)
    adapters = [n if isinstance(n, Engine) else get_engine(n) for n in names]
    case_names = list(cases) if cases else list(CONFORMANCE_CASE_NAMES)
    chosen = {n: conformance_case(n) for n in case_names}
    dts = [float(d) for d in dts]
    for d in dts:
        if not (math.isfinite(d) and d > 0):
            raise InvalidInputError(f"dt must be a positive number of seconds, got {d!r}")
    if settings:
        known = {s for a in adapters for s in a.settings}
        unknown = [s for s in settings if s not in known]
        if unknown:
            raise InvalidInputError(
                f"setting: unknown setting(s) {', '.join(unknown)} of {', '.join(a.name for a in adapters)}; settings: "
                + "; ".join(f"{a.name}: {', '.join(a.settings)}" for a in adapters)
            )
    report: dict = {"engines": {}, "cases": {}, "dts": dts, "cells": [], "target_error": TARGET_ERROR}
    for n, c in chosen.items():
        period, kind = natural_period(c)
        report["cases"][n] = {"description": c.description, "period": period, "period_kind": kind}
    todo = []
    for a in adapters:
        with _stdout_to_stderr():  # some engines print on import (PyBullet, Warp)
            ok, why = a.available()
        report["engines"][a.name] = {
            "title": a.title,
            "package": a.package,
            "available": ok,
            "reason": why,
            "version": a.version(),
            "settings": dict(a.settings),
            "conventions": a.conventions.to_dict(),
            "precision": a.precision,
            "max_steps": int(max_steps if max_steps is not None else a.max_steps),
            "min_dt": a.min_dt,
        }
        if not ok:
            if progress:
                progress(f"{a.name}: not available: {why}")
            continue
        for s in a.settings:
            if settings and s not in settings:
                continue
            todo += [(a, s, n, d) for n in case_names for d in dts if d >= a.min_dt * (1 - 1e-9)]
    t0 = time.perf_counter()
    if jobs > 1 and todo:
        report["cells"] = _run_parallel(todo, cells, max_steps, redo, jobs, progress)
    else:
        for i, (a, s, n, d) in enumerate(todo, 1):
            cell, old = run_cell(a, s, n, d, cells, max_steps=max_steps, redo=redo)
            report["cells"].append(cell)
            if progress:
                progress(f"[{i}/{len(todo)}] {a.name} {s} {n} dt={d:g}: {_cell_summary(cell, old)}")
    report["wall_s"] = time.perf_counter() - t0
    report["step_needed"] = step_needed(report["cells"])
    report["machine"] = machine_info()
    return report


def _run_group(engine: Engine, setting: str, work: list, cells: str, max_steps, redo: bool, verbose: bool) -> list:
    """The cells of one engine setting, in a worker process: ``[(index, cell)]``; progress lines on stderr."""
    out = []
    for i, total, n, d in work:
        cell, old = run_cell(engine, setting, n, d, cells, max_steps=max_steps, redo=redo)
        out.append((i, cell))
        if verbose:
            line = f"[{i}/{total}] {engine.name} {setting} {n} dt={d:g}: {_cell_summary(cell, old)}"
            print(f"eulerpoisson: conformance: {line}", file=sys.stderr, flush=True)
    return out


def _run_parallel(todo: list, cells, max_steps, redo: bool, jobs: int, progress) -> list:
    """The cells of ``todo`` in ``jobs`` worker processes, one engine setting per task, in ``todo``'s order."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    groups: dict[tuple[str, str], tuple[Engine, list]] = {}
    for i, (a, s, n, d) in enumerate(todo, 1):
        groups.setdefault((a.name, s), (a, []))[1].append((i, len(todo), n, d))
    results: list = [None] * len(todo)
    # spawned workers: the engines' libraries (JAX, Warp, PhysX) are not safe to fork
    with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = [
            pool.submit(_run_group, a, s, work, os.fspath(cells), max_steps, redo, progress is not None)
            for (_, s), (a, work) in groups.items()
        ]
        for f in futures:
            for i, cell in f.result():
                results[i - 1] = cell
    return results


def _cell_summary(cell: dict, old: bool = False) -> str:
    if cell.get("status") == "error":
        return f"error: {cell.get('message', '')}" + (" (done before)" if old else "")
    e10, e100 = cell.get("error_10"), cell.get("error_100")
    parts = [f"{_g(e10)} rad at 10 periods", f"{_g(e100)} at 100"]
    if cell.get("status") not in ("ok", None):
        parts.append(cell.get("message", ""))
    if cell.get("cell_wall_s") is not None:
        parts.append(f"{cell['cell_wall_s']:.1f} s")
    return ", ".join(parts) + (" (done before)" if old else "")


def _g(x, fmt: str = ".2e") -> str:
    return "n/r" if x is None else format(x, fmt)


def step_needed(cells: Sequence[dict], target: float = TARGET_ERROR) -> dict:
    """For each engine setting and case: the largest step whose error at 100 periods is within ``target``.

    Returns ``{"ENGINE/SETTING": {case: {"dt": float or None, "text": str}}}``: the step, or why there is
    none (``cannot reach``: at every step the error at 100 periods, or already at 10, is above the target,
    or the run blew up; ``not run to 100 periods``: a step that might reach it did not run that far).

    Examples
    --------
    >>> from eulerpoisson.oracle.conformance import step_needed
    >>> cells = [{"engine": "e", "setting": "s", "case": "c", "dt": d, "error_100": err}
    ...          for d, err in ((1e-2, 0.5), (1e-3, 2e-4), (1e-4, None))]
    >>> step_needed(cells)["e/s"]["c"]
    {'dt': 0.001, 'text': '0.001'}
    """
    groups: dict[str, dict[str, list]] = {}
    for c in cells:
        groups.setdefault(f"{c['engine']}/{c['setting']}", {}).setdefault(c["case"], []).append(c)
    out: dict = {}
    for key, by_case in groups.items():
        out[key] = {}
        for case, cs in by_case.items():
            good = [c["dt"] for c in cs if c.get("error_100") is not None and c["error_100"] <= target]
            if good:
                out[key][case] = {"dt": max(good), "text": f"{max(good):g}"}
                continue
            # what shows the target is out of reach at each step: the error at 100 periods, one above the
            # target sooner (the largest error up to 100 periods is at least that), or a run that blew up
            bounds: list[tuple[float, str] | None] = []
            for c in cs:
                if c.get("error_100") is not None:
                    bounds.append((c["error_100"], f"{c['error_100']:.1e} rad at dt = {c['dt']:g}"))
                elif c.get("error_10") is not None and c["error_10"] > target:
                    bounds.append((c["error_10"], f"{c['error_10']:.1e} rad by 10 periods at dt = {c['dt']:g}"))
                elif c.get("status") in ("diverged", "failed"):
                    bounds.append((math.inf, f"diverges at dt = {c['dt']:g}"))
                else:
                    bounds.append(None)
            if all(b is not None for b in bounds):
                best = min((b for b in bounds if b is not None), key=lambda b: b[0])
                text = "cannot reach (diverges at every step)" if math.isinf(best[0]) else f"cannot reach ({best[1]})"
                out[key][case] = {"dt": None, "text": text}
            else:
                out[key][case] = {"dt": None, "text": "not run to 100 periods"}
    return out


_COLUMNS = (
    ("engine", "engine"),
    ("setting", "setting"),
    ("case", "case"),
    ("dt", "dt (s)"),
    ("error_10", "error @10 T (rad)"),
    ("error_100", "error @100 T (rad)"),
    ("flip", "flips"),
    ("flip_time_error", "flip time error (s)"),
    ("energy_drift_per_1000", "energy drift /1000 T"),
    ("momentum_drift_per_1000", "|m| drift /1000 T"),
    ("wall_per_step", "wall/step (us)"),
    ("periods_run", "periods run"),
    ("status", "status"),
)


def _cell_text(cell: dict, key: str) -> str:
    v = cell.get(key)
    if key == "wall_per_step":
        return "" if v is None else f"{v * 1e6:.3g}"
    if key == "dt":
        return f"{v:g}"
    if key == "periods_run":
        return "" if v is None else f"{v:.3g}"
    if key == "flip":
        return "" if v is None else str(v)
    if key == "status":
        msg = cell.get("message") or ""
        hint = cell.get("convention_hint")
        text = str(v) if not msg else (msg if msg.startswith(str(v)) else f"{v}: {msg}")
        return text + (f"; convention: {hint}" if hint else "")
    if key in ("engine", "setting", "case"):
        return str(v)
    if v is None:
        return "n/r" if key.startswith("error_") else ""
    return f"{v:.2e}"


def _md(text: str) -> str:
    """Text for a cell of a Markdown table: its pipes escaped."""
    return str(text).replace("|", "\\|")


def markdown_table(report: dict) -> str:
    """The report as Markdown: engines and machine, the step needed per engine setting, a table per case.

    The text starts with four lines of front matter (``orphan: true``: the file is a page of its own where
    Sphinx finds it) and a title (two lines); the sections are ``##`` headings, to be included from line 7
    under another page's title.
    """
    # front matter and title first (6 lines): a page of its own where Sphinx finds it; the user guide includes
    # the rest from line 7, under its own title
    lines = [
        "---",
        "orphan: true",
        "---",
        "",
        "# Conformance: physics engines against the exact free rigid-body motion",
        "",
    ]
    m = report.get("machine", {})
    if m:
        lines += [
            f"Machine: {m.get('processor', '')} ({m.get('cores')} cores), {m.get('platform', '')}; "
            f"Python {m.get('python')}, NumPy {m.get('numpy')}, eulerpoisson {m.get('eulerpoisson')}.",
            "",
        ]
    spent = sum(float(c.get("cell_wall_s") or 0.0) for c in report["cells"])
    lines += [
        f"{len(report['cells'])} cells (engine x setting x case x step), {spent / 60:.0f} minutes of runs in all "
        "(building, stepping and comparing, added up).",
        "",
    ]
    lines += [
        "## Engines",
        "",
        "| engine | package | version | settings | conventions | precision | |",
        "|---|---|---|---|---|---|---|",
    ]
    for e in report["engines"].values():
        c = e["conventions"]
        lines.append(
            f"| {e['title']} | `{e['package']}` | {e['version'] or ''} | {', '.join(e['settings'])} | "
            f"{c['quaternion_order']}, {c['omega_frame']} rate, {c['attitude_convention']} | {e['precision']} | "
            + ("" if e["available"] else _md(f"not run: {e['reason']}"))
            + (f"steps below {e['min_dt']:g} s not run" if e["available"] and e.get("min_dt") else "")
            + " |"
        )
    lines += ["", "## Cases", "", "| case | natural period T (s) | kind | |", "|---|---|---|---|"]
    for name, c in report["cases"].items():
        lines.append(f"| `{name}` | {c['period']:.4g} | {c['period_kind']} | {_md(c['description'])} |")
    needed = report.get("step_needed", {})
    if needed:
        case_names = list(report["cases"])
        lines += [
            "",
            f"## Step size for {report.get('target_error', TARGET_ERROR):g} rad at 100 periods",
            "",
            "The largest step of the report whose attitude error stays within the target up to 100 natural periods.",
            "",
            "| engine / setting | " + " | ".join(f"`{c}`" for c in case_names) + " |",
            "|---|" + "---|" * len(case_names),
        ]
        for key, by_case in needed.items():
            lines.append(f"| {key} | " + " | ".join(_md(by_case.get(c, {}).get("text", "")) for c in case_names) + " |")
    for case in report["cases"]:
        cells = [c for c in report["cells"] if c["case"] == case]
        if not cells:
            continue
        lines += ["", f"## `{case}`", "", "| " + " | ".join(_md(h) for k, h in _COLUMNS if k != "case") + " |"]
        lines.append("|" + "---|" * (len(_COLUMNS) - 1))
        for c in cells:
            lines.append("| " + " | ".join(_md(_cell_text(c, k)) for k, _ in _COLUMNS if k != "case") + " |")
    lines.append("")
    return "\n".join(lines)


def _csv_text(report: dict) -> str:
    import csv
    import io

    buf = io.StringIO()
    keys = [k for k, _ in _COLUMNS] + ["message", "convention_hint", "version", "period", "t_end", "steps", "max_error"]
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(keys)
    for c in report["cells"]:
        row = []
        for k in keys:
            v = c.get(k)
            row.append("" if v is None else (repr(float(v)) if isinstance(v, float) else str(v)))
        writer.writerow(row)
    return buf.getvalue()


def _plot_case(report: dict, case: str, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = [c for c in report["cells"] if c["case"] == case and c.get("error_10") is not None]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.6))
    groups: dict[str, list] = {}
    for c in cells:
        groups.setdefault(f"{c['engine']} {c['setting']}", []).append(c)
    markers = "os^vD<>ph*"
    period = report["cases"][case]["period"]
    for i, (label, cs) in enumerate(sorted(groups.items())):
        cs = sorted(cs, key=lambda c: c["dt"])
        dt = [c["dt"] for c in cs]
        err = [max(c["error_10"], 1e-16) for c in cs]
        style = {
            "marker": markers[i % len(markers)],
            "color": plt.get_cmap("tab20")(i % 20),
            "linestyle": "-" if i < 10 else "--",
            "label": label,
        }
        ax1.loglog(dt, err, **style)
        cost = [c.get("wall_per_step") for c in cs]
        if all(x is not None and x > 0 for x in cost):
            work = [x * period / c["dt"] for x, c in zip(cost, cs)]
            ax2.loglog(work, err, **style)
    for ax in (ax1, ax2):
        ax.axhline(TARGET_ERROR, color="0.5", linewidth=0.8, linestyle=":")
        ax.grid(True, which="major", alpha=0.3)
        ax.set_ylabel("attitude error up to 10 periods (rad)")
    ax1.set_xlabel("step size dt (s)")
    ax2.set_xlabel("wall time per simulated period (s)")
    ax1.set_title(f"{case}: error against step size")
    ax2.set_title("work against precision")
    handles, labels = ax1.get_legend_handles_labels()
    ax2.legend(handles, labels, fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_report(report: dict, out: str | os.PathLike[str], *, plots: bool = True) -> list[str]:
    """Write ``table.md``, ``table.csv``, ``report.json`` and (with ``plots``) ``CASE.png`` per case into ``out``.

    Returns
    -------
    list of str
        The files written.

    Raises
    ------
    InvalidInputError
        ``out`` is an existing file.
    OSError
        A file cannot be written (the message names it).
    """
    from ..io.atomic import atomic_path, atomic_write_text

    out = os.fspath(out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise InvalidInputError(f"out: {out} is a file; give a folder for the report")
    os.makedirs(out, exist_ok=True)
    files = []
    for name, text in (
        ("table.md", markdown_table(report)),
        ("table.csv", _csv_text(report)),
        ("report.json", json.dumps(_jsonable(report), indent=1, allow_nan=False)),
    ):
        path = os.path.join(out, name)
        atomic_write_text(path, text)
        files.append(path)
    if plots:
        for case in report["cases"]:
            if not any(c["case"] == case and c.get("error_10") is not None for c in report["cells"]):
                continue
            path = os.path.join(out, f"{case}.png")
            with atomic_path(path, suffix=".png") as tmp:
                _plot_case(report, case, tmp)
            files.append(path)
    return files
