"""``hystkit settling LOG.csv --out DIR`` and ``hystkit simulate-settling --out LOG.csv``.

Sec. 3.5.1: a freshly printed trace's resistance rises, then drops for days. ``settling`` fits
each resistance column of a log with the settling law (rise then drop, or drop only; time
constants with standard errors) and gives the rest time until the fitted drift stays below a
threshold. ``simulate-settling`` writes such a log: the virtual sensor's gauges at rest from
the end of printing, and a printed and an annealed block of conductive filament.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import SettlingFitError, fit_settling, plot_settling, rest_time
from ..errors import InputError
from ..io import atomic_folder, atomic_output, check_output_folder, check_output_path, write_json
from ..sensors import simulate_settling_log
from ._common import failures_exit
from ._lab_options import HOURS_PER

__all__ = ["SETTLING_FILES", "SettlingOptions", "SimulateSettlingOptions", "read_log",
           "run_settling", "run_simulate_settling", "settling", "simulate_settling"]

SETTLING_FILES = ("settling.json", "settling.png", "settling.svg")


@dataclass(frozen=True)
class SettlingOptions:
    """``hystkit settling``'s options, as parsed: ``time_column`` None for ``time_h`` if the
    log has it, else ``time``; ``traces`` None for every column but the time."""

    log: Path
    out: Path
    time_column: str | None
    time_unit: str  # a key of HOURS_PER
    traces: tuple[str, ...] | None
    model: str  # "auto", "rise-drop" or "drop"
    threshold: float  # %/h
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> SettlingOptions:
        """The options of a parsed ``settling`` command line."""
        return cls(args.log, args.out, args.time_column, args.time_unit, args.traces,
                   args.model, args.threshold, args.force)


@dataclass(frozen=True)
class SimulateSettlingOptions:
    """``hystkit simulate-settling``'s options, as parsed."""

    out: Path
    hours: float
    interval: float  # minutes
    seed: int
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> SimulateSettlingOptions:
        """The options of a parsed ``simulate-settling`` command line."""
        return cls(args.out, args.hours, args.interval, args.seed, args.force)


