"""Power-Law (PL) model as published, sec. 2.1.7, eq. 2.16-2.18 and table 5.1 (docs/models/pl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops (with
the loop blocks), ``fit`` the weight fit for a fixed structure, ``search`` the exhaustive
structural search behind ``hystkit pl-search``, ``family`` the protocol adapter (``FAMILY``).
"""

from ..._lazy import lazy_exports
from .family import PlFamily

FAMILY = PlFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("default_starts", "fit_pl", "solve_weights"),
     "grid": ("DEFAULT_GRID",),
     "search": ("format_search_table", "structural_search")},
    first=("FAMILY", "PlFamily"))
