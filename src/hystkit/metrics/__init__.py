"""Fit-quality, distortion and hysteresis metrics (thesis chapter 5)."""

from ._metrics import e_max_pct, e_rms_pct, loop_area, r2, sinad_db
from ._reversals import REVERSAL_DEADBAND, Reversals, confirmed_reversals

__all__ = ["REVERSAL_DEADBAND", "Reversals", "confirmed_reversals", "e_max_pct", "e_rms_pct",
           "loop_area", "r2", "sinad_db"]
