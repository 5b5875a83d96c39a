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
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError
from ._common import failures_exit, integer, number

if TYPE_CHECKING:
    import numpy as np

__all__ = ["SETTLING_FILES", "register"]

SETTLING_FILES = ("settling.json", "settling.png", "settling.svg")
_HOURS_PER = {"s": 1 / 3600, "min": 1 / 60, "h": 1.0, "d": 24.0}


def _names(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if not names:
        raise argparse.ArgumentTypeError(f"expected column names separated by commas, "
                                         f"got {text!r}")
    return names


def read_log(path: Path, time_column: str | None, time_unit: str,
             traces: tuple[str, ...] | None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Hours and the resistance columns [Ohm] of a CSV log; bad cells named by column and row."""
    import numpy as np
    import pandas as pd

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
    t_h = columns.pop(time_column) * _HOURS_PER[time_unit]
    return t_h, columns


def _warn_unit_suffix(time_column: str, time_unit: str) -> None:
    """One warning line when the time column's suffix (``_h``, ``_s``...) names another unit."""
    suffix = time_column.rsplit("_", 1)[-1] if "_" in time_column else ""
    if suffix in _HOURS_PER and suffix != time_unit:
        print(f"hystkit: warning: column {time_column!r} looks like {suffix!r} but "
              f"--time-unit is {time_unit!r}; times are read as {time_unit!r} (give "
              f"--time-unit {suffix} if the column's name is right)", file=sys.stderr)


def _settling(args: argparse.Namespace) -> int:
    from ..analysis import SettlingFitError, fit_settling, plot_settling, rest_time
    from ..io import atomic_folder, check_output_folder, write_json

    check_output_folder(args.out, SETTLING_FILES, args.force, inputs=[args.log])
    t_h, columns = read_log(args.log, args.time_column, args.time_unit, args.traces)
    results, drawn, failed = {}, {}, []
    for name, r in columns.items():
        try:
            fit = fit_settling(t_h, r, args.model)
            rest = rest_time(fit, args.threshold)
        except SettlingFitError as exc:
            print(f"  {name}: NOT FITTED: {exc}")
            results[name] = {"fitted": False, "reason": str(exc)}
            drawn[name] = (t_h, r, None, None)
            failed.append(name)
            continue
        except ValueError as exc:
            raise InputError(f"{args.log}: column {name!r}: {exc}") from None
        results[name] = {"fitted": True, "fit": fit.to_dict(), "rest_time": rest.to_dict()}
        drawn[name] = (t_h, r, fit, rest)
        _print_fit(name, fit, rest)
    fig = plot_settling(drawn)
    report = {"log": str(args.log), "time_unit_read": args.time_unit, "model": args.model,
              "threshold_pct_per_hour": args.threshold,
              "law": "R(t) = r_final + drop exp(-t/tau_drop_h) - rise exp(-t/tau_rise_h), "
                     "t in hours since the log's t = 0",
              "document": "sec. 3.5.1: rest 2-3 days before measuring non-annealed traces",
              "traces": results}
    with atomic_folder(args.out, args.force, SETTLING_FILES) as tmp:
        write_json(report, tmp / "settling.json")
        fig.savefig(tmp / "settling.png", dpi=120)
        fig.savefig(tmp / "settling.svg")
    print(f"wrote {args.out}/: {', '.join(SETTLING_FILES)}")
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


def _simulate_settling(args: argparse.Namespace) -> int:
    import pandas as pd

    from ..io import atomic_output, check_output_path
    from ..sensors import simulate_settling_log

    check_output_path(args.out, args.force, formats=(".csv",), what="a settling log")
    log = simulate_settling_log(args.hours, args.interval, args.seed)
    with atomic_output(args.out, args.force) as tmp:
        pd.DataFrame(log).to_csv(tmp, index=False)
    print(f"wrote {args.out}: {log['time_h'].size} readings over {args.hours:g} h, every "
          f"{args.interval:g} min: time_h, r1, r2 (virtual sensor at rest from printing), "
          "block, block_annealed [Ohm]")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``settling`` and ``simulate-settling`` to the ``hystkit`` parser."""
    p = sub.add_parser("settling", help="fit the resistance settling of freshly printed traces "
                       "and the rest time before use (sec. 3.5.1)")
    p.add_argument("log", type=Path, help="CSV log: a time column and one resistance column "
                   "[Ohm] per trace, t = 0 at the end of printing")
    p.add_argument("--out", type=Path, required=True,
                   help="folder for settling.json, settling.png, settling.svg")
    p.add_argument("--time-column", metavar="NAME",
                   help="the time column (default: time_h if present, else time)")
    p.add_argument("--time-unit", choices=list(_HOURS_PER), default="h",
                   help="unit of the time column (default h)")
    p.add_argument("--traces", type=_names, metavar="NAME,...",
                   help="resistance columns to fit (default: every column but time)")
    p.add_argument("--model", choices=["auto", "rise-drop", "drop"], default="auto",
                   help="rise then drop (5 parameters), drop only (3), or auto: both, the "
                        "lower BIC kept (default)")
    p.add_argument("--threshold", type=number(0, 100, low_open=True), default=0.1,
                   metavar="PCT_PER_H", help="rest time: the fitted drift |dR/dt| / R_final "
                   "stays below this for good (default 0.1 %%/h)")
    p.set_defaults(run=_settling)

    s = sub.add_parser("simulate-settling", help="write a resistance log from printing on: the "
                       "virtual sensor's gauges at rest and printed/annealed blocks")
    s.add_argument("--out", type=Path, required=True, help="CSV file to write")
    s.add_argument("--hours", type=number(0.2, 24 * 365, low_open=False), default=96.0,
                   metavar="H", help="length of the log (default 96)")
    s.add_argument("--interval", type=number(0.01, 1440), default=1.0, metavar="MIN",
                   help="minutes between readings (default 1, as in sec. 3.5.1)")
    s.add_argument("--seed", type=integer(0, 2**32 - 1), default=0, help="noise seed "
                   "(default 0)")
    s.set_defaults(run=_simulate_settling)
