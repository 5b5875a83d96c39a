"""The ``hystkit`` subcommands as a table: one row per command, nothing imported to list them.

A row names the command, its one-line help (``hystkit --help`` shows it), the function that
adds its options and the function that runs it, each as ``"module:function"`` inside
``hystkit.cli``. Building the parser imports the options function of the chosen command only
(options modules are light: option values that need the library are computed when shown); the
run function's module is imported after the command line parsed, so a ``cmd_*`` module imports
what it uses at its top.

A command with subcommands of its own (``table 5.4``, ``datasets list``) has no run function in
its row: its options function sets each one's (``set_defaults(run="module:function")``).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["COMMANDS", "Command", "command", "resolve"]


@dataclass(frozen=True)
class Command:
    """One subcommand: its name, one-line help, options function and run function."""

    name: str
    help: str
    options: str  # "module:function": add_options(parser)
    run: str | None = None  # "module:function" taking the parsed namespace


def resolve(reference: str) -> Callable:
    """The function ``"module:function"`` names (a module of ``hystkit.cli``), imported now."""
    module, _, name = reference.partition(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), name)


COMMANDS = (
    Command("batch", "fit many sensors: one model file each and one results table",
            "_study_options:batch_options", "cmd_batch:run_batch_command"),
    Command("compare", "fit every model on one recording, score on another",
            "_study_options:compare_options", "cmd_compare:run_compare"),
    Command("generalize", "train on each recording, test on each (default: the four "
            "virtual-sensor excitations)", "_study_options:generalize_options",
            "cmd_compare:run_generalize"),
    Command("control", "closed-loop position control with a hysteretic sensor: the "
            "document's ch. 7 experiments", "_control_options:control_options",
            "cmd_control:run_control_command"),
    Command("simulate-sensor", "record an experiment on the virtual sensor",
            "_core_options:simulate_sensor_options", "cmd_simulate:run_simulate_sensor"),
    Command("fit", "fit a compensator to a recording", "_core_options:fit_options",
            "cmd_fit:run_fit"),
    Command("compensate", "add a position_estimate column (and flags) to a recording",
            "_core_options:compensate_options", "cmd_core:_compensate"),
    Command("evaluate", "score a compensator on a recording", "_core_options:evaluate_options",
            "cmd_core:_evaluate"),
    Command("demo", "the main job on the built-in virtual sensor", "_core_options:demo_options",
            "cmd_simulate:run_demo"),
    Command("creep", "long step-and-hold experiment on the virtual sensor: each "
            "compensator's creep error against the sensor's creep term",
            "_study_options:creep_options", "cmd_creep:run_creep"),
    Command("cycles", "per-gauge loops of chosen cycles; loop area, offset and drift per cycle "
            "and per hour (figs. 4.16-4.17, table 3.1)", "_lab_options:cycles_options",
            "cmd_cycles:run_cycles"),
    Command("datasets", "public hysteresis data sets: list, export as a recording",
            "_lab_options:datasets_options"),
    Command("export", "write a fitted compensator as dependency-free C99 or as MATLAB/Octave "
            "code", "_study_options:export_options", "cmd_export:run_export"),
    Command("pl-search", "exhaustive N, p, M, S search of the Power-Law model (sec. 2.2, table "
            "5.1)", "_study_options:pl_search_options", "cmd_pl_search:run_pl_search"),
    Command("preprocess", "raw scope recording (v1, v2, encoder) -> position and dR/R at 40 Hz",
            "_lab_options:preprocess_options", "cmd_preprocess:run_preprocess"),
    Command("report", "one self-contained HTML page of a fit on your recordings, or of compare "
            "/ generalize / select / control output folders", "_study_options:report_options",
            "cmd_report:run_report"),
    Command("select", "choose model family, size, mode and centring, each validated on "
            "held-out data as it will be used", "_study_options:select_options",
            "cmd_select:run_select"),
    Command("settling", "fit the resistance settling of freshly printed traces and the rest "
            "time before use (sec. 3.5.1)", "_lab_options:settling_options",
            "cmd_settling:run_settling"),
    Command("simulate-settling", "write a resistance log from printing on: the virtual "
            "sensor's gauges at rest and printed/annealed blocks",
            "_lab_options:simulate_settling_options", "cmd_settling:run_simulate_settling"),
    Command("spectrum", "Welch PSD of each gauge and the differential signal with a suggested "
            "Butterworth cut-off (fig. 4.10)", "_lab_options:spectrum_options",
            "cmd_spectrum:run_spectrum"),
    Command("stability", "local stability of a fitted model of any family (linearised step; "
            "eq. 5.18-5.28 for the mPL), or with --control a loop's global stability",
            "_control_options:stability_options", "cmd_stability:run_stability"),
    Command("stream", "compensate live: time,sensor lines in (stdin, a file or a serial "
            "port), time,position_estimate,flags lines out", "_stream_options:stream_options",
            "cmd_stream:run_stream"),
    Command("table", "the reference document's tables 5.4 and 2.2 measured on the virtual "
            "sensor, the document's numbers beside them", "_study_options:table_options"),
    Command("warm", "compile the numba kernels of fit, stream, compare and control ahead, "
            "once per installation", "_study_options:warm_options", "cmd_warm:run_warm"),
)

_BY_NAME = {row.name: row for row in COMMANDS}


def command(name: str | None) -> Command | None:
    """The row of subcommand `name`, None for no such command."""
    return _BY_NAME.get(name)  # type: ignore[arg-type]
