"""Chua-Stromsmoe model, sec. 2.1.3 of the reference document (docs/models/circuits.md).

The folder has the layout of every family (:mod:`hystkit.models._protocol`).
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="chua", docs="docs/models/circuits.md", default_size=1, max_size=20,
    title="Chua-Stromsmoe, dy/dt = g(u - f(y)) (sec. 2.1.3, eq. 2.3)",
    size_help="elements in series N, output the sum of their states (6N params; 1 = eq. 2.3)")

__getattr__, __dir__ = family_exports(__name__, globals(), "ChuaFamily")
