"""A user's file layout, kept: the model file remembers how its training recordings were
read, later commands use it, and ``compensate`` writes in the input's names and time unit.

``fit --columns time=t_ms,position=x_mm,sensor=r_ohm --time-unit ms`` stores those settings in
the model file (its ``reading``: the columns, the time unit, a units line, the units), and
``evaluate``, ``compensate``, ``report`` and ``stream --in`` read a file with them by default
when it has the training file's time and sensor column names (variables or struct fields in a
``.mat`` file) and no settings file of its own, saying so in one line::

    reading val.csv as the model's training data were read: columns t_ms,x_mm,r_ohm, time in ms

A units line is read only where the file has one (a line of text below the header). A
settings file, or ``--columns``, describes the file instead; any other option given on the
command line wins over the remembered value (``--time-unit s`` over ``ms``).

``compensate`` writes the input's columns under the names they were read from, time in the
unit it was read in, and the estimate and its band named after the position column
(`output_names`, `estimate_names`).
"""

from __future__ import annotations

import argparse
import csv
from dataclasses import replace
from pathlib import Path

from .._read_options import FIELDS, ReadOptions
from ..errors import InputError

__all__ = ["TRAINED_NOTE", "add_trained_note", "estimate_names", "output_names",
           "remembered_options"]

_HEAD_BYTES = 1 << 16  # as io._csv_layout: the header must end within it


def remembered_options(given: dict, path: Path, reading: ReadOptions | None,
                       ) -> tuple[ReadOptions, str] | None:
    """The options to read `path` with as the model's training data were read, and the line
    that says so; None when they do not apply (see the module: nothing remembered, a settings
    file of its own, ``--columns`` in the reading options `given` on the command line, or
    not the training files' column names).

    Raises
    ------
    InputError
        A settings file beside `path` that `hystkit.io.settings_for` refuses (the reader
        would refuse it too).
    """
    from ..io import settings_for

    if reading is None or not (reading.columns or reading.time_unit != "s"
                               or reading.units_row):
        return None
    if "columns" in given or settings_for(path)[0] is not None:
        return None
    try:
        base = ReadOptions(**given)
    except ValueError:  # the command's own reading names the problem
        return None
    found = _file_names(Path(path), base)
    if found is None:
        return None
    names, units_line = found
    if not {reading.name("time"), reading.name("sensor")} <= names:
        return None
    remembered = {"columns": reading.columns, "time_unit": reading.time_unit,
                  "units": reading.units, "units_row": reading.units_row and units_line}
    options = replace(ReadOptions(**remembered), **given)
    shown = ",".join(reading.name(field) for field in FIELDS)
    parts = [f"columns {shown}"] if reading.columns else []
    parts.append(f"time in {options.time_unit}")
    if options.units_row:
        parts.append("a units line")
    return options, f"reading {path} as the model's training data were read: {', '.join(parts)}"


TRAINED_NOTE = ("a file with the training files' column names and no settings file of its own "
                "is read as the model's training data were read, said in one line (an option "
                "given here wins; --columns replaces it)")


def add_trained_note(p: argparse.ArgumentParser, replace_note: str | None = None) -> None:
    """Add `TRAINED_NOTE` to the description of `p`'s reading options (`add_read_options`),
    or put `replace_note` and it there (compensate: its output keeps the input's names)."""
    for group in p._action_groups:
        if (group.title or "").startswith("reading your own files"):
            first = replace_note if replace_note is not None else group.description
            group.description = f"{first}; {TRAINED_NOTE}" if first else TRAINED_NOTE


def _file_names(path: Path, options: ReadOptions) -> tuple[set[str], bool] | None:
    """The column names `path` offers (CSV header, Parquet columns, ``.mat`` variables and
    fields of its structs) and whether a CSV has a units line below its header; None when
    the file cannot be looked at (its reader names the problem)."""
    if not path.is_file():
        return None
    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            return _csv_names(path, options)
        if suffix == ".parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            try:
                return {str(name) for name in pq.read_schema(path).names}, False
            except (pa.ArrowException, ValueError):
                return None
        if suffix == ".mat":
            from ..io import load_mat

            contents = load_mat(path, [], str(path))
            names = set(contents.variables)
            for fields in contents.fields.values():
                names.update(fields)
            return names, False
    except (InputError, OSError, UnicodeDecodeError):
        return None
    return None


def _csv_names(path: Path, options: ReadOptions) -> tuple[set[str], bool]:
    """The header's names and whether the line below it holds text (a units line)."""
    from ..io import csv_layout

    layout = csv_layout(path, options)
    with path.open("rb") as file:
        lines = file.read(_HEAD_BYTES).decode("utf-8-sig", errors="replace").splitlines()
    if len(lines) <= layout.preamble:
        return set(), False
    header = lines[layout.preamble]
    if layout.comment_header:
        header = header.lstrip().lstrip("#")
    names = set(layout.names(_split(header, layout.sep)))
    below = lines[layout.preamble + 1] if len(lines) > layout.preamble + 1 else ""
    cells = [cell.strip() for cell in _split(below, layout.sep) if cell.strip()]
    return names, bool(cells) and not all(_number(c, layout.decimal) for c in cells)


def _split(line: str, sep: str) -> list[str]:
    return next(csv.reader([line], delimiter=sep), [])


def _number(cell: str, decimal: str) -> bool:
    try:
        float(cell.replace(decimal, ".") if decimal != "." else cell)
    except ValueError:
        return False
    return True


def output_names(options: ReadOptions) -> dict[str, str]:
    """hystkit name -> the input's column name, for the columns compensate writes (the
    input's own names); none for a ``.mat`` matrix's column numbers."""
    columns = dict(options.columns)
    if any(name.strip().isdigit() for name in columns.values()):
        return {}
    return columns


def estimate_names(names: dict[str, str]) -> dict[str, str]:
    """compensate's estimate and band columns, named after the input's position column
    (``x_mm_estimate``, ``x_mm_lower``, ``x_mm_upper``; hystkit's ``position_estimate``, ...
    for a file using hystkit's names)."""
    position = names.get("position", "position")
    return {f"position_{kind}": f"{position}_{kind}" for kind in ("estimate", "lower", "upper")}
