"""The main job on built-in data: table 5.5 of the document, rerun on the virtual sensor."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .. import __version__
from ..compensation import evaluate, fit_compensator, interval, with_band
from ..io import atomic_folder, check_output_folder, write_json
from ..preprocess import PreprocessSettings, preprocess_raw
from ..sensors import ScopeSettings, simulate_experiment, simulate_raw
from ..signals import EXPERIMENTS
from ._figures import plot_loops, plot_time_series
from ._html import figure_png, render_page
from ._report_demo import demo_report

__all__ = ["DEMO_FILES", "DOCUMENT_TABLE_5_5", "RAW_DEMO_FILES", "RAW_SCOPE_RATE",
           "REPORT_DEMO_FILES", "VIRTUAL_SENSOR_LABEL", "format_table", "run_demo",
           "run_raw_path"]

# Table 5.5 / paper 9.2 table I: (model R², straight-line R²) on the document's lab data.
DOCUMENT_TABLE_5_5 = {"sine": (0.990, 0.928), "chirp": (0.984, 0.945),
                      "decay": (0.987, 0.710), "noise": (0.958, 0.882)}
DEMO_FILES = ("metrics.json", "noise_trained.json", "config.json", "loops.png",
              "time_series.png")
RAW_DEMO_FILES = ("raw_path.json",)  # written too with raw=True
REPORT_DEMO_FILES = ("report.html",)  # written too with report=True
# What the virtual sensor outputs (hystkit.sensors): the half-bridge's differential signal.
VIRTUAL_SENSOR_LABEL = "ΔR1/R1 − ΔR2/R2 [-]"
FIGURE_DPI = 110
_LOOPS_CAPTION = ("Validation loops: the sensor against the position (top), the mPL and "
                  "straight-line estimates against it (middle, dashed: ideal), their error "
                  "against the position (bottom).")
_SERIES_CAPTION = ("Each validation recording's whole run with the error trace and the 90 % "
                   "prediction band shaded (calibrated on interleaved cycles of the fitting "
                   "recording); right: a zoom on the stretch around the largest mPL error.")
FIT_SEED, VALIDATION_SEED = 1, 2
# The raw path's scope rate: low enough to keep the demo fast (10 M samples per channel and
# recording), high enough for every encoder state to last 25 samples. The lab used 2 and
# 6.25 MHz; `hystkit simulate-sensor --raw --scope-rate 6.25e6` and the benchmark run those.
RAW_SCOPE_RATE = 50e3


def _cell(x: float | None, spec: str = ".4f") -> str:
    """A table cell with a leading space, so that a value wider than its column (R² of
    -2390.9675) still stands apart from its neighbour."""
    return " -" if x is None else " " + format(x, spec)


def format_table(metrics: dict, title: str, reference: dict | None = None) -> str:
    """Plain-text table per excitation: deployable and oracle R² of the model and the line.

    Parameters
    ----------
    metrics : dict
        Per excitation, the scores of :func:`~hystkit.compensation.evaluate`.
    title : str
        First line of the table.
    reference : dict, optional
        Per excitation, the document's (mPL R², line R²) for a further column.

    Returns
    -------
    str
        The table, one line per excitation.
    """
    banded = any(m.get("band_coverage") is not None for m in metrics.values())
    head = (f"{'excitation':<11}{'mPL R²':>9}{'line R²':>9}{'e_rms %':>9}{'loop area %':>13}"
            + (f"{'band cover':>12}" if banded else "")
            + f"{'oracle: mPL R²':>16}{'line R²':>9}")
    if reference:
        head += f"{'document mPL / line':>22}"
    centring = next(iter(metrics.values()))["center"] if metrics else ""
    level = next((m["band_level"] for m in metrics.values() if m.get("band_level")), None)
    band = ("" if level is None else f"; band cover: share of positions inside the "
            f"{level:.0%} prediction band")
    lines = [(f"{title}\ndeployable centring: {centring}{band}; oracle: recording (the "
             f"paper's protocol)"), head]
    for name, m in metrics.items():
        row = (f"{name:<11}{_cell(m['r2']):>9}{_cell(m['linear_r2']):>9}"
               f"{_cell(m['e_rms_pct'], '.2f'):>9}{_cell(m['loop_area'], '.2f'):>13}"
               + (f"{_cell(m.get('band_coverage'), '.3f'):>12}" if banded else "")
               + f"{_cell(m['r2_oracle']):>16}{_cell(m['linear_r2_oracle']):>9}")
        if reference and name in reference:
            row += f"{_cell(reference[name][0], '.3f'):>15} / {reference[name][1]:.3f}"
        lines.append(row)
    return "\n".join(lines)


def run_demo(out_dir: str | Path, *, n_cells: int = 3, force: bool = False,
             progress: Callable[[str], None] = print, raw: bool = False,
             report: bool = False) -> dict:
    """Simulate the four experiments, fit on each fitting recording, score on its validation one.

    Writes ``metrics.json`` (per excitation, the keys of :func:`~hystkit.compensation.evaluate`),
    ``noise_trained.json`` (the noise-trained compensator scored on every excitation: does
    compensation generalise?), ``config.json`` and the figures ``loops.png``,
    ``time_series.png``; with `raw`, also ``raw_path.json`` from :func:`run_raw_path` (the
    returned dict then has a ``raw_path`` key); with `report`, also ``report.html``, one
    self-contained page of all of it (:func:`~hystkit.studies._report_demo.demo_report`).
    Checks every output path before any work, and
    publishes the folder atomically (:func:`~hystkit.io.atomic_folder`): interrupted or failed,
    it leaves no folder and no file; into an existing folder, the files go in only once all
    were built.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        Output folder.
    n_cells : int, default 3
        Cells of the mPL model fitted.
    force : bool, default False
        Replace same-named files in an existing folder.
    progress : callable, default print
        Called with one line per step.
    raw : bool, default False
        Also run the raw-file chain (:func:`run_raw_path`).
    report : bool, default False
        Also write ``report.html``.

    Returns
    -------
    dict
        ``metrics``, ``noise_trained`` and ``config`` as written (and ``raw_path`` with `raw`).

    Raises
    ------
    OutputExistsError
        An output file exists and `force` is False.
    """
    out = Path(out_dir)
    names = DEMO_FILES + (RAW_DEMO_FILES if raw else ()) + (REPORT_DEMO_FILES if report else ())
    check_output_folder(out, names, force)
    t_start = time.perf_counter()
    recordings, compensators, metrics, shown, bands = {}, {}, {}, {}, {}
    for name in EXPERIMENTS:
        fit_rec = simulate_experiment(name, FIT_SEED)
        val_rec = simulate_experiment(name, VALIDATION_SEED)
        comp = with_band(fit_compensator(fit_rec, n_cells), [fit_rec], n_cells)
        recordings[name], compensators[name] = val_rec, comp
        metrics[name] = evaluate(comp, val_rec)
        shown[name] = (val_rec, comp.estimate(val_rec), comp.estimate_linear(val_rec))
        if comp.band is not None:
            bands[name] = interval(comp, val_rec, shown[name][1])
        progress(f"  {name:<6} fitted in {comp.fit_info['fit_seconds']:.2f} s "
                 f"({fit_rec.n_samples} samples, {n_cells} cells, "
                 f"{comp.structure.n_params} parameters)")
    noise_trained = {name: evaluate(compensators["noise"], rec)
                     for name, rec in recordings.items()}
    raw_path = run_raw_path(n_cells, progress=progress) if raw else None
    config = {"hystkit_version": __version__, "n_cells": n_cells, "mode": "direct",
              "center": comp.center, "fit_seed": FIT_SEED, "validation_seed": VALIDATION_SEED,
              "sensor": "VirtualSensor() defaults", "seconds": time.perf_counter() - t_start}
    loops = figure_png(plot_loops(shown, sensor_label=VIRTUAL_SENSOR_LABEL), FIGURE_DPI)
    series = figure_png(plot_time_series(shown, bands=bands or None, band_label="90% band"),
                        FIGURE_DPI)
    figures = {"loops": (loops, _LOOPS_CAPTION), "time_series": (series, _SERIES_CAPTION)}
    with atomic_folder(out, force, names) as tmp:
        write_json(metrics, tmp / "metrics.json")
        write_json(noise_trained, tmp / "noise_trained.json")
        if raw_path is not None:
            write_json(raw_path, tmp / "raw_path.json")
        write_json(config, tmp / "config.json")
        for name, (png, _) in figures.items():
            (tmp / f"{name}.png").write_bytes(png)
        if report:
            page = demo_report(metrics, noise_trained, compensators, config, figures,
                               DOCUMENT_TABLE_5_5)
            footer = (f"written by hystkit {__version__}; self-contained: figures embedded, "
                      f"nothing loaded from outside")
            (tmp / "report.html").write_text(render_page(page.title, page.sections, footer),
                                             encoding="utf-8")
    result = {"metrics": metrics, "noise_trained": noise_trained, "config": config}
    return result if raw_path is None else {**result, "raw_path": raw_path}


def run_raw_path(n_cells: int = 3, *, excitation: str = "sine", scope_rate: float = RAW_SCOPE_RATE,
                 progress: Callable[[str], None] = print) -> dict:
    """The lab's whole chain on the virtual sensor: raw scope files -> preprocess -> fit -> score.

    Writes the fitting and validation recordings of `excitation` as raw scope files (bridge
    voltages and the merged encoder signal at `scope_rate`) to a temporary folder, preprocesses
    them (eq. 4.2-4.5, encoder decoding, 20 Hz zero-phase filter, 40 Hz), fits the compensator
    on one and scores it on the other, and compares the decoded position and dR/R with the
    simulator's truth.

    Returns
    -------
    dict
        ``metrics`` (the keys of :func:`~hystkit.compensation.evaluate`), ``round_trip``
        (maximum position error [um] and [counts], dR/R error, illegal transitions) and
        ``preprocess`` (the validation recording's report).
    """
    t_start = time.perf_counter()
    recordings, round_trip, reports = {}, {}, {}
    with tempfile.TemporaryDirectory(prefix="hystkit-raw-") as folder:
        for role, seed in (("fit", FIT_SEED), ("validation", VALIDATION_SEED)):
            path = Path(folder) / f"{excitation}_{seed}.parquet"
            truth = simulate_raw(path, excitation, seed, scope=ScopeSettings(fs=scope_rate))
            result = preprocess_raw(path, PreprocessSettings(r_bridge=ScopeSettings.r_bridge,
                                                             v_supply=ScopeSettings.v_supply))
            ref, rec = truth.recording(), result.recording
            position_error = float(np.max(np.abs(rec.position - ref.position)))
            round_trip[role] = {
                "position_max_error_um": 1e3 * position_error,
                "position_max_error_counts": position_error / truth.encoder_mm,
                "sensor_max_error": float(np.max(np.abs(rec.sensor - ref.sensor))),
                "sensor_rms_error": float(np.sqrt(np.mean((rec.sensor - ref.sensor) ** 2))),
                "n_illegal": result.report.n_illegal, "n_edges": result.report.n_edges}
            recordings[role], reports[role] = rec, result.report.to_dict()
    comp = fit_compensator(recordings["fit"], n_cells)
    metrics = evaluate(comp, recordings["validation"])
    progress(f"  raw path: {excitation} at {scope_rate:g} Hz, "
             f"{reports['fit']['n_samples']} samples per channel and recording, preprocessed "
             f"and fitted in {time.perf_counter() - t_start:.2f} s")
    return {"excitation": excitation, "scope_rate_hz": scope_rate, "n_cells": n_cells,
            "metrics": metrics, "round_trip": round_trip, "preprocess": reports["validation"],
            "seconds": time.perf_counter() - t_start}
