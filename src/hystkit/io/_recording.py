"""Recordings (time, position, sensor) read from and written to CSV, Parquet and MATLAB files.

Every problem with an input file becomes one `InputError` whose message names the file,
the column and the row, so the CLI can print it verbatim.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from hystkit._read_options import ReadOptions
from hystkit.errors import InputError

from ._cells import COLUMNS as _COLUMNS  # also imported by _writing
from ._cells import Where as _Where
from ._cells import as_vector
from ._csv_reader import read_csv
from ._mat_reader import read_mat
from ._missing import fill_missing
from ._resample import MAX_GAP_STEPS, resample_arrays, time_gaps
from ._time_column import check_time_name, check_time_unit, time_step_warning

if TYPE_CHECKING:
    import pandas as pd

_MAX_STEP_DEVIATION = 0.01  # relative to the median step; beyond this we ask for resampling
MAX_MAGNITUDE = 1e100
"""Largest |value| accepted in a recording. Finite values near the float64 limit (1.7e308)
overflow in the first sum or square (metrics, scaling, JSON); 1e100 leaves 200 decades of
headroom for products and powers and is far beyond any physical time, position or ΔR/R."""


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
    units : mapping or tuple of (str, str)
        Units of the file's columns as read from it (``{"position": "mm", "sensor":
        "Ohm"}``), for labels and outputs; hystkit's own computations do not use them (time
        is always in seconds once read). Stored as a tuple of pairs.

    Notes
    -----
    The arrays are stored as read-only float64 copies, so a recording cannot change after
    it was validated. Invalid data raise `InputError`.
    """

    time: np.ndarray
    sensor: np.ndarray
    position: np.ndarray | None = None
    source: str = "<memory>"
    units: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "units", _unit_pairs(self.units))
        where = _Where(self.source, item="sample")
        arrays = {
            name: as_vector(getattr(self, name), name, where)
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

    def unit(self, name: str) -> str:
        """The unit of column `name` as the file gave it, or "" when unknown."""
        return dict(self.units).get(name, "")

    def to_frame(self) -> pd.DataFrame:
        """The recording as a DataFrame with columns ``time`` [s], ``position`` (when present)
        and ``sensor``; ``attrs`` keeps ``source`` and ``units``.

        Examples
        --------
        >>> from hystkit.io import Recording
        >>> rec = Recording(time=[0.0, 0.1, 0.2], sensor=[1.0, 2.0, 3.0], position=[0, 1, 2])
        >>> rec.to_frame()
           time  position  sensor
        0   0.0       0.0     1.0
        1   0.1       1.0     2.0
        2   0.2       2.0     3.0
        """
        import pandas as pd  # here: reading a CSV needs no pandas (about 1 s to import)

        frame = pd.DataFrame({name: getattr(self, name) for name in _COLUMNS
                              if getattr(self, name) is not None})
        frame.attrs.update(source=self.source, units=dict(self.units))
        return frame

    @classmethod
    def from_frame(cls, frame: pd.DataFrame, *, columns: Mapping[str, str] | None = None,
                   time_unit: str = "s", source: str = "<DataFrame>") -> Recording:
        """A validated recording from a DataFrame's columns.

        Parameters
        ----------
        frame : pandas.DataFrame
            Columns ``time``, ``sensor`` and, optionally, ``position`` (other columns are
            ignored); other names through `columns`.
        columns : mapping, optional
            hystkit name (``time``, ``position``, ``sensor``) -> the frame's column, as for
            files (`ReadOptions`).
        time_unit : {"s", "ms", "us", "ns", "min"}
            Unit of the time column, converted to seconds.
        source : str
            Name used in error messages.

        Raises
        ------
        InputError
            A missing time or sensor column, or data a `Recording` refuses (message names the
            column and the row).

        Examples
        --------
        >>> import pandas as pd
        >>> frame = pd.DataFrame({"t_ms": [0, 10, 20], "x_mm": [0.0, 0.5, 1.0],
        ...                       "r": [0.1, 0.2, 0.3]})
        >>> rec = Recording.from_frame(frame, columns={"time": "t_ms", "position": "x_mm",
        ...                                            "sensor": "r"}, time_unit="ms")
        >>> rec.dt
        0.01
        """
        options = ReadOptions(columns=columns or (), time_unit=time_unit)
        arrays = {}
        for name in _COLUMNS:
            column = options.name(name)
            if column in frame.columns:
                arrays[name] = _numbers(frame[column], f"{source}: column {column!r} ({name})")
            elif name != "position":
                raise InputError(f"{source}: missing column {column!r} ({name}); columns: "
                                 f"{', '.join(map(str, frame.columns))}")
        arrays["time"] = arrays["time"] * options.time_scale
        return cls(**arrays, source=source, units=frame.attrs.get("units", ()))


def _numbers(values: pd.Series, what: str) -> np.ndarray:
    """A DataFrame column as float64; InputError naming the first row that is not a number."""
    import pandas as pd  # here: as in to_frame

    numbers = pd.to_numeric(values, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
    bad = np.flatnonzero(np.isnan(numbers) & values.notna().to_numpy())
    if bad.size:
        raise InputError(f"{what}, sample {bad[0] + 1}: not a number: {values.iloc[bad[0]]!r}")
    return numbers


def _unit_pairs(units: object) -> tuple[tuple[str, str], ...]:
    pairs = units.items() if isinstance(units, Mapping) else units
    try:
        return tuple((str(name), str(unit)) for name, unit in pairs if str(unit).strip())
    except (TypeError, ValueError):
        raise ValueError(f"units must map column names to unit text, got {units!r}") from None


def read_recording(path: str | os.PathLike[str], *, need_position: bool = True,
                   options: ReadOptions | None = None) -> Recording:
    """Read and validate a recording from a ``.csv``, ``.parquet`` or ``.mat`` file.

    Parameters
    ----------
    path : str or path-like
        CSV files need a header row naming the columns; MATLAB files need variables
        named like the columns (row or column vectors). Other columns are ignored.
    need_position : bool
        Require a ``position`` column. If False it is still read when present.
    options : ReadOptions, optional
        The file's own column (or variable) names, time unit, for CSV the separator, the
        lines after the header to skip and a units line, for ``.mat`` the variable, and a
        rate to resample to (`hystkit.io._resample`: linear interpolation, a zero-phase
        anti-alias low-pass when decimating, gaps refused). Default: columns named ``time``, ``position``,
        ``sensor``, time in seconds, comma-separated, the header on the first line.

    Returns
    -------
    Recording
        Columns ``time`` [s], ``sensor`` [-] and, if present, ``position`` [mm].

    Raises
    ------
    InputError
        Unknown suffix, a ``mat_var`` for a file that is not ``.mat``, missing or empty file,
        damaged file (MATLAB files are parsed in a
        child process, so even a crash of the parser ends here), missing column, non-numeric,
        empty or non-finite cell, magnitude above `MAX_MAGNITUDE`, unequal lengths, time not strictly increasing, non-uniform
        sampling, fewer than 2 samples. The message names file, column and row.
    """
    options = ReadOptions() if options is None else options
    arrays, where, units = read_unvalidated(Path(path), need_position, options)
    if options.resample_hz is not None or options.gaps == "split":
        _validate(arrays, where, uniform=False)
    if options.gaps == "split":
        _refuse_pieces(arrays["time"], where)
    if options.resample_hz is not None:
        arrays = resample_arrays(arrays, options.resample_hz, where)
    _validate(arrays, where)
    # time is in seconds once read, whatever the file's unit
    return _adopt(arrays, str(path), tuple((k, v) for k, v in units.items()
                                           if k in ("position", "sensor")))


def _refuse_pieces(time: np.ndarray, where: _Where) -> None:
    """``gaps = "split"`` where one recording is read: a file with gaps is refused (its
    pieces are for commands that fit several recordings jointly, `read_pieces`)."""

    gaps = time_gaps(time)
    if gaps.size:
        raise where.fail(f"--gaps split cuts this recording at {gaps.size} time gap"
                         f"{'s' * (gaps.size > 1)} into {gaps.size + 1} pieces, and this "
                         "command reads it as one recording (split the file there)", "time",
                         int(gaps[0]) + 1)


def read_unvalidated(path: Path, need_position: bool, options: ReadOptions, *,
                     notices: bool = True,
                     ) -> tuple[dict[str, np.ndarray], _Where, dict[str, str]]:
    """The recording's arrays as the file holds them, time in seconds, not resampled nor
    checked; the error locator; the units (the file's own first). `notices`: say on stderr
    what the reading suggests (a time step that looks like another unit); False for a
    second read of the same file."""
    source = str(path)
    suffix = path.suffix.lower()
    if suffix not in _READERS:
        raise InputError(
            f"{source}: unsupported file type {suffix or '(no suffix)'!r}; "
            f"accepted: {', '.join(_READERS)}"
        )
    if options.mat_var is not None and suffix != ".mat":
        # Ignoring it would read the file as if the option were right.
        raise InputError(f"{source}: --mat-var {options.mat_var} names a variable of a .mat "
                         f"file, and this is a {suffix} file (drop --mat-var, or give it in "
                         "the settings file of the .mat recording)")
    if not path.exists():
        raise InputError(f"{source}: file not found")
    if not path.is_file():
        raise InputError(f"{source}: not a regular file")
    if path.stat().st_size == 0:
        raise InputError(f"{source}: file is empty (0 bytes)")
    try:
        with path.open("rb"):  # permissions, a FIFO's or a device's refusal: before any parser
            pass
        arrays, where = _READERS[suffix](path, source, need_position, options)
    except OSError as exc:  # also a disk failing halfway (EIO)
        raise InputError(f"{source}: cannot read the file ({exc.strerror or exc})") from exc
    units = {**dict(options.units), **dict(where.units)}  # the file's own units first
    check_time_unit(units.get("time"), options, where)
    check_time_name(dict(options.columns).get("time", "time"), options, where)
    if options.time_scale != 1.0:  # to seconds before the checks, whose messages say "s"
        arrays["time"] = arrays["time"] * options.time_scale
    arrays, where, notice = fill_missing(arrays, where, options.missing)
    if notices and notice:
        say(notice)
    if notices and (warning := time_step_warning(arrays["time"], options, where)):
        say(f"warning: {warning}")
    return arrays, where, units


def say(line: str) -> None:
    """Tell the user what reading a file did or suggests, on stderr (a command's stdout may
    carry its product: ``stream``'s estimates, ``datasets list``)."""
    print(f"hystkit: {line}", file=sys.stderr, flush=True)


def _adopt(arrays: dict[str, np.ndarray], source: str,
           units: tuple[tuple[str, str], ...] = ()) -> Recording:
    """A `Recording` around 1-D float64 arrays a reader made and `_validate` checked.

    ``Recording(...)`` would copy and check them again; nothing else holds these arrays, so
    adopting them saves a copy of the data at the peak (and a second pass over it).
    """
    recording = object.__new__(Recording)
    for name in _COLUMNS:
        values = arrays.get(name)
        if values is not None:
            values = np.ascontiguousarray(values, dtype=np.float64)  # no copy for readers' output
            values.setflags(write=False)
        object.__setattr__(recording, name, values)
    object.__setattr__(recording, "source", source)
    object.__setattr__(recording, "units", _unit_pairs(units))
    return recording


def _read_parquet(*args: object) -> tuple[dict[str, np.ndarray], _Where]:
    from ._parquet_reader import read_parquet  # here: pyarrow loads only for Parquet files

    return read_parquet(*args)


_READERS = {".csv": read_csv, ".parquet": _read_parquet, ".mat": read_mat}


def _validate(arrays: dict[str, np.ndarray], where: _Where, *, uniform: bool = True) -> None:
    """Check 1-D float arrays (``time`` among them) for the invariants of a `Recording`
    (`uniform`: including the uniform sampling, which resampling establishes)."""
    lengths = {name: values.size for name, values in arrays.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{name} {n}" for name, n in lengths.items())
        raise where.fail(f"{where.noun}s have different lengths: {listed}")
    for name, values in arrays.items():
        bad = np.flatnonzero(~(np.abs(values) <= MAX_MAGNITUDE))  # NaN, inf and huge at once
        if bad.size:
            i = int(bad[0])
            value = values[i]
            if np.isnan(value):
                problem = "missing or NaN value"
            elif np.isinf(value):
                problem = f"infinite value {value}"
            else:
                problem = (f"value {value:.6g} is too large; hystkit accepts magnitudes up to "
                           f"{MAX_MAGNITUDE:g}")
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
    if not uniform:
        return
    median = float(np.median(step))
    bad = np.flatnonzero(np.abs(step - median) > _MAX_STEP_DEVIATION * median)
    if bad.size:
        i = int(bad[0]) + 1

        fix = ("a time gap: split the recording there, or read the pieces between gaps "
               "with --gaps split to fit them jointly" if step[i - 1] > MAX_GAP_STEPS * median else
               "resample it to a uniform time grid (--resample HZ)")
        raise where.fail(f"non-uniform sampling: step {step[i - 1]:.6g} s deviates more than "
                         f"{_MAX_STEP_DEVIATION:.0%} from the median step {median:.6g} s; "
                         f"{fix}", "time", i)
