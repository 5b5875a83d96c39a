"""``hystkit stream``'s arguments and options (what they do: :mod:`.cmd_stream`) and the
frozen record they parse into (:class:`StreamOptions`). Light: building the parser loads
neither numba nor the live streams."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InputError
from . import _stream_defaults as defaults
from ._common import add_read_options, given_read_options, number, positive_int
from ._own_layout import add_trained_note

__all__ = ["StreamOptions", "stream_options"]

# The options of --adapt gain and weights, and of --adapt full
_ADAPT_OPTIONS = ("forgetting", "prior_gain", "prior_offset")
_REFIT_OPTIONS = ("window", "refit_every")


@dataclass(frozen=True)
class StreamOptions:
    """What ``hystkit stream`` was asked, as parsed and checked (``--baud`` only with
    ``--serial``, each adaptation option only with the ``--adapt`` that takes it).

    ``forgetting`` is the one used: ``--forgetting`` or its default for ``--adapt gain`` and
    ``weights``, None otherwise. ``reading`` holds the reading options given on the command
    line (`given`: as `hystkit.io.ReadOptions` keyword arguments).
    """

    model: Path
    input: Path | None
    serial: str | None
    baud: int | None
    start: str
    level: float | None
    adapt: str | None
    forgetting: float | None
    prior_gain: float | None
    prior_offset: float | None
    window: float | None
    refit_every: int | None
    reading: tuple[tuple[str, Any], ...]

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> StreamOptions:
        """The options of a parsed ``stream`` command line.

        Raises
        ------
        InputError
            ``--baud`` without ``--serial``, or an adaptation option that the chosen
            ``--adapt`` (or none) does not take.
        """
        if args.serial is None and args.baud is not None:
            raise InputError("--baud is for --serial")
        forgetting = _checked_adapt(args)
        return cls(args.model, args.input, args.serial, args.baud, args.start, args.level,
                   args.adapt, forgetting, args.prior_gain, args.prior_offset, args.window,
                   args.refit_every, tuple(given_read_options(args).items()))

    @property
    def given(self) -> dict:
        """The reading options given on the command line, as `hystkit.io.ReadOptions` keyword
        arguments."""
        return dict(self.reading)

    @property
    def source(self) -> str:
        """The input's name in messages."""
        return (str(self.serial) if self.serial is not None
                else str(self.input) if self.input is not None else "<stdin>")


def _checked_adapt(args: argparse.Namespace) -> float | None:
    """Refuse the adaptation options that the chosen ``--adapt`` (or none) does not take;
    the forgetting factor used (``--forgetting``'s default for gain and weights)."""
    def given(names: tuple[str, ...]) -> list[str]:
        return [f"--{k.replace('_', '-')}" for k in names if getattr(args, k) is not None]

    if args.adapt is None:
        if used := given(_ADAPT_OPTIONS):
            raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt")
        if used := given(_REFIT_OPTIONS):
            raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt full")
        return None
    if args.adapt == "full":
        if used := given(_ADAPT_OPTIONS):
            raise InputError(f"{', '.join(used)} {_verb(used)} to --adapt gain or weights, "
                             f"not full")
        return None
    if used := given(_REFIT_OPTIONS):
        raise InputError(f"{', '.join(used)} only {_verb(used)} with --adapt full")
    return defaults.DEFAULT_FORGETTING if args.forgetting is None else args.forgetting


def _verb(options: list[str]) -> str:
    return "applies" if len(options) == 1 else "apply"


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
