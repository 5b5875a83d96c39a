"""``hystkit simulate-sensor`` and ``hystkit demo``: the built-in virtual sensor's
recordings, and the main job run on them."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..compensation import DEFAULT_CENTER
from ..errors import HystkitError
from ..io import check_output_path, write_recording
from ..sensors import (
    ScopeSettings,
    VirtualSensor,
    occasional_references,
    simulate_experiment,
    simulate_raw,
    with_asymmetry,
    with_gain_drift,
)
from ..signals import EXPERIMENTS
from ..studies import DOCUMENT_TABLE_5_5, format_table
from ..studies import run_demo as demo_study
from ._common import UsageError, check_size
from .cmd_preprocess import SettingsError

__all__ = ["run_demo", "run_simulate_sensor"]


def run_simulate_sensor(args: argparse.Namespace) -> int:
    """``hystkit simulate-sensor``: one experiment of the virtual sensor, written."""
    if args.raw:
        if args.gain_drift is not None or args.references_every is not None:
            raise UsageError("--gain-drift and --references-every apply to the 40 Hz "
                             "recording, not to --raw")
        return _raw_simulation(args)
    check_output_path(args.out, args.force)
    rec = simulate_experiment(args.excitation, seed=args.seed, sensor=_sensor(args))
    if args.gain_drift is not None:
        rec = with_gain_drift(rec, args.gain_drift)
    kept, note = {}, ""
    if args.references_every is not None:  # empty cells where unknown: kept, not checked
        kept = {"reference": occasional_references(rec, args.references_every, args.seed)}
        note = f", a 'reference' column (one true position per {args.references_every:g} s)"
    write_recording(rec, args.out, force=args.force, kept=kept)
    drift = "" if args.gain_drift is None else f", sensor gain drift {args.gain_drift:+.1%}"
    print(f"wrote {args.out}: {EXPERIMENTS[args.excitation].description}, seed {args.seed}, "
          f"{rec.n_samples} samples at {rec.fs:g} Hz{drift}{note}")
    return 0


_RAW_ONLY = ("scope_rate", "duration", "encoder", "r_bridge", "v_supply", "glitches", "truth",
             "supply_drift", "supply_drift_period", "supply_channel")


def _sensor(args: argparse.Namespace) -> VirtualSensor:
    """The virtual sensor with the --age-hours / --asymmetry options applied."""

    if not args.raw:
        used = [f"--{k.replace('_', '-')}" for k in _RAW_ONLY if getattr(args, k) is not None]
        if used:
            raise SettingsError(f"{', '.join(used)} only apply with --raw")
    try:
        return with_asymmetry(VirtualSensor(), args.asymmetry, args.age_hours)
    except ValueError as exc:
        raise SettingsError(str(exc)) from None


def _raw_simulation(args: argparse.Namespace) -> int:
    """simulate-sensor --raw: write the raw file, its settings and optionally the truth."""

    config = args.out.with_suffix(".toml")
    for path in (args.out, config) + ((args.truth,) if args.truth else ()):
        check_output_path(path, args.force)
    sensor = _sensor(args)
    defaults = ScopeSettings()
    scope = ScopeSettings(
        fs=args.scope_rate or defaults.fs, r_bridge=args.r_bridge or defaults.r_bridge,
        v_supply=args.v_supply or defaults.v_supply, encoder_mode=args.encoder or "merged",
        n_missed_states=args.glitches or 0,
        bridge_supply_drift=args.supply_drift or 0.0,
        bridge_drift_period=args.supply_drift_period or defaults.bridge_drift_period,
        supply_channel=bool(args.supply_channel))
    t0 = time.perf_counter()
    try:
        truth = simulate_raw(args.out, args.excitation, args.seed, sensor=sensor, scope=scope,
                             duration=args.duration, force=args.force)
    except ValueError as exc:
        if isinstance(exc, HystkitError):
            raise
        raise SettingsError(str(exc)) from None
    print(f"wrote {args.out}: raw scope recording of the virtual sensor, "
          f"{EXPERIMENTS[args.excitation].description}, seed {args.seed}, {truth.n_samples} "
          f"samples at {scope.fs:.6g} Hz ({truth.n_samples / scope.fs:.6g} s), "
          f"{scope.encoder_mode} encoder, {len(truth.missed)} hidden encoder state(s) "
          f"({time.perf_counter() - t0:.1f} s)")
    supply = (f", bridge supply drift {100 * scope.bridge_supply_drift:g} % (period "
              f"{scope.bridge_drift_period:g} s)" if scope.bridge_supply_drift else "")
    supply += ", measured supply in column v0" if scope.supply_channel else ""
    print(f"wrote {config}: R_br = {scope.r_bridge:g} Ohm, V0 = {scope.v_supply:g} V, "
          f"fs = {scope.fs:.6g} Hz{supply}; 'hystkit preprocess {args.out}' reads it")
    if args.truth:
        write_recording(truth.recording(), args.truth, extra=truth.gauge_changes(),
                        force=args.force)
        print(f"wrote {args.truth}: the exact position [mm], dR1/R1 - dR2/R2 and each gauge's "
              "dR/R (dr1, dr2) at 40 Hz")
    return 0


def run_demo(args: argparse.Namespace) -> int:
    """``hystkit demo``: the main job on the virtual sensor, into a new folder."""
    out = args.out or Path(f"hystkit-demo-{time.strftime('%Y%m%d-%H%M%S')}")
    check_size("mpl", args.cells, "--cells")
    print(f"hystkit demo: virtual sensor, four experiments, {args.cells}-cell mPL compensator "
          f"fitted on one recording and scored on another (direct mode, deployable centring: "
          f"{DEFAULT_CENTER}; the paper's oracle centring beside it)")
    t0 = time.perf_counter()
    result = demo_study(out, n_cells=args.cells, force=args.force, raw=args.raw, report=True)
    print()
    print(format_table(result["metrics"], "Validation (fit on seed 1, test on seed 2); cf. "
                       "document table 5.5", DOCUMENT_TABLE_5_5))
    print()
    print(format_table(result["noise_trained"], "Compensator trained on noise, tested on each "
                       "excitation (does compensation generalise?)"))
    raw = result.get("raw_path")
    if raw is not None:
        _print_raw_path(raw)
    print(f"\nwrote {out}/: metrics.json, noise_trained.json, config.json, loops.png, "
          f"time_series.png, report.html{', raw_path.json' if raw else ''} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


def _print_raw_path(raw: dict) -> None:
    print()
    print(format_table({f"{raw['excitation']} raw": raw["metrics"]},
                       f"Raw path: scope files at {raw['scope_rate_hz']:g} Hz -> preprocess -> "
                       f"fit -> evaluate (cf. the {raw['excitation']} row above)"))
    trip = raw["round_trip"]["validation"]
    print(f"  decoded vs true: position max error {trip['position_max_error_um']:.2f} um "
          f"({trip['position_max_error_counts']:.2f} counts), dR/R rms error "
          f"{trip['sensor_rms_error']:.1e}, {trip['n_illegal']} illegal of {trip['n_edges']} "
          f"encoder transitions")
