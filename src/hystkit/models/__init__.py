"""Hysteresis models. Each module holds one model family with pure, explicit-state functions."""

from . import mpl
from .mpl import MplParams, MplStructure

__all__ = ["MplParams", "MplStructure", "mpl"]
