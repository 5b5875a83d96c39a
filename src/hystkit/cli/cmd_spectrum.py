"""``hystkit spectrum RAW_OR_DATA``: Welch PSDs and a suggested Butterworth cut-off (fig. 4.10).

A raw scope recording (v1, v2, encoder; its ``.toml`` settings or the bridge options) is taken
to dR/R at about 1 kHz (eq. 4.3-4.5); a recording (time, sensor and optionally dr1, dr2 as
``hystkit preprocess`` writes) is used as it is. Writes ``spectrum.png`` and ``spectrum.json``
into the ``--out`` folder (together or not at all).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from ..io import atomic_folder, check_output_folder, find_raw_config, read_recording, write_json
from ..preprocess import CutoffRule, raw_gauge_changes, spectrum
from .cmd_preprocess import RawOptions, SettingsError, raw_settings

if TYPE_CHECKING:  # the library loads when the command runs
    import numpy as np

__all__ = ["run_spectrum"]

SPECTRUM_FILES = ("spectrum.json", "spectrum.png")


def _is_raw(args: argparse.Namespace) -> bool:
    """Raw when asked, when bridge settings are given or stored beside the file, or when the
    file has v1 and v2 columns (variables)."""

    if args.kind != "auto":
        return args.kind == "raw"
    if args.config or args.r_bridge or find_raw_config(args.input) is not None:
        return True
    return {"v1", "v2"} <= _column_names(args.input)


def _column_names(path: Path) -> set[str]:
    from scipy.io import whosmat

    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            return {str(c) for c in pd.read_csv(path, nrows=0, encoding="utf-8-sig").columns}
        if suffix == ".parquet":
            return set(pq.read_schema(path).names)
        if suffix == ".mat":
            return {name for name, _, _ in whosmat(path)}
    except (OSError, ValueError, UnicodeDecodeError, pa.ArrowException, pd.errors.ParserError):
        pass  # the reader that follows names the problem
    return set()


def _recording_rows(path: Path) -> tuple[dict[str, np.ndarray], float]:
    """The differential sensor signal and, when the file has them, dr1 and dr2."""


    rec = read_recording(path, need_position=False)
    rows = {"differential": rec.sensor}
    if path.suffix.lower() in (".csv", ".parquet") and {"dr1", "dr2"} <= _column_names(path):
        frame = (pd.read_csv(path, usecols=["dr1", "dr2"]) if path.suffix.lower() == ".csv"
                 else pd.read_parquet(path, columns=["dr1", "dr2"]))
        if len(frame) == rec.sensor.size and frame.notna().all().all():
            rows = {"dr1": frame["dr1"].to_numpy(float), "dr2": frame["dr2"].to_numpy(float),
                    **rows}
    return rows, rec.fs


def run_spectrum(args: argparse.Namespace) -> int:
    """``hystkit spectrum``: Welch PSDs and a suggested cut-off."""

    check_output_folder(args.out, SPECTRUM_FILES, args.force, inputs=[args.input])
    try:
        rule = CutoffRule(margin_db=args.margin, safety=args.safety,
                          floor_width_hz=args.floor_width, order=args.order or 2)
    except ValueError as exc:
        raise SettingsError(str(exc)) from None
    t0 = time.perf_counter()
    compare = args.compare
    if _is_raw(args):
        settings, fmt, config_path = raw_settings(RawOptions.from_args(args, args.input))
        compare = settings.cutoff if compare is None else compare
        supply = "measured v0" if settings.supply_channel else f"V0 = {settings.v_supply:g} V"
        print(f"spectrum of raw {args.input}" + (f" (settings from {config_path})"
                                                 if config_path else "")
              + f": eq. 4.3 with {supply}, decimated to about {args.fs_analysis:g} Hz ...",
              flush=True)
        rows, fs = raw_gauge_changes(args.input, settings, fmt, args.fs_analysis)
        kind = "raw"
    else:
        rows, fs = _recording_rows(args.input)
        compare = 20.0 if compare is None else compare
        print(f"spectrum of recording {args.input} ({fs:.6g} Hz; already filtered if it came "
              "from preprocess) ...", flush=True)
        kind = "recording"
    try:
        result = spectrum(rows, fs, segment_s=args.segment, rule=rule, compare_cutoff=compare)
    except ValueError as exc:
        raise SettingsError(f"{args.input}: {exc}") from None
    s = result.summary
    print(f"  Welch: {s['n_segments']} segments of {s['segment_s']:.4g} s, resolution "
          f"{s['resolution_hz']:.3g} Hz, {', '.join(result.psd)}")
    print(f"  rule: {rule.text()}")
    if s["no_line"]:
        print(f"  {s['no_line']}; no cut-off suggested (the document: f_c = 20 Hz, "
              "sec. 4.3.1)")
    else:
        print(f"  f_signal = {result.f_signal:.4g} Hz (noise floor there "
              f"{s['noise_floor_at_f_signal_per_hz']:.3g} /Hz); suggested cut-off "
              f"{result.cutoff:.4g} Hz; the document: f_c,min >~ 8 Hz, f_c = 20 Hz "
              "(sec. 4.3.1)")
    for key, f in s["filters"].items():
        print(f"  {key} {f['cutoff_hz']:.4g} Hz: gain at f_signal {f['gain_at_f_signal_db']:.3g} "
              f"dB, noise floor above f_signal passed {f['noise_rms_above_f_signal_passed']:.3g}"
              f" RMS (of {f['noise_rms_above_f_signal_unfiltered']:.3g} unfiltered)")
    if s["compare_skipped"]:
        print(f"  {s['compare_skipped']}")
    report = {"source": str(args.input), "kind": kind, **result.to_dict(),
              "document": {"f_c_min_hz": 8.0, "f_c_hz": 20.0, "where": "sec. 4.3.1, fig. 4.10, "
                           "eq. 4.1"},
              "seconds": time.perf_counter() - t0}
    with atomic_folder(args.out, args.force, SPECTRUM_FILES) as tmp:
        write_json(report, tmp / "spectrum.json")
        title = (f"{args.input.name}: Welch PSD, no spectral line above the margin, no "
                 "cut-off" if s["no_line"] else
                 f"{args.input.name}: Welch PSD, suggested cut-off {result.cutoff:.3g} Hz")
        result.plot(title).savefig(tmp / "spectrum.png", dpi=110)
    print(f"wrote {args.out / 'spectrum.json'} and spectrum.png "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0
