"""Compensators: fitted models that turn a sensor signal into a position estimate."""

from ._compensator import CENTERS, MODES, Compensator, LinearBaseline, Scaling, fit_compensator
from ._estimator import CompensatorEstimator
from ._evaluate import evaluate
from ._model_file import (
                          compensator_from_dict,
                          compensator_to_dict,
                          load_compensator,
                          save_compensator,
)

__all__ = ["CENTERS", "MODES", "Compensator", "CompensatorEstimator", "LinearBaseline", "Scaling", "compensator_from_dict",
           "compensator_to_dict", "evaluate", "fit_compensator", "load_compensator",
           "save_compensator"]
