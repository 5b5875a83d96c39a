"""Options of the core subcommands: simulate-sensor, fit, compensate, evaluate, demo.

Light: option values that need the library (family names, centring modes, experiments) are
computed when their command is parsed or its help shown (`hystkit.cli._common.deferred`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import deferred, integer, number, positive_float, positive_int, size_limit, slope_cap
from ._fit_cost_options import add_cost_options
from ._fit_start_options import add_start_options
from ._lookups import compensation_value, experiment_names, families, family_info
from ._own_layout import add_trained_note
from ._read_args import add_read_options

__all__ = ["COMPENSATE_NAMES_NOTE", "DEFAULT_MODEL", "GUIDED_HELP", "GUIDED_MODEL",
           "add_simulation_options", "compensate_options", "demo_options", "evaluate_options",
           "fit_options", "model_options_given", "simulate_sensor_options"]

# fit's --model value for the guided fit (issue 27.5)
GUIDED_MODEL = "auto"
GUIDED_HELP = ("mpl with 1, 2 and 3 cells, mpl-poly, pi and pl, each fitted and scored on "
               "held-out data as select does, the best usable one written with its band and "
               "the choice explained in three lines (about 15-30 s for 10,000 samples on 2 "
               "cores)")
# fit's options that name one model's structure, start or cost: refused with --model auto
_MODEL_OPTIONS = {"cells": ("--cells", None), "slope_cap": ("--slope-cap", None),
                  "p": ("--p", None), "m": ("--m", None), "s": ("--s", None),
                  "init": ("--init", None), "no_limit": ("--no-limit", False),
                  "weight_sum_max": ("--weight-sum-max", None), "loss": ("--loss", "linear"),
                  "f_scale": ("--f-scale", None), "weights": ("--weights", None)}


def model_options_given(args: argparse.Namespace) -> list[str]:
    """The options of one named model on `args` (``--cells``, ``--init``, ``--loss``, ...)."""
    return [option for dest, (option, unset) in _MODEL_OPTIONS.items()
            if getattr(args, dest, unset) != unset]

def _add_centring_options(p: argparse.ArgumentParser) -> None:
    deferred(p.add_argument("--center"), choices=lambda: compensation_value("CENTERS"),
             default=lambda: compensation_value("DEFAULT_CENTER"))
    p._actions[-1].help = ("sensor offset: fit = the training offsets (default); tare = the level "
                        "of the first --tare-seconds of each recording, device at rest; track = "
                        "a causal low-pass drift tracker (time constant --track-seconds); "
                        "recording = ORACLE, the paper's protocol (whole-recording mean, not "
                        "causal); none")
    deferred(p.add_argument("--tare-seconds", type=positive_float),
             default=lambda: compensation_value("DEFAULT_TARE_SECONDS"),
             help=lambda: f"tare window at the start of each recording [s] (default "
                          f"{compensation_value('DEFAULT_TARE_SECONDS'):g})")
    deferred(p.add_argument("--track-seconds", type=positive_float),
             default=lambda: compensation_value("DEFAULT_TRACK_SECONDS"),
             help=lambda: f"drift-tracker time constant [s] (default "
                          f"{compensation_value('DEFAULT_TRACK_SECONDS'):g}); slower sensor "
                          f"content than ~1/(2 pi T) is taken for drift")


def _add_level(p: argparse.ArgumentParser) -> None:
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=None,
                   help="nominal coverage of the prediction band, in (0, 1) (default: the "
                        "model's own, 0.90 unless fitted otherwise)")


def _add_rest_position(p: argparse.ArgumentParser) -> None:
    p.add_argument("--rest-position", type=number(), default=None,
                   help="tare centring: position [mm] during the tare window (default: where "
                        "the device rested in training)")


_MODEL_HELP = "model file written by fit or select (.json or .mat)"
# fit's model without --model: the guided first fit (issue 27.5); tests and docs that mean one
# mPL fit say --model mpl (the guided fit takes 15-30 s where one fit takes 1-3 s)
DEFAULT_MODEL = GUIDED_MODEL

# The reading options' note of compensate, whose output keeps the input's names
COMPENSATE_NAMES_NOTE = ("the output keeps the input's column names and time unit, the "
                         "estimate named after the position column")


def add_simulation_options(p: argparse.ArgumentParser) -> None:
    """simulate-sensor options for the sensor (both modes) and the raw mode."""
    p.add_argument("--age-hours", type=number(0), metavar="H",
                   help="hours since printing: the resistance still settles (sec. 3.5.1; "
                        "default 48)")
    p.add_argument("--asymmetry", type=number(), metavar="S",
                   help="gauge symmetry 2(R1-R2)/(R1+R2) of the base resistances "
                        "(default 0.35: 22.4 / 15.7 kOhm)")
    p.add_argument("--raw", action="store_true",
                   help="write the raw scope recording (time, v1, v2, encoder) and its .toml "
                        "settings instead of the 40 Hz recording")
    p.add_argument("--scope-rate", type=number(0, 1e8, low_open=True), metavar="HZ",
                   help="raw: scope sample rate (default 1e6; the document: 1.98e6, 6.25e6)")
    p.add_argument("--duration", type=positive_float, metavar="S",
                   help="raw: only the first S seconds of the experiment")
    p.add_argument("--encoder", choices=["merged", "ab"],
                   help="raw: one merged 4-level channel (default) or enc_a, enc_b")
    p.add_argument("--r-bridge", type=positive_float, metavar="OHM",
                   help="raw: bridge resistor (default 10000)")
    p.add_argument("--v-supply", type=positive_float, metavar="V", help="raw: bridge supply "
                   "(default 2)")
    p.add_argument("--glitches", type=integer(0, 10**6), metavar="N",
                   help="raw: hide N encoder states (each an illegal double transition)")
    p.add_argument("--supply-drift", type=number(0, 1, high_open=True), metavar="FRACTION",
                   help="raw: the bridge supply drifts as V0 (1 + FRACTION sin(2 pi t / P)) "
                        "(default 0: a steady supply; 0.01 is a 1 %% drift)")
    p.add_argument("--supply-drift-period", type=positive_float, metavar="S",
                   help="raw: period P of the bridge supply drift (default 30)")
    p.add_argument("--supply-channel", action="store_true", default=None,
                   help="raw: also record the bridge supply as a column v0 (sec. 4.2.1's "
                        "reference channel); the .toml then sets supply_channel = true")
    p.add_argument("--truth", type=Path, metavar="FILE",
                   help="raw: also write the exact position and dR/R (differential and per gauge, "
                        "dr1, dr2) at 40 Hz here")



def simulate_sensor_options(p: argparse.ArgumentParser) -> None:
    deferred(p.add_argument("--excitation", required=True,
                            help="the experiment of the document to record (ch. 4, table 5.5)"),
             choices=experiment_names)
    p.add_argument("--seed", type=integer(0, 2**32 - 1), default=0,
                   help="random seed, 0 to 2^32 - 1 (default 0)")
    p.add_argument("--out", type=Path, required=True, help="CSV or Parquet file to write")
    add_simulation_options(p)
    p.add_argument("--gain-drift", type=number(-0.9, 10.0), default=None, metavar="FRACTION",
                   help="multiply the sensor signal by a gain rising linearly from 1 to "
                        "1 + FRACTION over the run (0.1: +10 %%; for 'hystkit stream --adapt')")
    p.add_argument("--references-every", type=number(0, 1e6, low_open=True), default=None,
                   metavar="S", help="add a 'reference' column: the true position at one random "
                   "sample in each S seconds, empty elsewhere (the occasional references of "
                   "'hystkit stream --adapt')")


def fit_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", type=Path, nargs="+",
                   help="recording(s): time, position, sensor (CSV/Parquet/.mat); several are "
                        "fitted jointly, each with its own initial state and tare")
    # The registry's names and the guided fit's as the choices: checking a name imports that
    # family only.
    deferred(p.add_argument("--model", default=None), choices=lambda: [*families(),
                                                                        GUIDED_MODEL],
             help=lambda: "; ".join([*(f"{f.name}: {f.title}" for f in family_info().values()),
                                     f"{GUIDED_MODEL}: a guided first fit, {GUIDED_HELP}"])
             + f" (default {DEFAULT_MODEL}; mpl when --cells or another option of a named "
               f"model is given)")
    p.add_argument("--budget", type=number(1, 24 * 3600), default=None, metavar="SECONDS",
                   help=f"--model {GUIDED_MODEL} only: seconds for the whole selection "
                        f"(default 60); a candidate not validated within half of it is "
                        f"skipped, said so")
    deferred(p.add_argument("--cells", "--size", type=positive_int, default=None),
             help=lambda: "model size: " + "; ".join(f"{f.name}: {f.size_help} (default "
                                                     f"{f.default_size}, at most "
                                                     f"{size_limit(f)})"
                                                     for f in family_info().values()))
    p.add_argument("--mode", default="direct",
                   help="direct: fit sensor->position (paper 9.2); inverse: fit "
                        "position->sensor and invert it (paper 9.1)")
    deferred(p._actions[-1], choices=lambda: compensation_value("MODES"))
    _add_centring_options(p)
    p.add_argument("--slope-cap", type=slope_cap, default=None,
                   help="families whose structure takes an Euler slope cap (given for another, "
                        "the error names them): cap on the step gain f'·dt of their non-linear "
                        "elements, in [0.001, 2), default 1 (eq. 5.28-5.29; a family may allow "
                        "less, and its docs page says what it caps)")
    p.add_argument("--p", type=number(1, low_open=True), default=None, metavar="P",
                   help="pl only: power p of the cells, > 1 (default 21; 'hystkit pl-search' "
                        "searches it)")
    p.add_argument("--m", type=integer(1, 1000), default=None, metavar="M",
                   help="pl only: number M of output basis functions, 1 to 1000 (default 1)")
    p.add_argument("--s", type=number(0), default=None, metavar="S",
                   help="pl only: smoothing weight S >= 0 (default 0.001)")
    p.add_argument("--out", type=Path, required=True,
                   help="model file to write: .json, or .mat (a MATLAB struct with every field "
                        "of the JSON file; evaluate and compensate read both)")
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=0.90,
                   help="nominal coverage of the prediction band stored in the model (default "
                        "0.90); the band is calibrated on held-out runs: left-out recordings, or "
                        "interleaved cycles of one recording (docs/band.md)")
    p.add_argument("--no-band", action="store_true",
                   help="fit without a prediction band (the band refits the model on each "
                        "validation fold: about four times the fit's time)")
    add_start_options(p)
    add_cost_options(p)
    add_read_options(p)


def compensate_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", type=Path, help=_MODEL_HELP)
    p.add_argument("data", type=Path, help="recording to compensate (CSV/Parquet/.mat): time "
                                           "and sensor; position is optional")
    _add_rest_position(p)
    p.add_argument("--out", type=Path, required=True,
                   help="file to write, by its extension: .csv, .parquet or .mat (MATLAB: one "
                        "variable per column, with column_names and units); the input's "
                        "columns under its own names, time in its own unit, then the estimate "
                        "named after the position column (position_estimate, or x_mm_estimate "
                        "for a column x_mm), its band position_lower and position_upper (if "
                        "the model has one; x_mm_lower, x_mm_upper) and the flags "
                        "sensor_outside, estimate_outside")
    _add_level(p)
    add_read_options(p)
    # compensate writes the input's names: not the group's note that outputs use hystkit's
    add_trained_note(p, COMPENSATE_NAMES_NOTE)


def evaluate_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("model", type=Path, help=_MODEL_HELP)
    p.add_argument("data", type=Path, help="recording with the true position (CSV/Parquet/.mat)")
    p.add_argument("--json", type=Path, help="also write the scores to this JSON file (.json)")
    p.add_argument("--out", type=Path,
                   help="also write the scores to this file, by its extension: .json or .mat "
                        "(MATLAB: one variable per score; missing scores are [])")
    _add_rest_position(p)
    _add_level(p)
    add_read_options(p)
    add_trained_note(p)


def demo_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, help="output folder (default: a new timestamped one)")
    p.add_argument("--cells", type=positive_int, default=3,
                   help="mPL cells (default 3: 11 parameters, as the document's model)")
    p.add_argument("--raw", action="store_true",
                   help="also run the lab chain on raw scope files: simulate-sensor --raw -> "
                        "preprocess -> fit -> evaluate (sine, 50 kHz; about 10 s more)")

