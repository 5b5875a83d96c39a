"""The ch. 7 compensator: sinh cells with a cubic output resistor g (sec. 7.2;
docs/models/mpl_g.md).

``model`` holds the equations, inverse and readable reference, ``kernels`` the compiled loops
(with the loop blocks), ``fit`` the identification, ``presets`` the sec. 7.2 compensators of
paper 9.2's table II sensors, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="mpl-g",
    title="ch. 7 compensator: sinh cells with a cubic output resistor g (sec. 7.2, eq. 5.1-5.6, "
          "5.16-5.17)",
    size_help="cells N (3N + 4 fitted params)",
    default_size=1,
    max_size=50,
    docs="docs/models/mpl_g.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "MplGFamily"), "model": ("*",), "fit": ("canonical", "fit_mpl_g"),
     "presets": ("ch7_compensator", "table_ii_response")},
    first=("INFO",))
