"""Polynomial modified Power-Law (mPL) model, sec. 5.3.5 and paper 9.2 of the reference document.

``N`` cells, each a capacitor ``C = 1`` charged through a cubic resistor ``f_k``; a cubic output
resistor ``g`` carries the output current (eq. 5.16-5.17)::

    du_k/dt = f_k(e - u_k),      i = g(w_0 e + sum_k w_k u_k - V_b),
    f_k(v) = c_k0 + c_k1 v + c_k2 v^2 + c_k3 v^3,   g(z) = g_0 + g_1 z + g_2 z^2 + g_3 z^3

integrated with forward Euler (eq. 5.6). The state ``x`` is the vector of cell voltages ``u_k``.

Decisions where the document is ambiguous or wrong, with the evidence, are in
docs/models/mpl_poly.md; in short:

- eq. 5.16's ``f2^2 x^2 + f3^3 x^3`` is the paper's parametrisation, not a typo. The model holds
  the plain cubic coefficients ``c``; ``presets.paper_9_2_params`` converts the paper's printed values (``c2 = f2^2``, ``c3 = f3^3``).
- Per-cell ``f_k`` (eq. 5.17's subscript): with one shared ``f`` all cells would be equal.
  ``5N + 6`` parameters, the paper's 11 for ``N = 1``; only ``4N + 4`` are identifiable.
- ``c_k3 > 0`` is required: only then is the cell stable for large ``|v|`` (paper 9.2, sec.
  II-C relies on it) and do the knees of eq. 5.29 exist on both sides (table II has it).
- Stability limit (eq. 5.29, corrected, ``limit=True``): ``f`` on ``x- <= x <= x+`` and lines of
  slope ``s = slope_cap / dt`` outside, ``f(x+) + s (x - x+)`` and ``f(x-) + s (x - x-)``, with
  ``x-, x+`` the extreme solutions of ``f'(x) = s`` (both at the vertex of ``f'`` if ``f' >= s``
  everywhere). Inside, ``f' <= 0`` is possible: such an equilibrium repels, the state settles
  at an outer stable root and stays bounded; three real roots make the cell bistable.

This module holds the step, its inverse and the runs; the records are in :mod:`.records`, the
resistors in :mod:`.resistors`, rest points and output branches in :mod:`.rest` (every public
name importable from here).
"""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._cells import check_weighted_cells
from .._cubic_output import output_invert_step, output_step
from .._docs import docfiller
from .._run import Runs, family_runs
from .._validation import (
    broadcast_state,
    check_signal,
    check_size,
)
from . import kernels
from .records import (
    C3_RANGE,
    G_MIN,
    POLY_MAX,
    REST_MAX,
    MplPolyParams,
    MplPolyStructure,
)
from .resistors import (
    knee_points,
    output_current,
    output_root,
    output_slope,
    resistor_current,
    resistor_slope,
)
from .rest import (
    check_branch_inverse,
    check_rest,
    equilibria,
    inverse_branch,
    output_bound,
    output_branch,
    rest_state,
    rest_voltages,
)

fill_doc = docfiller("MplPolyStructure", "MplPolyParams", state="x_cells")

__all__ = [
    "C3_RANGE",
    "G_MIN",
    "POLY_MAX",
    "REST_MAX",
    "MplPolyParams",
    "MplPolyStructure",
    "check_rest",
    "equilibria",
    "inverse_branch",
    "invert",
    "invert_step",
    "knee_points",
    "output_bound",
    "output_branch",
    "output_current",
    "output_slope",
    "resistor_current",
    "resistor_slope",
    "rest_state",
    "rest_voltages",
    "simulate",
    "simulate_reference",
    "simulate_with_jacobian",
    "step",
]


