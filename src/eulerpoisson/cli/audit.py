"""The ``eulerpoisson audit`` command: the paper's equations derived with SymPy (:mod:`eulerpoisson.paper.audit`)."""

from __future__ import annotations

import argparse

from .common import check_file_name

__all__ = ["add_commands", "cmd_audit"]


def cmd_audit(args) -> int:
    from ..paper.audit import run_audit, write_report

    check_file_name(args.out, "--out")
    if args.out is not None:
        from ..io.outputs import check_output

        check_output(args.out, "file", overwrite=bool(args.overwrite))  # before the 25 s of the audit
    report = run_audit()
    if args.out is not None:
        from ..io.outputs import OutputLock

        with OutputLock(args.out):
            write_report(report, args.format, args.out)
        if not args.quiet:
            print(f"wrote {args.out}")
    else:
        text = {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[args.format]()
        print(text)
    return 0


def add_commands(sub) -> None:
    """Register ``audit`` on the subcommand parser ``sub``."""
    ex = argparse.RawDescriptionHelpFormatter
    a = sub.add_parser(
        "audit",
        help="derive the paper's equations with SymPy and report which are confirmed",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson audit\n  eulerpoisson audit --format json --out audit.json\n  eulerpoisson audit --format tex --out audit.tex",
    )
    a.add_argument("--format", choices=["md", "json", "tex"], default="md", help="report format (default md)")
    a.add_argument("--out", help="write the report to this file instead of printing it")
    a.add_argument(
        "--overwrite", action="store_true", help="replace an existing report file (never a file of another kind)"
    )
    a.add_argument("--quiet", action="store_true")
    a.set_defaults(func=cmd_audit)
