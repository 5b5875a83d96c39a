"""Power-Law (PL) model as published, sec. 2.1.7, eq. 2.16-2.18 and table 5.1 (docs/models/pl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops (with
the loop blocks), ``fit`` the weight fit for a fixed structure, ``search`` the exhaustive
structural search behind ``hystkit pl-search``, ``family`` the protocol adapter (``FAMILY``).
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="pl", docs="docs/models/pl.md", default_size=1, max_size=50,
    title="Power-Law model as published, Biggio et al. (sec. 2.1.7, eq. 2.16-2.18)",
    size_help="cells N (N + M + 4 params; p, M, S via options or 'hystkit pl-search')")

__getattr__, __dir__ = family_exports(
    __name__, globals(), "PlFamily",
    fit=("default_starts", "fit_pl", "solve_weights"), grid=("DEFAULT_GRID",),
    search=("format_search_table", "structural_search"))
