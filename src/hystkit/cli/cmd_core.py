"""Core subcommands: simulate-sensor, fit, compensate, evaluate, demo (issue 2)."""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

from ..io import training_reading, training_units
from ._common import (
    GUARD_EXIT,
    UsageError,
    add_read_options,
    check_size,
    deferred,
    integer,
    next_step,
    number,
    positive_float,
    positive_int,
    read_training_files,
    say_next,
    size_limit,
    slope_cap,
)
from ._fit_cost_options import add_cost_options, cost_options, print_cost_summary
from ._fit_report import print_band, print_parameters, print_standard_errors, units_label
from ._fit_start_options import (
    add_start_options,
    list_presets,
    start_options,
    structure_options,
    weight_sum_options,
)
from ._guided_fit import GUIDED_HELP, GUIDED_MODEL, model_options_given, run_guided_fit
from ._inputs import check_inputs_exist
from ._own_layout import (
    add_trained_note,
    estimate_names,
    options_as_trained,
    output_names,
)
from .cmd_preprocess import add_simulation_options, run_raw_simulation, sensor_from_args

__all__ = ["register"]

# Library functions the commands call through this module, loaded on first use like every
# library name here; tests replace them on it (monkeypatch cmd_core.evaluate) to build faults.
_THROUGH_MODULE = ("evaluate", "interval", "load_compensator", "use_flags", "with_band")


def __getattr__(name: str):
    if name in _THROUGH_MODULE:
        from .. import compensation

        globals()[name] = value = getattr(compensation, name)
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


_module = sys.modules[__name__]


def _simulate_sensor(args: argparse.Namespace) -> int:
    from ..io import check_output_path, write_recording
    from ..sensors import simulate_experiment
    from ..signals import EXPERIMENTS

    if args.raw:
        if args.gain_drift is not None or args.references_every is not None:
            raise UsageError("--gain-drift and --references-every apply to the 40 Hz "
                             "recording, not to --raw")
        return run_raw_simulation(args)
    check_output_path(args.out, args.force)
    rec = simulate_experiment(args.excitation, seed=args.seed, sensor=sensor_from_args(args))
    if args.gain_drift is not None:
        from ..sensors import with_gain_drift

        rec = with_gain_drift(rec, args.gain_drift)
    kept, note = {}, ""
    if args.references_every is not None:  # empty cells where unknown: kept, not checked
        from ..sensors import occasional_references

        kept = {"reference": occasional_references(rec, args.references_every, args.seed)}
        note = f", a 'reference' column (one true position per {args.references_every:g} s)"
    write_recording(rec, args.out, force=args.force, kept=kept)
    drift = "" if args.gain_drift is None else f", sensor gain drift {args.gain_drift:+.1%}"
    print(f"wrote {args.out}: {EXPERIMENTS[args.excitation].description}, seed {args.seed}, "
          f"{rec.n_samples} samples at {rec.fs:g} Hz{drift}{note}")
    return 0


