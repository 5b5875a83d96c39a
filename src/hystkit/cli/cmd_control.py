"""``hystkit control``: the document's closed-loop experiments (ch. 7) on fitted sensor models."""

from __future__ import annotations

import argparse
import functools
import math
import re
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from . import _control_report as report
from ._common import (
    UsageError,
    add_read_options,
    check_size,
    deferred,
    number,
    positive_int,
    read_options,
)
from ._control_options import PID_TYPES, TUNE_TYPES, Checked

if TYPE_CHECKING:  # the library loads when the command runs
    from ..control import SensorModels
    from ..io import ReadOptions

__all__ = ["add_setup_options", "register", "setup_inputs", "setup_loop"]

# eq. 7.6 (scheme a) and eq. 7.8 (scheme b): the document's plant errors on the eq. 7.3 sine
DOCUMENT_SINE = {"direct": {"e_p_max": 6.94e-4, "e_p_mean": -1.543e-4, "source": "eq. 7.6"},
                 "weighting": {"e_p_max": 1.86e-4, "e_p_mean": -2.29e-5, "source": "eq. 7.8"}}


def _sensor(sensor: str):
    """``S_r`` from ``--sensor``: None (fit on the virtual sensor), the virtual sensor's own
    physics, a table-II column, or a model file run position -> sensor."""
    from ..control import sensor_block, table_ii_sensor, table_ii_sensors, virtual_sensor_block

    if sensor == "virtual":
        return None
    if sensor == "virtual-physics":
        return virtual_sensor_block()
    if sensor.startswith("table-ii-"):
        column = sensor.removeprefix("table-ii-")
        if column not in table_ii_sensors():
            raise UsageError(f"--sensor {sensor}: paper 9.2's table II has columns "
                             f"{', '.join(table_ii_sensors())}")
        return table_ii_sensor(column)
    return _file_block(sensor_block, Path(sensor), "S_r", "--sensor")


def _file_block(make, path: Path, name: str, option: str):
    """A model file as a loop block; a family that cannot serve in that slot is one line."""
    from ..compensation import load_compensator

    try:
        return make(load_compensator(path), name=name)
    except ValueError as exc:
        raise UsageError(f"{option} {path}: {exc}") from None


@functools.lru_cache(maxsize=4)
def _models(training: str, excitation: str, sensor_size: int | None, model_size: int | None,
            sensor_data: Path | None = None, training_data: Path | None = None,
            sensor: str = "virtual", sensor_model: str = "mpl",
            model: str = "mpl", sensor_options: ReadOptions | None = None,
            training_options: ReadOptions | None = None) -> SensorModels:
    # Kept on disk across runs (hystkit.control.cached_sensor_models, keyed by the inputs and
    # the code) and in memory per process (repeated main() calls in one session, e.g. tests).
    from ..control import cached_sensor_models
    from ..io import read_recording

    return cached_sensor_models(
        sensor=_sensor(sensor), training=training, training_excitation=excitation,
        sensor_cells=sensor_size, model_cells=model_size, sensor_model=sensor_model,
        model=model,
        sensor_recording=None if sensor_data is None else read_recording(
            sensor_data, options=sensor_options),
        training_recording=None if training_data is None else read_recording(
            training_data, options=training_options))


def _slug(label: str) -> str:
    return re.sub(r"[^0-9A-Za-z.]+", "_", label).strip("_")


def _outputs(args: argparse.Namespace, out: Path) -> list[Path]:
    from ..control import experiment_cases

    names = []
    if args.experiment:
        names += ["metrics.json", "config.json"]
        labels = [c.label for c in experiment_cases(args.experiment)]
        names += (["response.png"] if len(labels) == 1
                  else ["cases.png"] + [f"case_{_slug(x)}.png" for x in labels])
    else:
        names += ["analysis.json", "config.json"]
    if args.bode:
        names.append("bode.png")
    return [out / n for n in names]


def setup_inputs(args: argparse.Namespace) -> list[Path]:
    """The input files the loop options name (never to be overwritten by an output)."""
    return [x for x in (args.sensor_data, args.training_data, args.compensator,
                        args.model_file, Path(args.sensor)) if x is not None]


