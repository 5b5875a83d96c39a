"""The reporting side of ``hystkit control``: the experiment table, the linearised verdict, the
non-linear tuning (its options, with the held-out check) and the noise study. Kept apart from
the command so each module stays small."""

from __future__ import annotations

import argparse
import math

from ..control import SLOW_GROWTH_S, TYPICAL_RUN_S, slow_cell_words
from ._common import UsageError

__all__ = ["closed_loop", "fmt", "noise_study", "print_table", "resolve_tune_options", "tune"]

# defaults of the --tune-nonlinear options (None in the parser: given or not is seen)
TUNE_DEFAULTS = {"tune_objective": "rms", "tune_budget": 300, "min_phase_margin": 30.0,
                 "min_gain_margin": 6.0}


def fmt(x: float | None, none: str = "n/a") -> str:
    """``x`` to 3 significant digits; ``none`` for a missing value."""
    return none if x is None else f"{x:.3g}"


def resolve_tune_options(args: argparse.Namespace) -> None:
    """Refuse the ``--tune-nonlinear`` options without it (one line); fill in defaults."""
    given = [f"--{k.replace('_', '-')}" for k in TUNE_DEFAULTS if getattr(args, k) is not None]
    if given and not args.tune_nonlinear:
        verb = "applies" if len(given) == 1 else "apply"
        raise UsageError(f"{', '.join(given)} only {verb} with --tune-nonlinear")
    for key, value in TUNE_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)


def closed_loop(margins) -> str:
    """The linearised closed loop's stability in words."""
    if margins.closed_loop_stable:
        return "stable"
    if margins.marginal:
        return ("marginally stable (a pole on the unit circle, to within the rounding of its "
                "eigenvalue: a state the linearised loop neither corrects nor amplifies, e.g. a "
                "sticking element at rest or a double integrator)")
    if getattr(margins, "slow_cell", None) is not None:
        # slower than the slowest cell: a marginal mode, not a blow-up (the cause stays in
        # metrics.json's "linear")
        return slow_cell_words(margins.max_pole_radius, margins.growth_time_s,
                               margins.slow_cell, margins.slow_cell_s, TYPICAL_RUN_S)
    cause = f"; {margins.cause}" if margins.cause else ""
    if margins.growth_time_s >= SLOW_GROWTH_S:
        # a real but glacial instability (a slow cell's zero beyond z = 1): say what it means
        factor = math.exp(TYPICAL_RUN_S / margins.growth_time_s)
        return (f"unstable only over days (max |pole| {margins.max_pole_radius:.10f}: grows "
                f"e-fold in {duration(margins.growth_time_s)}, a factor {factor:.4f} over a "
                f"{TYPICAL_RUN_S / 60:g}-minute run{cause})")
    return (f"UNSTABLE (max |pole| {margins.max_pole_radius:.10f}: grows e-fold in "
            f"{duration(margins.growth_time_s)}{cause})")


def duration(seconds: float) -> str:
    """A duration as ``8.1e+05 s (9.38 days)``: seconds, and in hours or days when that long.

    Parameters
    ----------
    seconds : float
        The duration [s].

    Returns
    -------
    str
        Seconds to three significant digits; from two hours on also hours, from two days on
        days.
    """
    for unit, size in (("days", 86400.0), ("hours", 3600.0)):
        if seconds >= 2 * size:
            return f"{seconds:.3g} s ({seconds / size:.3g} {unit})"
    return f"{seconds:.3g} s"


def _change(before: float | None, after: float | None) -> str:
    if before is None or after is None or before == 0:
        return "n/a"
    return f"{100 * (after / before - 1):+.1f} %"


