"""scikit-learn-style wrapper over :func:`fit_compensator` for users who think in estimators."""

from __future__ import annotations

import numpy as np

from ..io import Recording
from ..metrics import r2
from ._centring import DEFAULT_CENTER, ORACLE_CENTER
from ._compensator import Compensator
from ._fitting import fit_compensator

__all__ = ["CompensatorEstimator"]


class CompensatorEstimator:
    """mPL compensator with the ``fit`` / ``predict`` / ``score`` contract.

    ``__init__`` only stores the settings; ``fit`` returns ``self`` and sets
    ``compensator_`` (a :class:`Compensator`, which can be saved and applied on its own).
    """

    def __init__(self, n_cells: int = 1, mode: str = "direct", center: str = DEFAULT_CENTER,
                 slope_cap: float = 1.0) -> None:
        self.n_cells = n_cells
        self.mode = mode
        self.center = center
        self.slope_cap = slope_cap

    def fit(self, recording: Recording) -> CompensatorEstimator:
        self.compensator_: Compensator = fit_compensator(
            recording, self.n_cells, mode=self.mode, center=self.center,
            slope_cap=self.slope_cap)
        return self

    def _fitted(self) -> Compensator:
        if not hasattr(self, "compensator_"):
            raise RuntimeError("this CompensatorEstimator is not fitted yet; call fit first")
        return self.compensator_

    def predict(self, recording: Recording) -> np.ndarray:
        """Position estimate [mm] (see :meth:`Compensator.estimate`)."""
        return self._fitted().estimate(recording)

    def score(self, recording: Recording) -> float:
        """R² of the estimate against the recording's position, with the fitted centring."""
        comp = self._fitted()
        mean = float(recording.position.mean()) if comp.center == ORACLE_CENTER else None
        return r2(recording.position, comp.estimate(recording, position_mean=mean))
