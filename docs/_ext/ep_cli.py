"""The command-line reference of the site, generated from the parser (``.. eulerpoisson-cli::``).

The directive walks ``eulerpoisson.cli.main.build_parser()`` (the parser the ``eulerpoisson`` command
runs) and writes, for the program and for every subcommand in the order ``eulerpoisson --help`` lists
them: its one-line summary and description, its usage, every argument (flags with their metavar, the
help text, the default, the choices and the unit of a physical quantity) as Sphinx ``option``
entries (so ``:option:`eulerpoisson simulate --t-end``` links to it), and its ``--help`` epilog (the
examples) as it prints. Nothing is written by hand, so the page cannot drift from the command.

:func:`cli_reference_rst` returns the page's reStructuredText (the tests call it directly); the
directive parses that text in place.
"""

from __future__ import annotations

import argparse
import importlib
import re
from pathlib import Path

#: the unit of each quantity a flag takes, by the flag's destination (``args.<dest>``). eulerpoisson
#: takes any consistent units: times in one time unit T (that of --t-end), angles in radians unless a
#: flag says degrees; inertia in any unit U (mass x length^2), so angular momentum is U rad/T and a
#: torque U rad/T^2. Every key here must be a destination of the parser (tests/test_docs_v3.py).
UNITS = {
    "inertia": "U, any unit of mass x length² (the motion depends only on the ratios and the rates)",
    "omega": "rad/T, T the time unit of the run",
    "m": "U rad/T (U the unit of the inertia)",
    "quaternion": "none (a unit quaternion, scalar first)",
    "gibbs": "none (k tan(α/2))",
    "t_end": "T, the time unit of the rates",
    "dt": "T",
    "com": "length, in the unit of the inertia's length² (U = mass x length²)",
    "mass": "mass, in the unit of the inertia's mass (U = mass x length²)",
    "gravity": "length/T², the length of --com",
    "gravity_gradient": "rad/T",
    "body_torque": "U rad/T²",
    "space_torque": "U rad/T²",
    "magnetic_dipole": "A m² (any unit whose product with the field's is U rad/T²)",
    "magnetic_field": "T (tesla; any unit whose product with the dipole's is U rad/T²)",
    "tolerance": "rad",
    "sigma_attitude": "degrees",
    "sigma_axis": "degrees",
    "sigma_omega": "the unit of the rates of the file",
    "fps": "frames per second",
}

#: what the reference says of the units, before the commands
UNITS_NOTE = (
    "Units: eulerpoisson takes any consistent units. Times are in one time unit T (that of --t-end), "
    "angular velocities in rad/T, moments of inertia in any unit U (mass x length², only the ratios and the "
    "rates matter for a free body), angular momenta in U rad/T and torques in U rad/T²; angles are radians "
    "unless a flag says degrees (DEG). Each argument below gives the unit of its quantity."
)

_FLAG = re.compile(r"(?<![\w`$-])(--?[A-Za-z][\w-]*|\$[A-Z_][A-Z0-9_]*)(?![\w`])")
_SPECIAL = re.compile(r"([\\*`|_])")
_WIDTH = 100


def build_parser() -> argparse.ArgumentParser:
    """The parser of the ``eulerpoisson`` command (``eulerpoisson.cli.main.build_parser``).

    ``eulerpoisson.cli.main`` as an attribute is the function ``main`` (the package re-exports it), so the
    module is imported by its name.
    """
    return importlib.import_module("eulerpoisson.cli.main").build_parser()


def subcommands(parser: argparse.ArgumentParser) -> list[tuple[str, str, argparse.ArgumentParser]]:
    """``(name, one-line summary, parser)`` of every subcommand, in the order ``--help`` lists them."""
    out = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            summaries = {a.dest: a.help or "" for a in action._choices_actions}
            for name, sub in action.choices.items():
                out.append((name, summaries.get(name, ""), sub))
    return out


