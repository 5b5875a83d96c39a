"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 of the reference document
(docs/models/circuits.md).

``model`` holds the equations and the readable reference, ``kernels`` the compiled loops,
``fit`` the identification, ``family`` the protocol adapter exported as ``FAMILY``.
"""

from ..._lazy import lazy_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="bobbio",
    title="Bobbio-Marrucci springs and friction pistons (sec. 2.1.4, eq. 2.5)",
    size_help="springs N, with N - 1 pistons (2N params)",
    default_size=10,
    max_size=100,
    docs="docs/models/circuits.md")

# The registry reads INFO (hystkit fit --help loads no model); the family object (FAMILY), its
# equations, fit and numba kernels load when one of their names is first used.
__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"family": ("FAMILY", "BobbioFamily"), "model": ("*",), "fit": ("*",)},
    first=("INFO",))
