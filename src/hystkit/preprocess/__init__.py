"""From raw lab signals to fit-ready recordings: filters and resampling."""

from ._filters import downsample, lowpass_zero_phase

__all__ = ["downsample", "lowpass_zero_phase"]
