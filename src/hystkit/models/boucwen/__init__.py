"""Bouc-Wen hysteresis with linear dynamics, a single-degree-of-freedom oscillator (beyond the
reference document; docs/models/boucwen.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="boucwen",
    title="Bouc-Wen oscillator, m y'' + c y' + k y + z = u (beyond the document; Noel-Schoukens "
          "benchmark)",
    size_help="RK4 substeps per sample (7 parameters whatever the size)",
    default_size=2,
    max_size=64,
    docs="docs/models/boucwen.md",
    no_inverse_reason="its input is a force and its output a displacement of a second-order "
                      "system: the inverse needs the measured output differentiated twice "
                      "(dynamic inversion), which is not implemented")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "BoucWenFamily"), "model": ("*",), "fit": ("*",)},
    first=("INFO",))
