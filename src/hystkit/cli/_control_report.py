"""The printed side of ``hystkit control``: the loop and its linearised verdict, the non-linear
tuning (with the held-out check), the experiment table and the noise study, from the records
:func:`hystkit.control.run_control` returns."""

from __future__ import annotations

import math

from ..control import SLOW_GROWTH_S, TYPICAL_RUN_S, slow_cell_words

__all__ = ["closed_loop", "duration", "fmt", "print_noise_study", "print_run", "print_table"]


def fmt(x: float | None, none: str = "n/a") -> str:
    """``x`` to 3 significant digits; ``none`` for a missing value."""
    return none if x is None else f"{x:.3g}"


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


def print_run(options, run) -> None:
    """The tuning (when asked), the loop and its linearised verdict."""
    if run.tuned is not None:
        _print_tuning(run.tuned, options.experiment)
    loop, models, margins = run.loop, run.setup.models, run.margins
    dob = f"{loop.dob.f_q:.3g} Hz" if loop.dob else "off"
    print(f"hystkit control: scheme {options.loop.scheme}"
          + (f", experiment {options.experiment}" if options.experiment else "")
          + f", DOB {dob}; sensor models in "
          f"{run.setup.fit_seconds:.1f} s (S_r: {models.info['sensor_source']}; compensator "
          f"and S_m: {models.info['training_source']})")
    p = loop.pid
    print(f"PID Kp = {p.kp:.4g}, Ti = {p.ti:.4g} s, Td = {p.td:.4g} s, Tf = {p.tf:.3g} s; "
          f"linearised at rest: crossover {fmt(margins.crossover_hz)} Hz, phase margin "
          f"{fmt(margins.phase_margin_deg)} deg, gain margin "
          f"{fmt(margins.gain_margin_db, 'inf')} dB")
    print(f"  closed loop {closed_loop(margins)}")  # the verdict on a line of its own


def _print_tuning(res, experiment: str) -> None:
    """``--tune-nonlinear``: before/after, and the held-out experiments (never seen by the
    search) beside them."""
    print(f"non-linear tuning ({experiment}, e_p {res.objective}, phase margin >= "
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


def print_noise_study(run, n) -> None:
    """``--noise``: the experiment without and with the noise, each without and with the DOB."""
    loop, dob = run.loop, run.noise_dob
    print(f"noise study: sensor SD {n.sensor:g} sensor units (= {n.sensor * loop.sensor_gain:.3g}"
          f" m through g_s), process SD {n.process:g} N, seed {n.seed}; DOB {dob.f_q:.3g} Hz")
    print(f"{'noise':<7}{'DOB':<5}{'case':<14}{'e_p,rms [m]':>13}{'e_p,max [m]':>13}"
          f"{'u rms [N]':>11}{'sensor noise SD':>17}")
    for r in run.noise_study["rows"]:
        print(f"{'yes' if r['noise'] else 'no':<7}{'on' if r['dob'] else 'off':<5}"
              f"{r['case']:<14}{fmt(r['e_p_rms']):>13}{fmt(r['e_p_max']):>13}"
              f"{fmt(r['u_rms']):>11}{fmt(r['sensor_noise_sd']):>17}"
              + ("" if r["bounded"] else "  UNBOUNDED"))


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
