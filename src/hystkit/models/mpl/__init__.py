"""Modified Power-Law (mPL) model, sec. 5.3.1 of the reference document (docs/models/mpl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``presets`` the document's table 5.2 and paper 9.1 values,
``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="mpl",
    title="modified Power-Law, sinh resistors (sec. 5.3.1, eq. 5.1-5.6)",
    size_help="cells N (3N + 2 params)",
    default_size=1,
    max_size=50,
    docs="docs/models/mpl.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "MplFamily"), "model": ("*",),
     "fit": ("default_starts", "fit_box", "fit_mpl"), "presets": ("PRESETS", "preset")},
    first=("INFO",))
