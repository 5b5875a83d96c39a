"""Least-squares identification of the ch. 7 compensator (sec. 7.2, cost eq. 5.9).

The model contains the sinh mPL: with ``g(z) = z`` it *is* the mPL. So the fit first fits the
mPL (``mpl.fit.fit_mpl``, its deterministic multi-start) and starts from that model with a
linear output resistor; the bounded trust-region solver then moves the parameters with the
exact Jacobian of the forward sensitivities (``kernels.simulate_with_jacobian``).

Two choices, both about the output resistor ``g``:

- *Gauge.* Only ``3N + 4`` of the ``3N + 6`` parameters are identifiable: an affine change of
  ``g``'s voltage (``z -> alpha z + beta``, ``g`` re-expanded, ``w`` and ``V_b`` rescaled)
  leaves every input-output map unchanged (:func:`canonical`). The fit works in the gauge
  ``w_0 = 1``, ``V_b = 0``, so a fitted model file is reproducible and every fitted number is
  determined by the data. (A sinh cell cannot be shifted: it rests at ``v = 0``.)
- *Monotone g.* Unconstrained, the fit bends ``g`` over just outside the training range (on the
  virtual sensor's noise run: ``g_3 = -0.37``, ``g' = 0`` at ``|z| = 1.1`` for data within
  about ``|z| <= 1``). A compensator whose output turns back there reverses the loop's sign as
  soon as a transient leaves the training range: scheme (a) with the document's PID runs away
  within 0.5 s (docs/models/mpl_g.md). So ``g'`` is parametrised by its Bernstein coefficients
  on ``|z| <= MONOTONE_RANGE`` (2, twice the range of normalised data, eq. 5.10), all of one
  sign (that of the mPL start's ``w_0``): ``g`` is strictly monotone there. Three of paper 9.2's
  table II output resistors are inside this set; the chirp column's turns at ``z = 1.32`` (in
  the gauge), at the edge of its own data.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...errors import FitDivergedError
from ...identification import FitResult, check_fit_data, fit_multistart
from ...identification._constrained import constrain_fit
from ...identification._normal_equations import dense_normal_equations
from .._docs import docfiller
from ..mpl import model as mpl
from ..mpl.box import LOG_G_MIN, LOG_VT_BOUNDS, W_BOUND
from ..mpl.fit import fit_mpl, theta_limits
from . import model as mpl_g
from .model import WEIGHT_SUM_FLOOR
from .slopes import (
    MONOTONE_RANGE,
    bernstein_slopes,
    output_from_slopes,
    slope_matrix,
)

fill_doc = docfiller("MplGStructure")

__all__ = ["MONOTONE_RANGE", "WEIGHT_SUM_FLOOR", "bernstein_slopes", "canonical", "fit_box",
           "fit_mpl_g", "output_from_slopes", "random_params", "start_theta", "theta_names"]

# Bounds in optimiser coordinates: the cells' and the weights' are the mPL's (mpl.box); g_0 only
# needs to stay finite; the Bernstein slopes of g between 1e-6 (g' near 0 somewhere on
# |z| <= R: a model limit) and 1e3.
_G0_BOUND = 1e3
_LOG_SLOPE_BOUNDS = (np.log(1e-6), np.log(1e3))


def theta_names(n_cells: int) -> list[str]:
    """Names of the optimiser coordinates, cells from 1: per cell ``log G``, ``log V_T``, then
    ``g_0``, the logs of ``g'``'s Bernstein coefficients on ``|z| <= R``, ``w_1..w_N``.

    Parameters
    ----------
    n_cells : int
        Number of cells ``N``.

    Returns
    -------
    list of str
        ``3N + 4`` names (``log_G[1]``, ``log_v_t[1]``, ..., ``g.c0``, ``g.log_slope0``, ...).
    """
    cells = [f"{name}[{k}]" for k in range(1, n_cells + 1) for name in ("log_G", "log_v_t")]
    return [*cells, "g.c0", *(f"g.log_slope{j}" for j in range(3)),
            *(f"w[{k}]" for k in range(1, n_cells + 1))]


@fill_doc
def fit_box(structure: mpl_g.MplGStructure) -> tuple[np.ndarray, np.ndarray]:
    """The fit's bounds on its coordinates (:func:`theta_names`): the mPL's cell box, ``g_0``
    in ``[-1e3, 1e3]``, the logs of the Bernstein slopes in ``[log 1e-6, log 1e3]``,
    ``w_1..w_N`` in ``[-100, 100]``.

    %(structure_parameters)s

    Returns
    -------
    lower, upper : numpy.ndarray, shape (3N + 4,)
    """
    n = structure.n_cells
    cap = structure.slope_cap / structure.dt
    lower = np.r_[np.tile([LOG_G_MIN, LOG_VT_BOUNDS[0]], n), -_G0_BOUND,
                  np.full(3, _LOG_SLOPE_BOUNDS[0]), np.full(n, -W_BOUND)]
    upper = np.r_[np.tile([np.log(cap), LOG_VT_BOUNDS[1]], n), _G0_BOUND,
                  np.full(3, _LOG_SLOPE_BOUNDS[1]), np.full(n, W_BOUND)]
    return lower, upper


def start_theta(params: mpl_g.MplGParams) -> np.ndarray:
    """The fit's coordinates of ``params`` brought to the gauge (:func:`canonical`), not yet
    clipped into :func:`fit_box`; a Bernstein slope of the wrong sign (``g`` not monotone on
    ``|z| <= MONOTONE_RANGE``) is ``-inf``.

    Parameters
    ----------
    params : MplGParams
        Parameters with ``w_0 != 0``.

    Returns
    -------
    numpy.ndarray, shape (3N + 4,)
    """
    canon = canonical(params)
    b = bernstein_slopes(canon.g)
    b = b * (1.0 if b.sum() >= 0 else -1.0)
    log_b = np.array([np.log(v) if v > 0 else -np.inf for v in b])
    return np.r_[canon.to_vector()[:2 * params.n_cells], canon.g[0], log_b, canon.w[1:]]


def _limits(n_cells: int) -> tuple[list[str | None], list[str | None]]:
    """The cells' model limits are the mPL's (``mpl.fit.theta_limits``); the floor of a
    Bernstein slope is the edge of the monotone set; every other bound is a search box."""
    lower, upper = theta_limits(n_cells)
    edge = (f"g' reaches about 0 within |z| <= {MONOTONE_RANGE:g}: the output resistor is at "
            f"the edge of the monotone set the fit allows")
    return (lower[:2 * n_cells] + [None] + [edge] * 3 + [None] * n_cells,
            upper[:2 * n_cells] + [None] * (n_cells + 4))


def canonical(params: mpl_g.MplGParams) -> mpl_g.MplGParams:
    """The output-equivalent parameters with ``w_0 = 1`` and ``V_b = 0``.

    ``z = w_0 z' - V_b`` with ``z' = e + sum (w_k / w_0) u_k``, so ``g'(z') = g(w_0 z' - V_b)``
    gives the same output for every input and state; the inverse's branch maps along (its
    rest point ``z = -V_b`` is ``z' = 0``).

    Parameters
    ----------
    params : MplGParams
        Any parameters of the family.

    Returns
    -------
    MplGParams
        The equivalent parameters with ``w_0 = 1``, ``V_b = 0``.

    Raises
    ------
    ValueError
        If ``w_0 = 0`` (no scale to fix), or the result leaves the parameter domain.
    """
    if params.w[0] == 0:
        raise ValueError("w_0 = 0: the canonical form fixes w_0 = 1")
    inner = np.polynomial.Polynomial([-params.v_b, params.w[0]])
    g = np.polynomial.Polynomial(params.g)(inner).coef
    return mpl_g.MplGParams(i_s=params.i_s, v_t=params.v_t, g=np.pad(g, (0, 4 - g.size)),
                            w=params.w / params.w[0], v_b=0.0)


def _from_mpl(params: mpl.MplParams) -> mpl_g.MplGParams:
    """The mPL as this family's member with ``g(z) = z`` (the same model, forward and inverse)."""
    return mpl_g.MplGParams(i_s=params.i_s, v_t=params.v_t, g=[0.0, 1.0, 0.0, 0.0],
                            w=params.w, v_b=params.v_b)


class _Coordinates:
    """The optimiser's coordinates ``[cells (2N), g_0, log |b| (3), w_1..w_N]`` and the model's
    parameters, for slopes of sign ``sign``; the Jacobian's chain rule."""

    def __init__(self, n_cells: int, sign: float) -> None:
        self.n, self.sign = n_cells, sign
        self.matrix = slope_matrix(MONOTONE_RANGE)

    def to_params(self, theta: np.ndarray) -> mpl_g.MplGParams:
        n = self.n
        cells = theta[:2 * n].reshape(n, 2)
        v_t = np.exp(cells[:, 1])
        g = output_from_slopes(theta[2 * n], self.sign * np.exp(theta[2 * n + 1:2 * n + 4]))
        return mpl_g.MplGParams(i_s=0.5 * np.exp(cells[:, 0]) * v_t, v_t=v_t, g=g,
                                w=np.r_[1.0, theta[2 * n + 4:]], v_b=0.0)

    def from_params(self, params: mpl_g.MplGParams) -> np.ndarray:
        """Coordinates of canonical ``params`` whose slopes have this sign (clipped to the
        floor where one does not)."""
        b = np.maximum(self.sign * bernstein_slopes(params.g), np.exp(_LOG_SLOPE_BOUNDS[0]))
        return np.r_[params.to_vector()[:2 * self.n], params.g[0], np.log(b), params.w[1:]]

    def jacobian(self, theta: np.ndarray, jac: np.ndarray) -> np.ndarray:
        """``dy/dtheta`` from the plain Jacobian (columns of :meth:`MplGParams.to_vector`)."""
        n = self.n
        b = self.sign * np.exp(theta[2 * n + 1:2 * n + 4])
        slopes = jac[:, 2 * n + 1:2 * n + 4] @ (self.matrix * b)
        return np.column_stack([jac[:, :2 * n + 1], slopes, jac[:, 2 * n + 5:3 * n + 5]])


@fill_doc
def fit_mpl_g(u: np.ndarray, y: np.ndarray, structure: mpl_g.MplGStructure, *,
              max_nfev: int = 200, screen_nfev: int = 12, n_polish: int = 2,
              accept: Callable[[mpl_g.MplGParams], bool] | None = None,
              accept_reason: str = "rejected by the acceptance test",
              solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
              weights: np.ndarray | None = None, init: mpl_g.MplGParams | None = None,
              weight_sum_max: float | None = None) -> FitResult:
    """Fit the ch. 7 compensator mapping ``u`` to ``y`` by minimising the SSE (eq. 5.9), in the
    gauge ``w_0 = 1``, ``V_b = 0`` with ``g`` monotone on ``|z| <= MONOTONE_RANGE``.

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target, sampled every ``structure.dt``, centred and normalised
        (eq. 5.10) by the caller.
    structure : MplGStructure
    %(multistart)s
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart`.
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`; the mPL
        start is fitted with the same cost.
    init : MplGParams, optional
        Start from these parameters only, instead of the fitted mPL: brought to the gauge
        (:func:`canonical`, the same model) and clipped into :func:`fit_box` (a ``g`` that is
        not monotone on ``|z| <= MONOTONE_RANGE`` has its slopes raised to the floor).
    weight_sum_max : float, optional
        Constrain ``sum_k |w_k| <= weight_sum_max`` (the document's fmincon constraint; SSE
        only). In the gauge ``w_0 = 1``, so ``sum_{k>=1} |w_k| <= weight_sum_max - 1``.

    Returns
    -------
    FitResult
        The best start's fit. If ``accept`` vetoes every fit with a cubic ``g``, the accepted
        mPL start with a linear ``g`` (its message says so; with `weight_sum_max`, only if
        it keeps the bound).

    Raises
    ------
    ValueError
        If `init` has another number of cells or ``w_0 = 0``, or `weight_sum_max` is at most
        1 or comes with a robust loss or weights.
    FitDivergedError
        If no start gives a finite cost, or every candidate is vetoed, or every fit with a
        cubic ``g`` is vetoed and the linear-g start breaks `weight_sum_max`.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_cells
    lower, upper = fit_box(structure)
    if weight_sum_max is not None and not weight_sum_max > WEIGHT_SUM_FLOOR:
        raise ValueError(f"in the gauge w_0 = 1 the weight sum is at least 1; got the bound "
                         f"{weight_sum_max!r}")
    if init is not None:
        if init.n_cells != n:
            raise ValueError(f"init has {init.n_cells} cell(s), the structure {n}")
        linear = None
        theta0 = start_theta(init)
        coords = _Coordinates(n, 1.0 if bernstein_slopes(canonical(init).g).sum() >= 0
                              else -1.0)
    else:
        mpl_accept = None if accept is None else (lambda p: accept(_from_mpl(p)))
        linear = fit_mpl(u, y, mpl.MplStructure(n_cells=n, dt=structure.dt,
                                                slope_cap=structure.slope_cap),
                         accept=mpl_accept, accept_reason=accept_reason, loss=loss,
                         f_scale=f_scale, weights=weights)
        start = canonical(_from_mpl(linear.params))
        coords = _Coordinates(n, 1.0 if linear.params.w[0] >= 0 else -1.0)
        theta0 = coords.from_params(start)
    cache: dict = {}

    def run(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # the residual and then the Jacobian at the same point: one sensitivity pass gives both
        key = theta.tobytes()
        if key not in cache:
            cache.clear()
            y_model, jac = mpl_g.simulate_with_jacobian(structure, coords.to_params(theta), u)
            cache[key] = y_model, coords.jacobian(theta, jac)
        return cache[key]

    try:
        result = fit_multistart(lambda th: run(th)[0] - y, [np.clip(theta0, lower, upper)],
                                (lower, upper), coords.to_params, structure,
                                jac=lambda th: run(th)[1], solver=solver, max_nfev=max_nfev,
                                screen_nfev=screen_nfev, n_polish=n_polish, accept=accept,
                                accept_reason=accept_reason, names=theta_names(n),
                                limits=_limits(n), loss=loss, f_scale=f_scale,
                                weights=weights)
    except FitDivergedError:
        if accept is None or linear is None:
            raise
    else:
        if weight_sum_max is None:
            return result
        normal_equations = dense_normal_equations(lambda th: run(th)[0] - y,
                                                  lambda th: run(th)[1], lower, upper)
        return constrain_fit(result, normal_equations, np.arange(2 * n + 4, 3 * n + 4),
                             weight_sum_max - 1.0, coords.to_params, accept=accept,
                             accept_reason=accept_reason, label="sum |w_1..w_N| (w_0 = 1)")
    # Every fit with a curved g was vetoed (an inverse that diverges on the training data);
    # the accepted mPL start is this family's model with a linear g, and is returned as such,
    # but only where it keeps the weight-sum bound: the constrained fit was not carried out.
    message = (f"{linear.message}; g kept linear: the fit with a cubic g was rejected "
               f"({accept_reason})")
    if weight_sum_max is not None:
        weight_sum = float(np.abs(start.w).sum())
        if weight_sum > weight_sum_max:
            raise FitDivergedError(
                f"the fit failed: the constrained fit (sum |w| <= {weight_sum_max:g}, w_0 = 1) "
                f"could not be carried out: every fit with a cubic g was rejected "
                f"({accept_reason}) and the linear-g start has sum |w| = {weight_sum:.6g}")
        message += (f"; not solved under sum |w| <= {weight_sum_max:g}, which this model keeps "
                     f"(sum |w| = {weight_sum:.6g})")
    return replace(linear, params=start, message=message)


# The domain random_params draws from: the mPL's cells over the fit's box, and an output stage
# within paper 9.2's range (its sets have |g| <= 1.4, |w| <= 1.6, |V_b| <= 0.6) chosen so that
# the inverse exists and is bounded on any output:
# - g increasing everywhere (g_1 > 0, g_2^2 < 3 g_1 g_3): a drawn g with a turning point near
#   the data would refuse outputs beyond it;
# - sum_k |w_k| < |w_0|: the inverse's cells then contract. Their update is
#   x+ = x - D (I + 1 a^T) x + ..., a = w[1:] / w_0, D = diag(secant slopes * dt) in (0, 1]
#   for slope_cap <= 1; by Gershgorin every eigenvalue of D (I + 1 a^T) lies in
#   d_k (1 +- sum |a|), inside (0, 2), so |1 - mu| < 1.
# The mPL's |w| <= 100 box would put z near 200 and g(z) near 1e9.
_RANDOM_G0 = 2.0
_RANDOM_G1 = (0.1, 2.0)
_RANDOM_LOG_G3 = (np.log(0.01), np.log(2.0))
_RANDOM_W0 = (0.5, 2.0)
_RANDOM_CELL_SHARE = 0.9
_RANDOM_VB = 1.0


@fill_doc
def random_params(structure: mpl_g.MplGStructure, rng: np.random.Generator) -> mpl_g.MplGParams:
    """Parameters from the family's documented domain for normalised data: ``log G_k`` and
    ``log V_T,k`` uniform between the fit's bounds (``G`` in ``[1e-4, slope_cap / dt]``,
    ``V_T`` in ``[1e-3, 1e3]``); an increasing output resistor: ``g_0`` uniform in
    ``[-2, 2]``, ``g_1`` in ``[0.1, 2]``, ``g_3`` log-uniform in ``[0.01, 2]``, ``g_2`` uniform
    within 0.9 of ``+-sqrt(3 g_1 g_3)``; ``|w_0|`` uniform in ``[0.5, 2]`` with a random sign,
    ``w_k / w_0`` uniform in ``[-0.9 / N, 0.9 / N]``; ``V_b`` uniform in ``[-1, 1]``.

    With ``|u| <= 1`` then ``|z| <= 2 |w_0| + 1 <= 5`` and ``|y| <= 2 + 2 |z| + 2.2 z^2 +
    2 |z|^3``; with ``slope_cap <= 1`` the inverse exists for every output and its cells
    contract (see the comment above), so it is bounded too.

    Parameters
    ----------
    structure : MplGStructure
        The model's structure (its ``N``, ``dt`` and ``slope_cap`` set the cells' range).
    %(rng)s

    Returns
    -------
    MplGParams
        One draw.
    """
    n = structure.n_cells
    log_g = rng.uniform(LOG_G_MIN, np.log(structure.slope_cap / structure.dt), n)
    log_vt = rng.uniform(*LOG_VT_BOUNDS, n)
    g1, g3 = rng.uniform(*_RANDOM_G1), np.exp(rng.uniform(*_RANDOM_LOG_G3))
    g2 = 0.9 * np.sqrt(3 * g1 * g3) * rng.uniform(-1.0, 1.0)
    w0 = rng.uniform(*_RANDOM_W0) * rng.choice([-1.0, 1.0])
    share = _RANDOM_CELL_SHARE / n
    rest = np.r_[rng.uniform(-_RANDOM_G0, _RANDOM_G0), g1, g2, g3, w0,
                 w0 * rng.uniform(-share, share, n), rng.uniform(-_RANDOM_VB, _RANDOM_VB)]
    return mpl_g.MplGParams.from_vector(
        np.r_[np.column_stack([log_g, log_vt]).reshape(-1), rest], n)
