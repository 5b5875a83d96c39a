"""Reports of result folders: ``compare``, ``generalize`` and ``select --report`` output.

Each folder is recognised by the JSON file its command writes; the page shows that file's
tables (deployable scores before oracle ones) and draws its figures again from the numbers, on
an honest scale: the unexplained fraction 1 - R² on a log axis, every value written beside its
mark, so 0.998 and 0.989 differ visibly and -2390 stays on the chart.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..errors import InputError
from ._generalization_plot import plot_generalization
from ._html import Section, note, paragraph, table
from ._report_model import ReportContent

__all__ = ["FOLDER_FILES", "folder_kind", "folder_report", "plot_unexplained"]

# The file that identifies each kind of folder (what the command writes first).
FOLDER_FILES = {"compare": "compare.json", "generalize": "generalize.json",
                "select": "selection.json"}
# 1 - R² below this (R² above 0.9999) is drawn at the floor
_FLOOR = 1e-4


def folder_kind(folder: Path) -> str:
    """``compare``, ``generalize``, ``select`` or ``control``, from the files in `folder`."""
    for kind, name in FOLDER_FILES.items():
        if (folder / name).is_file():
            return kind
    if (folder / "config.json").is_file() and any(
            (folder / name).is_file() for name in ("metrics.json", "analysis.json")):
        config = read_json(folder / "config.json")
        if isinstance(config, dict) and "scheme" in config:
            return "control"
    raise InputError(f"{folder}: not a result folder hystkit can report on (expected "
                     f"{', '.join(FOLDER_FILES.values())}, or config.json with metrics.json "
                     f"or analysis.json of 'hystkit control')")


def read_json(path: Path) -> object:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read ({exc})") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not JSON (line {exc.lineno}: {exc.msg})") from None


def plot_unexplained(rows: Sequence[tuple[str, Mapping[str, float | None]]],
                     xlabel: str) -> Figure:
    """Markers of 1 - R² on a log axis, one row per label and one marker style per series
    (e.g. ``{"compensator": 0.998, "straight line": 0.94}``); each R² written beside its
    marker; a missing value (None) is left out. 1 - R² below 1e-4 is drawn at 1e-4."""
    series = list(dict.fromkeys(key for _, values in rows for key in values))
    markers = ("o", "s", "^", "D", "v", "x")
    fig = Figure(figsize=(8.0, 0.45 * len(rows) + 1.6), layout="constrained")
    ax = fig.subplots()
    y = np.arange(len(rows))[::-1]
    for k, key in enumerate(series):
        shift = 0.18 * (k - (len(series) - 1) / 2)  # the series side by side in each row
        found = [(yy + shift, values[key]) for yy, (_, values) in zip(y, rows)
                 if values.get(key) is not None]
        if not found:
            continue
        ys, r2s = np.array(found).T
        xs = np.maximum(1.0 - r2s, _FLOOR)
        ax.plot(xs, ys, markers[k % len(markers)], color=f"C{k}", ls="none", label=key)
        for x, yy, value in zip(xs, ys, r2s):
            ax.annotate(f"{value:.4g}", (x, yy), xytext=(5, 0), textcoords="offset points",
                        va="center", fontsize="x-small", color=f"C{k}")
    ax.set_xscale("log")
    ax.set(yticks=y, yticklabels=[label for label, _ in rows], xlabel=xlabel,
           ylim=(-0.7, len(rows) - 0.3))
    ax.axvline(1.0, color="k", lw=0.8, ls="--")
    ax.grid(axis="x", which="both", alpha=0.3)
    fig.legend(loc="outside lower center", ncols=max(1, len(series)), fontsize="small",
               frameon=False)
    return fig


def _compare(folder: Path, content: ReportContent) -> None:
    path = folder / "compare.json"
    data = read_json(path)
    ok = {name: m for name, m in data.items() if "error" not in m}
    section = Section(f"compare: {folder}")
    section.add(paragraph(
        "Every family fitted on one recording and scored on another. R² fwd: the forward model "
        "position → sensor; R² inv: its inverse used as compensator; R² dir: a compensator "
        "fitted sensor → position; line: the straight line. Deployable: the fitting "
        "recording's offsets."))
    section.add(table(("model", "params", "fit s", "R² fwd", "R² inv", "R² dir", "line",
                       "e_rms %", "e_max %", "direct fit"),
                      [(name, m["n_params"], _f(m["fit_seconds"], ".2f"), m["r2_forward"],
                        m["r2_compensated"], m["r2_direct"], m["linear_r2"],
                        _f(m["e_rms_pct"], ".2f"), _f(m["e_max_pct"], ".2f"),
                        m["direct_status"]) for name, m in ok.items()]))
    section.add(paragraph("Oracle (the paper's protocol: the validation recording's own means, "
                          "which no compensator in use has):"))
    section.add(table(("model", "R² inv", "R² dir", "line"),
                      [(name, m["r2_compensated_oracle"], m["r2_direct_oracle"],
                        m["linear_r2_oracle"]) for name, m in ok.items()],
                      row_classes=["oracle"] * len(ok)))
    section.add(table(("model", "rate-dependent", "return-point memory", "minor loops close"),
                      [(name, m["rate_dependent"], m["return_point_memory"],
                        m["minor_loops_close"]) for name, m in ok.items()]))
    for name, m in data.items():
        if "error" in m:
            section.add(note(f"{name}: FAILED: {m['error']}", "bad"))
        elif m.get("compensated_note"):
            section.add(note(f"{name}: no R² inv: {m['compensated_note']}"))
    content.sections.append(section)
    if ok:
        content.add_figure(section, "compare", plot_unexplained(
            [(name, {"direct compensator": m["r2_direct"], "inverse": m["r2_compensated"],
                     "straight line": m["linear_r2"]}) for name, m in ok.items()],
            "1 − R² on validation (deployable; log scale, left is better; dashed: R² = 0)"),
            "Deployable validation R² of each family, as 1 − R² on a log scale, values "
            "written beside the marks.")


def _generalize(folder: Path, content: ReportContent) -> None:
    data = read_json(folder / "generalize.json")
    section = Section(f"generalize: {folder}")
    section.add(paragraph("A direct compensator trained on each recording (rows) and tested "
                          "on each (columns)."))
    for name, entry in data.items():
        for key, label, css in (("r2", "deployable R²", ""), ("r2_oracle", "oracle R²", "oracle")):
            grid = entry[key]
            tests = list(next(iter(grid.values()))) if grid else []
            section.add(paragraph(f"{name}: {label} (rows: trained on, columns: tested on)"))
            section.add(table(("trained on", *tests),
                              [(train, *(row[t] for t in tests)) for train, row in grid.items()],
                              row_classes=[css] * len(grid)))
        for where, reason in entry.get("errors", {}).items():
            section.add(note(f"{name} {where}: FAILED: {reason}", "bad"))
        for where, reason in entry.get("notes", {}).items():
            section.add(note(f"{name} {where}: {reason}"))
    content.sections.append(section)
    content.add_figure(section, "generalize", plot_generalization(data),
                       "Deployable R² matrix per model; colour: 1 − R² on one log scale for "
                       "all panels, each cell's R² written in it; blank: failed.")


def _select(folder: Path, content: ReportContent) -> None:
    data = read_json(folder / "selection.json")
    rows = data["ranking"]
    section = Section(f"select: {folder}")
    winner = data.get("winner")
    if winner is None:
        section.add(note("No candidate passed its guards; no model was written.", "bad"))
    else:
        oracle = winner.get("cv_r2_oracle")
        section.add(note(f"winner: {winner['candidate']} (held-out deployable R² "
                         f"{winner['cv_r2']:.4f}, straight line {winner['cv_linear_r2']:.4f}"
                         f"{'' if oracle is None else f', oracle {oracle:.4f}'}); model file "
                         f"{data.get('model_file', 'not stored')}", "good"))
    if data.get("refusal"):
        section.add(note(data["refusal"], "bad"))
    section.add(paragraph(f"Validation: {data.get('protocol', 'held-out folds')}; "
                          f"{len(data['folds'])} fold(s): "
                          + "; ".join(f"train {', '.join(f['train'])} → test {f['test']}"
                                      for f in data["folds"])))
    for caveat in data.get("caveats") or ():
        section.add(note(caveat))
    ok = [r for r in rows if "error" not in r]
    section.add(table(("candidate", "held-out R²", "min", "line", "oracle", "params", "AIC",
                       "BIC", "verdict"),
                      [(r["candidate"], r["cv_r2"], r["cv_r2_min"], r["cv_linear_r2"],
                        r["cv_r2_oracle"], r["n_params"], _f(r["aic"], ".0f"),
                        _f(r["bic"], ".0f"),
                        r["guard_failed"] or r.get("verdict", "ok")) for r in ok]))
    for r in rows:
        if "error" in r:
            section.add(note(f"{r['candidate']}: FAILED: {r['error']}", "bad"))
    content.sections.append(section)
    if ok:
        content.add_figure(section, "selection", plot_unexplained(
            [(r["candidate"], {"deployable (mean over folds)": r["cv_r2"],
                               "oracle": r["cv_r2_oracle"], "straight line": r["cv_linear_r2"]})
             for r in ok], "held-out 1 − R² (log scale, left is better; dashed: R² = 0)"),
            "Held-out R² of every candidate as 1 − R² on a log scale, values beside the marks.")


def _f(value: float | None, spec: str) -> str | None:
    return None if value is None else format(value, spec)


_BUILDERS: dict[str, Callable[[Path, ReportContent], None]] = {
    "compare": _compare, "generalize": _generalize, "select": _select}


def folder_report(folder: Path, kind: str, content: ReportContent) -> None:
    """Add `folder`'s section and figures to `content`; a file that is not what its command
    writes (a key missing, a wrong type) is an InputError naming it."""
    try:
        _BUILDERS[kind](folder, content)
    except (KeyError, TypeError, AttributeError, IndexError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{folder}: its {kind} result cannot be read ({type(exc).__name__}: "
                         f"{exc})") from None