def arguments(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The arguments a user can give (positionals and flags), without the subcommand list and hidden ones."""
    return [
        a for a in parser._actions if not isinstance(a, argparse._SubParsersAction) and a.help is not argparse.SUPPRESS
    ]


def _escape(text: str) -> str:
    """Plain text as reStructuredText: flags and environment variables as literals, markup characters escaped."""
    parts = []
    last = 0
    for match in _FLAG.finditer(text):
        parts.append(_SPECIAL.sub(r"\\\1", text[last : match.start()]))
        parts.append(f"``{match.group(1)}``")
        last = match.end()
    parts.append(_SPECIAL.sub(r"\\\1", text[last:]))
    out = "".join(parts)
    if re.match(r"[-+#]|\d+[.)]\s", out):  # not a list item
        out = "\\" + out
    return out


def _paragraph(text: str | None) -> str:
    """A description written for ``RawDescriptionHelpFormatter`` (lines broken by hand) as one paragraph."""
    return _escape(" ".join((text or "").split()))


def _signature(action: argparse.Action) -> str:
    """``-j N, --workers N``, ``--json``, ``config``: the argument as a user types it."""
    if not action.option_strings:
        return action.metavar if isinstance(action.metavar, str) else action.dest
    if action.nargs == 0:
        return ", ".join(action.option_strings)
    if isinstance(action.metavar, str):
        metavar = action.metavar
    elif action.choices is not None:
        metavar = "{" + ",".join(map(str, action.choices)) + "}"
    else:
        metavar = action.dest.upper()
    return ", ".join(f"{o} {metavar}" for o in action.option_strings)


def _default(action: argparse.Action) -> str | None:
    """What the argument is when not given, as the parser has it (None: nothing to say)."""
    if action.nargs == 0:
        return None  # a switch: off unless given
    default = action.default
    if default is None or default is argparse.SUPPRESS:
        return None
    return repr(default) if isinstance(default, str) and not default else str(default)


def _usage(parser: argparse.ArgumentParser) -> str:
    formatter = parser.formatter_class(prog=parser.prog, width=_WIDTH)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
    return formatter.format_help().strip()


def _literal_block(text: str) -> list[str]:
    return [".. code-block:: text", "", *(f"   {line}" if line.strip() else "" for line in text.splitlines()), ""]


def _argument_rst(action: argparse.Action) -> list[str]:
    lines = [f".. option:: {_signature(action)}", ""]
    help_text = action.help or ""
    if "%(" in help_text:
        help_text = help_text % {**vars(action), "prog": "eulerpoisson"}
    body = [_paragraph(help_text)] if help_text.strip() else []
    facts = []
    if action.nargs == 0:
        facts.append("a switch (takes no value)")
    if action.choices is not None and action.option_strings:
        facts.append("one of " + ", ".join(f"``{c}``" for c in action.choices))
    default = _default(action)
    if default is not None:
        facts.append(f"default ``{default}``")
    unit = UNITS.get(action.dest)
    if unit is not None:
        facts.append("unit: " + _escape(unit))
    if not action.option_strings:
        facts.append("positional" + ("" if action.nargs not in ("?", "*") else ", optional"))
    if facts:
        text = "; ".join(facts)
        body.append(text[0].upper() + text[1:] + ".")
    for paragraph in body:
        lines += [f"   {paragraph}", ""]
    return lines


def _command_rst(title: str, program: str, summary: str, parser: argparse.ArgumentParser) -> list[str]:
    heading = f"``{title}``"
    lines = [f".. _cli-{program.replace(' ', '-')}:", "", heading, "-" * len(heading), ""]
    if summary:
        lines += [f"*{_paragraph(summary)}*", ""]
    if parser.description:
        lines += [_paragraph(parser.description), ""]
    lines += _literal_block(_usage(parser))
    lines += [f".. program:: {program}", ""]
    for action in arguments(parser):
        lines += _argument_rst(action)
    if parser.epilog:
        lines += [f"From ``{program} --help``:", ""]
        lines += _literal_block(parser.epilog.replace("%(prog)s", parser.prog))
    return lines


def cli_reference_rst(parser: argparse.ArgumentParser | None = None) -> str:
    """The reference of every command of ``parser`` (default: the ``eulerpoisson`` command) as reStructuredText.

    One section per command: the program itself, then each subcommand in the order of ``--help``.
    """
    parser = build_parser() if parser is None else parser
    lines = [_escape(UNITS_NOTE), ""]
    commands = subcommands(parser)
    if commands:
        lines += ["Commands: " + ", ".join(f":ref:`{name} <cli-{parser.prog}-{name}>`" for name, _, _ in commands), ""]
    lines += _command_rst(parser.prog, parser.prog, "", parser)
    for name, summary, sub in commands:
        lines += _command_rst(f"{parser.prog} {name}", f"{parser.prog} {name}", summary, sub)
    return "\n".join(lines) + "\n"


def setup(app):
    """Register ``.. eulerpoisson-cli::``."""
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective
    from sphinx.util.nodes import nested_parse_with_titles

    class CommandLineReference(SphinxDirective):
        """``.. eulerpoisson-cli::``: the reference of every command, from the parser."""

        has_content = False

        def run(self):
            from docutils import nodes

            # the page depends on the command line's modules: rebuilt when one of them changes
            cli = Path(importlib.import_module("eulerpoisson.cli.common").__file__).parent
            for path in sorted(cli.glob("*.py")):
                self.env.note_dependency(str(path))
            text = cli_reference_rst()
            container = nodes.container()
            source = self.get_source_info()[0] or "<eulerpoisson-cli>"
            nested_parse_with_titles(self.state, StringList(text.splitlines(), source=source), container)
            return list(container.children)

    app.add_directive("eulerpoisson-cli", CommandLineReference)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
