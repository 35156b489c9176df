"""Every command of the README's command-line sections runs, top to bottom, as a new user would type it.

The one change: the example that streams 10^8 samples (about 11 GB) runs with 2*10^4 samples here.
The first command runs as typed in a shell (the ``eulerpoisson`` console script in a new process); the
others run in this process through the same entry point (``eulerpoisson.cli.main``, its exit status and
its stderr checked), which spares a Python start-up and a numba cache load per command, and the
``audit`` command prints the run's one audit report (computed once per test run, checked in
tests/test_audit.py; see conftest.shared_audit).
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from _limits import HANG_GUARD_S
from eulerpoisson.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
EXE = str(Path(sys.executable).with_name("eulerpoisson"))


def _commands():
    cmds = []
    for block in re.findall(r"```sh\n(.*?)```", README, flags=re.S):
        text = block.replace("\\\n", " ")
        for line in text.splitlines():
            line = line.split("#", 1)[0].strip()
            if line.startswith("eulerpoisson "):
                cmds.append(line)
    return cmds


COMMANDS = _commands()


def test_the_readme_has_commands():
    assert len(COMMANDS) >= 12 and any("--com" in c for c in COMMANDS)


@pytest.mark.slow
def test_readme_commands_run_top_to_bottom(tmp_path, monkeypatch, capsys, shared_audit):
    pytest.importorskip("matplotlib")
    pytest.importorskip("zarr")
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    for i, cmd in enumerate(COMMANDS):
        cmd = cmd.replace("--samples 100000000", "--samples 20000")
        argv = shlex.split(cmd)
        if i == 0:  # as typed in a shell
            res = subprocess.run(
                [EXE, *argv[1:]],
                cwd=tmp_path,
                capture_output=True,
                text=True,
                timeout=HANG_GUARD_S,
                env={**os.environ, "MPLBACKEND": "Agg"},
            )
            code, err = res.returncode, res.stderr
        else:
            code = main(argv[1:])
            err = capsys.readouterr().err
        assert code == 0, f"{cmd}\n{err}"
        assert "Traceback" not in err, cmd
    for name in (
        "run.nc",
        "polhode.png",
        "movie.html",
        "atlas.zarr",
        "atlas.png",
        "top.nc",
        "top_apex.png",
        "long.zarr",
    ):
        assert (tmp_path / name).exists(), name
