"""Writing recordings and JSON result files, each published atomically (`hystkit.io._atomic`)."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from hystkit.errors import NonFiniteError

from .._docfill import fill_output_doc
from .._read_options import TIME_UNITS
from ._atomic import atomic_output, atomic_outputs
from ._mat_writer import recording_variables, write_mat
from ._output_checks import check_output_format, check_output_path
from ._recording import _COLUMNS, Recording

if TYPE_CHECKING:  # pandas loads when a recording is written, not for a model file
    import pandas as pd



RECORDING_SUFFIXES = (".csv", ".parquet", ".mat")


def write_recording(
    recording: Recording,
    path: str | os.PathLike[str],
    *,
    extra: dict[str, np.ndarray] | None = None,
    force: bool = False,
    kept: dict[str, np.ndarray] | None = None,
    units: dict[str, str] | None = None,
    units_sidecar: bool = False,
    names: Mapping[str, str] | None = None,
    time_unit: str = "s",
) -> Path:
    """Write a recording as CSV, Parquet or MATLAB (chosen by the suffix of `path`), atomically.

    Parameters
    ----------
    recording : Recording
        Written as columns ``time``, ``position`` (if present), ``sensor`` (or as `names`
        says).
    path : str or path-like
        ``.csv``, ``.parquet`` or ``.mat``; parent directories are created.
    extra : dict of str to ndarray, shape (n,), optional
        Further columns appended in the given order (e.g. a compensated position [mm]);
        boolean ones (flags) are written as 0/1 (logical in ``.mat``).
    force : bool
        Overwrite an existing file.
    kept : dict of str to ndarray, shape (n,), optional
        Columns of the input copied as they were (numbers, or text), written between the
        recording's columns and `extra`; empty input cells (NaN, "") stay empty.
    units : dict of str to str, optional
        Units of columns beyond ``recording.units`` (e.g. ``position_estimate``). Written to
        Parquet's schema metadata (``hystkit.units``) and as the ``units`` struct of a
        ``.mat`` file; CSV keeps its header plain (a units line would need ``--units-row`` to
        read back).
    units_sidecar : bool
        CSV with units, or with `names` or a `time_unit` of its own: also write the settings
        file beside it (``out.toml``, `sidecar_path`: the units in a ``[units]`` table, the
        names in ``[columns]``, the ``time_unit``), which reading ``out.csv`` picks up; both
        files appear together or not at all.
    names : mapping of str to str, optional
        The names to write the recording's ``time``, ``position``, ``sensor`` under (those of
        the file it was read from, e.g. ``{"time": "t_ms"}``); `units` and `kept` use the
        written names.
    time_unit : {"s", "ms", "us", "ns", "min"}
        Unit of the written time column (the input's, `hystkit.io.ReadOptions.time_unit`);
        written in it and labelled so in the units (``ms``). A value is written in its
        shortest form when that reads back (times the unit's seconds) to the same time.

    Returns
    -------
    Path
        The written file. Floats are written in shortest round-trip form, so reading it
        back gives bit-identical values. In a ``.mat`` file every column is a variable
        (column vector; flags as logical, text as a cell array), names made MATLAB
        identifiers (`matlab_name`), with ``column_names`` (the written names in order) and
        ``units`` (a struct).

    Raises
    ------
    OutputExistsError
        `path` exists and `force` is False (message says to pass ``--force``), also when
        another process created it while this one was writing.
    NonFiniteError
        A column holds NaN or infinity (the message names column and row); nothing is written.
    ValueError
        An extra column has the wrong length or clashes with a recording column.
    OutputError
        A suffix other than ``.csv``/``.parquet``/``.mat`` (`check_output_format`).

    Notes
    -----
    The file appears complete or not at all (:func:`atomic_output`).
    """
    path = Path(path)
    suffix = check_output_format(path, RECORDING_SUFFIXES, "a recording")
    written = {name: (names or {}).get(name, name) for name in _COLUMNS}
    columns = {written[name]: getattr(recording, name) for name in _COLUMNS
               if getattr(recording, name) is not None}
    columns[written["time"]] = time_in_unit(recording.time, time_unit)
    for group in (kept or {}), (extra or {}):
        for name, values in group.items():
            values = np.asarray(values)
            if name in columns:
                raise ValueError(f"extra column {name!r} clashes with a recording column")
            if values.shape != (recording.n_samples,):
                raise ValueError(f"extra column {name!r} has shape {values.shape}; the "
                                 f"recording has {recording.n_samples} samples")
            columns[name] = values
    for name, values in columns.items():
        if name not in (kept or {}):
            _refuse_non_finite(path, name, np.asarray(values))
    all_units = {**{written.get(name, name): unit for name, unit in recording.units},
                 **(units or {})}
    all_units = {name: unit for name, unit in all_units.items() if name in columns}
    # the time's unit labels it in .mat and Parquet; a settings file says time_unit instead
    labels = {written["time"]: time_unit, **all_units} if time_unit != "s" else all_units
    if suffix == ".mat":
        return write_mat(path, {}, force=force,
                         verbatim=recording_variables(columns, labels))
    import pandas as pd  # here: see TYPE_CHECKING above

    # flags (bool) as 0/1 in text and Parquet files, as the files hystkit always wrote
    frame = pd.DataFrame({name: values.astype(int) if np.asarray(values).dtype.kind == "b"
                          else values for name, values in columns.items()})
    renamed = {name: other for name, other in written.items() if other != name}
    if suffix == ".csv" and units_sidecar and (all_units or renamed or time_unit != "s"):
        ours = {other: name for name, other in renamed.items()}  # [units] keys its three so
        text = units_settings_text({ours.get(name, name): unit for name, unit in
                                    all_units.items()}, path.name, columns=renamed,
                                   time_unit=time_unit)
        with atomic_outputs([path, sidecar_path(path)], force) as (tmp, toml_tmp):
            frame.to_csv(tmp, index=False)
            toml_tmp.write_text(text, encoding="utf-8")
        return path
    with atomic_output(path, force) as tmp:
        if suffix == ".csv":  # pandas writes floats as repr(): the shortest exact round trip
            frame.to_csv(tmp, index=False)
        else:
            _write_parquet(frame, tmp, labels)
    return path


def sidecar_path(path: str | os.PathLike[str]) -> Path:
    """The settings file beside a recording (``out.csv`` -> ``out.toml``).

    Parameters
    ----------
    path : str or os.PathLike
        The recording.

    Returns
    -------
    pathlib.Path
        The same path with the suffix ``.toml``.
    """
    return Path(path).with_suffix(".toml")


def units_settings_text(units: dict[str, str], file: str | None = None, *,
                        columns: Mapping[str, str] | None = None, time_unit: str = "s") -> str:
    """A recording's settings file (``out.toml``) that holds the units of its columns (and
    how to read a file written in its input's names and time unit).

    Parameters
    ----------
    units : dict of str to str
        Unit of each column, by column name (hystkit's ``time``, ``position``, ``sensor``
        for the columns `columns` renames).
    file : str, optional
        The name of the recording it is for (``out.csv``): then it applies to that file
        only, even when an ``out.mat`` appears beside it.
    columns : mapping of str to str, optional
        hystkit name -> the file's column name, written as a ``[columns]`` table.
    time_unit : str
        Unit of the time column; written when not ``s``.

    Returns
    -------
    str
        The TOML text: ``file``, ``time_unit``, a ``[columns]`` and a ``[units]`` table.
    """
    lines = ["# written by hystkit: how to read the file beside this one", ""]
    lines += [] if file is None else [f"file = {json.dumps(file)}"]
    lines += [] if time_unit == "s" else [f"time_unit = {json.dumps(time_unit)}"]
    lines += [""] if len(lines) > 2 else []
    for table, values in (("columns", columns or {}), ("units", units)):
        if values:
            lines += [f"[{table}]"]
            lines += [f"{json.dumps(name)} = {json.dumps(text)}" for name, text in values.items()]
            lines += [""]
    return "\n".join(lines).rstrip("\n") + "\n"


def time_in_unit(seconds: np.ndarray, unit: str) -> np.ndarray:
    """Times [s] in `unit` (``ms``, ...), each in its shortest form (15 significant digits)
    where that gives back exactly `seconds` when read in `unit`: 20 ms read as 0.02 s is
    written 20, not 20.000000000000004.

    Parameters
    ----------
    seconds : numpy.ndarray
        Times [s].
    unit : str
        A key of `hystkit.io.ReadOptions`' time units.

    Returns
    -------
    numpy.ndarray
        The times in `unit` (`seconds` itself for ``s``).
    """
    scale = TIME_UNITS[unit]
    if scale == 1.0:
        return seconds
    values = np.asarray(seconds, dtype=np.float64) / scale
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):  # checked below
        digits = 14 - np.floor(np.log10(np.abs(values)))
        factor = 10.0 ** np.where(np.isfinite(digits), digits, 0.0)
        short = np.round(values * factor) / factor
        return np.where(short * scale == seconds, short, values)


def _write_parquet(frame: pd.DataFrame, path: Path, units: dict[str, str]) -> None:
    import pyarrow as pa  # here: pyarrow loads only for Parquet files
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(frame, preserve_index=False)
    if units:
        metadata = {**(table.schema.metadata or {}),
                    b"hystkit.units": json.dumps(units).encode()}
        table = table.replace_schema_metadata(metadata)
    pq.write_table(table, path)


def _refuse_non_finite(path: Path, name: str, values: np.ndarray) -> None:
    if values.dtype.kind not in "fc":
        return
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise NonFiniteError(f"{path}: column {name!r} row {bad[0] + 1} is {values[bad[0]]} "
                             f"({bad.size} non-finite value(s)); refusing to write it")


@fill_output_doc
def write_json(obj: Any, path: str | os.PathLike[str], *, force: bool = False) -> Path:
    """Write `obj` as indented JSON (metrics, model parameters), atomically.

    NumPy scalars and arrays are converted to plain numbers and lists. NaN and infinity are
    refused because standard JSON cannot represent them.

    Parameters
    ----------
    obj : object
        JSON-serialisable data; numpy scalars and arrays allowed.
    path : str or os.PathLike
        Output ``.json`` file.
    %(force)s

    %(written_path)s
    OutputError
        `path` does not end in ``.json`` (`check_output_format`).
    NonFiniteError
        `obj` holds NaN or infinity (the message names the key path, e.g.
        ``metrics.sine.r2`` or ``params.a[3]``); nothing is written.
    """
    path = Path(path)
    check_output_path(path, force, formats=(".json",), what="a JSON file")
    # Serialise before touching the disk so a bad object leaves no file at all.
    try:
        text = json.dumps(obj, indent=2, allow_nan=False, default=_json_default) + "\n"
    except ValueError:
        where = _first_non_finite(json.loads(json.dumps(obj, default=_json_default)))
        raise NonFiniteError(f"{path}: {where}; refusing to write NaN or infinity to "
                             f"JSON") from None
    with atomic_output(path, force) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def _first_non_finite(obj: Any, where: str = "") -> str:
    """Key path and value of the first NaN/inf in a plain JSON object."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return f"value {where or '(top level)'} is {obj}"
    items = (obj.items() if isinstance(obj, dict) else enumerate(obj)
             if isinstance(obj, list) else ())
    for key, value in items:
        sub = f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}" if where else key
        found = _first_non_finite(value, sub)
        if found:
            return found
    return ""


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"cannot write {type(value).__name__} as JSON")
