"""The ``eulerpoisson`` command line.

Commands: ``simulate``, ``audit``, ``plot``, ``animate``, ``info``, ``demo``.
Bad input prints one line that says what is wrong and exits with status 2
(``--debug`` shows the traceback instead).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

from .errors import EulerPoissonError

__all__ = ["main"]

EXIT_USAGE = 2


class UsageError(EulerPoissonError, ValueError):
    """Bad command-line input (exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message):  # noqa: D401 - argparse API
        raise UsageError(f"{self.prog}: {message} (see '{self.prog} --help')")


# ---------------------------------------------------------------------------
# parsing helpers
# ---------------------------------------------------------------------------
def _floats(text, name: str, sizes: tuple[int, ...]) -> list[float]:
    if isinstance(text, (list, tuple)):
        vals = text
    else:
        parts = [p for p in str(text).replace(";", ",").replace(" ", ",").split(",") if p != ""]
        vals = []
        for p in parts:
            try:
                vals.append(float(p))
            except ValueError:
                raise UsageError(f"{name}: {p!r} is not a number (expected {' or '.join(map(str, sizes))} comma-separated numbers)") from None
    try:
        arr = np.asarray(vals, dtype=float)
    except (TypeError, ValueError):
        raise UsageError(f"{name}: expected numbers, got {text!r}") from None
    arr = arr.ravel()
    if arr.size not in sizes:
        raise UsageError(f"{name}: expected {' or '.join(map(str, sizes))} numbers, got {arr.size} ({text!r})")
    if not np.all(np.isfinite(arr)):
        raise UsageError(f"{name}: values must be finite, got {text!r}")
    return arr.tolist()


def _inertia_from(value, name="--inertia"):
    v = _floats(value, name, (3, 9))
    return np.array(v) if len(v) == 3 else np.array(v).reshape(3, 3)


def _load_toml(path: str) -> dict:
    import tomllib

    p = Path(path)
    if not p.exists():
        raise UsageError(f"configuration file {path!r} does not exist")
    try:
        with open(p, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise UsageError(f"{path}: invalid TOML: {exc}") from None


_TOML_KEYS = {
    "body": {"inertia", "masses", "positions", "name"},
    "initial": {"omega", "m", "quaternion", "gibbs"},
    "time": {"t_end", "samples"},
    "method": {"name", "tol", "dt", "scheme", "order", "integrator", "rtol", "atol"},
    "output": {"file", "json"},
}


def _config_from_toml(cfg: dict, path: str) -> dict:
    out: dict = {}
    for section, body in cfg.items():
        if section not in _TOML_KEYS:
            raise UsageError(f"{path}: unknown section [{section}]; known: {', '.join(sorted(_TOML_KEYS))}")
        if not isinstance(body, dict):
            raise UsageError(f"{path}: [{section}] must be a table")
        unknown = set(body) - _TOML_KEYS[section]
        if unknown:
            raise UsageError(
                f"{path}: unknown key(s) {', '.join(sorted(unknown))} in [{section}]; known: {', '.join(sorted(_TOML_KEYS[section]))}"
            )
        for k, v in body.items():
            out[f"{section}.{k}"] = v
    return out


# ---------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------
def _build_body(cfg):
    from .body import RigidBody

    name = cfg.get("body.name")
    if "body.masses" in cfg or "body.positions" in cfg:
        if "body.inertia" in cfg:
            raise UsageError("give either body.inertia or body.masses/body.positions, not both")
        if "body.masses" not in cfg or "body.positions" not in cfg:
            raise UsageError("a point-mass body needs both body.masses and body.positions")
        return RigidBody.from_particles(cfg["body.masses"], cfg["body.positions"], name=name)
    if "body.inertia" not in cfg:
        raise UsageError("no body given: use --inertia I1,I2,I3 (or nine numbers) or a TOML file with [body]")
    inertia = cfg["body.inertia"]
    if isinstance(inertia, list) and inertia and isinstance(inertia[0], list):
        inertia = [x for row in inertia for x in row]
    return RigidBody(_inertia_from(inertia, "inertia"), name=name)


def _method_options(cfg) -> dict:
    opts = {}
    for key in ("tol", "dt", "rtol", "atol"):
        if cfg.get(f"method.{key}") is not None:
            try:
                opts[key] = float(cfg[f"method.{key}"])
            except (TypeError, ValueError):
                raise UsageError(f"--{key}: {cfg[f'method.{key}']!r} is not a number") from None
            if not (math.isfinite(opts[key]) and opts[key] > 0):
                raise UsageError(f"--{key} must be a positive number, got {cfg[f'method.{key}']!r}")
    for key in ("scheme", "integrator"):
        if cfg.get(f"method.{key}") is not None:
            opts[key] = str(cfg[f"method.{key}"])
    if cfg.get("method.order") is not None:
        opts["order"] = int(cfg["method.order"])
    return opts


def _state_json(traj, drift) -> dict:
    i = int(np.argmax(traj.t))
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
    }


