"""``hystkit stream``'s arguments and options (what they do: :mod:`.cmd_stream`). Light:
building the parser loads neither numba nor the live streams."""

from __future__ import annotations

import argparse
from pathlib import Path

from . import _stream_defaults as defaults
from ._common import add_read_options, number, positive_int
from ._own_layout import add_trained_note

__all__ = ["stream_options"]


def stream_options(p: argparse.ArgumentParser) -> None:
    """``stream``'s arguments and options."""
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit' "
                                            "(centring fit, tare, track or none)")
    source = p.add_mutually_exclusive_group()
    source.add_argument("--in", dest="input", type=Path, metavar="FILE",
                        help="read this file instead of stdin")
    source.add_argument("--serial", metavar="PORT",
                        help=f"read a serial port (needs pyserial: {defaults.SERIAL_HINT})")
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
    adapt.add_argument("--adapt", choices=defaults.ADAPT_CHOICES,
                       help="re-fit from the references: gain (gain and offset of the "
                            "estimate, any model) or weights (cell output weights and offset; "
                            "direct compensators of the families that declare an output "
                            "linear in them) by recursive least squares; full (every "
                            "parameter, re-fitted on a sliding window; direct compensators)")
    adapt.add_argument("--forgetting", type=number(0, 1, low_open=True), metavar="LAMBDA",
                       help=f"forgetting factor per reference, in (0, 1]: remembers about "
                            f"1/(1-LAMBDA) references (default {defaults.DEFAULT_FORGETTING:g})")
    adapt.add_argument("--prior-gain", type=number(0, 1e6, low_open=True), metavar="STD",
                       help="prior standard deviation of each gain / weight multiplier "
                            "(default 0.1: 10 %%)")
    adapt.add_argument("--prior-offset", type=number(0, 1e9, low_open=True), metavar="MM",
                       help="prior standard deviation of the offset [mm] (default 10 %% of "
                            "the training positions' span)")
    adapt.add_argument("--window", type=number(0, 1e6, low_open=True), metavar="SECONDS",
                       help=f"--adapt full: length of the sliding window re-fitted [s] (default "
                            f"{defaults.DEFAULT_WINDOW:g}); it must hold 4 references per parameter")
    adapt.add_argument("--refit-every", type=positive_int, metavar="N",
                       help=f"--adapt full: re-fit after every N new references (default "
                            f"{defaults.DEFAULT_REFIT_EVERY})")
