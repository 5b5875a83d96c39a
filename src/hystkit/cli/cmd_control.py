"""``hystkit control``: the document's closed-loop experiments (ch. 7) on fitted sensor models.

The command line parses into :class:`~hystkit.cli._control_options.ControlOptions`, the files it
names are read into a :class:`hystkit.control.LoopSetup`, :func:`hystkit.control.run_control`
runs it, and the run is printed (``_control_report.py``) and written.
"""

from __future__ import annotations

import argparse
import math
import re
import time
from pathlib import Path

from .. import __version__, compensation
from .. import control as hc
from .. import io as hio
from . import _control_report as report
from ._common import UsageError, check_size
from ._control_options import ControlOptions, LoopOptions
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["loop_error", "loop_setup", "run_control_command"]

# eq. 7.6 (scheme a) and eq. 7.8 (scheme b): the document's plant errors on the eq. 7.3 sine
DOCUMENT_SINE = {"direct": {"e_p_max": 6.94e-4, "e_p_mean": -1.543e-4, "source": "eq. 7.6"},
                 "weighting": {"e_p_max": 1.86e-4, "e_p_mean": -2.29e-5, "source": "eq. 7.8"}}


def _model_file(path: Path | None, option: str):
    """A model file for a loop slot; a file that cannot be read is one line naming it."""
    if path is None:
        return None
    try:
        return compensation.load_compensator(path)
    except ValueError as exc:
        raise UsageError(f"{option} {path}: {exc}") from None


def loop_setup(options: LoopOptions, reader: Reader) -> hc.LoopSetup:
    """The library's loop description from the options: sizes checked, files read (with the
    command line's reading options, `reader`)."""
    check_size(options.sensor_model, options.sensor_size, "--sensor-size")
    check_size(options.model, options.model_size, "--model-size")
    if options.sensor != "virtual" and options.sensor_data is not None:
        raise UsageError("--sensor-data fits S_r on a recording; it cannot be combined with "
                         f"--sensor {options.sensor}")
    reading = {path: reader.options(path)
               for path in (options.sensor_data, options.training_data) if path is not None}
    sensor_file = _model_file(options.sensor_path, "--sensor")
    recordings = [None if path is None else hio.read_recording(path, options=reading[path])
                  for path in (options.sensor_data, options.training_data)]
    compensator = _model_file(options.compensator, "--compensator")
    model_file = _model_file(options.model_file, "--model-file")
    provenance = {key: str(path) for key, path in (("compensator_file", options.compensator),
                                                   ("model_file", options.model_file)) if path}
    pid = None if options.pid is None else hc.PID(*options.pid)
    return hc.LoopSetup(
        options.scheme, options.sensor, sensor_file, options.sensor_model, options.model,
        options.sensor_size, options.model_size, options.training, options.training_excitation,
        recordings[0], recordings[1], compensator, model_file, pid, options.tune, options.tf,
        options.anti_windup, options.mass, options.u_max, options.dob, options.dob_hz,
        not options.no_zero, provenance)


def loop_error(exc: ValueError, options: LoopOptions) -> UsageError:
    """A part of the loop that cannot serve, as the option that named it."""
    prefix = {"sensor": f"--sensor {options.sensor}: ",
              "compensator": f"--compensator {options.compensator}: ",
              "model": f"--model-file {options.model_file}: ",
              "tuning": "--tune-nonlinear: ",
              "noise": "--noise: the DOB comparison needs a DOB: "}.get(exc.part, "")
    return UsageError(prefix + str(exc))


def _slug(label: str) -> str:
    return re.sub(r"[^0-9A-Za-z.]+", "_", label).strip("_")


def _outputs(options: ControlOptions, out: Path) -> list[Path]:
    names = []
    if options.experiment:
        names += ["metrics.json", "config.json"]
        labels = [c.label for c in hc.experiment_cases(options.experiment)]
        names += (["response.png"] if len(labels) == 1
                  else ["cases.png"] + [f"case_{_slug(x)}.png" for x in labels])
    else:
        names += ["analysis.json", "config.json"]
    if options.bode:
        names.append("bode.png")
    return [out / n for n in names]