def setup_loop(args: argparse.Namespace):
    """``(loop, models, fit_seconds)`` from the options of :func:`add_setup_options`: the
    sensor models fitted (or read) and the loop built; bad combinations are one line."""
    check_size(args.sensor_model, args.sensor_size, "--sensor-size")
    check_size(args.model, args.model_size, "--model-size")
    if args.sensor != "virtual" and args.sensor_data is not None:
        raise UsageError("--sensor-data fits S_r on a recording; it cannot be combined with "
                         f"--sensor {args.sensor}")
    training = args.training or ("recording" if args.sensor in ("virtual", "virtual-physics")
                                 else "loop")
    t_start = time.perf_counter()
    def reading(path: Path | None):
        return None if path is None else read_options(args, path)

    models = _models(training, args.training_excitation, args.sensor_size,
                     args.model_size, args.sensor_data, args.training_data, args.sensor,
                     args.sensor_model, args.model, sensor_options=reading(args.sensor_data),
                     training_options=reading(args.training_data))
    if args.compensator is not None:
        models = replace(models, compensator=_file_block(
            _library("compensator_block"), args.compensator, "S_m^comp", "--compensator"),
            info={**models.info, "compensator_file": str(args.compensator)})
    if args.model_file is not None:
        models = replace(models, model=_file_block(_library("sensor_block"), args.model_file,
                                                   "S_m", "--model-file"),
                         info={**models.info, "model_file": str(args.model_file)})
    t_fit = time.perf_counter() - t_start
    return _loop(args, models), models, t_fit


def _loop(args: argparse.Namespace, models: SensorModels):
    """The configured loop; a library ValueError here is a bad option combination."""
    from ..control import PID, DisturbanceObserver, Plant, build_loop

    try:
        plant = Plant(args.mass, args.u_max)
        pid = None if args.pid is None else PID(args.pid[0], args.pid[1], args.pid[2])
        loop = build_loop(args.scheme, models, pid=pid, plant=plant,
                          zero_at_start=not args.no_zero)
        if args.tune is not None:
            pid = _library("tune_pid")(args.tune[0], args.tune[1], loop=loop)
        pid = replace(pid or loop.pid, tf=args.tf, anti_windup=args.anti_windup)
        loop = replace(loop, pid=pid)
        if args.dob:
            dob = (_library("design_dob")(loop) if args.dob_hz is None
                   else DisturbanceObserver(args.dob_hz))
            loop = replace(loop, dob=dob)
        loop.kernel_arguments()  # every block at the loop's Ts, or the family's refusal
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    return loop


def _control(args: argparse.Namespace) -> int:
    import numpy as np

    from .. import __version__
    from ..control import cached_loop_margins, plot_cases, plot_response, run_experiment
    from ..io import atomic_folder, check_output_folder, write_json

    if not (args.experiment or args.bode):
        raise UsageError("give --experiment NAME and/or --bode (see 'hystkit control --help')")
    stamp = time.strftime("%Y%m%d-%H%M%S")
    out = args.out or Path(f"hystkit-control-{args.scheme}-{args.experiment or 'bode'}-{stamp}")
    paths = _outputs(args, out)
    # refuse before any work
    check_output_folder(out, [p.name for p in paths], args.force, inputs=setup_inputs(args))
    report.resolve_tune_options(args)
    if args.tune_nonlinear and not args.experiment:
        raise UsageError("--tune-nonlinear tunes on an experiment: give --experiment NAME")
    if args.noise is not None and not args.experiment:
        raise UsageError("--noise runs an experiment with noise: give --experiment NAME")
    t_start = time.perf_counter()
    loop, models, t_fit = setup_loop(args)
    tuned = report.tune(args, loop) if args.tune_nonlinear else None
    if tuned is not None:
        loop = replace(loop, pid=tuned.pid)
    margins = cached_loop_margins(loop)  # python-control loads only when not stored
    dob = f"{loop.dob.f_q:.3g} Hz" if loop.dob else "off"
    print(f"hystkit control: scheme {args.scheme}"
          + (f", experiment {args.experiment}" if args.experiment else "")
          + f", DOB {dob}; sensor models in "
          f"{t_fit:.1f} s (S_r: {models.info['sensor_source']}; compensator and S_m: "
          f"{models.info['training_source']})")
    p = loop.pid
    print(f"PID Kp = {p.kp:.4g}, Ti = {p.ti:.4g} s, Td = {p.td:.4g} s, Tf = {p.tf:.3g} s; "
          f"linearised at rest: crossover {report.fmt(margins.crossover_hz)} Hz, phase margin "
          f"{report.fmt(margins.phase_margin_deg)} deg, gain margin "
          f"{report.fmt(margins.gain_margin_db, 'inf')} dB")
    print(f"  closed loop {report.closed_loop(margins)}")  # the verdict on a line of its own
    config = {
        "hystkit_version": __version__, "scheme": args.scheme, "sensor": args.sensor, "experiment": args.experiment,
        "ts": loop.ts, "mass": loop.plant.mass, "u_max": loop.plant.u_max
        if np.isfinite(loop.plant.u_max) else None,
        "pid": {"kp": p.kp, "ti": p.ti if np.isfinite(p.ti) else None, "td": p.td, "tf": p.tf,
                "anti_windup": p.anti_windup,
                "source": ("--tune-nonlinear" if tuned is not None else "--pid" if args.pid
                           else "--tune" if args.tune else "document")},
        "noise": None if args.noise is None else args.noise.to_dict(),
        "dob_f_q": loop.dob.f_q if loop.dob else None, "zeroed_at_start": not args.no_zero,
        "sensor_gain_m_per_unit": loop.sensor_gain, "models": models.info,
        "sensor_fit": models.sensor.info, "compensator_fit": models.compensator.info,
        "model_fit": models.model.info, "fit_seconds": t_fit}
    linear = {"operating_point": "rest (t = 0)", **margins.to_dict()}
    result = run_experiment(args.experiment, loop, args.noise) if args.experiment else None
    if result is not None:
        metrics = {**result.metrics(), "linear": linear}
        if args.experiment == "sine":
            metrics["document"] = DOCUMENT_SINE[args.scheme]
        if tuned is not None:
            metrics["tuning"] = tuned.to_dict()
        report.print_table(metrics)
        if args.noise is not None:
            metrics["noise_study"] = report.noise_study(args, loop)
    # Built in a hidden sibling and renamed into place: the folder appears complete or not at all.
    with atomic_folder(out, args.force, [p.name for p in paths]) as tmp:
        if result is not None:
            write_json(metrics, tmp / "metrics.json")
            title = f"scheme {args.scheme}, {args.experiment}"
            if len(result.cases) == 1:
                plot_response(next(iter(result.cases.values())), title).savefig(
                    tmp / "response.png", dpi=110)
            else:
                plot_cases(result).savefig(tmp / "cases.png", dpi=110)
                for label, resp in result.cases.items():
                    plot_response(resp, f"{title}: {label}").savefig(
                        tmp / f"case_{_slug(label)}.png", dpi=110)
        else:
            write_json({"scheme": args.scheme, "linear": linear}, tmp / "analysis.json")
        if args.bode:
            f, mag, phase = _library("bode_data")(loop)
            _library("plot_bode")(f, mag, phase, margins, f"scheme {args.scheme}: linearised open loop at "
                      f"rest, cut at the plant input").savefig(tmp / "bode.png", dpi=110)
        config["seconds"] = time.perf_counter() - t_start
        write_json(config, tmp / "config.json")
    print(f"wrote {out}/: {', '.join(x.name for x in paths)} "
          f"({config['seconds']:.1f} s)")
    return 0


