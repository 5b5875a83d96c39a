"""The ch. 7 compensator: sinh cells with a cubic output resistor g (sec. 7.2;
docs/models/mpl_g.md).

``model`` holds the equations, inverse and readable reference, ``kernels`` the compiled loops
(with the loop blocks), ``fit`` the identification, ``presets`` the sec. 7.2 compensators of
paper 9.2's table II sensors, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="mpl-g", docs="docs/models/mpl_g.md", default_size=1, max_size=50,
    title="ch. 7 compensator: sinh cells with a cubic output resistor g (sec. 7.2, eq. 5.1-5.6, "
          "5.16-5.17)",
    size_help="cells N (3N + 4 fitted params)")

__getattr__, __dir__ = family_exports(
    __name__, globals(), "MplGFamily",
    fit=("canonical", "fit_mpl_g"), presets=("ch7_compensator", "table_ii_response"))
