"""Errors hystkit raises for problems the user can fix (bad files, bad options, divergence)."""

from __future__ import annotations


class HystkitError(Exception):
    """Base class: the CLI prints the message on one line and exits non-zero."""


class InputError(HystkitError, ValueError):
    """A data or model file cannot be used; the message names file, column and row."""


class FitDivergedError(HystkitError, RuntimeError):
    """An identification or a compensator run left the finite range."""


class OutputExistsError(HystkitError, FileExistsError):
    """An output file exists and overwriting it was not asked for (``--force``)."""


class OutputError(HystkitError, OSError):
    """An output path cannot be written (its folder is a file, no permission, disk full)."""


class NonFiniteError(HystkitError, ValueError):
    """A result holds NaN or infinity; it is refused rather than written (names column/key, row)."""


class Terminated(BaseException):
    """Raised in the main thread on SIGTERM by the CLI's handler, so cleanup runs as for Ctrl-C.

    A BaseException, like KeyboardInterrupt, so that no ``except Exception`` swallows it.
    """
