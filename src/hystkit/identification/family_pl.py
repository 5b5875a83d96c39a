"""The Power-Law family as published (sec. 2.1.7, eq. 2.16-2.18) in the model registry, its
weight fit and the exhaustive structural search over N, p, M, S (sec. 2.2, table 5.1).

Fit for a fixed structure. The document (sec. 2.2) obtains the weights by "minimizing the
constrained quadratic cost function" of its ref. [15]. The cost is quadratic because it is
posed on the resistor's voltage side: with the measured current ``y``,
``f(y) = sum a_j phi_j(y)`` must equal ``w_0 e + sum w_k u_k - V_b`` (eq. 2.17-2.18), which is
linear in ``a``, ``w`` and ``V_b`` once the cell voltages ``u_k`` are simulated. Here that
equation error is solved by bounded linear least squares, with

* the scale fixed by a constraint, mean slope of ``f`` on [-1, 1] equal to 1 (``sum a_j = M``),
  because scaling ``a``, ``w`` and ``V_b`` together leaves ``i = f^-1(u)`` unchanged;
* ``a_j >= 0.05`` so that ``f`` stays invertible, ``|w| <= 100`` (sec. 5.3.3's weight bound);
* ``S`` times the squared slope changes ``a_j+1 - a_j`` added per sample (our reading of S).

The two resistor parameters ``I_T`` and ``V_T`` enter non-linearly; ``fit_multistart`` moves
them (log coordinates) with the output error ``f^-1(...) - y`` (eq. 5.9) as its residual, the
weights being re-solved at every evaluation (variable projection). N, p, M and S are not
fitted by least squares: :func:`structural_search` tries every combination of a grid.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict

import numpy as np
from scipy.optimize import lsq_linear

from ..metrics import e_max_pct, e_rms_pct
from ..models import pl
from ._least_squares import check_fit_data, fit_multistart
from ._registry import ModelFamily
from ._result import FitResult

__all__ = ["DEFAULT_GRID", "FAMILY", "fit_pl", "format_search_table", "structural_search"]

_W_BOUND = 100.0
_A_MIN = 0.05
_LOG_VT = (np.log(1e-3), np.log(2.0))  # thresholds beyond N * 2 never matter on [-1, 1] data
_LOG_IT = (np.log(1e-6), np.log(1e4))

#: Default grid of :func:`structural_search` (16 structures, < ~30 s on 8000 samples).
DEFAULT_GRID: dict[str, tuple] = {"n": (1, 2, 5, 10), "p": (5.0, 21.0), "m": (1, 5),
                                  "s": (0.001,)}


def solve_weights(structure: pl.PlStructure, x: np.ndarray, u: np.ndarray,
                  y: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Constrained quadratic fit of ``a``, ``w``, ``V_b`` on the voltage side (see module doc).

    Parameters
    ----------
    x : array, shape (n, N)
        Cell voltages at every sample.
    u, y : array, shape (n,)
        Source voltage and measured output current.

    Returns
    -------
    a : array, shape (M,)
    w : array, shape (N + 1,)
    v_b : float
    """
    n, m = y.size, structure.n_basis
    brk = pl.basis_breakpoints(m)
    lo, hi = np.r_[-np.inf, brk[1:-1]], np.r_[brk[1:-1], np.inf]
    phi = np.clip(y[:, None], lo, hi) - np.clip(0.0, lo, hi)
    # unknowns [a_1..a_M, w_0..w_N, V_b]: phi a - e w_0 - X w + V_b = 0
    rows = [np.column_stack([phi, -u, -x, np.ones(n)])]
    rhs = [np.zeros(n)]
    width = rows[0].shape[1]
    if m > 1 and structure.smoothing > 0:
        diff = np.zeros((m - 1, width))
        diff[np.arange(m - 1), np.arange(m - 1)] = -1.0
        diff[np.arange(m - 1), np.arange(1, m)] = 1.0
        rows.append(np.sqrt(structure.smoothing * n) * diff)
        rhs.append(np.zeros(m - 1))
    # the scale constraint as a heavily weighted row (exact to ~1e-8 relative)
    heavy = 1e4 * np.sqrt(n)
    constraint = np.zeros((1, width))
    constraint[0, :m] = heavy
    rows.append(constraint)
    rhs.append(np.array([heavy * m]))
    lower = np.r_[np.full(m, _A_MIN), np.full(structure.n_cells + 1, -_W_BOUND), -np.inf]
    upper = np.r_[np.full(m, np.inf), np.full(structure.n_cells + 1, _W_BOUND), np.inf]
    sol = lsq_linear(np.vstack(rows), np.concatenate(rhs), bounds=(lower, upper),
                     method="bvls", lsmr_tol=None)
    coef = np.clip(sol.x, lower, upper)
    return coef[:m], coef[m:-1], float(coef[-1])


