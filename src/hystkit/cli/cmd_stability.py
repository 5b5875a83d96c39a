"""``hystkit stability MODEL.json``: linearised Euler stability of a fitted mPL (sec. 5.3.5)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..compensation import Compensator, load_compensator
from ..errors import InputError
from ..io import check_output_path, read_recording, write_json
from ..models._linearise import stability_report
from ..signals import exponential_chirp

__all__ = ["register"]

FAMILIES = ("mpl", "mpl-poly")


def _probe_input(dt: float) -> np.ndarray:
    """The paper's chirp (0.1 -> 3 Hz over 100 s) at unit amplitude: the normalised training
    range [-1, 1] at every rate the experiments use."""
    return exponential_chirp(np.arange(round(100.0 / dt)) * dt, amplitude=1.0)


def _model_input(comp: Compensator, path: Path) -> np.ndarray:
    """The fitted model's input on a recording, normalised as at fit time (eq. 5.10): the
    sensor signal for a direct compensator, the position for an inverse one's forward model."""
    rec = read_recording(path, need_position=comp.mode == "inverse")
    comp.check_sampling(rec)
    sc = comp.scaling
    x, offset, scale = ((rec.sensor, sc.sensor_offset, sc.sensor_scale) if comp.mode == "direct"
                        else (rec.position, sc.position_offset, sc.position_scale))
    return (x - {"recording": np.mean(x), "fit": offset, "none": 0.0}[comp.center]) / scale


def _stability(args: argparse.Namespace) -> int:
    if args.json is not None:
        check_output_path(args.json, args.force)
    comp = load_compensator(args.model)
    if comp.model not in FAMILIES:
        raise InputError(f"{args.model}: stability analysis (eq. 5.18-5.28) covers the "
                         f"{' and '.join(FAMILIES)} families, not {comp.model!r}")
    structure = comp.structure
    u = (_probe_input(structure.dt) if args.data is None else _model_input(comp, args.data))
    probe = ("a unit chirp 0.1 -> 3 Hz" if args.data is None else str(args.data))
    report = stability_report(structure, comp.params, u)
    limit = getattr(structure, "limit", True)
    print(f"{args.model}: {comp.model}, {structure.n_cells} cell(s), dt = {structure.dt:g} s, "
          f"stability limit {'on' if limit else 'OFF'} (slope cap f'·dt <= "
          f"{structure.slope_cap:g} beyond the knees)")
    if comp.mode == "inverse":
        print("  (inverse-mode compensator: this is the fitted forward model; the inverse's own "
              "dynamics are not covered)")
    for k, ((lo, hi), rest) in enumerate(zip(report["knees"], report["rest"], strict=True)):
        rest_text = ", ".join(f"v* = {v:.4g} (f'·dt = {s:.4g})"
                              for v, s in zip(rest["v"], rest["slope_dt"], strict=True))
        print(f"  cell {k + 1}: knees x- = {lo:.4g}, x+ = {hi:.4g}; rest points: {rest_text}")
    n_samples = report["trajectory"]["n_samples"]
    print(f"operating points: {report['n_points']} (rest points, and {n_samples} samples of "
          f"the model driven by {probe})")
    print(f"discrete eigenvalues 1 - f'·dt (eq. 5.26, corrected): "
          f"{report['eigenvalue_min']:.4g} .. {report['eigenvalue_max']:.4g}; the augmented "
          f"constant state has eigenvalue 1 (not a mode)")
    verdict = ("yes" if report["stable_everywhere"] else
               f"no, violated at {report['n_violations']} of {report['n_points']} points")
    print(f"0 < f'·dt < 2 everywhere (eq. 5.28): {verdict}")
    if args.json is not None:
        write_json({"model_file": str(args.model), "model": comp.model, "mode": comp.mode,
                    "limit": limit, "slope_cap": structure.slope_cap, "probe": probe,
                    **report}, args.json, force=args.force)
        print(f"wrote {args.json}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stability`` subcommand to the ``hystkit`` parser."""
    p = sub.add_parser("stability", help="linearised Euler stability of an mpl / mpl-poly model "
                                         "(eq. 5.18-5.28)")
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit'")
    p.add_argument("--data", type=Path,
                   help="recording whose model input (normalised as at fit time) drives the "
                        "model; default: a unit chirp 0.1 -> 3 Hz")
    p.add_argument("--json", type=Path, help="also write the analysis to this JSON file")
    p.set_defaults(run=_stability)
