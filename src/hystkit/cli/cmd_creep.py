"""``hystkit creep``: a long step-and-hold experiment on the virtual sensor and each compensator's
creep error against the sensor's own creep term (issue 14.7)."""

from __future__ import annotations

import argparse

from ..io import check_output_folder
from ..studies import (
    CREEP_COLUMNS,
    CreepPlan,
    creep_experiment,
    format_markdown,
    output_names,
    write_table,
)
from ._common import GUARD_EXIT
from ._many_models import models_from, sizes_from

__all__ = ["run_creep"]


def run_creep(args: argparse.Namespace) -> int:
    """``hystkit creep``: the step-and-hold experiment and each compensator's creep error."""
    models = models_from(args.models) if args.models else ["mpl", "pl"]
    sizes = sizes_from(args.size)
    if args.out is not None:
        check_output_folder(args.out, output_names("creep"), args.force)
    hours = 0.2 if args.quick else args.hours
    plan = CreepPlan(hold_seconds=hours * 3600.0 / 3, amplitude_mm=args.amplitude)
    result = creep_experiment(plan, models=models, sizes=sizes, seed=args.seed,
                              progress=print)
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
