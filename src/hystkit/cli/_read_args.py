"""The reading options of the user's own files on the command line (``--columns``,
``--time-unit``, ...): adding them to a parser and collecting the ones given. Light: what
reads the files is `hystkit.cli._reading`."""

from __future__ import annotations

import argparse

from .._read_options import (
    GAPS,
    MAX_RESAMPLE_HZ,
    MAX_SKIP_ROWS,
    MISSING,
    SEPARATORS,
    TIME_UNITS,
    ReadOptions,
    parse_columns,
)
from ._option_types import integer, number

__all__ = ["OUTPUT_NAMES_NOTE", "add_read_options", "given_read_options"]


def _columns(text: str) -> tuple[tuple[str, str], ...]:
    try:
        return parse_columns(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _separator(text: str) -> str:
    if text not in SEPARATORS:
        raise argparse.ArgumentTypeError(f"expected ',', ';', 'tab' or 'auto', got {text!r}")
    return text


# What the commands write, as they do since issue 27.4 (compensate replaces this note with its
# own, cmd_core.COMPENSATE_NAMES_NOTE).
OUTPUT_NAMES_NOTE = ("fit and select remember the column names, time unit and units line in "
                     "the model file, so that later commands read files laid out alike "
                     "without options; compensate writes the "
                     "input's column names and time unit; scores, reports and stream's lines "
                     "use hystkit's column names (time [s], position, sensor, "
                     "position_estimate)")


def add_read_options(p: argparse.ArgumentParser) -> None:
    """Add ``--columns``, ``--time-unit``, ``--skip-rows`` and ``--sep`` (how to read the
    user's own recording files); `read_options` turns them into a `hystkit.io.ReadOptions`.
    Values are checked while parsing, so a bad one is one line (exit 2) before any work."""
    g = p.add_argument_group("reading your own files (the same settings for every recording)",
                             OUTPUT_NAMES_NOTE)
    g.add_argument("--columns", type=_columns, default=(), metavar="NAME=COLUMN,...",
                   help="the file's names of hystkit's columns, e.g. time=t,position="
                        "displacement_mm,sensor=resistance_ohm (.mat: variable or struct field "
                        "names; matrix column numbers, see --mat-var); names not given stay "
                        "time, position, sensor")
    g.add_argument("--time-unit", choices=list(TIME_UNITS), default=None,
                   help="unit of the time column, converted to seconds (default s)")
    g.add_argument("--skip-rows", type=integer(0, MAX_SKIP_ROWS), default=None, metavar="N",
                   help="CSV: lines to skip after the header, e.g. 1 for a units line "
                        "(default 0)")
    g.add_argument("--sep", type=_separator, default=None, metavar="{',',;,tab,auto}",
                   help="CSV field separator (default auto: the one that splits the header "
                        "and the first data lines alike; '#' comment lines before the header "
                        "are skipped)")
    g.add_argument("--decimal", choices=[".", ",", "auto"], default=None,
                   help="CSV decimal mark (default auto: a comma when the file is not "
                        "comma-separated and its first data lines write 1,5)")
    g.add_argument("--units-row", action="store_true", default=False,
                   help="CSV: the line after the header holds units (s,mm,Ohm); they are "
                        "kept and written to the outputs (--skip-rows counts lines after it)")
    g.add_argument("--missing", choices=list(MISSING), default=None,
                   help="a row whose time, position or sensor is empty or NaN: error (the "
                        "default) refuses the file, drop leaves the row out, interpolate fills "
                        "it linearly in time; the rows touched are counted in one line")
    g.add_argument("--gaps", choices=list(GAPS), default=None,
                   help="a time step longer than 3 median steps: error (the default) refuses "
                        "the file naming the row; split reads the pieces between gaps as "
                        "separate recordings for a joint fit, said in one line (a command "
                        "that reads one recording refuses them)")
    g.add_argument("--resample", type=number(0, MAX_RESAMPLE_HZ, low_open=True), default=None,
                   metavar="HZ",
                   help="bring jittered or non-uniform time onto a uniform grid at HZ: linear "
                        "interpolation of position and sensor; more than 5 %% below the "
                        "file's mean rate a zero-phase low-pass at 0.4 HZ first (anti-alias); "
                        "gaps longer than 3 median steps (and than 1/HZ) are refused "
                        "(default: time must be uniform)")
    g.add_argument("--mat-var", type=_mat_var, default=None, metavar="NAME",
                   help=".mat: the variable holding the recording: a struct (fields named as "
                        "--columns says) or a matrix with one sample per row (--columns gives "
                        "1-based column numbers, time=1,position=2,sensor=3; default 2 "
                        "columns: time, sensor; 3: time, position, sensor)")


def _mat_var(text: str) -> str:
    try:
        return ReadOptions(mat_var=text).mat_var
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


# Namespace attribute -> ReadOptions field, for the options add_read_options adds
_READ_OPTIONS = {"columns": "columns", "time_unit": "time_unit", "skip_rows": "skip_rows",
                 "sep": "sep", "units_row": "units_row", "resample": "resample_hz",
                 "mat_var": "mat_var", "decimal": "decimal", "missing": "missing",
                 "gaps": "gaps"}


def given_read_options(args: argparse.Namespace) -> dict:
    """The reading options set on the command line (not left at their defaults), as
    `hystkit.io.ReadOptions` keyword arguments."""
    given = {}
    for attr, name in _READ_OPTIONS.items():
        value = getattr(args, attr, None)
        if value not in (None, (), False):
            given[name] = value
    return given
