"""``hystkit stability MODEL.json``: local stability of a fitted model of any family.

Every family: eigenvalues of the linearised step (``hystkit.models.stability_report``) at rest
over the input range and along a driven run. The mPL families add the document's per-cell
analysis (eq. 5.18-5.28: knees, rest points, ``f' dt``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError

if TYPE_CHECKING:  # the library loads when the command runs
    import numpy as np

    from ..compensation import Compensator

__all__ = ["register"]


def _probe_input(dt: float) -> np.ndarray:
    """The paper's chirp (0.1 -> 3 Hz over 100 s) at unit amplitude: the normalised training
    range [-1, 1] at every rate the experiments use."""
    import numpy as np

    from ..signals import exponential_chirp

    return exponential_chirp(np.arange(round(100.0 / dt)) * dt, amplitude=1.0)


def _model_input(comp: Compensator, path: Path) -> np.ndarray:
    """The fitted model's input on a recording, normalised as at fit time (eq. 5.10): the
    sensor signal for a direct compensator, the position for an inverse one's forward model."""
    from ..io import read_recording

    rec = read_recording(path, need_position=comp.mode == "inverse")
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


def _stability(args: argparse.Namespace) -> int:
    from ..compensation import load_compensator
    from ..io import check_output_path, write_json
    from ..models import stability_report

    if args.json is not None:
        check_output_path(args.json, args.force,
                          inputs=[args.model] + ([args.data] if args.data else []))
    comp = load_compensator(args.model)
    family, structure = comp.family, comp.structure
    u = (_probe_input(structure.dt) if args.data is None else _model_input(comp, args.data))
    probe = ("a unit chirp 0.1 -> 3 Hz" if args.data is None else str(args.data))
    try:
        report = stability_report(family, structure, comp.params, u)
        inverse = (stability_report(family, structure, comp.params,
                                    _probe_input(structure.dt), inverse=True)
                   if comp.mode == "inverse" else None)
    except ValueError as exc:
        raise InputError(f"{args.model}: {exc}") from None
    print(f"{args.model}: {family.name} ({family.title}), dt = {structure.dt:g} s, "
          f"{report['n_state']} state(s)")
    details = report["details"]
    if details is not None:
        limit = getattr(structure, "limit", True)
        print(f"  stability limit {'on' if limit else 'OFF'} (slope cap f'·dt <= "
              f"{structure.slope_cap:g} beyond the knees)")
        _print_cells(details)
    print(f"operating points: {report['n_points']} (rest states at {len(report['rest']['inputs'])}"
          f" inputs, and {report['trajectory']['n_points']} of {report['trajectory']['n_samples']}"
          f" samples of the model driven by {probe})")
    print(f"linearised step, eigenvalues of A: {_verdict(report)}")
    if inverse is not None:
        print(f"inverse (the compensator as it runs, driven by a unit chirp): {_verdict(inverse)}")
    if args.json is not None:
        write_json({"model_file": str(args.model), "model": comp.model, "mode": comp.mode,
                    "probe": probe, **report, "inverse_report": inverse}, args.json,
                   force=args.force)
        print(f"wrote {args.json}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stability`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("stability", help="local stability of a fitted model of any family "
                                         "(linearised step; eq. 5.18-5.28 for the mPL)")
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit'")
    p.add_argument("--data", type=Path,
                   help="recording whose model input (normalised as at fit time) drives the "
                        "model; default: a unit chirp 0.1 -> 3 Hz")
    p.add_argument("--json", type=Path, help="also write the analysis to this JSON file")
    p.set_defaults(run=_stability)
