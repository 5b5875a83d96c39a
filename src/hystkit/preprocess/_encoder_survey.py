"""Encoder levels surveyed before the stream starts (sec. 4.3.2).

Unless the levels are given, the merged encoder column (four levels) or each logic channel
(two) is surveyed from the start, in blocks that do not depend on the chunk size, until every
level has been seen; a flat channel, too few or too many levels are refused with the reason.
Used by :func:`~hystkit.preprocess.preprocess_raw`.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from ..io import RawChunk, RawReader
from ._encoder import EncoderSettings
from ._levels import LevelSurvey

if TYPE_CHECKING:
    from ._raw_records import PreprocessSettings

__all__ = ["SURVEY_BLOCK", "encoder_setup"]

# Encoder levels are surveyed in blocks of this many samples, whatever the chunk size.
SURVEY_BLOCK = 1 << 16


def encoder_setup(reader: RawReader, settings: PreprocessSettings, dwell: int
                  ) -> tuple[EncoderSettings, np.ndarray, tuple[float, float] | None]:
    """Decoder settings, starting levels and, for logic channels, their thresholds [V]."""
    if reader.encoder_kind == "ab":
        thresholds = tuple(_logic_threshold(reader, c) for c in ("enc_a", "enc_b"))
        # Codes 2A + B are decoded as four fixed levels 0..3 in code order.
        return (EncoderSettings(states=(0, 1, 2, 3), dwell=dwell, illegal=settings.illegal,
                                track_block=0),
                np.arange(4.0), thresholds)  # type: ignore[return-value]
    enc = EncoderSettings(states=settings.encoder_states, dwell=dwell, illegal=settings.illegal)
    if settings.encoder_levels is not None:
        return enc, np.asarray(settings.encoder_levels, dtype=float), None
    survey = _survey(reader, "encoder", 4)
    _check_levels(reader, "encoder", survey, 4)
    return enc, survey.centres, None


def _logic_threshold(reader: RawReader, column: str) -> float:
    survey = _survey(reader, column, 2)
    _check_levels(reader, column, survey, 2)
    return float(survey.centres.mean())


def _survey(reader: RawReader, column: str, wanted: int) -> LevelSurvey:
    """Levels of `column`, surveyed in blocks of ``SURVEY_BLOCK`` samples from the start until
    `wanted` levels each hold 100 samples. The blocks do not depend on the reader's chunk size,
    so neither do the levels found (nor anything decoded with them)."""
    survey = LevelSurvey()
    for block in _blocks(reader.chunks(columns=(column,)), column, SURVEY_BLOCK):
        survey = survey.add(block)
        if survey.n_levels >= wanted and min(c[3] for c in survey.clusters) >= 100:
            break
    return survey


def _blocks(chunks: Iterator[RawChunk], column: str, size: int) -> Iterator[np.ndarray]:
    """`column` of consecutive chunks, re-cut into blocks of `size` samples (the last shorter)."""
    pending: list[np.ndarray] = []
    n = 0
    for chunk in chunks:
        pending.append(getattr(chunk, column))
        n += pending[-1].size
        while n >= size:
            joined = np.concatenate(pending)
            yield joined[:size]
            pending, n = [joined[size:]], n - size
    if n:
        yield np.concatenate(pending)


def _check_levels(reader: RawReader, column: str, survey: LevelSurvey, wanted: int) -> None:
    found = ", ".join(f"{c:.4g}" for c in survey.centres)
    if survey.n_levels == 0:  # no level held 2 samples: far too short to survey
        raise reader.fail(f"only {survey.n_samples} samples: too few to find the "
                          f"{wanted} levels of the channel (give --encoder-levels, or record "
                          "longer)", column)
    if survey.n_levels <= 1:
        lo, hi = survey.clusters[0][1], survey.clusters[0][2]
        raise reader.fail(f"flat: one level ({found} V, range {lo:.4g} to {hi:.4g} V) in "
                          f"{survey.n_samples} samples, so no encoder edges and no position; "
                          "is the encoder connected and did the actuator move?", column)
    if survey.n_levels < wanted:
        raise reader.fail(f"only {survey.n_levels} of {wanted} levels found ({found} V) in the "
                          "whole recording; the actuator never visited all A/B states or this "
                          "is not the encoder" + (", give --encoder-levels"
                                                  if wanted == 4 else ""), column)
    if survey.n_levels > wanted:
        raise reader.fail(f"{survey.n_levels} distinct levels ({found} V) where {wanted} were "
                          "expected; is this the " + ("merged encoder signal"
                                                      if wanted == 4 else "logic channel")
                          + "? (give --encoder-levels to skip the search)", column)
