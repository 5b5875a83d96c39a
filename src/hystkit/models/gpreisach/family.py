"""The generalised Preisach family (sec. 2.1.2, eq. 2.2) behind the family protocol.

The memory is the classical staircase, so everything but the structure, the fit and the
parameter count comes from the classical family's :class:`StaircaseFamily` (packed loop state,
rest states, the shared compiled block, the branch linearisation, rate independence).
"""

from __future__ import annotations

from typing import Any

from ..preisach import StaircaseFamily
from . import model as gpreisach
from .fit import fit_gpreisach

__all__ = ["GPreisachFamily"]


class GPreisachFamily(StaircaseFamily):
    name = "gpreisach"
    title = ("generalised (non-linear) Preisach, input-dependent weight and reversible part "
             "(sec. 2.1.2, eq. 2.2)")
    size_help = "grid levels L of the two Preisach weights ((L - 1) (L - 2) relay cells)"
    default_size = 16
    docs = "docs/models/preisach.md"
    Structure = gpreisach.GPreisachStructure
    Params = gpreisach.GPreisachParams
    stairs = gpreisach
    fit_function = fit_gpreisach

    def make_structure(self, dt: float, size: int,
                       **options: Any) -> gpreisach.GPreisachStructure:
        return gpreisach.GPreisachStructure(levels=size, dt=dt, **options)

    def n_params(self, structure, params) -> int:
        """Off-diagonal masses of both weights (the fit keeps the diagonal at zero), the
        Bernstein coefficients of ``nu`` and the offset."""
        return (structure.levels - 1) * (structure.levels - 2) + params.nu.size + 1
