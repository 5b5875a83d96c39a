"""CSV recordings: a fast numeric pass, and a chunked text pass that says what is wrong.

Most files are clean, so the first pass asks pandas' C parser for float64 directly, chunk by
chunk, into arrays sized by counting the line breaks first (memory: the recording columns
themselves plus one chunk). pandas >= 3 parses floats exactly by default (earlier
versions need ``float_precision="round_trip"``), so values stay bit-identical to what
`write_recording` wrote. Anything unusual in that pass (a cell that is not a number, an empty
cell or blank line, a long row, bytes that are not UTF-8) sends the file to the second pass,
which reads it as text in chunks of `CHUNK_ROWS` rows, keeps exact file line numbers and
produces the error message; it also accepts what the first pass is too strict for (trailing
blank lines, text columns beside the numbers). Neither pass holds all cells as text at once.

Before both, a file of at most `PLAIN_BYTES` whose every data cell is a plain decimal number
(``-1.5``, ``2e-3``; comma/semicolon/tab separated, LF line ends, no quotes) is parsed
without pandas: a command on a small clean file should not wait ~0.4 s for pandas to import.
Plain decimals are parsed correctly rounded by any reader, so the values are the same bits
pandas would give; anything else goes to the passes above, which decide and word the errors.

First of all `csv_layout` (:mod:`._csv_layout`) settles what the options leave to it: the
separator, a decimal comma, and comment lines before the header, which every pass skips.
"""

from __future__ import annotations

import codecs
import re
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from hystkit.errors import InputError

from .._read_options import DEFAULT_OPTIONS, ReadOptions
from ._cells import Where, cell_problem, pick, text_problems
from ._csv_layout import COMMA_NUMBER, POINT_NUMBER, SEP_NAMES, CsvLayout, csv_layout
from ._missing import missing_hint

CHUNK_ROWS = 100_000  # text cells held at once by the second pass
FAST_CHUNK_ROWS = 1 << 18  # rows parsed at once by the first pass, copied into the result
PLAIN_BYTES = 1 << 24  # larger files go straight to pandas, whose import is then a small share
_TEXT = {"header": None, "dtype": str, "keep_default_na": False, "skip_blank_lines": False,
         "encoding": "utf-8-sig"}


@cache
def _pandas() -> tuple[Any, dict[str, str], tuple[type[BaseException], ...]]:
    """pandas, its exact-float option, and what it raises on text it cannot tokenise (NUL
    bytes, huge fields, stray quotes, ...); imported on the first file that needs it."""
    import pandas as pd

    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    return pd, exact, (pd.errors.ParserError, ValueError, OverflowError, MemoryError)


def read_csv(path: Path, source: str, need_position: bool,
             options: ReadOptions = DEFAULT_OPTIONS) -> tuple[dict[str, np.ndarray], Where]:
    """Read the recording columns of a CSV file as float64 arrays (not yet validated).

    `options` gives the file's column names, the separator, the decimal mark and the lines
    skipped after the header (`csv_layout` settles those left at ``auto``); its time unit is
    applied by the caller.
    """
    # Data row r sits on file line r + preamble + 1 + units + skip_rows (comment lines,
    # header, units line, skipped lines).
    skip = options.skip_rows + options.units_row
    where = Where(source, names=options.columns)
    layout = csv_layout(path, options, where)
    where = replace(where, header_lines=layout.preamble + 1 + skip)
    sep, decimal, preamble = layout.sep, layout.decimal, layout.preamble
    first = "the first line" if not preamble else f"line {preamble + 1}, below the comments,"
    hint = f" ({first} must be a {SEP_NAMES[sep]}-separated header naming the columns)"
    header = {"decimal": decimal, "preamble": preamble, "comment_header": layout.comment_header}
    arrays = _read_plain(path, need_position, where, sep, skip, hint, **header)
    if arrays is None:
        arrays = _read_numbers(path, need_position, where, sep, skip, hint, **header)
    if arrays is None:
        arrays = _read_text(path, need_position, where, sep, skip, hint,
                            units_hint=not options.units_row, missing=options.missing, **header)
    if options.units_row:
        where = replace(where, units=_units_row(path, where, layout, list(arrays)))
    return arrays, where


