"""The demo's page: table 5.5 rerun on the virtual sensor, its figures and every fit, on one page.

Built from what :func:`~hystkit.studies.run_demo` computed (nothing is fitted again), so the
page shows exactly the numbers of ``metrics.json`` and ``noise_trained.json`` and the figures of
``loops.png`` and ``time_series.png``.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..compensation import Compensator
from ._html import Section, definition_list, paragraph, table
from ._report_model import ReportContent, fit_section

__all__ = ["demo_report"]

_COLUMNS = (("r2", ".4f"), ("linear_r2", ".4f"), ("e_rms_pct", ".2f"), ("e_max_pct", ".2f"),
            ("loop_area", ".2f"))


def _cells(m: dict, suffix: str) -> list[str | None]:
    return [None if m[f"{k}{suffix}"] is None else format(m[f"{k}{suffix}"], spec)
            for k, spec in _COLUMNS]


def _score_tables(metrics: Mapping[str, dict], reference: Mapping[str, tuple] | None) -> list:
    head = ("excitation", "mPL R²", "line R²", "e_rms %", "e_max %", "loop area %")
    deployable = [(name, *_cells(m, ""),
                   *((f"{reference[name][0]:.3f} / {reference[name][1]:.3f}",)
                     if reference else ())) for name, m in metrics.items()]
    oracle = [(name, *_cells(m, "_oracle")) for name, m in metrics.items()]
    return [table(head + (("document mPL / line R²",) if reference else ()), deployable),
            paragraph("Oracle (centring recording, the paper's protocol: each recording's own "
                      "sensor mean removed and its true mean position added back, which no "
                      "compensator in use can know):"),
            table(head, oracle, row_classes=["oracle"] * len(oracle))]


def demo_report(metrics: Mapping[str, dict], noise_trained: Mapping[str, dict],
                compensators: Mapping[str, Compensator], config: dict,
                figures: Mapping[str, tuple[bytes, str]],
                reference: Mapping[str, tuple] | None = None) -> ReportContent:
    """The demo's page.

    Parameters
    ----------
    metrics, noise_trained : mapping excitation -> :func:`~hystkit.compensation.evaluate` dict
        Each compensator on its validation recording; the noise-trained one on every recording.
    compensators : mapping excitation -> Compensator
        The fitted compensators (their fit report and parameters are shown).
    config : dict
        ``config.json`` of the demo.
    figures : mapping file stem -> (PNG bytes, caption)
        The demo's figures as written beside the page.
    reference : mapping excitation -> (model R², line R²), optional
        The document's table 5.5, shown beside the deployable scores.
    """
    content = ReportContent(title="hystkit demo: table 5.5 on the virtual sensor")
    first = next(iter(metrics.values()))
    summary = Section("Validation: fit on seed 1, test on seed 2")
    model = f"mPL, {config['n_cells']} cell(s), {config['mode']} mode"
    summary.add(definition_list([
        ("sensor", config.get("sensor")), ("model", model),
        ("deployable centring", first["center"]),
        ("hystkit version", config["hystkit_version"]),
        ("run time [s]", f"{config['seconds']:.1f}")]))
    summary.add(*_score_tables(metrics, reference))
    content.sections.append(summary)
    shown = Section("Figures")
    for name, (png, caption) in figures.items():
        content.add_png(shown, name, png, caption)
    content.sections.append(shown)
    general = Section("Compensator trained on noise, tested on each excitation")
    general.add(paragraph("Does compensation generalise? One compensator, fitted on the noise "
                          "recording, scored on every validation recording."),
                *_score_tables(noise_trained, None))
    content.sections.append(general)
    fits = Section("The fits")
    content.sections.append(fits)
    for name, comp in compensators.items():
        source = comp.fit_info.get("training_source", "seed 1")
        content.sections.append(fit_section(comp, f"{name}: fitted on {source}", sub=True))
    return content