#: output samples above which ``simulate`` works in chunks (and shows a progress bar on a terminal)
CHUNKED_SAMPLES = 5000
CHUNKS = 50


def _solve_in_chunks(body, t, omega0, m0, q0, method, opts, progress):
    """``solve`` over increasing output times, in chunks, with a progress bar on a terminal.

    The chunking depends only on the number of samples (never on whether a
    terminal is attached), so a run gives the same numbers everywhere. The
    closed form evaluates every chunk from the initial state (identical to one
    call); stepping methods continue each chunk from the last state of the
    previous one, as :func:`eulerpoisson.stream.solve_to_file` does.
    """
    from .solvers import get_method, solve
    from .stream import _Progress
    from .trajectory import Trajectory

    if t.size < CHUNKED_SAMPLES:
        return solve(body, t, omega0=omega0, m0=m0, attitude0=q0, method=method, **opts)
    closed_form = get_method(method).order is None
    pieces = np.array_split(np.arange(t.size), CHUNKS)
    qs, ws, wall = [], [], 0.0
    first = None
    with _Progress(progress, t.size, f"{method}: solving") as bar:
        done = 0
        for idx in pieces:
            if closed_form or first is None:
                tr = solve(body, t[idx], omega0=omega0, m0=m0, attitude0=q0, method=method, **opts)
            else:
                t0 = t[qs_end_index]
                tr = solve(body, t[idx] - t0, omega0=ws[-1][-1], attitude0=qs[-1][-1], method=method, **opts)
            first = tr if first is None else first
            qs.append(tr.quaternion)
            ws.append(tr.omega)
            qs_end_index = idx[-1]
            wall += tr.stats.get("wall_time", 0.0)
            done += idx.size
            bar.update(done)
    stats = dict(first.stats, wall_time=wall, chunks=len(pieces))
    return Trajectory(t, np.concatenate(qs, axis=-2), np.concatenate(ws, axis=-2), first.body, method, first.options, stats)