def _noise_option(text: str):
    from ..control import parse_noise

    try:
        return parse_noise(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _library(name: str):
    from .. import control  # python-control, scipy, numba: loaded when the command runs

    return getattr(control, name)


def _family_names() -> list[str]:
    from ..models import FAMILIES

    return sorted(FAMILIES)


def _excitation_names() -> list[str]:
    from ..signals import EXPERIMENTS

    return sorted(EXPERIMENTS)


def add_setup_options(p: argparse.ArgumentParser, *, scheme_required: bool = True) -> None:
    """The options that define a loop (scheme, PID, DOB, plant, sensor models), shared by
    ``hystkit control`` and ``hystkit stability --control``; :func:`setup_loop` builds it."""
    deferred(p.add_argument("--scheme", required=scheme_required,
                   help="direct: e = r - compensator(s) (fig. 7.1); weighting: "
                        "e = g_s (S_m(r) - s) (fig. 7.8)"),
             choices=lambda: _library("SCHEMES"))
    p.add_argument("--dob", action="store_true", help="add the disturbance observer (sec. 7.4)")
    p.add_argument("--dob-hz", type=number(0, 1e6, low_open=True),
                   help="Q-filter bandwidth [Hz] (default: chosen by design_dob)")
    p.add_argument("--pid", nargs=3, action=Checked, types=PID_TYPES,
                   metavar=("KP", "TI", "TD"),
                   help="PID gains: KP nonzero (|KP| <= 1e9), TI > 0 [s] (inf: no integral action), TD >= 0 [s] "
                        "(default: the document's for the scheme)")
    p.add_argument("--tune", nargs=2, action=Checked, types=TUNE_TYPES,
                   metavar=("FC_HZ", "PM_DEG"),
                   help="tune the PID for this crossover (> 0 Hz) and phase margin (between 0 "
                        "and 90 deg) on the linearised loop")
    p.add_argument("--tf", type=number(0, 1e3), default=0.0,
                   help="derivative filter time constant [s] (default 0: eq. 7.2)")
    p.add_argument("--anti-windup", action="store_true",
                   help="conditional integration while the force saturates (needs --u-max)")
    deferred(p.add_argument("--mass", type=number(1e-6, 1e6),
                   help="moving mass [kg], 1e-6 to 1e6"),
             default=lambda: _library("MASS"))
    p.add_argument("--u-max", type=number(0, low_open=True, allow_inf=True), default=math.inf,
                   help="actuator force limit [N] (default none)")
    p.add_argument("--sensor", default="virtual",
                   metavar="virtual|virtual-physics|table-ii-COLUMN|MODEL.json",
                   help="S_r: a model (family --sensor-model) fitted on the virtual sensor's "
                        "noise run (default); the virtual sensor's own causal physics "
                        "(virtual-physics: no model error, the compensator meets the sensor "
                        "itself; the compensator is fitted on its sine recording, as with "
                        "virtual); a column of paper 9.2's table II run as a sensor "
                        "(its inverse; table-ii-noise is the document's S_r, fig. 7.2); or a "
                        "model file of any family run position -> sensor (an inverse-mode file "
                        "as is, a direct-mode file through its family's inverse)")
    deferred(p.add_argument("--sensor-model", default="mpl",
                            help="family of the fitted S_r (default mpl)"),
             choices=_family_names)
    deferred(p.add_argument("--model", default="mpl",
                            help="family of the fitted compensator and S_m (default mpl)"),
             choices=_family_names)
    deferred(p.add_argument("--training", default=None,
                   help="compensator / S_m data: a virtual-sensor recording (default with "
                        "--sensor virtual or virtual-physics) or S_r's own response to the sine "
                        "(the document's protocol; default with a table-II sensor or a model "
                        "file)"),
             choices=lambda: _library("TRAININGS"))
    deferred(p.add_argument("--training-excitation", default="sine",
                            help="excitation of the training recording (default sine, 0.5 Hz "
                                 "3 mm)"),
             choices=_excitation_names)
    p.add_argument("--sensor-data", type=Path,
                   help="recording (time, position, sensor) to fit S_r on instead of the "
                        "virtual sensor's noise run")
    p.add_argument("--training-data", type=Path,
                   help="recording to fit the compensator and S_m on instead of the virtual "
                        "sensor's")
    p.add_argument("--compensator", type=Path,
                   help="use this model file (from 'hystkit fit', any family, direct or "
                        "inverse mode) as the compensator")
    p.add_argument("--model-file", type=Path,
                   help="use this model file as S_m of scheme (b), run position -> sensor "
                        "like --sensor MODEL.json")
    p.add_argument("--sensor-size", "--sensor-cells", type=positive_int, dest="sensor_size",
                   help="size of the fitted S_r (mPL cells; default 3 for mpl, else the "
                        "family's default)")
    p.add_argument("--model-size", "--model-cells", type=positive_int, dest="model_size",
                   help="size of the fitted compensator and S_m (mPL: 3, or 1 with "
                        "--training loop; else the family's default)")
    p.add_argument("--no-zero", action="store_true",
                   help="do not zero the estimates on the sensor's rest reading at start")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``hystkit control`` to the ``hystkit`` parser."""
    p = sub.add_parser("control", help="closed-loop position control with a hysteretic "
                       "sensor: the document's ch. 7 experiments")
    add_setup_options(p)
    add_read_options(p)  # for --sensor-data and --training-data
    deferred(p.add_argument("--experiment",
                   help="sine (eq. 7.3), frequency / amplitude sweeps, cubic trajectory, "
                        "output disturbance steps"),
             choices=lambda: _library("EXPERIMENTS"))
    p.add_argument("--bode", action="store_true",
                   help="write bode.png: the linearised open loop at rest (alone: "
                        "analysis.json)")
    p.add_argument("--noise", type=_noise_option, metavar="sensor=SD,process=SD[,seed=N]",
                   help="white Gaussian noise in the experiment: SD of the sensor noise "
                        "[sensor units] and of the plant-input force noise [N], seed (default "
                        "0); also runs it without noise and with and without the DOB, and "
                        "prints the comparison")
    p.add_argument("--tune-nonlinear", action="store_true",
                   help="re-tune the PID (from the gains given or the document's) on the "
                        "non-linear loop: minimise the experiment's plant error, keeping the "
                        "linearised margins")
    p.add_argument("--tune-objective", choices=("rms", "max"),
                   help="plant error to minimise with --tune-nonlinear: e_p rms or e_p max "
                        "(default rms; the worst case of the experiment)")
    p.add_argument("--tune-budget", type=positive_int,
                   help="most simulations --tune-nonlinear may run (default 300)")
    p.add_argument("--min-phase-margin", type=number(0, 90, high_open=True),
                   help="--tune-nonlinear constraint on the linearised loop [deg] (default 30)")
    p.add_argument("--min-gain-margin", type=number(0, 60),
                   help="--tune-nonlinear constraint on the linearised loop [dB] (default 6)")
    p.add_argument("--out", type=Path, help="output folder (default: a new timestamped one)")
    p.set_defaults(run=_control)
