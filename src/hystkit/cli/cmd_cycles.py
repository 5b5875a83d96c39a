"""``hystkit cycles INPUT --out DIR``: per-gauge, per-cycle loops, loop area, offset and drift.

The document's figs. 4.13 and 4.16-4.17 and table 3.1 for one recording: the loops of dR1/R1,
dR2/R2 and dR1/R1 - dR2/R2 against the position for chosen cycles, and for every complete
cycle (minimum to minimum of the position) the loop area, the offset and its drift per cycle
and per hour. The input is a recording (``hystkit preprocess`` writes the gauge columns r1, r2,
dr1, dr2 beside position and sensor; without them only the sensor column is analysed) or, with
``--raw``, a raw scope recording, preprocessed first with the settings file next to it.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import cycle_table, plot_cycles
from ..errors import InputError
from ..io import (
    RawFormat,
    atomic_folder,
    check_output_folder,
    find_raw_config,
    read_other_columns,
    read_raw_config,
    write_json,
)
from ..preprocess import (
    PreprocessSettings,
    RawDataWarning,
    gauge_symmetry,
    parse_states,
    preprocess_raw,
    relative_change,
)
from ._common import UsageError
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["CYCLES_FILES", "TABLE_3_1", "run_cycles"]

CYCLES_FILES = ("cycles.csv", "cycles.json", "cycles.png", "cycles.svg")
# Table 3.1 of the document (R1 top, R2 bottom [kOhm], symmetry 2 (R1 - R2) / (R1 + R2) [%]);
# paper 9.1 gives sample 4 the other way round: 22.4 kOhm top, 15.7 kOhm bottom.
TABLE_3_1 = {"sample 0": (1.58, 2.78, -55.0), "sample 1": (15.0, 16.82, -11.0),
             "sample 2": (12.7, 28.2, -75.0), "sample 3": (14.3, 35.8, -86.0),
             "sample 4": (15.7, 22.4, -35.0)}
# The figures' default: five cycles spread over the recording (figs. 4.16-4.17).
_DEFAULT_DRAWN = 5


def _gauges_from_raw(path: Path) -> tuple[np.ndarray, ...]:
    """Preprocess the raw file with its settings file: t, x, r1, r2 (or None), sensor."""
    config = find_raw_config(path)
    if config is None:
        raise InputError(f"{path}: --raw needs the settings file "
                         f"{Path(path).with_suffix('.toml')} (bridge resistor and "
                         "supply; 'hystkit simulate-sensor --raw' writes it), or run "
                         "'hystkit preprocess' with --r-bridge/--v-supply and analyse its output")
    values = read_raw_config(config)
    values.pop("simulation", None)
    missing = [key for key in ("r_bridge", "v_supply") if key not in values]
    if missing:
        raise InputError(f"{config}: {' and '.join(missing)} not set; the bridge must be known "
                         "to turn voltages into resistances (eq. 4.3)")
    fmt_keys = ("fs", "n_samples", "time_unit", "skip_rows")
    try:
        fmt = RawFormat(columns=tuple(values.pop("columns", {}).items()),
                        **{k: values.pop(k) for k in fmt_keys if k in values})
        if "encoder_levels" in values:
            values["encoder_levels"] = tuple(values["encoder_levels"])
        if isinstance(values.get("encoder_states"), str | list):
            values["encoder_states"] = parse_states(values["encoder_states"])
        settings = PreprocessSettings(**values)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{config}: {exc}") from None
    print(f"preprocessing {path} with the settings in {config} ...", flush=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RawDataWarning)
        result = preprocess_raw(path, settings, fmt)
    for warning in caught:
        print(f"hystkit: warning: {warning.message}", file=sys.stderr)
    rec = result.recording
    return rec.time, rec.position, result.extra["r1"], result.extra["r2"], rec.sensor


def _gauges_from_recording(path: Path, reader: Reader) -> tuple:
    """Read a recording and its gauge columns r1, r2 (Ohm) when present."""
    rec = reader.recording(path)
    other = read_other_columns(path, rec.n_samples, reader.options(path))
    r1, r2 = other.get("r1"), other.get("r2")
    if r1 is None or r2 is None or r1.dtype.kind != "f" or r2.dtype.kind != "f":
        return rec.time, rec.position, None, None, rec.sensor
    for name, r in (("r1", r1), ("r2", r2)):
        bad = np.flatnonzero(~(np.isfinite(r) & (r > 0)))
        if bad.size:
            raise InputError(f"{path}: column {name!r} row {bad[0] + 1}: a gauge "
                             f"resistance must be a positive number, got {r[bad[0]]}")
    return rec.time, rec.position, r1, r2, rec.sensor


def _signals(r1, r2, sensor) -> dict:
    """dR/R per gauge about its mean (eq. 4.4-4.5) and their difference, else the sensor."""
    if r1 is None:
        return {"sensor": sensor}

    dr1, dr2 = relative_change(r1), relative_change(r2)
    return {"dR1/R1": dr1, "dR2/R2": dr2, "dR1/R1 - dR2/R2": dr1 - dr2}


def _drawn(requested: tuple[int, ...] | str | None, n_cycles: int, source: Path) -> list[int]:
    if requested == "all":
        return list(range(1, n_cycles + 1))
    if requested is None:
        return sorted({int(k) for k in np.round(np.linspace(1, n_cycles,
                                                            min(_DEFAULT_DRAWN, n_cycles)))})
    if requested[-1] > n_cycles:
        raise InputError(f"{source}: --cycles asks for cycle {requested[-1]}, but the recording "
                         f"has {n_cycles} complete cycle(s) (minimum to minimum of the position)")
    return list(requested)


def _gauge_summary(r1, r2) -> dict | None:
    if r1 is None:
        return None

    return {"r1_mean_kohm": float(r1.mean()) / 1e3, "r2_mean_kohm": float(r2.mean()) / 1e3,
            "symmetry_pct": 100.0 * gauge_symmetry(r1, r2),
            "document_table_3_1": {name: {"r1_kohm": a, "r2_kohm": b, "symmetry_pct": s}
                                   for name, (a, b, s) in TABLE_3_1.items()}}


def _summary(table, signals: dict) -> dict:
    out = {}
    for name in signals:
        drift = table.drift.get(name)
        out[name] = {
            "area_mean": float(table.area[name].mean()),
            "area_pct_mean": float(table.area_pct[name].mean()),
            "offset_first": float(table.offset[name][0]),
            "offset_last": float(table.offset[name][-1]),
            "drift_per_hour": None if drift is None else drift.per_hour,
            "drift_stderr_per_hour": None if drift is None else drift.stderr_per_hour,
            "drift_per_cycle": None if drift is None else drift.per_cycle,
            "drift_stderr_method": _SE_METHOD,
            "drift_residual_lag1": None if drift is None else drift.residual_lag1,
            "drift_n_effective": None if drift is None else drift.n_effective,
            "drift_half_slopes_per_hour": (None if drift is None or drift.linear is None else
                                           dict(zip(("first", "first_stderr", "second",
                                                     "second_stderr"),
                                                    drift.half_slopes_per_hour, strict=True))),
            "drift_linear": None if drift is None else drift.linear,
        }
    return out


_SE_METHOD = ("least-squares slope; i.i.d. standard error times sqrt((1 + r1) / (1 - r1)), "
              "r1 the residuals' lag-1 autocorrelation (AR(1) effective sample size)")


def _print(table, summary: dict, gauges: dict | None) -> None:
    print(f"{table.n_cycles} complete cycles (minimum to minimum of the position), "
          f"{table.t_start[0]:.4g} s to {table.t_stop[-1]:.4g} s")
    print(f"  {'signal':<18} {'area [mm·%]':>12} {'area eq.5.15':>13} {'drift [%/h]':>12} "
          f"{'± s.e.':>9} {'[%/cycle]':>10} {'resid. r1':>9}")
    for name, s in summary.items():
        rate, se, per_cycle, rho = (s["drift_per_hour"], s["drift_stderr_per_hour"],
                                    s["drift_per_cycle"], s["drift_residual_lag1"])
        rate_text = "" if rate is None else f"{100 * rate:.4g}"
        se_text = "" if se is None else f"{100 * se:.2g}"
        cycle_text = "" if per_cycle is None else f"{100 * per_cycle:.3g}"
        rho_text = "" if rho is None else f"{rho:.2f}"
        print(f"  {name:<18} {100 * s['area_mean']:>12.4g} {s['area_pct_mean']:>12.3g}% "
              f"{rate_text:>12} {se_text:>9} {cycle_text:>10} {rho_text:>9}")
    print("  (± s.e. allows for the residual lag-1 autocorrelation r1: AR(1) effective sample "
          "size n (1 - r1) / (1 + r1))")
    for name, s in summary.items():
        if s["drift_linear"] is False:
            h = s["drift_half_slopes_per_hour"]
            print(f"  {name}: drift not linear over the record; the rate is an average "
                  f"(first half {100 * h['first']:.3g} ± {100 * h['first_stderr']:.2g}, second "
                  f"half {100 * h['second']:.3g} ± {100 * h['second_stderr']:.2g} %/h)")
    if gauges is not None:
        doc = TABLE_3_1["sample 4"]
        print(f"  gauges (table 3.1): R1 = {gauges['r1_mean_kohm']:.4g} kOhm, R2 = "
              f"{gauges['r2_mean_kohm']:.4g} kOhm, 2(R1-R2)/(R1+R2) = "
              f"{gauges['symmetry_pct']:.3g} % (document, sample 4: R1 = {doc[0]:g}, "
              f"R2 = {doc[1]:g} kOhm, {doc[2]:g} %)")


def run_cycles(args: argparse.Namespace) -> int:
    """``hystkit cycles``: per-gauge loops and the per-cycle table of one recording."""
    reader = Reader(given_read_options(args))
    if args.raw and reader.given:
        raise UsageError("--raw reads the raw file with its .toml settings; the options for "
                         "reading recordings (--columns, --time-unit, ...) do not apply")
    check_output_folder(args.out, CYCLES_FILES, args.force, inputs=[args.input])
    t, x, r1, r2, sensor = (_gauges_from_raw(args.input) if args.raw
                            else _gauges_from_recording(args.input, reader))
    signals = _signals(r1, r2, sensor)
    try:
        table = cycle_table(t, x, signals, args.deadband)
    except ValueError as exc:
        raise InputError(f"{args.input}: {exc}") from None
    drawn = _drawn(args.cycles, table.n_cycles, args.input)
    summary = _summary(table, signals)
    gauges = _gauge_summary(r1, r2)
    _print(table, summary, gauges)
    fig = plot_cycles(x, signals, table, drawn)
    report = {"input": str(args.input), "raw": bool(args.raw), "n_samples": int(t.size),
              "deadband": args.deadband, "n_cycles": table.n_cycles, "cycles_drawn": drawn,
              "units": {"area": "mm * (dR/R)", "area_pct": "% of the unit square (eq. 5.15)",
                        "offset": "dR/R (about the recording mean)",
                        "drift_per_hour": "dR/R per hour", "drift_per_cycle": "dR/R"},
              "signals": summary, "gauges": gauges}
    with atomic_folder(args.out, args.force, CYCLES_FILES) as tmp:
        pd.DataFrame(table.rows()).to_csv(tmp / "cycles.csv", index=False)
        write_json(report, tmp / "cycles.json")
        fig.savefig(tmp / "cycles.png", dpi=120)
        fig.savefig(tmp / "cycles.svg")
    shown = (", ".join(map(str, drawn)) if len(drawn) <= 10
             else f"{len(drawn)} cycles, {drawn[0]} to {drawn[-1]}")
    print(f"wrote {args.out}/: {', '.join(CYCLES_FILES)} (cycles drawn: {shown})")
    return 0
