"""Parameter identification: least-squares fits of hysteresis models to recordings."""

from ._fit import default_starts, fit_mpl
from ._least_squares import fit_multistart
from ._registry import FAMILIES, ModelFamily, get_family
from ._result import FitResult

__all__ = ["FAMILIES", "FitResult", "ModelFamily", "default_starts", "fit_mpl", "fit_multistart",
           "get_family"]
