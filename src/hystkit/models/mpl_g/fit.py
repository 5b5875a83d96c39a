"""Least-squares identification of the ch. 7 compensator (sec. 7.2, cost eq. 5.9).

The model contains the sinh mPL: with ``g(z) = z`` it *is* the mPL. So the fit first fits the
mPL (``mpl.fit.fit_mpl``, its deterministic multi-start) and starts from that model with a
linear output resistor; the bounded trust-region solver then moves all ``3N + 6`` parameters
with the exact Jacobian of the forward sensitivities (``kernels.simulate_with_jacobian``). The
result is never worse than the mPL's fit on the same data.

Only ``3N + 4`` parameters are identifiable: an affine change of the output resistor's voltage
(``z -> alpha z + beta``, ``g`` re-expanded, ``w`` and ``V_b`` rescaled) leaves every
input-output map unchanged. The result is mapped to the representative with ``w_0 = 1``,
``V_b = 0`` (:func:`canonical`), so a fitted model file is reproducible. (Unlike the cubic cells
of mpl-poly, a sinh cell cannot be shifted: it rests at ``v = 0``.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...identification import FitResult, check_fit_data, fit_multistart
from ..mpl import model as mpl
from ..mpl.fit import fit_mpl, theta_limits
from . import model as mpl_g

__all__ = ["canonical", "fit_mpl_g", "random_params", "theta_names"]

# Bounds in optimiser coordinates (MplGParams.to_vector): the cells' are the mPL's; |w| <= 100
# mirrors the document's weight-sum constraint (sec. 5.3.3); g's coefficients only need to
# stay finite.
_LOG_VT_BOUNDS = (np.log(1e-3), np.log(1e3))
_LOG_G_MIN = np.log(1e-4)
_G_BOUND = 1e3
_W_BOUND = 100.0


def theta_names(n_cells: int) -> list[str]:
    """Names of the optimiser coordinates (:meth:`MplGParams.to_vector`), cells from 1."""
    cells = [f"{name}[{k}]" for k in range(1, n_cells + 1) for name in ("log_G", "log_v_t")]
    return [*cells, *(f"g.c{j}" for j in range(4)), *(f"w[{k}]" for k in range(n_cells + 1)),
            "v_b"]


def _limits(n_cells: int) -> tuple[list[str | None], list[str | None]]:
    """The cells' model limits are the mPL's (``mpl.fit.theta_limits``); every other bound
    is a search box."""
    lower, upper = theta_limits(n_cells)
    rest = [None] * (n_cells + 6)
    return lower[:2 * n_cells] + rest, upper[:2 * n_cells] + rest


def canonical(params: mpl_g.MplGParams) -> mpl_g.MplGParams:
    """The output-equivalent parameters with ``w_0 = 1`` and ``V_b = 0``.

    ``z = w_0 z' - V_b`` with ``z' = e + sum (w_k / w_0) u_k``, so ``g'(z') = g(w_0 z' - V_b)``
    gives the same output for every input and state; the inverse's branch maps along (its
    rest point ``z = -V_b`` is ``z' = 0``).

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


def _start_from_mpl(params: mpl.MplParams) -> mpl_g.MplGParams:
    """The mPL as the member of this family with ``g(z) = z``."""
    return mpl_g.MplGParams(i_s=params.i_s, v_t=params.v_t, g=[0.0, 1.0, 0.0, 0.0], w=params.w,
                            v_b=params.v_b)


def fit_mpl_g(u: np.ndarray, y: np.ndarray, structure: mpl_g.MplGStructure, *,
              max_nfev: int = 200, screen_nfev: int = 12, n_polish: int = 2,
              accept: Callable[[mpl_g.MplGParams], bool] | None = None,
              accept_reason: str = "rejected by the acceptance test",
              solver: str = "tr") -> FitResult:
    """Fit the ch. 7 compensator mapping ``u`` to ``y`` by minimising the SSE (eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target, sampled every ``structure.dt``, centred and normalised
        (eq. 5.10) by the caller.
    structure : MplGStructure
    max_nfev, screen_nfev, n_polish : int
        As :func:`hystkit.identification.fit_multistart`.
    accept : callable, optional
        A candidate counts only if ``accept(params)``; ``accept_reason`` says why others failed.
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart`.

    Raises
    ------
    FitDivergedError
        If no start gives a finite cost, or every candidate is vetoed.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_cells
    cap = structure.slope_cap / structure.dt
    lower = np.r_[np.tile([_LOG_G_MIN, _LOG_VT_BOUNDS[0]], n), np.full(4, -_G_BOUND),
                  np.full(n + 2, -_W_BOUND)]
    upper = np.r_[np.tile([np.log(cap), _LOG_VT_BOUNDS[1]], n), np.full(4, _G_BOUND),
                  np.full(n + 2, _W_BOUND)]
    linear = fit_mpl(u, y, mpl.MplStructure(n_cells=n, dt=structure.dt,
                                            slope_cap=structure.slope_cap))
    cache: dict = {}

    def to_params(theta: np.ndarray) -> mpl_g.MplGParams:
        return mpl_g.MplGParams.from_vector(theta, n)

    def run(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # the residual and then the Jacobian at the same point: one sensitivity pass gives both
        key = theta.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = mpl_g.simulate_with_jacobian(structure, to_params(theta), u)
        return cache[key]

    result = fit_multistart(lambda th: run(th)[0] - y, [_start_from_mpl(linear.params)
                                                         .to_vector()],
                            (lower, upper), to_params, structure, jac=lambda th: run(th)[1],
                            solver=solver, max_nfev=max_nfev, screen_nfev=screen_nfev,
                            n_polish=n_polish, accept=accept, accept_reason=accept_reason,
                            names=theta_names(n), limits=_limits(n))
    try:
        return replace(result, params=canonical(result.params))
    except ValueError:  # w_0 = 0, or the canonical form leaves the domain (|w / w_0| > 1e6)
        return result


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


def random_params(structure: mpl_g.MplGStructure, rng: np.random.Generator) -> mpl_g.MplGParams:
    """Parameters from the family's documented domain for normalised data: ``log G_k`` and
    ``log V_T,k`` uniform between the fit's bounds (``G`` in ``[1e-4, slope_cap / dt]``,
    ``V_T`` in ``[1e-3, 1e3]``); an increasing output resistor: ``g_0`` uniform in
    ``[-2, 2]``, ``g_1`` in ``[0.1, 2]``, ``g_3`` log-uniform in ``[0.01, 2]``, ``g_2`` uniform
    within 0.9 of ``+-sqrt(3 g_1 g_3)``; ``|w_0|`` uniform in ``[0.5, 2]`` with a random sign,
    ``w_k / w_0`` uniform in ``[-0.9 / N, 0.9 / N]``; ``V_b`` uniform in ``[-1, 1]``.

    With ``|u| <= 1`` then ``|z| <= 2 |w_0| + 1 <= 5`` and ``|y| <= 2 + 2 |z| + 2.2 z^2 +
    2 |z|^3``; with ``slope_cap <= 1`` the inverse exists for every output and its cells
    contract (see the comment above), so it is bounded too."""
    n = structure.n_cells
    log_g = rng.uniform(_LOG_G_MIN, np.log(structure.slope_cap / structure.dt), n)
    log_vt = rng.uniform(*_LOG_VT_BOUNDS, n)
    g1, g3 = rng.uniform(*_RANDOM_G1), np.exp(rng.uniform(*_RANDOM_LOG_G3))
    g2 = 0.9 * np.sqrt(3 * g1 * g3) * rng.uniform(-1.0, 1.0)
    w0 = rng.uniform(*_RANDOM_W0) * rng.choice([-1.0, 1.0])
    share = _RANDOM_CELL_SHARE / n
    rest = np.r_[rng.uniform(-_RANDOM_G0, _RANDOM_G0), g1, g2, g3, w0,
                 w0 * rng.uniform(-share, share, n), rng.uniform(-_RANDOM_VB, _RANDOM_VB)]
    return mpl_g.MplGParams.from_vector(
        np.r_[np.column_stack([log_g, log_vt]).reshape(-1), rest], n)
