"""The ``eulerpoisson fit`` command: the torque-free body behind observations of a tumbling body.

Reads observations (:func:`eulerpoisson.io.observations.read_observations`:
CSV, NetCDF or a TOML file that names one), fits them with
:func:`eulerpoisson.fit`, prints the summary, and writes the result as JSON
(``--out``) and the figures (``--plot DIR``). Bad files and options: one line,
exit status 2.
"""

from __future__ import annotations

import argparse
import math
import os

from .common import UsageError

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


def cmd_fit(args) -> int:
    import json

    from ..estimation import fit
    from ..io.observations import read_observations
    from ..io.outputs import check_output

    for value, name in ((args.file, "observations file"), (args.out, "--out"), (args.plot, "--plot")):
        if value is not None and not str(value).strip():
            raise UsageError(f"{name}: empty file name")
    if not os.path.exists(args.file):
        raise UsageError(f"{args.file}: no such file (observations: .csv, .nc or .toml)")
    obs = read_observations(
        args.file,
        sigma_attitude_deg=_positive(args.sigma_attitude, "--sigma-attitude"),
        sigma_omega=_positive(args.sigma_omega, "--sigma-omega"),
        sigma_axis_deg=_positive(args.sigma_axis, "--sigma-axis"),
        omega_frame=args.omega_frame,
        axis=_vector(args.axis, "--axis"),
    )
    kwargs = obs.fit_kwargs()
    if args.principal_axes is not None:
        kwargs["principal_axes"] = args.principal_axes
    if args.inertia is not None:
        kwargs["inertia"] = _inertia(args.inertia)
    if args.out is not None:
        check_output(args.out, "file", overwrite=bool(args.overwrite), inputs=[args.file])
    if args.plot is not None:
        if os.path.exists(args.plot) and not os.path.isdir(args.plot):
            raise UsageError(f"--plot {args.plot!r} is a file; give a folder for the figures")
        clash = [f for f in PLOT_FILES if os.path.exists(os.path.join(args.plot, f))]
        if clash and not args.overwrite:
            raise UsageError(
                f"--plot {args.plot!r} already holds {', '.join(clash)}; run again with --overwrite to replace them"
            )
    t = kwargs.pop("t")
    res = fit(t, **kwargs)
    if args.out is not None:
        res.to_json(args.out)
    written = res.save_plots(args.plot) if args.plot is not None else []
    if args.json:
        print(json.dumps(res.as_dict()))
    else:
        print(f"{obs.source}:")
        print(res.summary())
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
        help="standard deviation of each angular-velocity component (the file's units)",
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
    f.add_argument("--json", action="store_true", help="print the result as one JSON object instead of the summary")
    f.add_argument("--overwrite", action="store_true", help="replace an existing --out file or --plot figures")
    f.set_defaults(func=cmd_fit)
