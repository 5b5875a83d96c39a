"""``hystkit preprocess``: raw scope recording -> 40 Hz recording; raw mode of simulate-sensor.

Settings come from, in increasing priority: the defaults, the TOML file stored next to the raw
file (same stem, ``.toml``) or given with ``--config``, and the command-line options.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from typing import Any

from ..errors import HystkitError
from ..io import (
    CONFIG_KEYS,
    RawFormat,
    atomic_outputs,
    check_output_path,
    find_raw_config,
    read_raw_config,
    write_json,
    write_recording,
)
from ..preprocess import PreprocessSettings, RawDataWarning, parse_states, preprocess_raw
from ..sensors import ScopeSettings, VirtualSensor, simulate_raw, with_asymmetry
from ..signals import EXPERIMENTS

__all__ = ["SettingsError", "raw_settings", "run_preprocess", "run_raw_simulation",
           "sensor_from_args"]


class SettingsError(HystkitError, ValueError):
    """Options or a settings file with values preprocessing cannot use."""


# Option dest -> settings key (the same names as the TOML keys).
_OPTIONS = ("r_bridge", "v_supply", "um_per_count", "position_offset_mm", "fs_out", "cutoff",
            "order", "fs", "encoder_states", "encoder_levels", "encoder_dwell_us",
            "illegal", "remove_mean", "normalise", "chunk_size", "time_unit")


def raw_settings(args: argparse.Namespace) -> tuple[PreprocessSettings, RawFormat, Path | None]:
    """Merge defaults, the settings file and the options; return what preprocessing needs.

    Reads ``args.raw``, ``args.config``, ``args.supply_channel`` and any of the preprocess
    options present on `args` (``hystkit spectrum`` shares the bridge ones)."""

    config_path = args.config if args.config is not None else find_raw_config(args.raw)
    if config_path is not None and not Path(config_path).is_file():
        problem = "is a folder" if Path(config_path).is_dir() else "does not exist"
        raise SettingsError(f"--config {config_path} {problem}; expected a TOML settings file")
    values: dict[str, Any] = read_raw_config(config_path) if config_path is not None else {}
    values.pop("simulation", None)
    for key in _OPTIONS:
        option = getattr(args, key, None)
        if option is not None and option is not False:
            values[key] = option
    if getattr(args, "supply_channel", None) is not None:  # --no-supply-channel overrides it
        values["supply_channel"] = args.supply_channel
    where = f"settings from {config_path} and the options" if config_path else "options"
    for key in ("r_bridge", "v_supply"):
        if key not in values:
            flag = "--" + key.replace("_", "-")
            raise SettingsError(f"{args.raw}: the bridge {CONFIG_KEYS[key][1]} is not known: "
                                f"pass {flag} or set {key} in a settings file "
                                f"({Path(args.raw).with_suffix('.toml')})")
    fmt_keys = {"fs", "n_samples", "time_unit", "skip_rows", "columns"}
    try:
        fmt = RawFormat(columns=tuple(values.get("columns", {}).items()),
                        **{k: values[k] for k in fmt_keys - {"columns"} if k in values})
        kwargs = {k: v for k, v in values.items() if k not in fmt_keys}
        if "encoder_states" in kwargs:
            kwargs["encoder_states"] = parse_states(kwargs["encoder_states"])
        if "encoder_levels" in kwargs:
            kwargs["encoder_levels"] = tuple(float(v) for v in kwargs["encoder_levels"])
        settings = PreprocessSettings(**kwargs)
    except (TypeError, ValueError) as exc:
        raise SettingsError(f"{where}: {exc}") from None
    return settings, fmt, config_path


def run_preprocess(args: argparse.Namespace) -> int:
    """``hystkit preprocess``: a raw scope recording to a 40 Hz recording and its report."""

    report_path = args.report if args.report is not None else args.out.with_suffix(".json")
    if report_path == args.out:
        raise SettingsError(f"--report {report_path} is the data output file")
    inputs = [args.raw] + ([args.config] if args.config is not None else [])
    check_output_path(args.out, args.force, inputs=inputs)
    check_output_path(report_path, args.force, inputs=inputs)
    settings, fmt, config_path = raw_settings(args)
    print(f"preprocessing {args.raw}" + (f" with settings from {config_path}" if config_path
                                          else "") + " ...", flush=True)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RawDataWarning)
        result = preprocess_raw(args.raw, settings, fmt, progress=True)
    rep = result.report
    print(f"  {rep.n_samples} samples at {rep.fs:.6g} Hz ({rep.duration_s:.6g} s), "
          f"{rep.encoder_kind} encoder, decimated by {round(rep.fs / rep.fs_mid)} to "
          f"{rep.fs_mid:.6g} Hz, zero-phase Butterworth (order {settings.order}, "
          f"{settings.cutoff:g} Hz), {settings.fs_out:g} Hz out")
    if rep.encoder_thresholds_v is None:
        levels = "levels " + ", ".join(f"{v:.4g}" for v in rep.encoder_levels) + " V"
    else:  # A/B: the decoder's levels are the codes 2A + B, not voltages
        levels = ("A/B logic channels, thresholds " + ", ".join(
            f"{name} {v:.4g} V" for name, v in zip(("enc_a", "enc_b"),
                                                    rep.encoder_thresholds_v, strict=True)))
    print(f"  encoder: {levels}; {rep.n_edges} state changes, {rep.n_illegal} illegal "
          f"double transition(s), {rep.n_rejected} short excursion(s) rejected "
          f"(dwell {rep.encoder_dwell_samples} samples)")
    print(f"  gauges: R1 = {rep.r1_mean_ohm:.6g} Ohm, R2 = {rep.r2_mean_ohm:.6g} Ohm, "
          f"symmetry 2(R1-R2)/(R1+R2) = {rep.symmetry:.4f}")
    if rep.supply == "measured":
        print(f"  supply: measured v0 used in eq. 4.3: mean {rep.v0_mean_v:.6g} V, range "
              f"{rep.v0_min_v:.6g} to {rep.v0_max_v:.6g} V (nominal {settings.v_supply:g} V)")
    else:
        print(f"  supply: nominal V0 = {settings.v_supply:g} V in eq. 4.3")
    for warning in caught:
        if issubclass(warning.category, RawDataWarning):
            print(f"hystkit: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename,
                                   warning.lineno)
    seconds = time.perf_counter() - t0
    # Data file and report appear together or not at all (a failure in either, or Ctrl-C,
    # leaves neither).
    with atomic_outputs([args.out, report_path], args.force) as (data_tmp, report_tmp):
        write_recording(result.recording, data_tmp, extra=result.extra, force=True)
        write_json({"report": rep.to_dict(), "settings": {k: _plain(v) for k, v in
                                                          vars(settings).items()},
                    "format": {k: _plain(v) for k, v in vars(fmt).items()},
                    "config_file": None if config_path is None else str(config_path)},
                   report_tmp, force=True)
    print(f"wrote {args.out}: {rep.n_out} samples at {rep.fs_out:g} Hz (time, position [mm], "
          f"sensor = dR1/R1 - dR2/R2, r1, r2 [Ohm], dr1, dr2) and {report_path} "
          f"({seconds:.1f} s, {rep.n_samples / seconds / 1e6:.3g} M samples/s per channel)")
    return 0


def _plain(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


_RAW_ONLY = ("scope_rate", "duration", "encoder", "r_bridge", "v_supply", "glitches", "truth",
             "supply_drift", "supply_drift_period", "supply_channel")


def sensor_from_args(args: argparse.Namespace) -> VirtualSensor:
    """The virtual sensor with the --age-hours / --asymmetry options applied."""

    if not args.raw:
        used = [f"--{k.replace('_', '-')}" for k in _RAW_ONLY if getattr(args, k) is not None]
        if used:
            raise SettingsError(f"{', '.join(used)} only apply with --raw")
    try:
        return with_asymmetry(VirtualSensor(), args.asymmetry, args.age_hours)
    except ValueError as exc:
        raise SettingsError(str(exc)) from None


def run_raw_simulation(args: argparse.Namespace) -> int:
    """simulate-sensor --raw: write the raw file, its settings and optionally the truth."""

    config = args.out.with_suffix(".toml")
    for path in (args.out, config) + ((args.truth,) if args.truth else ()):
        check_output_path(path, args.force)
    sensor = sensor_from_args(args)
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

