"""How long the tests wait: guards against a hang, never timings (issue 22).

A test that runs a subprocess or waits for an event gives it
:data:`HANG_GUARD_S`: far above (10x and more) the quiet time of the slowest
such wait (a cold numba compile on a loaded two-core machine), so that a busy
machine never fails a test; only a hang does.
"""

from __future__ import annotations

#: seconds a test waits for a subprocess, a lock, a file or a thread before it calls it a hang
HANG_GUARD_S = 1800
