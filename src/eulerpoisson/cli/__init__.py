"""The ``eulerpoisson`` command line (:mod:`.main`, one module per command) and the showcase of ``make demo`` (:mod:`.demo`)."""

from .main import main

__all__ = ["main"]
