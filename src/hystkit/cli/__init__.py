"""Command-line interface (``hystkit``)."""

from ._main import main, program

__all__ = ["main", "program"]
