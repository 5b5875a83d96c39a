"""Bouc-Wen hysteresis with linear dynamics, a single-degree-of-freedom oscillator (beyond the
reference document; docs/models/boucwen.md).

The folder has the layout of every family (:mod:`hystkit.models._protocol`).
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="boucwen", docs="docs/models/boucwen.md", default_size=2, max_size=64,
    title="Bouc-Wen oscillator, m y'' + c y' + k y + z = u (beyond the document; Noel-Schoukens "
          "benchmark)",
    size_help="RK4 substeps per sample (7 parameters whatever the size)",
    no_inverse_reason="its input is a force and its output a displacement of a second-order "
                      "system: the inverse needs the measured output differentiated twice "
                      "(dynamic inversion), which is not implemented")

__getattr__, __dir__ = family_exports(__name__, globals(), "BoucWenFamily")
