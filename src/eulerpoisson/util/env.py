"""Environment variables read on every call of a small solve (private helpers).

``os.environ.get(name)`` of an unset variable costs about 2 microseconds
(``os.environ`` raises and catches a ``KeyError`` inside), as much as
the rest of a tiny ``solve`` does in ten steps; the settings that
``solve`` reads on every call (``EULERPOISSON_WORKERS``,
``EULERPOISSON_NUMPY_BELOW``) are read here instead: the same value, from
the same mapping, without the exception.
"""

from __future__ import annotations

import os

__all__ = ["env_value"]

#: names as ``os.environ`` keys them (bytes on POSIX, upper-case text on Windows)
_KEYS: dict[str, object] = {}


def env_value(name: str) -> str | None:
    """``os.environ.get(name)``: the variable's value, or None where it is unset.

    Reads the mapping behind ``os.environ`` directly (CPython's
    ``os.environ._data``, which every change through ``os.environ`` updates),
    and falls back on ``os.environ.get`` where that mapping is not there.

    Examples
    --------
    >>> import os
    >>> os.environ["EULERPOISSON_EXAMPLE"] = "3"
    >>> env_value("EULERPOISSON_EXAMPLE"), env_value("EULERPOISSON_UNSET_EXAMPLE")
    ('3', None)
    >>> del os.environ["EULERPOISSON_EXAMPLE"]
    >>> env_value("EULERPOISSON_EXAMPLE") is None
    True
    """
    environ = os.environ
    data = getattr(environ, "_data", None)
    if type(data) is not dict:  # pragma: no cover - another Python implementation
        return environ.get(name)
    key = _KEYS.get(name)
    if key is None:
        key = _KEYS[name] = environ.encodekey(name)
    value = data.get(key)
    return None if value is None else environ.decodevalue(value)
