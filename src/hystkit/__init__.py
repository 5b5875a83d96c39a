"""hystkit: hysteresis models, compensators and closed-loop simulation for lousy sensors."""

__version__ = "0.1.0"
