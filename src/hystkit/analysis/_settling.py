"""Fitting the settling of a freshly printed trace and the rest time before it is usable.

Sec. 3.5.1 logs a printed trace's resistance for days and concludes that 2-3 days of rest are
needed. Here the log is fitted with the law of :class:`hystkit.sensors.SettlingLaw`,

``R(t) = R_final + drop e^(-t/tau_drop) - rise e^(-t/tau_rise)``  (t in hours),

either whole (``"rise-drop"``, five parameters, ``tau_rise < tau_drop``) or without the rise
(``"drop"``, three), or both with the one of lower BIC kept (``"auto"``). The time constants
enter non-linearly, the amplitudes linearly: a coarse grid over the time constants with the
amplitudes solved by linear least squares gives the start, ``scipy.optimize.least_squares``
refines all parameters together. Standard errors come from the Jacobian at the optimum,
``cov = s^2 (J^T J)^-1`` with ``s^2`` the residual variance, times
``sqrt((1 + rho) / (1 - rho))`` when the residuals' lag-1 autocorrelation ``rho`` is positive
(slow temperature drift makes neighbouring readings alike, and white-noise errors would then
be too small; the AR(1) variance inflation).

**Rest time** (the rule): the earliest time after which the fitted drift rate
``|dR/dt| / R_final`` stays below the threshold (default 0.1 %/h) for good. Its standard
error is propagated from the parameter covariance (delta method, numerical gradient). When
it lies after the end of the log it is an extrapolation of the fit, and is flagged so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from ._autocorr import ar1_inflation, lag1

__all__ = ["MODELS", "SettlingFit", "SettlingFitError", "fit_settling", "settling_curve"]

MODELS = ("auto", "rise-drop", "drop")
_NAMES = {"rise-drop": ("r_final", "drop", "tau_drop_h", "rise", "tau_rise_h"),
          "drop": ("r_final", "drop", "tau_drop_h")}
# Points of the log grid of starting time constants, from the reading interval (or 1e-3 of the
# log) to 10 times the log's length; the refinement does the rest.
_GRID_POINTS = 24
# A fit whose residuals have lag-1 autocorrelation above this and an RMS this many times the
# reading noise misses the log's shape (a drop fitted to a rise-then-drop: 0.99 and 25 times).
_MISFIT_RHO = 0.9
_MISFIT_RATIO = 3.0


def settling_curve(params: dict[str, float], t_h: npt.ArrayLike) -> np.ndarray:
    """R(t) [Ohm] of fitted or known parameters (keys of :attr:`SettlingFit.params`).

    Parameters
    ----------
    params : dict of str to float
        ``r_final``, ``drop`` [Ohm] and ``tau_drop_h`` [h]; with ``rise`` [Ohm] and
        ``tau_rise_h`` [h] for the rise-drop model.
    t_h : array_like
        Times [h] after printing.

    Returns
    -------
    numpy.ndarray
        Resistance [Ohm], same shape as `t_h`.
    """
    t = np.asarray(t_h, dtype=float)
    r = params["r_final"] + params["drop"] * np.exp(-t / params["tau_drop_h"])
    if "rise" in params:
        r = r - params["rise"] * np.exp(-t / params["tau_rise_h"])
    return r


@dataclass(frozen=True)
class SettlingFit:
    """Result of :func:`fit_settling`.

    ``model`` ("rise-drop" or "drop"); ``params`` and ``stderr`` by name (Ohm, hours);
    ``rms`` the residual RMS [Ohm]; ``rho`` the residuals' lag-1 autocorrelation and
    ``inflation`` the factor applied to the standard errors; ``bic``; ``converged`` and
    ``message`` of the optimiser; ``t_end_h`` the log's last time; ``alternatives`` the BIC of
    every model tried (auto); ``covariance`` of the parameters in the order of ``params``
    (inflated like ``stderr``).

    Parameters
    ----------
    model : {"rise-drop", "drop"}
        The model chosen.
    params, stderr : dict of str to float
        Parameters and their standard errors by name [Ohm, h].
    rms : float
        Residual RMS [Ohm].
    rho : float
        Lag-1 autocorrelation of the residuals.
    inflation : float
        Factor applied to the standard errors for that autocorrelation.
    bic : float
        Bayesian information criterion.
    converged : bool
        Whether the optimiser converged.
    message : str
        The optimiser's message, with notes on models that dropped out.
    n : int
        Readings fitted.
    t_end_h : float
        Time [h] of the log's last reading.
    covariance : numpy.ndarray, optional
        Covariance of the parameters in the order of `params` (inflated like `stderr`).
    alternatives : dict of str to float, optional
        BIC of every model tried.
    """

    model: str
    params: dict[str, float]
    stderr: dict[str, float]
    rms: float
    rho: float
    inflation: float
    bic: float
    converged: bool
    message: str
    n: int
    t_end_h: float
    covariance: np.ndarray | None = field(repr=False, compare=False, default=None)
    alternatives: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-ready."""
        return {"model": self.model, "params": self.params, "stderr": self.stderr,
                "rms_ohm": self.rms, "residual_lag1_autocorrelation": self.rho,
                "stderr_inflation": self.inflation, "bic": self.bic,
                "converged": self.converged, "message": self.message, "n_readings": self.n,
                "t_end_h": self.t_end_h, "bic_of_models_tried": self.alternatives}