@fill_doc
def step(structure: MplPolyStructure, params: MplPolyParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model: output ``y = g(w_0 u + sum w_k x_k - V_b)`` (eq. 5.17)
    from the present state and the model input ``u = e``, then the Euler update of the cell
    voltages over ``dt`` (eq. 5.6 with eq. 5.16).

    %(step)s
    """
    return output_step(structure, params, x, u, output_current, resistor_current)


@fill_doc
def invert_step(structure: MplPolyStructure, params: MplPolyParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse: ``z = g^-1(y)`` on :func:`output_branch`, the input from the
    output equation with the present state (as eq. 5.13), then the state update (fig. 5.12).

    %(invert_step)s
    """
    lo, hi, _ = output_branch(structure, params)
    return output_invert_step(structure, params, x, output_root(params, y, lo, hi),
                              resistor_current)


def _check(structure: MplPolyStructure, params: MplPolyParams, inverse: bool) -> None:
    check_weighted_cells(structure, params, inverse)
    check_rest(structure, params)


def _start(structure: MplPolyStructure, params: MplPolyParams, x0, value: float,
           inverse: bool) -> np.ndarray:
    if x0 is not None:
        return broadcast_state(x0, structure.n_cells)
    if not inverse:
        return rest_state(structure, params, value)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # a w_0 near 0
        x = rest_state(structure, params, value, inverse=True)
    if not np.all(np.isfinite(x)):
        raise FitDivergedError("the inverse's rest state is not finite: the input at rest "
                               "divides by sum(w), which is too small")
    return x


def _kernel_args(structure: MplPolyStructure, params: MplPolyParams) -> tuple:
    return (np.ascontiguousarray(params.f), knee_points(structure, params),
            structure.slope_cap / structure.dt, structure.limit, np.ascontiguousarray(params.g))


def _bound(structure: MplPolyStructure, *arrays: np.ndarray) -> float:
    """Divergence threshold of the forward run. With the limit the cells are provably bounded
    (however large a wild cubic makes them), so only non-finite values count; without it, far
    beyond anything a bounded run on these data reaches."""
    if structure.limit:
        return np.inf
    return 1e6 * (1.0 + max(float(np.max(np.abs(a))) for a in arrays))


def _forward(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    y, x_end, n_bad = kernels.simulate(u, x, *_kernel_args(structure, params), params.w,
                                       params.v_b, structure.dt, _bound(structure, u, x))
    if n_bad >= 0:
        raise FitDivergedError(f"the model diverged at sample {n_bad} of {u.size} (a cell "
                               f"voltage exceeded 1e6 times the input range or overflowed); "
                               f"without the stability limit (eq. 5.29) forward Euler is "
                               f"unstable here")
    return y, x_end  # inputs near 1e308 may still overflow: the finite check follows


def _inverse(structure: MplPolyStructure, params: MplPolyParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lo, hi, sign, centre = inverse_branch(structure, params)
    with np.errstate(over="ignore"):
        bound = min(1e6 * (1.0 + np.max(np.abs(y)) + np.max(np.abs(x))), 1e300)
    e_hat, x_end, n_bad, why = kernels.invert(y, x, *_kernel_args(structure, params), lo, hi,
                                              sign, centre, params.w, params.v_b, structure.dt,
                                              bound)
    check_branch_inverse(why, n_bad, y, lo, hi)
    return e_hat, x_end


RUNS = Runs(label="mpl-poly", step=step, n_state=lambda structure, params: structure.n_cells,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=_check,
            start=_start)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the polynomial mPL model",
    notes="The input is ``e``, the state the cell voltages ``u_k``; at rest ``u_k = e_0 - v*_k`` "
          "with ``v*_k`` from :func:`rest_voltages`. Only without the stability limit "
          "(``limit=False``) can a cell voltage diverge (FitDivergedError). The reference "
          "equals ``simulate`` for bounded runs.",
    inverse_notes="Per sample: ``z = g^-1(y_n)`` on the monotone branch of :func:`output_branch` "
                  "(safeguarded Newton), ``e = (z - sum w_k u_k + V_b) / w_0`` with the present "
                  "state, then the state update. The rest start is ``u_k = e_0 - v*_k`` with "
                  "``e_0 = (z_0 + sum w_k v*_k + V_b) / sum w`` (0 if ``sum w = 0``). "
                  "FitDivergedError if ``w_0 = 0``, ``g' = 0`` at the rest point, a sample lies "
                  "outside the range of ``g``'s monotone branch, or the estimate leaves the "
                  "finite range.")


@fill_doc
def simulate_with_jacobian(structure: MplPolyStructure, params: MplPolyParams, u: np.ndarray,
                           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Forward output and its exact Jacobian ``dy/dtheta``, shape (n, 5N + 6), columns in the
    order of :meth:`MplPolyParams.to_vector`. The rest start (``x0=None``) moves with the
    parameters: ``du_k(0)/dtheta = (df_k/dtheta)(v*) / f'_k(v*)``. Non-finite on divergence.

    Parameters
    ----------
    %(structure)s
    u : numpy.ndarray, shape (n,)
        Model input ``e`` sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial cell voltages, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    jac : numpy.ndarray, shape (n, 5N + 6)
        ``dy/dtheta``.
    """
    check_size(params.n_cells, structure.n_cells, "cells")
    u = check_signal(u, "u")
    try:
        check_rest(structure, params)
    except FitDivergedError:  # a point outside the domain: the fit rejects the step
        return np.full(u.size, np.nan), np.full((u.size, 5 * structure.n_cells + 6), np.nan)
    x = _start(structure, params, x0, u[0], False)
    fc, knees, s, limit, gc = _kernel_args(structure, params)
    sens0 = np.zeros((structure.n_cells, 4))
    if x0 is None:
        v_rest = u[0] - x
        slope = resistor_slope(structure, params, v_rest)
        for k in range(structure.n_cells):
            sens0[k] = kernels.cell_gradient(v_rest[k], fc[k], knees[k, 0], knees[k, 1], s,
                                             limit) / slope[k]
    y, jac, n_bad = kernels.simulate_with_jacobian(u, x, sens0, fc, knees, s, limit, gc,
                                                   params.w, params.v_b, structure.dt,
                                                   _bound(structure, u, x))
    if n_bad >= 0:
        y[:], jac[:] = np.nan, np.nan
    return y, jac
