"""Refuse input files that are not there before a command loads its heavy libraries.

A subcommand's run function imports numpy, pandas, numba kernels and the rest only when it
runs (``tests/cli/test_startup_imports.py``). A misspelt file name should not wait for all
of that: calling :func:`check_inputs_exist` first makes the error as instant as ``--help``.
The readers keep their own checks (empty, unreadable, damaged files); this one only looks
whether each path exists, with the readers' wording, so the message is the same either way.
Pure Python on purpose: nothing heavy may load here.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from ..errors import InputError

__all__ = ["check_inputs_exist"]


def check_inputs_exist(paths: Iterable[str | os.PathLike[str] | None]) -> None:
    """Raise for the first of `paths` that does not exist (None entries are skipped).

    Parameters
    ----------
    paths : iterable of str, path-like or None
        Input files or folders of a command, in the order the user gave them.

    Raises
    ------
    InputError
        ``"<path>: file not found"``, as `hystkit.io.read_recording` and
        `hystkit.compensation.load_compensator` say it.

    Examples
    --------
    >>> check_inputs_exist([None, "."])
    >>> check_inputs_exist(["no-such-recording.csv"])
    Traceback (most recent call last):
    ...
    hystkit.errors.InputError: no-such-recording.csv: file not found
    """
    for path in paths:
        if path is not None and not os.path.exists(path):
            raise InputError(f"{Path(path)}: file not found")