def read_log(path: Path, time_column: str | None, time_unit: str,
             traces: tuple[str, ...] | None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Hours and the resistance columns [Ohm] of a CSV log; bad cells named by column and row."""

    if path.suffix.lower() != ".csv":
        raise InputError(f"{path}: a settling log is read as CSV (.csv), not "
                         f"{path.suffix or 'a file without extension'!r}")
    try:
        frame = pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError, pd.errors.ParserError,
            pd.errors.EmptyDataError) as exc:
        raise InputError(f"{path}: cannot read the log as CSV ({' '.join(str(exc).split())})") \
            from None
    if time_column is None:
        time_column = "time_h" if "time_h" in frame.columns else "time"
    wanted = traces if traces is not None else tuple(c for c in frame.columns
                                                     if c != time_column)
    for name in (time_column, *wanted):
        if name not in frame.columns:
            raise InputError(f"{path}: no column {name!r}; the log has "
                             f"{', '.join(map(repr, frame.columns))}")
    if not wanted:
        raise InputError(f"{path}: no resistance column besides {time_column!r}")
    columns = {}
    for name in (time_column, *wanted):
        values = pd.to_numeric(frame[name].str.strip(), errors="coerce").to_numpy(float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise InputError(f"{path}: column {name!r} row {bad[0] + 2}: expected a finite "
                             f"number, got {frame[name].iloc[bad[0]]!r}")
        columns[name] = values
    _warn_unit_suffix(time_column, time_unit)
    t_h = columns.pop(time_column) * HOURS_PER[time_unit]
    return t_h, columns


def _warn_unit_suffix(time_column: str, time_unit: str) -> None:
    """One warning line when the time column's suffix (``_h``, ``_s``...) names another unit."""
    suffix = time_column.rsplit("_", 1)[-1] if "_" in time_column else ""
    if suffix in HOURS_PER and suffix != time_unit:
        print(f"hystkit: warning: column {time_column!r} looks like {suffix!r} but "
              f"--time-unit is {time_unit!r}; times are read as {time_unit!r} (give "
              f"--time-unit {suffix} if the column's name is right)", file=sys.stderr)


def run_settling(args: argparse.Namespace) -> int:
    """``hystkit settling``: the settling law fitted to each trace of a log."""
    return settling(SettlingOptions.from_args(args))


def settling(opts: SettlingOptions) -> int:
    """Fit the settling law to each trace of ``opts.log``; print and write the fits."""
    check_output_folder(opts.out, SETTLING_FILES, opts.force, inputs=[opts.log])
    t_h, columns = read_log(opts.log, opts.time_column, opts.time_unit, opts.traces)
    results, drawn, failed = {}, {}, []
    for name, r in columns.items():
        try:
            fit = fit_settling(t_h, r, opts.model)
            rest = rest_time(fit, opts.threshold)
        except SettlingFitError as exc:
            print(f"  {name}: NOT FITTED: {exc}")
            results[name] = {"fitted": False, "reason": str(exc)}
            drawn[name] = (t_h, r, None, None)
            failed.append(name)
            continue
        except ValueError as exc:
            raise InputError(f"{opts.log}: column {name!r}: {exc}") from None
        results[name] = {"fitted": True, "fit": fit.to_dict(), "rest_time": rest.to_dict()}
        drawn[name] = (t_h, r, fit, rest)
        _print_fit(name, fit, rest)
    fig = plot_settling(drawn)
    report = {"log": str(opts.log), "time_unit_read": opts.time_unit, "model": opts.model,
              "threshold_pct_per_hour": opts.threshold,
              "law": "R(t) = r_final + drop exp(-t/tau_drop_h) - rise exp(-t/tau_rise_h), "
                     "t in hours since the log's t = 0",
              "document": "sec. 3.5.1: rest 2-3 days before measuring non-annealed traces",
              "traces": results}
    with atomic_folder(opts.out, opts.force, SETTLING_FILES) as tmp:
        write_json(report, tmp / "settling.json")
        fig.savefig(tmp / "settling.png", dpi=120)
        fig.savefig(tmp / "settling.svg")
    print(f"wrote {opts.out}/: {', '.join(SETTLING_FILES)}")
    return failures_exit(failed, "trace(s)")


def _print_fit(name: str, fit, rest) -> None:
    p, se = fit.params, fit.stderr
    taus = f"tau_drop = {p['tau_drop_h']:.4g} ± {se['tau_drop_h']:.2g} h"
    if "rise" in p:
        taus += (f", tau_rise = {p['tau_rise_h']:.4g} ± {se['tau_rise_h']:.2g} h, rise "
                 f"{p['rise']:.4g} Ohm")
    rest_text = (f"{rest.hours:.4g} h ({rest.hours / 24:.3g} d)"
                 + ("" if rest.stderr_h is None else f" ± {rest.stderr_h:.2g} h")
                 + (" EXTRAPOLATED past the log's end" if rest.extrapolated else ""))
    print(f"  {name}: {fit.model}: R_final = {p['r_final']:.5g} ± {se['r_final']:.2g} Ohm, "
          f"drop {p['drop']:.4g} Ohm, {taus}; rms {fit.rms:.3g} Ohm; rest time "
          f"(drift |dR/dt| / R_final < {rest.threshold_pct_per_hour:g} %/h) {rest_text}")


def run_simulate_settling(args: argparse.Namespace) -> int:
    """``hystkit simulate-settling``: the virtual sensor's settling log, written."""
    return simulate_settling(SimulateSettlingOptions.from_args(args))


def simulate_settling(opts: SimulateSettlingOptions) -> int:
    """Write the virtual sensor's settling log to ``opts.out``."""
    check_output_path(opts.out, opts.force, formats=(".csv",), what="a settling log")
    log = simulate_settling_log(opts.hours, opts.interval, opts.seed)
    with atomic_output(opts.out, opts.force) as tmp:
        pd.DataFrame(log).to_csv(tmp, index=False)
    print(f"wrote {opts.out}: {log['time_h'].size} readings over {opts.hours:g} h, every "
          f"{opts.interval:g} min: time_h, r1, r2 (virtual sensor at rest from printing), "
          "block, block_annealed [Ohm]")
    return 0
