"""What a user reads (issue 22, items 13-15): the command-line reference, the documentation errors, the landing page.

* 13: the site's command-line reference is generated from the parser (``docs/_ext/ep_cli.py``): every
  subcommand and every flag appears, with its default, its unit and the ``--help`` examples; the page
  builds without a warning;
* 14: the ``viz.plots.plot`` example runs, the oracle guide says the verdict the code returns, and no
  command line of the site, the README or the docstrings' examples holds a non-ASCII dash (``–``, ``—``,
  ``−``), in the sources or as Sphinx renders them;
* 15: the landing page (one screen: the picture, the two commands, the four tasks) and the warm-up in
  getting started.
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import doctest
import html
import importlib
import io
import os
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import eulerpoisson

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import ep_cli  # noqa: E402  (docs/_ext: the directive of the command-line reference)

DASHES = "\u2013\u2014\u2212"  # en dash, em dash, minus sign
#: a non-ASCII dash where a command line has a flag or a minus: before a letter or another dash
BAD_DASH = re.compile(rf"(?:^|(?<=[\s=\[(\"'`]))[{DASHES}][-{DASHES}]?[A-Za-z]")
GENERATED = ("_build", "auto_examples", "generated", "__pycache__")


def _parser() -> argparse.ArgumentParser:
    return importlib.import_module("eulerpoisson.cli.main").build_parser()


def _programs(parser: argparse.ArgumentParser) -> dict[str, tuple[argparse.ArgumentParser, list[str]]]:
    """``"eulerpoisson simulate"`` -> (its parser, every option string and positional it takes)."""
    out = {}
    for prog, sub in [(parser.prog, parser)] + [(f"{parser.prog} {n}", s) for n, _, s in ep_cli.subcommands(parser)]:
        names = []
        for action in ep_cli.arguments(sub):
            names += action.option_strings or [action.metavar if isinstance(action.metavar, str) else action.dest]
        out[prog] = (sub, names)
    return out


def _reference_entries(text: str) -> dict[str, list[str]]:
    """The ``.. option::`` entries of the generated reference, by ``.. program::``."""
    out: dict[str, list[str]] = {}
    program = None
    for line in text.splitlines():
        if line.startswith(".. program:: "):
            program = line.split("::", 1)[1].strip()
            out.setdefault(program, [])
        elif line.startswith(".. option:: "):
            assert program is not None, line
            for signature in line.split("::", 1)[1].strip().split(", "):
                out[program].append(signature.split(" ", 1)[0])
    return out


# ---------------------------------------------------------------------------
# 13: the command-line reference
# ---------------------------------------------------------------------------
def test_the_cli_reference_has_every_subcommand_and_flag():
    parser = _parser()
    text = ep_cli.cli_reference_rst(parser)
    entries = _reference_entries(text)
    programs = _programs(parser)
    assert len(programs) >= 12 and "eulerpoisson simulate" in programs and "eulerpoisson warmup" in programs
    assert set(entries) == set(programs)
    for prog, (sub, names) in programs.items():
        assert entries[prog] == names, prog  # every argument, once, in the parser's order
        assert f"``{prog}``" in text, prog  # its section
        if sub.description:  # its description, from its first words
            assert " ".join(sub.description.split()[:4]) in text, prog
        if sub.epilog:  # the --help examples, verbatim
            for line in sub.epilog.splitlines():
                if line.strip().startswith("eulerpoisson "):
                    assert f"   {line}" in text, (prog, line)


def test_the_cli_reference_states_defaults_units_and_choices():
    text = ep_cli.cli_reference_rst()
    assert "Units: eulerpoisson takes any consistent units" in text
    audit = text.split(".. program:: eulerpoisson audit", 1)[1].split(".. program::", 1)[0]
    assert "One of ``md``, ``json``, ``tex``; default ``md``." in audit
    simulate = text.split(".. program:: eulerpoisson simulate", 1)[1].split(".. program::", 1)[0]
    t_end = simulate.split(".. option:: --t-end", 1)[1].split(".. option::", 1)[0]
    assert "Unit: T, the time unit of the rates." in t_end
    assert "(default 1001)" in simulate  # a default the help states
    demo = text.split(".. program:: eulerpoisson demo", 1)[1].split(".. program::", 1)[0]
    assert "Default ``out``." in demo


def test_every_unit_of_the_reference_names_a_flag_of_the_parser():
    dests = set()
    for sub, _ in _programs(_parser()).values():
        dests.update(a.dest for a in ep_cli.arguments(sub))
    assert not set(ep_cli.UNITS) - dests, sorted(set(ep_cli.UNITS) - dests)


def test_the_cli_reference_is_in_the_user_guide_and_registered():
    assert "   cli\n" in (DOCS / "user_guide" / "index.rst").read_text(encoding="utf-8")
    assert ".. eulerpoisson-cli::" in (DOCS / "user_guide" / "cli.rst").read_text(encoding="utf-8")
    conf = (DOCS / "conf.py").read_text(encoding="utf-8")
    assert '"ep_cli"' in conf


def _conf_value(name: str):
    """A constant assigned in docs/conf.py (None when it is not)."""
    tree = ast.parse((DOCS / "conf.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == name for t in node.targets):
            return ast.literal_eval(node.value)
    return None


def _mini_site(tmp_path: Path, pages: dict[str, str]) -> tuple[subprocess.CompletedProcess, Path]:
    """Build ``pages`` (name -> reST) with the site's directive and smart-quote setting; fast (no API, no gallery)."""
    src = tmp_path / "src"
    src.mkdir()
    smart = _conf_value("smartquotes_action")
    (src / "conf.py").write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(DOCS / '_ext')!r})\n"
        "extensions = ['ep_cli']\n"
        "project = 'eulerpoisson'\n" + (f"smartquotes_action = {smart!r}\n" if smart is not None else ""),
        encoding="utf-8",
    )
    for name, text in pages.items():
        (src / f"{name}.rst").write_text(text, encoding="utf-8")
    out = tmp_path / "html"
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-n", "--keep-going", "-q", str(src), str(out)]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env, check=False), out


