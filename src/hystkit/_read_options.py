"""How to read a user's own recording file: column names, time unit, skipped lines, separator.

Pure Python on purpose: the CLI validates its options with this module while building the
parser, which must not load numpy or pandas (``tests/cli/test_startup_imports.py``).
Re-exported as `hystkit.io.ReadOptions`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["DECIMALS", "DEFAULT_OPTIONS", "FIELDS", "GAPS", "MAX_RESAMPLE_HZ", "MAX_SKIP_ROWS",
           "MISSING", "SEPARATORS", "TIME_UNITS", "ReadOptions", "parse_columns"]

FIELDS = ("time", "position", "sensor")  # hystkit's names, as io._cells.COLUMNS
# Seconds per unit. s/ms/us/ns are the names raw files use (io._raw_config); min for slow logs.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0}
# Accepted spellings -> the separator itself; "auto" looks at the header and first data lines.
SEPARATORS = {",": ",", ";": ";", "tab": "\t", "\t": "\t", "\\t": "\t", "auto": "auto"}
# Decimal marks of CSV numbers; "auto" looks at the first data lines (a comma only where the
# separator is not one: Excel in most of Europe writes 1,5 between semicolons).
DECIMALS = (".", ",", "auto")
# What to do with a row whose time, position or sensor cell is empty (or NaN): refuse the file,
# drop the row, or interpolate it linearly in time (hystkit.io._missing)
MISSING = ("error", "drop", "interpolate")
# What to do with a recording whose time has gaps (steps far above the median step): refuse it
# naming the gap's row, or split it into pieces at the gaps (hystkit.io._pieces)
GAPS = ("error", "split")
# CSV lines skipped after the header (a units line or a few): pandas holds them as a set.
MAX_SKIP_ROWS = 1_000_000
MAX_RESAMPLE_HZ = 1e9  # as the raw files' fs_out
_MATLAB_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")


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
        ``s,mm,Ohm`` (the same meaning as ``skip_rows`` of raw files). The header is the
        first line of the file that is not a ``#`` comment (comment lines, and blank lines
        among them, before it are skipped).
    sep : {"auto", ",", ";", "tab"}
        CSV only: field separator; ``auto`` (the default) takes the one of the three that
        splits the header and the first data lines into the same number of fields (a file
        where two do is refused, naming the line and ``--sep``). Stored as the character
        itself.
    decimal : {"auto", ".", ","}
        CSV only: decimal mark of the numbers; ``auto`` (the default) reads ``1,5`` as 1.5 in
        a file that is not comma-separated when the first data lines write their numbers so
        (a file that mixes ``1,5`` and ``1.5`` there is refused, naming the lines).
    units_row : bool
        CSV only: the line after the header holds units (``s,mm,Ohm``); they are kept with
        the recording (`Recording.units`) and written to outputs. Lines skipped by
        `skip_rows` follow it.
    resample_hz : float, optional
        Bring the recording onto a uniform time grid at this rate [Hz] (for jittered or
        non-uniform time; method in `hystkit.io.resample_arrays`). None: the time must be
        uniform already.
    mat_var : str, optional
        ``.mat`` only: the variable holding the recording, a struct (fields named as
        `columns` says) or a matrix with samples as rows (`columns` then gives 1-based column
        numbers, ``time=1,position=2,sensor=3``). None: variables ``time``, ``position``,
        ``sensor`` (or as `columns` names them), else the file's only struct or matrix.
    units : mapping or tuple of (str, str)
        Units of the columns (``{"position": "mm", "sensor": "Ohm"}``; hystkit's names for
        its three, the file's names for other columns) for a file without a units row; a
        units row's entries take precedence. Only labels: values are not converted (the time
        unit is `time_unit`).
    missing : {"error", "drop", "interpolate"}
        A row whose time, position or sensor is empty (or NaN): ``error`` (the default)
        refuses the file naming the row; ``drop`` leaves the row out (its time steps become
        gaps); ``interpolate`` fills the cell linearly in time (a missing time by the row's
        place), dropping rows with nothing on one side (at the start or the end) and blank
        rows. Either says in one line how many rows it touched (`hystkit.io._missing`).
    gaps : {"error", "split"}
        A time step longer than 3 median steps: ``error`` (the default) refuses the file
        naming the gap's row; ``split`` makes the recording one piece per stretch between
        gaps, which commands that fit several recordings fit jointly
        (`hystkit.io.read_pieces`); a command that reads one recording refuses it.

    Raises
    ------
    ValueError
        One line naming the setting: unknown hystkit name, empty column name, two hystkit
        names read from the same file column, position and sensor read from each other's
        columns (``position=sensor,sensor=position``), unknown unit or separator, skip_rows
        outside [0, `MAX_SKIP_ROWS`].

    Notes
    -----
    The defaults read hystkit's own files and files as labs write them (``;`` or tab between
    fields, a decimal comma, comment lines before the header: `hystkit.io.csv_layout` says
    what it found). Files hystkit writes keep its standard column names (time [s],
    position, sensor) whatever was read.
    """

    columns: tuple[tuple[str, str], ...] = ()
    time_unit: str = "s"
    skip_rows: int = 0
    sep: str = "auto"
    units_row: bool = False
    resample_hz: float | None = None
    mat_var: str | None = None
    units: tuple[tuple[str, str], ...] = ()
    decimal: str = "auto"
    missing: str = "error"
    gaps: str = "error"

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
        _refuse_crossed(resolved)
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
        if self.decimal not in DECIMALS:
            raise ValueError(f"decimal must be one of '.', ',', 'auto', got {self.decimal!r}")
        if self.missing not in MISSING:
            raise ValueError(f"missing must be one of {', '.join(MISSING)}, got "
                             f"{self.missing!r}")
        if self.gaps not in GAPS:
            raise ValueError(f"gaps must be one of {', '.join(GAPS)}, got {self.gaps!r}")
        if not isinstance(self.units_row, bool):
            # ValueError like every bad setting: callers catch one type
            raise ValueError(f"units_row must be true or false, got {self.units_row!r}")  # noqa: TRY004
        if self.resample_hz is not None:
            rate = self.resample_hz
            if (isinstance(rate, bool) or not isinstance(rate, int | float)
                    or not math.isfinite(rate) or not 0 < rate <= MAX_RESAMPLE_HZ):
                raise ValueError(f"resample rate must be a number in (0, {MAX_RESAMPLE_HZ:g}] "
                                 f"Hz, got {rate!r}")
            object.__setattr__(self, "resample_hz", float(rate))
        units = self.units.items() if isinstance(self.units, Mapping) else self.units
        try:
            units = tuple((str(k), v) for k, v in units)
        except (TypeError, ValueError):
            raise ValueError(f"units must map column names to unit text, got "
                             f"{self.units!r}") from None
        for key, unit in units:
            if not key.strip() or not isinstance(unit, str) or not unit.strip():
                raise ValueError(f"units: {key!r} = {unit!r}; give unit text for a column")
        object.__setattr__(self, "units", units)
        if self.mat_var is not None and (not isinstance(self.mat_var, str)
                                         or not _MATLAB_NAME.fullmatch(self.mat_var)):
            raise ValueError(f"mat_var must be a MATLAB variable name (a letter, then letters, "
                             f"digits or _), got {self.mat_var!r}")

    def name(self, field: str) -> str:
        """The file's name for hystkit column `field`."""
        return dict(self.columns).get(field, field)

    @property
    def time_scale(self) -> float:
        """Seconds per unit of the time column."""
        return TIME_UNITS[self.time_unit]


def _refuse_crossed(resolved: dict[str, str]) -> None:
    """A file that names its columns ``position`` and ``sensor``, read the other way round
    (``--columns position=sensor,sensor=position``), is refused: a monotone sensor makes the
    swapped fit as good as the right one, so nothing downstream would notice (issue 24).

    Only the full cross is refused: a lab may call its reference instrument "sensor", but a
    file holding both names means hystkit's. Modelling the sensor from the position has its
    own route (``--mode inverse``), and a forward model (position = the system's output) is
    a file laid out that way (``hystkit datasets export --role forward``).
    """
    position, sensor = (resolved[f].strip().casefold() for f in ("position", "sensor"))
    if (position, sensor) == ("sensor", "position"):
        raise ValueError(f"columns: position would be read from column {resolved['position']!r} "
                         f"and sensor from column {resolved['sensor']!r}, the file's columns "
                         f"crossed (a compensator estimates the position from the sensor; "
                         f"--mode inverse models the sensor from the position; to fit the "
                         f"other way on purpose, rename the file's columns)")


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
"""Columns ``time``, ``position``, ``sensor``; seconds; separator and decimal mark detected;
the header on the first line that is not a comment."""
