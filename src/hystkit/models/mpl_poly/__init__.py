"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 (docs/models/mpl_poly.md).

``model`` holds the equations, limit, rest points, inverse and readable reference, ``kernels``
the compiled loops (with the loop blocks), ``fit`` the identification, ``presets`` paper 9.2's
tables, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import MplPolyFamily

FAMILY = MplPolyFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("canonical", "default_starts", "fit_box", "fit_mpl_poly"),
     "presets": ("PAPER_9_2_TABLE_I", "PAPER_9_2_TABLE_II", "paper_9_2_params")},
    first=("FAMILY", "MplPolyFamily"))
