"""Per-cycle and settling analysis of the sensor (figs. 4.13, 4.16-4.17, table 3.1, sec. 3.5.1).

Cycles: cut a recording at the input's minima (:func:`cycle_bounds`), then loop area, offset
and drift of every cycle for each gauge and their difference (:func:`cycle_table`), and the
document's figure of chosen cycles (:func:`plot_cycles`). Settling: fit a freshly printed
trace's resistance log (:func:`fit_settling`), the rest time before it is usable
(:func:`rest_time`) and its figure (:func:`plot_settling`).
"""

from ._cycles import DEFAULT_DEADBAND, cycle_bounds, input_minima, split_cycles
from ._figures import plot_cycles, plot_settling
from ._per_cycle import CycleTable, DriftRate, cycle_table, drift_rate, enclosed_area
from ._rest_time import REST_RULE, RestTime, rest_time
from ._settling import MODELS, SettlingFit, SettlingFitError, fit_settling, settling_curve

__all__ = ["DEFAULT_DEADBAND", "MODELS", "REST_RULE", "CycleTable", "DriftRate", "RestTime",
           "SettlingFit", "SettlingFitError", "cycle_bounds", "cycle_table", "drift_rate",
           "enclosed_area", "fit_settling", "input_minima", "plot_cycles", "plot_settling",
           "rest_time", "settling_curve", "split_cycles"]
