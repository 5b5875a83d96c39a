"""Options of the commands that fit many models: compare, generalize, select, batch, pl-search,
creep, table, report, export and warm. Light, as every options module (`hystkit.cli._commands`)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from ._common import deferred
from ._lookups import (
    compensation_value,
    default_centers,
    experiment_names,
    family_info,
    family_names,
)
from ._lookups import pl_default_grid as _default_grid
from ._option_types import integer, number, positive_int
from ._own_layout import add_trained_note
from ._read_args import add_read_options

__all__ = ["FORMATS", "add_parallel_options", "batch_options", "compare_options",
           "creep_options", "export_options", "generalize_options", "pl_search_options",
           "report_options", "select_options", "table_options", "warm_options"]

FORMATS = ("png", "svg", "pdf")  # as studies.FIGURE_FORMATS, without loading the library
_SEED = integer(0, 2**32 - 1)


def add_parallel_options(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--scheduler`` (with ``--scheduler-timeout``): where the command's
    independent pieces run."""
    g = p.add_argument_group("parallel runs (results are the same as a serial run's)")
    x = g.add_mutually_exclusive_group()
    x.add_argument("--workers", type=positive_int, default=None, metavar="N",
                   help="worker processes of a local Dask cluster (default: one per core); "
                        "1: serial, in this process, without Dask")
    x.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (every "
                        "worker needs the same hystkit version)")
    g.add_argument("--scheduler-timeout", type=number(0, 3600, low_open=True), default=None,
                   metavar="SECONDS",
                   help="seconds to reach --scheduler, connection and Dask's handshake "
                        "together (default 20)")


def _models_help() -> str:
    return f"comma-separated models (default: all: {', '.join(family_names())})"


def compare_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("data_fit", type=Path, help="recording to fit every model on")
    p.add_argument("data_val", type=Path, help="recording to score them on (not seen by the "
                   "fits)")
    _every_model_options(p, "", "folder for compare.json and compare.mat (the same table for "
                         "MATLAB)")


def generalize_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", type=Path, nargs="*",
                   help="your recordings (at least two, one rate); default: the virtual sensor")
    _every_model_options(p, "; default: each family's own", "output folder (default "
                         "hystkit-generalize): generalize.json, generalize.mat, generalize.png")


def _every_model_options(p: argparse.ArgumentParser, size_default: str, out_help: str) -> None:
    """The options of a command that fits every family (compare, generalize) after its data."""
    deferred(p.add_argument("--models"), help=_models_help)
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help=f"model size, e.g. --size mpl=3 (repeatable{size_default})")
    p.add_argument("--out", type=Path, help=out_help)
    add_read_options(p)
    add_parallel_options(p)


def batch_options(p: argparse.ArgumentParser) -> None:
    p.description = ("Fit every sensor of a manifest or a folder; OUT gets models/<id>.json, "
                     "sensors/<id>.json and results.parquet/.csv. Rerunning into the same OUT "
                     "skips the sensors already finished (same options and recordings) and "
                     "fits the others; failed sensors are listed and do not stop the batch "
                     "(exit 3 if any sensor failed or a fit failed its guards).")
    p.add_argument("source", type=Path,
                   help="manifest (.csv: columns sensor, fit, validate [, model, size, mode, "
                        "center], several recordings separated by ';'; .toml: [defaults] and "
                        "[[sensor]] tables with id, fit, validate, options) or a folder: each "
                        "sub-folder is a sensor with fit* and val* recordings, each recording "
                        "directly in it a sensor fitted on its first half and validated on "
                        "its second half")
    p.add_argument("--out", type=Path, required=True, help="batch folder (created, or resumed)")
    deferred(p.add_argument("--model", default="mpl"), choices=family_names,
             help=lambda: "model family where the manifest names none (default mpl)")
    p.add_argument("--size", type=positive_int, default=None,
                   help="model size where the manifest gives none (default: the family's)")
    deferred(p.add_argument("--mode", default="direct"),
             choices=lambda: compensation_value("MODES"),
             help=lambda: "direct or inverse where the manifest gives none (default direct)")
    deferred(p.add_argument("--center", default=None),
             choices=lambda: compensation_value("CENTERS"),
             help=lambda: f"centring where the manifest gives none (default "
                          f"{compensation_value('DEFAULT_CENTER')})")
    p.add_argument("--force", action="store_true",
                   help="refit every sensor, also those finished in OUT (and use an OUT that "
                        "is not a batch folder)")
    add_read_options(p)
    add_parallel_options(p)


