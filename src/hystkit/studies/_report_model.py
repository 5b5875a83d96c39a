"""The report of one model file on the user's recordings: provenance, fit, scores, figures.

Scores come from :func:`hystkit.compensation.evaluate`, the function ``hystkit evaluate`` runs:
the deployable ones first (the compensator's own centring), the oracle ones (the paper's
protocol, which needs the whole recording) after them and labelled so.
"""

from __future__ import annotations

import datetime
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from matplotlib.figure import Figure

from .._docfill import docfiller
from ..compensation import (
    Compensator,
    center_label,
    evaluate,
    interval,
    load_compensator,
    use_verdict,
)
from ..compensation import named_floats as named_parameters  # the standard errors' order
from ..io import Recording
from ._figures import DEFAULT_SENSOR_LABEL, plot_loops, plot_time_series
from ._html import Section, definition_list, figure_png, note, paragraph, png_block, table

__all__ = ["FIGURE_DPI", "ReportContent", "compensator_sections", "fit_section", "model_report",
           "named_parameters", "score_section"]

# What the builders of a report page return (%(report_content)s).
REPORT_ENTRIES = {
    "report_content": """Returns
-------
ReportContent
    The page's title, sections and figures.""",
}
fill_report_doc = docfiller(REPORT_ENTRIES.__getitem__)

# (evaluate key, column heading, format)
_SCORES = (("r2", "R²", ".4f"), ("e_rms_pct", "e_rms %", ".3f"), ("e_max_pct", "e_max %", ".3f"),
           ("sinad_db", "SINAD dB", ".2f"), ("loop_area", "loop area %", ".3f"))
FIGURE_DPI = 100  # the page's PNGs and the PNG files: sharp at the page's width, ~100 kB each


@dataclass
class ReportContent:
    """What a report shows: a title, sections, and its figures by file stem: ``pngs`` (every
    figure, as embedded in the page) and ``figures`` (those drawn here, which can also be saved
    as SVG or PDF; a ``control`` run's own PNG files have no Figure).

    Parameters
    ----------
    title : str
        The page title.
    sections : list of Section, optional
        The page's sections, in order.
    pngs : dict of str to bytes, optional
        Every figure as PNG, by file stem.
    figures : dict of str to matplotlib.figure.Figure, optional
        The figures drawn here, by file stem.
    prefix : str, optional
        Put before every figure name (several folders on one page).
    """

    title: str
    sections: list[Section] = field(default_factory=list)
    pngs: dict[str, bytes] = field(default_factory=dict)
    figures: dict[str, Figure] = field(default_factory=dict)
    prefix: str = ""  # put before every figure name (several folders on one page)

    def add_figure(self, section: Section, name: str, fig: Figure, caption: str) -> None:
        """Render `fig` once: embedded in `section`, kept for the figure files."""
        self.add_png(section, name, figure_png(fig, FIGURE_DPI), caption)
        self.figures[self.prefix + name] = fig

    def add_png(self, section: Section, name: str, png: bytes, caption: str) -> None:
        name = self.prefix + name
        if name in self.pngs:
            raise ValueError(f"two figures named {name!r}")
        self.pngs[name] = png
        section.add(png_block(png, caption))


def _provenance(comp: Compensator, model_path: Path | None, version: str | None) -> Section:
    info = comp.fit_info
    items = [("model file", str(model_path) if model_path else "(in memory)"),
             ("model", f"{comp.model}: {comp.family.title}"),
             ("structure", ", ".join(f"{k} = {_for_people(v)}"
                                     for k, v in comp.structure.to_dict().items())),
             ("mode", comp.mode), ("centring", center_label(comp.center)),
             ("fitted on", ", ".join(info.get("training_sources") or
                                     [info.get("training_source") or "not stored"])),
             ("training samples", info.get("training_samples")),
             ("fit date", info.get("fit_date") or "not stored in the model file"),
             ("written by hystkit", version or "not stored")]
    if model_path is not None:
        stamp = datetime.datetime.fromtimestamp(os.stat(model_path).st_mtime, datetime.UTC)
        items.append(("file last modified", stamp.strftime("%Y-%m-%d %H:%M UTC")))
    return Section("Model file").add(definition_list(items))