def default_starts(structure: pl.PlStructure) -> list[np.ndarray]:
    """Starts ``[log I_T, log V_T]``: a coarse grid of the two, thresholds spanning 0.2 to 2 of
    the normalised range (``N V_T``) and cell-1 creep time constants ``V_T / I_T`` of 0.3, 3
    and 30 s (12 starts; the cost has several basins in these two coordinates)."""
    starts = []
    for span in (0.2, 0.5, 1.0, 2.0):
        v_t = span / structure.n_cells
        for tau in (0.3, 3.0, 30.0):
            starts.append(np.log([v_t / tau, v_t]))
    return starts


def fit_pl(u: np.ndarray, y: np.ndarray, structure: pl.PlStructure, *,
           starts: list[np.ndarray] | None = None, max_nfev: int = 40, screen_nfev: int = 4,
           n_polish: int = 2, accept: Callable[[pl.PlParams], bool] | None = None,
           accept_reason: str = "rejected by the acceptance test") -> FitResult:
    """Fit the weights, bias, output resistor and ``I_T``, ``V_T`` for a fixed structure.

    Parameters
    ----------
    u, y : array, shape (n,)
        Centred, normalised data (eq. 5.10) every ``structure.dt``.
    starts : list of arrays ``[log I_T, log V_T]``, optional
        Default :func:`default_starts` (12 starts).
    max_nfev, screen_nfev, n_polish : int
        Passed to ``fit_multistart``.
    accept, accept_reason
        Candidates with ``accept(params)`` false are skipped.

    Raises
    ------
    FitDivergedError
        If no start gives a finite cost or every candidate is vetoed.
    """
    u, y = check_fit_data(u, y)
    cache: dict = {}

    def project(theta: np.ndarray) -> tuple[pl.PlParams, np.ndarray]:
        key = theta.tobytes()
        if key not in cache:
            i_t, v_t = np.exp(theta)
            probe = pl.PlParams(i_t=i_t, v_t=v_t, w=np.zeros(structure.n_cells + 1),
                                a=np.ones(structure.n_basis))
            x, _ = pl.states(structure, probe, u)
            a, w, v_b = solve_weights(structure, x, u, y)
            params = pl.PlParams(i_t=i_t, v_t=v_t, w=w, v_b=v_b, a=a)
            cache.clear()
            cache[key] = params, pl.simulate(structure, params, u)[0] - y
        return cache[key]

    lower = np.array([_LOG_IT[0], _LOG_VT[0]])
    upper = np.array([_LOG_IT[1], _LOG_VT[1]])
    return fit_multistart(lambda th: project(th)[1],
                          default_starts(structure) if starts is None else starts,
                          (lower, upper), lambda th: project(th)[0], structure,
                          max_nfev=max_nfev, screen_nfev=screen_nfev, n_polish=n_polish,
                          accept=accept, accept_reason=accept_reason)