def _fit(args: argparse.Namespace) -> int:
    args.model = _chosen_model(args)
    if args.model == GUIDED_MODEL:
        return run_guided_fit(args)
    if args.budget is not None:
        raise UsageError(f"--budget applies to --model {GUIDED_MODEL} (a named model is one "
                         f"fit, not a selection)")
    if args.init == "list":
        return list_presets(args)
    check_inputs_exist(args.data)  # a misspelt name is refused before the heavy imports
    from ..compensation import MODEL_SUFFIXES, center_label, fit_compensator, save_compensator
    from ..io import check_output_path
    from ..models import get_family

    check_output_path(args.out, args.force, inputs=args.data, formats=MODEL_SUFFIXES,
                      what="a model file")
    family = get_family(args.model)
    costs = cost_options(args)
    constraint = weight_sum_options(args, family)
    options = {} if args.slope_cap is None else {"slope_cap": args.slope_cap}
    if options and not has_slope_cap(family):
        raise UsageError(f"--slope-cap applies to the models with an Euler slope cap "
                         f"({', '.join(_slope_cap_models())}), not {args.model!r}")
    options.update(_pl_options(args, family))
    options.update(structure_options(args, family))
    check_size(args.model, args.cells, "--cells")
    reading, recs = read_training_files(args)
    size = family.default_size if args.cells is None else args.cells
    fit_options = {**start_options(args, family, recs[0].dt, size, options), **constraint}
    shown = "".join(f", {name} {str(value).lower() if isinstance(value, bool) else f'{value:g}'}"
                    for name, value in options.items())
    print(f"fitting {args.model} ({family.size_help}: {size}{shown}, {args.mode} mode, centring: "
          f"{center_label(args.center)}) on {', '.join(map(str, args.data))}: "
          f"{sum(r.n_samples for r in recs)} samples at {recs[0].fs:g} Hz"
          f"{units_label(recs[0])} ...", flush=True)
    fit_arguments = {"tare_seconds": args.tare_seconds, "track_seconds": args.track_seconds,
                     **costs.fit_arguments(args, recs), "fit_options": fit_options, **options}
    comp = fit_compensator(recs, size, model=args.model, mode=args.mode, center=args.center,
                           **fit_arguments)
    if not args.no_band and comp.fit_info["status"] == "ok":
        # the band's folds refit the same model: only for a model that may be used
        comp = _module.with_band(comp, recs, size, fit_arguments, level=args.level)
    elif not args.no_band:
        comp.fit_info["band"] = "no band: the fit did not pass its guards"
    units = training_units(recs)
    if units:
        comp.fit_info["units"] = units
    remembered, not_remembered = training_reading(reading, args.data, units)
    comp = replace(comp, reading=remembered)  # later commands read files of this layout so
    save_compensator(comp, args.out, force=args.force)
    info = comp.fit_info
    print(f"done in {info['fit_seconds']:.2f} s: SSE {info['cost']:.4g} (normalised), solver: "
          f"{info['message']}")
    print_band(comp)
    print_cost_summary(info)
    print_parameters(comp, info.get("standard_errors"))
    print_standard_errors(info.get("standard_errors"))
    print(f"  training R² {info['training_r2']:.4f}, straight line "
          f"{info['training_linear_r2']:.4f}; AIC {info['aic']:.1f}, BIC {info['bic']:.1f}; "
          f"sensor polarity {comp.polarity:+g}")
    if info.get("joint_fit"):
        print(f"  {info['joint_fit']}")
    for note in [*(info.get("at_model_limits") or ()), *(info.get("redundant") or ()),
                 *filter(None, [not_remembered])]:
        print(f"  note: {note}")
    print(f"wrote {args.out}")
    if info["status"] != "ok":
        print(f"hystkit: fit {info['status'].replace('_', ' ')}: {info['status_message']}; the "
              f"model was written for inspection, do not use it as a compensator",
              file=sys.stderr)
        say_next(next_step(info["status"], model=args.model, size=size, mode=args.mode,
                           line_r2=info["training_linear_r2"]))
        return GUARD_EXIT
    print(f"  status: ok ({info['status_message']})")
    return 0


def _chosen_model(args: argparse.Namespace) -> str:
    """``--model``, or without it `DEFAULT_MODEL`; mpl when an option of a named model is
    given (``--cells 3`` alone is the 3-cell mpl, whatever the default)."""
    if args.model is not None:
        return args.model
    return "mpl" if model_options_given(args) else DEFAULT_MODEL


def has_slope_cap(family) -> bool:
    """Whether the family's structure takes an Euler slope cap (``make_structure(...,
    slope_cap=...)``): the mPL families, PL, the ladder and Chua's model."""
    import inspect

    return "slope_cap" in inspect.signature(family.make_structure).parameters


def _slope_cap_models() -> list[str]:
    return [name for name, family in _families().items() if has_slope_cap(family)]


def _pl_options(args: argparse.Namespace, family) -> dict:
    """``--p``, ``--m``, ``--s`` of the pl model as structure options, checked by the family
    before any work (one line naming the option)."""
    given = {name: value for name, value in (("power", args.p), ("n_basis", args.m),
                                             ("smoothing", args.s)) if value is not None}
    if not given:
        return {}
    if args.model != "pl":
        raise UsageError(f"--p, --m and --s apply to the pl model only, not {args.model!r}")
    size = family.default_size if args.cells is None else args.cells
    try:
        family.make_structure(1 / 40, size, **given)
    except ValueError as exc:
        raise UsageError(f"--p/--m/--s: {exc}") from None
    return given


