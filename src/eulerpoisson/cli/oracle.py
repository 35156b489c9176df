"""The oracle's commands: ``eulerpoisson validate`` (a run against the exact motion) and ``eulerpoisson cases``.

``validate`` exits 0 when it ran (1 when a ``--tolerance`` is exceeded) and 2
on bad input (one line: missing columns, non-monotone times, quaternions far
from unit norm, ...); a likely convention mismatch is named in its message.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys

from .common import UsageError, check_file_name, inertia_from, json_text

__all__ = ["add_commands", "cmd_validate", "cmd_cases"]

EXIT_FAILED = 1

VALIDATE_EXAMPLES = [
    "eulerpoisson cases --out cases --overwrite",
    "eulerpoisson validate cases/tennis_racket_separatrix.csv --inertia 3,5,8 --tolerance 1e-9",
    "eulerpoisson validate cases/full_tensor.nc --json",
    "eulerpoisson validate cases/tennis_racket_circulating_1.csv --inertia 3,5,8 --plot racket_error.png",
    "eulerpoisson validate cases/long_run.csv --inertia 1,2,3 --omega-frame body --quaternion-order wxyz "
    "--attitude-convention body-to-space",
]
CASES_EXAMPLES = [
    "eulerpoisson cases --out cases",
    "eulerpoisson cases --out cases_csv --only tennis_racket_separatrix,sphere --csv-only",
]


def _tolerance(text):
    if text is None:
        return None
    try:
        x = float(str(text).strip())
    except ValueError:
        raise UsageError(f"--tolerance: {text!r} is not a number (radians)") from None
    if not (math.isfinite(x) and x > 0):
        raise UsageError(f"--tolerance must be a positive number of radians, got {text!r}")
    return x


def _fmt_times(xs, n=6):
    if not xs:
        return "none"
    s = ", ".join(f"{x:.6g}" for x in xs[:n])
    return s + (f", ... ({len(xs)} in all)" if len(xs) > n else "")


def _validate(args, inertia, tol):
    """The report of ``validate``; bad input is a UsageError (one line)."""
    from ..errors import InvalidInputError
    from ..oracle import validate

    try:
        return validate(
            args.run,
            inertia,
            quaternion_order=args.quaternion_order,
            omega_frame=args.omega_frame,
            attitude_convention=args.attitude_convention,
            tolerance=tol,
        )
    except InvalidInputError as exc:
        msg = str(exc).splitlines()[0]
        if "the run does not state it" in msg:
            raise UsageError(f"{args.run}: give the body's inertia with --inertia I1,I2,I3 (or nine numbers)") from None
        raise UsageError(msg) from None


def cmd_validate(args) -> int:
    check_file_name(args.run, "run file")
    check_file_name(args.plot, "--plot")
    inertia = inertia_from(args.inertia) if args.inertia is not None else None
    tol = _tolerance(args.tolerance)
    if not os.path.exists(args.run):
        raise UsageError(f"{args.run}: no such file (a run: .csv with header t,qw,qx,qy,qz,wx,wy,wz, .nc or .json)")
    claim = contextlib.ExitStack()
    if args.plot:
        from ..io.outputs import check_output, claim_output

        check_output(args.plot, "figure", overwrite=bool(args.overwrite), inputs=[args.run], option="--plot")
        ext = os.path.splitext(args.plot)[1].lower()
        if ext not in (".png", ".svg", ".pdf"):
            raise UsageError(f"--plot {args.plot!r}: use a .png, .svg or .pdf file name")
        # claimed before the comparison: a second writer is refused, a file that appears meanwhile is kept
        claim.enter_context(
            claim_output(args.plot, "figure", overwrite=bool(args.overwrite), inputs=[args.run], option="--plot")
        )
    with claim:
        rep = _validate(args, inertia, tol)
        if args.plot:
            from ..io.atomic import atomic_path
            from ..oracle import plot_report

            with atomic_path(args.plot, suffix=ext) as tmp:  # drawn next to its name, then renamed
                plot_report(rep, tmp)
    for w in rep.warnings:
        print(f"eulerpoisson: warning: {w}", file=sys.stderr)
    if args.json:
        print(json_text(rep.to_dict()))  # strict JSON: null (and why) for a non-finite value (issue 22)
    else:
        c = rep.conventions
        lines = [
            f"{rep.source}: {rep.samples} samples, t from {rep.t_start:.6g} to {rep.t_end:.6g}, inertia {rep.inertia}",
            f"  read as            quaternion {c.quaternion_order}, omega in the {c.omega_frame} frame, "
            f"attitude {c.attitude_convention}",
            f"  max attitude error {rep.max_attitude_error:.3e} rad (at t = {rep.max_attitude_error_time:.6g})",
            f"  max omega error    {rep.max_omega_error:.3e} (relative)",
            f"  energy drift       {rep.energy_drift:.3e} (relative, of the run)",
            f"  momentum drift     {rep.momentum_drift:.3e} (relative, of the run)",
        ]
        if rep.flip_times is not None and rep.flip_time_errors is not None:  # (set together)
            lines.append(f"  flips (exact)      {_fmt_times(rep.flip_times)}")
            errs = [e for e in rep.flip_time_errors if math.isfinite(e)]
            lines.append(
                "  flip time errors   "
                + (", ".join(f"{e:+.3e}" for e in rep.flip_time_errors[:6]) if errs else "the run does not flip")
            )
        if rep.tolerance is not None:
            lines.append(
                f"  tolerance          {rep.tolerance:g} rad: "
                + (f"exceeded at t = {rep.exceeded_at:.6g}" if rep.exceeded_at is not None else "never exceeded")
            )
        lines.append(f"  verdict            {rep.verdict.upper()}: {rep.message}")
        if args.plot:
            lines.append(f"  wrote {args.plot}")
        print("\n".join(lines))
    return EXIT_FAILED if rep.verdict == "fail" else 0


def cmd_cases(args) -> int:
    from ..oracle import CASE_NAMES, write_cases

    check_file_name(args.out, "--out")
    names = None
    if args.only is not None:
        names = [n.strip() for n in args.only.split(",") if n.strip()]
        unknown = [n for n in names if n not in CASE_NAMES]
        if unknown or not names:
            raise UsageError(
                f"--only: unknown case(s) {', '.join(unknown) or '(none given)'}; cases: {', '.join(CASE_NAMES)}"
            )
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise UsageError(f"--out {args.out!r} is a file; give a folder")
    from ..io.outputs import claim_output

    # a new or empty folder, or (with --overwrite) a folder of cases written before: claimed before the cases are
    # computed; they are written aside and moved in at the end (a failure leaves nothing), and the cases of the
    # folder not written again are removed (--only --overwrite leaves no stale case behind)
    with claim_output(args.out, "cases", overwrite=bool(args.overwrite), option="--out"):
        files = write_cases(args.out, names, netcdf=not args.csv_only)
    if not args.quiet:
        print(f"wrote {len(files)} files into {args.out} (README.md lists the cases)")
    return 0


def add_commands(sub) -> None:
    """Add ``validate`` and ``cases`` to the subcommands ``sub`` of the ``eulerpoisson`` parser."""
    from ..oracle import ATTITUDE_CONVENTIONS, CASE_NAMES, OMEGA_FRAMES, QUATERNION_ORDERS

    ex = argparse.RawDescriptionHelpFormatter
    v = sub.add_parser(
        "validate",
        help="validate another simulator's free rigid-body run against the exact motion",
        formatter_class=ex,
        description="Compare a run (attitude and angular velocity samples of a free body) with the exact motion "
        "from its first sample: attitude and rate errors, the run's energy and momentum drift, the "
        "tennis-racket flips, a verdict. Exit 0, 1 when --tolerance is exceeded, 2 on bad input.",
        epilog=(
            "examples:\n" + "\n".join(f"  {e}" for e in VALIDATE_EXAMPLES) + "\n\n"
            "RUN: a CSV with header t,qw,qx,qy,qz,wx,wy,wz (any column order: the names say the order, or\n"
            "--quaternion-order does), an eulerpoisson NetCDF file (its inertia is used when --inertia is not\n"
            "given) or a JSON list of records with the CSV's keys. A likely convention mismatch (scalar-last\n"
            "quaternions, space-frame rates, space-to-body attitudes) is named with the flags that fix it."
        ),
    )
    v.add_argument("run", help="the run: .csv, .nc or .json")
    v.add_argument("--inertia", help="principal moments I1,I2,I3 or nine numbers of the tensor in the run's body frame")
    v.add_argument(
        "--quaternion-order",
        dest="quaternion_order",
        choices=QUATERNION_ORDERS,
        help="order of the four quaternion columns as they appear (default: as the column names say)",
    )
    v.add_argument(
        "--omega-frame",
        dest="omega_frame",
        choices=OMEGA_FRAMES,
        default="body",
        help="frame of the angular velocity columns (default body)",
    )
    v.add_argument(
        "--attitude-convention",
        dest="attitude_convention",
        choices=ATTITUDE_CONVENTIONS,
        default="body-to-space",
        help="what the quaternion rotates (default body-to-space: x_space = R x_body)",
    )
    v.add_argument("--tolerance", metavar="RAD", help="attitude tolerance in radians: exit 1 when exceeded")
    v.add_argument("--json", action="store_true", help="print the report as one JSON object")
    v.add_argument("--plot", metavar="FILE", help="draw the attitude error and the drift over time (.png, .svg, .pdf)")
    v.add_argument("--overwrite", action="store_true", help="replace an existing --plot file")
    v.set_defaults(func=cmd_validate)

    c = sub.add_parser(
        "cases",
        help="write the standard suite of exact reference trajectories (CSV, NetCDF, README)",
        formatter_class=ex,
        description="Write exact free-body trajectories for validating simulators: " + ", ".join(CASE_NAMES) + ".",
        epilog="examples:\n" + "\n".join(f"  {e}" for e in CASES_EXAMPLES),
    )
    c.add_argument("--out", required=True, help="folder to write into (created if needed)")
    c.add_argument("--only", metavar="NAME[,NAME...]", help="some cases only")
    c.add_argument("--csv-only", dest="csv_only", action="store_true", help="no NetCDF files")
    c.add_argument("--overwrite", action="store_true", help="replace the cases of a folder written before")
    c.add_argument("--quiet", action="store_true")
    c.set_defaults(func=cmd_cases)
