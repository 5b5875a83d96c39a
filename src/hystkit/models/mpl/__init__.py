"""Modified Power-Law (mPL) model, sec. 5.3.1 of the reference document (docs/models/mpl.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``presets`` the document's table 5.2 and paper 9.1 values,
``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="mpl", docs="docs/models/mpl.md", default_size=1, max_size=50,
    title="modified Power-Law, sinh resistors (sec. 5.3.1, eq. 5.1-5.6)",
    size_help="cells N (3N + 2 params)")

__getattr__, __dir__ = family_exports(
    __name__, globals(), "MplFamily",
    fit=("default_starts", "fit_box", "fit_mpl"), presets=("PRESETS", "preset"))
