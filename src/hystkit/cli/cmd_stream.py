"""``hystkit stream MODEL``: compensate a live sensor, one ``time,sensor`` line at a time.

Input: CSV lines ``time,sensor`` (time in seconds) from stdin, a file (``--in``) or a serial
port (``--serial PORT --baud B``, needs the ``serial`` extra). An optional first non-empty
line naming the columns (``time,sensor``, any order, more columns allowed) is read as a header.
A file laid out otherwise is read as ``fit`` reads it (:mod:`._stream_input`): its settings file,
``--columns``, ``--time-unit``, ``--sep``, ``--decimal``, ``--units-row``, ``--skip-rows``, and
the separator, decimal comma and comment lines detected. A stream that compensates no sample
ends with an error naming the first line skipped and why.

Output, one line per accepted sample and flushed at once: ``time,position_estimate,flags``
after a header line, and ``position_lower,position_upper`` (the prediction band, bit for bit
``hystkit compensate``'s) when the model has a band; ``--adapt gain|weights`` re-scales it
from the references (:mod:`hystkit.compensation._adaptive`), ``--adapt full`` has none. ``time`` is
echoed as received, the estimate [mm] is printed to full precision, ``flags`` is a bit mask:
1 = sensor outside the training range, 2 = estimate outside the training position range (the
columns of ``hystkit compensate``). A closed stdout (``>&-``)
is refused before any work; a full disk or a failing device ends the stream with one error line.

Bad input never stops the stream: a line that is not numbers, lacks a field, is longer than
4096 characters, whose time does not advance, or a last line without its line end (cut off
mid-write, so perhaps mid-number) is skipped; a sample whose step differs from the
model's ``dt`` by more than 1 % (the tolerance ``compensate`` allows a recording's rate) is
compensated but counted, since the model's Euler step assumes ``dt`` (a dropped sample,
jitter); a sample whose estimate runs away is skipped and the model state kept. At the end (end
of input, a closed port, Ctrl-C or SIGTERM) stderr gets one warning line per kind with its count
and first line number, and the latency per sample (from the line's arrival until its output
line is ready: parse, compensate, format; writing it is one system call more).

Online adaptation (``--adapt gain`` or ``--adapt weights``, see
:mod:`hystkit.compensation._adaptive`): a third column ``reference`` (named in the header, or
the third field without one) gives the true position [mm] now and then, empty (or ``nan``) when
unknown; each known one re-fits the output's gain and offset (or cell weights) by recursive
least squares with forgetting, after its own sample's estimate is made. ``--adapt full``
(:mod:`hystkit.compensation._refit`) re-fits every parameter on the last ``--window`` seconds
after every ``--refit-every`` references. A reference that is not a number is ignored and
counted. At the end stderr gets the references used, the a-priori error at them and the
adapted parameters.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import time
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from ..errors import InputError, OutputError
from ._common import add_read_options, stdout_for
from ._own_layout import add_trained_note, stream_args
from ._stream_input import nothing_compensated, stream_format, stream_lines

if TYPE_CHECKING:
    from ..compensation import AdaptiveStream, RefittingStream, Stream, SyncExcitation

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
# As hystkit.compensation._adaptive and ._refit (not imported here: the parser stays light).
ADAPT_CHOICES = ("gain", "weights", "full")
DEFAULT_FORGETTING = 0.9
DEFAULT_WINDOW = 60.0
DEFAULT_REFIT_EVERY = 10


# Kinds of problem whose sample is still compensated, and what happened instead of skipping it.
NOT_SKIPPED = {
    "irregular step": "compensated, but the step differs from the model's dt = {dt:g} s by more "
                      f"than {STEP_TOLERANCE:.0%}",
    "reference not a number": "compensated; the reference ignored",
}


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
            what = NOT_SKIPPED.get(kind, "skipped").format(dt=dt)
            print(f"hystkit: warning: {source}: {n} line(s) {kind} ({what}; first at line "
                  f"{self.first[kind]})", file=sys.stderr)


class _Input:
    """The lines of an input and the handle they come from, closed together by `close` (also
    when never read: the output's header failed)."""

    def __init__(self, lines: Iterator[str], handle) -> None:
        self.lines, self.handle = lines, handle

    def __iter__(self) -> Iterator[str]:
        return self.lines

    def close(self) -> None:
        self.lines.close()  # type: ignore[attr-defined]  (a generator)
        self.handle.close()


def _lines(args: argparse.Namespace) -> tuple[str, _Input]:
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


def _file_lines(handle: TextIO) -> _Input:
    return _Input(_bounded(handle.readline), handle)


def _open_serial(port: str, baud: int):
    try:
        import serial
    except ImportError:
        raise InputError(f"--serial needs the optional pyserial package: {SERIAL_HINT}") from None
    try:
        return serial, serial.Serial(port, baudrate=baud, timeout=None)
    except (serial.SerialException, OSError, ValueError) as exc:
        raise InputError(f"{port}: cannot open serial port ({exc})") from None


def _serial_lines(port: str, baud: int) -> _Input:
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

    return _Input(lines(), handle)


Columns = tuple[int, int, int | None]
# Without a header: time, sensor and (adapting) the reference in this order.
DEFAULT_COLUMNS: Columns = (0, 1, 2)


def _columns(fields: list[str]) -> Columns | None:
    """Indices of time, sensor and reference (None: no such column) if ``fields`` is a header
    naming time and sensor, else None."""
    names = [f.strip().lstrip("\ufeff").lower() for f in fields]  # a UTF-8 BOM first
    if "time" in names and "sensor" in names:
        reference = names.index("reference") if "reference" in names else None
        return names.index("time"), names.index("sensor"), reference
    return None


def _parse(line: str, columns: Columns) -> tuple[str, float, float] | str:
    """``(time text, time, sensor)`` or the kind of problem."""
    fields = line.strip().split(",")
    if len(fields) <= max(columns[:2]) or any(not fields[i].strip() for i in columns[:2]):
        return "missing field"
    text = fields[columns[0]].strip()
    try:
        t, s = float(text), float(fields[columns[1]])
    except ValueError:
        return "not a number"
    if not (abs(t) < float("inf") and abs(s) < float("inf")):  # also NaN
        return "not a number"
    return text, t, s


def _reference(line: str, columns: Columns) -> float | None:
    """The line's reference [mm]: NaN when absent, empty or ``nan`` (unknown), None when not a
    number or infinite."""
    fields = line.strip().split(",")
    if columns[2] is None or len(fields) <= columns[2] or not fields[columns[2]].strip():
        return float("nan")
    try:
        r = float(fields[columns[2]])
    except ValueError:
        return None
    return r if math.isnan(r) or abs(r) < float("inf") else None


class _Learning:
    """References used by an adapting stream and its a-priori errors at them [mm]; those it
    rejected as implausible or refused (out of the parameters' domain) are only counted."""

    def __init__(self) -> None:
        self.n = 0
        self.sum_sq = 0.0
        self.ignored = 0

    def add(self, estimate: float, reference: float,
            stream: AdaptiveStream | RefittingStream) -> None:
        ignored = stream.n_rejected + getattr(stream, "n_refused", 0)
        if ignored > self.ignored:  # this reference moved nothing
            self.ignored = ignored
            return
        self.n += 1
        self.sum_sq += (estimate - reference) ** 2

    def _ignored_text(self, stream: AdaptiveStream | RefittingStream) -> str:
        text = (f"; {stream.n_rejected} rejected as implausible (beyond the training "
                f"positions or too far from the estimate)")
        if hasattr(stream, "n_refused"):
            text += (f", {stream.n_refused} refused (the update would have left the "
                     f"parameters' domain)")
        return text

    def summary(self, stream: AdaptiveStream | RefittingStream, adapt: str,
                forgetting: float | None) -> str:
        if adapt == "full":
            refit = stream.refit
            head = (f"hystkit stream: adaptation (full, window {refit.window_seconds:g} s, "
                    f"refit every {refit.every} references): ")
        else:
            head = f"hystkit stream: adaptation ({adapt}, forgetting {forgetting:g}): "
        if not self.n and not self.ignored:
            return head + "no reference arrived; the estimates are the plain stream's"
        used = (f"{self.n} references used, rms error at them before learning from each "
                f"{(self.sum_sq / self.n) ** 0.5:.4g} mm" if self.n else "no reference used")
        used += self._ignored_text(stream)
        if adapt == "full":
            report = stream.report
            return (head + f"{used}; refits: {report.kept} kept, "
                    f"{report.refused} refused, {report.skipped} skipped (the window held "
                    f"too few references), {report.evaluations} model evaluations; now "
                    f"{stream.compensator.params.to_dict()}")
        values = ", ".join(f"{k} {v:.6g}" for k, v in stream.parameters.items())
        state = stream.state
        band = ("" if not state.n_band_checks else
                f"; band: {state.n_band_misses} of {state.n_band_checks} references outside it, "
                f"now x{math.exp(state.band_log_factor):.3g} its calibrated width")
        return head + f"{used}; now {values}{band}"


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


def _run_stream(stream: Stream | AdaptiveStream | RefittingStream, lines: Iterator[str], tally: _Tally,
                latency: _Latency, learning: _Learning | None = None) -> None:
    """Compensate every line, writing each result at once; an adapting stream (``learning``
    given) also gets each line's reference."""
    from ..errors import FitDivergedError

    dt = stream.compensator.structure.dt
    columns, previous, first = DEFAULT_COLUMNS, None, True  # first: no non-empty line yet
    for line_no, line in enumerate(lines, start=1):
        arrived = time.perf_counter()
        if line is TOO_LONG:
            tally.add("line too long", line_no)
            continue
        if not line.strip():
            continue
        if not line.endswith("\n"):  # only the last line can be: cut off mid-write?
            tally.add("unterminated last line", line_no)
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
        reference = float("nan")
        if learning is not None and (reference := _reference(line, columns)) is None:
            tally.add("reference not a number", line_no)
            reference = float("nan")
        try:
            result = (stream.step_flagged(s) if learning is None
                      else stream.step_flagged(s, reference))
        except FitDivergedError:
            tally.add("estimate ran away", line_no)
            continue
        if learning is not None and not math.isnan(reference):
            learning.add(result.estimate, reference, stream)
        previous = t
        flags = (1 if result.sensor_outside else 0) + (2 if result.estimate_outside else 0)
        band = "" if result.lower is None else f",{result.lower!r},{result.upper!r}"
        row = f"{text},{result.estimate!r},{flags}{band}\n"
        # counted before the line leaves: a reader that got it finds it in the summary
        latency.add(time.perf_counter() - arrived)
        _write(row)


def _write(text: str) -> None:
    """Write and flush `text` to stdout at once; a full disk or a failing device is one error
    line (a reader that left stays a BrokenPipeError: exit 1, as for every command)."""
    out = stdout_for("the estimates")
    try:
        out.write(text)
        out.flush()
    except BrokenPipeError:
        raise
    except OSError as exc:
        raise OutputError(f"standard output: cannot write the estimates "
                          f"({exc.strerror or exc})") from None


def _stream(args: argparse.Namespace) -> int:
    from ..compensation import Stream, load_compensator, sync_excitation

    if args.serial is None and args.baud is not None:
        raise InputError("--baud is for --serial")
    _check_adapt_options(args)
    comp = load_compensator(args.model)
    stream_args(args, comp.reading)  # --in FILE of the training files' names: read as they were
    fmt = stream_format(args)  # --in FILE: its settings file and layout, as fit reads it
    stdout_for("the estimates")
    if args.level is not None and comp.band is None:
        raise InputError(f"--level: {args.model} has no prediction band (fitted without one or "
                         f"by a hystkit before bands); fit it again")
    stream = Stream(comp, label=str(args.model), level=args.level)  # refuses the oracle
    start = "rest"
    if args.start == "sync":
        sync = sync_excitation(comp)
        _print_sync(sync)
        start = sync.state_after
        stream = Stream(comp, start, label=str(args.model), level=args.level)
    learning = None
    if args.adapt is not None:
        stream, learning = _adaptive_stream(args, comp, start), _Learning()
    source, lines = _lines(args)
    if not fmt.plain:
        lines = _Input(stream_lines(iter(lines), fmt, source, TOO_LONG), lines)
    with contextlib.closing(lines):
        banded = comp.band is not None and args.adapt != "full"
        _write("time,position_estimate,flags" + (",position_lower,position_upper" * banded)
               + "\n")
        tally, latency = _Tally(), _Latency()
        try:
            _run_stream(stream, lines, tally, latency, learning)
            if not latency.n:  # a stream that compensates nothing is no success
                raise InputError(nothing_compensated(source, tally.count, tally.first))
        finally:  # also on Ctrl-C / SIGTERM: the summary, then main's exit 130 / 143
            tally.report(source, comp.structure.dt)
            print(latency.summary(), file=sys.stderr)
            if learning is not None:
                print(learning.summary(stream, args.adapt, args.forgetting), file=sys.stderr)
    return 0


ADAPT_OPTIONS = ("prior_gain", "prior_offset")
REFIT_OPTIONS = ("window", "refit_every")


def _check_adapt_options(args: argparse.Namespace) -> None:
    def given(names: tuple[str, ...]) -> list[str]:
        return [f"--{k.replace('_', '-')}" for k in names if getattr(args, k) is not None]

    if args.adapt is None:
        if used := given(("forgetting", *ADAPT_OPTIONS)):
            raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt")
        if used := given(REFIT_OPTIONS):
            raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt full")
    elif args.adapt == "full":
        if used := given(("forgetting", *ADAPT_OPTIONS)):
            raise InputError(f"{', '.join(used)} {_verb(used)} to --adapt gain or weights, "
                             f"not full")
    else:
        if used := given(REFIT_OPTIONS):
            raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt full")
        if args.forgetting is None:
            args.forgetting = DEFAULT_FORGETTING


def _verb(options: list[str]) -> str:
    return "applies" if len(options) == 1 else "apply"


def _adaptive_stream(args: argparse.Namespace, comp,
                     start) -> AdaptiveStream | RefittingStream:
    from ..compensation import Adaptation, AdaptiveStream, Refit, RefittingStream

    if args.adapt == "full":
        refit = Refit(DEFAULT_WINDOW if args.window is None else args.window,
                      DEFAULT_REFIT_EVERY if args.refit_every is None else args.refit_every)
        return RefittingStream(comp, refit, start, label=str(args.model))
    options = {k: getattr(args, k) for k in ADAPT_OPTIONS if getattr(args, k) is not None}
    adaptation = Adaptation(args.adapt, args.forgetting, **options)
    return AdaptiveStream(comp, adaptation, start, label=str(args.model), level=args.level)


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
    from ._common import number, positive_int

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
    add_read_options(p)  # --in FILE, stdin or a port laid out as the user's files
    add_trained_note(p)
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=None,
                   help="nominal coverage of the prediction band columns, in (0, 1) (default: "
                        "the model's own, 0.90 unless fitted otherwise)")
    adapt = p.add_argument_group("online adaptation (a reference column: the true position "
                                 "[mm] now and then, empty when unknown)")
    adapt.add_argument("--adapt", choices=ADAPT_CHOICES,
                       help="re-fit from the references: gain (gain and offset of the "
                            "estimate, any model) or weights (cell output weights and offset; "
                            "direct mpl, pl, ladder) by recursive least squares; full (every "
                            "parameter, re-fitted on a sliding window; direct compensators)")
    adapt.add_argument("--forgetting", type=number(0, 1, low_open=True), metavar="LAMBDA",
                       help=f"forgetting factor per reference, in (0, 1]: remembers about "
                            f"1/(1-LAMBDA) references (default {DEFAULT_FORGETTING:g})")
    adapt.add_argument("--prior-gain", type=number(0, 1e6, low_open=True), metavar="STD",
                       help="prior standard deviation of each gain / weight multiplier "
                            "(default 0.1: 10 %%)")
    adapt.add_argument("--prior-offset", type=number(0, 1e9, low_open=True), metavar="MM",
                       help="prior standard deviation of the offset [mm] (default 10 %% of "
                            "the training positions' span)")
    adapt.add_argument("--window", type=number(0, 1e6, low_open=True), metavar="SECONDS",
                       help=f"--adapt full: length of the sliding window re-fitted [s] (default "
                            f"{DEFAULT_WINDOW:g}); it must hold 4 references per parameter")
    adapt.add_argument("--refit-every", type=positive_int, metavar="N",
                       help=f"--adapt full: re-fit after every N new references (default "
                            f"{DEFAULT_REFIT_EVERY})")
    p.set_defaults(run=_stream)