def _html_text(path: Path) -> str:
    page = path.read_text(encoding="utf-8")
    return html.unescape(re.sub(r"<[^>]+>", "", page))


def test_the_cli_reference_page_builds_and_renders_every_flag(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra is not installed (pip install -e '.[docs]')")
    oracle = (DOCS / "user_guide" / "oracle.rst").read_text(encoding="utf-8")
    index = (DOCS / "user_guide" / "cli.rst").read_text(encoding="utf-8") + "\n.. toctree::\n\n   oracle\n"
    res, out = _mini_site(tmp_path, {"index": index, "oracle": oracle})
    log = res.stdout + res.stderr
    assert res.returncode == 0, log[-6000:]
    # the reference page itself is clean (the oracle page's cross-references point outside this small site)
    assert not [line for line in log.splitlines() if "index.rst" in line], log[-6000:]
    text = _html_text(out / "index.html")
    for prog, (_, names) in _programs(_parser()).items():
        assert prog in text
        for name in names:
            assert name in text, (prog, name)
    for page in ("index", "oracle"):  # as rendered: no flag turned into an en dash by smart quotes
        rendered = _html_text(out / f"{page}.html")
        assert not BAD_DASH.findall(rendered), (page, BAD_DASH.findall(rendered)[:5])
    assert "--quaternion-order xyzw" in _html_text(out / "oracle.html")


# ---------------------------------------------------------------------------
# 14: documentation errors
# ---------------------------------------------------------------------------
def test_the_plot_example_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    from eulerpoisson.viz import plots

    assert "+SKIP" not in plots.plot.__doc__ and "[3, 5, 9]" not in plots.plot.__doc__
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in doctest.DocTestFinder().find(plots.plot, "plot", globs={}):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.attempted >= 3 and result.failed == 0
    assert (tmp_path / "polhode.png").stat().st_size > 0


def _code_blocks(text: str, language: str = "python") -> list[str]:
    """The ``.. code-block:: <language>`` blocks of a reST page, dedented."""
    blocks = []
    for match in re.finditer(rf"^\.\. code-block:: {language}\n\n((?:   .*\n|\n)+)", text, flags=re.M):
        blocks.append("\n".join(line[3:] for line in match.group(1).splitlines()))
    return blocks


def test_the_oracle_guide_prints_the_verdict_the_code_returns(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    guide = (DOCS / "user_guide" / "oracle.rst").read_text(encoding="utf-8")
    (block,) = [b for b in _code_blocks(guide) if "rep.verdict" in b]
    said = re.search(r"print\(rep\.verdict.*#\s*(\S+)", block)
    assert said, block
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        exec(compile(block, "oracle.rst", "exec"), {})
    printed = buffer.getvalue().split()
    assert printed[0] == said.group(1).rstrip(";,") == "differs", (printed[:3], said.group(1))
    from eulerpoisson.oracle import compare

    source = Path(compare.__file__).read_text(encoding="utf-8")  # the verdicts the code returns, named in the guide
    for word in ("pass", "fail", "round-off", "differs"):
        assert f'"{word}"' in source, word
        assert f"``{word}``" in guide, word


# --- non-ASCII dashes in command lines -----------------------------------------------------------------
def _site_sources() -> list[Path]:
    files = [ROOT / "README.md"]
    for path in sorted(DOCS.rglob("*")):
        rel = path.relative_to(DOCS)
        if path.suffix in (".rst", ".md") and not any(part in GENERATED for part in rel.parts):
            if not (rel.parts[0] == "api" and path.name.startswith("eulerpoisson")) and path.name != "audit_report.md":
                files.append(path)
    return files


def _strip_comment(line: str) -> str:
    """A code line without its ``#`` comment (prose, not something a user runs)."""
    return re.split(r"(?:^|\s)#", line, maxsplit=1)[0]


def _starts_literal(line: str) -> bool:
    """The line introduces a literal block (``text::``) or a code directive (``.. code-block:: sh``)."""
    if re.match(r"\s*\.\. (code-block|code|sourcecode|literalinclude)::", line):
        return True
    return line.rstrip().endswith("::") and not line.lstrip().startswith(".. ")


def _rst_code(text: str) -> list[str]:
    """The lines of a reST text that a user copies: literal blocks, inline literals, doctest lines."""
    lines = text.splitlines()
    code = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if _starts_literal(line):
            indent = len(line) - len(line.lstrip())
            i += 1
            while i < len(lines) and (not lines[i].strip() or len(lines[i]) - len(lines[i].lstrip()) > indent):
                if lines[i].strip() and not lines[i].strip().startswith(":"):
                    code.append(_strip_comment(lines[i]))
                i += 1
            continue
        stripped = line.strip()
        if stripped.startswith((">>> ", "... ")):
            code.append(_strip_comment(stripped[4:]))
        code += re.findall(r"``(.+?)``", line)
        i += 1
    return code


def _md_code(text: str) -> list[str]:
    code = []
    for block in re.findall(r"^```[^\n]*\n(.*?)^```", text, flags=re.S | re.M):
        code += [_strip_comment(line) for line in block.splitlines()]
    prose = re.sub(r"^```[^\n]*\n.*?^```", "", text, flags=re.S | re.M)
    code += re.findall(r"`([^`\n]+)`", prose)
    return code


def _docstrings() -> dict[str, str]:
    """Every docstring of the package (modules, classes, functions, methods), by name."""
    out = {}
    for info in pkgutil.walk_packages(eulerpoisson.__path__, "eulerpoisson."):
        mod = importlib.import_module(info.name)
        tree = ast.parse(Path(mod.__file__).read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                doc = ast.get_docstring(node, clean=True)
                if doc:
                    out[f"{info.name}:{getattr(node, 'name', '')}"] = doc
    return out


def _bad(code: list[str]) -> list[str]:
    return [line.strip() for line in code if BAD_DASH.search(line)]


def test_no_command_line_of_the_site_has_a_non_ascii_dash():
    found = {}
    for path in _site_sources():
        text = path.read_text(encoding="utf-8")
        bad = _bad(_md_code(text) if path.suffix == ".md" else _rst_code(text))
        if bad:
            found[str(path.relative_to(ROOT))] = bad
    for name, doc in _docstrings().items():
        bad = _bad(_rst_code(doc))
        if bad:
            found[name] = bad
    parser = _parser()  # the --help texts the reference shows
    for prog, (sub, _) in _programs(parser).items():
        texts = [sub.description or "", sub.epilog or "", *(a.help or "" for a in ep_cli.arguments(sub))]
        bad = _bad([line for t in texts for line in t.splitlines()])
        if bad:
            found[prog] = bad
    assert not found, found


def test_the_scanner_finds_a_flag_written_with_an_en_dash():
    assert _bad(_rst_code("rerun with ``\u2013quaternion-order xyzw``"))
    assert _bad(_rst_code(".. code-block:: sh\n\n   eulerpoisson validate run.csv \u2014json\n"))
    assert _bad(_md_code("```sh\neulerpoisson simulate \u2212\u2212t-end 5\n```\n"))
    assert _bad(_rst_code(">>> main(['simulate', '\u2013\u2013json'])"))
    assert not _bad(_rst_code("``1 \u2212 k\u00b2``, work\u2013precision, ``roll\u2013yaw``"))


def _prose_flags(text: str) -> list[str]:
    """``--flag`` written in the prose of a reST page (outside literals): Sphinx's smart quotes render its
    ``--`` as an en dash unless ``smartquotes_action`` leaves dashes alone."""
    lines = text.splitlines()
    prose = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if _starts_literal(line):
            indent = len(line) - len(line.lstrip())
            i += 1
            while i < len(lines) and (not lines[i].strip() or len(lines[i]) - len(lines[i].lstrip()) > indent):
                i += 1
            continue
        prose.append(line)
        i += 1
    text = "\n".join(prose)
    text = re.sub(r"``.+?``", "", text, flags=re.S)
    text = re.sub(r"`[^`]+`", "", text)
    return re.findall(r"(?<![\w`-])--[A-Za-z][\w-]*", text)


def test_no_flag_is_written_in_prose_where_smart_quotes_would_make_it_an_en_dash():
    assert "D" not in (_conf_value("smartquotes_action") or "qDe")
    found = {}
    for path in _site_sources():
        if path.suffix == ".rst":
            flags = _prose_flags(path.read_text(encoding="utf-8"))
            if flags:
                found[str(path.relative_to(ROOT))] = flags
    assert not found, found


# ---------------------------------------------------------------------------
# 15: the landing page and getting started
# ---------------------------------------------------------------------------
def test_the_landing_page_fits_one_screen_with_the_picture_the_commands_and_the_four_tasks():
    index = (DOCS / "index.rst").read_text(encoding="utf-8")
    top = index.split(".. toctree::", 1)[0]
    assert len(top.splitlines()) <= 45 and len(top.split()) <= 330, "more than one screen before the contents"
    picture = re.search(r"^\.\. (?:figure|image):: (\S+)", top, flags=re.M)
    assert picture and (DOCS / picture.group(1)).exists(), picture
    assert "tennis" in top.lower() and "omega" in picture.group(1)
    assert "make demo" in top and "make test" in top
    pages = re.findall(r":doc:`(?:[^`<]*<)?([\w/]+)>?`", top)
    for task, page in (
        ("simulate", "getting_started"),
        ("torques", "user_guide/torques"),
        ("fit", "user_guide/fitting"),
        ("validate", "user_guide/oracle"),
    ):
        assert f"**{task}**" in top, task
        assert page in pages and (DOCS / f"{page}.rst").exists(), page
    assert "user_guide/cli" in pages


def test_getting_started_says_what_the_warm_up_costs():
    text = (DOCS / "getting_started.rst").read_text(encoding="utf-8")
    assert "eulerpoisson warmup" in text
    section = text.split("The warm-up\n", 1)[1].split("\n----", 1)[0] if "The warm-up\n" in text else text
    assert re.search(r"about 30\s*s on two cores", text), "the warm-up's cost"
    assert "numba" in section and "cache" in section
