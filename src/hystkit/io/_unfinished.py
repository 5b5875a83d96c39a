"""Temporaries a signal may leave behind, removed when the interpreter exits.

Ctrl-C and SIGTERM become exceptions (``hystkit.cli._signals``) raised between any two
bytecodes, so one can land after a temporary file is created and before the ``try`` that
discards it. A temporary's name is therefore registered here *before* it is created and
dropped once it is published or discarded; whatever is still registered at exit is removed.
Only the process that registered a name removes it: a forked worker that exits normally
leaves its parent's temporaries alone.
"""

from __future__ import annotations

import atexit
import os
import shutil
from pathlib import Path

__all__ = ["forget", "register", "remove_unfinished"]

_unfinished: dict[Path, int] = {}  # temporary -> the process that registered it


def register(path: Path) -> Path:
    """Mark `path`, about to be created, as unfinished; returns it."""
    _unfinished[path] = os.getpid()
    return path


def forget(path: Path) -> None:
    """`path` is published, discarded, or was never ours (it existed already)."""
    _unfinished.pop(path, None)


@atexit.register
def remove_unfinished() -> None:
    """Remove the temporaries this process registered and did not finish (at exit)."""
    pid = os.getpid()
    for path, owner in list(_unfinished.items()):
        if owner != pid:
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
        forget(path)
