"""Simulated sensors that produce the same recordings as the lab, and the virtual sensor's causal
physics as a loop model (the "real" sensor of the closed loop).

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`): simulating an
experiment needs neither the raw scope writer nor its reader (pandas, ~1 s to import).
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_drift": ("gain_ramp", "occasional_references", "simulate_drifting_experiment",
                "with_gain_drift"),
     "_loop_model": ("VIRTUAL_PHYSICS", "VirtualPhysics", "VirtualPhysicsParams",
                     "VirtualPhysicsStructure", "physics_of"),
     "_raw": ("RawTruth", "simulate_raw", "with_asymmetry"),
     "_scope": ("ScopeSettings", "merged_levels"),
     "_settling": ("ANNEALED_BLOCK", "PRINTED_BLOCK", "SettlingLaw", "simulate_settling_log"),
     "_virtual": ("VirtualSensor", "simulate_experiment"),
     },
    first=())
