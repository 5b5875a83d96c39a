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


# The domain random_params draws from: the mPL's cells over the fit's box, and paper 9.2's range
# of the output stage with margin (its sets have |g| <= 1.4, |w| <= 1.6, |V_b| <= 0.6, as the
# mpl-poly family's domain). The mPL's |w| <= 100 box would put z near 200 and g(z) near 1e9.
_RANDOM_G = 2.0
_RANDOM_W = 2.0
_RANDOM_VB = 1.0


def random_params(structure: mpl_g.MplGStructure, rng: np.random.Generator) -> mpl_g.MplGParams:
    """Parameters from the family's documented domain for normalised data: ``log G_k`` and
    ``log V_T,k`` uniform between the fit's bounds (``G`` in ``[1e-4, slope_cap / dt]``,
    ``V_T`` in ``[1e-3, 1e3]``), ``g_0..g_3`` and ``w_0..w_N`` uniform in ``[-2, 2]``, ``V_b``
    uniform in ``[-1, 1]``. With ``|u| <= 1`` then ``|z| <= 2 (N + 1) + 1`` and
    ``|y| <= 2 (1 + |z| + z^2 + |z|^3)``."""
    n = structure.n_cells
    log_g = rng.uniform(_LOG_G_MIN, np.log(structure.slope_cap / structure.dt), n)
    log_vt = rng.uniform(*_LOG_VT_BOUNDS, n)
    rest = np.r_[rng.uniform(-_RANDOM_G, _RANDOM_G, 4), rng.uniform(-_RANDOM_W, _RANDOM_W, n + 1),
                 rng.uniform(-_RANDOM_VB, _RANDOM_VB)]
    return mpl_g.MplGParams.from_vector(
        np.r_[np.column_stack([log_g, log_vt]).reshape(-1), rest], n)
