"""Parquet recordings, read with pyarrow column by column (pandas' metadata is not consulted).

A damaged file can fail anywhere inside pyarrow (ArrowInvalid, OSError, KeyError, MemoryError,
...); each becomes one `InputError`. Only the recording columns are read. Their Arrow types are
mapped explicitly: integers, floats and decimals become float64 (nulls become NaN and are
reported as missing values), dictionary-encoded columns are decoded first, text goes through the
same cell parser as CSV, and every other type (bool, timestamps, lists, structs, binary) is
refused by name. Columns are read one at a time, so the peak holds one column's Arrow buffers
beside the float64 arrays. Fuzzing 7 400 single-byte mutations found no crash inside pyarrow, so it runs
in-process (``tests/hostile/test_reader_fuzz.py`` keeps checking that).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from hystkit.errors import InputError

from .._read_options import DEFAULT_OPTIONS, ReadOptions
from ._cells import Where, parse_text, pick


def read_parquet(
    path: Path, source: str, need_position: bool, options: ReadOptions = DEFAULT_OPTIONS
) -> tuple[dict[str, np.ndarray], Where]:
    """Read the recording columns of a Parquet file as float64 arrays (not yet validated);
    of `options` only the column names apply here. Units hystkit wrote into the schema
    metadata come back in ``where.units``."""
    where = Where(source, names=options.columns)
    try:
        file = pq.ParquetFile(path)
        try:
            names = pick([str(name) for name in file.schema_arrow.names], need_position, where)
            arrays = {}
            for name in names:  # one column at a time: its Arrow buffers go before the next
                column = file.read(columns=[where.name(name)],
                                   use_pandas_metadata=False).column(0)
                if len(column) == 0:
                    raise where.fail("no data rows")
                arrays[name] = _column(column, name, where)
                del column
            units = _units(file.schema_arrow.metadata, names)
        finally:
            file.close()
        return arrays, replace(where, units=units)
    except InputError:
        raise  # our own (a ValueError too), from pick or the column checks
    except (pa.ArrowException, OSError, ValueError, TypeError, KeyError, IndexError,
            MemoryError, OverflowError, UnicodeDecodeError, RecursionError) as exc:
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise where.fail(f"cannot read Parquet file ({detail})") from exc


def _units(metadata: dict | None, names: list[str]) -> tuple[tuple[str, str], ...]:
    """Units hystkit wrote into the schema metadata (``hystkit.units``); anything unexpected
    there is ignored: units are labels, never needed to read the numbers."""
    try:
        units = json.loads((metadata or {}).get(b"hystkit.units", b"{}"))
        return tuple((n, units[n]) for n in names if isinstance(units.get(n), str))
    except (ValueError, TypeError, AttributeError):
        return ()


def _column(column: pa.ChunkedArray, name: str, where: Where) -> np.ndarray:
    """One Arrow column as float64, or the InputError saying why it is not numbers."""
    kind = column.type
    if pa.types.is_dictionary(kind):  # decode; nulls stay nulls
        column = column.cast(kind.value_type)
        kind = column.type
    if pa.types.is_null(kind):
        raise where.fail("empty cell", name, 0)
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_decimal(kind):
        values = pc.cast(column, pa.float64(), safe=False)
        # Nulls become NaN: reported later as "missing or NaN value" with the row.
        return values.to_numpy(zero_copy_only=False).astype(np.float64, copy=False)
    if pa.types.is_string(kind) or pa.types.is_large_string(kind) or pa.types.is_string_view(kind):
        return parse_text(column.to_pandas().reset_index(drop=True), name, where)
    raise where.fail(f"not numeric (dtype {kind})", name)
