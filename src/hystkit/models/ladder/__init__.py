"""PWL ladder circuit of Parodi, Storace and Cincotti, sec. 2.1.5 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="ladder",
    title="PWL ladder circuit, Parodi-Storace-Cincotti (sec. 2.1.5)",
    size_help="ladder sections N, a PWL resistor and a capacitor each (3N + 2 params)",
    default_size=2,
    max_size=50,
    docs="docs/models/circuits.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "LadderFamily"), "model": ("*",), "fit": ("*",)},
    first=("INFO",))
