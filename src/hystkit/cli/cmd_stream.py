"""``hystkit stream MODEL``: compensate a live sensor, one ``time,sensor`` line at a time.

Input: CSV lines ``time,sensor`` (time in seconds) from stdin, a file (``--in``) or a serial
port (``--serial PORT --baud B``, needs the ``serial`` extra). An optional first non-empty
line naming the columns (``time,sensor``, any order, more columns allowed) is read as a header.
A file laid out otherwise is read as ``fit`` reads it (:mod:`._stream_input`): its settings file,
``--columns``, ``--time-unit``, ``--sep``, ``--decimal``, ``--units-row``, ``--skip-rows``, and
the separator, decimal comma and comment lines detected; a model that remembers how its training
files were read reads a file of their names, and stdin or a port, that way. A stream that
compensates no sample ends with an error naming the first line skipped and why.

Output, one line per accepted sample: ``time,position_estimate,flags`` after a header line, and
``position_lower,position_upper`` (the prediction band, bit for bit ``hystkit compensate``'s)
when the model has a band; the columns named as ``compensate`` names them (the input's time
column, ``x_mm_estimate`` for an input whose position column is ``x_mm``); ``--adapt
gain|weights`` re-scales the band from the references (:mod:`hystkit.live._adaptive`),
``--adapt full`` has none. ``time`` is echoed as received (in the input's unit), the estimate
[mm] is printed to full precision, ``flags`` is a bit mask: 1 = sensor outside the training
range, 2 = estimate outside the training position range (the columns of ``hystkit
compensate``). A closed stdout (``>&-``) is refused before any work; a full disk or a failing
device ends the stream with one error line.

Reading in chunks: each read takes what the input holds at that moment (up to 64 KiB) and
never waits for more, so a live sensor's line is answered as soon as it arrives, and a file
or a fast pipe is compensated many lines per compiled call (:meth:`Stream.step_many`) and
written with one system call per chunk. Each chunk's output is flushed before the next read.

Bad input never stops the stream: a line that is not numbers, lacks a field, is longer than
4096 characters, whose time does not advance, or a last line without its line end (cut off
mid-write, so perhaps mid-number) is skipped; a sample whose step differs from the
model's ``dt`` by more than 1 % (the tolerance ``compensate`` allows a recording's rate) is
compensated but counted, since the model's Euler step assumes ``dt`` (a dropped sample,
jitter); a sample whose estimate runs away is skipped and the model state kept. At the end (end
of input, a closed port, Ctrl-C or SIGTERM) stderr gets one warning line per kind with its count
and first line number, and the latency per sample (from the read that brought its line until its
output line is ready: parse, compensate, format; writing it is one system call more).

Online adaptation (``--adapt gain`` or ``--adapt weights``, see
:mod:`hystkit.live._adaptive`): a third column ``reference`` (named in the header, or
the third field without one) gives the true position [mm] now and then, empty (or ``nan``) when
unknown; each known one re-fits the output's gain and offset (or cell weights) by recursive
least squares with forgetting, after its own sample's estimate is made. ``--adapt full``
(:mod:`hystkit.live._refit`) re-fits every parameter on the last ``--window`` seconds
after every ``--refit-every`` references. A reference that is not a number is ignored and
counted. At the end stderr gets the references used, the a-priori error at them and the
adapted parameters. Adapting streams run sample by sample in Python (their updates are).
"""

from __future__ import annotations

import argparse
import codecs
import contextlib
import io
import itertools
import math
import sys
import time
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError, OutputError
from ._common import add_read_options, stdout_for
from ._own_layout import add_trained_note, stream_args
from ._stream_input import (
    Rewriter,
    live_as_trained,
    nothing_compensated,
    output_header,
    stream_format,
)

if TYPE_CHECKING:
    from ..live import AdaptiveStream, RefittingStream, Stream, SyncExcitation

__all__ = ["register"]

