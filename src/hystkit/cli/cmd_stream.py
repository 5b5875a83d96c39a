"""``hystkit stream MODEL``: compensate a live sensor, one ``time,sensor`` line at a time.

Input: CSV lines ``time,sensor`` (time in seconds) from stdin, a file (``--in``) or a serial
port (``--serial PORT --baud B``, needs the ``serial`` extra). An optional first non-empty
line naming the columns (``time,sensor``, any order, more columns allowed) is read as a header.

Output, one line per accepted sample and flushed at once: ``time,position_estimate,flags``
after a header line. ``time`` is echoed as received, the estimate [mm] is printed to full
precision, ``flags`` is a bit mask: 1 = sensor outside the training range, 2 = estimate outside
the training position range (the columns of ``hystkit compensate``).

Bad input never stops the stream: a line that is not numbers, lacks a field, is longer than
4096 characters, or whose time does not advance is skipped; a sample whose step differs from the
model's ``dt`` by more than 1 % (the tolerance ``compensate`` allows a recording's rate) is
compensated but counted, since the model's Euler step assumes ``dt`` (a dropped sample,
jitter); a sample whose estimate runs away is skipped and the model state kept. At the end (end
of input, a closed port, Ctrl-C or SIGTERM) stderr gets one warning line per kind with its count
and first line number, and the latency per sample (from the line's arrival until its output
line is ready: parse, compensate, format; writing it is one system call more).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from ..errors import InputError

if TYPE_CHECKING:
    from ..compensation import Stream, SyncExcitation

__all__ = ["register"]

# Relative step tolerance of the model's dt, as Compensator.check_sampling.
STEP_TOLERANCE = 0.01
# Latency percentiles are over the most recent samples (memory stays bounded on a long run).
LATENCY_WINDOW = 100_000
DEFAULT_BAUD = 115200
# A longer line is no "time,sensor" pair: skipped without holding it in memory.
MAX_LINE = 4096
TOO_LONG = "\0 line too long"
SERIAL_HINT = 'pip install "hystkit[serial]"'


class _Tally:
    """Counts and first line number per kind of problem."""

    def __init__(self) -> None:
        self.count: dict[str, int] = {}
        self.first: dict[str, int] = {}

    def add(self, kind: str, line_no: int) -> None:
        self.count[kind] = self.count.get(kind, 0) + 1
        self.first.setdefault(kind, line_no)

    def report(self, source: str, dt: float) -> None:
        for kind, n in self.count.items():
            what = (f"compensated, but the step differs from the model's dt = {dt:g} s by more "
                    f"than {STEP_TOLERANCE:.0%}" if kind == "irregular step" else "skipped")
            print(f"hystkit: warning: {source}: {n} line(s) {kind} ({what}; first at line "
                  f"{self.first[kind]})", file=sys.stderr)


def _lines(args: argparse.Namespace) -> tuple[str, Iterator[str]]:
    """Name of the input and its lines (a serial port's until it closes)."""
    if args.serial is not None:
        return str(args.serial), _serial_lines(args.serial, args.baud or DEFAULT_BAUD)
    if args.input is not None:
        try:
            handle = open(args.input, encoding="utf-8", errors="replace")  # noqa: SIM115
        except OSError as exc:
            raise InputError(f"{args.input}: cannot read ({exc.strerror})") from None
        return str(args.input), _file_lines(handle)
    return "<stdin>", _file_lines(sys.stdin)


def _bounded(readline: Callable[[int], str]) -> Iterator[str]:
    """Lines from ``readline(limit)``; a line longer than ``MAX_LINE`` is read to its end in
    pieces (memory stays bounded) and given as ``TOO_LONG``."""
    while piece := readline(MAX_LINE):
        if len(piece) < MAX_LINE or piece.endswith("\n"):
            yield piece
            continue
        while (more := readline(MAX_LINE)) and not more.endswith("\n"):
            pass
        yield TOO_LONG


def _file_lines(handle: TextIO) -> Iterator[str]:
    with handle:
        yield from _bounded(handle.readline)


def _open_serial(port: str, baud: int):
    try:
        import serial
    except ImportError:
        raise InputError(f"--serial needs the optional pyserial package: {SERIAL_HINT}") from None
    try:
        return serial, serial.Serial(port, baudrate=baud, timeout=None)
    except (serial.SerialException, OSError, ValueError) as exc:
        raise InputError(f"{port}: cannot open serial port ({exc})") from None


def _serial_lines(port: str, baud: int) -> Iterator[str]:
    """Lines of a serial port, opened now (before the output's header: a caller that waits
    for the header knows the port is listening)."""
    serial, handle = _open_serial(port, baud)

    def lines() -> Iterator[str]:
        with handle:
            try:
                yield from _bounded(lambda limit: handle.readline(limit).decode(
                    "ascii", errors="replace"))
            except serial.SerialException:  # unplugged, or the other end closed
                print(f"hystkit stream: {port} closed", file=sys.stderr)

    return lines()


def _columns(fields: list[str]) -> tuple[int, int] | None:
    """Indices of time and sensor if ``fields`` is a header naming them, else None."""
    names = [f.strip().lstrip("\ufeff").lower() for f in fields]  # a UTF-8 BOM first
    if "time" in names and "sensor" in names:
        return names.index("time"), names.index("sensor")
    return None


def _parse(line: str, columns: tuple[int, int]) -> tuple[str, float, float] | str:
    """``(time text, time, sensor)`` or the kind of problem."""
    fields = line.strip().split(",")
    if len(fields) <= max(columns) or any(not fields[i].strip() for i in columns):
        return "missing field"
    text = fields[columns[0]].strip()
    try:
        t, s = float(text), float(fields[columns[1]])
    except ValueError:
        return "not a number"
    if not (abs(t) < float("inf") and abs(s) < float("inf")):  # also NaN
        return "not a number"
    return text, t, s


class _Latency:
    """Per-sample latencies [s]: the most recent ``LATENCY_WINDOW`` ones, the count, the max."""

    def __init__(self) -> None:
        self.recent: deque[float] = deque(maxlen=LATENCY_WINDOW)
        self.n = 0
        self.max = 0.0

    def add(self, seconds: float) -> None:
        self.recent.append(seconds)
        self.n += 1
        self.max = max(self.max, seconds)

    def summary(self) -> str:
        import numpy as np

        if not self.n:
            return "hystkit stream: no sample compensated"
        us = np.asarray(self.recent) * 1e6
        window = ("" if self.n <= LATENCY_WINDOW
                  else f" (median and p99 over the last {LATENCY_WINDOW})")
        return (f"hystkit stream: {self.n} samples; latency per sample median "
                f"{np.median(us):.1f} µs, p99 {np.percentile(us, 99):.1f} µs, max "
                f"{self.max * 1e6:.1f} µs{window}")


def _run_stream(stream: Stream, lines: Iterator[str], tally: _Tally, latency: _Latency) -> None:
    """Compensate every line, writing each result at once."""
    from ..errors import FitDivergedError

    dt = stream.compensator.structure.dt
    out = sys.stdout
    columns, previous, first = (0, 1), None, True  # first: no non-empty line yet
    for line_no, line in enumerate(lines, start=1):
        arrived = time.perf_counter()
        if line is TOO_LONG:
            tally.add("line too long", line_no)
            continue
        if not line.strip():
            continue
        if first and (named := _columns(line.split(","))) is not None:
            columns, first = named, False
            continue
        first = False
        parsed = _parse(line, columns)
        if isinstance(parsed, str):
            tally.add(parsed, line_no)
            continue
        text, t, s = parsed
        if previous is not None and not t > previous:
            tally.add("time not advancing", line_no)
            continue
        if previous is not None and abs(t - previous - dt) > STEP_TOLERANCE * dt:
            tally.add("irregular step", line_no)
        try:
            result = stream.step_flagged(s)
        except FitDivergedError:
            tally.add("estimate ran away", line_no)
            continue
        previous = t
        flags = (1 if result.sensor_outside else 0) + (2 if result.estimate_outside else 0)
        row = f"{text},{result.estimate!r},{flags}\n"
        # counted before the line leaves: a reader that got it finds it in the summary
        latency.add(time.perf_counter() - arrived)
        out.write(row)
        out.flush()


def _stream(args: argparse.Namespace) -> int:
    from ..compensation import Stream, load_compensator, sync_excitation

    if args.serial is None and args.baud is not None:
        raise InputError("--baud is for --serial")
    comp = load_compensator(args.model)
    stream = Stream(comp, label=str(args.model))  # refuses the oracle centring
    if args.start == "sync":
        sync = sync_excitation(comp)
        _print_sync(sync)
        stream = Stream(comp, sync.state_after, label=str(args.model))
    source, lines = _lines(args)
    sys.stdout.write("time,position_estimate,flags\n")
    sys.stdout.flush()
    tally, latency = _Tally(), _Latency()
    try:
        _run_stream(stream, lines, tally, latency)
    finally:  # also on Ctrl-C / SIGTERM: the summary, then main's exit 130 / 143
        tally.report(source, comp.structure.dt)
        print(latency.summary(), file=sys.stderr)
    return 0


def _print_sync(sync: SyncExcitation) -> None:
    levels = ", ".join(f"{v:.6g}" for v in _user_levels(sync))
    where = " (at the training data's offsets)" if sync.quantity == "sensor" else ""
    print(f"hystkit stream: start-up e_sync ({sync.rule}): drive the {sync.quantity} to "
          f"{levels} {sync.unit}{where}, holding each {sync.hold_seconds:g} s "
          f"({sync.duration:g} s in all); the stream starts from the state it leaves",
          file=sys.stderr)


def _user_levels(sync: SyncExcitation) -> list[float]:
    n_hold = round(sync.hold_seconds / sync.dt)
    return [float(sync.signal[k * n_hold]) for k in range(len(sync.levels))]


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stream`` subcommand to the ``hystkit`` parser."""
    from ._common import positive_int

    p = sub.add_parser("stream", help="compensate live: time,sensor lines in (stdin, a file or "
                                      "a serial port), time,position_estimate,flags lines out")
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit' "
                                            "(centring fit, tare, track or none)")
    source = p.add_mutually_exclusive_group()
    source.add_argument("--in", dest="input", type=Path, metavar="FILE",
                        help="read this file instead of stdin")
    source.add_argument("--serial", metavar="PORT",
                        help=f"read a serial port (needs pyserial: {SERIAL_HINT})")
    p.add_argument("--baud", type=positive_int, help="serial baud rate (default 115200)")
    p.add_argument("--start", choices=("rest", "sync"), default="rest",
                   help="rest: model at rest at the first sample (default); sync: after the "
                        "synchronisation excitation e_sync (eq. 2.21-2.22), printed to stderr")
    p.set_defaults(run=_stream)