def _config(options: ControlOptions, run: hc.ControlRun) -> dict:
    loop, models, p = run.loop, run.setup.models, run.loop.pid
    given = options.loop
    return {
        "hystkit_version": __version__, "scheme": given.scheme, "sensor": given.sensor,
        "experiment": options.experiment, "ts": loop.ts, "mass": loop.plant.mass,
        "u_max": loop.plant.u_max if math.isfinite(loop.plant.u_max) else None,
        "pid": {"kp": p.kp, "ti": p.ti if math.isfinite(p.ti) else None, "td": p.td, "tf": p.tf,
                "anti_windup": p.anti_windup,
                "source": ("--tune-nonlinear" if run.tuned is not None else "--pid" if given.pid
                           else "--tune" if given.tune else "document")},
        "noise": None if options.noise is None else options.noise.to_dict(),
        "dob_f_q": loop.dob.f_q if loop.dob else None, "zeroed_at_start": not given.no_zero,
        "sensor_gain_m_per_unit": loop.sensor_gain, "models": models.info,
        "sensor_fit": models.sensor.info, "compensator_fit": models.compensator.info,
        "model_fit": models.model.info, "fit_seconds": run.setup.fit_seconds}


def _metrics(options: ControlOptions, run: hc.ControlRun, linear: dict) -> dict:
    metrics = {**run.result.metrics(), "linear": linear}
    if options.experiment == "sine":
        metrics["document"] = DOCUMENT_SINE[options.loop.scheme]
    if run.tuned is not None:
        metrics["tuning"] = run.tuned.to_dict()
    return metrics


def _write(options: ControlOptions, run: hc.ControlRun, folder: Path, metrics: dict | None,
           linear: dict) -> None:
    scheme = options.loop.scheme
    if metrics is not None:
        hio.write_json(metrics, folder / "metrics.json")
        title = f"scheme {scheme}, {options.experiment}"
        if len(run.result.cases) == 1:
            hc.plot_response(next(iter(run.result.cases.values())), title).savefig(
                folder / "response.png", dpi=110)
        else:
            hc.plot_cases(run.result).savefig(folder / "cases.png", dpi=110)
            for label, resp in run.result.cases.items():
                hc.plot_response(resp, f"{title}: {label}").savefig(
                    folder / f"case_{_slug(label)}.png", dpi=110)
    else:
        hio.write_json({"scheme": scheme, "linear": linear}, folder / "analysis.json")
    if run.bode is not None:
        hc.plot_bode(*run.bode, run.margins, f"scheme {scheme}: linearised open loop at "
                     f"rest, cut at the plant input").savefig(folder / "bode.png", dpi=110)


def run_control_command(args: argparse.Namespace) -> int:
    """``hystkit control``: the loop set up, run, printed and written."""
    options = ControlOptions.from_args(args)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    out = options.out or Path(f"hystkit-control-{options.loop.scheme}-"
                              f"{options.experiment or 'bode'}-{stamp}")
    paths = _outputs(options, out)
    # refuse before any work
    hio.check_output_folder(out, [p.name for p in paths], options.force,
                            inputs=options.loop.inputs())
    t_start = time.perf_counter()
    try:
        run = hc.run_control(loop_setup(options.loop, Reader(given_read_options(args))),
                             experiment=options.experiment, noise=options.noise,
                             tuning=options.tuning, bode=options.bode)
    except hc.LoopError as exc:
        raise loop_error(exc, options.loop) from None
    report.print_run(options, run)
    linear = {"operating_point": "rest (t = 0)", **run.margins.to_dict()}
    metrics = None if run.result is None else _metrics(options, run, linear)
    if metrics is not None:
        report.print_table(metrics)
        if run.noise_study is not None:
            report.print_noise_study(run, options.noise)
            metrics["noise_study"] = run.noise_study
    config = _config(options, run)
    # Built in a hidden sibling and renamed into place: the folder appears complete or not at all.
    with hio.atomic_folder(out, options.force, [p.name for p in paths]) as tmp:
        _write(options, run, tmp, metrics, linear)
        config["seconds"] = time.perf_counter() - t_start
        hio.write_json(config, tmp / "config.json")
    print(f"wrote {out}/: {', '.join(x.name for x in paths)} "
          f"({config['seconds']:.1f} s)")
    return 0

