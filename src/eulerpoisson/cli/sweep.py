"""The ``eulerpoisson sweep`` command: a sweep over inertia ratios and initial states, on Dask, into Zarr."""

from __future__ import annotations

import argparse
import os
import sys

from ..errors import EulerPoissonError
from .common import UsageError, check_file_name, naming_target

__all__ = ["add_commands", "cmd_sweep", "EXIT_NOTHING"]

#: exit status of a sweep that ran but computed nothing (every body not physical, with --allow-unphysical)
EXIT_NOTHING = 1


def _resume_command(args) -> str:
    """The command line that resumes this sweep (the same sweep, without --overwrite)."""
    import shlex

    words = ["eulerpoisson", "sweep", args.config]
    if args.out is not None:
        words += ["--out", args.out]
    if args.scheduler is not None:
        words += ["--scheduler", args.scheduler]
    if args.workers is not None:
        words += ["--workers", str(args.workers)]
    if args.allow_unphysical:
        words.append("--allow-unphysical")
    return shlex.join(words)


def _summary(path, counts: dict) -> str:
    """``wrote x.zarr: 35 points: 33 regular, 2 separatrix`` (only the statuses that occur)."""
    words = {
        "regular": "regular",
        "separatrix": "on the separatrix (infinite half-period)",
        "symmetric body": "of a symmetric body (no flips: half-period NaN)",
        "not a physical body": "not a physical body (NaN)",
        "unfinished": "not computed",
    }
    parts = [f"{counts[k]} {w}" for k, w in words.items() if counts.get(k)]
    return f"wrote {path}: {counts['points']} points: {', '.join(parts)}"


def cmd_sweep(args) -> int:
    from ..sweep.config import check_store_name
    from ..sweep.runner import load_config, run_sweep, sweep_summary

    check_file_name(args.config, "sweep file")
    check_file_name(args.out, "--out")
    if not os.path.exists(args.config):
        raise UsageError(f"sweep file {args.config!r} does not exist (see examples/sweep.toml)")
    if not os.path.isfile(args.config):
        raise UsageError(f"sweep file {args.config!r} is not a file")
    allow = True if args.allow_unphysical else None
    try:
        # with --out, the file's [output] path is not used (nor checked)
        cfg = load_config(args.config, path=args.out, allow_unphysical=allow)
    except UnicodeDecodeError as exc:
        raise UsageError(
            f"{args.config}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at position {exc.start}); "
            "a TOML file must be UTF-8"
        ) from None
    except EulerPoissonError as exc:
        raise _flag_words(exc) from exc
    from ..io.outputs import OutputLock, check_output
    from ..io.resumable import partial_store

    target = args.out if args.out is not None else cfg.path
    check_output(target, "sweep-store", overwrite=bool(args.overwrite), inputs=[args.config])
    if args.out is not None:
        try:
            check_store_name(args.out, "--out")
        except EulerPoissonError as exc:
            raise UsageError(str(exc)) from None
    try:
        with OutputLock(target), naming_target(target):
            path = run_sweep(
                cfg,
                path=target,
                scheduler=args.scheduler,
                workers=args.workers,
                progress=False if args.quiet else None,
                overwrite=args.overwrite,
            )
    except KeyboardInterrupt:
        kept = partial_store(target)
        if kept.exists():
            print(
                f"eulerpoisson: interrupted; the finished chunks are kept in {kept} (a hidden folder next to "
                f"{target}); to resume, run: {_resume_command(args)}",
                file=sys.stderr,
            )
        else:
            print("eulerpoisson: interrupted before any chunk was finished; nothing was written", file=sys.stderr)
        raise
    except (EulerPoissonError, OSError) as exc:
        # the library speaks of its keyword arguments; on the command line they are flags
        new = _flag_words(exc)
        if new is not exc:
            raise new from exc
        raise
    counts = sweep_summary(path)
    if counts["not a physical body"] == counts["points"]:
        print(
            f"eulerpoisson: error: nothing was computed: all {counts['points']} points of {path} are bodies "
            "that are not physical (status 3, every value NaN)",
            file=sys.stderr,
        )
        return EXIT_NOTHING
    if not args.quiet:
        print(_summary(path, counts))
    return 0


def _flag_words(exc: BaseException) -> BaseException:
    """``exc`` re-worded for the command line (``--overwrite``, ``--allow-unphysical``), or ``exc`` itself."""
    msg = str(exc)
    new = (
        msg.replace("pass overwrite=True", "run again with --overwrite")
        .replace("overwrite=True", "--overwrite")
        .replace("pass allow_unphysical=True", "run again with --allow-unphysical")
    )
    if new == msg:
        return exc
    return type(exc)(new) if isinstance(exc, EulerPoissonError) else EulerPoissonError(new)


def add_commands(sub) -> None:
    """Register ``sweep`` on the subcommand parser ``sub``."""
    ex = argparse.RawDescriptionHelpFormatter
    sw = sub.add_parser(
        "sweep",
        help="a grid or random sweep over inertia ratios and initial states, on Dask, into Zarr",
        formatter_class=ex,
        epilog=(
            "examples:\n"
            "  eulerpoisson sweep examples/sweep.toml --out atlas.zarr   # without --out: examples/atlas.zarr\n"
            "  eulerpoisson plot atlas.zarr --kind atlas --out atlas.png\n"
            "  eulerpoisson sweep examples/sweep.toml --scheduler serial --out atlas_serial.zarr   # one process\n\n"
            "A sweep file writes only inside its own folder ([output] path, a NAME.zarr there); --out writes\n"
            "anywhere. A Dask cluster elsewhere is named on the command line only, never by a sweep file:\n"
            "--scheduler tcp://HOST:8786 (its scheduler's address; its workers need eulerpoisson installed).\n"
            "A sweep in which no body is physical (e.g. I = 1,2,5) is refused; --allow-unphysical runs it.\n"
            "An interrupted sweep resumes where it stopped when run again. Exit status: 0 done, 1 nothing\n"
            "computed (every body not physical), 2 bad input."
        ),
    )
    sw.add_argument("config", help="TOML file describing the sweep (see examples/sweep.toml)")
    sw.add_argument(
        "--out",
        help="Zarr store NAME.zarr, anywhere (default: [output] path of the file, in the file's folder)",
    )
    sw.add_argument("--scheduler", help="'local' (default, an embedded cluster), 'serial', or tcp://HOST:PORT")
    sw.add_argument(
        "-j",
        "--workers",
        type=int,
        metavar="N",
        help="worker processes of the local cluster, or threads with --scheduler serial "
        "(default: [compute] workers, else every core); the results do not depend on it",
    )
    sw.add_argument("--overwrite", action="store_true", help="replace a store made with another configuration")
    sw.add_argument(
        "--allow-unphysical",
        dest="allow_unphysical",
        action="store_true",
        help="sweep bodies whose moments violate the triangle inequality (status 3, NaN results) instead of "
        "refusing them (default: [inertia] allow_unphysical, false)",
    )
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=cmd_sweep)
