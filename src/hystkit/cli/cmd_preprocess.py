"""``hystkit preprocess``: raw scope recording -> 40 Hz recording (simulate-sensor's raw mode
writes such recordings: `hystkit.cli.cmd_simulate`).

Settings come from, in increasing priority: the defaults, the TOML file stored next to the raw
file (same stem, ``.toml``) or given with ``--config``, and the command-line options.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import dataclass
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

__all__ = ["RawOptions", "SettingsError", "raw_settings", "run_preprocess"]


class SettingsError(HystkitError, ValueError):
    """Options or a settings file with values preprocessing cannot use."""


# Option dest -> settings key (the same names as the TOML keys).
_OPTIONS = ("r_bridge", "v_supply", "um_per_count", "position_offset_mm", "fs_out", "cutoff",
            "order", "fs", "encoder_states", "encoder_levels", "encoder_dwell_us",
            "illegal", "remove_mean", "normalise", "chunk_size", "time_unit")


@dataclass(frozen=True)
class RawOptions:
    """How a raw scope file is to be read: the file, ``--config`` and the preprocess options
    given (by their settings keys; ``hystkit spectrum`` shares the bridge ones)."""

    raw: Path
    config: Path | None
    given: dict[str, Any]
    supply_channel: bool | None  # --supply-channel / --no-supply-channel, None: not given

    @classmethod
    def from_args(cls, args: argparse.Namespace, raw: Path) -> RawOptions:
        """The raw-reading options of a parsed command line, for the raw file `raw`."""
        given = {}
        for key in _OPTIONS:
            option = getattr(args, key, None)
            if option is not None and option is not False:
                given[key] = option
        return cls(raw, args.config, given, getattr(args, "supply_channel", None))


def raw_settings(options: RawOptions) -> tuple[PreprocessSettings, RawFormat, Path | None]:
    """Merge defaults, the settings file and the options; return what preprocessing needs."""
    config_path = (options.config if options.config is not None
                   else find_raw_config(options.raw))
    if config_path is not None and not Path(config_path).is_file():
        problem = "is a folder" if Path(config_path).is_dir() else "does not exist"
        raise SettingsError(f"--config {config_path} {problem}; expected a TOML settings file")
    values: dict[str, Any] = read_raw_config(config_path) if config_path is not None else {}
    values.pop("simulation", None)
    values.update(options.given)
    if options.supply_channel is not None:  # --no-supply-channel overrides it
        values["supply_channel"] = options.supply_channel
    where = f"settings from {config_path} and the options" if config_path else "options"
    for key in ("r_bridge", "v_supply"):
        if key not in values:
            flag = "--" + key.replace("_", "-")
            raise SettingsError(f"{options.raw}: the bridge {CONFIG_KEYS[key][1]} is not "
                                f"known: pass {flag} or set {key} in a settings file "
                                f"({Path(options.raw).with_suffix('.toml')})")
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
    settings, fmt, config_path = raw_settings(RawOptions.from_args(args, args.raw))
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
