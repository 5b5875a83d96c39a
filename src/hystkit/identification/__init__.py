"""Parameter identification machinery shared by every model family (no family lives here).

Each family's own fit is in its folder, ``hystkit.models.<family>``; the registry of families is
:mod:`hystkit.models`.
"""

from ._least_squares import check_fit_data, fit_multistart
from ._result import BoundHit, FitResult

__all__ = ["BoundHit", "FitResult", "check_fit_data", "fit_multistart"]
