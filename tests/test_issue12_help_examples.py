"""Every example of every subcommand's ``--help`` runs (issue 12, item 11).

The examples are read from the parser itself (``eulerpoisson COMMAND
--help``, the ``examples:`` block), so an example added later is run too.
The examples of ``simulate`` run first, in a fresh folder; those of every
other command then run in a copy of that folder (the files they read, such
as ``run.nc`` and ``top.nc``, are made by ``simulate``'s examples), as a new
user reading one help page would type them. The only help they get is the
input files the examples name (``run.toml``, the ``examples`` folder, a
small ``long.zarr``) and smaller sizes where a command would take minutes: the sweep grid is coarser and the
paper's audit is one equation (the whole audit is tested in test_audit.py).

No example may reach a network: a remote Dask scheduler (``tcp://...``) is
named in the prose of ``sweep --help``, never as an example.

This is the one test that runs the help examples (once per test run), and checks the files they write; the
tests of ``simulate``, ``plot`` (tests/test_cli_torque.py), ``validate`` and ``cases`` (tests/test_oracle.py)
check what their command's examples show.
"""

import argparse
import re
import shlex
import shutil
from pathlib import Path

import pytest

import eulerpoisson as ep
from eulerpoisson.cli import main
from eulerpoisson.cli.commands import _prepare_argv, build_parser

ROOT = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _subcommands() -> dict:
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def _examples(help_text: str) -> list[str]:
    """The command lines of the ``examples:`` (or ``example:``) block of a help text."""
    m = re.search(r"^examples?:\n(.*?)(?:\n\n|\Z)", help_text, flags=re.S | re.M)
    if m is None:
        return []
    cmds = []
    for line in m.group(1).replace("\\\n", " ").splitlines():
        line = line.split("#", 1)[0].strip()
        if line.startswith("eulerpoisson "):
            cmds.append(line)
    return cmds


EXAMPLES = {name: _examples(sp.format_help()) for name, sp in _subcommands().items()}


def test_every_subcommand_shows_examples_that_parse():
    parser = build_parser()
    assert set(EXAMPLES) >= {"simulate", "audit", "plot", "animate", "sweep", "info", "demo", "validate", "cases"}
    for name, cmds in EXAMPLES.items():
        assert cmds, f"'eulerpoisson {name} --help' shows no example"
        for cmd in cmds:
            argv = shlex.split(cmd)[1:]
            parser.parse_args(_prepare_argv(argv, parser))  # raises (UsageError) on a bad example


def test_no_example_reaches_a_network():
    for name, cmds in EXAMPLES.items():
        for cmd in cmds:
            assert "tcp://" not in cmd and "://" not in cmd, (name, cmd)
    text = _subcommands()["sweep"].format_help()
    assert "--scheduler tcp://HOST:8786" in text  # said in the prose, where nothing runs it


def _small_sweep(path: Path) -> None:
    text = (ROOT / "examples" / "sweep.toml").read_text(encoding="utf-8")
    small = text.replace("num = 91}", "num = 7}").replace("num = 181}", "num = 13}")
    assert small.count("num = 7}") == 1 and small.count("num = 13}") == 1, "examples/sweep.toml changed: update me"
    path.write_text(small, encoding="utf-8")


@pytest.mark.slow
def test_every_help_example_runs(capsys, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    pytest.importorskip("zarr")
    pytest.importorskip("sympy")
    from eulerpoisson.paper import audit as A

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    # the inputs the examples name
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    shutil.copy(ROOT / "examples" / "run.toml", tmp_path / "run.toml")
    _small_sweep(tmp_path / "examples" / "sweep.toml")
    # the README's 10^8-sample long.zarr, small
    assert (
        run(
            capsys,
            "simulate",
            "--inertia",
            "1,2,3",
            "--omega",
            "1,0.1,0.5",
            "--t-end",
            "100",
            "--samples",
            "20000",
            "--out",
            "long.zarr",
            "--quiet",
        )[0]
        == 0
    )
    # the audit of one equation instead of all (25 s each time)
    small = A.run_audit(entries=[e for e in A.ENTRIES if e.equation == "1.12"], integrability=False)
    monkeypatch.setattr(A, "run_audit", lambda **kw: small)

    # the examples of simulate make the files that the other pages read (run.nc, top.nc); every other page is
    # then tried on its own, in a copy of that folder, as a user reading one help page would
    base = tmp_path / "base"
    base.mkdir()
    for f in ("run.toml", "examples", "long.zarr"):
        shutil.move(tmp_path / f, base / f)
    ran = []
    for name in ["simulate"] + [n for n in EXAMPLES if n != "simulate"]:
        here = base if name == "simulate" else tmp_path / name
        if name != "simulate":
            shutil.copytree(base, here)
        monkeypatch.chdir(here)
        for cmd in EXAMPLES[name]:
            code, out, err = run(capsys, *shlex.split(cmd)[1:])
            assert code == 0, f"{name} --help example failed: {cmd}\n{err}"
            assert "Traceback" not in err, cmd
            ran.append(cmd)
    assert len(ran) == sum(len(c) for c in EXAMPLES.values()) >= 25
    for f in (
        "base/run.nc",
        "base/top.nc",
        "base/top_apex.png",
        "audit/audit.json",
        "audit/audit.tex",
        "plot/polhode.pdf",
        "plot/apex.png",
        "animate/movie.gif",
        "sweep/atlas.zarr",
        "sweep/atlas.png",
        "sweep/atlas_serial.zarr",
        "demo/out/tennis_racket.nc",
        "demo/out/audit.md",
        "validate/racket_error.png",
        "cases/cases_csv/sphere.csv",
    ):
        assert (tmp_path / f).exists(), f
    assert not (tmp_path / "cases" / "cases_csv" / "sphere.nc").exists()  # --csv-only
    assert ep.Trajectory.open(tmp_path / "base" / "top.nc").model.lagrange_top() is not None
