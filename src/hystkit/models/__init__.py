"""Hysteresis models. Each module holds one model family with pure, explicit-state functions."""

from . import bobbio, boucwen, chua, gpreisach, ladder, mpl, mpl_poly, pi, pl, preisach
from .mpl import MplParams, MplStructure

__all__ = ["MplParams", "MplStructure", "bobbio", "boucwen", "chua", "gpreisach", "ladder", "mpl",
           "mpl_poly", "pi", "pl", "preisach"]
