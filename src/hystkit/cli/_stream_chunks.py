"""``hystkit stream``'s chunks compensated: each chunk of input lines (:mod:`._stream_read`) in
one compiled call (:meth:`hystkit.live.Stream.step_many`) and its output lines formatted at once.

A chunk of plain ``time,sensor`` numbers (the common case: a file or a pipe in stream's own
form) is checked, split and parsed as one text (:func:`plain_chunk`); any other chunk line by
line (:func:`any_chunk`) with the same results, warnings and line numbers.
"""

from __future__ import annotations

import numpy as np

from ..live import Stream, StreamOutput
from ._stream_lines import STEP_TOLERANCE, Reading, Tally
from ._stream_read import TOO_LONG, lines_of

__all__ = ["any_chunk", "plain_chunk", "rows", "run_chunk"]

# What a line of two plain numbers holds (anything else: the line-by-line path)
_NOT_PLAIN = str.maketrans("", "", "0123456789.eE+-,\n")
# Samples checked and compensated per compiled call on the line-by-line path
_WINDOW = 512


def run_chunk(stream: Stream, chunk: str, reading: Reading, tally: Tally,
              banded: bool) -> list[str]:
    """The output lines of a chunk: its plain numbers at once (:func:`plain_chunk`), anything
    else line by line (:func:`any_chunk`); compensated in one compiled call either way."""
    if chunk is TOO_LONG:
        return any_chunk(stream, [chunk], reading, tally, banded)
    out: list[str] = []
    while reading.first and chunk:  # until the header (or the first data line)
        cut = chunk.find("\n") + 1 or len(chunk)
        out += any_chunk(stream, [chunk[:cut]], reading, tally, banded)
        chunk = chunk[cut:]
    if not chunk:
        return out
    plain = plain_chunk(stream, chunk, reading, tally, banded)
    return out + (any_chunk(stream, lines_of(chunk), reading, tally, banded)
                  if plain is None else plain)


def plain_chunk(stream: Stream, text: str, reading: Reading, tally: Tally,
                banded: bool) -> list[str] | None:
    """:func:`any_chunk` for a chunk of ``time,sensor`` lines of plain numbers (no space,
    no empty field, no third column, every line ended, times advancing): the same results,
    warnings and line numbers, without a Python step per line; None for any other chunk."""
    n_lines = text.count("\n")
    if (reading.columns[:2] != (0, 1) or not text.endswith("\n")
            or text.count(",") != n_lines or text.translate(_NOT_PLAIN)
            or text[0] in ",\n" or ",\n" in text or "\n," in text or "\n\n" in text):
        return None
    parts = text[:-1].replace("\n", ",").split(",")
    try:
        values = np.fromiter(map(float, parts), np.float64, len(parts))  # as _parse reads
    except ValueError:
        return None
    t = values[0::2] * reading.time_scale
    if not np.all(np.isfinite(values)) or not np.all(np.isfinite(t)):
        return None
    before = t[:-1] if reading.previous is None else np.concatenate([[reading.previous],
                                                                      t[:-1]])
    step = t[1:] if reading.previous is None else t
    if not np.all(step > before):
        return None  # a time not advancing: line by line decides what is skipped
    first = reading.line_no + 1
    dt = stream.compensator.structure.dt
    # line numbers of the irregular steps (the first line has no step without a previous)
    irregular = np.flatnonzero(np.abs(step - before - dt) > STEP_TOLERANCE * dt) + first \
        + (reading.previous is None)
    out = stream.step_many(values[1::2])
    taken = out.estimate.size
    checked = irregular[irregular <= first + taken]  # up to the refused sample, as line by line
    if checked.size:
        tally.add("irregular step", int(checked[0]), checked.size)
    reading.line_no += taken
    if taken:
        reading.previous = float(t[taken - 1])
    lines = rows(parts[0:2 * taken:2], out, banded)
    if taken < n_lines:  # a runaway: skipped; the lines after it as any others
        reading.line_no += 1
        tally.add("estimate ran away", reading.line_no)
        rest = lines_of(text)[taken + 1:]
        lines += any_chunk(stream, rest, reading, tally, banded)
    return lines


def any_chunk(stream: Stream, chunk: list[str], reading: Reading, tally: Tally,
              banded: bool) -> list[str]:
    """The output lines of any lines of input, parsed and checked line by line and
    compensated in one compiled call (as many as a runaway sample needs: the samples after
    it are checked again from the time before it, since it is skipped)."""
    samples = []  # (time text, time [s], sensor, line number)
    for line in chunk:
        if (parsed := reading.parsed(line, tally)) is not None:
            samples.append((*parsed, reading.line_no))
    dt = stream.compensator.structure.dt
    lines: list[str] = []
    i = 0
    while i < len(samples):
        # a window at a time (a split run equals the whole run): after a refused sample only
        # the rest of its window is checked again, not the rest of the chunk (quadratic)
        window = range(i, min(i + _WINDOW, len(samples)))
        kept, problems, previous = [], [], reading.previous
        for j in window:
            problem = reading.step_problem(samples[j][1], previous, dt)
            if problem is not None:
                problems.append((j, problem))
            if problem != "time not advancing":
                kept.append(j)
                previous = samples[j][1]
        out = stream.step_many([samples[j][2] for j in kept])
        taken = out.estimate.size
        stop = kept[taken] if taken < len(kept) else window[-1]  # the refused or last sample
        for j, problem in problems:
            if j <= stop:  # (after a refused sample they are checked again)
                tally.add(problem, samples[j][3])
        if taken < len(kept):
            tally.add("estimate ran away", samples[stop][3])
        if taken:
            reading.previous = samples[kept[taken - 1]][1]
            lines += rows([samples[j][0] for j in kept[:taken]], out, banded)
        i = stop + 1
    return lines


def rows(times: list[str], out: StreamOutput, banded: bool) -> list[str]:
    """Output lines: time as received, estimate in full (repr: bit for bit), flags, band."""
    flags = np.zeros(out.estimate.size, dtype=np.int64)
    if out.sensor_outside is not None:
        flags += out.sensor_outside
    if out.estimate_outside is not None:
        flags += 2 * out.estimate_outside
    columns = [times, out.estimate.tolist(), flags.tolist()]
    if banded:
        columns += [out.lower.tolist(), out.upper.tolist()]
        return [f"{t},{e!r},{f},{lo!r},{up!r}\n" for t, e, f, lo, up in zip(*columns, strict=True)]
    return [f"{t},{e!r},{f}\n" for t, e, f in zip(*columns, strict=True)]