def fit_section(comp: Compensator, title: str = "Fit", sub: bool = False) -> Section:
    """Fit status, solver, training scores, bound hits and the parameter table."""
    info = comp.fit_info
    section = Section(title, sub=sub)
    status = info.get("status")
    if status is None:
        section.add(note("fit status: not stored in the model file"))
    elif status == "ok":
        section.add(note(f"fit status: ok ({info.get('status_message', '')})", "good"))
    else:
        section.add(note(f"fit status: {status.replace('_', ' ')}: "
                         f"{info.get('status_message', '')}. Do not use this model as a "
                         f"compensator.", "bad"))
    section.add(definition_list([
        ("solver", info.get("message")), ("converged", info.get("converged")),
        ("starts", info.get("n_starts")), ("evaluations", info.get("n_evaluations")),
        ("fit time [s]", _fixed(info.get("fit_seconds"), ".2f")),
        ("cost (SSE, normalised)", _fixed(info.get("cost"), ".5g")),
        ("training R²", _fixed(info.get("training_r2"), ".4f")),
        ("training R², straight line", _fixed(info.get("training_linear_r2"), ".4f")),
        ("AIC / BIC", f"{_fixed(info.get('aic'), '.1f')} / {_fixed(info.get('bic'), '.1f')}"),
        ("parameters on a search-box bound",
         ", ".join(info["on_bounds"]) if info.get("on_bounds") else
         ("none" if "on_bounds" in info else "not stored")),
        ("at the model's own limits", "; ".join(info.get("at_model_limits") or ()) or "none"),
        ("redundant cells", "; ".join(info.get("redundant") or ()) or "none found"),
        ("prediction band", info.get("band") or "none (fitted without one)"),
        ("joint fit", info.get("joint_fit") or "no (one recording)")]))
    section.add(_parameter_table(comp))
    return section


def _for_people(value: object) -> object:
    """A float to 10 significant digits (dt = 0.02, not 0.019999999999999574: the sample time
    a recording's time column gives, with its rounding); anything else as it is."""
    return f"{value:.10g}" if isinstance(value, float) else value


def _fixed(value: object, spec: str) -> str:
    return "not stored" if value is None else format(value, spec)


def _parameter_table(comp: Compensator) -> str:
    """Fitted values with their standard errors (Gauss-Newton, stored by the fit)."""
    named = named_parameters(comp.params.to_dict())
    names = [name for name, _ in named]
    se = comp.fit_info.get("standard_errors")
    if not se or len(se.get("values", ())) != len(names):
        rows = [(name, value, "not stored") for name, value in named]
        return (table(("parameter", "value", "standard error"), rows, spec=".6g")
                + paragraph("Standard errors are not stored in this model file (written "
                            "before they were); refit to get them."))
    fixed = se.get("fixed", [])  # held fixed by the fit (a gauge): no SE, not undetermined
    rows = [(n, v, s, "fixed by the fit" if n in fixed else "undetermined" if r is None
             else f"{100 * r:.3g} %")
            for n, v, s, r in zip(names, se["values"], se["standard_errors"], se["relative"])]
    blind = sum(s is None for s in se["standard_errors"]) - len(fixed)
    text = ("Standard errors: Gauss-Newton, s² (JᵀJ)⁻¹ from the finite-difference Jacobian at "
            f"the optimum (condition number of JᵀJ {_fixed(se.get('condition_number'), '.3g')})"
            + (f"; {blind} parameter(s) not determined by the data (–)" if blind else "")
            + (f"; {', '.join(fixed)} fixed by the fit (its gauge)." if fixed else ".")
            + (f" Caveat: {se['caveat']}." if se.get("caveat") else ""))
    return (table(("parameter", "value", "standard error", "relative"), rows, spec=".6g")
            + paragraph(text))


