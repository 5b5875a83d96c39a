"""``hystkit stability MODEL.json``: local stability of a fitted model of any family;
``hystkit stability --control --scheme ...``: global stability of a control loop.

Every family: eigenvalues of the linearised step (``hystkit.models.stability_report``) at rest
over the input range and along a driven run. The mPL families add the document's per-cell
analysis (eq. 5.18-5.28: knees, rest points, ``f' dt``).

With ``--control`` the loop of ``hystkit control`` (same options) is examined beyond its
linearisation: slope sectors of the hysteretic blocks (on the trained sine and in the
simulated experiment, their hull tested) and the discrete circle criterion
(``hystkit.control.global_stability``; a proof for a constant reference, within that sector),
with a simulation that shows divergence when there is.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from .. import compensation, models
from .. import control as hc
from .. import io as hio
from ..errors import InputError
from ..signals import exponential_chirp
from ._control_options import StabilityOptions
from ._read_args import given_read_options
from ._reading import Reader
from .cmd_control import loop_error, loop_setup

__all__ = ["run_stability"]


def _probe_input(dt: float) -> np.ndarray:
    """The paper's chirp (0.1 -> 3 Hz over 100 s) at unit amplitude: the normalised training
    range [-1, 1] at every rate the experiments use."""
    return exponential_chirp(np.arange(round(100.0 / dt)) * dt, amplitude=1.0)


def _model_input(comp: compensation.Compensator, path: Path, reader: Reader) -> np.ndarray:
    """The fitted model's input on a recording, normalised as at fit time (eq. 5.10): the
    sensor signal for a direct compensator, the position for an inverse one's forward model."""
    rec = reader.recording(path, need_position=comp.mode == "inverse")
    comp.check_sampling(rec)
    if comp.mode == "direct":
        return comp.normalised_sensor(rec.sensor)
    sc = comp.scaling
    return (rec.position - sc.position_offset) / sc.position_scale


def _print_cells(details: dict) -> None:
    for k, ((lo, hi), rest) in enumerate(zip(details["knees"], details["rest"], strict=True)):
        rest_text = ", ".join(f"v* = {v:.4g} (f'·dt = {s:.4g})"
                              for v, s in zip(rest["v"], rest["slope_dt"], strict=True))
        print(f"  cell {k + 1}: knees x- = {lo:.4g}, x+ = {hi:.4g}; rest points: {rest_text}")
    print(f"  discrete eigenvalues 1 - f'·dt (eq. 5.26, corrected): "
          f"{details['eigenvalue_min']:.4g} .. {details['eigenvalue_max']:.4g}; the augmented "
          f"constant state has eigenvalue 1 (not a mode)")
    verdict = ("yes" if details["stable_everywhere"] else
               f"no, violated at {details['n_violations']} of {details['n_points']} points")
    print(f"  0 < f'·dt < 2 everywhere (eq. 5.28): {verdict}")


def _verdict(report: dict) -> str:
    if report["n_unstable"]:
        return (f"UNSTABLE at {report['n_unstable']} of {report['n_points']} points "
                f"(max |lambda| {report['radius_max']:.6g})")
    marginal = (f"; {report['n_marginal']} marginal (|lambda| = 1: memory that holds)"
                if report["n_marginal"] else "")
    return f"stable (max |lambda| {report['radius_max']:.6g}){marginal}"


def _sector_line(name: str, sector) -> str:
    return (f"  {name:<18}[{sector.k_min:.4g}, {sector.k_max:.4g}] {sector.units} "
            f"({sector.n_used} of {sector.n_samples} increments; the left-out ones leave the "
            f"sector by up to {100 * sector.unexplained_step:.3g} % of the largest output "
            f"step)")


