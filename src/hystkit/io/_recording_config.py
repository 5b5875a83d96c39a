"""How to read a recording, from a TOML settings file stored next to it.

The rule (as for raw files, `hystkit.io.find_raw_config`): the settings of ``my.csv`` are in
``my.toml`` in the same folder (same stem). They apply to that one file: when ``my.mat`` or
``my.parquet`` sits beside ``my.csv``, the file must say which it is for (``file``), and a
recording it is not for is read without it (`settings_for` says so), never with settings
written for another format (a ``.mat`` in s beside a CSV in ms). The file holds the
`ReadOptions` settings as flat keys and two tables::

    file = "my.csv"           # the recording these are for, or one extension ("*.csv")
    time_unit = "ms"          # s, ms, us, ns, min
    skip_rows = 0             # CSV lines skipped after the header (after the units line)
    sep = ";"                 # ",", ";", "tab", "auto" (the default: detected)
    decimal = ","             # ".", ",", "auto" (the default: detected)
    units_row = true          # CSV: the line after the header holds units
    resample_hz = 100.0       # bring jittered time onto a uniform grid
    mat_var = "run1"          # .mat: the struct or matrix holding the recording
    missing = "interpolate"   # a row missing a value: error (the default), drop, interpolate
    gaps = "split"            # time gaps: error (the default), split into pieces

    [columns]                 # hystkit name = the file's column (or .mat field/number)
    time = "t_ms"
    position = "displacement_mm"
    sensor = "resistance_ohm"

    [units]                   # units when the file has no units line (other columns
    position = "mm"           # by their own names)
    sensor = "Ohm"

Options given on the command line override the file's. The format is the one ``preprocess``
reads for raw files (flat keys, a ``[columns]`` table). A raw recording's own settings file
(``run.toml`` of ``run.parquet``, which ``preprocess`` turns into ``run.csv`` beside it) is
recognised by its raw-only keys or raw column names and left alone (`is_raw_settings`).
"""

from __future__ import annotations

import os
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from hystkit.errors import InputError

from .._read_options import FIELDS, ReadOptions
from ._raw_config import _COLUMN_NAMES as RAW_COLUMNS
from ._raw_config import CONFIG_KEYS as RAW_KEYS
from ._toml import check_type, load_settings, settings_beside

__all__ = ["RECORDING_KEYS", "find_recording_config", "is_raw_settings", "options_for",
           "read_recording_config", "settings_for"]

RECORDING_SUFFIXES = (".csv", ".parquet", ".mat")  # as _recording._READERS

RECORDING_KEYS: dict[str, tuple[tuple[type, ...], str]] = {
    "file": ((str,), "the recording these settings are for (my.csv), or one extension (*.csv)"),
    "time_unit": ((str,), "unit of the time column: s, ms, us, ns or min"),
    "skip_rows": ((int,), "CSV: lines to skip after the header (and its units line)"),
    "sep": ((str,), "CSV field separator: ',', ';', 'tab' or 'auto'"),
    "decimal": ((str,), "CSV decimal mark: '.', ',' or 'auto'"),
    "units_row": ((bool,), "CSV: the line after the header holds units"),
    "resample_hz": ((int, float), "resample to a uniform grid at this rate [Hz]"),
    "mat_var": ((str,), ".mat: the variable holding the recording"),
    "missing": ((str,), "a row missing a value: 'error', 'drop' or 'interpolate'"),
    "gaps": ((str,), "time gaps: 'error' or 'split' (into pieces fitted jointly)"),
    "columns": ((dict,), "hystkit name = the file's column, e.g. {time = 't_ms'}"),
    "units": ((dict,), "units of the columns, e.g. {position = 'mm', sensor = 'Ohm'}"),
}


find_recording_config = settings_beside  # the same rule as a raw recording's


