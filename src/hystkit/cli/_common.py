"""Pieces shared by the subcommand modules: the one-line-error parser and option types.

Every numeric option goes through a type here: finite unless infinity means something (no
actuator limit), within a range, and sizes that allocate below a per-family maximum
(the family's ``max_size``), so a bad value is one line before any work.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import TextIO

from .._read_options import (
    GAPS,
    MAX_RESAMPLE_HZ,
    MAX_SKIP_ROWS,
    MISSING,
    SEPARATORS,
    TIME_UNITS,
    parse_columns,
)
from ..errors import HystkitError, OutputError

__all__ = ["GUARD_EXIT", "INTERNAL_EXIT", "Deferred", "Parser", "UsageError", "add_read_options",
           "check_size", "deferred", "failures_exit", "given_read_options", "integer",
           "next_step", "number", "positive_float", "positive_int", "read_options",
           "read_recording_args", "read_recordings_args", "read_training_files", "say_next",
           "size_limit", "slope_cap", "stdout_for"]

# Exit code of work that ran but failed its guards (a fit collapsed, worse than the line, on
# bounds, not converged; a family failed in compare/select); 2 is kept for errors that stop a
# command.
GUARD_EXIT = 3
# Exit code of an internal error (a bug; BSD's EX_SOFTWARE): one line instead of a traceback.
INTERNAL_EXIT = 70



class UsageError(HystkitError):
    """A command line argparse rejected; reported on one line like every other error."""


def stdout_for(what: str) -> TextIO:
    """The standard output of a command whose product is written there (``stream``'s
    estimates, ``datasets list``), refused when it is closed (``>&-``: Python makes it None);
    other commands' progress lines then go nowhere, as ``print`` does."""
    if sys.stdout is None:
        raise OutputError(f"standard output is closed: nowhere to write {what} (redirect it "
                          "to a file or a pipe)")
    return sys.stdout


class Deferred:
    """A value of an option (its choices, default or help text) that needs a heavy module (the
    model families, scipy, ...): computed when its subcommand is parsed or its help shown, so
    building the whole ``hystkit`` parser stays cheap (``--help``, ``--version``)."""

    def __init__(self, compute: Callable[[], object]):
        self.compute = compute


def deferred(action: argparse.Action, **values: Callable[[], object]) -> argparse.Action:
    """Set `action`'s attributes (``choices``, ``default``, ``help``) to computed-later values."""
    for name, compute in values.items():
        setattr(action, name, Deferred(compute))
    return action


class Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse would print the usage and call sys.exit(2)
        raise UsageError(f"{message} (see '{self.prog} --help')")

    def _resolve(self, names: tuple[str, ...] = ("choices", "default", "help")) -> None:
        for action in self._actions:
            for name in names:
                value = getattr(action, name, None)
                if isinstance(value, Deferred):
                    setattr(action, name, value.compute())

    def parse_known_args(self, args=None, namespace=None):
        # A subcommand's parser: only the chosen one pays for its values, and parsing needs
        # no help text (fit's lists every model family; its --model check needs one).
        self._resolve(("choices", "default"))
        return super().parse_known_args(args, namespace)

    def format_usage(self) -> str:
        self._resolve()
        return super().format_usage()

    def format_help(self) -> str:
        self._resolve()
        return super().format_help()


