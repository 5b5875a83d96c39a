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
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .. import compensation
from .. import control as hc
from .. import io as hio
from ..errors import InputError
from ._common import UsageError, add_read_options, deferred, read_recording_args
from ._control_options import LoopOptions, add_setup_options
from .cmd_control import loop_error, loop_setup

if TYPE_CHECKING:
    import numpy as np

__all__ = ["register"]


def _probe_input(dt: float) -> np.ndarray:
    """The paper's chirp (0.1 -> 3 Hz over 100 s) at unit amplitude: the normalised training
    range [-1, 1] at every rate the experiments use."""
    import numpy as np  # this module is imported to build the parser: --help loads no numpy

    from ..signals import exponential_chirp

    return exponential_chirp(np.arange(round(100.0 / dt)) * dt, amplitude=1.0)


def _model_input(comp: compensation.Compensator, path: Path, args: argparse.Namespace) -> np.ndarray:
    """The fitted model's input on a recording, normalised as at fit time (eq. 5.10): the
    sensor signal for a direct compensator, the position for an inverse one's forward model."""
    rec = read_recording_args(args, path, need_position=comp.mode == "inverse")
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


@dataclass(frozen=True)
class StabilityOptions:
    """``hystkit stability``'s options: a model file's local stability, or with ``control`` a
    loop's global stability."""

    model_json: Path | None
    data: Path | None
    json: Path | None
    force: bool
    control: bool
    experiment: str
    loop: LoopOptions

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> StabilityOptions:
        """The options of a parsed command line; a combination that does not fit is one line."""
        options = cls(args.model_json, args.data, args.json, args.force, args.control,
                      args.experiment, LoopOptions.from_args(args))
        if options.control:
            if options.model_json is not None or options.data is not None:
                raise UsageError("--control examines a loop: give no MODEL.json and no --data")
            if options.loop.scheme is None:
                raise UsageError("--control needs --scheme direct|weighting")
        elif options.loop.scheme is not None:
            raise UsageError("--scheme and the other loop options need --control")
        elif options.model_json is None:
            raise UsageError("give MODEL.json (a model's local stability) or --control (a "
                             "loop's)")
        return options


def _control_stability(options: StabilityOptions, args: argparse.Namespace) -> int:
    if options.json is not None:
        hio.check_output_path(options.json, options.force, inputs=options.loop.inputs())
    try:
        study = hc.examine_loop(loop_setup(options.loop, args), options.experiment)
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


def _stability(args: argparse.Namespace) -> int:
    from .. import models  # its registry loads numpy: not when the parser is built

    options = StabilityOptions.from_args(args)
    if options.control:
        return _control_stability(options, args)
    if args.json is not None:
        hio.check_output_path(args.json, args.force,
                              inputs=[args.model_json] + ([args.data] if args.data else []))
    comp = compensation.load_compensator(args.model_json)
    family, structure = comp.family, comp.structure
    u = (_probe_input(structure.dt) if args.data is None else _model_input(comp, args.data, args))
    probe = ("a unit chirp 0.1 -> 3 Hz" if args.data is None else str(args.data))
    try:
        report = models.stability_report(family, structure, comp.params, u)
        inverse = (models.stability_report(family, structure, comp.params,
                                    _probe_input(structure.dt), inverse=True)
                   if comp.mode == "inverse" else None)
    except ValueError as exc:
        raise InputError(f"{args.model_json}: {exc}") from None
    print(f"{args.model_json}: {family.name} ({family.title}), dt = {structure.dt:g} s, "
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
    if args.json is not None:
        hio.write_json({"model_file": str(args.model_json), "model": comp.model, "mode": comp.mode,
                    "probe": probe, **report, "inverse_report": inverse}, args.json,
                   force=args.force)
        print(f"wrote {args.json}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stability`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("stability", help="local stability of a fitted model of any family "
                                         "(linearised step; eq. 5.18-5.28 for the mPL), or "
                                         "with --control a loop's global stability")
    p.add_argument("model_json", type=Path, nargs="?", metavar="MODEL.json",
                   help="model JSON file written by 'hystkit fit' (not with --control)")
    p.add_argument("--data", type=Path,
                   help="recording whose model input (normalised as at fit time) drives the "
                        "model; default: a unit chirp 0.1 -> 3 Hz")
    p.add_argument("--json", type=Path, help="also write the analysis to this JSON file")
    p.add_argument("--control", action="store_true",
                   help="examine the control loop set up by the options below (as 'hystkit "
                        "control'): slope sectors, circle criterion, a simulation")
    deferred(p.add_argument("--experiment", default="sine",
                            help="with --control: the experiment simulated (default sine); its "
                                 "closed-loop slopes join the trained sine's in the sector "
                                 "tested, and a divergence shows instability"),
             choices=lambda: hc.EXPERIMENTS)
    add_setup_options(p, scheme_required=False)
    add_read_options(p)
    p.set_defaults(run=_stability)
