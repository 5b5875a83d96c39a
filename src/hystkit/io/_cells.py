"""What every recording reader shares: error locations, column picking, text and array checks."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from hystkit.errors import InputError

if TYPE_CHECKING:  # pandas loads with the first text cell: a clean CSV never needs it
    import pandas as pd

COLUMNS = ("time", "position", "sensor")  # also the column order of written files
_SHOWN_CHARS = 40  # of a bad cell in a message: a 10 MB field must not become a 10 MB line


@dataclass(frozen=True)
class Where:
    """Turns a column name and a 0-based sample index into a location for an error message."""

    source: str
    noun: str = "column"
    item: str = "row"
    header_lines: int | None = None  # CSV only: data row r sits on file line r + header_lines
    # (hystkit name, file name) of columns named differently in the file (ReadOptions.columns)
    names: tuple[tuple[str, str], ...] = ()
    # (hystkit name, unit) the file itself states (a CSV units row, Parquet metadata, .mat units)
    units: tuple[tuple[str, str], ...] = ()
    # The file's row of each sample once rows were dropped (ReadOptions.missing); None: the same
    rows: np.ndarray | None = field(default=None, compare=False, repr=False)

    def name(self, column: str) -> str:
        """The file's name for hystkit column `column`."""
        return dict(self.names).get(column, column)

    def label(self, column: str) -> str:
        """``'time'``, or ``'t_ms' (time)`` when the file names it differently: the user
        must recognise the column of their own file."""
        name = self.name(column)
        return repr(name) if name == column else f"{name!r} ({column})"

    def at(self, index: int) -> str:
        """``'row 5 (line 6)'`` for sample `index` (0-based; the file's row when rows were
        dropped), ``'sample 5'`` where there are no lines."""
        if self.rows is not None and 0 <= index < self.rows.size:
            index = int(self.rows[index])
        text = f"{self.item} {index + 1}"
        if self.header_lines is not None:
            text += f" (line {index + 1 + self.header_lines})"
        return text

    def fail(self, message: str, column: str | None = None, index: int | None = None) -> InputError:
        parts = [] if column is None else [f"{self.noun} {self.label(column)}"]
        if index is not None:
            parts.append(self.at(index))
        location = f"{', '.join(parts)}: " if parts else ""
        return InputError(f"{self.source}: {location}{message}")


def pick(found: list[str], need_position: bool, where: Where, hint: str = "") -> list[str]:
    """Hystkit names of the recording columns present in `found` (the file's names, looked up
    through ``where.name``); missing or doubled ones fail."""
    required = [n for n in COLUMNS if need_position or n != "position"]
    missing = [n for n in required if where.name(n) not in found]
    if missing:
        listed = ", ".join(repr(n) for n in found) or "none"
        raise where.fail(f"missing required {where.noun} {', '.join(map(where.label, missing))}"
                         f"; {where.noun}s found: {listed}{hint}")
    for name in COLUMNS:
        if found.count(where.name(name)) > 1:
            raise where.fail(f"appears {found.count(where.name(name))} times in the header", name)
    return [n for n in COLUMNS if where.name(n) in found]


def text_problems(text: pd.Series, decimal: str = ".") -> tuple[np.ndarray, np.ndarray,
                                                                 pd.Series]:
    """Parse text cells to float64 without failing; `decimal`: the numbers' decimal mark
    (``,``: ``1,5`` is 1.5 and ``1.5`` is not a number).

    Returns
    -------
    numbers : ndarray of float64
        The values; NaN where a cell is empty or not a number (and for a literal ``nan``).
    bad : ndarray of bool
        Cells that are empty or not a number (a literal ``nan`` is a number here).
    stripped : Series of str
        The cells without surrounding whitespace, for the error message.
    """
    import pandas as pd  # here: a clean CSV never needs pandas (about 1 s to import)

    missing = text.isna().to_numpy()
    stripped = text.where(~missing, "").astype(str).str.strip()
    empty = missing | (stripped == "").to_numpy()
    cells = stripped
    if decimal == ",":  # a point is no number here; a comma is the point
        cells = stripped.where(~stripped.str.contains(".", regex=False), "x")
        cells = cells.str.replace(",", ".", regex=False)
    numbers = pd.to_numeric(cells.where(~empty), errors="coerce")
    # to_numeric also yields NaN for a literal 'nan'; that one is numeric, the checks report it.
    literal_nan = stripped.str.lower().str.lstrip("+-").eq("nan").to_numpy()
    bad = empty | (numbers.isna().to_numpy() & ~literal_nan)
    return numbers.to_numpy(dtype=np.float64, na_value=np.nan), bad, stripped


def cell_problem(stripped: pd.Series, i: int) -> str:
    """How to describe the bad cell `i` found by `text_problems`."""
    value = stripped.iloc[i]
    if value == "":
        return "empty cell"
    shown = repr(value) if len(value) <= _SHOWN_CHARS else f"{value[:_SHOWN_CHARS]!r}... " \
        f"({len(value)} characters)"
    return f"non-numeric value {shown}"


def parse_text(text: pd.Series, name: str, where: Where) -> np.ndarray:
    """Parse text cells (positional index) to float64, failing at the first empty or bad cell."""
    numbers, bad, stripped = text_problems(text)
    if bad.any():
        i = int(np.argmax(bad))
        raise where.fail(cell_problem(stripped, i), name, i)
    return numbers


def as_vector(values: Any, name: str, where: Where) -> np.ndarray:
    """Copy `values` to a 1-D float64 array; row and column vectors are accepted."""
    array = np.asarray(values)
    if array.dtype.kind not in "iuf":  # bool, complex, text and objects are not measurements
        raise where.fail(f"not real numbers (dtype {array.dtype})", name)
    array = np.atleast_1d(np.squeeze(array))
    if array.ndim != 1:
        raise where.fail(f"must be a row or column vector, got shape {np.shape(values)}", name)
    return array.astype(np.float64, copy=True)
