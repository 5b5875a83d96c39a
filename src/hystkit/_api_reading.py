"""What the notebook functions (:mod:`hystkit._api`) accept as a recording, and how they read
it: a `Recording` as it is, a DataFrame converted, a file path read with its settings file.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Union

from .io import ReadOptions, Recording, options_for, read_pieces, read_recording, settings_for

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Data", "as_recording", "as_recordings", "read", "reading_options"]

Data = Union[Recording, "pd.DataFrame", str, os.PathLike]
"""What every function here accepts as a recording: a `Recording`, a DataFrame with columns
``time`` [s], ``position`` [mm] (needed to fit and to score) and ``sensor``, or a file path
(CSV, Parquet, MATLAB) with those columns."""


def read(path: str | os.PathLike, *, columns: Mapping[str, str] | None = None,
         time_unit: str | None = None, **options: Any) -> Recording:
    """Read a recording from a CSV, Parquet or MATLAB file, with its own column names.

    A settings file beside it (``my.toml`` for ``my.csv``: columns, time unit, ..., see
    ``docs/own_data.md``) is read first, as the command line does, and one line on stderr
    says so (``hystkit: reading my.csv with the settings in my.toml``; or that one beside it
    is for another file and was not applied); what is given here overrides it (``columns``
    name by name). So do the other functions here given a file path.

    Parameters
    ----------
    path : str or path-like
        The file.
    columns : mapping, optional
        hystkit name (``time``, ``position``, ``sensor``) -> the file's column (or MATLAB
        variable) name; names not given are read as hystkit's.
    time_unit : {"s", "ms", "us", "ns", "min"}, optional
        Unit of the time column, converted to seconds; default: the settings file's, else
        seconds.
    **options
        The other fields of `hystkit.io.ReadOptions` (``skip_rows``, ``sep``, ``units_row``,
        ...).

    Returns
    -------
    Recording
        ``time`` [s], ``sensor``, ``position`` [mm] when the file has one; ``to_frame()`` gives
        a DataFrame.

    Raises
    ------
    InputError
        A missing file or column, or bad data; the message names file, column and row.

    Examples
    --------
    >>> import hystkit as hk
    >>> path = "own.csv"
    >>> with open(path, "w") as f:
    ...     _ = f.write("t_ms,x_mm,r_ohm\\n0,0.0,100.0\\n25,0.5,100.2\\n50,1.0,100.5\\n")
    >>> rec = hk.read(path, columns={"time": "t_ms", "position": "x_mm", "sensor": "r_ohm"},
    ...               time_unit="ms")
    >>> rec.fs
    40.0
    >>> rec.to_frame().columns.tolist()
    ['time', 'position', 'sensor']
    """
    given = dict(options)
    if columns is not None:
        given["columns"] = tuple(columns.items())
    if time_unit is not None:
        given["time_unit"] = time_unit
    return read_recording(path, need_position=False, options=reading_options(path, given))


def reading_options(path: str | os.PathLike, given: dict | None = None) -> ReadOptions:
    """The options to read `path` with (its settings file, then `given`); says on stderr
    which settings file was applied, or that one beside it is for another file."""
    reading, settings = options_for(path, given)  # an unknown option is a TypeError there
    note = settings_for(path)[1] if settings is None else ""
    if settings is not None:
        print(f"hystkit: reading {path} with the settings in {settings}", file=sys.stderr)
    elif note:
        print(f"hystkit: reading {path} without its settings: {note}", file=sys.stderr)
    return reading


def as_recordings(data: Data, options: ReadOptions | None = None) -> list[Recording]:
    """`data` as recordings to fit jointly: a file whose settings say ``gaps = "split"`` as
    its pieces between time gaps (`hystkit.io.read_pieces`), anything else as one. A file is
    read with `options` (default: `reading_options`')."""
    if isinstance(data, str | os.PathLike):
        options = reading_options(data) if options is None else options
        if options.gaps == "split":
            return read_pieces(data, need_position=False, options=options)
        return [read_recording(data, need_position=False, options=options)]
    return [as_recording(data)]


def as_recording(data: Data) -> Recording:
    """`data` as a `Recording`: kept, converted from a DataFrame, or read from a file path.

    Raises
    ------
    TypeError
        `data` is none of those.
    """
    if isinstance(data, Recording):
        return data
    if isinstance(data, str | os.PathLike):
        return read_recording(data, need_position=False, options=reading_options(data))
    if hasattr(data, "columns") and hasattr(data, "to_numpy"):  # a DataFrame, without pandas
        return Recording.from_frame(data)
    raise TypeError(f"expected a Recording, a DataFrame or a file path, got "
                    f"{type(data).__name__}")