def _compensate(args: argparse.Namespace) -> int:
    check_inputs_exist([args.model, args.data])
    from ..compensation import center_label
    from ..io import (
        RECORDING_SUFFIXES,
        check_output_path,
        read_other_columns,
        read_recording,
        sidecar_path,
        write_recording,
    )

    load_compensator, use_flags = _module.load_compensator, _module.use_flags

    check_output_path(args.out, args.force, inputs=[args.model, args.data],
                      formats=RECORDING_SUFFIXES, what="a recording")
    comp = load_compensator(args.model)
    _warn_if_oracle(comp.center, args.model)
    options = options_as_trained(args, args.data, comp.reading)
    rec = read_recording(args.data, need_position=False, options=options)
    kept = read_other_columns(args.data, rec.n_samples, options)
    names = output_names(options)  # the input's names and time unit, kept in the output
    new = estimate_names(names)
    units = _output_units(comp, rec, options, kept, args.data, new)
    sidecar = args.out.suffix.lower() == ".csv" and bool(units or rec.units or names
                                                          or options.time_unit != "s")
    if sidecar:  # the units and names go beside it: check it too
        check_output_path(sidecar_path(args.out), args.force, inputs=[args.data])
    estimate = comp.estimate(rec, rest_position=args.rest_position)
    flags = use_flags(comp, rec, estimate)
    extra = {new["position_estimate"]: estimate}
    if comp.band is not None:
        extra[new["position_lower"]], extra[new["position_upper"]] = _module.interval(
            comp, rec, estimate, args.level)
    elif args.level is not None:
        raise UsageError(f"--level: {args.model} has no prediction band (fitted without one "
                         f"or by a hystkit before bands); fit it again")
    extra.update({name: mask for name, mask in flags.items() if mask is not None})
    # an input column of such a name is renamed
    taken = {*(names.get(name, name) for name in ("time", "position", "sensor")), *extra}
    kept = {(f"{name}_input" if name in taken else name): values for name, values in kept.items()}
    write_recording(rec, args.out, extra=extra, kept=kept, units=units, force=args.force,
                    units_sidecar=True, names=names, time_unit=options.time_unit)
    unit = units.get(new["position_estimate"], "unit of the training position")
    band = ("" if comp.band is None else f", its {_level(comp, args.level):.0%} band "
            f"'{new['position_lower']}', '{new['position_upper']}'")
    print(f"wrote {args.out}: {rec.n_samples} samples with column '{new['position_estimate']}' "
          f"[{unit}]{band} (centring: {center_label(comp.center)}) and the flag columns "
          f"{', '.join(n for n, m in flags.items() if m is not None) or '(none: old model file)'}"
          + (f"; kept {len(kept)} other column(s): {', '.join(kept)}" if kept else "")
          + (f"; {'units' if not names and options.time_unit == 's' else 'how to read it'} "
             f"in {sidecar_path(args.out)}" if sidecar else ""))
    if options.resample_hz is not None:
        print("  (resampled: the input's other numeric columns were resampled like the "
              "recording; columns with text or empty cells cannot be and are left out)")
    _warn_if_outside(flags, args.data)
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
    from ..compensation import ORACLE_CENTER

    if center == ORACLE_CENTER:
        print(f"hystkit: warning: {path} was fitted with centring 'recording' (the paper's "
              f"protocol): it removes each recording's own sensor mean, which needs the whole "
              f"recording; refit with --center fit, tare or track for a causal compensator",
              file=sys.stderr)


