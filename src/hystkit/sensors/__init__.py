"""Simulated sensors that produce the same recordings as the lab."""

from ._raw import RawTruth, ScopeSettings, merged_levels, simulate_raw, with_asymmetry
from ._virtual import VirtualSensor, simulate_experiment

__all__ = ["RawTruth", "ScopeSettings", "VirtualSensor", "merged_levels", "simulate_experiment",
           "simulate_raw", "with_asymmetry"]