def score_section(comp: Compensator, scores: Mapping[str, dict]) -> Section:
    """Deployable scores of every recording, then the oracle ones, from `evaluate`'s dicts."""
    head = ("recording", "", *(label for _, label, _ in _SCORES))
    deployable, oracle = [], []
    for name, s in scores.items():
        for rows, suffix in ((deployable, ""), (oracle, "_oracle")):
            rows.append((name, comp.model, *(_score_cell(s, f"{k}{suffix}", f)
                                             for k, _, f in _SCORES)))
            rows.append((name, "straight line", *(_score_cell(s, f"linear_{k}{suffix}", f)
                                                  for k, _, f in _SCORES)))
    first = next(iter(scores.values()))
    section = Section("Scores")
    section.add(paragraph(f"Deployable: centring {first['center']}, what the compensator "
                          f"delivers in use. Errors in % of the fitting data's largest "
                          f"|position| (eq. 5.10-5.11); loop area: eq. 5.15, 0 for a perfect "
                          f"compensator."),
                table(head, deployable, text_columns=2))
    # why a score is n/a (e.g. SINAD of a recording too short for its fundamental), once each
    for text in dict.fromkeys(f"{name}: {why}" for name, s in scores.items()
                              for why in s.get("notes", {}).values()):
        section.add(note(text))
    trained = _training_names(comp) & set(scores)
    if trained:
        section.add(note(f"{', '.join(sorted(trained))}: the file name of a recording the model "
                         f"was fitted on; if it is that recording, its scores are training "
                         f"scores, not validation."))
    section.add(paragraph(f"Oracle: centring {first['center_oracle']}, the paper's protocol. It "
                          f"removes each recording's own sensor mean and adds its true mean "
                          f"position, which no compensator in use can know: for comparison "
                          f"with the document only."),
                table(head, oracle, text_columns=2, row_classes=["oracle"] * len(oracle)))
    # the shared verdict of `evaluate`, per recording, on the deployable scores
    for name, s in scores.items():
        if s.get("verdict") not in (None, "ok", "undetermined"):
            section.add(note(f"{name}: {s['verdict'].replace('_', ' ')}: {s['verdict_message']}"
                             f"; do not use the {comp.model} compensator on data like these.",
                             "bad"))
    banded = [(name, f"{s['band_level']:.0%}", _fixed_or_none(s["band_coverage"], ".3f"),
               _fixed_or_none(s["band_width_median"], ".4g"),
               _fixed_or_none(s["interval_score"], ".4g"))
              for name, s in scores.items() if s.get("band_coverage") is not None]
    if banded:
        section.add(paragraph("Prediction band (deployable): the share of samples whose "
                              "position it covers, its median width and the interval score "
                              "(width plus 2 / (1 - level) times the miss; lower is better)."),
                    table(("recording", "level", "coverage", "median width", "interval score"),
                          banded, text_columns=2))
    guards = [(name, s["n_samples"], _count(s["n_sensor_outside"]),
               _count(s["n_estimate_outside"]), _fixed_or_none(s["sensor_loop_area"], ".3f"))
              for name, s in scores.items()]
    section.add(table(("recording", "samples", "sensor outside training",
                       "estimate outside training", "sensor loop area %"), guards))
    return section


def _training_names(comp: Compensator) -> set[str]:
    """File names of the recordings the model file says it was fitted on."""
    info = comp.fit_info
    sources = info.get("training_sources") or [info.get("training_source") or ""]
    return {Path(s).name for s in sources if s}


