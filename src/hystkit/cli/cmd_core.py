"""``hystkit compensate`` and ``hystkit evaluate``: a fitted compensator used on a
recording (issue 2)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

from ..compensation import (
    ORACLE_CENTER,
    POSITION_MARGIN,
    SENSOR_MARGIN,
    center_label,
    evaluate,
    interval,
    load_compensator,
    use_flags,
    use_verdict,
)
from ..io import (
    RECORDING_SUFFIXES,
    check_output_path,
    read_other_columns,
    read_recording,
    sidecar_path,
    write_json,
    write_mat,
    write_recording,
)
from ._common import GUARD_EXIT, UsageError, say_next
from ._inputs import check_inputs_exist
from ._next_step import next_step
from ._own_layout import estimate_names, output_names
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["UseOptions"]  # the commands run through the table (cli._commands)


@dataclass(frozen=True)
class UseOptions:
    """What ``compensate`` or ``evaluate`` was asked: a model file applied to a recording."""

    model: Path
    data: Path
    out: Path | None
    json: Path | None  # evaluate's --json (compensate has none)
    rest_position: float | None
    level: float | None
    force: bool
    reader: Reader  # the recording's reading options

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> UseOptions:
        return cls(args.model, args.data, args.out, getattr(args, "json", None),
                   args.rest_position, args.level, args.force, Reader(given_read_options(args)))


def _compensate(args: argparse.Namespace) -> int:
    opts = UseOptions.from_args(args)
    check_inputs_exist([opts.model, opts.data])
    check_output_path(opts.out, opts.force, inputs=[opts.model, opts.data],
                      formats=RECORDING_SUFFIXES, what="a recording")
    comp = load_compensator(opts.model)
    _warn_if_oracle(comp.center, opts.model)
    options = opts.reader.as_trained(opts.data, comp.reading)
    rec = read_recording(opts.data, need_position=False, options=options)
    kept = read_other_columns(opts.data, rec.n_samples, options)
    names = output_names(options)  # the input's names and time unit, kept in the output
    new = estimate_names(names)
    units = _output_units(comp, rec, options, kept, opts.data, new)
    sidecar = opts.out.suffix.lower() == ".csv" and bool(units or rec.units or names
                                                          or options.time_unit != "s")
    if sidecar:  # the units and names go beside it: check it too
        check_output_path(sidecar_path(opts.out), opts.force, inputs=[opts.data])
    estimate = comp.estimate(rec, rest_position=opts.rest_position)
    flags = use_flags(comp, rec, estimate)
    extra = {new["position_estimate"]: estimate}
    if comp.band is not None:
        extra[new["position_lower"]], extra[new["position_upper"]] = interval(
            comp, rec, estimate, opts.level)
    elif opts.level is not None:
        raise UsageError(f"--level: {opts.model} has no prediction band (fitted without one "
                         f"or by a hystkit before bands); fit it again")
    extra.update({name: mask for name, mask in flags.items() if mask is not None})
    # an input column of such a name is renamed
    taken = {*(names.get(name, name) for name in ("time", "position", "sensor")), *extra}
    kept = {(f"{name}_input" if name in taken else name): values for name, values in kept.items()}
    write_recording(rec, opts.out, extra=extra, kept=kept, units=units, force=opts.force,
                    units_sidecar=True, names=names, time_unit=options.time_unit)
    unit = units.get(new["position_estimate"], "unit of the training position")
    band = ("" if comp.band is None else f", its {_level(comp, opts.level):.0%} band "
            f"'{new['position_lower']}', '{new['position_upper']}'")
    print(f"wrote {opts.out}: {rec.n_samples} samples with column '{new['position_estimate']}' "
          f"[{unit}]{band} (centring: {center_label(comp.center)}) and the flag columns "
          f"{', '.join(n for n, m in flags.items() if m is not None) or '(none: old model file)'}"
          + (f"; kept {len(kept)} other column(s): {', '.join(kept)}" if kept else "")
          + (f"; {'units' if not names and options.time_unit == 's' else 'how to read it'} "
             f"in {sidecar_path(opts.out)}" if sidecar else ""))
    if options.resample_hz is not None:
        print("  (resampled: the input's other numeric columns were resampled like the "
              "recording; columns with text or empty cells cannot be and are left out)")
    _warn_if_outside(flags, opts.data)
    return 0


def _output_units(comp, rec, options, kept: dict, data: Path,
                  new: dict[str, str]) -> dict[str, str]:
    """Units of compensate's output columns beyond the recording's (written with it): the
    estimate and its band (`new`'s names) in the training position's unit (from the model
    file, else the input's position unit), the kept columns' from the settings file. Warns
    when the sensor unit differs from training."""
    trained = comp.fit_info.get("units") or {}
    units = {}
    position = trained.get("position") or rec.unit("position")
    if position:
        units.update(dict.fromkeys(new.values(), position))
    if trained.get("sensor") and rec.unit("sensor") and trained["sensor"] != rec.unit("sensor"):
        print(f"hystkit: warning: {data}: sensor unit {rec.unit('sensor')!r} but the model was "
              f"trained on {trained['sensor']!r}; the estimate is meaningless unless the "
              f"values are in the same unit", file=sys.stderr)
    units.update({name: unit for name, unit in options.units if name in kept})
    return units


def _warn_if_oracle(center: str, path: Path) -> None:
    if center == ORACLE_CENTER:
        print(f"hystkit: warning: {path} was fitted with centring 'recording' (the paper's "
              f"protocol): it removes each recording's own sensor mean, which needs the whole "
              f"recording; refit with --center fit, tare or track for a causal compensator",
              file=sys.stderr)


def _warn_if_outside(flags: dict, data: Path) -> None:
    """Say so when the compensator runs outside what it was trained on."""
    mask = flags["sensor_outside"]
    if mask is not None and mask.any():
        print(f"hystkit: warning: {data}: {int(mask.sum())} sample(s) "
              f"({100 * mask.mean():.2g} %) lie outside the sensor range the compensator was "
              f"trained on (+{100 * SENSOR_MARGIN:g} % margin); its estimate there is an "
              f"extrapolation", file=sys.stderr)
    mask = flags["estimate_outside"]
    if mask is not None and mask.any():
        print(f"hystkit: warning: {data}: {int(mask.sum())} estimate(s) "
              f"({100 * mask.mean():.2g} %) lie outside the training position range "
              f"(+{100 * POSITION_MARGIN:g} % margin)", file=sys.stderr)


def _evaluate(args: argparse.Namespace) -> int:
    opts = UseOptions.from_args(args)
    check_inputs_exist([opts.model, opts.data])
    if opts.json is not None:
        check_output_path(opts.json, opts.force, inputs=[opts.model, opts.data],
                          formats=(".json",), what="--json output")
    if opts.out is not None:
        check_output_path(opts.out, opts.force, inputs=[opts.model, opts.data, opts.json or ""],
                          formats=(".json", ".mat"), what="the scores")
    comp = load_compensator(opts.model)
    _warn_if_oracle(comp.center, opts.model)
    rec = read_recording(opts.data, options=opts.reader.as_trained(opts.data, comp.reading))
    scores = evaluate(comp, rec, rest_position=opts.rest_position, level=opts.level)
    scores["units"] = dict(rec.units)  # of position and sensor, as the file gave them
    _warn_if_outside(use_flags(comp, rec, comp.estimate(rec, rest_position=opts.rest_position)),
                     opts.data)
    print(f"{opts.data} with {opts.model} ({scores['n_samples']} samples); deployable centring: "
          f"{scores['center']}, oracle: {scores['center_oracle']}")
    print(f"{'':<20}{comp.model:>12}{'line':>10}{comp.model + ' oracle':>16}{'line oracle':>13}")
    for key, label in (("r2", "R²"), ("e_rms_pct", "e_rms %"), ("e_max_pct", "e_max %"),
                       ("sinad_db", "SINAD dB"), ("loop_area", "loop area %")):
        values = (scores[key], scores[f"linear_{key}"], scores[f"{key}_oracle"],
                  scores[f"linear_{key}_oracle"])
        print(f"{label:<20}" + "".join(f"{_fmt(v):>{w}}" for v, w in zip(values,
                                                                        (12, 10, 16, 13))))
    for note in dict.fromkeys(scores["notes"].values()):  # why a score is n/a, once each
        print(f"  {note}")
    print(f"{'sensor loop area %':<20}{_fmt(scores['sensor_loop_area']):>12}")
    if scores["band_coverage"] is not None:
        print(f"band {scores['band_level']:.0%}: coverage {scores['band_coverage']:.3f}, width "
              f"mean {scores['band_width_mean']:.4g}, median {scores['band_width_median']:.4g}, "
              f"interval score {scores['interval_score']:.4g} (deployable)")
    else:
        print("band: n/a (the model was fitted without a prediction band)")
    print(f"outside training: {_count(scores['n_sensor_outside'])} sensor samples, "
          f"{_count(scores['n_estimate_outside'])} estimates")
    # the shared verdict, on the deployable scores: what a compensator in use would give
    status, message = use_verdict(scores, f"{opts.data}: deployable")
    scores["verdict"], scores["verdict_message"] = status, message
    if opts.json is not None:
        write_json(scores, opts.json, force=opts.force)
        print(f"wrote {opts.json}")
    if opts.out is not None:
        if opts.out.suffix.lower() == ".mat":
            write_mat(opts.out, scores, force=opts.force)
        else:
            write_json(scores, opts.out, force=opts.force)
        print(f"wrote {opts.out}")
    if status not in ("ok", "undetermined"):
        print(f"hystkit: evaluate: {status.replace('_', ' ')}: {message}; do not use the "
              f"{comp.model} compensator on data like these", file=sys.stderr)
        far = scores["n_sensor_far_outside"]  # counted by evaluate for the verdict
        say_next(next_step(status, command="evaluate", line_r2=scores["linear_r2"],
                           training_line_r2=comp.fit_info.get("training_linear_r2"),
                           outside=None if far is None else far / scores["n_samples"]))
        return GUARD_EXIT
    print(f"verdict: {status} ({message})")
    return 0


def _level(comp, level: float | None) -> float:
    return comp.band.level if level is None else level


def _count(n: int | None) -> str:
    return "unknown (old model file)" if n is None else str(n)


def _fmt(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.4f}"
