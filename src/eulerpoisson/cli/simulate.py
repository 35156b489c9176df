"""The ``eulerpoisson simulate`` command: solve the motion of a body and print or save it."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import time

import numpy as np

from ..attitude.core import UNIT_QUATERNION_TOLERANCE
from ..errors import EulerPoissonError
from .common import UsageError, check_file_name, check_run_scales, json_text, load_toml, naming_target, parse_floats
from .config import (
    FLAGS,
    METHOD_OPTIONS,
    build_body,
    build_torques,
    config_from_toml,
    method_options,
    namer,
    pair,
)

__all__ = ["add_commands", "cmd_simulate", "solve_run", "MAX_SAMPLES", "CHUNKED_SAMPLES"]


#: most output times of one run (a float64 time axis has 2**53 distinct integers; far beyond any disk)
MAX_SAMPLES = 10**13

#: bytes per sample and body of an in-memory run: q, omega, their copies in the Trajectory and the derived
#: quantities written to a file (M, m, energy, Gibbs vector), float64
_BYTES_PER_SAMPLE = 8 * (4 + 3) * 4 + 8 * (3 + 3 + 1 + 3)


def _memory_needed(samples: int, batch_shape) -> float:
    bodies = int(np.prod(batch_shape)) if batch_shape else 1
    return float(samples) * bodies * _BYTES_PER_SAMPLE


def _memory_available() -> float | None:
    """Available memory in bytes (None where the system does not say)."""
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return None


def _torque_records(model) -> list[dict]:
    return [tq.to_dict() for tq in model.torques]


def _state_json(traj, drift) -> dict:
    i = int(np.argmax(np.abs(traj.t)))  # the state at T (T < 0: backwards)
    q = traj.quaternion[..., i, :]
    sing = bool(q[0] == 0)
    return {
        "t": float(traj.t[i]),
        "quaternion": q.tolist(),
        "omega": traj.omega[..., i, :].tolist(),
        "gibbs": None if sing else (q[1:] / q[0]).tolist(),
        "m": traj.m[..., i, :].tolist(),
        "energy": float(traj.energy[..., i]),
        "method": traj.method,
        "drift": {k: float(v) for k, v in drift.items()},
        "torque": _torque_records(traj.model),
        "integrals": {k: float(v[..., i]) for k, v in traj.integrals().items()},
    }


#: output samples above which ``simulate`` shows a progress bar on a terminal (the run is solved by the engine's
#: segments, :mod:`eulerpoisson.solvers.engine`, the same in every route)
CHUNKED_SAMPLES = 5000


def solve_run(model, t_end, samples, omega0, m0, q0, method, opts, progress, keep: bool = True):
    """The run of ``simulate`` in memory: the one engine's segments, with a progress bar on a terminal.

    The segments are those of every other route (:func:`eulerpoisson.solve`, a Zarr store, a sweep), so
    ``simulate`` gives the same bits whether it writes a NetCDF file, a Zarr store or nothing.

    ``keep=False`` (nothing is written): only the first and the last sample are kept and the drift of the
    integrals is accumulated segment by segment, so memory does not grow with the samples; returns
    ``(trajectory of those two samples, drift)``.
    """
    from ..io.stream import ProgressDisplay
    from ..model.drift import DriftAccumulator
    from ..solvers.engine import Segment, TimeGrid, collect, merge_stats, prepare_run
    from ..trajectory import Trajectory

    run = prepare_run(
        model,
        TimeGrid(0.0, t_end, samples),
        omega0=omega0,
        m0=m0,
        attitude0=q0,
        method=method,
        in_memory=keep,
        caller="simulate",
        **opts,
    )
    show = progress if (samples >= CHUNKED_SAMPLES or len(run.bounds) > 1) else False
    start = time.perf_counter()
    pieces: list[Segment] = []  # (keep)
    counters: list[dict] = []  # the segments' stats (not keep)
    acc = None if keep else DriftAccumulator(model)
    first = last = None
    with ProgressDisplay(show, samples, f"{run.method_name}: solving") as bar:
        for seg in run.segments():
            tr = seg.trajectory
            if acc is None:
                pieces.append(seg)
            else:
                acc.update(tr.t, tr.quaternion, tr.omega)
                first = tr[[0]] if first is None else first
                last = tr[[-1]]
                counters.append(tr.stats)
            bar.update(seg.stop)
    if acc is None:
        return collect(run, pieces)
    assert first is not None and last is not None  # at least one sample
    stats = merge_stats(run.method, counters)
    if len(counters) > 1:
        stats["segments"] = len(counters)
    stats["wall_time"] = time.perf_counter() - start
    ends = Trajectory(
        np.concatenate([first.t, last.t]),
        np.concatenate([first.quaternion, last.quaternion], axis=-2),
        np.concatenate([first.omega, last.omega], axis=-2),
        first.body,
        run.method_name,
        run.options,
        stats,
        torque=list(model.torques),
        keep_signs=True,  # the signs of the whole run at its two ends
    )
    return ends, acc.result()


def cmd_simulate(args) -> int:
    # the output is claimed (checked, locked) before the work and held until the command ends
    with contextlib.ExitStack() as claims:
        return _simulate(args, claims)


def _simulate(args, claims: contextlib.ExitStack) -> int:
    from ..attitude.core import quaternion_from_gibbs
    from ..model.equations import Model
    from ..solvers import available_methods
    from ..solvers.registry import check_supported

    cfg: dict = {}
    src: dict = {}
    if args.config is not None:
        cfg.update(config_from_toml(load_toml(args.config), args.config, src))
        # a file that contradicts itself is an error even when a flag would replace both values
        file_name = namer(src)
        for k1, k2, what in (
            ("initial.omega", "initial.m", "exactly one of"),
            ("initial.quaternion", "initial.gibbs", "at most one of"),
            ("body.inertia", "body.masses", "either"),
            ("body.inertia", "body.positions", "either"),
        ):
            if k1 in cfg and k2 in cfg:
                pre, a, b = pair(file_name, k1, k2)
                raise UsageError(f"{pre}give {what} {a} {'or' if what == 'either' else 'and'} {b}, not both")
    given = {
        key: getattr(args, attr)
        for attr, key in (
            ("inertia", "body.inertia"),
            ("omega", "initial.omega"),
            ("m", "initial.m"),
            ("quaternion", "initial.quaternion"),
            ("gibbs", "initial.gibbs"),
            ("t_end", "time.t_end"),
            ("samples", "time.samples"),
            ("method", "method.name"),
            ("allow_unphysical", "body.allow_unphysical"),
            *((opt, f"method.{opt}") for opt in METHOD_OPTIONS),
            ("out", "output.file"),
            # the torque flags of the registered torques (add_commands: dest = the flag without "--", "-" -> "_")
            *((FLAGS[key][2:].replace("-", "_"), key) for key in FLAGS if key.startswith("torque.")),
            ("workers", "compute.workers"),
        )
        if getattr(args, attr, None) is not None
    }
    # two flags that say the same thing differently are an error; a flag replaces what the file says
    if "initial.omega" in given and "initial.m" in given:
        raise UsageError(
            "give exactly one of --omega and --m (the initial body angular velocity or the angular momentum), not both"
        )
    if "initial.quaternion" in given and "initial.gibbs" in given:
        raise UsageError("give at most one of --quaternion and --gibbs (the initial attitude), not both")
    replaces = {
        "initial.omega": ("initial.m",),
        "initial.m": ("initial.omega",),
        "initial.quaternion": ("initial.gibbs",),
        "initial.gibbs": ("initial.quaternion",),
        "body.inertia": ("body.masses", "body.positions"),
    }
    for key, v in given.items():
        for other in replaces.get(key, ()):
            cfg.pop(other, None)
            src.pop(other, None)
        cfg[key] = v
        src[key] = FLAGS[key]
    name = namer(src)

    body = build_body(cfg, name)
    if "initial.omega" in cfg and "initial.m" in cfg:
        pre, a, b = pair(name, "initial.omega", "initial.m")
        raise UsageError(f"{pre}give exactly one of {a} and {b}, not both")
    if "initial.omega" not in cfg and "initial.m" not in cfg:
        raise UsageError(
            "give exactly one initial condition: --omega W1,W2,W3 (body angular velocity) or --m (angular momentum)"
        )
    omega0 = m0 = None
    if "initial.omega" in cfg:
        omega0 = parse_floats(cfg["initial.omega"], name("initial.omega"), (3,))
    else:
        m0 = parse_floats(cfg["initial.m"], name("initial.m"), (3,))
    if "initial.quaternion" in cfg and "initial.gibbs" in cfg:
        pre, a, b = pair(name, "initial.quaternion", "initial.gibbs")
        raise UsageError(f"{pre}give at most one of {a} and {b}, not both")
    q0 = None
    if "initial.quaternion" in cfg:
        q0 = np.array(parse_floats(cfg["initial.quaternion"], name("initial.quaternion"), (4,)))
        nrm = float(np.linalg.norm(q0))
        if abs(nrm - 1.0) > UNIT_QUATERNION_TOLERANCE:
            raise UsageError(
                f"{name('initial.quaternion')} must be a unit quaternion w,x,y,z (norm 1 within {UNIT_QUATERNION_TOLERANCE:g}); its norm is {nrm:.9g}"
            )
        q0 = q0 / nrm
    elif "initial.gibbs" in cfg:
        q0 = quaternion_from_gibbs(parse_floats(cfg["initial.gibbs"], name("initial.gibbs"), (3,)))
    if "time.t_end" not in cfg:
        raise UsageError("give the final time with --t-end T")
    try:
        t_end = float(cfg["time.t_end"])
    except (TypeError, ValueError):
        raise UsageError(f"{name('time.t_end')}: {cfg['time.t_end']!r} is not a number") from None
    if not math.isfinite(t_end):
        raise UsageError(
            f"{name('time.t_end')} must be a finite number (negative: backwards in time), got {cfg['time.t_end']!r}"
        )
    samples = cfg.get("time.samples", 1001)
    if isinstance(samples, str):
        try:
            samples = int(samples.strip())
        except ValueError:
            raise UsageError(f"{name('time.samples')} must be an integer >= 2, got {samples!r}") from None
    if samples < 2:
        raise UsageError(f"{name('time.samples')} must be an integer >= 2, got {samples}")
    if samples > MAX_SAMPLES:
        raise UsageError(
            f"{name('time.samples')} = {samples} is more than {MAX_SAMPLES:.3g} output times, which no "
            f"file or memory holds (a .zarr store of 1e8 samples is about 11 GB)"
        )
    out_name = cfg.get("output.file")
    if not (isinstance(out_name, str) and out_name.endswith(".zarr")):
        # a run written to NetCDF is held in memory; one written nowhere keeps its ends and the times only
        need = _memory_needed(samples, body.batch_shape) if out_name is not None else 16.0 * samples
        free = _memory_available()
        if free is not None and need > free:
            raise UsageError(
                f"{name('time.samples')} = {samples} needs about {need / 2**30:.3g} GiB in memory, more than the "
                f"{free / 2**30:.3g} GiB available; stream it to disk instead: --out run.zarr"
            )
    torques = build_torques(cfg, name)
    model = Model(body, torques)
    check_run_scales(model, omega0, m0, q0, t_end, name)  # numbers float64 can hold and follow (issue 22)
    # one rule with ep.solve: the most accurate method that can run the model (exact, else taylor, ...)
    from ..solvers.engine import default_method

    method = cfg.get("method.name") or default_method(model)
    if method not in available_methods():
        raise UsageError(
            f"{name('method.name')}: unknown method {method!r}; available: {', '.join(available_methods())}"
        )
    check_supported(method, model)  # UnsupportedModelError (one line, exit 2) names the methods that can
    opts = method_options(cfg, name, method)
    workers = cfg.get("compute.workers")
    if workers is not None:
        try:
            workers = int(str(workers).strip())
        except ValueError:
            workers = 0
        if workers < 1 and workers != -1:
            raise UsageError(
                f"{name('compute.workers')} must be a whole number of threads >= 1 (-1: every core), "
                f"got {cfg['compute.workers']!r}"
            )
        opts["workers"] = workers  # a keyword of solve, solve_from and solve_to_file, not a method option
    out = cfg.get("output.file")
    check_file_name(out, name("output.file"))
    as_json = bool(args.json or cfg.get("output.json", False))
    progress = False if (args.quiet or as_json) else None
    if out is not None and not str(out).endswith((".nc", ".nc4", ".netcdf", ".zarr")):
        raise UsageError(f"{name('output.file')} {out!r}: use a .nc (NetCDF) or .zarr (streamed) file name")
    if out is not None:
        # one policy for outputs: nothing replaced without --overwrite, never an input or another kind of file
        # claimed before the work: a second writer is refused at once, and the output is checked again under the
        # lock and just before the rename (a file that appeared meanwhile is not replaced without --overwrite)
        from ..io.outputs import claim_output

        zarr_out = str(out).endswith(".zarr")
        kind = "trajectory-store" if zarr_out else "netcdf"
        claims.enter_context(
            claim_output(out, kind, overwrite=bool(args.overwrite), inputs=[args.config], option=name("output.file"))
        )
    if out is not None and str(out).endswith(".zarr"):
        # long runs stream to disk chunk by chunk (atomic, resumable); the state at T is read back from the file
        from ..io.stream import partial_store, solve_to_file

        if partial_store(out).exists() and not args.overwrite and not args.quiet and not as_json:
            print(
                f"resuming the interrupted run to {out} from its finished chunks (--overwrite starts afresh)",
                file=sys.stderr,
            )
        start = time.perf_counter()
        with naming_target(out):
            try:
                solve_to_file(
                    model,
                    (0.0, t_end, samples),
                    out,
                    omega0=omega0,
                    m0=m0,
                    attitude0=q0,
                    method=method,
                    progress=progress,
                    resume=not args.overwrite,
                    overwrite=bool(args.overwrite),
                    **opts,
                )
            except KeyboardInterrupt:
                # name the folder that really holds the chunks, and the command that resumes (never --overwrite:
                # it starts afresh); the command line is known when this runs as the `eulerpoisson` program
                import shlex

                kept = partial_store(out)
                argv = sys.argv[1:] if os.path.basename(sys.argv[0] or "").startswith("eulerpoisson") else []
                again = [a for a in argv if a != "--overwrite"]
                how = "run the same command again" + (" without --overwrite" if args.overwrite else "") + " to resume"
                cmd = f": {shlex.join(['eulerpoisson', *again])}" if again else ""
                if not kept.exists():
                    msg = f"eulerpoisson: interrupted before any chunk of {out} was finished; nothing was kept"
                elif args.overwrite and os.path.exists(out):
                    msg = (
                        f"eulerpoisson: interrupted; the finished chunks are kept in {kept} (a hidden folder next "
                        f"to {out}, which is unchanged); remove {out} and {how}{cmd}"
                    )
                else:
                    msg = (
                        f"eulerpoisson: interrupted; the finished chunks are kept in {kept} (a hidden folder next "
                        f"to {out}); {how}{cmd}"
                    )
                print(msg, file=sys.stderr)
                raise
            except EulerPoissonError as exc:
                raise type(exc)(
                    str(exc)
                    .replace("pass overwrite=True", "run again with --overwrite")
                    .replace("overwrite=True", "--overwrite")
                ) from exc
        from ..trajectory import Trajectory

        store = Trajectory.open(out)  # lazy: only the two samples below are read
        traj = store[[0, len(store) - 1]]
        traj.stats["wall_time"] = time.perf_counter() - start
    else:
        if out is None:  # nothing is written: keep the ends and the drift only (bounded memory)
            traj, drift = solve_run(model, t_end, samples, omega0, m0, q0, method, opts, progress, keep=False)
        else:
            traj = solve_run(model, t_end, samples, omega0, m0, q0, method, opts, progress)
            traj.to_netcdf(out)
    if out is not None:
        drift = traj.drift()
    if as_json:
        print(json_text(_state_json(traj, drift)))  # strict JSON: null (and why) for a non-finite value
    elif not args.quiet:
        s = _state_json(traj, drift)
        print(f"{traj.method}: {samples} samples to t = {t_end:g}, wall time {traj.stats.get('wall_time', 0.0):.3g} s")
        if not model.is_free:
            print(f"  torque        {model.describe()}")
        print(f"  quaternion(T) = {np.round(s['quaternion'], 12).tolist()}")
        print(f"  omega(T)      = {np.round(s['omega'], 12).tolist()}")
        print(f"  energy        = {s['energy']:.15g}" + ("" if model.is_free else "  (kinetic + potential)"))
        print("  relative drift: " + ", ".join(f"{k} {v:.2e}" for k, v in drift.items()))
        if out is not None:
            print(f"  wrote {out}")
    return 0


def add_commands(sub) -> None:
    """Register ``simulate`` on the subcommand parser ``sub``."""
    from ..solvers import available_methods, get_method
    from .config import sync_torque_keys, torque_params, torque_toml_keys

    sync_torque_keys()  # torques registered since the import of the configuration get their flags and keys

    ex = argparse.RawDescriptionHelpFormatter
    s = sub.add_parser(
        "simulate",
        help="solve the motion of a body and print or save it",
        formatter_class=ex,
        description="Solve the motion of a rigid body, free or under torque, from an initial state.",
        epilog=(
            "examples:\n"
            "  eulerpoisson simulate --inertia 3,5,8 --omega 0,0.4,0.001 --t-end 50 --json\n"
            "  eulerpoisson simulate --inertia 1,2,3 --omega 1,0.1,0.5 --t-end 100 --method taylor --tol 1e-15 --out run.nc\n"
            "  eulerpoisson simulate run.toml --t-end 20     # flags override the file\n"
            "  eulerpoisson simulate --inertia 1,1,0.5 --omega 0,0,10 --gibbs 0.577,0,0 --com 0,0,0.25 --mass 1 \\\n"
            "      --gravity 0,0,-9.81 --t-end 15 --out top.nc     # a heavy top (taylor by default)\n"
            "  eulerpoisson plot top.nc --kind apex --out top_apex.png\n"
            "  eulerpoisson simulate examples/heavy_top.toml --t-end 5   # the same top from a file ([torque])\n"
            "  eulerpoisson simulate --inertia 1,2,3 --omega 0,0.001,0.001 --gravity-gradient 0.001 --t-end 6000 --json\n\n"
            "TOML file sections: [body] inertia=[...] | masses=[...], positions=[[...]...]; name\n"
            "  [initial] omega=[...] | m=[...]; quaternion=[w,x,y,z] | gibbs=[...]\n"
            "  [time] t_end, samples   [method] name, tol, dt, scheme, order, integrator, rtol, atol\n"
            "  [output] file, json\n"
            f"  [torque] {torque_toml_keys()}\n\n"
            "Torques: a heavy top is --com (centre of mass, body frame, from the fixed point; the inertia is about\n"
            "the fixed point) with --mass (default 1) and --gravity (default 0,0,-9.81); --gravity-gradient NU is a\n"
            "circular orbit of mean motion NU; --body-torque / --space-torque are constant torques. They add up.\n"
            "Under a torque the default method is taylor; rk and symplectic run them too (see --method)."
        ),
    )
    s.add_argument("config", nargs="?", help="optional TOML file describing the run")
    s.add_argument("--inertia", help="principal moments I1,I2,I3 or nine numbers of a full tensor (row-major)")
    s.add_argument("--omega", help="initial body angular velocity W1,W2,W3")
    s.add_argument("--m", help="initial spatial angular momentum m1,m2,m3 (instead of --omega)")
    s.add_argument("--quaternion", help="initial attitude w,x,y,z (unit, scalar first); default identity")
    s.add_argument("--gibbs", help="initial attitude as the Gibbs vector n1,n2,n3")
    s.add_argument("--t-end", dest="t_end", help="final time T (negative: the motion backwards from t = 0)")
    s.add_argument(
        "--allow-unphysical",
        dest="allow_unphysical",
        action="store_true",
        default=None,
        help="accept moments that violate the triangle inequality (e.g. 3,5,9: no mass distribution has them)",
    )
    s.add_argument("--samples", type=str, help="number of output times in [0, T] (default 1001)")
    s.add_argument(
        "--method", help="solution method: exact, taylor, symplectic, rk (default exact; taylor under a torque)"
    )
    for opt in METHOD_OPTIONS:  # every option of every method, read from the option dataclasses
        owners = "; ".join(
            f"{m}: default {get_method(m).options[opt]}" for m in available_methods() if opt in get_method(m).options
        )
        s.add_argument(
            "--" + opt.replace("_", "-"), dest=opt, metavar=opt.upper(), help=f"method option {opt} ({owners})"
        )
    for _, p in torque_params():  # every parameter of every registered torque (Torque.cli), in the registry's order
        s.add_argument(p.flag, dest=p.flag[2:].replace("-", "_"), metavar=p.metavar, help=p.help)
    s.add_argument("--out", help="write the trajectory to this NetCDF (.nc) file or stream it to a Zarr (.zarr) store")
    s.add_argument(
        "--json",
        action="store_true",
        help="print the state at T, the torques, the integrals at T and their drift as one JSON object",
    )
    s.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an existing output of the same kind (an interrupted .zarr run resumes without it)",
    )
    s.add_argument(
        "-j",
        "--workers",
        metavar="N",
        help="threads that solve a batch of bodies (default: $EULERPOISSON_WORKERS, else every core; "
        "1: one thread; -1: every core); the results do not depend on it",
    )
    s.add_argument("--quiet", action="store_true", help="print nothing but errors")
    s.set_defaults(func=cmd_simulate)
