"""The ``eulerpoisson plot`` and ``eulerpoisson animate`` commands: figures and movies of a trajectory file."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

import numpy as np

from .common import UsageError, check_file_name, read_trajectory

__all__ = ["add_commands", "cmd_plot", "cmd_animate", "FPS_RANGE", "MAX_FRAMES"]


#: frames per second accepted by ``animate --fps``
FPS_RANGE = (1.0, 240.0)
#: most frames of a GIF/MP4 written by ``animate`` (each frame is rendered by matplotlib)
MAX_FRAMES = 1200


def _time_option(text, flag: str) -> float | None:
    """The number given to ``--t-start``/``--t-end`` (a time of the run, in its unit), or None when not given."""
    if text is None:
        return None
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise UsageError(f"{flag}: {text!r} is not a number (a time of the run, in its time unit)") from None
    if not math.isfinite(value):
        raise UsageError(f"{flag} must be a finite time, got {text!r}")
    return value


def cmd_plot(args) -> int:
    from ..io.outputs import check_output_name, claim_output

    t_start = _time_option(getattr(args, "t_start", None), "--t-start")
    t_end = _time_option(getattr(args, "t_end", None), "--t-end")
    if t_start is not None and t_end is not None and t_start > t_end:
        raise UsageError(f"--t-start {args.t_start} is after --t-end {args.t_end}; give --t-start <= --t-end")
    check_file_name(args.out, "--out")
    out = args.out if args.out is not None else f"{Path(args.file).stem}_{args.kind}.png"
    check_output_name(out, "--out")
    # the same output policy as simulate: an existing figure is replaced only with --overwrite, never the input
    # or a file of another kind; the figure is claimed before the trajectory is read
    with claim_output(out, "figure", overwrite=bool(args.overwrite), inputs=[args.file], option="--out"):
        from ..viz.plots import FORMATS

        if Path(out).suffix.lower().lstrip(".") not in FORMATS:  # (the flag's name, not the library's out=)
            raise UsageError(
                f"--out {out!r}: unsupported file extension {Path(out).suffix!r}; use one of "
                + ", ".join("." + f for f in FORMATS)
            )
        if args.kind == "atlas":
            from ..io.outputs import file_kind
            from ..sweep.runner import load_sweep, plot_atlas

            if t_start is not None or t_end is not None:
                raise UsageError("--t-start/--t-end select a window of a trajectory; --kind atlas draws a whole sweep")
            if not os.path.exists(args.file):
                raise UsageError(f"{args.file}: no such sweep store (make one with 'eulerpoisson sweep sweep.toml')")
            if file_kind(args.file) != "sweep-store":
                raise UsageError(
                    f"{args.file}: --kind atlas draws a sweep store (made by 'eulerpoisson sweep'), and this "
                    f"is not one; a trajectory has the kinds omega, invariants, polhode, gibbs, attitude, apex"
                )
            plot_atlas(load_sweep(args.file), out)
        else:
            from ..viz import plots

            traj = read_trajectory(args.file)
            plots.plot(traj, args.kind, out=out, t_start=t_start, t_end=t_end)
    if not args.quiet:
        print(f"wrote {out}")
    return 0


def _fps(text) -> float:
    lo, hi = FPS_RANGE
    try:
        fps = float(text)
    except (TypeError, ValueError):
        raise UsageError(f"--fps: {text!r} is not a number (frames per second, {lo:g} to {hi:g})") from None
    if not (math.isfinite(fps) and lo <= fps <= hi):
        raise UsageError(f"--fps must be between {lo:g} and {hi:g} frames per second, got {text!r}")
    return int(fps) if fps.is_integer() else fps


def cmd_animate(args) -> int:
    from ..io.outputs import check_output_name, claim_output
    from ..viz.animate import FORMATS, animate, default_duration

    check_file_name(args.out, "--out")
    check_output_name(args.out, "--out")
    ext = Path(args.out).suffix.lower().lstrip(".")
    if ext not in FORMATS and ext != "htm":
        raise UsageError(
            f"--out {args.out!r}: unsupported file extension; use .html (self-contained page), .gif or .mp4"
        )
    video = ext in ("gif", "mp4")
    if args.fps is not None and not video:
        raise UsageError(
            "--fps applies to .gif and .mp4 movies only (an HTML page animates at the browser's frame rate)"
        )
    fps = _fps(args.fps) if args.fps is not None else 30
    # the same output policy as simulate, claimed before the trajectory is read and the frames are drawn
    with claim_output(args.out, "movie", overwrite=bool(args.overwrite), inputs=[args.file], option="--out"):
        traj = read_trajectory(args.file)
        if video:
            if getattr(traj, "lazy", False):  # a store: its ends (the times of a stream are monotonic)
                ends = traj[[0, len(traj) - 1]] if len(traj) else traj.head()
                span = float(np.max(ends.t) - np.min(ends.t))
            else:
                span = float(np.max(traj.t) - np.min(traj.t))
            nframes = int(round(fps * default_duration(span)))
            if nframes > MAX_FRAMES:
                dur = default_duration(span)
                raise UsageError(
                    f"--fps {args.fps}: a {dur:g} s movie would have {nframes} frames, more than {MAX_FRAMES}; "
                    f"use --fps {int(MAX_FRAMES // dur)} or less"
                )
        animate(traj, args.out, fps=fps)  # (a page is marked as ours by animate: --overwrite knows it)
    if not args.quiet:
        print(f"wrote {args.out}")
    return 0


def add_commands(sub) -> None:
    """Register ``plot`` and ``animate`` on the subcommand parser ``sub``."""
    ex = argparse.RawDescriptionHelpFormatter
    pl = sub.add_parser(
        "plot",
        help="draw a figure from a trajectory file",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson plot run.nc --kind omega --out omega.png\n  eulerpoisson plot run.nc --kind polhode --out polhode.pdf\n"
        "  eulerpoisson plot top.nc --kind apex --out apex.png   # a top: its axis on the unit sphere\n"
        "  eulerpoisson plot long.zarr --kind omega --out long_omega.png   # a streamed run: min/max per pixel column\n"
        "  eulerpoisson plot long.zarr --kind omega --t-start 10 --t-end 20 --out w.png   # a window of it\n\n"
        "Long runs (more than 20000 samples, and every .zarr store) are decimated: time series are drawn as\n"
        "the min/max of the samples in each pixel column (a translucent band, the mean on top), the 3-D\n"
        "pictures from evenly strided samples.",
    )
    pl.add_argument(
        "file",
        help="trajectory written by 'simulate --out': a NetCDF file (version 4 or 3) or a .zarr "
        "store, read chunk by chunk (or a sweep store for --kind atlas)",
    )
    pl.add_argument(
        "--kind", required=True, choices=["omega", "invariants", "polhode", "gibbs", "attitude", "apex", "atlas"]
    )
    pl.add_argument("--out", help="figure file (.png, .svg or .pdf; default FILE_KIND.png)")
    pl.add_argument(
        "--overwrite", action="store_true", help="replace an existing figure (never a file of another kind)"
    )
    pl.add_argument(
        "--t-start",
        metavar="T",
        help="draw only the samples at times >= T (in the run's time unit; default: the first sample); "
        "a store is read from there on",
    )
    pl.add_argument(
        "--t-end", metavar="T", help="draw only the samples at times <= T (in the run's time unit; default: the last)"
    )
    pl.add_argument("--quiet", action="store_true")
    pl.set_defaults(func=cmd_plot)

    an = sub.add_parser(
        "animate",
        help="animate the tumbling body (self-contained HTML, GIF or MP4)",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson animate run.nc --out movie.html\n  eulerpoisson animate run.nc --out movie.gif",
    )
    an.add_argument("file", help="trajectory file: NetCDF (version 4 or 3) or a .zarr store")
    an.add_argument("--out", required=True, help="movie.html, movie.gif or movie.mp4")
    an.add_argument("--overwrite", action="store_true", help="replace an existing movie (never a file of another kind)")
    an.add_argument(
        "--fps", help=f"frames per second of a .gif/.mp4 ({FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}, default 30)"
    )
    an.add_argument("--quiet", action="store_true")
    an.set_defaults(func=cmd_animate)
