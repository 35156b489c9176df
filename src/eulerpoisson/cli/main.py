"""The ``eulerpoisson`` command line.

Commands: ``simulate``, ``audit``, ``plot``, ``animate``, ``info``, ``sweep``, ``demo``, ``validate``,
``cases``, ``fit``, ``warmup``.
Bad input prints one line that says what is wrong and exits with status 2
(``--debug``, anywhere on the command line, shows the traceback instead).
An unexpected exception is a bug of eulerpoisson, not a mistake of the user:
it prints one line ``eulerpoisson: internal error: ...`` that says where its
traceback was saved and exits with status 3.
Python warnings (overflow, ill-conditioning, ...) are silenced unless
``--debug`` is given, so that an error is a single line.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import tempfile
import time
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path

from ..errors import AuditError, EulerPoissonError
from . import audit, info, plot, simulate, sweep
from .common import EXIT_USAGE, Parser, UsageError, check_file_name, error_message

__all__ = ["main", "build_parser", "prepare_argv", "cmd_demo", "EXIT_INTERNAL", "is_bad_input", "crash_folder"]

#: exit status of an unexpected exception (a bug of eulerpoisson); bad input exits with 2
EXIT_INTERNAL = 3


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
    from .conformance import add_commands as add_conformance_command  # conformance (issue 23)

    add_conformance_command(sub)
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


def is_bad_input(exc: BaseException) -> bool:
    """Whether ``exc`` reports bad input or a limit of the machine (exit 2) rather than a bug (exit 3).

    Bad input: the package's own errors (:class:`~eulerpoisson.EulerPoissonError`
    and its subclasses, the usage errors of the command line), which every
    check of the input raises; ``OSError`` (files, folders, disks); a
    numerical overflow; a missing dependency; a feature not available for
    the input (``NotImplementedError``); running out of memory. Anything else
    (a bare ``ValueError`` or ``TypeError`` from deep inside, ``RuntimeError``,
    ``AssertionError``, ``IndexError``, ``KeyError``, ``ZeroDivisionError``,
    ``AttributeError``, a compiler's error, ...) escaped every check: a bug.

    Examples
    --------
    >>> from eulerpoisson.cli.main import is_bad_input
    >>> from eulerpoisson.errors import InvalidInputError
    >>> is_bad_input(InvalidInputError("omega0 must be finite")), is_bad_input(FileNotFoundError("run.nc"))
    (True, True)
    >>> is_bad_input(IndexError("index 3 is out of bounds")), is_bad_input(ValueError("too many values to unpack"))
    (False, False)
    """
    if isinstance(exc, EulerPoissonError):
        return not isinstance(exc, AuditError)  # the audit disagreeing with itself is a bug
    return isinstance(exc, (OSError, OverflowError, ImportError, NotImplementedError, MemoryError))


def crash_folder() -> Path:
    """Where the traceback of an internal error is saved: ``$XDG_CACHE_HOME/eulerpoisson/crashes``.

    ``$XDG_CACHE_HOME`` defaults to ``~/.cache``; where no home folder can
    be found, the folder is ``eulerpoisson-crashes`` in the temporary folder
    (:func:`tempfile.gettempdir`).
    """
    cache = os.environ.get("XDG_CACHE_HOME", "").strip()
    if cache and os.path.isabs(cache):
        return Path(cache) / "eulerpoisson" / "crashes"
    try:
        return Path.home() / ".cache" / "eulerpoisson" / "crashes"
    except (RuntimeError, KeyError, OSError):  # no home folder
        return Path(tempfile.gettempdir()) / "eulerpoisson-crashes"


def _save_traceback(exc: BaseException, argv: Sequence[str]) -> str:
    """Write the traceback of ``exc`` (with the command line and versions) to a new file; its path, or a reason."""
    import platform

    from ..version import package_version

    try:
        version = package_version()
    except Exception:  # noqa: BLE001 - the report must not fail on its own
        version = "unknown"
    text = (
        f"eulerpoisson {version}, Python {platform.python_version()} on {platform.platform()}\n"
        f"command: eulerpoisson {' '.join(argv)}\n"
        f"time: {time.strftime('%Y-%m-%d %H:%M:%S %z')}\n\n"
        + "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    )
    stamp = time.strftime("%Y%m%d-%H%M%S")
    last: OSError | None = None
    for folder in (crash_folder(), Path(tempfile.gettempdir()) / "eulerpoisson-crashes"):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, name = tempfile.mkstemp(prefix=f"crash-{stamp}-", suffix=".txt", dir=folder)
            with os.fdopen(fd, "w", encoding="utf-8", errors="backslashreplace") as fh:
                fh.write(text)
            return f"the traceback was saved to {name}"
        except OSError as err:
            last = err
    return f"the traceback could not be saved ({error_message(last) if last else 'no folder'}; run again with --debug)"


def _internal_error_line(exc: BaseException, argv: Sequence[str]) -> str:
    """``eulerpoisson: internal error: TYPE: MESSAGE (a bug; the traceback was saved to PATH; please report it)``."""
    where = _save_traceback(exc, argv)
    return (
        f"eulerpoisson: internal error: {type(exc).__name__}: {error_message(exc)} (a bug; {where}; please report it)"
    )


def _cli_words(msg: str) -> str:
    """A library message in the words of the command line (``allow_unphysical=True`` is ``--allow-unphysical``)."""
    return msg.replace("pass allow_unphysical=True", "run with --allow-unphysical").replace(
        "allow_unphysical=True", "--allow-unphysical"
    )


def _error_line(exc: BaseException) -> str:
    msg = _cli_words(error_message(exc))
    if isinstance(exc, UsageError):
        return f"eulerpoisson: error: {msg}"  # every error line starts the same way
    if isinstance(exc, MemoryError):
        msg = f"out of memory: {msg}" if msg != type(exc).__name__ else "out of memory"
        msg += (
            " (the machine has not enough memory for this run: ask for fewer samples or bodies, or write a long "
            "run to a .zarr store with --out, which keeps only one chunk in memory)"
        )
    elif isinstance(exc, OverflowError) and "overflow" not in msg.lower():
        msg = f"numerical overflow: {msg}"
    return f"eulerpoisson: error: {msg}"


def _command_prog(parser: argparse.ArgumentParser, args: argparse.Namespace) -> str:
    """``eulerpoisson COMMAND`` of the command ``args`` ran (``eulerpoisson`` when none)."""
    command = getattr(args, "command", None)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            return action.choices[command].prog
    return parser.prog


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

    Bad input prints one line ``eulerpoisson: error: ...`` to stderr and
    returns 2 (:func:`is_bad_input`); an unexpected exception (a bug) prints
    one line ``eulerpoisson: internal error: ...`` naming the file its
    traceback was saved to (in :func:`crash_folder`) and returns 3;
    ``--debug`` anywhere on the command line shows the traceback (and Python
    warnings) instead.

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
            args, extra = parser.parse_known_args(prepare_argv(argv, parser))
            if extra:  # name the command whose options were meant
                raise UsageError(
                    f"unrecognized arguments: {' '.join(extra)} (see '{_command_prog(parser, args)} --help')"
                )
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
        if not is_bad_input(exc):  # a bug of ours, not the user's mistake
            print(_internal_error_line(exc, argv), file=sys.stderr)
            return EXIT_INTERNAL
        print(_error_line(exc), file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
