"""Simulated sensors that produce the same recordings as the lab, and the virtual sensor's causal
physics as a loop model (the "real" sensor of the closed loop)."""

from ._drift import (
    gain_ramp,
    occasional_references,
    simulate_drifting_experiment,
    with_gain_drift,
)
from ._loop_model import (
    VIRTUAL_PHYSICS,
    VirtualPhysics,
    VirtualPhysicsParams,
    VirtualPhysicsStructure,
    physics_of,
)
from ._raw import RawTruth, ScopeSettings, merged_levels, simulate_raw, with_asymmetry
from ._settling import ANNEALED_BLOCK, PRINTED_BLOCK, SettlingLaw, simulate_settling_log
from ._virtual import VirtualSensor, simulate_experiment

__all__ = ["ANNEALED_BLOCK", "PRINTED_BLOCK", "VIRTUAL_PHYSICS", "RawTruth", "ScopeSettings",
           "SettlingLaw", "VirtualPhysics",
           "VirtualPhysicsParams", "VirtualPhysicsStructure", "VirtualSensor", "gain_ramp",
           "merged_levels", "occasional_references", "physics_of",
           "simulate_drifting_experiment", "simulate_experiment", "simulate_raw",
           "simulate_settling_log", "with_asymmetry", "with_gain_drift"]
