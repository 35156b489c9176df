"""The ``eulerpoisson sweep`` command: a sweep over inertia ratios and initial states, on Dask, into Zarr."""

from __future__ import annotations

import argparse
import os

from ..errors import EulerPoissonError
from .common import UsageError, check_file_name, naming_target

__all__ = ["add_commands", "cmd_sweep"]


def cmd_sweep(args) -> int:
    from ..sweep.runner import load_config, run_sweep

    check_file_name(args.config, "sweep file")
    check_file_name(args.out, "--out")
    if not os.path.exists(args.config):
        raise UsageError(f"sweep file {args.config!r} does not exist (see examples/sweep.toml)")
    if not os.path.isfile(args.config):
        raise UsageError(f"sweep file {args.config!r} is not a file")
    try:
        cfg = load_config(args.config)
    except UnicodeDecodeError as exc:
        raise UsageError(
            f"{args.config}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at position {exc.start}); "
            "a TOML file must be UTF-8"
        ) from None
    from ..io.outputs import OutputLock, check_output

    target = args.out if args.out is not None else cfg.path
    check_output(target, "sweep-store", overwrite=bool(args.overwrite), inputs=[args.config])
    try:
        with OutputLock(target), naming_target(target):
            path = run_sweep(
                cfg,
                path=args.out,
                scheduler=args.scheduler,
                workers=args.workers,
                progress=False if args.quiet else None,
                overwrite=args.overwrite,
            )
    except (EulerPoissonError, OSError) as exc:
        # the library speaks of its keyword argument; on the command line it is a flag
        msg = str(exc)
        if "overwrite=True" in msg:
            raise EulerPoissonError(
                msg.replace("pass overwrite=True", "run again with --overwrite").replace(
                    "overwrite=True", "--overwrite"
                )
            ) from exc
        raise
    if not args.quiet:
        print(f"wrote {path}")
    return 0


def add_commands(sub) -> None:
    """Register ``sweep`` on the subcommand parser ``sub``."""
    ex = argparse.RawDescriptionHelpFormatter
    sw = sub.add_parser(
        "sweep",
        help="a grid or random sweep over inertia ratios and initial states, on Dask, into Zarr",
        formatter_class=ex,
        epilog=(
            "examples:\n"
            "  eulerpoisson sweep examples/sweep.toml        # writes atlas.zarr (the file's [output] path)\n"
            "  eulerpoisson plot atlas.zarr --kind atlas --out atlas.png\n"
            "  eulerpoisson sweep examples/sweep.toml --scheduler serial --out atlas_serial.zarr   # one process\n\n"
            "A Dask cluster elsewhere is named on the command line only, never by a sweep file:\n"
            "--scheduler tcp://HOST:8786 (its scheduler's address; its workers need eulerpoisson installed).\n"
            "An interrupted sweep resumes where it stopped when run again."
        ),
    )
    sw.add_argument("config", help="TOML file describing the sweep (see examples/sweep.toml)")
    sw.add_argument("--out", help="Zarr store (default: [output] path of the file)")
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
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=cmd_sweep)