def select_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", type=Path, nargs="+",
                   help="training recording(s), one rate; give one per run: each is then held "
                        "out in turn (left-out recording), the only check of offsets that "
                        "change between runs")
    p.add_argument("--out", type=Path, required=True, help="model JSON file of the winner")
    p.add_argument("--report", type=Path,
                   help="folder for selection.json/.csv/.png (default: OUT's name + -selection)")
    p.add_argument("--models", help="comma-separated families (default: all)")
    deferred(p.add_argument("--centers"), default=default_centers,
             help=lambda: f"comma-separated centrings to try (default {default_centers()})")
    add_read_options(p)
    add_parallel_options(p)
    # the option's name before issue 13; --workers N does the same
    p.add_argument("--jobs", type=positive_int, dest="workers", help=argparse.SUPPRESS)


def _list(parse: Callable[[str], float], what: str) -> Callable[[str], tuple]:
    """An option type: comma-separated values, each checked by `parse`."""

    def parse_all(text: str) -> tuple:
        try:
            return tuple(parse(v) for v in text.split(","))
        except argparse.ArgumentTypeError as exc:
            raise argparse.ArgumentTypeError(f"expected comma-separated {what}: {exc}") \
                from None

    return parse_all


def _cells(text: str) -> tuple:
    """An option type: comma-separated cell counts up to the Power-Law family's
    ``max_size`` (the registry's record: no kernels load)."""
    largest = family_info()["pl"].max_size
    return _list(integer(1, largest), f"cell counts 1 to {largest}")(text)


_cells.__name__ = "parse_all"  # argparse names the type in some messages, as before
_powers = _list(number(1, 100, low_open=True), "powers p in (1, 100]")
_bases = _list(integer(1, 50), "basis counts 1 to 50")
_smoothing = _list(number(0), "smoothing weights >= 0")


def pl_search_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", type=Path, help="fitting recording (time, position, sensor)")
    deferred(p.add_argument("--n", type=_cells, help="cell counts N"),
             default=lambda: _default_grid("n"))
    deferred(p.add_argument("--p", type=_powers, help="powers p (> 1)"),
             default=lambda: _default_grid("p"))
    deferred(p.add_argument("--m", type=_bases, help="numbers M of output basis functions"),
             default=lambda: _default_grid("m"))
    deferred(p.add_argument("--s", type=_smoothing, help="smoothing weights S (>= 0)"),
             default=lambda: _default_grid("s"))
    p.add_argument("--direction", choices=("position-to-sensor", "sensor-to-position"),
                   default="position-to-sensor",
                   help="model the sensor (the document's toolbox, default) or a direct "
                        "compensator")
    p.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    add_parallel_options(p)
    add_read_options(p)


def creep_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--hours", type=number(0.01, 24.0), default=1.0,
                   help="total length of the three holds (+A, -A, 0) in hours, at most 24 "
                        "(default 1; the sensor runs at 400 Hz: about 250 MB and 6 s per hour)")
    p.add_argument("--amplitude", type=number(0.0, 3.0, low_open=True), default=2.0,
                   metavar="MM", help="held position A in mm (default 2)")
    p.add_argument("--models", help="comma-separated models fitted as direct compensators on "
                                    "the noise experiment (default mpl,pl)")
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=2 (repeatable)")
    p.add_argument("--seed", type=integer(0, 2**32 - 1), default=3,
                   help="seed of the hold recording (default 3; the fit uses seed 1)")
    p.add_argument("--quick", action="store_true", help="0.2 h of holds (seconds, for tests)")
    p.add_argument("--out", type=Path, help="folder for creep.json (everything) and creep.csv "
                                            "(the table); default: print only")


def _table_output(p: argparse.ArgumentParser, stem: str) -> None:
    p.add_argument("--out", type=Path, help=f"folder for {stem}.json (everything) and "
                   f"{stem}.csv (the table); default: print only")
    # SUPPRESS: a --force given before the table number (hystkit table --force 5.4) stays
    p.add_argument("--force", action="store_true", default=argparse.SUPPRESS,
                   help="overwrite existing output files")


