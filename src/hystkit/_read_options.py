"""How to read a user's own recording file: column names, time unit, skipped lines, separator.

Pure Python on purpose: the CLI validates its options with this module while building the
parser, which must not load numpy or pandas (``tests/cli/test_startup_imports.py``).
Re-exported as `hystkit.io.ReadOptions`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["DEFAULT_OPTIONS", "FIELDS", "MAX_SKIP_ROWS", "SEPARATORS", "TIME_UNITS", "ReadOptions", "parse_columns"]

FIELDS = ("time", "position", "sensor")  # hystkit's names, as io._cells.COLUMNS
# Seconds per unit. s/ms/us/ns are the names raw files use (io._raw_config); min for slow logs.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0}
# Accepted spellings -> the separator itself; "auto" looks at the header line.
SEPARATORS = {",": ",", ";": ";", "tab": "\t", "\t": "\t", "\\t": "\t", "auto": "auto"}
# CSV lines skipped after the header (a units line or a few): pandas holds them as a set.
MAX_SKIP_ROWS = 1_000_000


@dataclass(frozen=True)
class ReadOptions:
    """How to find a recording in a file whose columns are not named time, position, sensor.

    Parameters
    ----------
    columns : mapping or tuple of (str, str)
        hystkit name (``time``, ``position``, ``sensor``) -> the file's column name (for
        ``.mat`` files: the variable name). Names not given keep hystkit's name. Stored as a
        tuple of pairs in hystkit's order, so the object is hashable.
    time_unit : {"s", "ms", "us", "ns", "min"}
        Unit of the time column; converted to seconds on reading.
    skip_rows : int
        CSV only: lines to skip *after* the header row, e.g. 1 for a units line such as
        ``s,mm,Ohm`` (the same meaning as ``skip_rows`` of raw files). The header must be the
        first line of the file.
    sep : {",", ";", "tab", "auto"}
        CSV only: field separator; ``auto`` takes the most frequent of the three in the
        header line (a comma when none occurs). Stored as the character itself.

    Raises
    ------
    ValueError
        One line naming the setting: unknown hystkit name, empty column name, two hystkit
        names read from the same file column, unknown unit or separator, skip_rows outside
        [0, `MAX_SKIP_ROWS`].

    Notes
    -----
    The defaults read files exactly as `read_recording` always did. Files hystkit writes keep
    its standard column names (time [s], position, sensor) whatever was read.
    """

    columns: tuple[tuple[str, str], ...] = ()
    time_unit: str = "s"
    skip_rows: int = 0
    sep: str = ","

    def __post_init__(self) -> None:
        pairs = self.columns.items() if isinstance(self.columns, Mapping) else self.columns
        try:
            pairs = [(str(k), v) for k, v in pairs]
        except (TypeError, ValueError):
            raise ValueError(f"columns must map time/position/sensor to column names, got "
                             f"{self.columns!r}") from None
        given = dict(pairs)
        if len(given) != len(pairs):
            raise ValueError("columns: a hystkit name is given twice")
        for key, name in pairs:
            if key not in FIELDS:
                raise ValueError(f"columns: unknown name {key!r}; use {', '.join(FIELDS)}")
            if not isinstance(name, str) or not name.strip():
                raise ValueError(f"columns: {key} needs a column name, got {name!r}")
        resolved = {field: given.get(field, field) for field in FIELDS}
        for i, field in enumerate(FIELDS):
            for other in FIELDS[i + 1:]:
                if resolved[field] == resolved[other]:
                    raise ValueError(f"columns: {field} and {other} would both be read from "
                                     f"column {resolved[field]!r}")
        object.__setattr__(self, "columns",
                           tuple((f, given[f]) for f in FIELDS if f in given and given[f] != f))
        if self.time_unit not in TIME_UNITS:
            raise ValueError(f"time_unit must be one of {', '.join(TIME_UNITS)}, got "
                             f"{self.time_unit!r}")
        if (isinstance(self.skip_rows, bool) or not isinstance(self.skip_rows, int)
                or not 0 <= self.skip_rows <= MAX_SKIP_ROWS):
            raise ValueError(f"skip_rows must be a whole number in [0, {MAX_SKIP_ROWS}], got "
                             f"{self.skip_rows!r}")
        if self.sep not in SEPARATORS:
            raise ValueError(f"sep must be one of ',', ';', 'tab', 'auto', got {self.sep!r}")
        object.__setattr__(self, "sep", SEPARATORS[self.sep])

    def name(self, field: str) -> str:
        """The file's name for hystkit column `field`."""
        return dict(self.columns).get(field, field)

    @property
    def time_scale(self) -> float:
        """Seconds per unit of the time column."""
        return TIME_UNITS[self.time_unit]


def parse_columns(text: str) -> tuple[tuple[str, str], ...]:
    """Parse ``time=t,position=displacement_mm,sensor=resistance_ohm`` into checked pairs.

    Column names are taken as written between ``=`` and the next comma, without surrounding
    spaces (so a name containing a comma cannot be given this way; use `ReadOptions`).

    Raises
    ------
    ValueError
        One line: an entry without ``=``, an empty side, or whatever `ReadOptions` refuses.
    """
    pairs = []
    for entry in text.split(","):
        key, eq, name = entry.partition("=")
        if not eq or not key.strip() or not name.strip():
            raise ValueError(f"expected NAME=COLUMN entries separated by commas, e.g. "
                             f"time=t,position=displacement_mm; got {entry.strip()!r}")
        pairs.append((key.strip(), name.strip()))
    keys = [k for k, _ in pairs]
    for key in keys:
        if keys.count(key) > 1:
            raise ValueError(f"{key} is given {keys.count(key)} times")
    return ReadOptions(columns=tuple(pairs)).columns


DEFAULT_OPTIONS = ReadOptions()
"""Columns ``time``, ``position``, ``sensor``; seconds; commas; the header on line 1."""
