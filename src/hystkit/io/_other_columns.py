"""The columns of a user's file that are not the recording (a temperature, a trigger, notes),
so that outputs such as ``compensate``'s can keep them beside the results."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from hystkit.errors import InputError

from .._read_options import DEFAULT_OPTIONS, FIELDS, ReadOptions
from ._csv_reader import _check_width

__all__ = ["read_other_columns"]


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
        text (an empty cell is ""). Empty for ``.mat`` files (their other variables are not
        recording columns) and when the recording was resampled (the columns have no values
        at the new times).

    Raises
    ------
    InputError
        The columns have a different number of rows than the recording.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if options.resample_hz is not None or suffix not in (".csv", ".parquet"):
        return {}
    ours = {options.name(field) for field in FIELDS}
    if suffix == ".parquet":
        import pyarrow.parquet as pq

        names = [n for n in pq.ParquetFile(path).schema_arrow.names if n not in ours]
        frame = pd.read_parquet(path, columns=names) if names else pd.DataFrame()
    else:
        from ._cells import Where

        sep = _check_width(path, Where(str(path)), options.sep)
        header = pd.read_csv(path, nrows=0, sep=sep, encoding="utf-8-sig").columns
        names = [n for n in header if str(n).strip() not in ours]
        if not names:
            return {}
        skip = options.skip_rows + options.units_row
        frame = pd.read_csv(path, sep=sep, usecols=names, encoding="utf-8-sig",
                            skiprows=range(1, 1 + skip) if skip else None)
    if not names:
        return {}
    if len(frame) != n_samples:
        raise InputError(f"{path}: the other columns ({', '.join(map(str, names))}) have "
                         f"{len(frame)} rows, the recording {n_samples}")
    out = {}
    for name in names:
        column = frame[name]
        if pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column):
            out[str(name).strip()] = column.to_numpy(dtype=np.float64)
        else:
            out[str(name).strip()] = column.fillna("").astype(str).to_numpy(dtype=object)
    return out