def cmd_simulate(args) -> int:
    from .attitude import quaternion_from_gibbs
    from .solvers import available_methods, solve

    cfg: dict = {}
    if args.config:
        cfg.update(_config_from_toml(_load_toml(args.config), args.config))
    flag_map = {
        "inertia": "body.inertia",
        "omega": "initial.omega",
        "m": "initial.m",
        "quaternion": "initial.quaternion",
        "gibbs": "initial.gibbs",
        "t_end": "time.t_end",
        "samples": "time.samples",
        "method": "method.name",
        "tol": "method.tol",
        "dt": "method.dt",
        "scheme": "method.scheme",
        "out": "output.file",
    }
    for attr, key in flag_map.items():
        v = getattr(args, attr, None)
        if v is not None:
            cfg[key] = v
            if key == "initial.omega":
                cfg.pop("initial.m", None)
            if key == "initial.m":
                cfg.pop("initial.omega", None)
            if key == "initial.quaternion":
                cfg.pop("initial.gibbs", None)
            if key == "initial.gibbs":
                cfg.pop("initial.quaternion", None)
            if key == "body.inertia":
                cfg.pop("body.masses", None)
                cfg.pop("body.positions", None)

    body = _build_body(cfg)
    if ("initial.omega" in cfg) == ("initial.m" in cfg):
        raise UsageError("give exactly one initial condition: --omega W1,W2,W3 (body angular velocity) or --m (angular momentum)")
    omega0 = m0 = None
    if "initial.omega" in cfg:
        omega0 = _floats(cfg["initial.omega"], "--omega", (3,))
    else:
        m0 = _floats(cfg["initial.m"], "--m", (3,))
    if "initial.quaternion" in cfg and "initial.gibbs" in cfg:
        raise UsageError("give at most one of --quaternion and --gibbs")
    q0 = None
    if "initial.quaternion" in cfg:
        q0 = np.array(_floats(cfg["initial.quaternion"], "--quaternion", (4,)))
        nrm = float(np.linalg.norm(q0))
        if abs(nrm - 1.0) > 1e-6:
            raise UsageError(
                f"--quaternion must be a unit quaternion w,x,y,z (norm 1 within 1e-6); its norm is {nrm:.9g}"
            )
        q0 = q0 / nrm
    elif "initial.gibbs" in cfg:
        q0 = quaternion_from_gibbs(_floats(cfg["initial.gibbs"], "--gibbs", (3,)))
    if "time.t_end" not in cfg:
        raise UsageError("give the final time with --t-end T")
    try:
        t_end = float(cfg["time.t_end"])
    except (TypeError, ValueError):
        raise UsageError(f"--t-end: {cfg['time.t_end']!r} is not a number") from None
    if not math.isfinite(t_end) or t_end < 0:
        raise UsageError(f"--t-end must be a finite number >= 0, got {cfg['time.t_end']!r}")
    samples = cfg.get("time.samples", 1001)
    try:
        samples = int(samples)
    except (TypeError, ValueError):
        raise UsageError(f"--samples must be an integer >= 2, got {samples!r}") from None
    if samples < 2:
        raise UsageError(f"--samples must be an integer >= 2, got {samples}")
    method = str(cfg.get("method.name", "exact"))
    if method not in available_methods():
        raise UsageError(f"--method: unknown method {method!r}; available: {', '.join(available_methods())}")
    opts = _method_options(cfg)
    out = cfg.get("output.file")
    if out and str(out).endswith(".zarr"):
        # long runs stream to disk chunk by chunk (atomic, resumable); the final state is read back
        from .stream import solve_to_file

        solve_to_file(body, (0.0, t_end, samples), out, omega0=omega0, m0=m0, attitude0=q0, method=method,
                      progress=False if (args.quiet or args.json) else None, overwrite=True, **opts)
        traj = solve(body, np.array([0.0, t_end]), omega0=omega0, m0=m0, attitude0=q0, method=method, **opts)
    else:
        t = np.linspace(0.0, t_end, samples)
        progress = False if (args.quiet or args.json) else None
        traj = _solve_in_chunks(body, t, omega0, m0, q0, method, opts, progress)
        if out:
            if not str(out).endswith((".nc", ".nc4", ".netcdf")):
                raise UsageError(f"--out {out!r}: use a .nc (NetCDF) or .zarr (streamed) file name")
            traj.to_netcdf(out)
    drift = traj.drift()
    if args.json:
        print(json.dumps(_state_json(traj, drift)))
    elif not args.quiet:
        s = _state_json(traj, drift)
        print(f"{traj.method}: {samples} samples to t = {t_end:g}, wall time {traj.stats.get('wall_time', 0.0):.3g} s")
        print(f"  quaternion(T) = {np.round(s['quaternion'], 12).tolist()}")
        print(f"  omega(T)      = {np.round(s['omega'], 12).tolist()}")
        print(f"  energy        = {s['energy']:.15g}")
        print("  relative drift: " + ", ".join(f"{k} {v:.2e}" for k, v in drift.items()))
        if out:
            print(f"  wrote {out}")
    return 0


