"""What a raw scope recording holds: its channels (:data:`RAW_COLUMNS`), how a file names them
(:class:`RawFormat`) and a run of consecutive samples (:class:`RawChunk`).

Read with :func:`hystkit.io.open_raw` (:mod:`._raw_reader`), written with
:class:`hystkit.io.RawWriter` (:mod:`._raw_writer`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RAW_COLUMNS", "RawChunk", "RawFormat"]

RAW_COLUMNS = ("time", "v1", "v2", "encoder", "enc_a", "enc_b", "v0")
# Columns read only when the caller asks for them.
OPTIONAL_COLUMNS = ("v0",)
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}  # seconds per unit
# No scope channel reads more; beyond it a histogram of the levels would overflow.
MAX_VOLTAGE = 1e6
# CSV lines skipped after the header (a units line or a few): pandas holds them as a set.
MAX_SKIP_ROWS = 1_000_000


@dataclass(frozen=True)
class RawFormat:
    """How to find the raw channels in a file.

    Parameters
    ----------
    columns : tuple of (str, str)
        (hystkit name, file column name) pairs for columns named differently in the file.
    time_unit : {"s", "ms", "us", "ns"}
        Unit of the time column.
    skip_rows : int
        CSV lines to skip after the header row.
    fs : float, optional
        Sample rate [Hz]: needed without a time column, checked against one.
    n_samples : int, optional
        Expected samples per channel; fewer means the file was truncated.
    """

    columns: tuple[tuple[str, str], ...] = ()
    time_unit: str = "s"
    skip_rows: int = 0
    fs: float | None = None
    n_samples: int | None = None

    def __post_init__(self) -> None:
        unknown = [k for k, _ in self.columns if k not in RAW_COLUMNS]
        if unknown:
            raise ValueError(f"unknown raw column(s) {unknown}; known: {', '.join(RAW_COLUMNS)}")
        if self.time_unit not in TIME_UNITS:
            raise ValueError(f"time_unit must be one of {', '.join(TIME_UNITS)}, "
                             f"got {self.time_unit!r}")
        if not 0 <= self.skip_rows <= MAX_SKIP_ROWS or (
                self.fs is not None and not 0 < self.fs < np.inf) or (
                self.n_samples is not None and self.n_samples < 1):
            raise ValueError(f"skip_rows must lie in [0, {MAX_SKIP_ROWS}], fs be finite and "
                             f"> 0 and n_samples >= 1")

    def name(self, column: str) -> str:
        """The file's name for hystkit column `column`."""
        return dict(self.columns).get(column, column)


@dataclass(frozen=True, eq=False)
class RawChunk:
    """Consecutive samples of a raw recording, from sample ``start`` (0-based) on.

    Arrays are float32 or float64 as stored (other numbers become float64), shape (n,). A
    column not read, or absent (``time`` without a time column, ``encoder`` when the file has
    ``enc_a``/``enc_b`` and vice versa, ``v0`` unless asked for), is None.

    Parameters
    ----------
    start : int
        Index of the chunk's first sample in the recording (0-based).
    time : numpy.ndarray, optional
        Time [s].
    v1, v2 : numpy.ndarray, optional
        Bridge voltages [V].
    encoder : numpy.ndarray, optional
        Merged encoder signal [V].
    enc_a, enc_b : numpy.ndarray, optional
        Encoder channels A and B [V].
    v0 : numpy.ndarray, optional
        Measured supply voltage [V].
    """

    start: int
    time: np.ndarray | None = None
    v1: np.ndarray | None = None
    v2: np.ndarray | None = None
    encoder: np.ndarray | None = None
    enc_a: np.ndarray | None = None
    enc_b: np.ndarray | None = None
    v0: np.ndarray | None = None

    @property
    def n(self) -> int:
        """Samples in the chunk."""
        return next(int(a.size) for a in (self.time, self.v1, self.v2, self.encoder,
                                          self.enc_a, self.enc_b, self.v0) if a is not None)

