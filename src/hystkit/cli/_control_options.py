"""The options of ``hystkit control`` and ``hystkit stability``: the parser's options
(:func:`control_options`, :func:`stability_options`, from the shared :func:`add_setup_options`)
and the frozen records they parse into (:class:`LoopOptions`, :class:`ControlOptions`,
:class:`StabilityOptions`). Nothing here loads the library: option values that need it
(schemes, families, experiments) are computed when shown or checked.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

from .. import control as hc
from ._common import UsageError, deferred, number, positive_int
from ._read_args import add_read_options

__all__ = ["PID_TYPES", "TUNE_DEFAULTS", "TUNE_TYPES", "Checked", "ControlOptions",
           "LoopOptions", "StabilityOptions", "add_control_options", "add_setup_options",
           "control_options", "stability_options"]


# PID gains (eq. 7.2): 0 < Kp <= 1e9, 1 us <= Ti <= 1e6 s (inf: no integral action),
# 0 <= Td <= 1000 s; one type per slot. Far beyond any tuning of a 0.25 kg stage, and the range
# in which the loop's linearisation and simulation stay well conditioned.
def _gain(text: str) -> float:
    """KP: finite, nonzero, |KP| <= 1e9. A negative gain is allowed: a sign error is an
    experiment worth running (the loop then reports itself unbounded)."""
    value = number(-1e9, 1e9)(text)
    if value == 0:
        raise argparse.ArgumentTypeError("must not be 0 (no feedback at all)")
    return value


PID_TYPES = (_gain, number(1e-6, 1e6, allow_inf=True), number(0, 1e3))
TUNE_TYPES = (number(0, 1e4, low_open=True), number(0, 90, low_open=True, high_open=True))
# defaults of the --tune-nonlinear options (None in the parser: given or not is seen)
TUNE_DEFAULTS = {"tune_objective": "rms", "tune_budget": 300, "min_phase_margin": 30.0,
                 "min_gain_margin": 6.0}


class Checked(argparse.Action):
    """``nargs`` values, each parsed by its own type (argparse gives all one type)."""

    def __init__(self, *args, types=(), **kwargs) -> None:
        self.types = types
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        parsed = []
        for meta, parse, text in zip(self.metavar, self.types, values, strict=True):
            try:
                parsed.append(parse(text))
            except argparse.ArgumentTypeError as exc:
                raise UsageError(f"argument {option_string} {meta}: {exc}") from None
        setattr(namespace, self.dest, parsed)


@dataclass(frozen=True)
class LoopOptions:
    """The options that define a loop, as given (files not read yet)."""

    scheme: str | None
    dob: bool
    dob_hz: float | None
    pid: tuple[float, float, float] | None
    tune: tuple[float, float] | None
    tf: float
    anti_windup: bool
    mass: float
    u_max: float
    sensor: str
    sensor_model: str
    model: str
    training: str | None
    training_excitation: str
    sensor_data: Path | None
    training_data: Path | None
    compensator: Path | None
    model_file: Path | None
    sensor_size: int | None
    model_size: int | None
    no_zero: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> LoopOptions:
        """The loop options of a parsed command line."""
        pid, tune = args.pid, args.tune
        return cls(args.scheme, args.dob, args.dob_hz, None if pid is None else tuple(pid),
                   None if tune is None else tuple(tune), args.tf, args.anti_windup, args.mass,
                   args.u_max, args.sensor, args.sensor_model, args.model, args.training,
                   args.training_excitation, args.sensor_data, args.training_data,
                   args.compensator, args.model_file, args.sensor_size, args.model_size,
                   args.no_zero)

    @property
    def sensor_path(self) -> Path | None:
        """``--sensor MODEL.json``: a model file (anything but the named sensors)."""
        named = self.sensor in ("virtual", "virtual-physics") or self.sensor.startswith(
            "table-ii-")
        return None if named else Path(self.sensor)

    def inputs(self) -> list[Path]:
        """The input files named (never to be overwritten by an output)."""
        return [x for x in (self.sensor_data, self.training_data, self.compensator,
                            self.model_file, Path(self.sensor)) if x is not None]


@dataclass(frozen=True)
class ControlOptions:
    """``hystkit control``'s options beyond the loop's."""

    loop: LoopOptions
    experiment: str | None
    bode: bool
    noise: hc.NoiseSpec | None
    tuning: hc.Tuning | None
    out: Path | None
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ControlOptions:
        """The options of a parsed command line; an option that needs another is one line."""
        if not (args.experiment or args.bode):
            raise UsageError("give --experiment NAME and/or --bode (see 'hystkit control --help')")
        given = [f"--{k.replace('_', '-')}" for k in TUNE_DEFAULTS if getattr(args, k) is not None]
        if given and not args.tune_nonlinear:
            verb = "applies" if len(given) == 1 else "apply"
            raise UsageError(f"{', '.join(given)} only {verb} with --tune-nonlinear")
        tuning = None
        if args.tune_nonlinear:
            value = {k: d if getattr(args, k) is None else getattr(args, k)
                     for k, d in TUNE_DEFAULTS.items()}
            tuning = hc.Tuning(value["tune_objective"], value["tune_budget"],
                               value["min_phase_margin"], value["min_gain_margin"])
        options = cls(LoopOptions.from_args(args), args.experiment, args.bode, args.noise,
                      tuning, args.out, args.force)
        if options.tuning is not None and not options.experiment:
            raise UsageError("--tune-nonlinear tunes on an experiment: give --experiment NAME")
        if options.noise is not None and not options.experiment:
            raise UsageError("--noise runs an experiment with noise: give --experiment NAME")
        return options


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


def _noise_option(text: str):
    try:
        return hc.parse_noise(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _family_names() -> list[str]:
    from ..models import FAMILIES  # the registry: names without the families' code

    return sorted(FAMILIES)


def _excitation_names() -> list[str]:
    from ..signals import EXPERIMENTS

    return sorted(EXPERIMENTS)


# The files a loop may be given, each instead of what it is fitted or run on by default
_LOOP_FILES = {
    "--sensor-data": ("recording (time, position, sensor) to fit S_r on instead of the virtual "
                      "sensor's noise run"),
    "--training-data": ("recording to fit the compensator and S_m on instead of the virtual "
                        "sensor's"),
    "--compensator": ("use this model file (from 'hystkit fit', any family, direct or inverse "
                      "mode) as the compensator"),
    "--model-file": ("use this model file as S_m of scheme (b), run position -> sensor like "
                     "--sensor MODEL.json")}


def add_setup_options(p: argparse.ArgumentParser, *, scheme_required: bool = True) -> None:
    """The options that define a loop (scheme, PID, DOB, plant, sensor models), shared by
    ``hystkit control`` and ``hystkit stability --control``."""
    deferred(p.add_argument("--scheme", required=scheme_required,
                   help="direct: e = r - compensator(s) (fig. 7.1); weighting: "
                        "e = g_s (S_m(r) - s) (fig. 7.8)"),
             choices=lambda: hc.SCHEMES)
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
             default=lambda: hc.MASS)
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
             choices=lambda: hc.TRAININGS)
    deferred(p.add_argument("--training-excitation", default="sine",
                            help="excitation of the training recording (default sine, 0.5 Hz "
                                 "3 mm)"),
             choices=_excitation_names)
    for option, text in _LOOP_FILES.items():
        p.add_argument(option, type=Path, help=text)
    p.add_argument("--sensor-size", "--sensor-cells", type=positive_int, dest="sensor_size",
                   help="size of the fitted S_r (mPL cells; default 3 for mpl, else the "
                        "family's default)")
    p.add_argument("--model-size", "--model-cells", type=positive_int, dest="model_size",
                   help="size of the fitted compensator and S_m (mPL: 3, or 1 with "
                        "--training loop; else the family's default)")
    p.add_argument("--no-zero", action="store_true",
                   help="do not zero the estimates on the sensor's rest reading at start")


def add_control_options(p: argparse.ArgumentParser) -> None:
    """``hystkit control``'s own options (after :func:`add_setup_options`)."""
    deferred(p.add_argument("--experiment",
                   help="sine (eq. 7.3), frequency / amplitude sweeps, cubic trajectory, "
                        "output disturbance steps"),
             choices=lambda: hc.EXPERIMENTS)
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


def control_options(p: argparse.ArgumentParser) -> None:
    """``hystkit control``'s arguments and options."""
    add_setup_options(p)
    add_read_options(p)  # for --sensor-data and --training-data
    add_control_options(p)


def stability_options(p: argparse.ArgumentParser) -> None:
    """``hystkit stability``'s arguments and options: a model file, or a loop (as ``control``'s)."""
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
