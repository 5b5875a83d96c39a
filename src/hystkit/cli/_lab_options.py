"""Options of the lab commands: preprocess, the raw mode of simulate-sensor, cycles, settling,
simulate-settling, spectrum and datasets. Light, as every options module
(`hystkit.cli._commands`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import deferred
from ._lookups import dataset_names, roles
from ._option_types import integer, number
from ._read_args import add_read_options

__all__ = ["HOURS_PER", "cycles_options", "datasets_options",
           "preprocess_options", "settling_options", "simulate_settling_options",
           "spectrum_options"]

# Units of a settling log's time column, in hours
HOURS_PER = {"s": 1 / 3600, "min": 1 / 60, "h": 1.0, "d": 24.0}

_positive = number(0, low_open=True)
# Samples per chunk: below ~1000 the filters' edge handling dominates a chunk; above 2^27 a
# chunk of float64 channels alone passes a gigabyte.
_chunk_size = integer(1024, 2**27)


def _levels(text: str) -> tuple[float, ...]:
    try:
        values = tuple(number()(v) for v in text.split(","))
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"must be four comma-separated voltages, got {text!r}")
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"must be four comma-separated voltages, got {text!r}")
    return values


def _states(text: str) -> str:
    from ..preprocess import parse_states  # numpy: only when the option is given

    try:
        parse_states(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text

def _cycle_list(text: str) -> tuple[int, ...] | str:
    if text.strip() == "all":
        return "all"
    parts = [p.strip() for p in text.split(",")]
    if not parts or not all(p.isascii() and p.isdigit() and int(p) >= 1 for p in parts):
        raise argparse.ArgumentTypeError(f"expected 'all' or cycle numbers 1, 2, ... "
                                         f"separated by commas, e.g. 1,5,20; got {text!r}")
    return tuple(sorted({int(p) for p in parts}))

def _names(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if not names:
        raise argparse.ArgumentTypeError(f"expected column names separated by commas, "
                                         f"got {text!r}")
    return names

def preprocess_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("raw", type=Path, help="raw recording: time, v1, v2 and encoder or "
                   "enc_a/enc_b (CSV, Parquet or .mat)")
    p.add_argument("--out", type=Path, required=True, help="CSV or Parquet file to write")
    p.add_argument("--report", type=Path, help="JSON report (default: --out with .json)")
    p.add_argument("--config", type=Path, help="TOML settings (default: the raw file's stem "
                   "with .toml, if it exists)")
    p.add_argument("--r-bridge", type=_positive, metavar="OHM", help="bridge resistor (eq. 4.2)")
    p.add_argument("--v-supply", type=_positive, metavar="V", help="bridge supply V0 (eq. 4.2)")
    p.add_argument("--supply-channel", action=argparse.BooleanOptionalAction, default=None,
                   help="use the measured supply column v0 in eq. 4.3 instead of --v-supply "
                        "(sec. 4.2.1's reference channel; removes supply drift); "
                        "--no-supply-channel uses the nominal V0 even if the settings file "
                        "asks for the column (default: the settings file, else nominal)")
    p.add_argument("--um-per-count", type=_positive, metavar="UM",
                   help="encoder resolution (default 5; eq. 9.16 calibrates 5.1)")
    p.add_argument("--position-offset", dest="position_offset_mm", type=number(), metavar="MM",
                   help="added to the position, which counts from the first sample (default 0)")
    p.add_argument("--fs-out", type=_positive, metavar="HZ", help="output rate (default 40)")
    p.add_argument("--cutoff", type=_positive, metavar="HZ",
                   help="zero-phase Butterworth cut-off (default 20, eq. 4.1)")
    p.add_argument("--order", type=integer(1, 10), metavar="N",
                   help="Butterworth order, 1 to 10 (default 2)")
    p.add_argument("--fs", type=_positive, metavar="HZ",
                   help="scope sample rate: needed without a time column, checked against one")
    p.add_argument("--time-unit", choices=["s", "ms", "us", "ns"],
                   help="unit of the time column (default s)")
    p.add_argument("--encoder-states", type=_states, metavar="AB,AB,AB,AB",
                   help="A/B states of the merged levels, ascending (default 00,01,10,11)")
    p.add_argument("--encoder-levels", type=_levels, metavar="V,V,V,V",
                   help="the four merged levels (default: found in the data)")
    p.add_argument("--encoder-dwell", dest="encoder_dwell_us", type=_positive, metavar="US",
                   help="a new encoder level must last this long (default 4 us, >= 2 samples)")
    p.add_argument("--illegal", choices=["continue", "hold"],
                   help="a double transition adds 2 counts in the direction of travel "
                        "(continue, default) or nothing (hold); both are counted and reported")
    p.add_argument("--remove-mean", action="store_true", help="subtract the mean of position "
                   "and sensor")
    p.add_argument("--normalise", action="store_true",
                   help="divide position and sensor by their max |.| (eq. 5.10)")
    p.add_argument("--chunk-size", type=_chunk_size, metavar="N",
                   help="samples per chunk, 1024 to 2^27 (default 262144); memory grows with "
                        "it, the result does not depend on it")

def cycles_options(p: argparse.ArgumentParser) -> None:
    _input_and_folder(p, "input", "recording (time, position, sensor; with r1, r2 from 'hystkit "
                      "preprocess' per gauge) or, with --raw, a raw scope recording",
                      "cycles.csv, cycles.json, cycles.png, cycles.svg")
    p.add_argument("--raw", action="store_true",
                   help="INPUT is a raw scope recording (v1, v2, encoder) with its .toml "
                        "settings: preprocess it first, as 'hystkit preprocess' would")
    p.add_argument("--cycles", type=_cycle_list, metavar="K,K,...",
                   help="cycles to draw, numbered 1.. over the complete cycles, or 'all' "
                        "(fig. 4.13: every cycle, coloured by time; default: 5 spread over the "
                        "recording)")
    p.add_argument("--deadband", type=number(0, 0.5, high_open=True), default=0.01,
                   metavar="F", help="a position reversal counts after the position came back "
                   "by this fraction of its range (default 0.01)")
    add_read_options(p)

def settling_options(p: argparse.ArgumentParser) -> None:
    _input_and_folder(p, "log", "CSV log: a time column and one resistance column [Ohm] per "
                      "trace, t = 0 at the end of printing",
                      "settling.json, settling.png, settling.svg")
    p.add_argument("--time-column", metavar="NAME",
                   help="the time column (default: time_h if present, else time)")
    p.add_argument("--time-unit", choices=list(HOURS_PER), default="h",
                   help="unit of the time column (default h)")
    p.add_argument("--traces", type=_names, metavar="NAME,...",
                   help="resistance columns to fit (default: every column but time)")
    p.add_argument("--model", choices=["auto", "rise-drop", "drop"], default="auto",
                   help="rise then drop (5 parameters), drop only (3), or auto: both, the "
                        "lower BIC kept (default)")
    p.add_argument("--threshold", type=number(0, 100, low_open=True), default=0.1,
                   metavar="PCT_PER_H", help="rest time: the fitted drift |dR/dt| / R_final "
                   "stays below this for good (default 0.1 %%/h)")



def simulate_settling_options(s: argparse.ArgumentParser) -> None:
    s.add_argument("--out", type=Path, required=True, help="CSV file to write")
    s.add_argument("--hours", type=number(0.2, 24 * 365, low_open=False), default=96.0,
                   metavar="H", help="length of the log (default 96)")
    s.add_argument("--interval", type=number(0.01, 1440), default=1.0, metavar="MIN",
                   help="minutes between readings (default 1, as in sec. 3.5.1)")
    s.add_argument("--seed", type=integer(0, 2**32 - 1), default=0, help="noise seed "
                   "(default 0)")

def spectrum_options(p: argparse.ArgumentParser) -> None:
    _input_and_folder(p, "input", "raw scope recording (v1, v2, encoder) or a recording (time, "
                      "sensor; dr1, dr2 used when present)", "spectrum.json and spectrum.png")
    p.add_argument("--kind", choices=["auto", "raw", "data"], default="auto",
                   help="raw or recording (default auto: raw when bridge settings are given "
                        "or stored beside the file, or the file has v1 and v2)")
    p.add_argument("--segment", type=_positive, metavar="S",
                   help="Welch segment length (default 20 s, bins 0.05 Hz apart, or half the "
                        "recording when shorter; at least 3 segments are needed)")
    p.add_argument("--margin", type=_positive, default=10.0, metavar="DB",
                   help="a line is signal when this far above the local noise floor "
                        "(default 10 dB)")
    p.add_argument("--safety", type=number(1), default=2.5, metavar="X",
                   help="suggested cut-off = X * f_signal (default 2.5, the document's "
                        "20 Hz / 8 Hz)")
    p.add_argument("--floor-width", type=_positive, default=4.0, metavar="HZ",
                   help="running-median width of the local noise floor (default 4 Hz)")
    p.add_argument("--order", type=integer(1, 10), metavar="N",
                   help="one-way Butterworth order of the proposed filter (default 2, eq. 4.1)")
    p.add_argument("--compare", type=_positive, metavar="HZ",
                   help="also overlay this cut-off (default: the settings' cutoff, else 20 Hz, "
                        "the document's)")
    p.add_argument("--fs-analysis", type=_positive, default=1000.0, metavar="HZ",
                   help="raw: decimate to about this rate before the Welch PSD (default 1000)")
    p.add_argument("--config", type=Path, help="raw: TOML settings (default: the raw file's "
                   "stem with .toml, if it exists)")
    p.add_argument("--r-bridge", type=_positive, metavar="OHM", help="raw: bridge resistor "
                   "(eq. 4.2)")
    p.add_argument("--v-supply", type=_positive, metavar="V", help="raw: bridge supply V0")
    p.add_argument("--supply-channel", action=argparse.BooleanOptionalAction, default=None,
                   help="raw: use the measured supply column v0 in eq. 4.3 (default: the "
                        "settings file, else the nominal V0)")
    p.add_argument("--fs", type=_positive, metavar="HZ",
                   help="raw: scope sample rate, needed without a time column")
    p.add_argument("--time-unit", choices=["s", "ms", "us", "ns"],
                   help="raw: unit of the time column (default s)")

def _input_and_folder(p: argparse.ArgumentParser, name: str, input_help: str,
                      files: str) -> None:
    """A lab command's input file `name` and its ``--out`` folder of `files`."""
    p.add_argument(name, type=Path, help=input_help)
    p.add_argument("--out", type=Path, required=True, help=f"folder for {files}")


