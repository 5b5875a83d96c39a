"""Plain-text tables whose columns never run together, whatever the numbers' size."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["format_number", "text_table"]

# Beyond these magnitudes a fixed-point number is unreadable: scientific notation instead.
_FIXED_RANGE = (1e-3, 1e6)


def format_number(value: object, digits: int = 4) -> str:
    """A cell for people: ``n/a`` for None, integers as they are, floats to `digits` decimals
    within a readable range and in scientific notation outside it.

    Parameters
    ----------
    value : object
        A number, None or text.
    digits : int, default 4
        Decimals of a fixed-point float (significant digits - 1 in scientific notation).

    Returns
    -------
    str
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool | int) or not isinstance(value, float):
        return str(value)
    size = abs(value)
    if size != 0 and not _FIXED_RANGE[0] <= size < _FIXED_RANGE[1]:
        return f"{value:.{digits - 1}e}"
    return f"{value:.{digits}f}"


def text_table(header: Sequence[str], rows: Sequence[Sequence[object]], *,
               digits: Sequence[int] | int = 4) -> str:
    """Columns as wide as their widest cell plus two spaces; the first left-aligned, numbers
    right-aligned.

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : sequence of sequences
        Cells (numbers, None or text), one sequence per row, as long as `header`.
    digits : int or sequence of int, default 4
        Decimals per column (:func:`format_number`).

    Returns
    -------
    str
        The table, lines joined by newlines, without a trailing newline.
    """
    per_column = [digits] * len(header) if isinstance(digits, int) else list(digits)
    cells = [[format_number(v, d) for v, d in zip(row, per_column, strict=True)]
             for row in rows]
    widths = [max([len(h), *(len(r[j]) for r in cells)]) for j, h in enumerate(header)]
    lines = []
    for row in [list(header), *cells]:
        first, *rest = row
        lines.append(f"{first:<{widths[0]}}" + "".join(
            f"  {cell:>{w}}" for cell, w in zip(rest, widths[1:], strict=True)))
    return "\n".join(lines)
