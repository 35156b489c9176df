"""The ``eulerpoisson`` command line (compatibility module).

The command line lives in one module per command (:mod:`.simulate`,
:mod:`.audit`, :mod:`.plot`, :mod:`.info`, :mod:`.sweep`, :mod:`.oracle`,
:mod:`.fit`, :mod:`.warmup`), what they share in :mod:`.common`, the
configuration of ``simulate`` in :mod:`.config` and the parser and the
entry point in :mod:`.main`. This module re-exports the names that were
importable from it; new code imports them from where they are defined.
"""

from __future__ import annotations

import sys

# the names importable from here before the split into modules (re-exported, not redefined)
from .audit import cmd_audit  # noqa: F401
from .common import EXIT_USAGE, UsageError, check_file_name, inertia_from  # noqa: F401
from .config import METHOD_OPTIONS  # noqa: F401
from .info import cmd_info  # noqa: F401
from .main import build_parser, cmd_demo, main  # noqa: F401
from .main import prepare_argv as _prepare_argv  # noqa: F401 - the tests import it under its old name
from .plot import FPS_RANGE, MAX_FRAMES, cmd_animate, cmd_plot  # noqa: F401
from .simulate import CHUNKED_SAMPLES, MAX_SAMPLES, cmd_simulate  # noqa: F401
from .sweep import cmd_sweep  # noqa: F401

__all__ = ["main"]

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
