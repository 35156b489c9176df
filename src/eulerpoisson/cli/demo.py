"""The showcase behind ``make demo``: the tennis-racket effect and a heavy top.

A body with principal moments (3, 5, 8) spun almost exactly about its
intermediate axis, M0 = (0, 2, 0.01), flips over and over (the
Dzhanibekov or tennis-racket effect). The demo solves it in closed form,
measures the time between flips and compares it with the closed-form value
2K(k)/lambda, checks the integrals of motion, and writes the trajectory,
figures, an animation and the audit report into one folder.

The third scene estimates a spin state: a tumbling body (principal moments
0.22, 0.35, 0.43, trace 1) observed 120 times over 40 time units, attitude
with 0.1 degree noise and body rate with 2e-3 noise; ``ep.fit`` finds its
inertia ratios and initial state from its default starts, printed as truth
against estimate and standard error (``fit.json``, ``fit_residuals.png``).

The second scene is a fast heavy symmetric top (a Lagrange top): inertia
(1, 1, 0.5) about the fixed point, centre of mass 0.25 up the symmetry axis,
mass 1 under g = 9.81, tilted 60 degrees from the vertical and released
spinning at 10 rad/s about its axis. It precesses slowly around the vertical
while it nutates, with a cusp each time the axis stops at its highest point.
It is solved with the Taylor integrator and, when the closed form supports
the Lagrange top, with ``method="exact"`` too (the largest difference is
printed); the locus of the axis on the unit sphere is drawn (``top_apex.png``).

The outputs follow the policy of every command (:mod:`eulerpoisson.io.outputs`):
the folder is created when missing, and a file already in it is replaced only
when it holds what the demo writes there (:data:`DEMO_FILES`: a NetCDF file, a
picture, an animation page, a fit result or an audit report of ours, recognized
by content), so that ``make demo`` reruns into the same folder; any other file
(a configuration, data, notes) is never replaced: the demo stops before any work.
The demo has no ``--overwrite``: it always replaces its own outputs.
"""

from __future__ import annotations

import contextlib
import functools
import os
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis import flip_times, tennis_racket_half_period
from ..model.body import RigidBody
from ..solvers import solve

__all__ = ["run_demo", "run_top", "run_fit", "TENNIS_RACKET", "HEAVY_TOP", "TUMBLER", "DEMO_FILES"]

#: every file the demo writes into its folder, and its kind (:data:`eulerpoisson.io.outputs.KINDS`): a file
#: already there is replaced only when it holds this kind of output (:func:`eulerpoisson.io.outputs.check_output`)
DEMO_FILES: dict[str, str] = {
    "tennis_racket.nc": "netcdf",
    "omega.png": "figure",
    "polhode.png": "figure",
    "gibbs.png": "figure",
    "invariants.png": "figure",
    "attitude.png": "figure",
    "tennis_racket.html": "movie",
    "top.nc": "netcdf",
    "top_apex.png": "figure",
    "fit.json": "fit-result",
    "fit_residuals.png": "figure",
    "audit.md": "audit-report",
    "audit.json": "audit-report",
}
_TOP_FILES = ("top.nc", "top_apex.png")
_FIT_FILES = ("fit.json", "fit_residuals.png")

#: the demo's body and initial body angular momentum
TENNIS_RACKET: dict[str, Any] = {"inertia": (3.0, 5.0, 8.0), "M0": (0.0, 2.0, 0.01)}

#: the heavy-top scene: inertia about the fixed point, torque, initial tilt (about x), spin, time span
HEAVY_TOP: dict[str, Any] = {
    "inertia": (1.0, 1.0, 0.5),
    "mass": 1.0,
    "center_of_mass": (0.0, 0.0, 0.25),
    "g": (0.0, 0.0, -9.81),
    "tilt_deg": 60.0,
    "omega0": (0.0, 0.0, 10.0),
    "t_end": 15.0,
    "samples": 3001,
}


#: the fit scene: the tumbling body, its state at t = 0, the observations and their noise
TUMBLER: dict[str, Any] = {
    "moments": (0.22, 0.35, 0.43),
    "omega0": (0.3, -0.2, 1.0),
    "attitude0": (0.7, 0.1, -0.5, 0.5),
    "t_end": 40.0,
    "samples": 120,
    "sigma_attitude_deg": 0.1,
    "sigma_omega": 2e-3,
    "seed": 1,
}