def table_options(p: argparse.ArgumentParser) -> None:
    tables = p.add_subparsers(dest="table", required=True, metavar="{5.4,2.2}")

    q = tables.add_parser("5.4", help="SINAD and loop area of encoder, R1, R2, R1-R2, fitted "
                                      "model and compensated signal (raw recordings)")
    q.add_argument("--model", default="mpl",
                   help="model family with an inverse (default mpl, as the document)")
    q.add_argument("--size", type=positive_int, default=None,
                   help="model size (default: 1 cell for mpl, as the document; the family's "
                        "default size for another model)")
    q.add_argument("--fit-seed", type=_SEED, default=1, help="seed of the fitting recording")
    q.add_argument("--val-seed", type=_SEED, default=2, help="seed of the validation recording")
    q.add_argument("--scope-rate", type=number(2e3, 2e5), default=20e3, metavar="HZ",
                   help="raw scope rate, at most 2e5 (default 2e4; each 200 s recording takes "
                        "4 kB per Hz of temporary disk: the document's 1.98e6 would need 16 GB)")
    q.add_argument("--quick", action="store_true",
                   help="40 s of each recording at a 10 kHz scope rate, whatever --scope-rate "
                        "says (a few seconds)")
    _table_output(q, "table_5_4")
    q.set_defaults(run="cmd_table:run_table_5_4")

    q = tables.add_parser("2.2", help="min / mean / variance of the RMSE over repeated "
                                      "training and test recordings")
    q.add_argument("--repeats", type=integer(2, 10_000), default=10,
                   help="training/test pairs (default 10)")
    q.add_argument("--seed", type=_SEED, default=1,
                   help="repeat r uses seeds SEED + 2r (training) and SEED + 2r + 1 (test)")
    deferred(q.add_argument("--excitation", default="noise",
                            help="experiment of every recording (default noise: a new "
                                 "trajectory per seed)"), choices=experiment_names)
    q.add_argument("--models", help="comma-separated models (default pl,pi,mpl: the "
                                    "document's PL and Kuhnen, and the mPL)")
    q.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=2 (repeatable)")
    q.add_argument("--quick", action="store_true", help="3 repeats (seconds, for tests)")
    _table_output(q, "table_2_2")
    q.set_defaults(run="cmd_table:run_table_2_2")


def report_options(p: argparse.ArgumentParser) -> None:
    p.description = ("MODEL.json RECORDING... : the model file's provenance, fit (parameters "
                     "with standard errors, bound hits, status), deployable and oracle scores, "
                     "loops with the error against the position, whole time series with the "
                     "error. FOLDER... : the tables and figures of compare, generalize, "
                     "select --report or control output folders. Figures are embedded; the "
                     "page loads nothing from outside.")
    p.add_argument("inputs", type=Path, nargs="+", metavar="INPUT",
                   help="a model file (from 'hystkit fit') followed by one or more recordings "
                        "(CSV/Parquet/.mat with a position column), or one or more result "
                        "folders")
    p.add_argument("--out", type=Path, required=True, help="HTML file to write (.html)")
    p.add_argument("--figures", type=Path, metavar="DIR",
                   help="also write every figure as PNG (and --format) files into DIR")
    p.add_argument("--format", choices=FORMATS, default="png",
                   help="format of the figure files beside PNG: svg or pdf (default png only; "
                        "needs --figures)")
    add_read_options(p)
    add_trained_note(p)


def export_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit'")
    p.add_argument("--lang", choices=("c", "matlab"), default="c",
                   help="target language (default: c)")
    p.add_argument("--out", type=Path, required=True,
                   help="folder to write (refused if it exists, unless --force)")
    p.add_argument("--double", action="store_true",
                   help="C only: double arithmetic (default float, for single-precision FPUs); "
                        "refused with --lang matlab, whose code is always double")
    p.add_argument("--name", help="name of the generated functions (default: from the model "
                                  "file name)")
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=None,
                   help="nominal coverage of the exported prediction band, in (0, 1) (default: "
                        "the model's own, 0.90 unless fitted otherwise); refused for a model "
                        "without a band")


def warm_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--models", metavar="NAME,...",
                   help="only these model families (default: all)")
    p.add_argument("--no-control", action="store_true", help="skip the control loop")
