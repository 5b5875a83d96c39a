"""``hystkit stream``'s input read as ``fit`` reads a file: the same reading options.

``stream`` parses ``time,sensor[,reference]`` lines one at a time. A user's file has its own
layout: another separator, a decimal comma, ``#`` comment lines, a units line, its own column
names, time in ms; ``--in FILE`` also has a settings file beside it (``my.toml``). Here each
input line is rewritten into ``stream``'s own form before it is parsed (one line out per line
in, so line numbers stay the file's): comment, units and skipped lines become blank lines,
the header becomes ``time,sensor[,reference]``, a data line its time [s], sensor and
reference with decimal points (blank lines stay blank). Anything that does not fit (a missing field, text) stays
recognisably bad, so ``stream`` counts and skips it as before. Time read in another unit is
written (and echoed) in seconds. Without any of this (a plain ``time,sensor`` input and no
option), the lines pass through untouched.

In a file (``--in``), a first line that is neither numbers nor a header naming the time and
sensor columns as the options say is refused at once, with the fix (``--columns``), instead
of every line being skipped; a live input may start mid-line, so there it is only skipped.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

__all__ = ["StreamFormat", "nothing_compensated", "stream_format", "stream_lines"]

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
    """

    sep: str = ","
    decimal: str = "."
    time: str = "time"
    sensor: str = "sensor"
    time_scale: float = 1.0
    after_header: int = 0
    check_header: bool = False
    comment_header: int = 0

    @property
    def plain(self) -> bool:
        """Whether lines need no rewriting (``stream``'s own form)."""
        return self == StreamFormat()


def stream_format(args: argparse.Namespace) -> StreamFormat:
    """The format of the stream's input: for ``--in FILE``, its settings file (``my.toml``),
    then the command line, then what `hystkit.io.csv_layout` detects; for stdin and a serial
    port, the command line (a comma and decimal points unless given). What was applied or
    detected is said on stderr (stdout carries the estimates).

    Raises
    ------
    InputError
        ``--resample`` or ``--mat-var`` (a stream takes samples as they come), or a settings
        file or layout that `hystkit.io` refuses.
    """
    from ..io import ReadOptions, csv_layout, options_for, settings_for
    from ._common import given_read_options

    given = given_read_options(args)
    refused = [f"--{k}" for k in ("resample", "mat_var") if getattr(args, k, None) is not None]
    missing = given.get("missing") == "interpolate"
    refused += ["--missing interpolate"] if missing else []
    if refused:
        raise InputError(f"{', '.join(refused).replace('_', '-')}: stream compensates the "
                         "samples of a text input as they come (resample the file, or read "
                         "it with compensate)" + ("; a line missing a value is skipped and "
                                                  "counted" if missing else ""))
    if args.input is None:
        try:
            options = ReadOptions(**given)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        sep = "," if options.sep == "auto" else options.sep
        decimal = "." if options.decimal == "auto" else options.decimal
        return _format(options, sep, decimal)
    path = Path(args.input)
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
                        comment_header)


def _say(line: str) -> None:
    print(f"hystkit stream: {line}", file=sys.stderr, flush=True)


def stream_lines(lines: Iterator[str], fmt: StreamFormat, source: str,
                 too_long: str) -> Iterator[str]:
    """`lines` rewritten into ``time,sensor[,reference]`` lines as `fmt` says (see the
    module); `too_long` (stream's marker of an overlong line) passes through."""
    columns: tuple[int, int, int | None] | None = None
    skip = 0
    for line_no, line in enumerate(lines, start=1):
        if line is too_long:
            yield line
            continue
        end = "\n" if line.endswith("\n") else ""
        text = line.rstrip("\r\n")
        if columns is None:
            text = text.lstrip("\ufeff")  # a UTF-8 BOM first
            if line_no == fmt.comment_header:
                text = text.lstrip().lstrip("#")  # the header, written as a comment
            elif not text.strip() or text.lstrip().startswith("#"):
                yield end  # blank and comment lines before the header
                continue
            fields = _split(text, fmt.sep)
            columns = _header(fields, fmt)
            if columns is not None:
                skip = fmt.after_header
                yield "time,sensor,reference" + end if columns[2] is not None \
                    else "time,sensor" + end
                continue
            if fmt.check_header and not any(_NUMBER.fullmatch(f) for f in fields[:2]):
                raise InputError(_no_header(source, line_no, fields, fmt))
            columns = (0, 1, 2)  # no header: time, sensor, reference in this order
        if skip:
            skip -= 1
            yield end
            continue
        yield _rewrite(text, fmt, columns) + end if text.strip() else line


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
    """One data line as ``time,sensor[,reference]``; a field it lacks stays empty (stream
    counts the line as missing a field), text stays text (not a number)."""
    fields = _split(text, fmt.sep)
    picked = [fields[j] if j is not None and j < len(fields) else "" for j in columns]
    if fmt.decimal == ",":
        picked = [f if "." in f else f.replace(",", ".") for f in picked]
    elif fmt.sep != ",":
        picked = [f.replace(",", ";") for f in picked]  # a stray comma is no separator here
    if fmt.time_scale != 1.0 and picked[0]:
        try:
            picked[0] = repr(float(picked[0]) * fmt.time_scale)  # stream's time is in s
        except ValueError:
            pass
    return ",".join(picked if picked[2] else picked[:2])
