"""Fit-quality, distortion and hysteresis metrics (thesis chapter 5)."""

from ._metrics import e_max_pct, e_rms_pct, loop_area, r2, sinad_db

__all__ = ["e_max_pct", "e_rms_pct", "loop_area", "r2", "sinad_db"]
