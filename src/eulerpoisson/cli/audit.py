"""The ``eulerpoisson audit`` command: the paper's equations derived with SymPy (:mod:`eulerpoisson.paper.audit`)."""

from __future__ import annotations

import argparse

from .common import check_file_name

__all__ = ["add_commands", "cmd_audit"]


def cmd_audit(args) -> int:
    from ..paper.audit import run_audit

    check_file_name(args.out, "--out")
    if args.out is None:
        report = run_audit()
        text = {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[args.format]()
        print(text)
        return 0
    from ..io.atomic import atomic_write_text
    from ..io.outputs import claim_output, mark_text

    # claimed before the 25 s of the audit: a second writer is refused at once, a file that appears meanwhile
    # is not replaced; --overwrite replaces only an audit report of ours (recognized by its marker)
    with claim_output(args.out, "audit-report", overwrite=bool(args.overwrite), option="--out"):
        report = run_audit()
        text = {"md": report.to_markdown, "json": report.to_json, "tex": report.to_latex}[args.format]()
        atomic_write_text(args.out, mark_text(text, "audit-report", args.format))
    if not args.quiet:
        print(f"wrote {args.out}")
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
        "--overwrite", action="store_true", help="replace an audit report written before (never a file of another kind)"
    )
    a.add_argument("--quiet", action="store_true")
    a.set_defaults(func=cmd_audit)
