"""PWL ladder circuit of Parodi, Storace and Cincotti, sec. 2.1.5 of the reference document
(docs/models/circuits.md).

The folder has the layout of every family (:mod:`hystkit.models._protocol`).
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="ladder", docs="docs/models/circuits.md", default_size=2, max_size=50,
    title="PWL ladder circuit, Parodi-Storace-Cincotti (sec. 2.1.5)",
    size_help="ladder sections N, a PWL resistor and a capacitor each (3N + 2 params)")

__getattr__, __dir__ = family_exports(__name__, globals(), "LadderFamily")