def _make_folder(out: Path) -> None:
    """Create the output folder ``out``; an :class:`OutputError` when it, or a folder above it, is a file."""
    from ..errors import OutputError
    from ..io.atomic import write_error

    for p in (out, *out.parents):
        if p.exists() or p.is_symlink():
            if not p.is_dir():
                where = "" if p == out else f": {p} is a file"
                what = "is a file, not a folder" if p == out else "is under a file, not in a folder"
                raise OutputError(
                    f"--out {os.fspath(out)!r} {what}{where}; the demo writes a folder of files: "
                    "give a new or existing folder"
                )
            break
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise write_error(out, exc) from None


@contextlib.contextmanager
def _claim_folder(out: Path, names: Iterable[str]) -> Iterator[None]:
    """Claim the files ``names`` of folder ``out`` for the whole work (the policy of :func:`claim_output`).

    Each is checked before any work (only an output of its kind of
    :data:`DEMO_FILES` is replaced), the folder is created and locked (a
    second demo writing there fails at once), and each file is checked again
    just before its rename.
    """
    from ..io.atomic import guard_replace
    from ..io.outputs import OutputLock, check_output

    checks = [
        (out / name, functools.partial(check_output, out / name, DEMO_FILES[name], overwrite=True, flag="the demo"))
        for name in names
    ]
    _make_folder(out)
    for _, check in checks:
        check()
    with contextlib.ExitStack() as claims:
        claims.enter_context(OutputLock(out / "demo"))  # .demo.lock in the folder
        for path, check in checks:
            check()
            claims.enter_context(guard_replace(path, check))
        yield


def run_fit(out: str | os.PathLike[str], *, say: Callable[[str], object] = print) -> list[Path]:
    """The fit scene: synthetic noisy observations of a tumbling body, fitted; ``fit.json`` and a residual plot.

    Raises
    ------
    OutputError
        ``out`` is a file, or a file of another kind is where an output goes (nothing is written).
    """
    out = Path(out)
    with _claim_folder(out, _FIT_FILES):
        return _fit_scene(out, say)


def _fit_scene(out: Path, say: Callable[[str], object]) -> list[Path]:
    from ..estimation import fit
    from ..estimation.residuals import exp_quaternion
    from ..io.atomic import atomic_write_text
    from ..io.outputs import mark_text
    from ..numerics.quaternion import qmul

    body = RigidBody(TUMBLER["moments"], name="tumbler")
    q0 = np.array(TUMBLER["attitude0"]) / np.linalg.norm(TUMBLER["attitude0"])
    t = np.linspace(0.0, TUMBLER["t_end"], TUMBLER["samples"])
    truth = solve(body, t, omega0=TUMBLER["omega0"], attitude0=q0)
    rng = np.random.default_rng(TUMBLER["seed"])
    sa = np.radians(TUMBLER["sigma_attitude_deg"])
    sw = TUMBLER["sigma_omega"]
    q_obs = qmul(truth.quaternion, exp_quaternion(sa * rng.standard_normal((t.size, 3))))
    w_obs = truth.omega + sw * rng.standard_normal((t.size, 3))
    t0 = time.perf_counter()
    res = fit(t, attitude=q_obs, attitude_sigma=sa, omega=w_obs, omega_sigma=sw)
    wall = time.perf_counter() - t0
    js = out / "fit.json"
    atomic_write_text(js, mark_text(res.to_json(), "fit-result", "json"))  # marked: recognized as ours on a rerun
    files = [js]
    try:
        fig = res.plot_residuals()
    except ImportError:  # pragma: no cover - the plot extra is missing
        fig = None
    if fig is not None:
        import matplotlib.pyplot as plt

        from ..io.atomic import atomic_path

        png = out / "fit_residuals.png"
        with atomic_path(png) as tmp:
            fig.savefig(tmp, dpi=100, format="png")
        plt.close(fig)
        files.append(png)
    moments = np.array(TUMBLER["moments"]) / np.sum(TUMBLER["moments"])
    say("eulerpoisson demo: spin-state estimation (ep.fit)")
    say(
        f"  {t.size} noisy attitudes ({TUMBLER['sigma_attitude_deg']:g} deg) and body rates ({sw:g}) of a tumbling "
        f"body over t = 0..{TUMBLER['t_end']:g}; fitted from {res.n_starts} default starts in {wall:.2f} s, "
        f"chi2/dof = {res.reduced_chi2:.3f}"
    )
    say(f"  {'':10s}{'truth':>12s}{'estimate':>14s}{'+- sigma':>12s}")
    rows = [
        ("I_xx", moments[0], res.parameters["I_xx"], res.stderr["I_xx"]),
        ("I_yy", moments[1], res.parameters["I_yy"], res.stderr["I_yy"]),
        ("I_zz", moments[2], res.parameters["I_zz"], res.stderr["I_zz"]),
    ]
    rows += [
        (f"omega0_{c}", TUMBLER["omega0"][i], res.omega0[i], res.stderr[f"omega0_{c}"]) for i, c in enumerate("xyz")
    ]
    for name, tv, ev, se in rows:
        say(f"  {name:10s}{tv:12.6f}{ev:14.6f}{se:12.2e}")
    err = np.degrees(np.linalg.norm(res.attitude_error(q0)))
    sig = np.degrees(np.sqrt(sum(res.stderr[f"attitude0_{c}"] ** 2 for c in "xyz")))
    say(f"  attitude at t = 0: {err:.4f} deg from the truth (sigma of the angle {sig:.4f} deg)")
    return files


