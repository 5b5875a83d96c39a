"""What a stream remembers between samples (:class:`StreamState`), apart from the stream's code
so that the compiled path (:mod:`._stream_kernel`) and the readable one (:mod:`._stream`) both
build it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..compensation import BandState

__all__ = ["StreamState"]


@dataclass(frozen=True, eq=False)
class StreamState:
    """Everything a stream remembers between samples.

    Parameters
    ----------
    x : array or None
        The model's state vector (for an inverse compensator its forward model's, which every
        family's ``invert`` carries); None before the first sample of a stream that starts at
        rest (the rest state depends on that sample).
    n_samples : int, default 0
        Samples processed so far (the next sample's index).
    tare_sum : float, default 0.0
        Sum of the sensor samples [sensor units] inside the tare window so far (``tare``).
    track_value : float, default 0.0
        Last output of the tracker's un-normalised low-pass [sensor units] (``track``).
    track_weight : float, default 0.0
        Last output of the same low-pass run on ones: its weight sum (``track``).
    band : BandState, default BandState()
        What the prediction band's local scale remembers
        (:class:`hystkit.compensation.BandState`).
    """

    x: np.ndarray | None
    n_samples: int = 0
    tare_sum: float = 0.0
    track_value: float = 0.0
    track_weight: float = 0.0
    band: BandState = field(default_factory=BandState)

    def __post_init__(self) -> None:
        if self.x is not None:
            x = np.array(self.x, dtype=np.float64)
            x.flags.writeable = False
            object.__setattr__(self, "x", x)
