"""Every Python example of the README and of the docstrings runs (and prints what it says)."""

import doctest
import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import eulerpoisson

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"```python\n(.*?)```", README, flags=re.S)
MODULES = sorted(m.name for m in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."))


def test_the_readme_has_python_examples():
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, tmp_path, monkeypatch, capsys, shared_audit):
    # run_audit() gives the run's one audit report (computed once, checked in test_audit.py; conftest)
    monkeypatch.chdir(tmp_path)
    # the later blocks use the names of the first one (the short tour), as in one session
    namespace: dict = {}
    for i in sorted({0, index}):
        exec(compile(BLOCKS[i], f"README.md block {i}", "exec"), namespace)
    out = capsys.readouterr().out
    if "UnsupportedModelError as err" in BLOCKS[index]:
        assert "methods that can: rk" in out


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name, tmp_path, monkeypatch, request):
    monkeypatch.chdir(tmp_path)
    mod = importlib.import_module(name)
    if name.startswith("eulerpoisson.jax"):
        request.getfixturevalue("xla_optimized")  # these examples run their programs more than they compile them
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} docstring examples failed"
