"""Reading TOML settings files (as Windows editors save them too), found beside their data."""

from __future__ import annotations

import codecs
import os
import tomllib
from pathlib import Path
from typing import Any

from hystkit.errors import InputError

__all__ = ["check_type", "load_settings", "load_toml", "settings_beside"]


def settings_beside(data_path: str | os.PathLike[str]) -> Path | None:
    """The settings file stored next to a recording, raw or not: same folder, same stem,
    ``.toml`` (``run1.parquet`` -> ``run1.toml``).

    ``hystkit.io`` exports it as ``find_raw_config`` and ``find_recording_config``: the rule is
    the same for both kinds of file, which settings apply is decided when they are read.

    Parameters
    ----------
    data_path : str or os.PathLike
        The recording.

    Returns
    -------
    pathlib.Path or None
        ``<stem>.toml`` beside it, None if there is none.
    """
    candidate = Path(data_path).with_suffix(".toml")
    return candidate if candidate.is_file() else None


def check_type(path: Path, key: str, value: Any, types: tuple[type, ...]) -> None:
    """Refuse a setting of the wrong type (a TOML ``true`` is no number), naming file and key."""
    if not isinstance(value, types) or (isinstance(value, bool) and bool not in types):
        raise InputError(f"{path}: key {key!r} must be "
                         f"{' or '.join(t.__name__ for t in types)}, got {value!r}")


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


def load_settings(path: Path, what: str) -> dict[str, Any]:
    """`load_toml`, each failure one InputError line naming `path` (`what`: the kind of file)."""
    try:
        if path.is_dir():
            raise InputError(f"{path}: is a folder, not a TOML settings file")
        return load_toml(path)
    except FileNotFoundError as exc:
        raise InputError(f"{path}: {what} not found") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read {what} ({exc})") from exc
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        raise InputError(f"{path}: invalid TOML ({exc})") from exc
