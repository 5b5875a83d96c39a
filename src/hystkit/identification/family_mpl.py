"""The modified Power-Law family (sec. 5.3.1) in the model registry."""

from __future__ import annotations

from ..models import mpl
from ._fit import fit_mpl
from ._registry import ModelFamily

__all__ = ["FAMILY"]


def _make_structure(dt: float, size: int, slope_cap: float = 1.0) -> mpl.MplStructure:
    return mpl.MplStructure(n_cells=size, dt=dt, slope_cap=slope_cap)


FAMILY = ModelFamily(
    name="mpl", title="modified Power-Law, sinh resistors (sec. 5.3.1, eq. 5.1-5.6)",
    structure_type=mpl.MplStructure, params_type=mpl.MplParams, make_structure=_make_structure,
    simulate=mpl.simulate, fit=fit_mpl, invert=mpl.invert, size_help="cells N (3N + 2 params)",
    default_size=1)
