"""``hystkit stream``'s input read as ``fit`` reads a file: the same reading options.

``stream`` parses ``time,sensor[,reference]`` lines. A user's file has its own layout: another
separator, a decimal comma, ``#`` comment lines, a units line, its own column names, time in
ms; ``--in FILE`` also has a settings file beside it (``my.toml``). Here each input line is
rewritten into ``stream``'s own form before it is parsed (one line out per line in, so line
numbers stay the file's): comment, units and skipped lines become blank lines, the header
becomes ``time,sensor[,reference]``, a data line its time (in the input's unit, which the
parser converts: `StreamFormat.time_scale`), sensor and reference with decimal points (blank
lines stay blank). Anything that does not fit (a missing field, text) stays recognisably bad,
so ``stream`` counts and skips it as before. Without any of this (a plain ``time,sensor`` input
and no option), the lines pass through untouched.

In a file (``--in``), a first line that is neither numbers nor a header naming the time and
sensor columns as the options say is refused at once, with the fix (``--columns``), instead
of every line being skipped; a live input may start mid-line, so there it is only skipped.

The output keeps the input's names as ``compensate`` does (`output_header`): the time column
under the input's name and unit (echoed as received), the estimate and band named after the
position column (``x_mm_estimate``, ...). A model that remembers how its training files were
read (their ``reading``) reads stdin and a serial port that way too unless ``--columns`` or
``--time-unit`` say otherwise (`reading_options`): a live input cannot be looked at before the
output's header is written.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass, replace
from pathlib import Path

from .._read_options import FIELDS
from ..errors import InputError
from ..io import ReadOptions, csv_layout, options_for, settings_for
from ._own_layout import estimate_names, remembered_options
from ._stream_options import StreamOptions
from ._stream_read import lines_of

__all__ = ["Rewriter", "StreamFormat", "nothing_compensated", "output_header",
           "reading_options", "stream_format"]

_NUMBER = re.compile(r"\s*[+-]?(\d+[.,]?\d*|[.,]\d+)([eE][+-]?\d+)?\s*")


@dataclass(frozen=True)
class StreamFormat:
    """How the input lines of a stream are written.

    Parameters
    ----------
    sep, decimal : str
        Field separator and decimal mark.
    time, sensor : str
        The input's names of the time and sensor columns (a header naming them is looked for,
        ignoring case; ``reference`` is the reference's name).
    time_scale : float
        Seconds per unit of the time column.
    after_header : int
        Lines after the header that hold no data (a units line, skipped lines).
    check_header : bool
        Refuse a first line that is neither numbers nor a header naming the columns (a file:
        its header is there from the start; a live input may begin mid-line).
    comment_header : int
        The line (from 1) of a header written as a comment (``# time,position,sensor``, as
        ``numpy.savetxt`` writes it, `hystkit.io.CsvLayout`); 0: none.
    position : str
        The input's name of the position column (the output names its estimate after it).
    """

    sep: str = ","
    decimal: str = "."
    time: str = "time"
    sensor: str = "sensor"
    time_scale: float = 1.0
    after_header: int = 0
    check_header: bool = False
    comment_header: int = 0
    position: str = "position"

    @property
    def plain(self) -> bool:
        """Whether lines need no rewriting (``stream``'s own form; the names of the output
        play no part)."""
        return replace(self, position="position", time_scale=1.0) == StreamFormat()


def stream_format(path: Path | None, given: dict) -> StreamFormat:
    """The format of the stream's input read with the reading options `given`
    (`hystkit.io.ReadOptions` keyword arguments): for ``--in FILE`` (`path`), its settings
    file (``my.toml``), then `given`, then what `hystkit.io.csv_layout` detects; for stdin and
    a serial port (`path` None), `given` (a comma and decimal points unless given). What was
    applied or detected is said on stderr (stdout carries the estimates).

    Raises
    ------
    InputError
        ``--resample`` or ``--mat-var`` (a stream takes samples as they come), or a settings
        file or layout that `hystkit.io` refuses.
    """
    refused = [option for option, key in (("--resample", "resample_hz"), ("--mat-var", "mat_var"))
               if key in given]
    missing = given.get("missing") == "interpolate"
    refused += ["--missing interpolate"] if missing else []
    if refused:
        raise InputError(f"{', '.join(refused)}: stream compensates the "
                         "samples of a text input as they come (resample the file, or read "
                         "it with compensate)" + ("; a line missing a value is skipped and "
                                                  "counted" if missing else ""))
    if path is None:
        try:
            options = ReadOptions(**given)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        sep = "," if options.sep == "auto" else options.sep
        decimal = "." if options.decimal == "auto" else options.decimal
        return _format(options, sep, decimal)
    path = Path(path)
    options, settings = options_for(path, given)
    note = settings_for(path)[1] if settings is None else ""
    if settings is not None:
        _say(f"reading {path} with the settings in {settings}")
    elif note:
        _say(f"reading {path} without its settings: {note}")
    if options.resample_hz is not None:
        _say(f"{settings}: resample_hz is not applied: stream compensates the samples as they "
             "come and counts irregular steps")
    if options.missing == "interpolate":
        _say(f"{settings}: missing = \"interpolate\" is not applied: stream skips a line "
             "missing a value and counts it")
    if not path.is_file():
        return _format(options, ",", ".")  # stream's own reading names the problem
    layout = csv_layout(path, options)
    if notice := layout.notice():
        _say(f"reading {path}: {notice}")
    return _format(options, layout.sep, layout.decimal, check_header=True,
                   comment_header=layout.preamble + 1 if layout.comment_header else 0)


def _format(options, sep: str, decimal: str, check_header: bool = False,
            comment_header: int = 0) -> StreamFormat:
    return StreamFormat(sep, decimal, options.name("time"), options.name("sensor"),
                        options.time_scale, options.units_row + options.skip_rows, check_header,
                        comment_header, options.name("position"))


def output_header(fmt: StreamFormat, banded: bool) -> str:
    """The output's header line: ``time,position_estimate,flags`` (and the band's
    ``position_lower,position_upper``) in the input's names, as ``compensate`` names them
    (`hystkit.cli._own_layout.estimate_names`)."""
    new = estimate_names({"position": fmt.position})
    band = f",{new['position_lower']},{new['position_upper']}" if banded else ""
    return f"{fmt.time},{new['position_estimate']},flags{band}\n"


def reading_options(options: StreamOptions, reading: ReadOptions | None) -> dict:
    """The reading options to read the input with (`hystkit.io.ReadOptions` keyword
    arguments): those given on the command line, and how the model's training files were
    read (`reading`) where that applies, as if given, said on stderr. ``--in FILE``: when the
    file has the training files' column names (`hystkit.cli._own_layout.remembered_options`);
    stdin or a serial port: their columns and time unit unless ``--columns`` or
    ``--time-unit`` is given, no units line (a live input has none to look for)."""
    given = options.given
    if options.input is not None:
        return _file_as_trained(Path(options.input), given, reading)
    if reading is None or not (reading.columns or reading.time_unit != "s"):
        return given
    if "columns" in given or "time_unit" in given:
        return given
    parts = [f"columns {','.join(reading.name(field) for field in FIELDS)}"] \
        if reading.columns else []
    parts.append(f"time in {reading.time_unit}")
    _say(f"reading {options.source} as the model's training data were read: "
         f"{', '.join(parts)} (--columns and --time-unit read it otherwise)")
    return _as_given(given, columns=reading.columns, time_unit=reading.time_unit)


def _file_as_trained(path: Path, given: dict, reading: ReadOptions | None) -> dict:
    """`given` with the model's reading of the file `path`, when it applies."""
    if not path.is_file():
        return given
    found = remembered_options(given, path, reading)
    if found is None:
        return given
    remembered, line = found
    _say(line)
    return _as_given(given, columns=remembered.columns, time_unit=remembered.time_unit,
                     units_row=remembered.units_row)


