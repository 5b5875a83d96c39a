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
import contextlib
import itertools
import sys
import time
from collections import deque
from collections.abc import Iterator

import numpy as np

from ..compensation import load_compensator
from ..errors import InputError, OutputError
from ..live import AdaptiveStream, RefittingStream, Stream, SyncExcitation, sync_excitation
from ..live._stream import check_streamable
from ._common import stdout_for
from ._stream_adapt import Learning, adaptive_stream, run_line
from ._stream_chunks import run_chunk
from ._stream_input import (
    Rewriter,
    nothing_compensated,
    output_header,
    reading_options,
    stream_format,
)
from ._stream_lines import Reading, Tally
from ._stream_options import StreamOptions
from ._stream_read import TOO_LONG, Input, lines_of, open_input

__all__ = ["run_stream"]

# Latency percentiles are over the most recent samples (memory stays bounded on a long run).
LATENCY_WINDOW = 100_000


class Latency:
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
        if not self.n:
            return "hystkit stream: no sample compensated"
        us = np.asarray(self.recent) * 1e6
        window = ("" if self.n <= LATENCY_WINDOW
                  else f" (median and p99 over the last {LATENCY_WINDOW})")
        return (f"hystkit stream: {self.n} samples; latency per sample median "
                f"{np.median(us):.1f} µs, p99 {np.percentile(us, 99):.1f} µs, max "
                f"{self.max * 1e6:.1f} µs{window}")


def run_stream(args: argparse.Namespace) -> int:
    """Run ``hystkit stream`` on the parsed command line (see the module)."""
    options = StreamOptions.from_args(args)
    comp = load_compensator(options.model)
    # --in FILE of the training files' names, stdin or a port: read as they were, unless told
    # otherwise; --in FILE: its settings file and layout, as fit reads it
    fmt = stream_format(options.input, reading_options(options, comp.reading))
    stdout_for("the estimates")
    if options.level is not None and comp.band is None:
        raise InputError(f"--level: {options.model} has no prediction band (fitted without one "
                         f"or by a hystkit before bands); fit it again")
    check_streamable(comp)  # the oracle centring, --no-limit: before anything is said
    start = "rest"
    if options.start == "sync":
        sync = sync_excitation(comp)
        _print_sync(sync)
        start = sync.state_after
    learning = None
    if options.adapt is None:
        stream = Stream(comp, start, label=str(options.model), level=options.level)
    else:
        stream, learning = adaptive_stream(options, comp, start), Learning()
    source, chunks = open_input(options)
    if not fmt.plain:
        rewrite = Rewriter(fmt, source, TOO_LONG)
        chunks = Input((rewrite.chunk(chunk) for chunk in chunks), chunks)
    with contextlib.closing(chunks):
        _write(output_header(fmt, comp.band is not None and options.adapt != "full"))
        tally, latency = Tally(), Latency()
        try:
            _run(stream, chunks, tally, latency, fmt.time_scale, learning)
            if not latency.n:  # a stream that compensates nothing is no success
                raise InputError(nothing_compensated(source, tally.count, tally.first))
        finally:  # also on Ctrl-C / SIGTERM: the summary, then main's exit 130 / 143
            tally.report(source, comp.structure.dt)
            print(latency.summary(), file=sys.stderr)
            if learning is not None:
                print(learning.summary(stream, options.adapt, options.forgetting),
                      file=sys.stderr)
    return 0


def _run(stream: Stream | AdaptiveStream | RefittingStream, chunks: Iterator[str],
         tally: Tally, latency: Latency, time_scale: float,
         learning: Learning | None = None) -> None:
    """Compensate every line, writing each chunk's results at once
    (:func:`._stream_chunks.run_chunk`); an adapting stream (``learning`` given) runs line by
    line and also gets each line's reference."""
    reading = Reading(time_scale)
    banded = stream.compensator.band is not None
    for chunk in chunks:
        arrived = time.perf_counter()
        if learning is None:
            rows = run_chunk(stream, chunk, reading, tally, banded)
        else:
            rows = [row for line in lines_of(chunk)
                    if (row := run_line(stream, line, reading, tally, learning)) is not None]
        if rows:
            # counted before the lines leave: a reader that got them finds them in the summary
            latency.add(time.perf_counter() - arrived, len(rows))
            _write("".join(rows))


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
