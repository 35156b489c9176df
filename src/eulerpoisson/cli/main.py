"""The ``eulerpoisson`` command line.

Commands: ``simulate``, ``audit``, ``plot``, ``animate``, ``info``, ``sweep``, ``demo``, ``validate``,
``cases``, ``fit``, ``warmup``.
Bad input prints one line that says what is wrong and exits with status 2
(``--debug``, anywhere on the command line, shows the traceback instead).
Python warnings (overflow, ill-conditioning, ...) are silenced unless
``--debug`` is given, so that an error is a single line.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import warnings
from collections.abc import Sequence

from ..errors import EulerPoissonError
from . import audit, info, plot, simulate, sweep
from .common import EXIT_USAGE, Parser, UsageError, check_file_name, error_message

__all__ = ["main", "build_parser", "prepare_argv", "cmd_demo"]


def cmd_demo(args) -> int:
    from .demo import run_demo

    check_file_name(args.out, "--out")
    return run_demo(args.out, quiet=args.quiet)


def build_parser() -> argparse.ArgumentParser:
    from ..version import package_version

    __version__ = package_version()

    p = Parser(
        prog="eulerpoisson",
        description="Rigid-body rotation, free (exact, in the Gibbs rotation vector n = k tan(alpha/2)) and "
        "under torque: solvers, the paper's audit, files and pictures.",
        epilog="Run 'eulerpoisson COMMAND --help' for a command's options and examples.",
    )
    p.add_argument("--version", action="version", version=f"eulerpoisson {__version__}")
    p.add_argument(
        "--debug",
        action="store_true",
        help="show tracebacks and warnings instead of one-line errors (accepted anywhere on the line)",
    )
    sub = p.add_subparsers(dest="command", parser_class=Parser, metavar="COMMAND")

    simulate.add_commands(sub)  # simulate
    audit.add_commands(sub)  # audit
    plot.add_commands(sub)  # plot, animate
    sweep.add_commands(sub)  # sweep
    info.add_commands(sub)  # info

    ex = argparse.RawDescriptionHelpFormatter
    d = sub.add_parser(
        "demo",
        help="the showcase: the tennis-racket effect, a heavy top, figures, animation and audit",
        epilog="example:\n  eulerpoisson demo --out out",
        formatter_class=ex,
    )
    d.add_argument("--out", default="out", help="output folder (default out/)")
    d.add_argument("--quiet", action="store_true")
    d.set_defaults(func=cmd_demo)

    from .oracle import add_commands  # validate, cases (issue 14)

    add_commands(sub)
    from .fit import add_commands as add_fit_command  # fit (issue 13)

    add_fit_command(sub)
    from .warmup import add_commands as add_warmup_command  # warmup (issue 15, cold start)

    add_warmup_command(sub)
    return p


# ---------------------------------------------------------------------------
# argv pre-processing
# ---------------------------------------------------------------------------
def _value_options(parser: argparse.ArgumentParser) -> tuple[set[str], set[str]]:
    """Long options that take a value, and all option strings, of ``parser`` and its subcommands."""
    takes: set[str] = set()
    every: set[str] = set()
    stack = [parser]
    while stack:
        p = stack.pop()
        for action in p._actions:
            every.update(action.option_strings)
            if action.option_strings and action.nargs != 0:
                takes.update(o for o in action.option_strings if o.startswith("--"))
            if isinstance(action, argparse._SubParsersAction):
                stack.extend(action.choices.values())
    return takes, every


def prepare_argv(argv: list[str], parser: argparse.ArgumentParser) -> list[str]:
    """Drop ``--debug`` (accepted anywhere) and glue values that begin with '-' to their option.

    argparse reads ``--omega -1,0.1,0.5`` as two options; ``--omega=-1,0.1,0.5``
    is what the user meant. A value is glued to a value-taking long option (or
    an abbreviation of one) when it begins with a single '-' and is not itself
    a known option.
    """
    takes, every = _value_options(parser)
    out: list[str] = []
    i = 0
    while i < len(argv):
        tok = argv[i]
        if tok == "--":
            out.extend(argv[i:])
            break
        if tok == "--debug":
            i += 1
            continue
        if (
            tok.startswith("--")
            and "=" not in tok
            and len(tok) > 2
            and i + 1 < len(argv)
            and any(o.startswith(tok) for o in takes)
        ):
            nxt = argv[i + 1]
            if nxt.startswith("-") and not nxt.startswith("--") and nxt not in every and len(nxt) > 1:
                out.append(f"{tok}={nxt}")
                i += 2
                continue
        out.append(tok)
        i += 1
    return out


def _error_line(exc: BaseException) -> str:
    msg = error_message(exc)
    if isinstance(exc, UsageError):
        return f"eulerpoisson: error: {msg}"  # every error line starts the same way
    if isinstance(exc, MemoryError):
        msg = f"out of memory: {msg}" if msg != type(exc).__name__ else "out of memory"
    elif isinstance(exc, OverflowError) and "overflow" not in msg.lower():
        msg = f"numerical overflow: {msg}"
    elif not isinstance(
        exc, (EulerPoissonError, ValueError, TypeError, OSError, ArithmeticError, LookupError, ImportError)
    ):
        msg = f"{type(exc).__name__}: {msg}"  # unexpected: say what kind of failure it was
    return f"eulerpoisson: error: {msg}"


@contextlib.contextmanager
def _quiet_warnings(enabled: bool):
    """Silence Python warnings here and in worker processes started meanwhile (when ``enabled``)."""
    if not enabled:
        yield
        return
    old = os.environ.get("PYTHONWARNINGS")
    os.environ["PYTHONWARNINGS"] = "ignore"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        if old is None:
            os.environ.pop("PYTHONWARNINGS", None)
        else:
            os.environ["PYTHONWARNINGS"] = old


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``eulerpoisson`` command; returns the exit status.

    Bad input, and any failure of a command, prints one line
    ``eulerpoisson: error: ...`` (or the usage message) to stderr and returns
    2; ``--debug`` anywhere on the command line shows the traceback (and
    Python warnings) instead.

    Examples
    --------
    >>> from eulerpoisson.cli import main
    >>> main(["simulate", "--inertia", "1,2,2.5", "--omega", "1,0.1,0.5", "--t-end", "1", "--json"])
    {"t": 1.0, "quaternion": [0.849693475..., 0.454793915..., 0.133837061..., 0.230805400...],
     ..., "method": "exact", ...}
    0
    """
    argv = [str(a) for a in (sys.argv[1:] if argv is None else argv)]
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    try:
        with _quiet_warnings(not debug):
            parser = build_parser()
            args = parser.parse_args(prepare_argv(argv, parser))
            if not getattr(args, "command", None):
                parser.print_help()
                return EXIT_USAGE
            return int(args.func(args) or 0)
    except SystemExit as exc:  # --help / --version
        return int(exc.code or 0) if isinstance(exc.code, int) else 0
    except KeyboardInterrupt:
        print("eulerpoisson: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader closed the pipe (``eulerpoisson info run.nc | head``): not an error
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):  # pragma: no cover - stdout without a file descriptor
            pass
        return 0
    except Exception as exc:  # noqa: BLE001 - the command line never shows a traceback without --debug
        if debug:
            raise
        print(_error_line(exc), file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