def _as_given(given: dict, **values) -> dict:
    """`given` with `values` set as if given on the command line (an option left at its
    default is no given option: `hystkit.cli._read_args.given_read_options`)."""
    return {k: v for k, v in {**given, **values}.items() if v not in (None, (), False)}


def _say(line: str) -> None:
    print(f"hystkit stream: {line}", file=sys.stderr, flush=True)


class Rewriter:
    """Input lines rewritten one by one into ``time,sensor[,reference]`` lines as `fmt`
    says (see the module); `too_long` (stream's marker of an overlong line) passes through.

    Parameters
    ----------
    fmt : StreamFormat
        How the input is written.
    source : str
        Names the input in errors.
    too_long : str
        The marker, passed through as it is.
    """

    def __init__(self, fmt: StreamFormat, source: str, too_long: str) -> None:
        self.fmt, self.source, self.too_long = fmt, source, too_long
        self.columns: tuple[int, int, int | None] | None = None
        self.skip = 0
        self.line_no = 0
        # once the header is behind: lines already in stream's form (a comma, decimal points,
        # time and sensor first) pass as they are, since stream's parser reads them alike
        self.same = False

    def chunk(self, text: str) -> str:
        """A chunk of lines (:mod:`._stream_read`) rewritten, in order: the header decides
        how; once lines pass as they are, the rest of the chunk passes whole."""
        if self.same:
            return text
        if text is self.too_long:
            return self(text)
        lines = lines_of(text)
        done: list[str] = []
        for k, line in enumerate(lines):
            if self.same:
                return "".join(done + lines[k:])
            done.append(self(line))
        return "".join(done)

    def __call__(self, line: str) -> str:
        self.line_no += 1
        if line is self.too_long:
            return line
        fmt = self.fmt
        end = "\n" if line.endswith("\n") else ""
        text = line.rstrip("\r\n")
        if self.columns is None:
            text = text.lstrip("\ufeff")  # a UTF-8 BOM first
            if self.line_no == fmt.comment_header:
                text = text.lstrip().lstrip("#")  # the header, written as a comment
            elif not text.strip() or text.lstrip().startswith("#"):
                return end  # blank and comment lines before the header
            fields = _split(text, fmt.sep)
            self.columns = _header(fields, fmt)
            if self.columns is not None:
                self.skip = fmt.after_header
                return ("time,sensor,reference" if self.columns[2] is not None
                        else "time,sensor") + end
            if fmt.check_header and not any(_NUMBER.fullmatch(f) for f in fields[:2]):
                raise InputError(_no_header(self.source, self.line_no, fields, fmt))
            self.columns = (0, 1, 2)  # no header: time, sensor, reference in this order
        if self.skip:
            self.skip -= 1
            return end
        self.same = (fmt.sep, fmt.decimal) == (",", ".") and self.columns[:2] == (0, 1) \
            and self.columns[2] in (None, 2)
        return _rewrite(text, fmt, self.columns) + end if text.strip() else line


