"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 of the reference document
(docs/models/circuits.md).

The folder has the layout of every family (:mod:`hystkit.models._protocol`).
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="bobbio", docs="docs/models/circuits.md", default_size=10, max_size=100,
    title="Bobbio-Marrucci springs and friction pistons (sec. 2.1.4, eq. 2.5)",
    size_help="springs N, with N - 1 pistons (2N params)")

__getattr__, __dir__ = family_exports(__name__, globals(), "BobbioFamily")
