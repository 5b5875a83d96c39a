"""``hystkit creep``: a long step-and-hold experiment on the virtual sensor and each compensator's
creep error against the sensor's own creep term (issue 14.7)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

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

__all__ = ["CreepOptions", "creep", "run_creep"]


@dataclass(frozen=True)
class CreepOptions:
    """``hystkit creep``'s options, as parsed: ``hours`` of holds as given (``quick``: 0.2 h
    whatever it says)."""

    hours: float
    amplitude: float  # mm
    models: str | None
    sizes: tuple[str, ...]  # --size MODEL=N, as given
    seed: int
    quick: bool
    out: Path | None
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> CreepOptions:
        """The options of a parsed ``creep`` command line."""
        return cls(args.hours, args.amplitude, args.models, tuple(args.size), args.seed,
                   args.quick, args.out, args.force)


def run_creep(args: argparse.Namespace) -> int:
    """``hystkit creep``: the step-and-hold experiment and each compensator's creep error."""
    return creep(CreepOptions.from_args(args))


def creep(opts: CreepOptions) -> int:
    """Run the step-and-hold experiment; print (and write) each compensator's creep error."""
    models = models_from(opts.models) if opts.models else ["mpl", "pl"]
    sizes = sizes_from(opts.sizes)
    if opts.out is not None:
        check_output_folder(opts.out, output_names("creep"), opts.force)
    hours = 0.2 if opts.quick else opts.hours
    plan = CreepPlan(hold_seconds=hours * 3600.0 / 3, amplitude_mm=opts.amplitude)
    result = creep_experiment(plan, models=models, sizes=sizes, seed=opts.seed,
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
    if opts.out is not None:
        paths = write_table(opts.out, "creep", result, result["rows"], force=opts.force)
        print(f"wrote {', '.join(str(p) for p in paths)}")
    return GUARD_EXIT if failed else 0
