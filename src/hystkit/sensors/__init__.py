"""Simulated sensors that produce the same recordings as the lab, and the virtual sensor's causal
physics as a loop model (the "real" sensor of the closed loop)."""

from ._loop_model import (
    VIRTUAL_PHYSICS,
    VirtualPhysics,
    VirtualPhysicsParams,
    VirtualPhysicsStructure,
    physics_of,
)
from ._raw import RawTruth, ScopeSettings, merged_levels, simulate_raw, with_asymmetry
from ._virtual import VirtualSensor, simulate_experiment

__all__ = ["VIRTUAL_PHYSICS", "RawTruth", "ScopeSettings", "VirtualPhysics",
           "VirtualPhysicsParams", "VirtualPhysicsStructure", "VirtualSensor", "merged_levels",
           "physics_of", "simulate_experiment", "simulate_raw", "with_asymmetry"]
