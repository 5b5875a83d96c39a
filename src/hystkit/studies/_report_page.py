"""``hystkit report``: what the inputs are, the page built from them, and writing it atomically.

Inputs are either a model file followed by recordings, or result folders (``compare``,
``generalize``, ``select --report``, ``control``), recognised by their files. The page and
the figure files (``--figures``) are published together, all or none.
"""

from __future__ import annotations

import datetime
import os
from collections.abc import Callable, Sequence
from pathlib import Path

from .. import __version__
from ..compensation import MODEL_SUFFIXES
from ..errors import InputError
from ..io import ReadOptions, Recording, atomic_outputs, options_for, read_recording
from ._figures import DEFAULT_SENSOR_LABEL
from ._html import render_page
from ._report_control import control_report
from ._report_folders import folder_kind, folder_report
from ._report_model import ReportContent, fill_report_doc, model_report

__all__ = ["FIGURE_FORMATS", "build_report", "figure_paths", "sensor_label", "write_report"]

FIGURE_FORMATS = ("png", "svg", "pdf")


def sensor_label(options: ReadOptions | None, recordings: Sequence[Recording] = ()) -> str:
    """The sensor axis' label: the user's own column name when they mapped one (else the
    neutral "sensor": hystkit does not know what a recording's sensor measures), with the unit
    the files give when they all give the same one."""
    name = dict((options or ReadOptions()).columns).get("sensor", DEFAULT_SENSOR_LABEL)
    units = {dict(getattr(rec, "units", ())).get("sensor", "") for rec in recordings}
    unit = units.pop() if len(units) == 1 else ""
    return f"{name} [{unit}]" if unit else name


@fill_report_doc
def build_report(inputs: Sequence[str | os.PathLike[str]], *,
                 options: ReadOptions | Callable[[Path], ReadOptions] | None = None,
                 ) -> ReportContent:
    """The page's content for `inputs`: ``MODEL.json RECORDING...`` or ``FOLDER...``.

    Parameters
    ----------
    inputs : sequence of str or os.PathLike
        A model file and recordings, or result folders.
    options : ReadOptions or callable, optional
        How to read the recordings (see :func:`~hystkit.io.read_recording`): one
        `ReadOptions` for all, or a function of a recording's path giving its own. Default:
        each recording's settings file beside it when it has one (``my.toml`` for ``my.csv``,
        :func:`~hystkit.io.options_for`), as the command line reads it.

    %(report_content)s

    Raises
    ------
    InputError
        Inputs of neither form (naming what was given), an unreadable model file, recording
        or result folder, two recordings with the same file name.
    """
    paths = [Path(p) for p in inputs]
    if not paths:
        raise InputError("report: give a model file and recordings, or result folders")
    if all(p.is_dir() for p in paths):
        return _folders(paths)
    first = paths[0]
    folders = [p for p in paths if p.is_dir()]
    if folders:
        raise InputError(f"{folders[0]}: a folder among files; report either a model file "
                         f"with recordings or result folders, not both")
    if first.suffix.lower() not in MODEL_SUFFIXES:
        raise InputError(f"{first}: expected a model file ({', '.join(MODEL_SUFFIXES)} from "
                         f"'hystkit fit') or a result folder first")
    if len(paths) < 2:
        raise InputError(f"{first}: give one or more recordings to report the model on")
    recordings, reading = {}, []
    for path in paths[1:]:
        if path.name in recordings:
            raise InputError(f"{path}: two recordings named {path.name!r}; the page and its "
                             f"figures name them by file name")
        if options is None:
            reading.append(options_for(path)[0])  # its settings file, if it has one
        else:
            reading.append(options(path) if callable(options) else options)
        recordings[path.name] = read_recording(path, options=reading[-1])
    return model_report(first, recordings,
                        sensor_label=sensor_label(reading[0], list(recordings.values())))


def _folders(folders: list[Path]) -> ReportContent:
    kinds = [folder_kind(f) for f in folders]  # every folder recognised before any work
    content = ReportContent(title=f"hystkit report: {', '.join(f.name or str(f) for f in folders)}")
    for folder, kind in zip(folders, kinds):
        content.prefix = f"{folder.resolve().name}_" if len(folders) > 1 else ""
        if kind == "control":
            control_report(folder, content)
        else:
            folder_report(folder, kind, content)
    return content


def figure_paths(content: ReportContent, folder: Path | None, fmt: str) -> list[Path]:
    """The figure files of `content` in `folder`: every figure as PNG, and as `fmt` (svg,
    pdf) where it was drawn here (a control run's own PNGs have no vector form)."""
    if folder is None:
        return []
    paths = [folder / f"{name}.png" for name in content.pngs]
    if fmt != "png":
        paths += [folder / f"{name}.{fmt}" for name in content.figures]
    return paths


def write_report(content: ReportContent, out: str | os.PathLike[str], *,
                 figures: str | os.PathLike[str] | None = None, fmt: str = "png",
                 force: bool = False) -> list[Path]:
    """Write the page (and with `figures` the figure files), all published together.

    Without `force` an existing file is refused (nothing is written); an interruption leaves
    none of them. Returns the written paths, the page first.

    Parameters
    ----------
    content : ReportContent
        What the page shows (:func:`build_report`).
    out : str or os.PathLike
        The HTML page.
    figures : str or os.PathLike, optional
        Folder for the figure files; none are written if None.
    fmt : {"png", "svg", "pdf"}, default "png"
        Format of the figures drawn here, besides PNG.
    force : bool, default False
        Replace existing files.

    Returns
    -------
    list of pathlib.Path
        The written paths, the page first.

    Raises
    ------
    InputError
        An unknown figure format.
    OutputExistsError
        A file exists and `force` is False.
    """
    if fmt not in FIGURE_FORMATS:
        raise InputError(f"figure format {fmt!r}: use {', '.join(FIGURE_FORMATS)}")
    folder = None if figures is None else Path(figures)
    extra = figure_paths(content, folder, fmt)
    stamp = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    page = render_page(content.title, content.sections,
                       footer=f"written by hystkit {__version__} on {stamp}; self-contained: "
                              f"figures embedded, nothing loaded from outside")
    paths = [Path(out), *extra]
    with atomic_outputs(paths, force) as temps:
        temps[0].write_text(page, encoding="utf-8")
        for path, tmp in zip(extra, temps[1:]):
            name = path.stem
            if path.suffix == ".png":
                tmp.write_bytes(content.pngs[name])
            else:
                content.figures[name].savefig(tmp, format=fmt)
    return paths
