"""Simulated sensors that produce the same recordings as the lab."""

from ._virtual import VirtualSensor, simulate_experiment

__all__ = ["VirtualSensor", "simulate_experiment"]
