"""Rows of an experiment table: a markdown print, and JSON + CSV written atomically."""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Sequence
from pathlib import Path

from ..io import atomic_folder, write_json

__all__ = ["format_markdown", "output_names", "write_table"]


def _cell(value: object, digits: int) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        if not math.isfinite(value):
            return "–"
        return f"{value:.{digits}g}"
    return str(value)


def format_markdown(rows: Sequence[dict], columns: Sequence[tuple[str, str]],
                    digits: int = 4) -> str:
    """A markdown table of `rows`; `columns` are (key, header) pairs; None prints as "–".

    Parameters
    ----------
    rows : sequence of dict
        One dict per table row; a missing key, None or a non-finite float prints as "–".
    columns : sequence of (str, str)
        (key in the rows, column header) pairs, in order.
    digits : int
        Significant digits of floats.

    Returns
    -------
    str
        The table, one line per row after the header and separator lines.
    """
    lines = ["| " + " | ".join(header for _, header in columns) + " |",
             "|" + "|".join(" --- " for _ in columns) + "|"]
    for row in rows:
        lines.append("| " + " | ".join(_cell(row.get(key), digits) for key, _ in columns)
                     + " |")
    return "\n".join(lines)


def output_names(stem: str) -> list[str]:
    """The files an experiment writes into its output folder.

    Parameters
    ----------
    stem : str
        File name without extension.

    Returns
    -------
    list of str
        ``STEM.json`` and ``STEM.csv``.
    """
    return [f"{stem}.json", f"{stem}.csv"]


def write_table(out: str | os.PathLike[str], stem: str, result: dict, rows: Sequence[dict],
                force: bool = False) -> list[Path]:
    """Write ``STEM.json`` (all of `result`) and ``STEM.csv`` (`rows`) into folder `out`.

    Both appear together or not at all (:func:`hystkit.io.atomic_folder`); existing files are
    kept unless `force`.

    Parameters
    ----------
    out : str or path-like
        Output folder.
    stem : str
        File name without extension.
    result : dict
        Everything the experiment returns, written as JSON.
    rows : sequence of dict
        The table rows, written as CSV (columns: every key in order of first appearance; None
        as an empty cell).
    force : bool
        Replace existing files of the same names.

    Returns
    -------
    list of Path
        The JSON and CSV file written.

    Raises
    ------
    OutputExistsError
        If a file exists and `force` is not given.
    OutputError
        If `out` is a file or cannot be written.
    """
    names = output_names(stem)
    keys = list(dict.fromkeys(key for row in rows for key in row))
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: ("" if row.get(k) is None else row.get(k)) for k in keys}
                     for row in rows)
    with atomic_folder(out, force, names) as tmp:
        write_json(result, tmp / names[0])
        (tmp / names[1]).write_text(text.getvalue(), encoding="utf-8")
    return [Path(out) / name for name in names]
