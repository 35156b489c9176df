"""The ``eulerpoisson warmup`` command: compile every numba kernel into its on-disk cache (issue 15).

Run once after installing (``make demo`` runs it): the first run of a
method then loads its kernels from the cache (well under a second) instead
of compiling them (up to half a minute each). See
:mod:`eulerpoisson.util.warmup`.
"""

from __future__ import annotations

import argparse

from .common import UsageError

__all__ = ["add_commands", "cmd_warmup", "WARMUP_EXAMPLES"]

WARMUP_EXAMPLES = [
    "eulerpoisson warmup --list",
    "eulerpoisson warmup --only fit,plots",
    "eulerpoisson warmup --only plots -j 1 --quiet",
]


def cmd_warmup(args) -> int:
    from ..util.warmup import GROUPS, group_names, warmup

    if args.list:
        for g in GROUPS:
            print(f"{g.name:<16s} {g.title}")
        return 0
    only = None
    if args.only is not None:
        only = [n.strip() for n in str(args.only).split(",") if n.strip()]
        unknown = [n for n in only if n not in group_names()]
        if not only or unknown:
            raise UsageError(
                f"--only: unknown kernel group(s) {', '.join(map(repr, unknown)) or repr(args.only)}; "
                f"the groups are: {', '.join(group_names())} (see 'eulerpoisson warmup --list')"
            )
    if args.jobs is None:
        from ..solvers.parallel import available_cores

        jobs = available_cores()
    else:
        try:
            jobs = int(str(args.jobs).strip())
        except ValueError:
            jobs = 0
        if jobs < 1:
            raise UsageError(f"--jobs must be a whole number >= 1, got {args.jobs!r}")
    say = (lambda line: None) if args.quiet else (lambda line: print(line, flush=True))
    warmup(only, say=say, jobs=jobs)
    return 0


def add_commands(sub) -> None:
    """Register ``warmup`` on the subcommand parser ``sub``."""
    w = sub.add_parser(
        "warmup",
        help="compile every numba kernel into its on-disk cache (once, after installing)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Compile every numba kernel of eulerpoisson into numba's on-disk cache (the __pycache__ folders of "
            "the\ninstalled package, or $NUMBA_CACHE_DIR), one progress line per group of kernels and the total "
            "time.\nRun 'eulerpoisson warmup' once after installing ('make demo' does): compiling takes a minute "
            "or two of\nCPU time once (groups in parallel processes, -j); later runs load a method's kernels from "
            "the cache in\nwell under a second. Small problems need no kernel at all: NumPy solves them without "
            "importing numba."
        ),
        epilog="examples:\n" + "\n".join("  " + e for e in WARMUP_EXAMPLES),
    )
    w.add_argument(
        "--only", metavar="GROUP[,GROUP...]", help="compile these groups only (names from --list; default: every group)"
    )
    w.add_argument(
        "-j",
        "--jobs",
        metavar="N",
        help="groups compiled at the same time, one process each (default: every core; 1: one after "
        "the other in this process)",
    )
    w.add_argument("--list", action="store_true", help="list the kernel groups and exit")
    w.add_argument("--quiet", action="store_true", help="print nothing but errors")
    w.set_defaults(func=cmd_warmup)