def _read_plain(path: Path, need_position: bool, where: Where, sep: str, skip: int,
                hint: str, *, decimal: str = ".", preamble: int = 0,
                comment_header: bool = False) -> dict[str, np.ndarray] | None:
    """The pandas-free pass: every data cell a plain decimal, or None (the file goes on)."""
    if path.stat().st_size > PLAIN_BYTES:
        return None
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return None
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()  # the final line end
    if len(lines) <= preamble:
        return None
    header = lines[preamble].split(sep)
    body = lines[preamble + 1 + skip:]
    if "\r" in text or '"' in lines[preamble] or not body or any(not h.strip() for h in header):
        return None
    # The data lines hold only digits, . e E + -, separators and single line ends (a blank
    # line, spaces, nan, inf, quotes or hex go on to pandas). Over that alphabet numpy's
    # parser accepts exactly the plain decimals and refuses everything else (1e, 1.2.3, an
    # empty cell, a short or long row): a one-pass byte check instead of a regular
    # expression per line (~5 ms on 8000 lines).
    start = len(codecs.BOM_UTF8) if data.startswith(codecs.BOM_UTF8) else 0  # as decoded
    for _ in range(preamble + 1 + skip):
        start = data.index(b"\n", start) + 1
    if b"\n\n" in data[start - 1:] or data[start:].translate(None, _plain_bytes(sep, decimal)):
        return None
    if decimal == ",":  # the separator is not a comma: every comma is a decimal mark
        body = [line.replace(",", ".") for line in body]
    header = CsvLayout(comment_header=comment_header).names(header)
    names = pick(header, need_position, where, hint=hint)
    try:
        table = np.loadtxt(body, delimiter=sep, dtype=np.float64, ndmin=2)
    except ValueError:
        return None
    if table.shape[1] != len(header):
        return None
    arrays = {name: np.ascontiguousarray(table[:, header.index(where.name(name))])
              for name in names}
    if not all(np.isfinite(values).all() for values in arrays.values()):
        return None  # e.g. 1e999: the checks downstream say which cell, as for every file
    return arrays


def _plain_bytes(sep: str, decimal: str = ".") -> bytes:
    """The bytes a plain data line may hold: deleting them leaves nothing."""
    return b"0123456789eE+-\n" + decimal.encode() + sep.encode()