def read_recording_config(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a recording's TOML settings as `ReadOptions` keyword arguments.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML settings file.

    Returns
    -------
    dict
        Keyword arguments for `ReadOptions`; ``columns`` and ``units`` as tuples of pairs.

    Raises
    ------
    InputError
        Unreadable or invalid TOML, an unknown key (or one of raw files only), a value of the
        wrong type or one `ReadOptions` refuses; one line naming the file and the key.
    """
    path = Path(path)
    values = load_settings(path, "settings file")
    for key, value in values.items():
        if key not in RECORDING_KEYS:
            raw = " (a setting of raw scope files, for 'hystkit preprocess')" \
                if key in RAW_KEYS else ""
            raise InputError(f"{path}: unknown key {key!r}{raw}; a recording's settings file "
                             f"knows {', '.join(RECORDING_KEYS)}")
        check_type(path, key, value, RECORDING_KEYS[key][0])
    for name, item in values.get("columns", {}).items():
        if name not in FIELDS or not isinstance(item, str):
            raise InputError(f"{path}: key 'columns.{name}' = {item!r}: names must be among "
                             f"{', '.join(FIELDS)} and map to column names (text)")
    for name, item in values.get("units", {}).items():
        if not isinstance(item, str):
            raise InputError(f"{path}: key 'units.{name}' = {item!r}: units are text")
    if "file" in values:
        _check_file(path, values.pop("file"))
    if "columns" in values:
        values["columns"] = tuple(values["columns"].items())
    if "units" in values:
        values["units"] = tuple(values["units"].items())
    try:
        ReadOptions(**values)
    except ValueError as exc:
        raise InputError(f"{path}: {exc}") from None
    return values


def _check_file(path: Path, target: str) -> None:
    """``file`` names a recording of this settings file's stem, or one recording extension:
    found by its name, ``my.toml`` can be for nothing else."""
    stem = Path(path).stem
    names = [stem + suffix for suffix in RECORDING_SUFFIXES]
    if target not in names and _extension(target) not in RECORDING_SUFFIXES:
        raise InputError(f"{path}: key 'file' = {target!r}: settings found by their name are "
                         f"for {', '.join(names)} (or one extension: \"*.csv\", ...)")


def _extension(target: str) -> str | None:
    """``.csv`` of ``*.csv`` or ``.csv``; None for a file name."""
    if target.startswith("*."):
        return target[1:].lower()
    return target.lower() if target.startswith(".") else None


def settings_for(data_path: str | os.PathLike[str]) -> tuple[Path | None, str]:
    """The settings file that applies to a recording, and why one beside it does not.

    ``my.toml`` applies to ``my.csv`` when it names it (``file = "my.csv"`` or ``"*.csv"``),
    or names nothing and ``my.csv`` is the only recording of that stem there. A raw scope
    recording's settings (`is_raw_settings`) are not a recording's.

    Parameters
    ----------
    data_path : str or path-like
        The recording.

    Returns
    -------
    settings : Path or None
        The settings file to read `data_path` with.
    note : str
        When a settings file beside it is for another file: ``"my.toml is for my.csv"``, to
        say that it was not applied; else "".

    Raises
    ------
    InputError
        A settings file that names no file, beside two recordings of its stem (``my.csv``
        and ``my.mat``): one line asking for ``file``. Unreadable or invalid TOML.
    """
    data = Path(data_path)
    settings = find_recording_config(data)
    if settings is None:
        return None, ""
    values = load_settings(settings, "settings file")
    if is_raw_settings(values):
        return None, ""  # the raw recording's settings (for preprocess), not this file's
    target = values.get("file")
    if isinstance(target, str):
        _check_file(settings, target)
        if target == data.name or _extension(target) == data.suffix.lower():
            return settings, ""
        return None, f"{settings} is for {target}"
    others = [data.with_suffix(s).name for s in RECORDING_SUFFIXES
              if s != data.suffix.lower() and data.with_suffix(s).is_file()]
    if others:
        raise InputError(f"{settings}: settings beside {data.name} and {', '.join(others)}, "
                         f"which may differ (a time unit, a separator): say which file they "
                         f"are for with file = \"{data.name}\" in it (the other is then read "
                         "with options given on the command line)")
    return settings, ""


def is_raw_settings(values: dict[str, Any]) -> bool:
    """Whether TOML `values` are a raw scope recording's settings (`read_raw_config`): a key
    only raw files have (``r_bridge``, ``fs_out``, ...) or a raw column name (``v1``,
    ``encoder``, ...) in ``[columns]``. ``run.parquet`` (raw) and ``preprocess``'s ``run.csv``
    share the stem, so ``run.toml`` beside ``run.csv`` may be the raw file's."""
    raw_only = set(RAW_KEYS) - set(RECORDING_KEYS)
    columns = values.get("columns")
    return bool(raw_only & set(values)) or (
        isinstance(columns, dict) and bool(set(columns) & (set(RAW_COLUMNS) - set(FIELDS))))


_FIELD_NAMES = {f.name for f in fields(ReadOptions)}


def options_for(data_path: str | os.PathLike[str], given: dict[str, Any] | None = None,
                ) -> tuple[ReadOptions, Path | None]:
    """The settings to read `data_path` with: its settings file, then `given` on top.

    Parameters
    ----------
    data_path : str or path-like
        The recording.
    given : dict, optional
        `ReadOptions` keyword arguments set explicitly (on the command line); they override
        the file's. ``columns`` overrides name by name (``--columns sensor=R`` keeps the
        file's time and position names).

    Returns
    -------
    options : ReadOptions
    settings : Path or None
        The settings file used, if any (`settings_for`: not one written for another file of
        the same stem, nor a raw recording's).

    Raises
    ------
    TypeError
        A key of `given` that is not a `ReadOptions` field.
    InputError
        A settings file that cannot be read or that `settings_for` refuses (one beside two
        recordings of its stem that does not say which it is for).
    """
    given = dict(given or {})
    unknown = sorted(set(given) - _FIELD_NAMES)
    if unknown:
        raise TypeError(f"unexpected reading option(s): {', '.join(unknown)} (ReadOptions "
                        f"has {', '.join(sorted(_FIELD_NAMES))})")
    settings, _ = settings_for(data_path)
    values = read_recording_config(settings) if settings is not None else {}
    if "columns" in given and "columns" in values:
        given["columns"] = tuple({**dict(values["columns"]), **dict(given["columns"])}.items())
    try:
        return replace(ReadOptions(**values), **given), settings
    except ValueError as exc:
        raise InputError(f"{data_path}: {exc}") from None
