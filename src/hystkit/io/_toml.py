"""Reading TOML settings files, as Windows editors save them too."""

from __future__ import annotations

import codecs
import tomllib
from pathlib import Path
from typing import Any

__all__ = ["load_toml"]


def load_toml(path: Path) -> dict[str, Any]:
    """The TOML file `path` parsed, a leading UTF-8 byte-order mark skipped.

    Windows Notepad saves one; TOML has none, and ``tomllib`` calls it an invalid character
    at line 1, column 1, which does not say what is wrong.

    Parameters
    ----------
    path : pathlib.Path
        The settings file.

    Returns
    -------
    dict
        Its tables and values.

    Raises
    ------
    OSError, UnicodeDecodeError, tomllib.TOMLDecodeError
        As ``tomllib.load``.
    """
    data = path.read_bytes()
    return tomllib.loads(data.removeprefix(codecs.BOM_UTF8).decode("utf-8"))