def tune(args: argparse.Namespace, loop):
    """``--tune-nonlinear``: the PID tuned on the non-linear loop; before/after printed, and
    the held-out experiments (never seen by the search) beside them."""
    from ..control import tune_nonlinear

    try:
        res = tune_nonlinear(loop, args.experiment, objective=args.tune_objective,
                             min_phase_margin=args.min_phase_margin,
                             min_gain_margin_db=args.min_gain_margin, noise=args.noise,
                             max_evaluations=args.tune_budget)
    except ValueError as exc:
        raise UsageError(f"--tune-nonlinear: {exc}") from None
    print(f"non-linear tuning ({args.experiment}, e_p {res.objective}, phase margin >= "
          f"{res.min_phase_margin:g} deg, gain margin >= {res.min_gain_margin_db:g} dB on the "
          f"loop linearised at rest, the only stability check): {res.n_evaluations} runs, "
          f"{res.n_margin_checks} linearisations, {res.seconds:.1f} s")
    for name, p, cost, m in (("before", res.pid_start, res.cost_start, res.margins_start),
                             ("after", res.pid, res.cost, res.margins)):
        print(f"  {name:<7}Kp = {p.kp:.4g}, Ti = {p.ti:.4g} s, Td = {p.td:.4g} s: e_p "
              f"{res.objective} {cost:.4g} m (in-sample); phase margin "
              f"{fmt(m.phase_margin_deg)} deg, gain margin "
              f"{fmt(m.gain_margin_db, 'inf')} dB")
    if not res.improved:
        print("  nothing better within the constraints: the start gains are kept")
    _print_held_out(res)
    return res


def _print_held_out(res) -> None:
    if not res.held_out:
        return
    print(f"  held-out (not seen by the search): e_p {res.objective} [m] before -> after")
    for r in res.held_out:
        seed = "" if r["seed"] is None else f", noise seed {r['seed']}"
        print(f"    {r['experiment'] + seed + ': ' + r['case']:<34}"
              f"{fmt(r['before'], 'unbounded'):>10} -> {fmt(r['after'], 'unbounded'):<10}"
              f"{_change(r['before'], r['after']):>9}"
              + ("  (the tuned run itself)" if r["repeats_tuned_run"] else ""))


def noise_study(args: argparse.Namespace, loop) -> dict:
    """``--noise``: the experiment without and with the noise, each without and with the DOB
    (the loop's own, else one from ``design_dob``); the table printed, the rows returned."""
    from ..control import design_dob
    from ..control import noise_study as study

    try:
        dob = loop.dob or design_dob(loop)
    except ValueError as exc:
        raise UsageError(f"--noise: the DOB comparison needs a DOB: {exc}") from None
    rows = study(args.experiment, loop, args.noise, dob)
    n = args.noise
    print(f"noise study: sensor SD {n.sensor:g} sensor units (= {n.sensor * loop.sensor_gain:.3g}"
          f" m through g_s), process SD {n.process:g} N, seed {n.seed}; DOB {dob.f_q:.3g} Hz")
    print(f"{'noise':<7}{'DOB':<5}{'case':<14}{'e_p,rms [m]':>13}{'e_p,max [m]':>13}"
          f"{'u rms [N]':>11}{'sensor noise SD':>17}")
    for r in rows:
        print(f"{'yes' if r['noise'] else 'no':<7}{'on' if r['dob'] else 'off':<5}"
              f"{r['case']:<14}{fmt(r['e_p_rms']):>13}{fmt(r['e_p_max']):>13}"
              f"{fmt(r['u_rms']):>11}{fmt(r['sensor_noise_sd']):>17}"
              + ("" if r["bounded"] else "  UNBOUNDED"))
    return {"dob_f_q": dob.f_q, "noise": n.to_dict(), "rows": rows}


def print_table(metrics: dict) -> None:
    """The experiment's cases, one row each (``metrics`` of ``ExperimentResult.metrics``)."""
    print(f"{'case':<14}{'e_p,max [m]':>12}{'e_p,mean [m]':>14}{'e_p,rms [m]':>13}"
          f"{'tracking rms':>14}{'bounded':>9}{'compile s':>11}{'simulation s':>14}")
    for label, m in metrics["cases"].items():
        row = (f"{label:<14}{fmt(m.get('e_p_max')):>12}{fmt(m.get('e_p_mean')):>14}"
               f"{fmt(m.get('e_p_rms')):>13}{fmt(m.get('tracking_rms')):>14}"
               f"{'yes' if m['bounded'] else 'NO':>9}{m['compile_seconds']:>11.3f}"
               f"{m['seconds']:>14.4f}")
        if "e_p_max_during" in m:
            row += (f"  |e_p| max 2.0-2.2 s {fmt(m['e_p_max_during'])} m, "
                    f"after 2.5 s {fmt(m['e_p_max_after'])} m")
        if not m["bounded"]:
            row += f"  stopped at t = {m['stop_time']:.3f} s: {m['stop_reason']}"
        print(row)
    if "document" in metrics:
        d = metrics["document"]
        print(f"document ({d['source']}): e_p,max {d['e_p_max']:.3g} m, e_p,mean "
              f"{d['e_p_mean']:.4g} m")