_DRIFT_NAMES = {"m_vertical": "vertical momentum", "M3": "spin momentum M3"}


def run_top(
    out: str | os.PathLike[str],
    *,
    say: Callable[[str], object] = print,
    t_end: float = HEAVY_TOP["t_end"],
    samples: int = HEAVY_TOP["samples"],
) -> list[Path]:
    """The heavy-top scene: ``top.nc`` and ``top_apex.png`` in ``out``; returns the files written.

    Solved with ``method="taylor"``; also with ``method="exact"`` when the
    closed form runs the Lagrange top (an :class:`UnsupportedModelError`
    otherwise, which skips the comparison).

    Raises
    ------
    OutputError
        ``out`` is a file, or a file of another kind is where an output goes (nothing is written).
    """
    out = Path(out)
    with _claim_folder(out, _TOP_FILES):
        return _top_scene(out, say, t_end, samples)


def _top_scene(out: Path, say: Callable[[str], object], t_end: float, samples: int) -> list[Path]:
    from ..errors import UnsupportedModelError
    from ..model.torques import Gravity
    from ..viz import plots

    body = RigidBody(HEAVY_TOP["inertia"], name="heavy top")
    top = Gravity(HEAVY_TOP["mass"], HEAVY_TOP["center_of_mass"], HEAVY_TOP["g"])
    half = np.radians(HEAVY_TOP["tilt_deg"]) / 2
    q0 = np.array([np.cos(half), np.sin(half), 0.0, 0.0])
    t = np.linspace(0.0, t_end, samples)
    traj = solve(body, t, omega0=HEAVY_TOP["omega0"], attitude0=q0, torque=top, method="taylor", tol=1e-15)
    try:
        exact = solve(body, t, omega0=HEAVY_TOP["omega0"], attitude0=q0, torque=top, method="exact")
    except UnsupportedModelError as exc:
        exact, why = None, str(exc)
    nc = out / "top.nc"
    traj.to_netcdf(nc)
    png = out / "top_apex.png"
    plots.plot(traj, "apex", out=png)
    drift = traj.drift()
    axis = np.einsum(
        "tij,j->ti", traj.matrix, np.array(HEAVY_TOP["center_of_mass"]) / np.linalg.norm(HEAVY_TOP["center_of_mass"])
    )
    theta = np.degrees(np.arccos(np.clip(axis[:, 2], -1.0, 1.0)))
    say("eulerpoisson demo: a heavy top (Lagrange top)")
    say(
        f"  body: moments about the fixed point {body.principal_moments.tolist()}, mass {HEAVY_TOP['mass']:g}, "
        f"centre of mass {list(HEAVY_TOP['center_of_mass'])}, g = {list(HEAVY_TOP['g'])}"
    )
    say(
        f"  released at {HEAVY_TOP['tilt_deg']:g} deg from the vertical, spinning at {HEAVY_TOP['omega0'][2]:g} rad/s; "
        f"the axis nutates between {theta.min():.2f} and {theta.max():.2f} deg"
    )
    say(
        f"  taylor: {samples} samples to t = {t_end:g}, wall time {traj.stats.get('wall_time', 0.0):.2f} s; "
        "max relative drift: " + ", ".join(f"{_DRIFT_NAMES.get(k, k)} {v:.1e}" for k, v in drift.items())
    )
    if exact is not None:
        dq = float(np.max(np.abs(np.abs(np.sum(exact.quaternion * traj.quaternion, -1)) - 1.0)))
        dw = float(np.max(np.abs(exact.omega - traj.omega)))
        say(
            f"  closed form (exact) beside taylor: max |omega difference| {dw:.1e} rad/s, "
            f"max 1-|q_exact.q_taylor| {dq:.1e}"
        )
    else:
        say(
            "  closed form (exact): not run, " + why.split(";")[0].replace("method 'exact' cannot run this model: ", "")
        )
    return [nc, png]