class SettlingFitError(ValueError):
    """The settling law could not be fitted: not converged, not identifiable, collapsed onto a
    bound, a parameter not determined (standard error above its value), or residuals that show
    the law misses the log's shape.
    """


def fit_settling(t_h: npt.ArrayLike, r: npt.ArrayLike, model: str = "auto") -> SettlingFit:
    """Fit the settling law to a resistance log.

    Parameters
    ----------
    t_h : array_like, shape (n,)
        Hours since printing, increasing.
    r : array_like, shape (n,)
        Resistance [Ohm], > 0.
    model : {"auto", "rise-drop", "drop"}
        Law to fit; auto fits both and keeps the lower BIC (a "rise-drop" that fails or
        cannot be identified, e.g. on a log without a rise, drops out).

    Returns
    -------
    SettlingFit

    Raises
    ------
    ValueError
        Bad input (lengths, non-finite, R <= 0, time not increasing, under 8 readings).
    SettlingFitError
        No model gave a usable fit; the message says why for each (not converged, singular,
        a parameter at its bound, a standard error above its value, or residuals far above
        the reading noise with lag-1 autocorrelation > 0.9).
    """
    t, y = _checked(t_h, r)
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    tried = ("rise-drop", "drop") if model == "auto" else (model,)
    fits, reasons = {}, []
    for name in tried:
        try:
            fits[name] = _fit_one(t, y, name)
        except SettlingFitError as exc:
            reasons.append(f"{name}: {exc}")
    if not fits:
        raise SettlingFitError("; ".join(reasons))
    best = min(fits.values(), key=lambda f: f.bic)
    alternatives = {name: f.bic for name, f in fits.items()}
    note = "" if not reasons else " (" + "; ".join(reasons) + ")"
    return SettlingFit(**{**best.__dict__, "alternatives": alternatives,
                          "message": best.message + note})