def structural_search(u: np.ndarray, y: np.ndarray, dt: float,
                      grid: Mapping[str, Sequence] | None = None,
                      slope_cap: float = 1.0) -> list[dict]:
    """Exhaustive search over N, p, M, S (sec. 2.2, table 5.1): fit every combination.

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and output every ``dt`` [s]; centred on their means and scaled to
        max |.| = 1 here (eq. 5.10), so the errors are those of eq. 5.11 on normalised data.
    grid : mapping with keys "n", "p", "m", "s", optional
        Values to try for each structural parameter; :data:`DEFAULT_GRID` fills missing keys.

    Returns
    -------
    list of dict
        One row per combination, in grid order: ``n_cells, power, n_basis, smoothing,
        n_params, e_rms_pct, e_max_pct, seconds``, and ``structure`` / ``params`` (dicts).
    """
    grid = {**DEFAULT_GRID, **(grid or {})}
    u = np.asarray(u, dtype=float) - np.mean(u)
    y = np.asarray(y, dtype=float) - np.mean(y)
    u, y = u / np.max(np.abs(u)), y / np.max(np.abs(y))
    rows = []
    for n, p, m, s in itertools.product(grid["n"], grid["p"], grid["m"], grid["s"]):
        structure = pl.PlStructure(n_cells=int(n), power=float(p), n_basis=int(m),
                                   smoothing=float(s), dt=dt, slope_cap=slope_cap)
        t0 = time.perf_counter()
        result = fit_pl(u, y, structure)
        seconds = time.perf_counter() - t0
        y_hat = pl.simulate(structure, result.params, u)[0]
        rows.append({"n_cells": structure.n_cells, "power": structure.power,
                     "n_basis": structure.n_basis, "smoothing": structure.smoothing,
                     "n_params": structure.n_params, "e_rms_pct": e_rms_pct(y, y_hat, 1.0),
                     "e_max_pct": e_max_pct(y, y_hat, 1.0), "seconds": seconds,
                     "structure": asdict(structure),
                     "params": result.params.to_dict()})
    return rows


def format_search_table(rows: Sequence[dict], best_only_per_n: bool = False) -> str:
    """The search result laid out like table 5.1 (one line per structure, or the best per N)."""
    if best_only_per_n:
        best: dict[int, dict] = {}
        for r in rows:
            if r["n_cells"] not in best or r["e_rms_pct"] < best[r["n_cells"]]["e_rms_pct"]:
                best[r["n_cells"]] = r
        rows = [best[n] for n in sorted(best)]
    head = (f"{'Model':<10} {'Cells (N)':>9} {'No. pars':>8} {'e_rms %':>8} {'e_max %':>8} "
            f"{'M':>3} {'S':>7} {'p':>5} {'fit s':>6}")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(f"{'Power-Law':<10} {r['n_cells']:>9d} {r['n_params']:>8d} "
                     f"{r['e_rms_pct']:>8.3f} {r['e_max_pct']:>8.3f} {r['n_basis']:>3d} "
                     f"{r['smoothing']:>7g} {r['power']:>5g} {r['seconds']:>6.2f}")
    return "\n".join(lines)


def _make_structure(dt: float, size: int, power: float = 21.0, n_basis: int = 1,
                    smoothing: float = 0.001, slope_cap: float = 1.0) -> pl.PlStructure:
    return pl.PlStructure(n_cells=size, power=power, n_basis=n_basis, smoothing=smoothing,
                          dt=dt, slope_cap=slope_cap)


FAMILY = ModelFamily(
    name="pl", title="Power-Law model as published, Biggio et al. (sec. 2.1.7, eq. 2.16-2.18)",
    structure_type=pl.PlStructure, params_type=pl.PlParams, make_structure=_make_structure,
    simulate=pl.simulate, fit=fit_pl, invert=pl.invert,
    size_help="cells N (N + M + 4 params; p, M, S via options or 'hystkit pl-search')",
    default_size=1)