def run_demo(
    out: str | os.PathLike[str] = "out", *, quiet: bool = False, t_end: float = 400.0, samples: int = 4001
) -> int:
    """Run the tennis-racket showcase and write everything into ``out``.

    Parameters
    ----------
    out : str or Path
        Output folder (created; an existing one is written into).
    quiet : bool
        Print nothing.
    t_end, samples : float, int
        Time span and number of output samples.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    OutputError
        ``out`` is a file (or is under one), or a file in it named as an
        output holds something else than the demo writes there
        (:data:`DEMO_FILES`): checked before any work, nothing is written.
    """
    out = Path(out)
    with _claim_folder(out, DEMO_FILES):
        return _demo(out, quiet, t_end, samples)


def _demo(out: Path, quiet: bool, t_end: float, samples: int) -> int:
    say = (lambda *a: None) if quiet else print
    t0 = time.perf_counter()
    body = RigidBody(TENNIS_RACKET["inertia"], name="tennis racket")
    M0 = np.array(TENNIS_RACKET["M0"])
    omega0 = M0 / body.principal_moments
    t = np.linspace(0.0, t_end, samples)
    traj = solve(body, t, omega0=omega0, method="exact")
    nc = out / "tennis_racket.nc"
    traj.to_netcdf(nc)

    half_exact = tennis_racket_half_period(body.principal_moments, M0)
    flips = flip_times(traj, component=1)
    half_measured = float(np.mean(np.diff(flips))) if len(flips) > 1 else float("nan")
    drift = traj.drift()

    files = [nc]
    from ..viz import plots

    for kind in ("omega", "polhode", "gibbs", "invariants", "attitude"):
        path = out / f"{kind}.png"
        plots.plot(traj, kind, out=path)
        files.append(path)
    from ..viz.animate import animate

    anim = out / "tennis_racket.html"
    sub = slice(None, None, max(1, samples // 1200))
    from ..trajectory import Trajectory

    light = Trajectory(traj.t[sub], traj.quaternion[sub], traj.omega[sub], body, traj.method, traj.options)
    animate(light, anim)  # (marked as ours by animate: recognized on a rerun)
    files.append(anim)
    top_lines: list[str] = []
    files.extend(_top_scene(out, top_lines.append, HEAVY_TOP["t_end"], HEAVY_TOP["samples"]))
    fit_lines: list[str] = []
    files.extend(_fit_scene(out, fit_lines.append))
    from ..paper.audit import run_audit, write_report

    report = run_audit()
    for fmt in ("md", "json"):
        files.append(Path(write_report(report, fmt, out / f"audit.{fmt}")))  # (marked as ours)

    wall = time.perf_counter() - t0
    say("eulerpoisson demo: the tennis-racket effect")
    say(f"  body: principal moments {body.principal_moments.tolist()}, initial body momentum M0 = {M0.tolist()}")
    say(f"  flips of Omega_2 observed in [0, {t_end:g}]: {len(flips)}")
    say(
        f"  time between flips: measured {half_measured:.12g}, closed form 2K(k)/lambda = {half_exact:.12g}"
        f" (relative difference {abs(half_measured - half_exact) / half_exact:.1e})"
    )
    say("  integrals of motion, max relative drift: " + ", ".join(f"{k} {v:.1e}" for k, v in drift.items()))
    counts = report.summary()["counts"]
    say(
        "  audit of the paper: "
        + ", ".join(f"{v} {k}" for k, v in counts.items())
        + " (misprints in eq. "
        + ", ".join(m["equation"] for m in report.summary()["misprints"])
        + ")"
    )
    for line in top_lines + fit_lines:
        say(line)
    say(f"  wrote {len(files)} files into {out}/ in {wall:.1f} s:")
    for f in files:
        say(f"    {f}")
    return 0