# Relative step tolerance of the model's dt, as Compensator.check_sampling.
STEP_TOLERANCE = 0.01
# Latency percentiles are over the most recent samples (memory stays bounded on a long run).
LATENCY_WINDOW = 100_000
DEFAULT_BAUD = 115200
# A longer line is no "time,sensor" pair: skipped without holding it in memory.
MAX_LINE = 4096
# At most this many bytes per read: what a pipe holds at once, a few thousand lines.
CHUNK_BYTES = 1 << 16
TOO_LONG = "\0 line too long"
SERIAL_HINT = 'pip install "hystkit[serial]"'
# As hystkit.live._adaptive and ._refit (not imported here: the parser stays light).
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

    def add(self, kind: str, line_no: int, n: int = 1) -> None:
        """`n` lines of this kind, the first at `line_no`."""
        self.count[kind] = self.count.get(kind, 0) + n
        self.first.setdefault(kind, line_no)

    def report(self, source: str, dt: float) -> None:
        for kind, n in self.count.items():
            what = NOT_SKIPPED.get(kind, "skipped").format(dt=dt)
            print(f"hystkit: warning: {source}: {n} line(s) {kind} ({what}; first at line "
                  f"{self.first[kind]})", file=sys.stderr)


Chunk = list[str]


class _Input:
    """The chunks of lines of an input and the handle they come from, closed together by
    `close` (also when never read: the output's header failed)."""

    def __init__(self, chunks: Iterator[Chunk], handle) -> None:
        self.chunks, self.handle = chunks, handle

    def __iter__(self) -> Iterator[Chunk]:
        return self.chunks

    def close(self) -> None:
        self.chunks.close()  # type: ignore[attr-defined]  (a generator)
        self.handle.close()


def _lines(args: argparse.Namespace) -> tuple[str, _Input]:
    """Name of the input and its chunks of lines (a serial port's until it closes)."""
    if args.serial is not None:
        return str(args.serial), _serial_lines(args.serial, args.baud or DEFAULT_BAUD)
    if args.input is not None:
        try:
            handle = open(args.input, "rb")  # noqa: SIM115
        except OSError as exc:
            raise InputError(f"{args.input}: cannot read ({exc.strerror})") from None
        return str(args.input), _Input(_line_chunks(_decoded(handle.read1)), handle)
    binary = getattr(sys.stdin, "buffer", None)
    if binary is not None and hasattr(binary, "read1"):
        return "<stdin>", _Input(_line_chunks(_decoded(binary.read1)), sys.stdin)
    # a text stream without bytes underneath (a StringIO put in place of stdin)
    return "<stdin>", _Input(_line_chunks(lambda: sys.stdin.read(CHUNK_BYTES)), sys.stdin)


def _decoded(read1: Callable[[int], bytes]) -> Callable[[], str]:
    """Text from `read1` (one system call at most: what is there, waiting only when nothing
    is), as UTF-8 with universal line ends as a text file reads it; "" at the end."""
    decoder = io.IncrementalNewlineDecoder(codecs.getincrementaldecoder("utf-8")("replace"),
                                           translate=True)
    ended = False

    def read() -> str:
        nonlocal ended
        while not ended:
            data = read1(CHUNK_BYTES)
            ended = not data
            if text := decoder.decode(data, final=ended):
                return text  # (a lone carriage return waits for what follows it)
        return ""

    return read


def _line_chunks(read: Callable[[], str]) -> Iterator[Chunk]:
    """The complete lines of each read (a chunk per read that ended a line), a line longer
    than ``MAX_LINE`` given as ``TOO_LONG`` without holding it in memory, and a last line
    without its line end as it is."""
    pending, too_long = "", False
    while text := read():
        parts = text.split("\n")
        chunk = []
        for part in parts[:-1]:
            if too_long or len(pending) + len(part) >= MAX_LINE:
                chunk.append(TOO_LONG)
            else:
                chunk.append(pending + part + "\n")
            pending, too_long = "", False
        if not too_long:
            pending += parts[-1]
            if len(pending) >= MAX_LINE:
                pending, too_long = "", True
        if chunk:
            yield chunk
    if too_long:
        yield [TOO_LONG]
    elif pending:
        yield [pending]