def _units_row(path: Path, where: Where, layout: CsvLayout,
               names: list[str]) -> tuple[tuple[str, str], ...]:
    """(hystkit name, unit) from the line after the header; empty cells give no unit."""
    pd, _, parse_errors = _pandas()
    line = layout.preamble + 2
    try:
        lines = pd.read_csv(path, nrows=2, sep=layout.sep, skiprows=layout.preamble, **_TEXT)
    except (*parse_errors, UnicodeDecodeError) as exc:
        raise where.fail(f"cannot read the units line (line {line}): {exc}") from exc
    if len(lines) < 2:
        raise where.fail(f"--units-row: there is no line {line} to read units from")
    header = layout.names(list(lines.iloc[0]))
    row = lines.iloc[1].fillna("")
    cells = [str(cell).strip() for cell in row if str(cell).strip()]
    if cells and all(_is_number(cell.replace(layout.decimal, ".")) for cell in cells):
        # A file without a units line: reading on would drop its first sample unsaid.
        shown = ", ".join(cells[:3]) + (", ..." if len(cells) > 3 else "")
        raise where.fail(f"line {line}: --units-row reads units there but it holds numbers "
                         f"({shown}), the first sample: this file has no units line (drop "
                         "--units-row, or units_row from its settings file)")
    units = []
    for name in names:
        unit = str(row.iloc[header.index(where.name(name))]).strip()
        if unit:
            units.append((name, unit))
    return tuple(units)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _read_numbers(path: Path, need_position: bool, where: Where, sep: str = ",", skip: int = 0,
                  hint: str = "", *, decimal: str = ".", preamble: int = 0,
                  comment_header: bool = False) -> dict[str, np.ndarray] | None:
    """The fast pass: every column as float64, or None when anything needs a closer look."""
    pd, exact, parse_errors = _pandas()
    try:
        first = pd.read_csv(path, nrows=1, sep=sep, skiprows=preamble, **_TEXT)
    except (*parse_errors, UnicodeDecodeError):
        return None
    if first.empty or first.iloc[0].isna().any():  # blank first line or empty file: pass 2
        return None
    header = CsvLayout(comment_header=comment_header).names(list(first.iloc[0]))
    if any("\n" in name or "\r" in name for name in header):  # a quoted header spans lines
        return None
    names = pick(header, need_position, where, hint=hint)
    columns = [header.index(where.name(name)) for name in names]
    # Rows <= line breaks + 1. np.empty pages that are never written cost no memory, so the
    # bound may be generous (CRLF counts twice).
    out = [np.empty(_line_bound(path)) for _ in names]
    n = 0
    try:
        # index_col=False: with names given, pandas would otherwise make a long row's extra
        # leading field an index; skip_blank_lines=False: a blank line becomes a NaN row.
        with pd.read_csv(path, header=None, skiprows=preamble + 1 + skip,
                         names=list(range(len(header))), index_col=False, dtype=np.float64,
                         skip_blank_lines=False, sep=sep, decimal=decimal, encoding="utf-8-sig",
                         chunksize=FAST_CHUNK_ROWS, **exact) as reader:
            for chunk in reader:
                if n + len(chunk) > out[0].size:
                    return None  # cannot happen with the bound above; the text pass decides
                for target, j in zip(out, columns):
                    values = chunk[j].to_numpy(dtype=np.float64)
                    if np.isnan(values).any():
                        return None  # pass 2 tells an empty cell from 'nan', blank lines
                    target[n:n + values.size] = values
                n += len(chunk)
    except (*parse_errors, UnicodeDecodeError):
        return None
    if n == 0:
        return None
    return {name: values[:n] for name, values in zip(names, out)}


def _line_bound(path: Path, block: int = 1 << 22) -> int:
    """An upper bound of the data rows: line feeds plus carriage returns plus one."""
    count = 1
    with path.open("rb") as file:
        while data := file.read(block):
            count += data.count(b"\n") + data.count(b"\r")
    return count


def _read_text(path: Path, need_position: bool, where: Where, sep: str = ",", skip: int = 0,
               hint: str = "", units_hint: bool = False, *, decimal: str = ".",
               preamble: int = 0, comment_header: bool = False,
               missing: str = "error") -> dict[str, np.ndarray]:
    """The careful pass: text cells chunk by chunk, the first problem of each column kept;
    `units_hint`: when every column's first data cell is text, suggest ``--units-row``;
    `missing` other than ``error``: an empty cell is NaN (`hystkit.io._missing` decides)."""
    pd, _, parse_errors = _pandas()
    header: list[str] | None = None
    names: list[str] = []
    parts: dict[str, list[np.ndarray]] = {}
    first_bad: dict[str, tuple[int, str]] = {}
    n_rows = 0  # data rows up to the last one with any cell filled
    empty_rows: list[np.ndarray] = []  # data rows with an empty recording cell
    offset = 0  # data rows before this chunk
    try:
        # header=None because with a header pandas silently turns the first column into an
        # index when every data row has one field too many.
        skipped = [*range(preamble), *range(preamble + 1, preamble + 1 + skip)]
        with pd.read_csv(path, chunksize=CHUNK_ROWS, sep=sep, skiprows=skipped or None,
                         **_TEXT) as reader:
            for chunk in reader:
                if header is None:
                    header = CsvLayout(comment_header=comment_header).names(
                        list(chunk.iloc[0]))
                    names = pick(header, need_position, where, hint=hint)
                    parts = {name: [] for name in names}
                    chunk = chunk.iloc[1:]
                filled = np.zeros(len(chunk), dtype=bool)
                for j in chunk.columns:
                    filled |= (chunk[j].fillna("").str.strip() != "").to_numpy()
                if filled.any():
                    # Trailing blank lines are common at the end of logger files and carry no data.
                    n_rows = offset + int(np.flatnonzero(filled)[-1]) + 1
                empty = np.zeros(len(chunk), dtype=bool)
                for name in names:
                    numbers, bad, stripped = text_problems(chunk[header.index(where.name(name))],
                                                           decimal)
                    empty |= (stripped == "").to_numpy()
                    if missing != "error":
                        bad &= (stripped != "").to_numpy()  # NaN: read_recording decides
                    if name not in first_bad and bad.any():
                        i = int(np.argmax(bad))
                        first_bad[name] = (offset + i, cell_problem(stripped, i)
                                           + _decimal_hint(stripped.iloc[i], sep, decimal))
                    parts[name].append(numbers)
                empty_rows.append(offset + np.flatnonzero(empty))
                offset += len(chunk)
    except pd.errors.EmptyDataError as exc:
        raise where.fail("file is empty (no header row)") from exc
    except UnicodeDecodeError as exc:
        raise where.fail(f"not a UTF-8 text file ({_first_bad_utf8(path)})") from exc
    except parse_errors as exc:
        raise _parse_error(exc, where) from exc
    if header is None:
        raise where.fail("file is empty (no header row)")
    if n_rows == 0:
        raise where.fail("no data rows below the header")
    units_like = units_hint and all(first_bad.get(name, (-1, ""))[0] == 0 for name in names) \
        and all(first_bad[name][1].startswith("non-numeric") and "decimal" not in
                first_bad[name][1] for name in names)
    for name in names:  # the first column in recording order with a bad cell in the data
        if name in first_bad and first_bad[name][0] < n_rows:
            row, problem = first_bad[name]
            if units_like:
                problem += ("; if this line holds units, pass --units-row (or units_row = "
                            "true in the settings file)")
            elif problem == "empty cell":
                empty = np.concatenate(empty_rows)
                problem += missing_hint(int(np.count_nonzero(empty < n_rows)))
            raise where.fail(problem, name, row)
    return {name: np.concatenate(parts.pop(name))[:n_rows] for name in names}


