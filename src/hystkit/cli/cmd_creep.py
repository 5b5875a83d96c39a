"""``hystkit creep``: a long step-and-hold experiment on the virtual sensor and each compensator's
creep error against the sensor's own creep term (issue 14.7)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import GUARD_EXIT, integer, number

__all__ = ["register"]


def _creep(args: argparse.Namespace) -> int:
    from ..io import check_output_folder
    from ..studies import CREEP_COLUMNS, CreepPlan, creep_experiment, output_names
    from .cmd_compare import _models, _sizes

    models = _models(args.models) if args.models else ["mpl", "pl"]
    sizes = _sizes(args.size)
    if args.out is not None:
        check_output_folder(args.out, output_names("creep"), args.force)
    hours = 0.2 if args.quick else args.hours
    plan = CreepPlan(hold_seconds=hours * 3600.0 / 3, amplitude_mm=args.amplitude)
    result = creep_experiment(plan, models=models, sizes=sizes, seed=args.seed,
                              progress=print)
    from ..studies import format_markdown, write_table

    columns = CREEP_COLUMNS + tuple((f"{m}_creep_error_pct", f"{m} creep error (%)")
                                    for m in models)
    print("\ncreep during each hold, in % of the step made up to t_a (the start of the "
          f"measurement, {plan.settle_seconds:g} s after the ramp); a model's creep error is "
          "its estimate's drift in % of the true step (the position does not move)")
    print(format_markdown(result["rows"], columns))
    summary = result["summary"]
    term = " / ".join(f"{h['physics_creep_pct']:.3g}" for h in summary)
    print(f"\ncreep error at the end of the holds, % of the step (the sensor's creep term: "
          f"{term} %):")
    for m in models:
        errors = " / ".join(f"{h[f'{m}_creep_error_pct']:.3g}" for h in summary)
        worst = max(abs(h[f"{m}_creep_error_mm"]) for h in summary)
        print(f"  {m}: {errors} % (at most {worst:.3g} mm)")
    sensor = result["sensor"]
    print(f"\nthe virtual sensor's creep is exponential (Prony time constants "
          f"{', '.join(f'{t:g}' for t in sensor['prony_taus_s'])} s), not log(t): after "
          f"{sensor['late_after_s']:g} s of a hold")
    for hold in result["summary"]:
        if hold["late_physics_creep_pct"] is None:
            print(f"  {hold['hold']}: the hold is shorter than that (use --hours)")
            continue
        errors = ", ".join(f"{m} {hold[f'late_{m}_creep_error_pct']:+.3g} %" for m in models)
        print(f"  {hold['hold']}: creep term {hold['late_physics_creep_pct']:+.3g} %, sensor "
              f"signal {hold['late_sensor_creep_pct']:+.3g} %, creep error {errors}")
    failed = [m for m, fit in result["fits"].items() if fit["status"] != "ok"]
    for m in failed:
        print(f"hystkit: warning: {m}: fit {result['fits'][m]['status']}: "
              f"{result['fits'][m]['status_message']}")
    if args.out is not None:
        paths = write_table(args.out, "creep", result, result["rows"], force=args.force)
        print(f"wrote {', '.join(str(p) for p in paths)}")
    return GUARD_EXIT if failed else 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``creep`` subcommand."""
    p = sub.add_parser("creep", help="long step-and-hold experiment on the virtual sensor: each "
                                     "compensator's creep error against the sensor's creep term")
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
    p.set_defaults(run=_creep)
