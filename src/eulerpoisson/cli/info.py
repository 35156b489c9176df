"""The ``eulerpoisson info`` command: describe a trajectory file, or how far an interrupted run got."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from ..errors import EulerPoissonError
from .common import check_file_name, inertia_from, parse_floats, read_trajectory
from .config import FLAGS, METHOD_OPTIONS, build_body, build_torques, method_options

__all__ = ["add_commands", "cmd_info"]


def _info_store(args, traj) -> int:
    """``info`` of a .zarr store: its metadata and its first and last samples, nothing else is read."""
    b = traj.body
    lines = [
        f"{args.file}: eulerpoisson trajectory (Zarr store, read lazily: {traj.chunk} samples per chunk)",
        f"  method      {traj.method} {json.dumps(traj.options) if traj.options else ''}".rstrip(),
        f"  torque      {traj.model.describe()}",
    ]
    if len(traj) == 0:
        lines.append("  samples     0 (no output times)")
        lines.append(
            f"  body        {b!r}" if not traj.batch_shape else f"  bodies      batch of shape {traj.batch_shape}"
        )
        print("\n".join(lines))
        return 0
    first, last = traj.head(), traj.tail()
    lines.append(f"  samples     {len(traj)}, t from {float(first.t[0]):.6g} to {float(last.t[0]):.6g}")
    lines.append(f"  variables   {', '.join(traj.variables)}")
    if traj.batch_shape:
        lines.append(f"  bodies      batch of shape {traj.batch_shape}")
    else:
        lines.append(f"  body        {b!r}")
        lines.append(
            f"  energy      {float(first.energy[0]):.15g}" + ("" if traj.model.is_free else " (kinetic + potential)")
        )
        lines.append(f"  m           {np.round(first.m[0], 12).tolist()}")
    drift = traj.drift_endpoints()
    lines.append(
        "  drift       "
        + ", ".join(f"{k} {np.max(v):.2e}" for k, v in drift.items())
        + " (last sample against the first)"
    )
    print("\n".join(lines))
    return 0


# ---------------------------------------------------------------------------
# info of an unfinished (interrupted) .zarr run
# ---------------------------------------------------------------------------
def _partial_run_of(path) -> tuple[Path, Path, bool] | None:
    """``(target, work folder, named)`` of the unfinished stream to ``path``, or None.

    ``path`` is the destination of a ``simulate --out X.zarr`` run (its work
    folder is ``.X.zarr.partial`` beside it), or that work folder or the
    partial store inside it (``named``: the user asked about the partial run itself).
    """
    p = Path(path)
    if not p.name:
        return None
    for work in ((p.parent,) if p.name == "store.zarr" else ()) + (p,):
        if work.name.startswith(".") and work.name.endswith(".partial") and len(work.name) > 9 and work.is_dir():
            return work.with_name(work.name[1 : -len(".partial")]), work, True
    work = p.with_name(f".{p.name}.partial")
    return (p, work, False) if work.is_dir() else None


def _num(x) -> str:
    """A float as the shortest text that reads back to it bit for bit (``1`` rather than ``1.0``)."""
    r = repr(float(x))
    return r[:-2] if r.endswith(".0") else r


def _resume_command(target: str, fp: dict) -> str | None:
    """The ``simulate`` command that resumes the stream recorded by fingerprint ``fp``, or None.

    The command is rebuilt from the recorded arguments and checked by running
    them through the code of ``simulate`` itself (body, torques, method
    options, initial state): it is returned only if it gives the very same
    fingerprint, i.e. if it resumes the run rather than being refused.
    """
    import inspect

    from ..io.stream import TIME_VARIABLES, solve_to_file, torque_fingerprint
    from ..model.body import RigidBody
    from ..model.equations import Model
    from ..solvers import get_method, make_problem

    known = {
        "version",
        "method",
        "options",
        "inertia",
        "positions",
        "q0",
        "omega0",
        "times",
        "chunk",
        "n",
        "variables",
        "torque",
    }
    try:
        chunk = inspect.signature(solve_to_file).parameters["chunk"].default
        if set(fp) - known or fp.get("positions") is not None or fp["chunk"] != chunk:
            return None  # a point-mass body, another chunk or other variables: not a 'simulate' run
        if list(fp["variables"]) != list(TIME_VARIABLES):
            return None
        t0, t_end, samples = fp["times"]["grid"]
        if float(t0) != 0.0:
            return None
        inertia = np.array(fp["inertia"], dtype=float)
        cfg: dict = {}
        flags: list[str] = []
        diag = inertia.shape == (3, 3) and np.all(inertia == np.diag(np.diag(inertia)))
        cfg["body.inertia"] = ",".join(_num(v) for v in (np.diag(inertia) if diag else inertia.ravel()))
        flags += ["--inertia", cfg["body.inertia"]]
        try:
            RigidBody(inertia_from(cfg["body.inertia"]))
        except EulerPoissonError:
            cfg["body.allow_unphysical"] = True
            flags.append("--allow-unphysical")
        cfg["initial.omega"] = ",".join(_num(v) for v in fp["omega0"])
        flags += ["--omega", cfg["initial.omega"]]
        if list(fp["q0"]) != [1.0, 0.0, 0.0, 0.0]:
            cfg["initial.quaternion"] = ",".join(_num(v) for v in fp["q0"])
            flags += ["--quaternion", cfg["initial.quaternion"]]
        flags += ["--t-end", _num(t_end), "--samples", str(int(samples))]
        from ..model.torques import TORQUES

        # the flags of every registered torque, from its own description (a torque without flags cannot be resumed
        # by a command)
        keys = {kind: tuple((f"torque.{p.toml_key}", p.name) for p in cls.cli) for kind, cls in TORQUES.items()}
        for rec in fp.get("torque", []):
            if not keys.get(rec.get("kind")):
                return None
            for key, field in keys[rec["kind"]]:
                v = rec[field]
                cfg[key] = ",".join(_num(x) for x in v) if isinstance(v, list) else _num(v)
                flags += [FLAGS[key], cfg[key]]
        model = Model(build_body(cfg), build_torques(cfg))
        method = fp["method"]
        from ..solvers.engine import default_method

        if method != default_method(model):
            flags += ["--method", method]
        cls = get_method(method)

        def config(opts):
            return json.loads(json.dumps(cls(**opts).config, default=float, sort_keys=True))

        defaults = config({})
        for k, v in sorted(fp["options"].items()):
            if defaults.get(k) != v:
                if k not in METHOD_OPTIONS or v is None or isinstance(v, (dict, list)):
                    return None
                cfg[f"method.{k}"] = _num(v) if isinstance(v, float) else str(v)
                flags += [FLAGS[f"method.{k}"], cfg[f"method.{k}"]]
        q0 = None
        if "initial.quaternion" in cfg:  # as simulate does: normalized
            q0 = np.array(parse_floats(cfg["initial.quaternion"], "--quaternion", (4,)))
            q0 = q0 / float(np.linalg.norm(q0))
        problem = make_problem(
            model, np.array([0.0]), omega0=parse_floats(cfg["initial.omega"], "--omega", (3,)), attitude0=q0
        )
        mine = {
            "version": fp["version"],
            "method": method,
            "options": config(method_options(cfg, None, method)),
            "inertia": np.asarray(problem.body.inertia).tolist(),
            "positions": None,
            "q0": problem.q0.tolist(),
            "omega0": problem.omega0.tolist(),
            "times": {"grid": [0.0, float(_num(t_end)), int(samples)]},
            "chunk": chunk,
            "n": int(samples),
            "variables": list(TIME_VARIABLES),
        }
        if not model.is_free:
            mine["torque"] = torque_fingerprint(model)
        if json.loads(json.dumps(mine, default=float, sort_keys=True)) != fp:
            return None
    except Exception:  # noqa: BLE001 - anything unexpected: no command rather than a wrong one
        return None
    import shlex

    return shlex.join(["eulerpoisson", "simulate", *flags, "--out", str(target)])


def _info_partial(args, target: Path, work: Path) -> int:
    """``info`` of an unfinished stream: how far it got, up to what time, and how to resume it."""
    from ..io.outputs import pid_alive
    from ..io.stream import TimeGrid

    try:
        with open(work / "state.json", encoding="utf-8") as fh:
            fp = json.load(fh)
    except (OSError, ValueError):
        print(
            f"{args.file}: an unfinished run to {target} that stopped before its first chunk (while its store "
            f"was being created): nothing was computed; the next run to {target} starts afresh"
        )
        return 0
    try:
        n, chunk = int(fp["n"]), int(fp["chunk"])
        fp["times"]["grid" if "grid" in fp["times"] else "array"]
    except (TypeError, KeyError):  # not a trajectory stream: a sweep (or a newer format)
        finished = [f for f in (work / "done").iterdir() if f.name.isdigit()] if (work / "done").is_dir() else []
        print(
            f"{args.file}: an unfinished sweep (or another unfinished result) to {target}, not a trajectory: "
            f"{len(finished)} chunk(s) finished; run the command that wrote it again to resume it "
            f"('eulerpoisson sweep CONFIG --out {target}')"
        )
        return 0
    nchunks = max(1, -(-n // chunk))
    done_dir = work / "done"
    done = (
        sorted(k for k in (int(f.name) for f in done_dir.iterdir() if f.name.isdigit()) if k < nchunks)
        if done_dir.is_dir()
        else []
    )
    samples_done = sum(min(chunk, n - k * chunk) for k in done)
    prefix = 0
    while prefix < len(done) and done[prefix] == prefix:
        prefix += 1
    pid = 0
    lock = target.with_name(f".{target.name}.lock")
    try:
        pid = int(lock.read_text().strip() or "0")
    except (OSError, ValueError):
        pass
    running = bool(pid) and pid != os.getpid() and pid_alive(pid)
    state = f"being written now (process {pid})" if running else "interrupted"
    lines = [
        f"{args.file}: unfinished run to {target} ({state}): {len(done)} of {nchunks} chunks finished, "
        f"{samples_done} of {n} samples ({100.0 * samples_done / n:.3g}%)"
        if n
        else f"{args.file}: unfinished run to {target} ({state}): no output times"
    ]

    def times(idx):
        grid = fp.get("times", {}).get("grid")
        if grid is not None:
            g = TimeGrid(float(grid[0]), float(grid[1]), int(grid[2]))
            return [float(g[i : i + 1][0]) for i in idx]
        from ..io.read import zarr_group

        tarr = zarr_group(work / "store.zarr")["time"]
        return [float(tarr[i]) for i in idx]

    try:
        if prefix:
            last = min(n, prefix * chunk) - 1
            ta, tb = times([0, last])
            lines.append(
                f"  finished    samples 0 to {last}: t from {ta:.6g} to {tb:.6g}"
                + (f" (and {len(done) - prefix} chunk(s) further on)" if len(done) > prefix else "")
            )
        elif done:
            lines.append(
                f"  finished    chunk(s) {', '.join(map(str, done[:8]))}{' ...' if len(done) > 8 else ''}"
                f" ({chunk} samples each)"
            )
        else:
            lines.append("  finished    nothing yet")
        if n:
            tn = times([n - 1])[0]
            lines.append(f"  run         {n} samples to t = {tn:.6g}, {chunk} per chunk")
    except Exception:  # noqa: BLE001 - the times are a courtesy: the counts above are what matters
        pass
    lines.append(f"  method      {fp.get('method', '?')}")
    try:
        from ..model.body import RigidBody
        from ..model.equations import Model
        from ..model.torques import torque_from_dict

        body = (
            RigidBody(np.array(fp["inertia"], dtype=float), allow_unphysical=True)
            if fp.get("positions") is None
            else None
        )
        if body is not None:
            lines.append(f"  body        {body!r}")
            lines.append(f"  torque      {Model(body, [torque_from_dict(r) for r in fp.get('torque', [])]).describe()}")
    except Exception:  # noqa: BLE001
        pass
    lines.append(
        f"  store       {work / 'store.zarr'}: the finished chunks (xarray.open_zarr reads it; unfinished "
        "samples are NaN)"
    )
    if running:
        lines.append("  resume      not now: wait for the running process to finish (or stop it with Ctrl-C)")
    else:
        cmd = _resume_command(str(target), fp)
        lines.append(
            f"  resume      {cmd}"
            if cmd
            else f"  resume      run the command that wrote it again ('eulerpoisson simulate ... --out {target}', "
            "or solve_to_file(..., resume=True) with the same arguments)"
        )
    print("\n".join(lines))
    return 0


def cmd_info(args) -> int:
    check_file_name(args.file, "trajectory file")
    partial = _partial_run_of(args.file)
    if partial is not None and (partial[2] or not os.path.exists(args.file)):
        return _info_partial(args, partial[0], partial[1])
    traj = read_trajectory(args.file)
    if partial is not None:  # a finished file, and an unfinished run to replace it (simulate --overwrite)
        print(
            f"{args.file}: note: an unfinished run to replace it is kept in {partial[1]} "
            f"('eulerpoisson info {partial[1] / 'store.zarr'}' says how far it got)"
        )
    if getattr(traj, "lazy", False):
        return _info_store(args, traj)
    b = traj.body
    lines = [
        f"{args.file}: eulerpoisson trajectory",
        f"  method      {traj.method} {json.dumps(traj.options) if traj.options else ''}".rstrip(),
        f"  torque      {traj.model.describe()}",
    ]
    if len(traj.t) == 0:  # a valid file with no output times: nothing to measure
        lines.append("  samples     0 (no output times)")
        lines.append(
            f"  body        {b!r}" if not traj.batch_shape else f"  bodies      batch of shape {traj.batch_shape}"
        )
        print("\n".join(lines))
        return 0
    lines.append(f"  samples     {len(traj.t)}, t from {traj.t.min():.6g} to {traj.t.max():.6g}")
    if traj.batch_shape:
        lines.append(f"  bodies      batch of shape {traj.batch_shape}")
    else:
        lines.append(f"  body        {b!r}")
        lines.append(
            f"  energy      {float(traj.energy[0]):.15g}" + ("" if traj.model.is_free else " (kinetic + potential)")
        )
        lines.append(f"  m           {np.round(traj.m[0], 12).tolist()}")
    lines.append("  drift       " + ", ".join(f"{k} {np.max(v):.2e}" for k, v in traj.drift().items()))
    print("\n".join(lines))
    return 0


def add_commands(sub) -> None:
    """Register ``info`` on the subcommand parser ``sub``."""
    ex = argparse.RawDescriptionHelpFormatter
    i = sub.add_parser(
        "info",
        help="describe a trajectory file",
        formatter_class=ex,
        epilog="examples:\n  eulerpoisson info run.nc\n  eulerpoisson info long.zarr   # a store: only its "
        "metadata and its first and last samples are read",
    )
    i.add_argument("file", help="trajectory file: NetCDF (version 4 or 3) or a .zarr store")
    i.set_defaults(func=cmd_info)