# ---------------------------------------------------------------------------
# other commands
# ---------------------------------------------------------------------------
def cmd_audit(args) -> int:
    from .audit import run_audit, write_report

    report = run_audit()
    if args.out:
        write_report(report, args.format, args.out)
        if not args.quiet:
            print(f"wrote {args.out}")
    else:
        text = {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[args.format]()
        print(text)
    return 0


def _read_traj(path):
    from .trajectory import Trajectory

    if not os.path.exists(path):
        raise UsageError(f"{path}: no such file (write one with 'eulerpoisson simulate ... --out {path}')")
    return Trajectory.from_netcdf(path)


def cmd_plot(args) -> int:
    out = args.out or f"{Path(args.file).stem}_{args.kind}.png"
    if args.kind == "atlas":
        from .sweep import load_sweep, plot_atlas

        if not os.path.exists(args.file):
            raise UsageError(f"{args.file}: no such sweep store (make one with 'eulerpoisson sweep sweep.toml')")
        plot_atlas(load_sweep(args.file), out)
    else:
        from . import plots

        traj = _read_traj(args.file)
        plots.plot(traj, args.kind, out=out)
    if not args.quiet:
        print(f"wrote {out}")
    return 0


def cmd_animate(args) -> int:
    from .animate import animate

    traj = _read_traj(args.file)
    animate(traj, args.out, fps=args.fps)
    if not args.quiet:
        print(f"wrote {args.out}")
    return 0


def cmd_info(args) -> int:
    traj = _read_traj(args.file)
    b = traj.body
    lines = [
        f"{args.file}: eulerpoisson trajectory",
        f"  method      {traj.method} {json.dumps(traj.options) if traj.options else ''}".rstrip(),
        f"  samples     {len(traj.t)}, t from {traj.t.min():.6g} to {traj.t.max():.6g}",
    ]
    if traj.batch_shape:
        lines.append(f"  bodies      batch of shape {traj.batch_shape}")
    else:
        lines.append(f"  body        {b!r}")
        lines.append(f"  energy      {float(traj.energy[0]):.15g}")
        lines.append(f"  m           {np.round(traj.m[0], 12).tolist()}")
    lines.append("  drift       " + ", ".join(f"{k} {np.max(v):.2e}" for k, v in traj.drift().items()))
    print("\n".join(lines))
    return 0


def cmd_sweep(args) -> int:
    from .sweep import load_config, run_sweep

    if not os.path.exists(args.config):
        raise UsageError(f"sweep file {args.config!r} does not exist (see examples/sweep.toml)")
    path = run_sweep(
        load_config(args.config),
        path=args.out,
        scheduler=args.scheduler,
        workers=args.workers,
        progress=False if args.quiet else None,
        overwrite=args.overwrite,
    )
    if not args.quiet:
        print(f"wrote {path}")
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    return run_demo(args.out, quiet=args.quiet)


# ---------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    p = _Parser(
        prog="eulerpoisson",
        description="The free rigid body in the Gibbs rotation vector n = k tan(alpha/2): "
        "exact motion, integrators, the paper's audit, files and pictures.",
        epilog="Run 'eulerpoisson COMMAND --help' for a command's options and examples.",
    )
    p.add_argument("--version", action="version", version=f"eulerpoisson {__version__}")
    p.add_argument("--debug", action="store_true", help="show tracebacks instead of one-line errors")
    sub = p.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")

    ex = argparse.RawDescriptionHelpFormatter
    s = sub.add_parser(
        "simulate",
        help="solve the motion of a body and print or save it",
        formatter_class=ex,
        description="Solve the free rigid body from an initial state.",
        epilog=(
            "examples:\n"
            "  eulerpoisson simulate --inertia 3,5,9 --omega 0,0.4,0.001 --t-end 50 --json\n"
            "  eulerpoisson simulate --inertia 1,2,3 --omega 1,0.1,0.5 --t-end 100 --method taylor --tol 1e-15 --out run.nc\n"
            "  eulerpoisson simulate run.toml --t-end 20     # flags override the file\n\n"
            "TOML file sections: [body] inertia=[...] | masses=[...], positions=[[...]...]; name\n"
            "  [initial] omega=[...] | m=[...]; quaternion=[w,x,y,z] | gibbs=[...]\n"
            "  [time] t_end, samples   [method] name, tol, dt, scheme   [output] file"
        ),
    )
    s.add_argument("config", nargs="?", help="optional TOML file describing the run")
    s.add_argument("--inertia", help="principal moments I1,I2,I3 or nine numbers of a full tensor (row-major)")
    s.add_argument("--omega", help="initial body angular velocity W1,W2,W3")
    s.add_argument("--m", help="initial spatial angular momentum m1,m2,m3 (instead of --omega)")
    s.add_argument("--quaternion", help="initial attitude w,x,y,z (unit, scalar first); default identity")
    s.add_argument("--gibbs", help="initial attitude as the Gibbs vector n1,n2,n3")
    s.add_argument("--t-end", dest="t_end", help="final time T >= 0")
    s.add_argument("--samples", type=str, help="number of output times in [0, T] (default 1001)")
    s.add_argument("--method", help="solution method (default exact)")
    s.add_argument("--tol", help="tolerance for adaptive methods")
    s.add_argument("--dt", help="step size for fixed-step methods")
    s.add_argument("--scheme", help="scheme of the symplectic method (gauss2, gauss4, gauss6, ...)")
    s.add_argument("--out", help="write the trajectory to this NetCDF file")
    s.add_argument("--json", action="store_true", help="print the state at T as one JSON object")
    s.add_argument("--quiet", action="store_true", help="print nothing but errors")
    s.set_defaults(func=cmd_simulate)

    a = sub.add_parser(
        "audit",
        help="derive the paper's equations with SymPy and report which are confirmed",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson audit\n  eulerpoisson audit --format json --out audit.json\n  eulerpoisson audit --format tex --out audit.tex",
    )
    a.add_argument("--format", choices=["md", "json", "tex"], default="md", help="report format (default md)")
    a.add_argument("--out", help="write the report to this file instead of printing it")
    a.add_argument("--quiet", action="store_true")
    a.set_defaults(func=cmd_audit)

    pl = sub.add_parser(
        "plot",
        help="draw a figure from a trajectory file",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson plot run.nc --kind omega --out omega.png\n  eulerpoisson plot run.nc --kind polhode --out polhode.pdf",
    )
    pl.add_argument("file", help="trajectory NetCDF file written by 'simulate --out' (or a sweep store for --kind atlas)")
    pl.add_argument("--kind", required=True, choices=["omega", "invariants", "polhode", "gibbs", "attitude", "atlas"])
    pl.add_argument("--out", help="figure file (.png, .svg or .pdf)")
    pl.add_argument("--quiet", action="store_true")
    pl.set_defaults(func=cmd_plot)

    an = sub.add_parser(
        "animate",
        help="animate the tumbling body (self-contained HTML, GIF or MP4)",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson animate run.nc --out movie.html\n  eulerpoisson animate run.nc --out movie.gif",
    )
    an.add_argument("file", help="trajectory NetCDF file")
    an.add_argument("--out", required=True, help="movie.html, movie.gif or movie.mp4")
    an.add_argument("--fps", type=int, default=30)
    an.add_argument("--quiet", action="store_true")
    an.set_defaults(func=cmd_animate)

    sw = sub.add_parser(
        "sweep",
        help="a grid or random sweep over inertia ratios and initial states, on Dask, into Zarr",
        formatter_class=ex,
        epilog=(
            "examples:\n  eulerpoisson sweep examples/sweep.toml\n"
            "  eulerpoisson sweep atlas.toml --scheduler tcp://10.0.0.5:8786 --out atlas.zarr\n"
            "  eulerpoisson plot atlas.zarr --kind atlas --out atlas.png\n\n"
            "An interrupted sweep resumes where it stopped when run again."
        ),
    )
    sw.add_argument("config", help="TOML file describing the sweep (see examples/sweep.toml)")
    sw.add_argument("--out", help="Zarr store (default: [output] path of the file)")
    sw.add_argument("--scheduler", help="'local' (default, an embedded cluster), 'serial', or tcp://HOST:PORT")
    sw.add_argument("--workers", type=int, help="workers of the local cluster")
    sw.add_argument("--overwrite", action="store_true", help="replace a store made with another configuration")
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=cmd_sweep)

    i = sub.add_parser("info", help="describe a trajectory file", epilog="example:\n  eulerpoisson info run.nc", formatter_class=ex)
    i.add_argument("file")
    i.set_defaults(func=cmd_info)

    d = sub.add_parser(
        "demo",
        help="the showcase: the tennis-racket effect, figures, animation and audit",
        epilog="example:\n  eulerpoisson demo --out out",
        formatter_class=ex,
    )
    d.add_argument("--out", default="out", help="output folder (default out/)")
    d.add_argument("--quiet", action="store_true")
    d.set_defaults(func=cmd_demo)
    return p


def main(argv=None) -> int:
    """Entry point of the ``eulerpoisson`` command; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        if not getattr(args, "command", None):
            parser.print_help()
            return EXIT_USAGE
        return int(args.func(args) or 0)
    except SystemExit as exc:  # --help / --version
        return int(exc.code or 0) if isinstance(exc.code, int) else 0
    except KeyboardInterrupt:
        print("eulerpoisson: interrupted", file=sys.stderr)
        return 130
    except (EulerPoissonError, ValueError, TypeError, FileNotFoundError, ImportError, OSError) as exc:
        if debug:
            raise
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if not isinstance(exc, UsageError):
            msg = f"eulerpoisson: error: {msg}"
        print(msg, file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
