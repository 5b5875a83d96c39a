"""Hysteresis models: the family protocol, the registry, and one folder per model family.

``from hystkit.models import get_family`` gives a family by its CLI name; ``FAMILIES`` maps
every registered name to its family. See :mod:`hystkit.models._protocol` for what a family
provides and how to add one.
"""

from ._cells import DT_RANGE
from ._protocol import Block, Family, FitStart, Record, Reduction, numerical_linearisation
from ._registry import FAMILIES, family_of, get_family, register, unregister
from ._stability import stability_report

__all__ = ["DT_RANGE", "FAMILIES", "Block", "Family", "FitStart", "Record", "Reduction",
           "family_of", "get_family", "numerical_linearisation", "register", "stability_report",
           "unregister"]
