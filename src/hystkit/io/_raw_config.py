"""Settings of a raw recording in a small TOML file stored next to the data.

The file has the data file's stem (``run1.parquet`` -> ``run1.toml``), flat keys
(:data:`CONFIG_KEYS`) and optional tables ``columns`` (file column names) and ``simulation``
(free-form notes). ``hystkit preprocess`` reads it; command-line options override it.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from hystkit.errors import InputError

from .._docfill import fill_output_doc
from ._atomic import atomic_output
from ._raw_format import MAX_SKIP_ROWS
from ._toml import check_type, load_settings, settings_beside

__all__ = ["CONFIG_KEYS", "find_raw_config", "read_raw_config", "write_raw_config"]

# key: (type(s), meaning). Read by read_raw_config; used by hystkit.preprocess and the CLI.
CONFIG_KEYS: dict[str, tuple[tuple[type, ...], str]] = {
    "r_bridge": ((int, float), "bridge resistor R_br [Ohm] (eq. 4.2)"),
    "v_supply": ((int, float), "bridge supply V0 [V] (eq. 4.2)"),
    "supply_channel": ((bool,), "use the measured supply column v0 in eq. 4.3 (sec. 4.2.1)"),
    "um_per_count": ((int, float), "encoder resolution [um per count] (5 in the document)"),
    "position_offset_mm": ((int, float), "added to the position [mm] (eq. 9.16: -0.0656)"),
    "fs_out": ((int, float), "output sample rate [Hz]"),
    "cutoff": ((int, float), "zero-phase Butterworth cut-off [Hz] (eq. 4.1)"),
    "order": ((int,), "Butterworth order (one way)"),
    "fs": ((int, float), "scope sample rate [Hz]; checked against the time column"),
    "n_samples": ((int,), "samples per channel; a shorter file is reported as truncated"),
    "encoder_states": ((str, list), "A/B states of the merged levels, ascending: 00,01,10,11"),
    "encoder_levels": ((list,), "the four merged encoder levels [V], ascending"),
    "encoder_dwell_us": ((int, float), "a new encoder level must last this long [us]"),
    "illegal": ((str,), "double transitions add 2 counts ('continue') or none ('hold')"),
    "remove_mean": ((bool,), "subtract the mean of position and sensor"),
    "normalise": ((bool,), "divide position and sensor by their max |.| (eq. 5.10)"),
    "chunk_size": ((int,), "rows per chunk"),
    "time_unit": ((str,), "unit of the time column: s, ms, us or ns"),
    "skip_rows": ((int,), "CSV: lines to skip after the header (e.g. a units line)"),
    "columns": ((dict,), "file column names, e.g. {v1 = 'Channel A', time = 'Time'}"),
    "simulation": ((dict,), "free-form notes written by simulate-sensor (ignored)"),
}


# Ranges of the numeric keys, checked on reading (before anything is allocated or looped over):
# key: (low, high, low included). Wide enough for every real setup, narrow enough that a typo
# (skip_rows = 1000000000, fs = 1e300, chunk_size = 0) is named instead of hanging or crashing.
CONFIG_RANGES: dict[str, tuple[float, float, bool]] = {
    "r_bridge": (0.0, 1e9, False),
    "v_supply": (0.0, 1e3, False),
    "um_per_count": (0.0, 1e6, False),
    "position_offset_mm": (-1e6, 1e6, True),
    "fs_out": (0.0, 1e9, False),
    "cutoff": (0.0, 1e9, False),
    "order": (1, 20, True),
    "fs": (0.0, 1e11, False),
    "n_samples": (1, 1e13, True),
    "encoder_dwell_us": (0.0, 1e6, False),
    "chunk_size": (1, 1 << 27, True),
    "skip_rows": (0, MAX_SKIP_ROWS, True),
}
# Encoder levels are voltages a scope can show.
_MAX_LEVEL_V = 1e3
_CHOICES = {"illegal": ("continue", "hold"), "time_unit": ("s", "ms", "us", "ns")}
_COLUMN_NAMES = ("time", "v1", "v2", "encoder", "enc_a", "enc_b", "v0")


find_raw_config = settings_beside  # the same rule as a recording's settings


def read_raw_config(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a raw recording's TOML settings; keys and types as in :data:`CONFIG_KEYS`.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML settings file.

    Returns
    -------
    dict
        The checked settings, by key.

    Raises
    ------
    InputError
        Unreadable or invalid TOML, an unknown key (a typo would otherwise be ignored), a value
        of the wrong type, a number outside :data:`CONFIG_RANGES` (or not finite), an unknown
        choice or column name; one line naming the file and the key.
    """
    path = Path(path)
    values = load_settings(path, "config file")
    for key, value in values.items():
        if key not in CONFIG_KEYS:
            raise InputError(f"{path}: unknown key {key!r}; known keys: "
                             f"{', '.join(CONFIG_KEYS)}")
        check_type(path, key, value, CONFIG_KEYS[key][0])
        _check_value(path, key, value)
    return values


def _check_value(path: Path, key: str, value: Any) -> None:
    """Range, finiteness and choices of one key whose type is already right."""
    def fail(message: str) -> None:
        raise InputError(f"{path}: key {key!r}: {message}")

    if key in CONFIG_RANGES:
        low, high, closed = CONFIG_RANGES[key]
        if not math.isfinite(value):
            fail(f"must be a finite number, got {value}")
        if not ((value >= low if closed else value > low) and value <= high):
            fail(f"{value!r} is outside {'[' if closed else '('}{low:g}, {high:g}]")
    elif key in _CHOICES and value not in _CHOICES[key]:
        fail(f"must be one of {', '.join(_CHOICES[key])}, got {value!r}")
    elif key == "encoder_levels":
        ok = len(value) == 4 and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            and abs(v) <= _MAX_LEVEL_V for v in value)
        if not ok:
            fail(f"must be four finite voltages within +-{_MAX_LEVEL_V:g} V, got {value!r}")
    elif key == "encoder_states" and isinstance(value, list):
        if len(value) != 4 or not all(isinstance(v, str) for v in value):
            fail(f"must be four A/B states such as \"00\", got {value!r}")
    elif key == "columns":
        for name, column in value.items():
            if name not in _COLUMN_NAMES or not isinstance(column, str):
                fail(f"entry {name!r} = {column!r}: names must be among "
                     f"{', '.join(_COLUMN_NAMES)} and map to column names (strings)")


@fill_output_doc
def write_raw_config(path: str | os.PathLike[str], values: dict[str, Any], *,
                     comment: str = "", force: bool = False) -> Path:
    """Write flat settings (numbers, strings, booleans, lists, one level of tables) as TOML,
    atomically (a temporary renamed into place); refuses to overwrite unless `force`.

    Parameters
    ----------
    path : str or os.PathLike
        Output ``.toml`` file.
    values : dict
        Settings; a dict value becomes a table.
    comment : str, optional
        Text written first, each line as a ``#`` comment.
    %(force)s

    %(written_path)s
    """
    path = Path(path)
    lines = [f"# {line}" for line in comment.splitlines()]
    tables = {k: v for k, v in values.items() if isinstance(v, dict)}
    lines += [f"{k} = {_toml_value(v)}" for k, v in values.items() if k not in tables]
    for name, table in tables.items():
        lines += ["", f"[{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    text = "\n".join(lines) + "\n"
    with atomic_output(path, force) as tmp:  # the whole file or nothing
        tmp.write_text(text, encoding="utf-8")
    return path


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        if not math.isfinite(value):
            raise ValueError(f"cannot write {value} to TOML settings")
        return repr(float(value))
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML settings")


