"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 (docs/models/pi.md).

``model`` holds the equations, the analytical inverse (eq. 2.19) and the readable reference,
``kernels`` the compiled loops, ``fit`` the identification (Kuhnen's generalised error, one
bounded linear least-squares solve), ``family`` the protocol adapter exported as ``FAMILY``.
"""

from .._package import family_exports
from .._protocol import FamilyInfo

INFO = FamilyInfo(
    name="pi", docs="docs/models/pi.md", default_size=10, max_size=200,
    title="Kuhnen / modified Prandtl-Ishlinskii with creep (sec. 2.1.6, eq. 2.6-2.19)",
    size_help="play operators n (thresholds i/n, i < n; plus 2 x 2 dead zones, 4 creep operators "
              "by default)")

__getattr__, __dir__ = family_exports(__name__, globals(), "PiFamily")