def _control_stability(options: StabilityOptions, reader: Reader) -> int:
    if options.json is not None:
        hio.check_output_path(options.json, options.force, inputs=options.loop.inputs())
    try:
        study = hc.examine_loop(loop_setup(options.loop, reader), options.experiment)
    except hc.LoopError as exc:
        raise loop_error(exc, options.loop) from None
    loop, models_, report, margins = (study.setup.loop, study.setup.models, study.report,
                                      study.margins)
    p = loop.pid
    print(f"loop: scheme {loop.scheme}, PID Kp = {p.kp:.4g}, Ti = {p.ti:.4g} s, Td = "
          f"{p.td:.4g} s, DOB {f'{loop.dob.f_q:.3g} Hz' if loop.dob else 'off'}; S_r "
          f"{models_.info['sensor_model']}, compensator and S_m {models_.info['model']}")
    print("slope sectors (chord slopes of consecutive samples where the input moves by more "
          "than 1 % of its largest step; the trained sine 0.5 Hz, 3 mm, 6 s at Ts):")
    for name, sector in report.sectors.items():
        print(_sector_line(name, sector))
    if report.loop_sector is not None:
        print(_sector_line(f"{report.experiment} run", report.loop_sector))
    print(_sector_line("tested (hull)", report.sector)
          + f"; covers the {' and the '.join(report.sector_sources)}")
    c = report.circle
    if c is not None:
        top = ("none (condition 1 fails)" if c.k_max_proved is None
               else f"{c.k_max_proved:.4g} (worst at {c.worst_hz:.4g} Hz)")
        print(f"circle criterion (discrete): linear loop at k_min "
              f"{'stable' if c.base_stable else 'NOT asymptotically stable'}; largest proved "
              f"upper bound {top}")
    pm = "n/a" if margins.phase_margin_deg is None else f"{margins.phase_margin_deg:.3g}"
    print(f"linearised at rest (local only): phase margin {pm} deg, "
          f"closed loop {'stable' if margins.closed_loop_stable else 'not strictly stable'}")
    scope = (" (constant reference, slopes inside the tested sector)"
             if report.verdict == "proved stable" else "")
    print(f"global stability: {report.verdict.upper()}{scope}: {report.reason}")
    if options.json is not None:
        hio.write_json({"scheme": loop.scheme, **report.to_dict(), "linear": margins.to_dict()},
                       options.json, force=options.force)
        print(f"wrote {options.json}")
    return 0


def run_stability(args: argparse.Namespace) -> int:
    """``hystkit stability``: a model file's local stability, or a loop's (``--control``)."""
    options = StabilityOptions.from_args(args)
    reader = Reader(given_read_options(args))
    if options.control:
        return _control_stability(options, reader)
    model_json, data = options.model_json, options.data
    if options.json is not None:
        hio.check_output_path(options.json, options.force,
                              inputs=[model_json] + ([data] if data else []))
    comp = compensation.load_compensator(model_json)
    family, structure = comp.family, comp.structure
    u = _probe_input(structure.dt) if data is None else _model_input(comp, data, reader)
    probe = "a unit chirp 0.1 -> 3 Hz" if data is None else str(data)
    try:
        report = models.stability_report(family, structure, comp.params, u)
        inverse = (models.stability_report(family, structure, comp.params,
                                    _probe_input(structure.dt), inverse=True)
                   if comp.mode == "inverse" else None)
    except ValueError as exc:
        raise InputError(f"{model_json}: {exc}") from None
    print(f"{model_json}: {family.name} ({family.title}), dt = {structure.dt:g} s, "
          f"{report['n_state']} state(s)")
    details = report["details"]
    if details is not None:
        if getattr(structure, "limit", True):
            print(f"  stability limit on (slope cap f'·dt <= {structure.slope_cap:g} beyond the "
                  f"knees, eq. 5.29)")
        else:
            print(f"  stability limit OFF (eq. 5.29 not applied: beyond the knees below, where "
                  f"f'·dt would reach {structure.slope_cap:g}, an Euler step can diverge)")
        _print_cells(details)
    print(f"operating points: {report['n_points']} (rest states at {len(report['rest']['inputs'])}"
          f" inputs, and {report['trajectory']['n_points']} of {report['trajectory']['n_samples']}"
          f" samples of the model driven by {probe})")
    print(f"linearised step, eigenvalues of A: {_verdict(report)}")
    if inverse is not None:
        print(f"inverse (the compensator as it runs, driven by a unit chirp): {_verdict(inverse)}")
    if options.json is not None:
        hio.write_json({"model_file": str(model_json), "model": comp.model, "mode": comp.mode,
                        "probe": probe, **report, "inverse_report": inverse}, options.json,
                       force=options.force)
        print(f"wrote {options.json}")
    return 0