def _checked(t_h: npt.ArrayLike, r: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    t, y = np.asarray(t_h, dtype=float), np.asarray(r, dtype=float)
    if t.ndim != 1 or t.shape != y.shape:
        raise ValueError(f"time and resistance must be 1-D of one length, got {t.shape}, "
                         f"{y.shape}")
    if t.size < 8:
        raise ValueError(f"{t.size} readings; a settling fit needs at least 8")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise ValueError("time or resistance holds NaN or infinite values")
    if np.any(np.diff(t) <= 0):
        row = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise ValueError(f"time must increase; reading {row + 1} is not after reading {row}")
    if np.any(y <= 0):
        raise ValueError(f"resistance must be > 0; reading {int(np.argmax(y <= 0)) + 1} is not")
    return t, y


def _basis(t: np.ndarray, taus: tuple[float, ...]) -> np.ndarray:
    """Columns 1, e^(-t/tau_drop)[, -e^(-t/tau_rise)]: the amplitudes enter linearly."""
    cols = [np.ones_like(t), np.exp(-t / taus[0])]
    if len(taus) > 1:
        cols.append(-np.exp(-t / taus[1]))
    return np.column_stack(cols)


def _start(t: np.ndarray, y: np.ndarray, name: str) -> np.ndarray:
    """Best grid point: time constants on a log grid, amplitudes by linear least squares."""
    step = float(np.median(np.diff(t)))
    span = float(t[-1] - t[0])
    grid = np.geomspace(max(step, 1e-3 * span), 10.0 * span, _GRID_POINTS)
    pairs = ([(td,) for td in grid] if name == "drop"
             else [(td, tr) for td in grid for tr in grid if tr < td])
    best, best_cost = None, math.inf
    for taus in pairs:
        a = _basis(t, taus)
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        cost = float(np.sum((a @ coef - y) ** 2))
        if cost < best_cost and np.all(coef[1:] >= 0):
            best, best_cost = (coef, taus), cost
    if best is None:
        raise SettlingFitError("no starting point with non-negative amplitudes (the log does "
                               "not settle downwards)")
    coef, taus = best
    x0 = [coef[0], coef[1], taus[0]]
    if name == "rise-drop":
        x0 += [coef[2], taus[1]]
    return np.array(x0)


def _fit_one(t: np.ndarray, y: np.ndarray, name: str) -> SettlingFit:
    names = _NAMES[name]
    x0 = _start(t, y, name)
    scale = np.array([np.ptp(y) or 1.0, np.ptp(y) or 1.0, 1.0, np.ptp(y) or 1.0, 1.0])[:x0.size]

    def residual(p: np.ndarray) -> np.ndarray:
        return settling_curve(dict(zip(names, p, strict=True)), t) - y

    lower = [0.0, 0.0, 1e-9] + ([0.0, 1e-9] if name == "rise-drop" else [])
    x0 = np.maximum(x0, np.array(lower) + 1e-12)
    res = least_squares(residual, x0, bounds=(lower, np.inf), x_scale=scale, method="trf",
                        xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=2000)
    if not res.success:
        raise SettlingFitError(f"the optimiser did not converge ({res.message})")
    params = dict(zip(names, (float(v) for v in res.x), strict=True))
    if name == "rise-drop" and not params["tau_rise_h"] < params["tau_drop_h"]:
        raise SettlingFitError("the fitted rise is not faster than the drop (tau_rise_h >= "
                               "tau_drop_h): no rise in this log")
    n, k = t.size, len(names)
    # Floored at rounding level, so a noise-free log has a finite BIC (and zero errors).
    rss = max(float(np.sum(res.fun ** 2)), n * (1e-15 * float(np.max(np.abs(y)))) ** 2)
    jtj = res.jac.T @ res.jac
    if np.linalg.cond(jtj) > 1e14:
        raise SettlingFitError("parameters not identifiable from this log (singular Jacobian; "
                               "e.g. a rise of amplitude 0, or a log far shorter than the time "
                               "constants)")
    cov = np.linalg.inv(jtj) * rss / (n - k)
    rho = lag1(res.fun)
    inflation = ar1_inflation(rho)
    stderr = {p: float(inflation * math.sqrt(max(cov[i, i], 0.0))) for i, p in enumerate(names)}
    _check_determined(params, stderr, res.active_mask, y)
    _check_describes(math.sqrt(rss / n), rho, y)
    bic = n * math.log(rss / n) + k * math.log(n)
    return SettlingFit(model=name, params=params, stderr=stderr,
                       rms=math.sqrt(rss / n), rho=rho, inflation=inflation, bic=bic,
                       converged=True, message=str(res.message), n=n, t_end_h=float(t[-1]),
                       covariance=cov * inflation**2)


def _check_determined(params: dict[str, float], stderr: dict[str, float],
                      active_mask: np.ndarray, y: np.ndarray) -> None:
    """Refuse a fit that collapsed onto a bound or leaves a parameter undetermined.

    The optimiser "converges" there too (its cost stops falling), but e.g. a drop fitted to a
    log that rises first ends with R_final = 0 and every error larger than its value.
    """
    at_bound = [p for p, active in zip(params, active_mask, strict=True) if active != 0]
    if params["r_final"] <= 1e-9 * float(np.max(y)) and "r_final" not in at_bound:
        at_bound.append("r_final")
    if at_bound:
        raise SettlingFitError(f"collapsed: {', '.join(at_bound)} ended at its lower bound "
                               "(about 0), so this law does not describe the log")
    vague = [f"{p} = {v:.3g} ± {stderr[p]:.2g}" for p, v in params.items()
             if not stderr[p] < abs(v)]
    if vague:
        raise SettlingFitError("fitted but not determined: standard error above the value "
                               f"for {'; '.join(vague)}")


def _check_describes(rms: float, rho: float, y: np.ndarray) -> None:
    """Refuse a fit whose residuals are a smooth curve far above the reading noise.

    The noise is estimated from reading-to-reading differences (robustly, MAD), which the slow
    settling barely touches; a residual RMS several times larger with lag-1 autocorrelation
    near 1 means the law misses the shape of the log.
    """
    d = np.diff(y)
    noise = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(2)
    # the floor keeps a noise-free log's rounding-level residuals from counting
    if rho > _MISFIT_RHO and rms > max(_MISFIT_RATIO * noise, 1e-9 * float(np.max(y))):
        raise SettlingFitError("the law does not describe this log: residual rms "
                               f"{rms:.3g} Ohm against a reading noise of {noise:.3g} Ohm, "
                               f"residual lag-1 autocorrelation {rho:.2f}")
