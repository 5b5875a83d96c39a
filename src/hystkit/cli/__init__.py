"""Command-line interface (``hystkit``)."""

from ._main import main

__all__ = ["main"]
