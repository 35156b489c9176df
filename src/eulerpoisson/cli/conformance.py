"""``eulerpoisson conformance``: physics engines held against the exact motion of a free rigid body.

Runs each engine x setting x case x step (a cell; cells found in the cells folder are not run again),
writes the table (Markdown, CSV, JSON) and a work-precision figure per case into ``--out``. Exit 0 when
it ran (an engine that is not installed is listed with its reason), 2 on bad input (one line).
Progress goes to standard error, one line per cell.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

from .common import UsageError, check_file_name, json_text

__all__ = ["add_commands", "cmd_conformance"]

EXAMPLES = [
    "eulerpoisson conformance --list",
    "eulerpoisson conformance --engine mujoco --setting RK4 --case racket_near_separatrix --dt 1e-2 --max-steps 2000",
    "eulerpoisson conformance --engine mujoco,pybullet --case spin_largest_axis --dt 1e-2,1e-3 --max-steps 1010 "
    "--out report --no-plots --json",
]


def _names(values) -> list[str]:
    """Repeated and comma-separated values, in order, without repeats."""
    out: list[str] = []
    for v in values or []:
        for part in str(v).split(","):
            part = part.strip()
            if part and part not in out:
                out.append(part)
    return out


def _dts(values) -> list[float]:
    out = []
    for text in _names(values):
        try:
            x = float(text)
        except ValueError:
            raise UsageError(f"--dt: {text!r} is not a number (a step size in seconds, e.g. 1e-3)") from None
        if not (math.isfinite(x) and x > 0):
            raise UsageError(f"--dt must be positive step sizes in seconds, got {text!r}")
        out.append(x)
    return out


def _list_text() -> str:
    from ..oracle.cases import CONFORMANCE_CASE_NAMES
    from ..oracle.engines import all_engines

    lines = ["engines (setting: what it is):"]
    for e in all_engines():
        ok, why = e.available()
        state = f"version {e.version()}" if ok else f"not available: {why}"
        lines.append(f"  {e.name} ({e.title}, pip install {e.package}): {state}")
        lines += [f"    {s}: {d}" for s, d in e.settings.items()]
    lines.append("cases: " + ", ".join(CONFORMANCE_CASE_NAMES) + " (or any case of 'eulerpoisson cases')")
    return "\n".join(lines)


def cmd_conformance(args) -> int:
    from ..errors import InvalidInputError
    from ..oracle.conformance import DEFAULT_DTS, run_matrix, write_report

    if args.list:
        print(_list_text())
        return 0
    check_file_name(args.out, "--out")
    check_file_name(args.cells, "--cells")
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise UsageError(f"--out {args.out!r} is a file; give a folder for the report")
    cells = args.cells if args.cells is not None else os.path.join(args.out, "cells")
    if os.path.exists(cells) and not os.path.isdir(cells):
        raise UsageError(f"--cells {cells!r} is a file; give a folder for the cells")
    if args.jobs < 1:
        raise UsageError(f"--jobs must be a positive number of processes, got {args.jobs}")
    if args.max_steps is not None and args.max_steps < 1:
        raise UsageError(f"--max-steps must be a positive number of steps, got {args.max_steps}")
    dts = _dts(args.dt) or list(DEFAULT_DTS)

    def progress(line: str) -> None:
        if not args.quiet:
            print(f"eulerpoisson: conformance: {line}", file=sys.stderr, flush=True)

    try:
        report = run_matrix(
            _names(args.engine) or None,
            _names(args.case) or None,
            dts,
            cells,
            settings=_names(args.setting) or None,
            max_steps=args.max_steps,
            redo=bool(args.redo),
            jobs=args.jobs,
            progress=progress,
        )
    except InvalidInputError as exc:
        raise UsageError(str(exc).splitlines()[0]) from None
    files = write_report(report, args.out, plots=not args.no_plots)
    missing = [n for n, e in report["engines"].items() if not e["available"]]
    if args.json:
        summary = {k: v for k, v in report.items() if k != "cells"}
        summary["cells"] = report["cells"]
        summary["files"] = files
        print(json_text(summary))
    elif not args.quiet:
        ran = len(report["cells"])
        print(
            f"{ran} cells ({len(report['engines']) - len(missing)} engines, {len(report['cases'])} cases, "
            f"{len(report['dts'])} steps) in {report['wall_s']:.0f} s; wrote {len(files)} files into {args.out}"
            + (f"; not available here: {', '.join(missing)}" if missing else "")
        )
    return 0


def add_commands(sub) -> None:
    """Add ``conformance`` to the subcommands ``sub`` of the ``eulerpoisson`` parser."""
    c = sub.add_parser(
        "conformance",
        help="hold physics engines (MuJoCo, PyBullet, Drake, ...) against the exact free rigid-body motion",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run the conformance cases in each installed physics engine, with each of its rotational "
        "settings and step sizes, and compare every run with the exact motion: the attitude error at 10 and "
        "100 natural periods, the flips, the energy and momentum drift, the wall time per step. Writes "
        "table.md, table.csv, report.json and a work-precision figure per case. Cells already run (in "
        "--cells) are skipped. Exit 0, 2 on bad input.",
        epilog="examples:\n"
        + "\n".join(f"  {e}" for e in EXAMPLES)
        + "\n\nThe whole report (every engine, case and step; about 20 minutes with two workers): 'make conformance', "
        "or 'eulerpoisson conformance --jobs 2' with the engines installed.",
    )
    c.add_argument("--engine", action="append", metavar="NAME[,NAME...]", help="engines to run (default: all)")
    c.add_argument("--setting", action="append", metavar="NAME[,NAME...]", help="only these engine settings")
    c.add_argument("--case", action="append", metavar="NAME[,NAME...]", help="cases (default: the conformance cases)")
    c.add_argument("--dt", action="append", metavar="DT[,DT...]", help="step sizes in seconds (default 1e-2,1e-3,1e-4)")
    c.add_argument("--out", default="conformance", help="folder of the report (default conformance/)")
    c.add_argument("--cells", help="folder of the cell files (default OUT/cells)")
    c.add_argument("--max-steps", dest="max_steps", type=int, help="step budget of one run (default: per engine)")
    c.add_argument("--redo", action="store_true", help="run the cells found in --cells again")
    c.add_argument("--jobs", type=int, default=1, help="worker processes, one engine setting each (default 1)")
    c.add_argument("--no-plots", dest="no_plots", action="store_true", help="no figures")
    c.add_argument("--json", action="store_true", help="print the report as one JSON object")
    c.add_argument("--list", action="store_true", help="list the engines, their settings and the cases, and exit")
    c.add_argument("--quiet", action="store_true", help="no progress lines")
    c.set_defaults(func=cmd_conformance)