def nothing_compensated(source: str, count: dict[str, int], first: dict[str, int]) -> str:
    """The error of a stream that ended without compensating a sample: the first line skipped
    and why (`count`, `first`: lines and first line number per kind of problem)."""
    if not count:
        return f"{source}: no sample compensated: the input held no data line"
    kind = min(first, key=first.__getitem__)
    return (f"{source}: no sample compensated: every one of {sum(count.values())} line(s) was "
            f"skipped, the first at line {first[kind]}: {kind} (is the input laid out as the "
            "options say? --sep, --columns, --time-unit)")


def _split(text: str, sep: str) -> list[str]:
    return [f.strip() for f in text.split(sep)]


def _header(fields: list[str], fmt: StreamFormat) -> tuple[int, int, int | None] | None:
    names = [f.lstrip("\ufeff").strip().lower() for f in fields]
    time, sensor = fmt.time.lower(), fmt.sensor.lower()
    if time in names and sensor in names:
        return names.index(time), names.index(sensor), (
            names.index("reference") if "reference" in names else None)
    return None


def _no_header(source: str, line_no: int, fields: list[str], fmt: StreamFormat) -> str:
    shown = ", ".join(repr(f) for f in fields[:8]) + (", ..." if len(fields) > 8 else "")
    return (f"{source}: line {line_no}: a header without the columns {fmt.time!r} (time) and "
            f"{fmt.sensor!r} (sensor); found {shown}: name them with --columns time=NAME,"
            "sensor=NAME (or in the settings file), or check --sep")


def _rewrite(text: str, fmt: StreamFormat, columns: tuple[int, int, int | None]) -> str:
    """One data line as ``time,sensor[,reference]``, time in its own unit; a field it lacks
    stays empty (stream counts the line as missing a field), text stays text (not a
    number)."""
    fields = _split(text, fmt.sep)
    picked = [fields[j] if j is not None and j < len(fields) else "" for j in columns]
    if fmt.decimal == ",":
        picked = [f if "." in f else f.replace(",", ".") for f in picked]
    elif fmt.sep != ",":
        picked = [f.replace(",", ";") for f in picked]  # a stray comma is no separator here
    return ",".join(picked if picked[2] else picked[:2])
