"""Rows with a missing time, position or sensor: refused, dropped or interpolated.

A logger that misses a sample leaves an empty cell (read as NaN, as is a ``nan`` cell or a
NaN in a ``.mat`` or Parquet file). `ReadOptions.missing` says what to do:

- ``error`` (the default): the file is refused at the first such row, and the message counts
  the rows like it and names the option;
- ``drop``: every row with a missing cell is left out; its time steps become gaps (refused
  as non-uniform unless resampled or split), which the notice says;
- ``interpolate``: a missing position or sensor is interpolated linearly in time between the
  nearest complete rows, a missing time linearly by the row's place among them (uniform
  sampling); rows with nothing on one side (before the first or after the last complete
  row) cannot be and are dropped, as are blank rows (every cell missing: no sample there).

Either way one line says how many rows were touched and where (`fill_missing` returns it).
The error locator keeps the file's row of every sample left (`Where.rows`), so later errors
still name the file's own rows and lines.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ._cells import Where

__all__ = ["fill_missing", "missing_hint"]

_LISTED = 3  # rows named in a notice


def missing_hint(n_rows: int) -> str:
    """The end of a refusal: how many rows miss a cell and what to pass."""
    rows = f"{n_rows} row{'s' * (n_rows != 1)} miss{'es' * (n_rows == 1)} a value"
    return (f" ({rows}; --missing interpolate or --missing drop reads past them, or missing = "
            "\"interpolate\" in the settings file)")


def fill_missing(arrays: dict[str, np.ndarray], where: Where, mode: str
                 ) -> tuple[dict[str, np.ndarray], Where, str]:
    """Apply `mode` (``error``, ``drop``, ``interpolate``) to the NaN cells of `arrays`.

    Parameters
    ----------
    arrays : dict of str to ndarray, shape (n,)
        The recording's columns as read (``time`` first, in seconds), NaN where missing.
    where : Where
        The file's error locator.
    mode : {"error", "drop", "interpolate"}
        `ReadOptions.missing`.

    Returns
    -------
    arrays : dict of str to ndarray, shape (m,)
        Without missing values (``error``: `arrays` unchanged when none is missing).
    where : Where
        With ``rows``, the file's row of each of the m samples (``drop``/``interpolate``).
    notice : str
        One line: rows dropped or interpolated, and where; "" when there were none.

    Raises
    ------
    InputError
        ``error`` and a missing value: the first row and column, the count of such rows and
        the options that read past them.
    """
    names = list(arrays)
    lengths = {values.size for values in arrays.values()}
    if len(lengths) != 1:  # the checks after this say which column is short
        return arrays, where, ""
    missing = np.vstack([np.isnan(arrays[name]) for name in names])
    rows = np.flatnonzero(missing.any(axis=0))
    if mode == "error":
        if rows.size:
            first = int(rows[0])
            name = names[int(np.argmax(missing[:, first]))]
            raise where.fail("missing or NaN value" + missing_hint(rows.size), name, first)
        return arrays, where, ""
    n = missing.shape[1]
    blank = missing.all(axis=0)
    if mode == "drop":
        keep = ~missing.any(axis=0)
    else:
        complete = np.flatnonzero(~missing.any(axis=0))
        keep = ~blank
        if complete.size:
            keep[:complete[0]] = False
            keep[complete[-1] + 1:] = False
    kept = np.flatnonzero(keep)
    out = {name: values[kept] for name, values in arrays.items()}
    filled = np.zeros(0, dtype=np.intp)
    if mode == "interpolate" and kept.size:
        filled = kept[missing[:, kept].any(axis=0)]
        out = _interpolate(out)
    notice = _notice(where, n, rows, kept, filled, mode)
    return out, replace(where, rows=kept), notice


def _interpolate(arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Fill the NaN of `arrays` whose first and last rows are complete: time by row place,
    the others linearly in time."""
    time = arrays["time"]
    gap = np.isnan(time)
    if gap.any():
        place = np.arange(time.size, dtype=np.float64)
        time = time.copy()
        time[gap] = np.interp(place[gap], place[~gap], time[~gap])
    out = {"time": time}
    for name, values in arrays.items():
        if name != "time":
            gap = np.isnan(values)
            if gap.any():
                values = values.copy()
                values[gap] = np.interp(time[gap], time[~gap], values[~gap])
            out[name] = values
    return out


def _notice(where: Where, n: int, rows: np.ndarray, kept: np.ndarray, filled: np.ndarray,
            mode: str) -> str:
    """``my.csv: 3 of 8000 rows miss a value: 2 interpolated linearly in time (row 5 (line
    6), row 9 (line 10)); 1 dropped, blank or ... (row 8000 (line 8001))``; "" for none."""
    if not rows.size:
        return ""
    dropped = np.setdiff1d(np.arange(n), kept, assume_unique=True)
    parts = []
    if filled.size:
        parts.append(f"{filled.size} interpolated linearly in time ({_rows(where, filled)})")
    if dropped.size:
        inside = kept.size and ((dropped > kept[0]) & (dropped < kept[-1])).any()
        why = (", blank or with nothing to interpolate from on one side" if mode ==
               "interpolate" else "")
        gaps = ("; the time steps over them are gaps (--missing interpolate keeps the time "
                "grid)" if mode == "drop" and inside else "")
        parts.append(f"{dropped.size} dropped{why} ({_rows(where, dropped)}){gaps}")
    verb = "misses" if rows.size == 1 else "miss"
    return f"{where.source}: {rows.size} of {n} rows {verb} a value: {'; '.join(parts)}"


def _rows(where: Where, rows: np.ndarray) -> str:
    """``row 5 (line 6), row 9 (line 10), ... and 4 more`` for file rows `rows` (0-based)."""
    shown = [where.at(int(i)) for i in rows[:_LISTED]]
    more = f" and {rows.size - _LISTED} more" if rows.size > _LISTED else ""
    return ", ".join(shown) + more
