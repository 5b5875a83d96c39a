"""A recording with time gaps, read as pieces (``--gaps split``, ``gaps = "split"``).

A logger that stops for a few seconds (a buffer flush, a paused test) leaves a time step far
above the others. hystkit's models step at a fixed Δt, so such a file is refused by default,
naming the gap's row; ``--resample`` does not bridge it either (it would invent samples).
`read_pieces` cuts the recording at every gap (`hystkit.io._resample.time_gaps`: a step longer
than `MAX_GAP_STEPS` median steps) into pieces, each a `Recording` checked as any other
(uniform, resampled if asked), which ``fit`` fits jointly as it fits several files: each
piece starts from its own rest state, so no model runs across a gap.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from hystkit._read_options import ReadOptions

from ._recording import _adopt, _validate, read_unvalidated, say
from ._resample import resample_arrays, time_gaps

__all__ = ["read_pieces"]

_LISTED = 3  # gaps described in the notice


def read_pieces(path: str | os.PathLike[str], *, need_position: bool = True,
                options: ReadOptions | None = None) -> list:
    """Read a recording and cut it at its time gaps into pieces, each a `Recording`.

    One line on stderr says how many pieces and where (``hystkit: my.csv: 2 time gaps, read
    as 3 pieces: rows 1-500, 502-1300, ...``); a file without gaps is one piece, unsaid.

    Parameters
    ----------
    path : str or path-like
        A recording file, as for `read_recording`.
    need_position : bool
        Require a ``position`` column.
    options : ReadOptions, optional
        How to read it (``gaps`` aside: this function splits).

    Returns
    -------
    list of Recording
        In time order; source ``"my.csv (piece 2 of 3)"``.

    Raises
    ------
    InputError
        Whatever `read_recording` refuses in a piece (non-uniform sampling that is no gap,
        ...), or a piece of a single sample between two gaps; the message names the file's
        row.

    Examples
    --------
    >>> from pathlib import Path
    >>> rows = [f"{0.025 * i!r},{i % 7},{i % 5}" for i in [*range(100), *range(150, 250)]]
    >>> _ = Path("gap.csv").write_text("time,position,sensor\\n" + "\\n".join(rows) + "\\n")
    >>> [piece.n_samples for piece in read_pieces("gap.csv")]
    [100, 100]
    """

    options = ReadOptions() if options is None else options
    arrays, where, units = read_unvalidated(Path(path), need_position, options)
    _validate(arrays, where, uniform=False)
    gaps = time_gaps(arrays["time"])
    n = arrays["time"].size
    bounds = list(zip([0, *(gaps + 1).tolist()], [*(gaps + 1).tolist(), n]))
    rows = np.arange(n) if where.rows is None else where.rows
    kept_units = tuple((k, v) for k, v in units.items() if k in ("position", "sensor"))
    pieces = []
    for k, (start, stop) in enumerate(bounds, start=1):
        piece_where = replace(where, rows=rows[start:stop])
        if stop - start < 2:
            raise piece_where.fail("a single sample between two time gaps: no recording "
                                   "(drop the row, or --missing drop with its cells emptied)",
                                   "time", 0)
        piece = {name: values[start:stop] for name, values in arrays.items()}
        if options.resample_hz is not None:
            piece = resample_arrays(piece, options.resample_hz, piece_where)
        _validate(piece, piece_where)
        source = str(path) if len(bounds) == 1 else f"{path} (piece {k} of {len(bounds)})"
        pieces.append(_adopt(piece, source, kept_units))
    if gaps.size:
        say(_notice(str(path), arrays["time"], gaps, bounds, where.item,
                    lambda i: int(rows[i]) + 1))
    return pieces


def _notice(source: str, time: np.ndarray, gaps: np.ndarray, bounds: list[tuple[int, int]],
            item: str, file_row) -> str:
    """``my.csv: 2 time gaps, read as 3 pieces: rows 1-500, 501-1300, 1301-8000 (gaps of
    3 s after 12.5 s, ...)``."""
    spans = ", ".join(f"{file_row(a)}-{file_row(b - 1)}" for a, b in bounds[:_LISTED + 1])
    spans += f" and {len(bounds) - _LISTED - 1} more" if len(bounds) > _LISTED + 1 else ""
    step = np.diff(time)
    shown = ", ".join(f"{step[i]:.6g} s after {time[i]:.12g} s" for i in gaps[:_LISTED])
    shown += ", ..." if gaps.size > _LISTED else ""
    return (f"{source}: {gaps.size} time gap{'s' * (gaps.size > 1)}, read as {len(bounds)} "
            f"pieces fitted jointly: {item}s {spans} (gap{'s' * (gaps.size > 1)} of {shown})")