def _score_cell(scores: Mapping[str, object], key: str, spec: str) -> str | None:
    """A score formatted; "n/a" where `evaluate` said why it has none (its ``notes``)."""
    if scores[key] is None and key in scores.get("notes", {}):
        return "n/a"
    return _fixed_or_none(scores[key], spec)


def _fixed_or_none(value: float | None, spec: str) -> str | None:
    return None if value is None else format(value, spec)


def _count(n: int | None) -> str:
    return "unknown (old model file)" if n is None else str(n)


def compensator_sections(comp: Compensator, recordings: Mapping[str, Recording], *,
                         model_path: Path | None = None, version: str | None = None,
                         sensor_label: str = DEFAULT_SENSOR_LABEL,
                         prefix: str = "") -> ReportContent:
    """Sections and figures of one compensator on named recordings (each needs a position).

    Figures (file stems ``{prefix}loops`` and ``{prefix}time_series``): the loops before and
    after compensation with the error against the position, and every recording's whole run
    with its error trace (:mod:`hystkit.studies._figures`). `version`: the hystkit version
    that wrote the model file.
    """
    content = ReportContent(title="")
    content.sections += [_provenance(comp, model_path, version), fit_section(comp)]
    scores, shown, bands = {}, {}, {}
    for name, rec in recordings.items():
        scores[name] = evaluate(comp, rec)
        scores[name]["verdict"], scores[name]["verdict_message"] = use_verdict(
            scores[name], "deployable")
        shown[name] = (rec, comp.estimate(rec), comp.estimate_linear(rec))
        if comp.band is not None:
            bands[name] = interval(comp, rec, shown[name][1])
    content.sections.append(score_section(comp, scores))
    figures = Section("Figures")
    content.sections.append(figures)
    centring = center_label(comp.center)
    content.add_figure(
        figures, f"{prefix}loops",
        plot_loops(shown, sensor_label=sensor_label, model_label=comp.model),
        f"Loops: the sensor against the position (top), the {comp.model} and straight-line "
        f"estimates against it (middle, dashed: ideal) and their error (bottom); deployable "
        f"centring {centring}.")
    content.add_figure(
        figures, f"{prefix}time_series",
        plot_time_series(shown, model_label=comp.model, bands=bands or None,
                         band_label=f"{comp.band.level:.0%} band" if comp.band else "band"),
        "Each recording's whole run: measured and estimated position, and the error "
        "(estimate − position); right: a zoom on the stretch around the largest "
        f"{comp.model} error."
        + (f" Shaded: the {comp.band.level:.0%} prediction band (deployable: the sensor up to "
           f"each sample and the model file), around the error in the lower panels: the "
           f"band covers the position where the shading holds 0." if comp.band else ""))
    return content


@fill_report_doc
def model_report(model_path: Path, recordings: Mapping[str, Recording], *,
                 sensor_label: str = DEFAULT_SENSOR_LABEL) -> ReportContent:
    """The page of a model file (read with :func:`~hystkit.compensation.load_compensator`,
    which checks it) on named recordings.

    Parameters
    ----------
    model_path : pathlib.Path
        The model file.
    recordings : mapping of str to Recording
        Recordings to score it on, by name.
    sensor_label : str, default "sensor"
        The sensor axis' label in the loop figure.

    %(report_content)s

    Raises
    ------
    InputError
        A missing, damaged or foreign model file.
    """
    comp = load_compensator(model_path)
    version = _written_by(Path(model_path))
    content = compensator_sections(comp, recordings, model_path=Path(model_path),
                                   version=version, sensor_label=sensor_label)
    content.title = f"hystkit report: {Path(model_path).name} on {', '.join(recordings)}"
    return content


def _written_by(path: Path) -> str:
    """The hystkit version a JSON model file names (a top-level key the Compensator does not
    keep). The file was checked by ``load_compensator``."""
    if path.suffix.lower() != ".json":
        return "not shown for a .mat model file"
    return json.loads(path.read_text(encoding="utf-8")).get("hystkit_version") or "not stored"
