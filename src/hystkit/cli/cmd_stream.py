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
from pathlib import Path

from ._common import add_read_options, number, positive_int
from ._own_layout import add_trained_note
from ._stream_defaults import (
    ADAPT_CHOICES,
    DEFAULT_FORGETTING,
    DEFAULT_REFIT_EVERY,
    DEFAULT_WINDOW,
    SERIAL_HINT,
)

__all__ = ["ADAPT_CHOICES", "DEFAULT_FORGETTING", "DEFAULT_REFIT_EVERY", "DEFAULT_WINDOW",
           "register", "stream_options"]


def _run(args: argparse.Namespace) -> int:
    # the run's module loads numba: imported once the command line parsed, not for --help
    from ._stream_run import run_stream

    return run_stream(args)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stream`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("stream", help="compensate live: time,sensor lines in (stdin, a file or "
                                      "a serial port), time,position_estimate,flags lines out")
    stream_options(p)
    p.set_defaults(run=_run)


def stream_options(p: argparse.ArgumentParser) -> None:
    """``stream``'s arguments and options."""
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
