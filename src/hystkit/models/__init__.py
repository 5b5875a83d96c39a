"""Hysteresis models: the family protocol, the registry, and one folder per model family.

``from hystkit.models import get_family`` gives a family by its CLI name; ``FAMILIES`` maps
every registered name to its family (its code loaded on first use) and ``FAMILY_INFO`` to its
light :class:`FamilyInfo` (what ``hystkit fit --help`` shows, no model loaded). See
:mod:`hystkit.models._protocol` for what a family provides and how to add one.
"""

from ._capabilities import ALL_LOSSES
from ._cells import DT_RANGE
from ._protocol import (
                        Block,
                        Capabilities,
                        Family,
                        FamilyInfo,
                        FitStart,
                        Record,
                        Reduction,
                        Translation,
                        numerical_linearisation,
)
from ._registry import (
                        FAMILIES,
                        FAMILY_INFO,
                        family_info,
                        family_of,
                        get_family,
                        register,
                        unregister,
)
from ._stability import stability_report
from ._warm import warm_kernels

__all__ = ["ALL_LOSSES", "DT_RANGE", "FAMILIES", "FAMILY_INFO", "Block", "Capabilities", "Family",
           "FamilyInfo", "FitStart", "Record", "Reduction", "Translation", "family_info", "family_of", "get_family",
           "numerical_linearisation", "register", "stability_report", "unregister", "warm_kernels"]
