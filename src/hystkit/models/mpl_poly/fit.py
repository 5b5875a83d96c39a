"""Least-squares identification of the polynomial mPL (sec. 5.3.5, paper 9.2).

The paper ran MATLAB's patternsearch for 60 s from table I's start. Here the same SSE (eq. 5.9)
goes to the shared multi-start trust-region least squares with exact normal equations
``J^T J``, ``J^T r`` accumulated in one pass of the forward sensitivities through the Euler
recursion and the limited cubic (``kernels.normal_equations``), from deterministic starts:
table I of paper 9.2 as printed, and six "linear-output" starts whose cells are sinh-like
cubics with time constants spread over decades and whose weights come from linear least
squares (with ``g(z) = z`` the output is linear in ``w`` and ``V_b``).

Only 4N + 4 of the 5N + 6 parameters are identifiable (:func:`canonical`). The solver
works on all of them, as the paper did (trust-region steps are well defined on the rank-
deficient Jacobian, and on the virtual sensor this took fewer evaluations than optimising in
the gauge ``c_k0 = 0, w_0 = 1, V_b = 0``), and the result is mapped to the canonical
representative, so a fitted model file is reproducible rather than one arbitrary point of an
(N + 2)-dimensional valley of equivalent parameters. A fit whose ``w_0`` is exactly 0 (no
canonical form) is returned as found.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ...errors import FitDivergedError
from ...identification import FitResult, NormalEquations, check_fit_data, fit_multistart
from .._docs import docfiller
from ..mpl.box import W_BOUND
from . import kernels
from . import model as mpl_poly
from .presets import PAPER_9_2_TABLE_I, paper_9_2_params

fill_doc = docfiller("mpl_poly.MplPolyStructure")

__all__ = ["canonical", "default_starts", "fit_box", "fit_mpl_poly", "random_params",
           "theta_names"]

# Bounds in optimiser coordinates (MplPolyParams.to_vector): the weights' are the mPL's
# (mpl.box); the polynomial coefficients only need to stay finite.
_COEF_BOUND = 1e3
_LOG_C3_BOUNDS = (np.log(1e-6), np.log(1e4))


def theta_names(n_cells: int) -> list[str]:
    """Names of the optimiser coordinates (:meth:`MplPolyParams.to_vector`), cells from 1.

    No bound of this fit is a model limit: the Euler slope cap acts through the limited
    resistor's knees (eq. 5.29), not through a bound, so every bound hit is a search box hit.
    That includes ``log c_k3`` at its floor: over the training data the cubic term is then
    negligible, but it is what keeps the resistor increasing for large voltages; without it
    (fitted on the virtual noise run: ``f = 5.9 v + 0.38 v^2``) the ch. 7 loop, linearly
    stable, ran away within 0.5 s.
    """
    cells = [f"f[{k}].{c}" for k in range(1, n_cells + 1) for c in ("c0", "c1", "c2", "log_c3")]
    return [*cells, *(f"g.c{j}" for j in range(4)), *(f"w[{k}]" for k in range(n_cells + 1)),
            "v_b"]


@fill_doc
def fit_box(structure: mpl_poly.MplPolyStructure) -> tuple[np.ndarray, np.ndarray]:
    """The fit's bounds in optimiser coordinates (:meth:`MplPolyParams.to_vector`):
    ``c_k0..c_k2`` and ``g`` in ``[-1e3, 1e3]``, ``log c_k3`` in ``[log 1e-6, log 1e4]``,
    ``w`` and ``V_b`` in ``[-100, 100]``.

    %(structure_parameters)s

    Returns
    -------
    lower, upper : numpy.ndarray, shape (5N + 6,)
    """
    n = structure.n_cells
    lower = np.r_[np.tile([-_COEF_BOUND] * 3 + [_LOG_C3_BOUNDS[0]], n),
                  np.full(4, -_COEF_BOUND), np.full(n + 2, -W_BOUND)]
    upper = np.r_[np.tile([_COEF_BOUND] * 3 + [_LOG_C3_BOUNDS[1]], n),
                  np.full(4, _COEF_BOUND), np.full(n + 2, W_BOUND)]
    return lower, upper


def canonical(structure: mpl_poly.MplPolyStructure,
              params: mpl_poly.MplPolyParams) -> mpl_poly.MplPolyParams:
    """The output-equivalent parameters whose cells rest at ``v* = 0``, with ``w_0 = 1`` and
    ``V_b = 0``.

    The 5N + 6 parameters are not all identifiable: shifting a cell's voltage
    (``u_k -> u_k - gamma_k``, ``f_k(v) -> f_k(v - gamma_k)``; knees and rest points move
    along) and an affine change of the output resistor's voltage (``z -> alpha z + beta``,
    ``g`` re-expanded, ``w``, ``V_b`` rescaled) leave every input-output map, forward and
    inverse, unchanged. Fixing these N + 2 directions leaves 4N + 4 identifiable parameters
    (8 of the paper's 11 for N = 1). The representative chosen: every cell's rest voltage
    (``mpl_poly.rest_voltages``) moved to 0, so that at rest ``u_k = e`` as in the sinh mPL
    (then ``c_k0 = 0`` unless the rest point lies on a straight continuation), then
    ``w_0 = 1``, ``V_b = 0``.

    Parameters
    ----------
    structure : mpl_poly.MplPolyStructure
        The model's structure.
    params : mpl_poly.MplPolyParams
        Parameters to bring to canonical form.

    Returns
    -------
    mpl_poly.MplPolyParams
        The equivalent canonical parameters.

    Raises
    ------
    ValueError
        If ``w_0 = 0`` (no scale to fix it with).
    """
    if params.w[0] == 0:
        raise ValueError("w_0 = 0: the canonical form fixes w_0 = 1")
    shift = mpl_poly.rest_voltages(structure, params)
    f = np.array([_compose(c, [r, 1.0]) for c, r in zip(params.f, shift, strict=True)])
    knees = mpl_poly.knee_points(structure, params)
    on_cubic = np.logical_or(not structure.limit, (knees[:, 0] < shift) & (shift < knees[:, 1]))
    f[on_cubic, 0] = 0.0  # exactly, not to rounding
    v_b = params.v_b + params.w[1:] @ shift
    return mpl_poly.MplPolyParams(f=f, g=_compose(params.g, [-v_b, params.w[0]]),
                                  w=params.w / params.w[0], v_b=0.0)


def _compose(c: np.ndarray, inner: list[float]) -> np.ndarray:
    """Coefficients of ``p(inner(x))`` for the cubic ``p`` and a linear ``inner``."""
    coef = np.polynomial.Polynomial(c)(np.polynomial.Polynomial(inner)).coef
    return np.pad(coef, (0, 4 - coef.size))


def _table_i_start(n_cells: int) -> mpl_poly.MplPolyParams:
    """Paper 9.2's table I start; extra cells copy its resistor with zero weight."""
    p = paper_9_2_params(PAPER_9_2_TABLE_I)
    return mpl_poly.MplPolyParams(f=np.repeat(p.f, n_cells, axis=0), g=p.g,
                                  w=np.r_[p.w, np.zeros(n_cells - 1)], v_b=p.v_b)


@fill_doc
def default_starts(structure: mpl_poly.MplPolyStructure) -> list[np.ndarray]:
    """Deterministic cell resistors ``f_k`` (shape (N, 4) each) for the linear-output starts.

    ``f_k(v) = G_k (v + v^3 / (6 V^2))``, the cubic Taylor polynomial of the sinh mPL's
    resistor: rates ``G_k`` at geometric spreads around 0.3, 3 and 30 % of the Euler cap, a
    strongly (``V = 0.2``, the document's ``V_T`` start) and a mildly (``V = 2``) non-linear
    shape, for data normalised to max |.| = 1 (eq. 5.10).

    %(structure_parameters)s

    Returns
    -------
    list of numpy.ndarray
        Cell resistor coefficients, each of shape (N, 4).
    """
    g_max = structure.slope_cap / structure.dt
    k = np.arange(structure.n_cells)
    starts = []
    for v in (0.2, 2.0):
        for frac in (0.003, 0.03, 0.3):
            rate = np.minimum(g_max * frac * 6.0 ** (k - (structure.n_cells - 1) / 2),
                              0.9 * g_max)
            z = np.zeros_like(rate)
            starts.append(np.column_stack([z, rate, z, rate / (6 * v * v)]))
    return starts


def _linear_output_start(structure: mpl_poly.MplPolyStructure, f: np.ndarray, u: np.ndarray,
                         y: np.ndarray) -> mpl_poly.MplPolyParams | None:
    """Given the cell resistors and ``g(z) = z``: weights and bias by linear least squares.
    None if the cells diverge on ``u`` (possible only without the limit).

    With ``w = 0``, ``V_b = 0`` the output is ``g(0) = 0``, so ``r = -y``, and as ``g' = 1`` the
    columns of ``w_0..w_N``, ``V_b`` are ``[u, x_1..x_N, -1]``: their block of the normal
    equations gives ``coef = -(J_l^T J_l)^+ J_l^T r``.
    """
    n = structure.n_cells
    probe = mpl_poly.MplPolyParams(f=f, g=[0.0, 1.0, 0.0, 0.0], w=np.zeros(n + 1))
    ne = normal_equations(structure, probe, u, y)
    if not np.isfinite(ne.cost):
        return None
    lin = slice(4 * n + 4, None)
    coef = -np.linalg.lstsq(ne.jtj[lin, lin], ne.jtr[lin], rcond=None)[0]
    coef[:-1] = np.clip(coef[:-1], -0.9 * W_BOUND, 0.9 * W_BOUND)
    return mpl_poly.MplPolyParams(f=f, g=probe.g, w=coef[:-1], v_b=coef[-1])


def normal_equations(structure: mpl_poly.MplPolyStructure, params: mpl_poly.MplPolyParams,
                     u: np.ndarray, y: np.ndarray) -> NormalEquations:
    """Cost ``0.5 SSE``, ``J^T J`` and ``J^T r`` of the run from rest, in one pass.

    As :func:`mpl_poly.simulate_with_jacobian` (the rest start moves with the parameters)
    without the ``n x (5N + 6)`` Jacobian; infinite cost outside the domain or on divergence.
    """
    p = 5 * structure.n_cells + 6
    try:
        mpl_poly.check_rest(structure, params)
    except FitDivergedError:
        return NormalEquations(np.inf, np.full((p, p), np.nan), np.full(p, np.nan))
    x = mpl_poly.rest_state(structure, params, u[0])
    fc, knees, s, limit, gc = mpl_poly._kernel_args(structure, params)
    slope = mpl_poly.resistor_slope(structure, params, u[0] - x)
    sens0 = np.array([kernels.cell_gradient(u[0] - x[k], fc[k], knees[k, 0], knees[k, 1], s,
                                            limit) / slope[k] for k in range(structure.n_cells)])
    sse, jtj, jtr, n_bad = kernels.normal_equations(
        u, y, x, sens0, fc, knees, s, limit, gc, params.w,
        params.v_b, structure.dt, mpl_poly._bound(structure, u, x))
    if n_bad >= 0:
        return NormalEquations(np.inf, np.full((p, p), np.nan), np.full(p, np.nan))
    return NormalEquations(0.5 * sse, jtj, jtr)


@fill_doc
def fit_mpl_poly(u: np.ndarray, y: np.ndarray, structure: mpl_poly.MplPolyStructure, *,
                 max_nfev: int = 200, screen_nfev: int = 12, n_polish: int = 2,
                 accept: Callable[[mpl_poly.MplPolyParams], bool] | None = None,
                 accept_reason: str = "rejected by the acceptance test",
                 solver: str = "tr", loss: str = "linear", f_scale: float = 1.0,
                 weights: np.ndarray | None = None,
                 init: mpl_poly.MplPolyParams | None = None) -> FitResult:
    """Fit a polynomial mPL mapping ``u`` to ``y`` by minimising the SSE (eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and target, sampled every ``structure.dt``, centred and normalised
        (eq. 5.10) by the caller.
    structure : MplPolyStructure
        With ``limit=False`` trial points whose run diverges are rejected by the solver.
    %(multistart)s
    solver : {"tr", "lm", "trf"}
        See :func:`hystkit.identification.fit_multistart` ("trf" works on the dense Jacobian).
    loss, f_scale, weights
        The cost minimised: the SSE by default, or a robust loss and/or per-sample weights
        (one per sample of ``y``); see :func:`hystkit.identification.fit_multistart`.
    init : MplPolyParams, optional
        Start from exactly these parameters and from them only (paper 9.2 started its
        patternsearch from table I: the preset ``paper-9.2-table-i``); clipped into
        :func:`fit_box`.

    %(best_start)s

    Raises
    ------
    ValueError
        If `init` has another number of cells.
    FitDivergedError
        If no start runs without diverging, none gives a finite cost, or all are vetoed.
    """
    u, y = check_fit_data(u, y)
    n = structure.n_cells
    lower, upper = fit_box(structure)
    cache: dict = {}

    def to_params(theta: np.ndarray) -> mpl_poly.MplPolyParams:
        return mpl_poly.MplPolyParams.from_vector(theta, n)

    def run(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # solver="trf": least_squares asks for the residual and then the Jacobian at the same
        # point: the sensitivity kernel yields both in one pass. A diverged run is all NaN,
        # which the trust-region solver treats as a rejected step.
        key = theta.tobytes()
        if key not in cache:
            cache.clear()
            try:
                cache[key] = mpl_poly.simulate_with_jacobian(structure, to_params(theta), u)
            except ValueError:  # outside the parameter domain (a rest point beyond REST_MAX)
                cache[key] = (np.full(u.size, np.nan), np.full((u.size, theta.size), np.nan))
        return cache[key]

    def one_pass(theta: np.ndarray) -> NormalEquations:
        try:
            params = to_params(theta)
        except ValueError:  # outside the parameter domain (a rest point beyond REST_MAX)
            p = theta.size
            return NormalEquations(np.inf, np.full((p, p), np.nan), np.full(p, np.nan))
        return normal_equations(structure, params, u, y)

    if init is not None:
        if init.n_cells != n:
            raise ValueError(f"init has {init.n_cells} cell(s), the structure {n}")
        candidates = [init]
    else:
        candidates = [_table_i_start(n)] + [_linear_output_start(structure, f, u, y)
                                            for f in default_starts(structure)]
    # the solver needs a finite cost at each start
    thetas = [p.to_vector() for p in candidates
              if p is not None and np.isfinite(one_pass(p.to_vector()).cost)]
    if not thetas:
        raise FitDivergedError(f"the fit failed: the model diverges on the training data from "
                               f"{'the given start' if init is not None else 'every start'} "
                               f"(use the stability limit)")
    result = fit_multistart(lambda th: run(th)[0] - y, thetas, (lower, upper), to_params,
                            structure, jac=lambda th: run(th)[1], normal_equations=one_pass,
                            solver=solver, max_nfev=max_nfev, screen_nfev=screen_nfev,
                            n_polish=n_polish, accept=accept, accept_reason=accept_reason,
                            names=theta_names(n), loss=loss, f_scale=f_scale,
                            weights=weights)
    # the (N + 2)-dimensional valley of equivalent parameters (see the module docstring)
    if result.params.w[0] == 0:
        return result
    try:
        return replace(result, params=canonical(structure, result.params))
    except ValueError:  # its canonical form leaves the domain (|w / w_0| > 1e6, say)
        return result



# The domain random_params draws from: the fit's box above is a search box (no bound is a model
# limit), and at its corners the cells rest ~1e8 away from the data (c3 = 1e-6 with |c2| = 1e3
# puts the inflection point at -c2 / (3 c3) ~ 3e8), so outputs reach 1e58: finite but
# meaningless for normalised data. Paper 9.2's published sets (tables I, II; N = 1) have
# |f0..f2| <= 5, 5e-7 <= c3 <= 31, |g| <= 1.4, |w| <= 1.6, |V_b| <= 0.6; the domain is
# that range with margin, c3 >= 0.1 keeping the rest points within a few units of 0.
_RANDOM_F = 5.0
_RANDOM_LOG_C3 = (np.log(0.1), np.log(100.0))
_RANDOM_G = 2.0
_RANDOM_W = 2.0
_RANDOM_VB = 1.0


def random_params(structure: mpl_poly.MplPolyStructure,
                  rng: np.random.Generator) -> mpl_poly.MplPolyParams:
    """Parameters from the family's documented domain for normalised data (the range of paper
    9.2's published sets with margin): ``c_k0..c_k2`` uniform in ``[-5, 5]``, ``c_k3``
    log-uniform in ``[0.1, 100]``, ``g_0..g_3`` and ``w_0..w_N`` uniform in ``[-2, 2]``, ``V_b``
    uniform in ``[-1, 1]``. Narrower than the fit's search box: see ``_RANDOM_F``."""
    n = structure.n_cells
    cells = np.column_stack([rng.uniform(-_RANDOM_F, _RANDOM_F, (n, 3)),
                             rng.uniform(*_RANDOM_LOG_C3, n)])
    rest = np.r_[rng.uniform(-_RANDOM_G, _RANDOM_G, 4),
                 rng.uniform(-_RANDOM_W, _RANDOM_W, n + 1),
                 rng.uniform(-_RANDOM_VB, _RANDOM_VB)]
    return mpl_poly.MplPolyParams.from_vector(np.r_[cells.reshape(-1), rest], n)
