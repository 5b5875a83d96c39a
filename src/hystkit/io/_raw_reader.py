"""Reading raw scope recordings (time, v1, v2, encoder or enc_a/enc_b) in chunks.

A raw recording is what the oscilloscope saved (sec. 4.2.1, 4.3): the two half-bridge voltages
``v1``, ``v2`` [V] of gauges R1 (top) and R2 (bottom), measured across the bridge resistor
(eq. 4.2), and the encoder, either merged into one 4-level channel ``encoder`` [V] or as two
logic channels ``enc_a``, ``enc_b`` [V]; ``time`` [s] may be left out when the sample rate ``fs``
is given in the settings. A fifth channel ``v0`` [V], the measured bridge supply (the reference
channel of sec. 4.2.1), is read when asked for (``open_raw(..., extra=("v0",))``). CSV (header row) and Parquet are read in chunks of rows, so memory does
not grow with the file; MATLAB ``.mat`` files are read whole (scipy cannot stream them).

Settings can sit beside the data in a TOML file with the data file's stem
(``run1.parquet`` -> ``run1.toml``; :mod:`._raw_config`). Every problem becomes one
`InputError` naming file, column and row.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from hystkit.errors import InputError

from ._cells import Where
from ._mat_reader import load_mat
from ._raw_checks import MAX_STEP_DEVIATION, check_time_steps, check_values
from ._raw_format import OPTIONAL_COLUMNS, RAW_COLUMNS, TIME_UNITS, RawChunk, RawFormat

__all__ = ["RawReader", "open_raw"]

_FS_HEAD = 4096  # samples whose mean step gives fs


class RawReader:
    """A raw recording opened for chunked reading; iterate with :meth:`chunks`.

    Opening reads only the header (CSV), the schema (Parquet) or the whole file (.mat), and the
    first rows to measure the sample rate. Attributes: ``source``, ``encoder_kind``
    (``"merged"`` or ``"ab"``), ``has_time``, ``fs`` [Hz], ``n_samples`` (None for CSV until read).
    `extra` names optional columns (:data:`OPTIONAL_COLUMNS`) that must be present and are read.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv``, ``.parquet`` or ``.mat`` raw recording.
    fmt : RawFormat, optional
        Column names, time unit, rows to skip, sample rate; the defaults if None.
    chunk_size : int, default 262144
        Samples per chunk.
    extra : tuple of str, optional
        Optional columns that must be present and are read.

    Raises
    ------
    InputError
        Missing file or column, unreadable or truncated file, a time column that disagrees
        with the ``fs`` setting.
    """

    def __init__(self, path: str | os.PathLike[str], fmt: RawFormat | None = None,
                 chunk_size: int = 1 << 18, *, extra: tuple[str, ...] = ()) -> None:
        unknown = [c for c in extra if c not in OPTIONAL_COLUMNS]
        if unknown:
            raise ValueError(f"unknown optional column(s) {unknown}; known: "
                             f"{', '.join(OPTIONAL_COLUMNS)}")
        self.extra = tuple(extra)
        self.path = Path(path)
        self.source = str(self.path)
        self.fmt = RawFormat() if fmt is None else fmt
        self.chunk_size = int(chunk_size)
        if self.chunk_size < 1:
            raise ValueError(f"chunk_size must be at least 1, got {chunk_size}")
        self.suffix = self.path.suffix.lower()
        if self.suffix not in (".csv", ".parquet", ".mat"):
            raise InputError(f"{self.source}: unsupported raw file type "
                             f"{self.suffix or '(no suffix)'!r}; accepted: .csv, .parquet, .mat")
        if not self.path.is_file():
            raise InputError(f"{self.source}: " + ("not a regular file" if self.path.exists()
                                                   else "file not found"))
        if self.path.stat().st_size == 0:
            raise InputError(f"{self.source}: file is empty (0 bytes)")
        self._where = Where(self.source, noun="variable" if self.suffix == ".mat" else "column",
                            item="sample" if self.suffix == ".mat" else "row",
                            header_lines=1 + self.fmt.skip_rows if self.suffix == ".csv"
                            else None)
        self._mat: dict[str, np.ndarray] | None = None
        self.n_samples: int | None = None
        found = self._open()
        if self.n_samples is not None:  # Parquet and .mat know their length: check it now
            self._check_count(self.n_samples)
        self.columns = self._pick(found)
        self.encoder_kind = "merged" if "encoder" in self.columns else "ab"
        self.has_time = "time" in self.columns
        self.fs = self._measure_fs()

    def fail(self, message: str, column: str | None = None, index: int | None = None
             ) -> InputError:
        """An InputError naming the file, the column (hystkit name) and the 0-based sample."""
        return self._where.fail(message, None if column is None else self.fmt.name(column),
                                index)

    def _check_values(self, values: np.ndarray, column: str, start: int) -> None:
        check_values(values, column, start, self.fail, n_samples=self.n_samples,
                     from_csv=self.suffix == ".csv")

    # ------------------------------------------------------------------ opening

    def _open(self) -> list[str]:
        if self.suffix == ".csv":
            try:
                header = pd.read_csv(self.path, nrows=0, encoding="utf-8-sig")
            except pd.errors.EmptyDataError as exc:
                raise self.fail("file is empty (no header row)") from exc
            except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as exc:
                raise self.fail(f"cannot read the CSV header ({exc})") from exc
            self._header = [str(c) for c in header.columns]
            return self._header
        if self.suffix == ".parquet":
            try:
                with pq.ParquetFile(self.path) as meta:
                    self.n_samples = int(meta.metadata.num_rows)
                    self._schema = meta.schema_arrow
            except (pa.ArrowException, OSError, ValueError) as exc:
                raise self.fail(f"cannot read Parquet file ({exc}); a file cut short "
                                "(truncated) has no footer") from exc
            return list(self._schema.names)
        # Parsed in a child process: a damaged file cannot crash or hang this one.
        contents = load_mat(self.path, [self.fmt.name(c) for c in RAW_COLUMNS], self.source)
        self._mat = contents.arrays
        self._mat_types = {k: v for k, v in contents.variables.items() if not k.startswith("__")}
        sizes = {int(np.prod(shape)) for _, shape in self._mat_types.values()}
        self.n_samples = sizes.pop() if len(sizes) == 1 else None
        return list(self._mat_types)

    def _pick(self, found: list[str]) -> tuple[str, ...]:
        names = {c: self.fmt.name(c) for c in RAW_COLUMNS}
        present = [c for c in RAW_COLUMNS if names[c] in found]
        encoder = ["encoder"] if "encoder" in present else [
            c for c in ("enc_a", "enc_b") if c in present]
        need = ["v1", "v2"] + ([] if self.fmt.fs is not None else ["time"])
        missing = [repr(names[c]) for c in need if c not in present]
        if "encoder" not in present and len(encoder) < 2:
            missing.append(f"{names['encoder']!r} or {names['enc_a']!r} and {names['enc_b']!r}")
        if "v0" in self.extra and "v0" not in present:
            listed = ", ".join(repr(n) for n in found) or "none"
            raise self.fail(f"missing {self._where.noun} {names['v0']!r}, the measured bridge "
                            "supply that supply_channel (--supply-channel) asks for; name it "
                            f"with columns.v0 in the settings file; found: {listed}")
        if missing:
            listed = ", ".join(repr(n) for n in found) or "none"
            raise self.fail(f"missing required {self._where.noun}(s) {', '.join(missing)}; a raw "
                            "recording needs v1, v2, the encoder (encoder, or enc_a and enc_b) "
                            f"and time (or an fs setting); found: {listed}")
        extra = [c for c in self.extra if c in present]
        for c in ["v1", "v2"] + encoder + extra + (["time"] if "time" in present else []):
            if found.count(names[c]) > 1:
                raise self.fail(f"appears {found.count(names[c])} times", c)
            if self.suffix == ".parquet":
                kind = self._schema.field(names[c]).type
                if not (pa.types.is_floating(kind) or pa.types.is_integer(kind)):
                    raise self.fail(f"not numeric (type {kind})", c)
        return tuple(["time"] * ("time" in present) + ["v1", "v2"] + encoder + extra)

    def _measure_fs(self) -> float:
        if not self.has_time:
            return float(self.fmt.fs)  # type: ignore[arg-type]
        # A fixed head, not one chunk: the rate must not depend on the chunk size.
        head = next(self._raw_chunks(_FS_HEAD, ("time",)), None)
        if head is None or head[1]["time"].size < 2:
            raise self.fail("fewer than 2 samples; a raw recording needs more")
        t = head[1]["time"]
        self._check_values(t, "time", 0)
        step = float((t[-1] - t[0]) / (t.size - 1))  # the mean step: jitter averages out
        if not step > 0:
            raise self.fail("time is not increasing", "time", 1)
        fs = 1.0 / step
        if self.fmt.fs is not None and abs(fs / self.fmt.fs - 1) > MAX_STEP_DEVIATION:
            raise self.fail(f"the time column is sampled at {fs:.6g} Hz but the settings say "
                            f"fs = {self.fmt.fs:.6g} Hz; fix the fs setting (or time_unit, "
                            f"now {self.fmt.time_unit!r})", "time")
        return fs

    # ------------------------------------------------------------------ reading

    def chunks(self, columns: tuple[str, ...] | None = None) -> Iterator[RawChunk]:
        """Validated chunks of the recording (optionally only some of its columns).

        Checks: finite numbers in every cell (a short last line is reported as truncation),
        uniform time steps within 1 % of 1/fs across chunk borders, and the sample count
        against ``n_samples`` of the settings. Restartable: each call reads from the start.
        """
        wanted = self.columns if columns is None else tuple(
            c for c in self.columns if c in columns)
        t_prev = None
        n = 0
        for start, arrays in self._raw_chunks(self.chunk_size, wanted):
            for name, values in arrays.items():
                self._check_values(values, name, start)
            if "time" in arrays:
                t_prev = check_time_steps(arrays["time"], t_prev, start, self.fs, self.fail)
            n = start + next(iter(arrays.values())).size
            yield RawChunk(start=start, **arrays)
        if n < 2:
            raise self.fail(f"only {n} sample(s); a raw recording needs at least 2")
        if columns is None:
            self._check_count(n)
        self.n_samples = n

    def _check_count(self, n: int) -> None:
        if self.fmt.n_samples is not None and n != self.fmt.n_samples:
            raise self.fail(f"{n} samples but the settings say n_samples = "
                            f"{self.fmt.n_samples}" + ("; the file looks truncated"
                                                       if n < self.fmt.n_samples else ""))

    def _raw_chunks(self, size: int, wanted: tuple[str, ...]
                    ) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        scale = TIME_UNITS[self.fmt.time_unit]
        start = 0
        for arrays in self._read(size, wanted):
            if "time" in arrays and scale != 1.0:
                arrays["time"] = arrays["time"] * scale
            yield start, arrays
            start += next(iter(arrays.values())).size

    def _read(self, size: int, wanted: tuple[str, ...]) -> Iterator[dict[str, np.ndarray]]:
        names = [self.fmt.name(c) for c in wanted]
        if self.suffix == ".parquet":
            # pre_buffer=False: the default pre-buffers every column chunk it will read, which
            # holds the whole file in memory by the end of the iteration.
            with pq.ParquetFile(self.path, pre_buffer=False) as handle:
                batches = handle.iter_batches(batch_size=size, columns=names)
                while True:
                    try:
                        batch = next(batches)
                    except StopIteration:
                        return
                    except (pa.ArrowException, OSError) as exc:
                        raise self.fail(f"cannot read Parquet data ({exc})") from exc
                    yield {c: _as_float(batch.column(n).to_numpy(zero_copy_only=False))
                           for c, n in zip(wanted, names)}
        elif self.suffix == ".mat":
            assert self._mat is not None
            arrays = {c: self._mat_vector(c) for c in wanted}
            lengths = {c: a.size for c, a in arrays.items()}
            if len(set(lengths.values())) > 1:
                raise self.fail("variables have different lengths: "
                                + ", ".join(f"{self.fmt.name(c)} {n}" for c, n in lengths.items()))
            total = next(iter(lengths.values()))
            for i in range(0, total, size):
                yield {c: a[i:i + size] for c, a in arrays.items()}
        else:
            yield from self._read_csv(size, wanted)

    def _read_csv(self, size: int, wanted: tuple[str, ...]) -> Iterator[dict[str, np.ndarray]]:
        # skip_blank_lines=False keeps rows and file lines in step (for error locations) and
        # shows a blank line as an all-NaN row: allowed only at the end of the file.
        # Every channel of the recording is read, even when fewer are wanted: a blank line is
        # empty in all of them, while a NaN cell of the one wanted column is a bad cell.
        every = self.columns if hasattr(self, "columns") else wanted
        read = [self.fmt.name(c) for c in every]
        with pd.read_csv(self.path, usecols=read, dtype=np.float64, chunksize=size,
                         skiprows=range(1, 1 + self.fmt.skip_rows), skip_blank_lines=False,
                         encoding="utf-8-sig") as reader:
            start = 0
            blank_at = -1  # first blank line seen so far
            while True:
                try:
                    frame = next(reader)
                except StopIteration:
                    return
                except ValueError as exc:  # pandas: a cell that is not a number
                    raise self._locate_csv_error(start, size, every, read, exc) from exc
                arrays = {c: frame[n].to_numpy(dtype=np.float64) for c, n in zip(every, read)}
                empty = np.logical_and.reduce([np.isnan(a) for a in arrays.values()])
                arrays = {c: arrays[c] for c in wanted}
                data = np.flatnonzero(~empty)
                if data.size and blank_at >= 0:
                    raise self.fail("empty line inside the data", index=blank_at)
                if empty.any():
                    first_blank = int(np.argmax(empty))
                    if data.size and first_blank < data[-1]:
                        raise self.fail("empty line inside the data", index=start + first_blank)
                    blank_at = start + first_blank
                    arrays = {c: a[~empty] for c, a in arrays.items()}
                if data.size:
                    yield arrays
                start += len(frame)

    def _locate_csv_error(self, start: int, size: int, wanted: tuple[str, ...],
                          names: list[str], exc: Exception) -> InputError:
        """Re-read the failing chunk as text to name the first bad cell."""
        # An integer skiprows skips lines in C; a range would become a set of `start` ints.
        text = pd.read_csv(self.path, header=None, names=self._header, usecols=names, dtype=str,
                           nrows=size, skiprows=1 + self.fmt.skip_rows + start,
                           skip_blank_lines=False, keep_default_na=False, encoding="utf-8-sig")
        for column, name in zip(wanted, names):
            cells = text[name].fillna("").astype(str).str.strip().reset_index(drop=True)
            numbers = pd.to_numeric(cells.where(cells != ""), errors="coerce")
            literal_nan = cells.str.lower().str.lstrip("+-").eq("nan")
            bad = np.flatnonzero((numbers.isna() & ~literal_nan).to_numpy())
            if bad.size:
                i = int(bad[0])
                problem = "empty cell" if cells[i] == "" else f"non-numeric value {cells[i]!r}"
                return self.fail(problem, column, start + i)
        return self.fail(f"cannot parse CSV ({exc})", index=start)

    def _mat_vector(self, column: str) -> np.ndarray:
        assert self._mat is not None
        name = self.fmt.name(column)
        if name not in self._mat:  # the reader hands back real numbers only
            raise self.fail(f"not real numbers (type {self._mat_types[name][0]})", column)
        values = np.asarray(self._mat[name])
        if values.dtype.kind not in "iuf":
            raise self.fail(f"not real numbers (dtype {values.dtype})", column)
        values = np.atleast_1d(np.squeeze(values))
        if values.ndim != 1:
            raise self.fail(f"must be a row or column vector, got shape {values.shape}", column)
        return _as_float(values)


def _as_float(values: np.ndarray) -> np.ndarray:
    """float32 stays float32 (a scope's samples fit, and it halves the memory); others float64."""
    return values if values.dtype in (np.float32, np.float64) else values.astype(np.float64)


def open_raw(path: str | os.PathLike[str], fmt: RawFormat | None = None,
             chunk_size: int = 1 << 18, *, extra: tuple[str, ...] = ()) -> RawReader:
    """Open a raw recording (``.csv``, ``.parquet``, ``.mat``) for chunked reading.

    `extra` lists optional channels to read as well (``("v0",)``: the measured supply); each
    must then be in the file.

    Parameters
    ----------
    path : str or os.PathLike
        The raw recording.
    fmt : RawFormat, optional
        Column names, time unit, rows to skip, sample rate; the defaults if None.
    chunk_size : int, default 262144
        Samples per chunk.
    extra : tuple of str, optional
        Optional channels to read as well.

    Returns
    -------
    RawReader
        The opened recording; iterate its :meth:`RawReader.chunks`.

    Raises
    ------
    InputError
        Missing file or column, unreadable or truncated file, a time column that disagrees
        with the ``fs`` setting. Further problems are raised while iterating chunks.
    """
    return RawReader(path, fmt, chunk_size, extra=extra)