def _bounded(readline: Callable[[int], str]) -> Iterator[Chunk]:
    """Lines from ``readline(limit)``, one per chunk; a line longer than ``MAX_LINE`` is
    read to its end in pieces (memory stays bounded) and given as ``TOO_LONG``."""
    while piece := readline(MAX_LINE):
        if len(piece) < MAX_LINE or piece.endswith("\n"):
            yield [piece]
            continue
        while (more := readline(MAX_LINE)) and not more.endswith("\n"):
            pass
        yield [TOO_LONG]


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
    """Lines of a serial port, one per chunk, opened now (before the output's header: a
    caller that waits for the header knows the port is listening)."""
    serial, handle = _open_serial(port, baud)

    def lines() -> Iterator[Chunk]:
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


def _parse(line: str, columns: Columns, time_scale: float) -> tuple[str, float, float] | str:
    """``(time text, time [s], sensor)`` or the kind of problem."""
    fields = line.strip().split(",")
    if len(fields) <= max(columns[:2]) or any(not fields[i].strip() for i in columns[:2]):
        return "missing field"
    text = fields[columns[0]].strip()
    try:
        t, s = float(text) * time_scale, float(fields[columns[1]])
    except ValueError:
        return "not a number"
    if not (abs(t) < math.inf and abs(s) < math.inf):  # also NaN
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

    def add(self, seconds: float, n: int = 1) -> None:
        """`n` samples that took `seconds` each (a chunk's: each waited for the whole)."""
        self.recent.extend(itertools.repeat(seconds, n))
        self.n += n
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


class _Reading:
    """Where the reading of an input stands: its lines' numbers, the columns (a header may
    name them), the time of the last sample compensated."""

    def __init__(self, time_scale: float) -> None:
        self.line_no = 0
        self.columns: Columns = DEFAULT_COLUMNS
        self.first = True  # no non-empty line yet
        self.previous: float | None = None
        self.time_scale = time_scale

    def parsed(self, line: str, tally: _Tally) -> tuple[str, float, float] | None:
        """The next line's ``(time text, time [s], sensor)``, or None (a header, a blank
        line, or a problem counted in `tally`). The time's order is not checked here."""
        self.line_no += 1
        if line is TOO_LONG:
            tally.add("line too long", self.line_no)
            return None
        if not line.strip():
            return None
        if not line.endswith("\n"):  # only the last line can be: cut off mid-write?
            tally.add("unterminated last line", self.line_no)
            return None
        if self.first and (named := _columns(line.split(","))) is not None:
            self.columns, self.first = named, False
            return None
        self.first = False
        parsed = _parse(line, self.columns, self.time_scale)
        if isinstance(parsed, str):
            tally.add(parsed, self.line_no)
            return None
        return parsed

    def step_problem(self, t: float, previous: float | None, dt: float) -> str | None:
        """Why the time `t` after `previous` is a problem: ``time not advancing`` (skipped),
        ``irregular step`` (compensated, counted), or None."""
        if previous is None:
            return None
        if not t > previous:
            return "time not advancing"
        if abs(t - previous - dt) > STEP_TOLERANCE * dt:
            return "irregular step"
        return None


def _run_stream(stream: Stream | AdaptiveStream | RefittingStream, chunks: Iterator[Chunk],
                tally: _Tally, latency: _Latency, time_scale: float,
                learning: _Learning | None = None) -> None:
    """Compensate every line, writing each chunk's results at once (:func:`_run_chunk`); an
    adapting stream (``learning`` given) runs line by line and also gets each line's
    reference."""
    reading = _Reading(time_scale)
    banded = stream.compensator.band is not None
    for chunk in chunks:
        arrived = time.perf_counter()
        if learning is None:
            rows = _run_chunk(stream, chunk, reading, tally, banded)
        else:
            rows = [row for line in chunk
                    if (row := _run_line(stream, line, reading, tally, learning)) is not None]
        if rows:
            # counted before the lines leave: a reader that got them finds them in the summary
            latency.add(time.perf_counter() - arrived, len(rows))
            _write("".join(rows))


