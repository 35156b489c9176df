"""The ``eulerpoisson`` command line (:mod:`.commands`) and the showcase of ``make demo`` (:mod:`.demo`)."""

from .commands import main

__all__ = ["main"]