def _decimal_hint(cell: str, sep: str, decimal: str) -> str:
    """What to do about a cell that is a number written with the other decimal mark."""
    if decimal == "." and sep != "," and COMMA_NUMBER.fullmatch(cell):
        return " (a decimal comma? pass --decimal ',', or decimal = \",\" in the settings file)"
    if decimal == "," and POINT_NUMBER.fullmatch(cell):
        return (" (a decimal point, where this file's numbers use a decimal comma: pass "
                "--decimal '.' if they do not)")
    return ""


def _parse_error(exc: Exception, where: Where) -> InputError:
    """The InputError for a tokeniser failure, with the file line where pandas names one."""
    quote = re.search(r"EOF inside string starting at row (\d+)", str(exc))
    if quote is not None:  # pandas counts file lines from 0 here
        return where.fail("a quote opened here is never closed",
                          index=int(quote.group(1)) - where.header_lines)
    found = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", str(exc))
    if found is None:
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        return where.fail(f"cannot parse CSV ({detail})")
    expected, line, saw = (int(g) for g in found.groups())
    # pandas counts file lines from 1, skipped lines included
    return where.fail(f"{saw} fields but the header names {expected} columns",
                      index=line - 1 - where.header_lines)


def _first_bad_utf8(path: Path, block: int = 1 << 20) -> str:
    """Where the first byte that is not UTF-8 sits: 'line L, byte offset B: reason'."""
    decoder = codecs.getincrementaldecoder("utf-8")()
    line, start = 1, 0
    with path.open("rb") as file:
        while data := file.read(block):
            try:
                decoder.decode(data)
            except UnicodeDecodeError as exc:
                # The decoder keeps at most 3 bytes of an unfinished character from the last
                # block; exc.start counts from those.
                held = len(exc.object) - len(data)
                newlines = data.count(b"\n", 0, max(exc.start - held, 0))
                return f"line {line + newlines}, byte offset {start + exc.start - held}: {exc.reason}"
            line += data.count(b"\n")
            start += len(data)
    try:
        decoder.decode(b"", final=True)
    except UnicodeDecodeError as exc:
        return f"line {line}, byte offset {start - (len(exc.object) - exc.start)}: {exc.reason}"
    return "invalid byte sequence"