def _run_chunk(stream: Stream, chunk: Chunk, reading: _Reading, tally: _Tally,
               banded: bool) -> list[str]:
    """The output lines of a chunk of input lines: its plain numbers at once
    (:func:`_plain_chunk`), anything else line by line (:func:`_any_chunk`); compensated in
    one compiled call either way."""
    k = 0
    rows: list[str] = []
    while reading.first and k < len(chunk):  # until the header (or the first data line)
        rows += _any_chunk(stream, chunk[k:k + 1], reading, tally, banded)
        k += 1
    rest = chunk[k:] if k else chunk
    plain = _plain_chunk(stream, rest, reading, tally, banded)
    return rows + (_any_chunk(stream, rest, reading, tally, banded) if plain is None else plain)


# What a line of two plain numbers holds (anything else: the line-by-line path)
_NOT_PLAIN = str.maketrans("", "", "0123456789.eE+-,\n")


def _plain_chunk(stream: Stream, chunk: Chunk, reading: _Reading, tally: _Tally,
                 banded: bool) -> list[str] | None:
    """:func:`_any_chunk` for a chunk of ``time,sensor`` lines of plain numbers (no space,
    no empty field, no third column, every line ended, times advancing): the same results,
    warnings and line numbers, without a Python step per check; None for any other chunk."""
    import numpy as np

    text = "".join(chunk)
    if (not chunk or reading.columns[:2] != (0, 1) or text.count(",") != len(chunk)
            or text.count("\n") != len(chunk) or text.translate(_NOT_PLAIN)
            or text[0] in ",\n" or ",\n" in text or "\n," in text or "\n\n" in text):
        return None
    parts = text[:-1].replace("\n", ",").split(",")
    try:
        values = np.array(list(map(float, parts)))  # as _parse reads them
    except ValueError:
        return None
    t = values[0::2] * reading.time_scale
    if not np.all(np.isfinite(values)) or not np.all(np.isfinite(t)):
        return None
    before = t[:-1] if reading.previous is None else np.concatenate([[reading.previous],
                                                                      t[:-1]])
    step = t[1:] if reading.previous is None else t
    if not np.all(step > before):
        return None  # a time not advancing: line by line decides what is skipped
    first = reading.line_no + 1
    dt = stream.compensator.structure.dt
    # line numbers of the irregular steps (the first line has no step without a previous)
    irregular = np.flatnonzero(np.abs(step - before - dt) > STEP_TOLERANCE * dt) + first \
        + (reading.previous is None)
    out = stream.step_many(values[1::2])
    taken = out.estimate.size
    checked = irregular[irregular <= first + taken]  # up to the refused sample, as line by line
    if checked.size:
        tally.add("irregular step", int(checked[0]), checked.size)
    reading.line_no += taken
    if taken:
        reading.previous = float(t[taken - 1])
    rows = _rows(parts[0:2 * taken:2], out, banded)
    if taken < len(chunk):  # a runaway: skipped; the lines after it as any others
        reading.line_no += 1
        tally.add("estimate ran away", reading.line_no)
        rows += _any_chunk(stream, chunk[taken + 1:], reading, tally, banded)
    return rows


def _any_chunk(stream: Stream, chunk: Chunk, reading: _Reading, tally: _Tally,
               banded: bool) -> list[str]:
    """The output lines of any chunk of input lines, parsed and checked line by line and
    compensated in one compiled call (as many as a runaway sample needs: the samples after
    it are checked again from the time before it, since it is skipped)."""
    samples = []  # (time text, time [s], sensor, line number)
    for line in chunk:
        if (parsed := reading.parsed(line, tally)) is not None:
            samples.append((*parsed, reading.line_no))
    dt = stream.compensator.structure.dt
    rows: list[str] = []
    i = 0
    while i < len(samples):
        kept, problems, previous = [], [], reading.previous
        for j in range(i, len(samples)):
            problem = reading.step_problem(samples[j][1], previous, dt)
            if problem is not None:
                problems.append((j, problem))
            if problem != "time not advancing":
                kept.append(j)
                previous = samples[j][1]
        out = stream.step_many([samples[j][2] for j in kept])
        taken = out.estimate.size
        stop = kept[taken] if taken < len(kept) else len(samples)  # the refused sample
        for j, problem in problems:
            if j <= stop:  # (after a refused sample they are checked again)
                tally.add(problem, samples[j][3])
        if taken < len(kept):
            tally.add("estimate ran away", samples[stop][3])
        if taken:
            reading.previous = samples[kept[taken - 1]][1]
            rows += _rows([samples[j][0] for j in kept[:taken]], out, banded)
        i = stop + 1
    return rows


