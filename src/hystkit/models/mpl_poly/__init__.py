"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 (docs/models/mpl_poly.md).

``model`` holds the equations, limit, rest points, inverse and readable reference, ``kernels``
the compiled loops (with the loop blocks), ``fit`` the identification, ``presets`` paper 9.2's
tables, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="mpl-poly", docs="docs/models/mpl_poly.md", default_size=1, max_size=30,
    title="polynomial modified Power-Law, cubic resistors (sec. 5.3.5, eq. 5.16-5.17, 5.29)",
    size_help="cells N (5N + 6 params)")

__getattr__, __dir__ = family_exports(
    __name__, globals(), "MplPolyFamily",
    fit=("canonical", "default_starts", "fit_box", "fit_mpl_poly"),
    presets=("PAPER_9_2_TABLE_I", "PAPER_9_2_TABLE_II", "paper_9_2_params"))