def _warn_if_outside(flags: dict, data: Path) -> None:
    """Say so when the compensator runs outside what it was trained on."""
    from ..compensation import POSITION_MARGIN, SENSOR_MARGIN

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
    check_inputs_exist([args.model, args.data])
    from ..compensation import FAR_MARGIN, use_verdict
    from ..io import check_output_path, read_recording, write_json, write_mat

    evaluate, load_compensator = _module.evaluate, _module.load_compensator
    use_flags = _module.use_flags

    if args.json is not None:
        check_output_path(args.json, args.force, inputs=[args.model, args.data],
                          formats=(".json",), what="--json output")
    if args.out is not None:
        check_output_path(args.out, args.force, inputs=[args.model, args.data, args.json or ""],
                          formats=(".json", ".mat"), what="the scores")
    comp = load_compensator(args.model)
    _warn_if_oracle(comp.center, args.model)
    rec = read_recording(args.data, options=options_as_trained(args, args.data, comp.reading))
    scores = evaluate(comp, rec, rest_position=args.rest_position, level=args.level)
    scores["units"] = dict(rec.units)  # of position and sensor, as the file gave them
    _warn_if_outside(use_flags(comp, rec, comp.estimate(rec, rest_position=args.rest_position)),
                     args.data)
    print(f"{args.data} with {args.model} ({scores['n_samples']} samples); deployable centring: "
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
    status, message = use_verdict(comp, rec, scores, f"{args.data}: deployable")
    scores["verdict"], scores["verdict_message"] = status, message
    if args.json is not None:
        write_json(scores, args.json, force=args.force)
        print(f"wrote {args.json}")
    if args.out is not None:
        if args.out.suffix.lower() == ".mat":
            write_mat(args.out, scores, force=args.force)
        else:
            write_json(scores, args.out, force=args.force)
        print(f"wrote {args.out}")
    if status not in ("ok", "undetermined"):
        print(f"hystkit: evaluate: {status.replace('_', ' ')}: {message}; do not use the "
              f"{comp.model} compensator on data like these", file=sys.stderr)
        far = comp.sensor_outside(rec, margin=FAR_MARGIN)
        say_next(next_step(status, command="evaluate", line_r2=scores["linear_r2"],
                           outside=None if far is None else float(far.mean())))
        return GUARD_EXIT
    print(f"verdict: {status} ({message})")
    return 0


def _level(comp, level: float | None) -> float:
    return comp.band.level if level is None else level


def _count(n: int | None) -> str:
    return "unknown (old model file)" if n is None else str(n)


def _fmt(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.4f}"


def _demo(args: argparse.Namespace) -> int:
    # Imported here so the other subcommands do not pay for loading matplotlib.
    from ..compensation import DEFAULT_CENTER
    from ..studies import DOCUMENT_TABLE_5_5, format_table, run_demo

    out = args.out or Path(f"hystkit-demo-{time.strftime('%Y%m%d-%H%M%S')}")
    check_size("mpl", args.cells, "--cells")
    print(f"hystkit demo: virtual sensor, four experiments, {args.cells}-cell mPL compensator "
          f"fitted on one recording and scored on another (direct mode, deployable centring: "
          f"{DEFAULT_CENTER}; the paper's oracle centring beside it)")
    t0 = time.perf_counter()
    result = run_demo(out, n_cells=args.cells, force=args.force, raw=args.raw, report=True)
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
    from ..studies import format_table  # lazily, as in _demo

    print()
    print(format_table({f"{raw['excitation']} raw": raw["metrics"]},
                       f"Raw path: scope files at {raw['scope_rate_hz']:g} Hz -> preprocess -> "
                       f"fit -> evaluate (cf. the {raw['excitation']} row above)"))
    trip = raw["round_trip"]["validation"]
    print(f"  decoded vs true: position max error {trip['position_max_error_um']:.2f} um "
          f"({trip['position_max_error_counts']:.2f} counts), dR/R rms error "
          f"{trip['sensor_rms_error']:.1e}, {trip['n_illegal']} illegal of {trip['n_edges']} "
          f"encoder transitions")


def _compensation(name: str):
    from .. import compensation  # loaded when a subcommand needs the value

    return getattr(compensation, name)


def _families() -> dict:
    from ..models import FAMILIES

    return FAMILIES


def _family_info() -> dict:
    from ..models import FAMILY_INFO  # names, titles, sizes: no model loads for the help

    return FAMILY_INFO


def _experiment_names() -> list[str]:
    from ..signals import EXPERIMENTS

    return sorted(EXPERIMENTS)


def _add_centring_options(p: argparse.ArgumentParser) -> None:
    deferred(p.add_argument("--center"), choices=lambda: _compensation("CENTERS"),
             default=lambda: _compensation("DEFAULT_CENTER"))
    p._actions[-1].help = ("sensor offset: fit = the training offsets (default); tare = the level "
                        "of the first --tare-seconds of each recording, device at rest; track = "
                        "a causal low-pass drift tracker (time constant --track-seconds); "
                        "recording = ORACLE, the paper's protocol (whole-recording mean, not "
                        "causal); none")
    deferred(p.add_argument("--tare-seconds", type=positive_float),
             default=lambda: _compensation("DEFAULT_TARE_SECONDS"),
             help=lambda: f"tare window at the start of each recording [s] (default "
                          f"{_compensation('DEFAULT_TARE_SECONDS'):g})")
    deferred(p.add_argument("--track-seconds", type=positive_float),
             default=lambda: _compensation("DEFAULT_TRACK_SECONDS"),
             help=lambda: f"drift-tracker time constant [s] (default "
                          f"{_compensation('DEFAULT_TRACK_SECONDS'):g}); slower sensor content "
                          f"than ~1/(2 pi T) is taken for drift")


def _add_level(p: argparse.ArgumentParser) -> None:
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=None,
                   help="nominal coverage of the prediction band, in (0, 1) (default: the "
                        "model's own, 0.90 unless fitted otherwise)")