def _rows(times: list[str], out, banded: bool) -> list[str]:
    """Output lines: time as received, estimate in full (repr: bit for bit), flags, band."""
    import numpy as np

    flags = np.zeros(out.estimate.size, dtype=np.int64)
    if out.sensor_outside is not None:
        flags += out.sensor_outside
    if out.estimate_outside is not None:
        flags += 2 * out.estimate_outside
    columns = [times, out.estimate.tolist(), flags.tolist()]
    if banded:
        columns += [out.lower.tolist(), out.upper.tolist()]
        return [f"{t},{e!r},{f},{lo!r},{up!r}\n" for t, e, f, lo, up in zip(*columns, strict=True)]
    return [f"{t},{e!r},{f}\n" for t, e, f in zip(*columns, strict=True)]


def _run_line(stream: AdaptiveStream | RefittingStream, line: str, reading: _Reading,
              tally: _Tally, learning: _Learning) -> str | None:
    """One input line through an adapting stream: its output line, or None."""
    from ..errors import FitDivergedError

    parsed = reading.parsed(line, tally)
    if parsed is None:
        return None
    text, t, s = parsed
    problem = reading.step_problem(t, reading.previous, stream.compensator.structure.dt)
    if problem is not None:
        tally.add(problem, reading.line_no)
        if problem == "time not advancing":
            return None
    if (reference := _reference(line, reading.columns)) is None:
        tally.add("reference not a number", reading.line_no)
        reference = math.nan
    try:
        result = stream.step_flagged(s, reference)
    except FitDivergedError:
        tally.add("estimate ran away", reading.line_no)
        return None
    if not math.isnan(reference):
        learning.add(result.estimate, reference, stream)
    reading.previous = t
    flags = (1 if result.sensor_outside else 0) + (2 if result.estimate_outside else 0)
    band = "" if result.lower is None else f",{result.lower!r},{result.upper!r}"
    return f"{text},{result.estimate!r},{flags}{band}\n"


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
    from ..compensation import load_compensator
    from ..live import Stream, sync_excitation
    from ..live._stream import check_streamable

    if args.serial is None and args.baud is not None:
        raise InputError("--baud is for --serial")
    _check_adapt_options(args)
    comp = load_compensator(args.model)
    stream_args(args, comp.reading)  # --in FILE of the training files' names: read as they were
    live_as_trained(args, comp.reading)  # stdin or a port: so too, unless told otherwise
    fmt = stream_format(args)  # --in FILE: its settings file and layout, as fit reads it
    stdout_for("the estimates")
    if args.level is not None and comp.band is None:
        raise InputError(f"--level: {args.model} has no prediction band (fitted without one or "
                         f"by a hystkit before bands); fit it again")
    check_streamable(comp)  # the oracle centring, --no-limit: before anything is said
    start = "rest"
    if args.start == "sync":
        sync = sync_excitation(comp)
        _print_sync(sync)
        start = sync.state_after
    learning = None
    if args.adapt is None:
        stream = Stream(comp, start, label=str(args.model), level=args.level)
    else:
        stream, learning = _adaptive_stream(args, comp, start), _Learning()
    source, chunks = _lines(args)
    if not fmt.plain:
        rewrite = Rewriter(fmt, source, TOO_LONG)
        chunks = _Input((rewrite.chunk(chunk) for chunk in chunks), chunks)
    with contextlib.closing(chunks):
        _write(output_header(fmt, comp.band is not None and args.adapt != "full"))
        tally, latency = _Tally(), _Latency()
        try:
            _run_stream(stream, chunks, tally, latency, fmt.time_scale, learning)
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
    from ..live import Adaptation, AdaptiveStream, Refit, RefittingStream

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
