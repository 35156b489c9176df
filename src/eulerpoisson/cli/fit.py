"""The ``eulerpoisson fit`` command: the torque-free body behind observations of a tumbling body.

Reads observations (:func:`eulerpoisson.io.observations.read_observations`:
CSV, NetCDF or a TOML file that names one), fits them with
:func:`eulerpoisson.fit`, prints the summary, and writes the result as JSON
(``--out``) and the figures (``--plot DIR``). Bad files and options: one line,
exit status 2.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import math
import os

from .common import UsageError, json_text

__all__ = ["add_commands", "cmd_fit", "FIT_EXAMPLES"]

FIT_EXAMPLES = [
    "eulerpoisson fit examples/tumbling_data/phone_toss_2.csv",
    "eulerpoisson fit examples/tumbling_data/phone_toss.toml --out toss_fit.json --plot toss_plots --overwrite",
    "eulerpoisson fit examples/tumbling_data/phone_toss_1.csv --sigma-omega 0.2 --principal-axes fit --json",
]

PLOT_FILES = ("residuals.png", "fit.png", "polhode.png")


def _positive(text, name):
    if text is None:
        return None
    try:
        x = float(str(text).strip())
    except ValueError:
        raise UsageError(f"{name}: {text!r} is not a number") from None
    if not (math.isfinite(x) and x > 0):
        raise UsageError(f"{name} must be a positive number, got {text!r}")
    return x


def _vector(text, name):
    if text is None:
        return None
    parts = [p for p in str(text).replace(" ", "").split(",") if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        raise UsageError(f"{name}: {text!r} is not three numbers separated by commas") from None
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise UsageError(f"{name} must be three finite numbers x,y,z; got {text!r}")
    return v


def _inertia(text):
    import numpy as np

    try:
        v = [float(p) for p in str(text).replace(" ", "").split(",") if p]
    except ValueError:
        raise UsageError(f"--inertia: {text!r} is not numbers separated by commas") from None
    if len(v) not in (3, 9) or not all(math.isfinite(x) for x in v):
        raise UsageError(f"--inertia must be three principal moments or nine tensor entries; got {text!r}")
    return np.array(v) if len(v) == 3 else np.array(v).reshape(3, 3)


def _reading_flag(res, args):
    """The flag that reads the data as ``res.better_reading`` (relative to the flags given), or None."""
    reading = res.better_reading
    if reading == "conjugate":
        now = args.attitude_convention or "body-to-space"
        return "--attitude-convention " + ("space-to-body" if now == "body-to-space" else "body-to-space")
    return {
        "xyzw": "--quaternion-order xyzw",
        "space": "--omega-frame space",
        "body": "--omega-frame body",
        "deg": "--omega-unit deg",
    }.get(reading)


def _poor_fit_line(res, args):
    """One line for a refused fit: why, the flag that reads the data better, and --accept-poor-fit."""
    from ..estimation.data import POOR_FIT_CHI2

    flag = _reading_flag(res, args)
    why = res.reading_advice(flag) if flag is not None else None
    if why is None:
        why = (
            f"reduced chi2 = {res.reduced_chi2:.4g} > {POOR_FIT_CHI2:g}: check the sigmas (--sigma-attitude, "
            "--sigma-omega, --sigma-axis) and the conventions (--quaternion-order, --attitude-convention, "
            "--omega-frame, --omega-unit)"
        )
    return f"poor fit: {why} (or --accept-poor-fit to keep this fit)"


def cmd_fit(args) -> int:
    from ..errors import PoorFitError
    from ..estimation import fit
    from ..io.atomic import atomic_write_text, guard_replace
    from ..io.observations import read_observations
    from ..io.outputs import OutputLock, check_output, check_output_name, claim_output, mark_text

    for value, name in ((args.file, "observations file"), (args.out, "--out"), (args.plot, "--plot")):
        if value is not None and not str(value).strip():
            raise UsageError(f"{name}: empty file name")
    if args.out is not None:
        check_output_name(args.out, "--out")
    if args.plot is not None:
        check_output_name(args.plot, "--plot", folder=True)
    if not os.path.exists(args.file):
        raise UsageError(f"{args.file}: no such file (observations: .csv, .nc or .toml)")
    obs = read_observations(
        args.file,
        sigma_attitude_deg=_positive(args.sigma_attitude, "--sigma-attitude"),
        sigma_omega=_positive(args.sigma_omega, "--sigma-omega"),
        sigma_axis_deg=_positive(args.sigma_axis, "--sigma-axis"),
        omega_frame=args.omega_frame,
        axis=_vector(args.axis, "--axis"),
        quaternion_order=args.quaternion_order,
        attitude_convention=args.attitude_convention,
        omega_unit=args.omega_unit,
    )
    kwargs = obs.fit_kwargs()
    rate_unit = args.omega_unit or "rad"  # out in the units of the flags: degrees for angles, the rates' unit
    if args.principal_axes is not None:
        kwargs["principal_axes"] = args.principal_axes
    if args.inertia is not None:
        kwargs["inertia"] = _inertia(args.inertia)
    # every file read is an input (the TOML and the data file it names): never an output, even with --overwrite
    inputs = [args.file, *obs.files]
    if args.plot is not None:
        if os.path.exists(args.plot) and not os.path.isdir(args.plot):
            raise UsageError(f"--plot {args.plot!r} is a file; give a folder for the figures")
        clash = [f for f in PLOT_FILES if os.path.exists(os.path.join(args.plot, f))]
        if clash and not args.overwrite:
            raise UsageError(
                f"--plot {args.plot!r} already holds {', '.join(clash)}; run again with --overwrite to replace them"
            )
    # the outputs are claimed (checked and locked) before the fit and checked again before each rename
    with contextlib.ExitStack() as claims:
        if args.out is not None:
            claims.enter_context(
                claim_output(args.out, "fit-result", overwrite=bool(args.overwrite), inputs=inputs, option="--out")
            )
        if args.plot is not None:  # the folder is locked; each figure is checked now and before its rename
            claims.enter_context(OutputLock(args.plot))
            for f in PLOT_FILES:
                fig = os.path.join(args.plot, f)
                check = functools.partial(
                    check_output, fig, "figure", overwrite=bool(args.overwrite), inputs=inputs, option="--plot"
                )
                check()
                claims.enter_context(guard_replace(fig, check))
        t = kwargs.pop("t")
        try:
            res = fit(t, **kwargs, accept_poor_fit=bool(args.accept_poor_fit))
        except PoorFitError as exc:
            raise UsageError(f"{obs.source}: {_poor_fit_line(exc.result, args)}") from None
        if args.out is not None:
            text = res.to_json(angle_unit="deg", rate_unit=rate_unit)  # the sigmas in the flags' units
            atomic_write_text(args.out, mark_text(text, "fit-result", "json"))
        written = res.save_plots(args.plot) if args.plot is not None else []
    if args.json:
        print(json_text(res.as_dict(angle_unit="deg", rate_unit=rate_unit)))  # strict JSON (issue 22)
    else:
        print(f"{obs.source}:")
        print(res.summary(angle_unit="deg", rate_unit=rate_unit, flag=_reading_flag(res, args)))
        for p in ([args.out] if args.out else []) + [str(w) for w in written]:
            print(f"  wrote {p}")
    return 0


def add_commands(sub) -> None:
    """Add ``fit`` to the subcommands ``sub`` of the ``eulerpoisson`` parser."""
    ex = argparse.RawDescriptionHelpFormatter
    f = sub.add_parser(
        "fit",
        help="fit a torque-free body (inertia ratios, attitude and rate at t0) to observations of its rotation",
        formatter_class=ex,
        description="Spin-state estimation: the inertia ratios (trace 1) and the attitude and body angular velocity "
        "at the first observation that best explain observed attitudes, angular velocities and axis "
        "directions, with standard errors, the distinct optima found from starts on both sides of the "
        "separatrix, and the fit's chi2.",
        epilog=(
            "examples:\n" + "\n".join(f"  {e}" for e in FIT_EXAMPLES) + "\n\n"
            "FILE: a CSV with a header row: t; qw,qx,qy,qz or euler_<SEQ>_1..3 (degrees, SEQ as scipy: ZXZ\n"
            "intrinsic, zxz extrinsic); wx,wy,wz; ax,ay,az (with --axis); optional sigma_attitude_deg,\n"
            "sigma_omega or sigma_wx..sigma_wz, sigma_axis_deg. Empty cells are missing observations. Or a\n"
            "NetCDF file (t, q, omega, axis_direction), or a TOML file with [observations] file = ... and the\n"
            "settings. A sigma not given anywhere is estimated from the residuals."
        ),
    )
    f.add_argument("file", help="observations: .csv, .nc or .toml")
    f.add_argument(
        "--sigma-attitude",
        dest="sigma_attitude",
        metavar="DEG",
        help="standard deviation of the attitudes about each axis, degrees",
    )
    f.add_argument(
        "--sigma-omega",
        dest="sigma_omega",
        metavar="RATE",
        help="standard deviation of each angular-velocity component, in the unit of the rates (--omega-unit)",
    )
    f.add_argument(
        "--sigma-axis", dest="sigma_axis", metavar="DEG", help="standard deviation of the axis directions, degrees"
    )
    f.add_argument(
        "--omega-frame",
        dest="omega_frame",
        choices=("body", "space"),
        help="frame of wx,wy,wz (default body, or the file's)",
    )
    f.add_argument(
        "--omega-unit",
        dest="omega_unit",
        choices=("rad", "deg"),
        help="unit of wx,wy,wz and of their sigmas (--sigma-omega): radians (default) or degrees per unit of t",
    )
    f.add_argument(
        "--quaternion-order",
        dest="quaternion_order",
        choices=("wxyz", "xyzw"),
        help="what the quaternion columns hold in file order: scalar first or last (default: as the names say)",
    )
    f.add_argument(
        "--attitude-convention",
        dest="attitude_convention",
        choices=("body-to-space", "space-to-body"),
        help="what the attitudes rotate (default body-to-space: x_space = R x_body)",
    )
    f.add_argument("--axis", metavar="X,Y,Z", help="the body axis whose space direction ax,ay,az is observed")
    f.add_argument(
        "--principal-axes",
        dest="principal_axes",
        choices=("given", "fit"),
        help="'given': inertia diagonal in the body frame of the data (default); 'fit': a full tensor",
    )
    f.add_argument("--inertia", help="fix the inertia (I1,I2,I3 or nine numbers): fit the state only")
    f.add_argument("--out", metavar="FILE", help="write the result as JSON")
    f.add_argument("--plot", metavar="DIR", help="write residuals.png, fit.png and polhode.png into DIR")
    f.add_argument(
        "--accept-poor-fit",
        dest="accept_poor_fit",
        action="store_true",
        help="keep a poor fit (reduced chi2 > 100, or another reading of the data fits far better) instead of exit 2",
    )
    f.add_argument("--json", action="store_true", help="print the result as one JSON object instead of the summary")
    f.add_argument("--overwrite", action="store_true", help="replace an existing --out file or --plot figures")
    f.set_defaults(func=cmd_fit)
