"""Modified Power-Law (mPL) model, sec. 5.3.1 of the reference document (docs/models/mpl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``presets`` the document's table 5.2 and paper 9.1 values,
``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .family import MplFamily

FAMILY = MplFamily()

# The model's equations, its fit and its numba kernels load when one of their names is first
# used, so that the registry (hystkit fit --help) lists the family without compiling anything.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"model": ("*",), "fit": ("default_starts", "fit_box", "fit_mpl"),
     "presets": ("PRESETS", "preset")},
    first=("FAMILY", "MplFamily"))
