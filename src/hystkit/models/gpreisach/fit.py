"""Identification of the generalised Preisach model (sec. 2.1.2, eq. 2.2).

Like the classical fit (``models/preisach/fit.py``) this is one bounded linear least-squares
problem: the output of eq. 2.2 in the form of ``model.py`` is linear in the cell
masses of ``mu_-`` and ``mu_+`` (columns ``(1 - w) Phi`` and ``w Phi``, ``w = (1 + u) / 2``),
in the Bernstein coefficients of ``nu`` and in the offset. Bounds: hysteretic masses of the
chosen loop orientation's sign, ``nu >= 0`` (a non-decreasing reversible part). The relay
weights are kept off the diagonal: zero-width relays are reversible, and eq. 2.2 gives the
reversible behaviour its own term. Penalty: the smoothness of ``mu_-`` and ``mu_+`` as in the
classical fit, plus the same weight on ``rho_+ - rho_-`` so that the input dependence is
only as strong as the data ask for.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...identification import FitResult, require_linear_loss
from .. import preisach
from .._docs import docfiller
from ..preisach import check_data, fit_oriented, smoothness_rows
from . import model as gpreisach

fill_doc = docfiller()

__all__ = ["SUPPORTED_LOSSES", "fit_gpreisach"]

SUPPORTED_LOSSES = ("linear",)
"""Costs :func:`fit_gpreisach` minimises: the (weighted) SSE only (one linear solve)."""


@fill_doc
def fit_gpreisach(u: np.ndarray, y: np.ndarray, structure: gpreisach.GPreisachStructure, *,
                  accept: Callable[[gpreisach.GPreisachParams], bool] | None = None,
                  accept_reason: str = "rejected by the acceptance test", loss: str = "linear",
                  f_scale: float = 1.0, weights: np.ndarray | None = None) -> FitResult:
    """Fit eq. 2.2 mapping ``u`` to ``y`` by bounded linear least squares (eq. 5.9).

    Parameters
    ----------
    u, y : array, shape (n,)
        Centred, normalised (eq. 5.10) input and target output; the model starts
        demagnetised, as :func:`gpreisach.simulate` does.
    structure : GPreisachStructure
    accept : callable, optional
        Checked on each solution (one per orientation tried), cheapest first.
    accept_reason : str, optional
        Why solutions were rejected, for the message.
    %(linear_loss)s
    %(penalised_weights)s

    Returns
    -------
    FitResult
        The best accepted solution.

    Raises
    ------
    FitDivergedError
        If ``accept`` rejects every solution.
    InputError
        If `loss` is a robust loss.
    """
    require_linear_loss(loss, f_scale, "gpreisach", "linear least squares")
    u, y = check_data(u, y)
    levels, degree = structure.levels, structure.degree
    rows, cols = np.tril_indices(levels - 1)
    off = rows != cols
    u_clip = np.clip(u, -1.0, 1.0)
    beyond = (u - u_clip)[:, None]  # the straight-line extension, linear in every weight
    w = 0.5 * (1.0 + u_clip)[:, None]
    phi = preisach.cell_regressors(levels, u, capacity=structure.capacity)[:, off]
    basis = np.column_stack([b(u_clip) for b in gpreisach.reversible_basis(degree)])
    a = np.column_stack([(1.0 - w) * phi + 0.5 * beyond, w * phi + 0.5 * beyond,
                         basis + 2.0 / (degree + 1) * beyond, np.ones(u.size)])
    n_off = int(off.sum())
    d = smoothness_rows(levels)[:, off]
    d = d[np.any(d != 0, axis=1)]  # diagonal pairs concern no off-diagonal mass
    h = 2.0 / (levels - 1)
    blocks = [np.hstack([d, np.zeros_like(d)]), np.hstack([np.zeros_like(d), d]),
              np.hstack([-np.eye(n_off), np.eye(n_off)]) / h]  # (m+ - m-) / h^2 * area^(1/2)
    penalty = np.vstack(blocks) * np.sqrt(structure.smoothing * u.size)
    penalty = np.hstack([penalty, np.zeros((penalty.shape[0], degree + 2))])
    hysteretic = np.r_[np.ones(2 * n_off, bool), np.zeros(degree + 2, bool)]
    nonneg = np.r_[np.ones(2 * n_off + degree + 1, bool), False]

    def to_params(coef: np.ndarray) -> gpreisach.GPreisachParams:
        tables = []
        for part in (coef[:n_off], coef[n_off: 2 * n_off]):
            masses = np.zeros((levels - 1, levels - 1))
            masses[rows[off], cols[off]] = part
            tables.append(preisach.everett_from_masses(masses))
        return gpreisach.GPreisachParams(everett_minus=tables[0], everett_plus=tables[1],
                                         nu=coef[2 * n_off: -1], offset=coef[-1])

    return fit_oriented(a, y, penalty, hysteretic, nonneg, structure.orientation, to_params,
                        structure, accept, accept_reason, weights)