def number(low: float | None = None, high: float | None = None, *, low_open: bool = False,
           high_open: bool = False, allow_inf: bool = False) -> Callable[[str], float]:
    """An option type: a float in ``[low, high]`` (ends open if asked), finite unless
    `allow_inf` (then ``inf`` is accepted beside the range)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if math.isinf(value) and value > 0 and allow_inf:
            return value
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
        if low is not None and (value < low or (low_open and value == low)):
            raise argparse.ArgumentTypeError(f"must be {'>' if low_open else '>='} {low:g}, "
                                             f"got {text}")
        if high is not None and (value > high or (high_open and value == high)):
            raise argparse.ArgumentTypeError(f"must be {'<' if high_open else '<='} {high:g}, "
                                             f"got {text}")
        return value

    return parse


def integer(low: int | None = None, high: int | None = None) -> Callable[[str], int]:
    """An option type: a whole number (decimal digits, optional sign) in ``[low, high]``."""

    def parse(text: str) -> int:
        stripped = text.strip()
        if not stripped.lstrip("+-").isascii() or not stripped.lstrip("+-").isdigit():
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}")
        value = int(stripped)
        if (low is not None and value < low) or (high is not None and value > high):
            span = (f"in [{low}, {high}]" if low is not None and high is not None
                    else f">= {low}" if low is not None else f"<= {high}")
            raise argparse.ArgumentTypeError(f"must be a whole number {span}, got {text}")
        return value

    return parse


positive_int = integer(1)
positive_float = number(0, low_open=True)


def slope_cap(text: str) -> float:
    # Below 1e-3 the cap undercuts the fit's smallest conductance at usual rates: no box left.
    value = number(1e-3, 2, high_open=True)(text)
    return value


def size_limit(family) -> int:
    """Largest size of `family` the CLI accepts (the family's ``max_size``: beyond it a fit
    takes hours or its Jacobian stops being solvable, e.g. mpl with 300 cells)."""
    return family.max_size


def check_size(family_name: str, size: int | None, option: str = "--size") -> None:
    """Refuse a model size beyond the family's limit or its own structure checks, before work.

    Raises
    ------
    UsageError
        One line naming the option, the family and the accepted range.
    """
    if size is None:
        return
    from ..models import get_family  # the families load only for commands with a model

    family = get_family(family_name)
    limit = size_limit(family)
    if size > limit:
        raise UsageError(f"{_label(option, size)}: {family_name} accepts at most {limit} "
                         f"({family.size_help})")
    try:
        family.make_structure(1 / 40, size)  # the family's own checks (e.g. levels >= 2)
    except ValueError as exc:
        raise UsageError(f"{_label(option, size)}: {family_name}: {exc}") from None


def _label(option: str, size: int) -> str:
    return f"{option}{'' if option.endswith('=') else ' '}{size}"


def failures_exit(failed: list[str], what: str = "model(s)", next_step: str | None = None
                  ) -> int:
    """Exit code after everything else was written: GUARD_EXIT (a line on stderr, then the
    `say_next` line: `next_step`, or what suits `what`) when something failed, else 0."""
    if failed:
        print(f"hystkit: {len(failed)} {what} failed: {', '.join(failed)} (reasons above)",
              file=sys.stderr)
        say_next(next_step or _NEXT_AFTER_FAILED.get(what, _NEXT_AFTER_FAILED["model(s)"]))
        return GUARD_EXIT
    return 0


# What to try when part of a command failed, by what failed (failures_exit's `what`)
_NEXT_AFTER_FAILED = {
    "model(s)": "one failed family alone, 'hystkit fit DATA --model NAME --out m.json' (its "
                "refusal names the reason and what to try), or leave it out with --models",
    "sensor(s)": "'hystkit fit' on one failed sensor's recordings alone: its refusal names the "
                 "reason and what to try (e.g. --model auto)",
    "trace(s)": "--model drop (3 parameters) for a trace that does not rise first, or a longer "
                "log that reaches its rest",
}


def say_next(step: str) -> None:
    """The last line of a refusal (exit GUARD_EXIT): ``next: try STEP``. On standard output,
    after the refusal's line on stderr: the guard tests read that line as stderr's last."""
    print(f"next: try {step}", flush=True)


_AUTO = ("--model auto (mpl with 1-3 cells, mpl-poly, pi and pl, each scored on held-out "
         "data)")
_EVALUATE_COLUMNS = ("checking that this file's columns are the training files' "
                     "(--columns position=NAME,sensor=NAME)")
_COLUMNS = ("checking the columns: the sensor column may not carry the position "
            "(--columns position=NAME,sensor=NAME); no model recovers a signal that is not there")


def next_step(status: str, *, command: str = "fit", model: str | None = None,
              size: int | None = None, mode: str = "direct", line_r2: float | None = None,
              outside: float | None = None) -> str:
    """What to try after a refusal whose reason is `status`, as the words after ``next: try``.

    Parameters
    ----------
    status : str
        A fit's status (``on_bounds``, ``not_converged``, ``collapsed``, ``no_signal``,
        ``worse_than_line``, ``no_limit``), a use verdict (``extrapolated``), or a selection's
        (``failed``: every candidate failed; ``refit``: the best ones' fits on all the data
        failed their guards; ``skipped``: candidates left out for the time budget).
    command : {"fit", "evaluate", "select", "guided"}
        The refusing command (``guided``: ``fit --model auto``): the same status asks for
        another step after a fit than after an evaluation or a selection.
    model, size, mode : optional
        The refused model's family, size and mode (``fit``); a selection's best candidate.
    line_r2 : float, optional
        R² of the straight line on the same data: a model below a line that explains nothing
        either (a noise-only sensor) is a sensor problem, not a model's.
    outside : float, optional
        Share of the judged sensor samples far outside the training range (``evaluate``): when
        it is above the verdict's limit, the data left the model's range, and a refit on data
        that cover it comes first, whatever the scores.
    """
    from ..compensation import MAX_OUTSIDE, MIN_EXPLAINED

    far_outside = command == "evaluate" and outside is not None and outside > MAX_OUTSIDE
    if status == "worse_than_line" and line_r2 is not None and line_r2 < MIN_EXPLAINED:
        status = "no_signal"
    if far_outside and status == "no_signal":  # swapped columns, or data beyond the range
        return (f"{_EVALUATE_COLUMNS}; if they are, refitting on recordings that cover this "
                f"range ({outside:.0%} of its sensor samples lie far outside the training "
                f"range), e.g. 'hystkit fit TRAIN.csv THIS.csv' (fitted jointly)")
    if far_outside:
        status = "extrapolated"
    if command == "evaluate":
        return {
            "no_signal": f"{_EVALUATE_COLUMNS}: a sensor read from another column, or "
                         f"wired differently, carries nothing the model learnt",
            "extrapolated": "refitting on recordings that cover this range, e.g. 'hystkit fit "
                            "TRAIN.csv THIS.csv' (fitted jointly)",
        }.get(status, "refitting on recordings like these, e.g. 'hystkit fit TRAIN.csv "
                      "THIS.csv' (fitted jointly; without --model it chooses among small "
                      "models on held-out data)")
    if status == "no_signal":
        return _COLUMNS
    if command in ("select", "guided"):  # a selection (select, fit --model auto) refused
        centers = "--centers" if command == "select" else "--center"
        return {
            "worse_than_line": f"{centers} track (an offset that drifts) or one recording per "
                               f"run; if the straight line still wins, the sensor is linear "
                               f"enough for a straight-line calibration",
            "failed": "'hystkit fit DATA --model mpl --out m.json': one fit's own error says "
                      "what stops them",
            "skipped": "--budget with more seconds, or fewer samples (--resample HZ)",
        }.get(status, f"'hystkit fit DATA --model {model or 'NAME'}"
                      f"{'' if size is None else f' --size {size}'}' (the best candidate): "
                      f"its refusal names what failed and what to try")
    smaller = None if size is None or size <= 1 else size - 1
    if status == "on_bounds":
        if model == "mpl":
            fewer = f"--cells {smaller}" if smaller else "--cells 2"
            return (f"--model mpl-poly (a curved static curve in one cell) or {fewer}; "
                    f"{_AUTO} compares them")
        return (f"--size {smaller} (fewer parameters to pin) or {_AUTO}" if smaller
                else _AUTO)
    if status == "not_converged":
        return (f"--cells {smaller} (a smaller model settles within its evaluation budget) or "
                f"{_AUTO}" if smaller else f"another start (--init list) or {_AUTO}")
    if status == "collapsed":
        return ("--mode direct, or " + _AUTO if mode == "inverse"
                else f"{_AUTO}; if every model collapses, {_COLUMNS}")
    if status == "worse_than_line":
        return (f"{_AUTO}: {model or 'this model'} does no better than a straight line on "
                f"these data")
    if status == "no_limit":
        return "the fit without --no-limit (the stability limit keeps its Euler step bounded)"
    return _AUTO


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
    from .._read_options import ReadOptions

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


def read_training_files(args: argparse.Namespace) -> tuple[list, list]:
    """How each training file of ``args.data`` is read (`read_options`) and its recordings:
    one per file, or its pieces between time gaps (``--gaps split``: fitted jointly)."""
    from ..io import read_pieces, read_recording

    reading, recs = [], []
    for path in args.data:
        reading.append(read_options(args, path))
        if reading[-1].gaps == "split":
            recs += read_pieces(path, options=reading[-1])
        else:
            recs.append(read_recording(path, options=reading[-1]))
    return reading, recs


def read_options(args: argparse.Namespace, path=None):
    """The `hystkit.io.ReadOptions` of the options `add_read_options` added.

    With `path` (a recording), the settings file next to it (``my.toml`` for ``my.csv``,
    `hystkit.io.options_for`) comes first and the command line overrides it; the file used
    is printed once per command. Without, only the command line counts.
    """
    from .._read_options import ReadOptions

    if path is not None:
        from ..io import options_for, settings_for

        options, settings = options_for(path, given_read_options(args))
        shown = args.__dict__.setdefault("_settings_shown", set())  # once per command
        note = settings_for(path)[1] if settings is None else ""
        said = (f"reading {path} with the settings in {settings}" if settings is not None
                else f"reading {path} without its settings: {note}" if note else "")
        if said and said not in shown:
            shown.add(said)
            print(said, flush=True)
        _say_layout(args, path, options)
        return options
    try:
        return ReadOptions(**given_read_options(args))
    except ValueError as exc:  # already checked one by one while parsing; kept as a guard
        raise UsageError(str(exc)) from None


def _say_layout(args: argparse.Namespace, path, options) -> None:
    """Print once per file what was detected in a CSV file that a plain comma-separated one
    would not have (``reading my.csv: semicolon-separated, decimal comma``): a guess is said.
    A file that cannot be opened is left to the reader, whose message names the problem."""
    from pathlib import Path

    from ..io import csv_layout

    path = Path(path)
    shown = args.__dict__.setdefault("_layout_shown", set())
    if str(path) in shown or path.suffix.lower() != ".csv" or not path.is_file():
        return
    shown.add(str(path))
    try:
        notice = csv_layout(path, options).notice()
    except OSError:
        return
    if notice:
        print(f"reading {path}: {notice}", flush=True)


def read_recordings_args(args: argparse.Namespace, paths, *, need_position: bool = True
                         ) -> list:
    """The recordings of `paths` for a command that fits several jointly (``fit``): each
    read as `read_recording_args` does, and a file read with ``gaps = "split"`` (``--gaps
    split`` or its settings file) as its pieces between time gaps (`hystkit.io.read_pieces`,
    which says how many and where)."""
    from ..io import read_pieces, read_recording

    recordings = []
    for path in paths:
        options = read_options(args, path)
        if options.gaps == "split":
            recordings += read_pieces(path, need_position=need_position, options=options)
        else:
            recordings.append(read_recording(path, need_position=need_position,
                                             options=options))
    return recordings


def read_recording_args(args: argparse.Namespace, path, *, need_position: bool = True):
    """Read recording `path` with the command line's reading options and its settings file
    (`read_options`): what every command that reads a user's recording calls."""
    from ..io import read_recording

    return read_recording(path, need_position=need_position, options=read_options(args, path))
