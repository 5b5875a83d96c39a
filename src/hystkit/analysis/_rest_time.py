"""The rest time of a printed trace (sec. 3.5.1): hours after printing until the fitted drift
rate ``|dR/dt| / R_final`` stays below a threshold for good, with its standard error propagated
from the fit's covariance (delta method, numerical gradient); see :mod:`._settling`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ._settling import SettlingFit, SettlingFitError

__all__ = ["REST_RULE", "RestTime", "rest_time"]


@dataclass(frozen=True)
class RestTime:
    """Rest time of :func:`rest_time`: ``hours`` [h] after printing, its ``stderr_h`` (None
    when it is 0: already settled at the first reading), the ``threshold_pct_per_hour`` it
    used, and ``extrapolated`` when it lies after the end of the log.

    Parameters
    ----------
    hours : float
        Rest time [h] after printing.
    stderr_h : float or None
        Its standard error [h]; None when the rest time is 0.
    threshold_pct_per_hour : float
        Drift-rate threshold [% per hour] it used.
    extrapolated : bool
        True when it lies after the end of the log.
    """

    hours: float
    stderr_h: float | None
    threshold_pct_per_hour: float
    extrapolated: bool

    def to_dict(self) -> dict:
        """JSON-ready, with the rule in words."""
        return {"hours": self.hours, "days": self.hours / 24.0, "stderr_h": self.stderr_h,
                "threshold_pct_per_hour": self.threshold_pct_per_hour,
                "extrapolated": self.extrapolated, "rule": REST_RULE}


REST_RULE = ("earliest time after which the fitted drift rate |dR/dt| / R_final stays below "
             "the threshold for good")


def rest_time(fit: SettlingFit, threshold_pct_per_hour: float = 0.1) -> RestTime:
    """Hours after printing until the fitted drift rate stays below a threshold.

    Parameters
    ----------
    fit : SettlingFit
    threshold_pct_per_hour : float
        Largest acceptable drift ``|dR/dt| / R_final`` [%/h], > 0.

    Returns
    -------
    RestTime
        The rule: the earliest t after which ``|dR/dt|(t') / R_final < threshold`` for every
        t' > t. For the plain drop this is ``tau ln(drop / (R_final tau thr))`` (or 0).

    Raises
    ------
    SettlingFitError
        R_final not positive or not determined (standard error >= its value).
    """
    if not (math.isfinite(threshold_pct_per_hour) and threshold_pct_per_hour > 0):
        raise ValueError(f"threshold must be a positive number, got {threshold_pct_per_hour}")
    r_final, se = fit.params["r_final"], fit.stderr["r_final"]
    if not (r_final > 0 and se < r_final):
        raise SettlingFitError(f"no rest time: R_final = {r_final:.3g} ± {se:.2g} Ohm is not "
                               "positive and determined, and the drift is relative to it")
    thr = threshold_pct_per_hour / 100.0
    hours = _last_crossing(fit.params, thr)
    stderr = None
    if hours > 0:
        names = list(fit.params)
        grad = np.empty(len(names))
        for i, name in enumerate(names):
            h = 1e-6 * max(abs(fit.params[name]), 1e-9)
            up = _last_crossing({**fit.params, name: fit.params[name] + h}, thr)
            down = _last_crossing({**fit.params, name: fit.params[name] - h}, thr)
            grad[i] = (up - down) / (2 * h)
        stderr = float(math.sqrt(max(float(grad @ fit.covariance @ grad), 0.0)))
    return RestTime(hours=hours, stderr_h=stderr, threshold_pct_per_hour=threshold_pct_per_hour,
                    extrapolated=hours > fit.t_end_h)


def _last_crossing(params: dict[str, float], thr: float) -> float:
    """Last t >= 0 where |dR/dt| / R_final equals `thr` (0 if it never exceeds it)."""
    terms = [(params["drop"], params["tau_drop_h"])]
    if "rise" in params:
        terms.append((params["rise"], params["tau_rise_h"]))
    # Past each term's own t_j its rate is below thr / 2, so past all of them the sum is below
    # thr: the search ends there.
    horizon = max([tau * math.log(2 * a / (tau * params["r_final"] * thr))
                   for a, tau in terms if a > 0] + [0.0])
    if horizon <= 0.0:
        return 0.0
    grid = np.linspace(0.0, horizon, 20001)
    excess = np.abs(_drift_rate(params, grid)) - thr
    above = np.flatnonzero(excess > 0)
    if above.size == 0:
        return 0.0
    i = int(above[-1])
    if i == grid.size - 1:
        return float(grid[-1])
    return float(brentq(lambda t: abs(float(_drift_rate(params, np.array(t)))) - thr,
                        grid[i], grid[i + 1], xtol=1e-12 * max(horizon, 1.0)))


def _drift_rate(params: dict[str, float], t_h: np.ndarray) -> np.ndarray:
    """dR/dt / R_final [1/h]."""
    rate = -params["drop"] / params["tau_drop_h"] * np.exp(-t_h / params["tau_drop_h"])
    if "rise" in params:
        rate = rate + params["rise"] / params["tau_rise_h"] * np.exp(-t_h / params["tau_rise_h"])
    return rate / params["r_final"]
