"""The documentation site builds without a warning or a broken cross-reference, and documents every public name.

The site is built as ``make docs`` builds it (Sphinx, nitpicky, warnings as errors) from a copy of the
sources in a temporary folder, so that the build here never touches the working tree; the gallery's
examples are not run (``-D plot_gallery=0``; ``make docs`` runs them) and the paper's audit is not
computed (``-D eulerpoisson_run_audit=0``; tests/test_audit.py runs it).
"""

import importlib
import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import eulerpoisson
from _limits import HANG_GUARD_S

pytest.importorskip("sphinx", reason="the docs extra is not installed (pip install -e '.[docs]')")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(p.stem for p in (ROOT / "examples").glob("*.py"))


def _public_modules():
    """``eulerpoisson`` and every subpackage that has an ``__all__``."""
    mods = ["eulerpoisson"]
    for info in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."):
        if info.ispkg and hasattr(importlib.import_module(info.name), "__all__"):
            mods.append(info.name)
    return mods


def _build(tmp):
    """Build the site from a copy of docs/, examples/ and the benchmark results; returns (result, html dir)."""
    generated = ("_build", "auto_examples", "generated", "__pycache__", "audit_report.md", "modules.rst.inc")
    shutil.copytree(ROOT / "docs", tmp / "docs", ignore=shutil.ignore_patterns(*generated, "eulerpoisson*.rst"))
    shutil.copytree(ROOT / "examples", tmp / "examples", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "benchmarks" / "results", tmp / "benchmarks" / "results")
    out = tmp / "html"
    options = "-b html -n -W --keep-going -q -D plot_gallery=0 -D eulerpoisson_run_audit=0".split()
    cmd = [sys.executable, "-m", "sphinx", *options, str(tmp / "docs"), str(out)]
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONWARNINGS": "default"}
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=HANG_GUARD_S), out


# one test, one build (about 37 s of CPU with docs/conf.py's build-time shortcuts): split into several,
# pytest-xdist would build the site once per worker
def test_the_site_builds_clean_and_documents_every_public_name(tmp_path):
    res, out = _build(tmp_path)
    log = res.stdout + res.stderr
    assert res.returncode == 0, log[-20000:]
    # Sphinx's warnings, and numpydoc's own ("Unknown section Options in the docstring of ...": Python warnings)
    for word in ("WARNING", "ERROR", "in the docstring of"):
        assert word not in log, log[-20000:]

    # every name of eulerpoisson.__all__ and of each subpackage's __all__ has its API page
    missing = []
    for module in _public_modules():
        mod = importlib.import_module(module)
        if not (out / "api" / f"{module}.html").exists():
            missing.append(module)
        pages = out / "api" / "generated"
        missing += [f"{module}.{n}" for n in mod.__all__ if not (pages / f"{module}.{n}.html").exists()]
    assert not missing, f"no API page for {missing}"

    # the guide, the theory, the gallery (one page per example), the benchmarks, the changelog
    guide = [f"user_guide/{p}" for p in ("conventions", "methods", "torques", "files", "sweeps", "fitting", "oracle")]
    theory = ["theory/equations", "theory/audit", "theory/audit_report"]
    gallery = ["auto_examples/index", *(f"auto_examples/{name}" for name in EXAMPLES)]
    for page in ["getting_started", *guide, *theory, *gallery, "benchmarks", "changelog"]:
        assert (out / f"{page}.html").exists(), page
    equations = (out / "theory" / "equations.html").read_text(encoding="utf-8")
    for label in ("1.9", "1.12", "1.13", "1.16", "1.21", "1.23.1", "1.30"):
        assert f"\\tag{{{label}}}" in equations, label
    bench = (out / "benchmarks.html").read_text(encoding="utf-8")
    summary = (ROOT / "benchmarks" / "results" / "summary.md").read_text(encoding="utf-8")
    title = summary.splitlines()[0].lstrip("# ").strip()
    assert title in bench, title
    if (ROOT / "benchmarks" / "results" / "work_precision.png").exists():
        assert (out / "_images" / "work_precision.png").exists()
