"""Static checks of the tree: mypy on the package, ruff's linter and formatter on everything.

Each runs as a subprocess from the repository root, so the settings are those of
``pyproject.toml`` (``[tool.mypy]``, ``[tool.ruff]``); the tools are pinned in the
``test`` extra. A tool that is not installed skips its test with the reason.

mypy keeps its cache in the default ``.mypy_cache`` of the repository (ignored by
git): a fresh clone pays the cold run (about 15 s on two cores), later runs reuse it.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

from _limits import HANG_GUARD_S

ROOT = Path(__file__).resolve().parents[1]


def _run(module: str, *args: str, timeout: float = HANG_GUARD_S) -> subprocess.CompletedProcess:
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed (it comes with the 'test' extra: pip install -e '.[test]')")
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def _report(proc: subprocess.CompletedProcess) -> str:
    out = (proc.stdout + proc.stderr).strip()
    lines = out.splitlines()
    if len(lines) > 80:
        lines = lines[:40] + [f"... ({len(lines) - 80} lines left out) ..."] + lines[-40:]
    return "\n".join(lines)


@pytest.mark.slow
def test_mypy_is_clean_on_the_package():
    proc = _run("mypy")  # files, strictness and per-module settings: [tool.mypy] in pyproject.toml
    assert proc.returncode == 0, f"mypy found problems (python -m mypy):\n{_report(proc)}"


def test_ruff_check_is_clean():
    proc = _run("ruff", "check", ".", "--output-format", "concise", "--no-fix")
    assert proc.returncode == 0, f"ruff check found problems (python -m ruff check .):\n{_report(proc)}"


def test_ruff_format_leaves_the_tree_as_it_is():
    proc = _run("ruff", "format", "--check", ".")
    assert proc.returncode == 0, (
        f"files that 'ruff format' would change (run python -m ruff format . and commit):\n{_report(proc)}"
    )
