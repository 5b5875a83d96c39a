"""Parameter identification: least-squares fits of hysteresis models to recordings."""

from ._fit import FitResult, default_starts, fit_mpl

__all__ = ["FitResult", "default_starts", "fit_mpl"]
