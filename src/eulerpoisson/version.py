"""The package's version, read from its installed metadata (``eulerpoisson.__version__``)."""

from __future__ import annotations

__all__ = ["package_version"]


def package_version() -> str:
    """The installed version of eulerpoisson (``"0+unknown"`` when run from a source tree not installed).

    Examples
    --------
    >>> from eulerpoisson.version import package_version
    >>> isinstance(package_version(), str)
    True
    """
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("eulerpoisson")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0+unknown"
