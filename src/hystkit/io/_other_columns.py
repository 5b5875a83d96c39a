"""The columns of a user's file that are not the recording (a temperature, a trigger, notes),
so that outputs such as ``compensate``'s can keep them beside the results.

In a ``.mat`` file they are the other vectors beside the recording's: the other fields of its
struct, the other top-level vectors, or the other columns of its matrix (``column_K``). When
the recording is resampled (``--resample``), numeric columns go through the same resampling
as position and sensor (`hystkit.io._resample`); columns with text or empty cells cannot be
interpolated and are left out, and `dropped_by_resampling` names them.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hystkit.errors import InputError

from .._read_options import DEFAULT_OPTIONS, FIELDS, ReadOptions
from ._cells import COLUMNS, Where
from ._csv_layout import csv_layout
from ._mat_reader import load_mat
from ._recording import _validate, read_unvalidated
from ._resample import resample_arrays

__all__ = ["dropped_by_resampling", "read_other_columns"]

_MAT_LABELS = ("units", "column_names")  # what hystkit writes beside a recording's columns


def read_other_columns(path: str | os.PathLike[str], n_samples: int,
                       options: ReadOptions = DEFAULT_OPTIONS) -> dict[str, np.ndarray]:
    """Columns of a CSV or Parquet file other than time, position and sensor, as read.

    Parameters
    ----------
    path : str or path-like
        The file `read_recording` read with the same `options`.
    n_samples : int
        Rows of the recording read from it; the columns must have as many.
    options : ReadOptions
        Column names, separator, skipped lines as for the recording.

    Returns
    -------
    dict of str to ndarray, shape (n_samples,)
        In the file's order: numbers as float64 (an empty cell is NaN), anything else as
        text (an empty cell is ""). With ``options.resample_hz`` only the numeric columns
        without empty cells, resampled like the recording (see `dropped_by_resampling`).
        With ``options.missing`` ``drop`` or ``interpolate``, the rows the recording kept
        (other columns are not interpolated: an empty cell stays empty).

    Raises
    ------
    InputError
        The columns have a different number of rows than the recording.
    """
    path = Path(path)
    if options.missing != "error":
        as_read = _kept_rows(path, options)
        if options.resample_hz is None:
            _check_rows(path, as_read, n_samples)
            return as_read
    elif options.resample_hz is None:
        return _as_read(path, n_samples, options)
    else:
        as_read = _as_read(path, None, options)
    numeric = {name: values for name, values in as_read.items() if name not in
               dropped_by_resampling(as_read)}
    if not numeric:
        return {}
    arrays, where, _ = read_unvalidated(path, False, options, notices=False)
    _validate(arrays, where, uniform=False)  # as read_recording does before resampling
    out = resample_arrays({"time": arrays["time"], **numeric}, options.resample_hz, where)
    out.pop("time")
    if any(values.size != n_samples for values in out.values()):
        raise InputError(f"{path}: the resampled other columns have "
                         f"{next(iter(out.values())).size} rows, the recording {n_samples}")
    return out


def _kept_rows(path: Path, options: ReadOptions) -> dict[str, np.ndarray]:
    """The other columns at the rows `read_recording` keeps under ``options.missing``."""
    _, where, _ = read_unvalidated(path, False, options, notices=False)
    as_read = _as_read(path, None, options)
    rows = where.rows
    if rows is None or not rows.size or not as_read:
        return as_read
    short = [name for name, values in as_read.items() if values.size <= rows[-1]]
    if short:
        raise InputError(f"{path}: the other columns ({', '.join(short)}) end before the "
                         f"recording's row {rows[-1] + 1}")
    return {name: values[rows] for name, values in as_read.items()}


def _check_rows(path: Path, columns: dict[str, np.ndarray], n_samples: int) -> None:
    if any(values.size != n_samples for values in columns.values()):
        raise InputError(f"{path}: the other columns ({', '.join(columns)}) have "
                         f"{next(iter(columns.values())).size} rows, the recording {n_samples}")


def dropped_by_resampling(columns: dict[str, np.ndarray]) -> list[str]:
    """Names of the `columns` that resampling cannot carry: text, or numbers with empty cells."""
    return [name for name, values in columns.items()
            if values.dtype.kind != "f" or not np.isfinite(values).all()]


def _as_read(path: Path, n_samples: int | None, options: ReadOptions) -> dict[str, np.ndarray]:
    """The other columns as in the file; `n_samples` None: any length (checked by the caller)."""
    suffix = path.suffix.lower()
    if suffix == ".mat":
        return _mat_others(path, n_samples, options)
    if suffix not in (".csv", ".parquet"):
        return {}
    import pandas as pd  # here: only outputs that keep other columns need pandas

    ours = {options.name(field) for field in FIELDS}
    clean: dict[object, str] = {}  # the file's name -> the column's name (a comment header's
    # first without its '#')
    if suffix == ".parquet":
        import pyarrow.parquet as pq  # here: pyarrow loads only for Parquet files

        names = [n for n in pq.ParquetFile(path).schema_arrow.names if n not in ours]
        frame = pd.read_parquet(path, columns=names) if names else pd.DataFrame()
    else:
        layout = csv_layout(path, options, Where(str(path), names=options.columns))
        header = pd.read_csv(path, nrows=0, sep=layout.sep, skiprows=layout.preamble,
                             encoding="utf-8-sig").columns
        clean = dict(zip(header, layout.names(list(header))))
        names = [n for n in header if clean[n] not in ours]
        if not names:
            return {}
        skip = options.skip_rows + options.units_row
        skipped = [*range(layout.preamble), *range(layout.preamble + 1,
                                                   layout.preamble + 1 + skip)]
        # missing cells read past: a blank line is a row, as the recording's reader counts
        frame = pd.read_csv(path, sep=layout.sep, decimal=layout.decimal, usecols=names,
                            encoding="utf-8-sig", skiprows=skipped or None,
                            skip_blank_lines=options.missing == "error")
    if not names:
        return {}
    if n_samples is not None and len(frame) != n_samples:
        raise InputError(f"{path}: the other columns ({', '.join(map(str, names))}) have "
                         f"{len(frame)} rows, the recording {n_samples}")
    out = {}
    for name in names:
        column = frame[name]
        if pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column):
            out[clean.get(name, str(name).strip())] = column.to_numpy(dtype=np.float64)
        else:
            out[clean.get(name, str(name).strip())] = column.fillna("").astype(
                str).to_numpy(dtype=object)
    return out


def _mat_others(path: Path, n_samples: int | None, options: ReadOptions) -> dict[str, np.ndarray]:
    """The real vectors beside the recording in a ``.mat`` file (see the module notes);
    only those as long as the recording (`n_samples`; None: as long as its time)."""
    source = str(path)
    where = Where(source, names=options.columns)
    ours = {where.name(name) for name in COLUMNS}
    contents = load_mat(path, [], source)
    var = options.mat_var
    if var is None and not ours & set(contents.variables):  # the file's only struct/matrix
        candidates = [name for name, (kind, shape) in contents.variables.items()
                      if name not in _MAT_LABELS and (name in contents.fields or (
                          kind not in ("struct", "char", "cell", "object", "sparse")
                          and len(shape) == 2 and 2 <= shape[1] < shape[0]))]
        var = candidates[0] if len(candidates) == 1 else None
    if var is not None and var in contents.fields:  # a struct: its other vector fields
        kinds = contents.fields[var]
        keys = {f"{var}.{f}": f for f in kinds if f not in ours}
    elif var is not None:  # a matrix: its columns not named by --columns (or the defaults)
        return _matrix_others(path, var, contents.variables[var][1], options, n_samples)
    else:
        kinds = contents.variables
        keys = {f: f for f in kinds if f not in ours and f not in _MAT_LABELS}
    length = _mat_length(kinds, where.name("time"), n_samples)
    wanted = [key for key, name in keys.items() if _is_vector(kinds[name], length)]
    if not wanted:
        return {}
    arrays = load_mat(path, wanted, source).arrays
    return {keys[key]: np.asarray(arrays[key], dtype=np.float64).reshape(-1)
            for key in wanted if key in arrays and arrays[key].dtype.kind in "iuf"}


def _matrix_others(path: Path, var: str, shape: tuple[int, ...], options: ReadOptions,
                   n_samples: int | None) -> dict[str, np.ndarray]:
    n_rows, n_cols = shape
    used = {int(v) for v in dict(options.columns).values() if v.isdigit()} or \
        set(range(1, min(n_cols, 3) + 1))
    if n_samples is not None and n_rows != n_samples:
        return {}
    matrix = load_mat(path, [var], str(path)).arrays.get(var)
    if matrix is None or matrix.dtype.kind not in "iuf":
        return {}
    return {f"column_{k}": np.asarray(matrix[:, k - 1], dtype=np.float64).copy()
            for k in range(1, n_cols + 1) if k not in used}


def _mat_length(kinds: dict, time_name: str, n_samples: int | None) -> int | None:
    if n_samples is not None:
        return n_samples
    shape = kinds.get(time_name, ("", ()))[1]
    return max(shape) if len(shape) == 2 and min(shape) == 1 else None


def _is_vector(kind_shape: tuple[str, tuple[int, ...]], length: int | None) -> bool:
    kind, shape = kind_shape
    return (length is not None and kind not in ("struct", "char", "cell", "object", "sparse")
            and len(shape) == 2 and min(shape) == 1 and max(shape) == length)