def _add_rest_position(p: argparse.ArgumentParser) -> None:
    p.add_argument("--rest-position", type=number(), default=None,
                   help="tare centring: position [mm] during the tare window (default: where "
                        "the device rested in training)")


_MODEL_HELP = "model file written by fit or select (.json or .mat)"
# fit's model without --model: the guided first fit (issue 27.5); tests and docs that mean one
# mPL fit say --model mpl (the guided fit takes 15-30 s where one fit takes 1-3 s)
DEFAULT_MODEL = GUIDED_MODEL

# The reading options' note of compensate, whose output keeps the input's names
COMPENSATE_NAMES_NOTE = ("the output keeps the input's column names and time unit, the "
                         "estimate named after the position column")


def register(sub: argparse._SubParsersAction) -> None:
    """Add this module's subcommands to the ``hystkit`` parser."""
    p = sub.add_parser("simulate-sensor", help="record an experiment on the virtual sensor")
    deferred(p.add_argument("--excitation", required=True,
                            help="the experiment of the document to record (ch. 4, table 5.5)"),
             choices=_experiment_names)
    p.add_argument("--seed", type=integer(0, 2**32 - 1), default=0,
                   help="random seed, 0 to 2^32 - 1 (default 0)")
    p.add_argument("--out", type=Path, required=True, help="CSV or Parquet file to write")
    add_simulation_options(p)
    p.add_argument("--gain-drift", type=number(-0.9, 10.0), default=None, metavar="FRACTION",
                   help="multiply the sensor signal by a gain rising linearly from 1 to "
                        "1 + FRACTION over the run (0.1: +10 %%; for 'hystkit stream --adapt')")
    p.add_argument("--references-every", type=number(0, 1e6, low_open=True), default=None,
                   metavar="S", help="add a 'reference' column: the true position at one random "
                   "sample in each S seconds, empty elsewhere (the occasional references of "
                   "'hystkit stream --adapt')")
    p.set_defaults(run=_simulate_sensor)

    p = sub.add_parser("fit", help="fit a compensator to a recording")
    p.add_argument("data", type=Path, nargs="+",
                   help="recording(s): time, position, sensor (CSV/Parquet/.mat); several are "
                        "fitted jointly, each with its own initial state and tare")
    # The registry's names and the guided fit's as the choices: checking a name imports that
    # family only.
    deferred(p.add_argument("--model", default=None), choices=lambda: [*_families(),
                                                                        GUIDED_MODEL],
             help=lambda: "; ".join([*(f"{f.name}: {f.title}" for f in _family_info().values()),
                                     f"{GUIDED_MODEL}: a guided first fit, {GUIDED_HELP}"])
             + f" (default {DEFAULT_MODEL}; mpl when --cells or another option of a named "
               f"model is given)")
    p.add_argument("--budget", type=number(1, 24 * 3600), default=None, metavar="SECONDS",
                   help=f"--model {GUIDED_MODEL} only: seconds for the whole selection "
                        f"(default 60); a candidate not validated within half of it is "
                        f"skipped, said so")
    deferred(p.add_argument("--cells", "--size", type=positive_int, default=None),
             help=lambda: "model size: " + "; ".join(f"{f.name}: {f.size_help} (default "
                                                     f"{f.default_size}, at most "
                                                     f"{size_limit(f)})"
                                                     for f in _family_info().values()))
    p.add_argument("--mode", default="direct",
                   help="direct: fit sensor->position (paper 9.2); inverse: fit "
                        "position->sensor and invert it (paper 9.1)")
    deferred(p._actions[-1], choices=lambda: _compensation("MODES"))
    _add_centring_options(p)
    p.add_argument("--slope-cap", type=slope_cap, default=None,
                   help="models with an Euler slope cap (mpl, mpl-poly, mpl-g, pl, ladder, "
                        "chua): cap on the step gain f'·dt of their non-linear elements, in "
                        "[0.001, 2), default 1 (eq. 5.28-5.29; the ladder allows at most 1; "
                        "each model's docs page says what it caps)")
    p.add_argument("--p", type=number(1, low_open=True), default=None, metavar="P",
                   help="pl only: power p of the cells, > 1 (default 21; 'hystkit pl-search' "
                        "searches it)")
    p.add_argument("--m", type=integer(1, 1000), default=None, metavar="M",
                   help="pl only: number M of output basis functions, 1 to 1000 (default 1)")
    p.add_argument("--s", type=number(0), default=None, metavar="S",
                   help="pl only: smoothing weight S >= 0 (default 0.001)")
    p.add_argument("--out", type=Path, required=True,
                   help="model file to write: .json, or .mat (a MATLAB struct with every field "
                        "of the JSON file; evaluate and compensate read both)")
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=0.90,
                   help="nominal coverage of the prediction band stored in the model (default "
                        "0.90); the band is calibrated on held-out runs: left-out recordings, or "
                        "interleaved cycles of one recording (docs/band.md)")
    p.add_argument("--no-band", action="store_true",
                   help="fit without a prediction band (the band refits the model on each "
                        "validation fold: about four times the fit's time)")
    add_start_options(p)
    add_cost_options(p)
    add_read_options(p)
    p.set_defaults(run=_fit)

    p = sub.add_parser("compensate", help="add a position_estimate column (and flags) to a "
                                          "recording")
    p.add_argument("model", type=Path, help=_MODEL_HELP)
    p.add_argument("data", type=Path, help="recording to compensate (CSV/Parquet/.mat): time "
                                           "and sensor; position is optional")
    _add_rest_position(p)
    p.add_argument("--out", type=Path, required=True,
                   help="file to write, by its extension: .csv, .parquet or .mat (MATLAB: one "
                        "variable per column, with column_names and units); the input's "
                        "columns under its own names, time in its own unit, then the estimate "
                        "named after the position column (position_estimate, or x_mm_estimate "
                        "for a column x_mm), its band position_lower and position_upper (if "
                        "the model has one; x_mm_lower, x_mm_upper) and the flags "
                        "sensor_outside, estimate_outside")
    _add_level(p)
    add_read_options(p)
    # compensate writes the input's names: not the group's note that outputs use hystkit's
    add_trained_note(p, COMPENSATE_NAMES_NOTE)
    p.set_defaults(run=_compensate)

    p = sub.add_parser("evaluate", help="score a compensator on a recording")
    p.add_argument("model", type=Path, help=_MODEL_HELP)
    p.add_argument("data", type=Path, help="recording with the true position (CSV/Parquet/.mat)")
    p.add_argument("--json", type=Path, help="also write the scores to this JSON file (.json)")
    p.add_argument("--out", type=Path,
                   help="also write the scores to this file, by its extension: .json or .mat "
                        "(MATLAB: one variable per score; missing scores are [])")
    _add_rest_position(p)
    _add_level(p)
    add_read_options(p)
    add_trained_note(p)
    p.set_defaults(run=_evaluate)

    p = sub.add_parser("demo", help="the main job on the built-in virtual sensor")
    p.add_argument("--out", type=Path, help="output folder (default: a new timestamped one)")
    p.add_argument("--cells", type=positive_int, default=3,
                   help="mPL cells (default 3: 11 parameters, as the document's model)")
    p.add_argument("--raw", action="store_true",
                   help="also run the lab chain on raw scope files: simulate-sensor --raw -> "
                        "preprocess -> fit -> evaluate (sine, 50 kHz; about 10 s more)")
    p.set_defaults(run=_demo)

