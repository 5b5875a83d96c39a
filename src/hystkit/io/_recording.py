"""Recordings (time, position, sensor) read from and written to CSV, Parquet and MATLAB files.

Every problem with an input file becomes one `InputError` whose message names the file,
the column and the row, so the CLI can print it verbatim.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy.io import loadmat
from scipy.io.matlab import MatReadError

from hystkit.errors import InputError

_COLUMNS = ("time", "position", "sensor")  # also the column order of written files
_MAX_STEP_DEVIATION = 0.01  # relative to the median step; beyond this we ask for resampling


@dataclass(frozen=True)
class _Where:
    """Turns a column name and a 0-based sample index into a location for an error message."""

    source: str
    noun: str = "column"
    item: str = "row"
    header_lines: int | None = None  # CSV only: data row r sits on file line r + header_lines

    def fail(self, message: str, column: str | None = None, index: int | None = None) -> InputError:
        parts = [] if column is None else [f"{self.noun} {column!r}"]
        if index is not None:
            text = f"{self.item} {index + 1}"
            if self.header_lines is not None:
                text += f" (line {index + 1 + self.header_lines})"
            parts.append(text)
        location = f"{', '.join(parts)}: " if parts else ""
        return InputError(f"{self.source}: {location}{message}")


class Sampled:
    """Sample count, step and rate of anything with a ``time`` array (recordings, data sets)."""

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.time.size)

    @property
    def dt(self) -> float:
        """Median sampling step [s]."""
        return float(np.median(np.diff(self.time)))

    @property
    def fs(self) -> float:
        """Sampling rate [Hz], 1 / `dt`."""
        return 1.0 / self.dt


@dataclass(frozen=True, eq=False)  # eq=False: element-wise array comparison has no single truth
class Recording(Sampled):
    """One validated, uniformly sampled recording.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], strictly increasing, uniform to within 1 % of the median step.
    sensor : array_like, shape (n,)
        Differential sensor signal ΔR/R [-].
    position : array_like, shape (n,), optional
        Reference position [mm]; None when the recording has none.
    source : str
        Where the data came from (a file name); used in error messages.

    Notes
    -----
    The arrays are stored as read-only float64 copies, so a recording cannot change after
    it was validated. Invalid data raise `InputError`.
    """

    time: np.ndarray
    sensor: np.ndarray
    position: np.ndarray | None = None
    source: str = "<memory>"

    def __post_init__(self) -> None:
        where = _Where(self.source, item="sample")
        arrays = {
            name: _as_vector(getattr(self, name), name, where)
            for name in _COLUMNS
            if name != "position" or self.position is not None
        }
        _validate(arrays, where)
        for name, values in arrays.items():
            values.setflags(write=False)
            object.__setattr__(self, name, values)

    def has_position(self) -> bool:
        """Whether the recording carries a reference position."""
        return self.position is not None


def read_recording(path: str | os.PathLike[str], *, need_position: bool = True) -> Recording:
    """Read and validate a recording from a ``.csv``, ``.parquet`` or ``.mat`` file.

    Parameters
    ----------
    path : str or path-like
        CSV files need a header row naming the columns; MATLAB files need variables
        named like the columns (row or column vectors). Other columns are ignored.
    need_position : bool
        Require a ``position`` column. If False it is still read when present.

    Returns
    -------
    Recording
        Columns ``time`` [s], ``sensor`` [-] and, if present, ``position`` [mm].

    Raises
    ------
    InputError
        Unknown suffix, missing or empty file, missing column, non-numeric, empty or
        non-finite cell, unequal lengths, time not strictly increasing, non-uniform
        sampling, fewer than 2 samples. The message names file, column and row.
    """
    path = Path(path)
    source = str(path)
    suffix = path.suffix.lower()
    if suffix not in _READERS:
        raise InputError(
            f"{source}: unsupported file type {suffix or '(no suffix)'!r}; "
            f"accepted: {', '.join(_READERS)}"
        )
    if not path.exists():
        raise InputError(f"{source}: file not found")
    if not path.is_file():
        raise InputError(f"{source}: not a regular file")
    if path.stat().st_size == 0:
        raise InputError(f"{source}: file is empty (0 bytes)")
    arrays, where = _READERS[suffix](path, source, need_position)
    _validate(arrays, where)
    return Recording(arrays["time"], arrays["sensor"], arrays.get("position"), source)


def _read_csv(path: Path, source: str, need_position: bool) -> tuple[dict[str, np.ndarray], _Where]:
    where = _Where(source, header_lines=1)
    try:
        # All cells as text: lets us tell 'abc' from an empty cell and keep exact line numbers
        # (blank lines are kept). header=None because with a header pandas silently turns
        # the first column into an index when every data row has one field too many.
        raw = pd.read_csv(path, header=None, dtype=str, keep_default_na=False,
                          skip_blank_lines=False, encoding="utf-8-sig")
    except pd.errors.EmptyDataError as exc:
        raise where.fail("file is empty (no header row)") from exc
    except pd.errors.ParserError as exc:
        found = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", str(exc))
        if found is None:
            raise where.fail(f"cannot parse CSV ({exc})") from exc
        expected, line, saw = (int(g) for g in found.groups())
        raise where.fail(f"{saw} fields but the header names {expected} columns",
                         index=line - 2) from exc
    except UnicodeDecodeError as exc:
        raise where.fail(f"not a UTF-8 text file (byte {exc.start}: {exc.reason})") from exc
    header = [str(name).strip() for name in raw.iloc[0]]
    cells = [raw[j].iloc[1:].fillna("").str.strip().reset_index(drop=True) for j in raw.columns]
    names = _pick(header, need_position, where,
                  hint=" (the first line must be a comma-separated header naming the columns)")
    # Trailing blank lines are common at the end of logger files and carry no data.
    filled = np.flatnonzero(np.logical_or.reduce([(c != "").to_numpy() for c in cells]))
    n_rows = int(filled[-1]) + 1 if filled.size else 0
    if n_rows == 0:
        raise where.fail("no data rows below the header")
    return {n: _parse_text(cells[header.index(n)].iloc[:n_rows], n, where) for n in names}, where


def _read_parquet(
    path: Path, source: str, need_position: bool
) -> tuple[dict[str, np.ndarray], _Where]:
    where = _Where(source)
    try:
        frame = pd.read_parquet(path)
    except (ValueError, OSError) as exc:  # pyarrow's ArrowInvalid / ArrowIOError derive from these
        raise where.fail(f"cannot read Parquet file ({exc})") from exc
    names = _pick([str(c) for c in frame.columns], need_position, where)
    if len(frame) == 0:
        raise where.fail("no data rows")
    arrays = {}
    for name in names:
        column = frame[name]
        if pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column):
            arrays[name] = column.to_numpy(dtype=np.float64, na_value=np.nan)
        elif pd.api.types.is_string_dtype(column) or column.dtype == object:
            arrays[name] = _parse_text(column.reset_index(drop=True), name, where)
        else:
            raise where.fail(f"not numeric (dtype {column.dtype})", name)
    return arrays, where


def _read_mat(path: Path, source: str, need_position: bool) -> tuple[dict[str, np.ndarray], _Where]:
    where = _Where(source, noun="variable", item="sample")
    try:
        contents = loadmat(path)
    except NotImplementedError as exc:  # scipy's answer to HDF5-based files
        raise where.fail("MATLAB v7.3 (HDF5) files are not supported; save with '-v7'") from exc
    except (ValueError, OSError, MatReadError) as exc:
        raise where.fail(f"cannot read MATLAB file ({exc})") from exc
    variables = {k: v for k, v in contents.items() if not k.startswith("__")}
    names = _pick(list(variables), need_position, where)
    return {name: _as_vector(variables[name], name, where) for name in names}, where


_READERS = {".csv": _read_csv, ".parquet": _read_parquet, ".mat": _read_mat}


def _pick(found: list[str], need_position: bool, where: _Where, hint: str = "") -> list[str]:
    """Names of the recording columns present in `found`; missing or doubled ones fail."""
    required = [n for n in _COLUMNS if need_position or n != "position"]
    missing = [n for n in required if n not in found]
    if missing:
        listed = ", ".join(repr(n) for n in found) or "none"
        raise where.fail(f"missing required {where.noun} {', '.join(map(repr, missing))}; "
                         f"{where.noun}s found: {listed}{hint}")
    for name in _COLUMNS:
        if found.count(name) > 1:
            raise where.fail(f"appears {found.count(name)} times in the header", name)
    return [n for n in _COLUMNS if n in found]


def _parse_text(text: pd.Series, name: str, where: _Where) -> np.ndarray:
    """Parse text cells (positional index) to float64, failing at the first empty or bad cell."""
    missing = text.isna().to_numpy()
    text = text.where(~missing, "").astype(str).str.strip()
    empty = missing | (text == "").to_numpy()
    numbers = pd.to_numeric(text.where(~empty), errors="coerce")
    # to_numeric also yields NaN for a literal 'nan'; that one is numeric, _validate reports it.
    literal_nan = text.str.lower().str.lstrip("+-").eq("nan").to_numpy()
    bad = np.flatnonzero(empty | (numbers.isna().to_numpy() & ~literal_nan))
    if bad.size:
        i = int(bad[0])
        problem = "empty cell" if empty[i] else f"non-numeric value {text.iloc[i]!r}"
        raise where.fail(problem, name, i)
    return numbers.to_numpy(dtype=np.float64, na_value=np.nan)


def _as_vector(values: Any, name: str, where: _Where) -> np.ndarray:
    """Copy `values` to a 1-D float64 array; row and column vectors are accepted."""
    array = np.asarray(values)
    if array.dtype.kind not in "iuf":  # bool, complex, text and objects are not measurements
        raise where.fail(f"not real numbers (dtype {array.dtype})", name)
    array = np.atleast_1d(np.squeeze(array))
    if array.ndim != 1:
        raise where.fail(f"must be a row or column vector, got shape {np.shape(values)}", name)
    return array.astype(np.float64, copy=True)


def _validate(arrays: dict[str, np.ndarray], where: _Where) -> None:
    """Check 1-D float arrays (``time`` among them) for the invariants of a `Recording`."""
    lengths = {name: values.size for name, values in arrays.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{name} {n}" for name, n in lengths.items())
        raise where.fail(f"{where.noun}s have different lengths: {listed}")
    for name, values in arrays.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            problem = "missing or NaN value" if np.isnan(values[i]) else f"infinite value {values[i]}"
            raise where.fail(problem, name, i)
    time = arrays["time"]
    if time.size < 2:
        raise where.fail(f"only {time.size} sample(s); a recording needs at least 2")
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise where.fail(f"time is not strictly increasing: {time[i]:.12g} s follows "
                         f"{time[i - 1]:.12g} s", "time", i)
    median = float(np.median(step))
    bad = np.flatnonzero(np.abs(step - median) > _MAX_STEP_DEVIATION * median)
    if bad.size:
        i = int(bad[0]) + 1
        raise where.fail(f"non-uniform sampling: step {step[i - 1]:.6g} s deviates more than "
                         f"{_MAX_STEP_DEVIATION:.0%} from the median step {median:.6g} s; "
                         "resample the recording to a uniform time grid", "time", i)