def datasets_options(p: argparse.ArgumentParser) -> None:
    # The parent gets a --force too (the CLI adds one to every top-level command); the child's
    # default is SUPPRESS so that 'datasets --force export' is not reset to False by it.
    p.add_argument("--force", action="store_true", help="overwrite existing output files")
    actions = p.add_subparsers(dest="datasets_command", required=True)

    _dataset_command(actions, "list", "the data sets (or the runs of one) and whether the "
                         "shared data are here", "list this data set's runs", nargs="?")
    _dataset_command(actions, "show", "where a data set's files come from (repository, "
                         "commit, licence, credit) and where to put them",
                         "the data set (see 'hystkit datasets list')")
    q = _dataset_command(actions, "export", "write one run as a time, position, sensor "
                         "recording (CSV, Parquet or .mat) plus a .json sidecar",
                         "the data set to export (see 'hystkit datasets list')", root=False)
    q.add_argument("--variant", help="the run (default: the data set's default; see "
                                     "'hystkit datasets list NAME')")
    q.add_argument("--segment", help="only this named segment of the run")
    deferred(q.add_argument("--role", default="inverse",
                   help="inverse (default): position = system input, sensor = output, so "
                        "'hystkit fit' learns output -> input; forward: the other way round"),
             choices=roles)
    q.add_argument("--excerpt", action="store_true",
                   help="use the excerpt shipped with hystkit instead of the shared data")
    _add_root(q)
    q.add_argument("--out", type=Path, required=True,
                   help="file to write, by its extension: .csv, .parquet or .mat (MATLAB: one "
                        "variable per column, with units)")
    q.add_argument("--force", action="store_true", default=argparse.SUPPRESS,
                   help="overwrite existing output files")


def _dataset_command(actions, name: str, help_text: str, name_help: str, *,
                     nargs: str | None = None, root: bool = True) -> argparse.ArgumentParser:
    """``datasets NAME``'s parser: its run function (``cmd_datasets:run_NAME``), the data
    set's name and (`root`) ``--root``."""
    q = actions.add_parser(name, help=help_text)
    q.set_defaults(run=f"cmd_datasets:run_{name}")
    deferred(q.add_argument("name", nargs=nargs, help=name_help), choices=dataset_names)
    if root:
        _add_root(q)
    return q


def _add_root(q: argparse.ArgumentParser) -> None:
    q.add_argument("--root", type=Path, help="shared data root (default: $HYSTKIT_SHARED_DATA "
                                             "or a shared/data folder found above)")
