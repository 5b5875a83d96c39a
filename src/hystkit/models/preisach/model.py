"""Classical Preisach model (sec. 2.1.1, eq. 2.1; appendix 9.3-9.5, eq. 9.1-9.13).

Relays ``gamma_ab`` (+1 once ``u >= alpha``, -1 once ``u <= beta``, unchanged in between) fill
the limiting triangle ``T = {-1 <= beta <= alpha <= 1}`` (data normalised to max |.| = 1,
eq. 5.10) with weight ``mu(alpha, beta) >= 0``. With the Everett function
``F(alpha, beta) = integral of mu over T(alpha, beta)`` (eq. 9.6) the output is (eq. 9.11-9.13)::

    y = -F(1, -1) + 2 * sum_{i=1}^{n-1} d_i F(max(s_i-1, s_i), min(s_i-1, s_i)) + y_0

where ``s_0 = -1, s_1, ..., s_n-1 = u(t)`` is the staircase of alternating dominant extrema
(the state) and ``d_i = +1`` on rising, ``-1`` on falling segments. Paired up this is eq. 9.13,
``2 sum_k [F(M_k, m_k-1) - F(M_k, m_k)]`` with ``m_0 = -1``; the last pair is
``2 [F(M_n, m_n-1) - F(M_n, u)]`` for a falling input (9.13 as printed) and ``2 F(u, m_n-1)``
for a rising one (``M_n = u``, and ``F(u, u) = 0``).

Typos of the document, fixed here: eq. 9.3 swaps its labels -- the printed ``f_1`` (ending in
``f_{M_n u} - f_{M_n m_n-1}``) is the *decreasing*-input output -- and its ``f_2`` is garbled;
with eq. 9.4 (``2 F(a, b) = f_a - f_ab``) the increasing-input output is
``-f+ + sum_{k<n} (f_{M_k m_k} - f_{M_k m_k-1}) + f_u - f_{u m_n-1}``. Eq. 9.1 writes
``Gamma mu(t)`` for ``Gamma u(t)``. The classical output is odd between the saturations
(``f- = -f+``); measured data are not, so an output offset ``y_0 = (f+ + f-) / 2`` is added.

Discretisation. ``F`` is stored at the nodes of ``L`` equally spaced levels ``h_i`` (the size
knob), ``E[i, j] = F(h_i, h_j)`` for ``i > j``, and interpolated bilinearly after extending it
antisymmetrically (``F(b, a) := -F(a, b)``), which keeps the interpolant zero on the diagonal:
on a diagonal square it reduces to ``E[i+1, i] (s - t)``. The interpolant is itself the
Everett function of a Preisach weight -- a uniform density of mass
``E[i+1, j] - E[i+1, j+1] - E[i, j] + E[i, j+1]`` on each off-diagonal grid square and mass
``E[i+1, i]`` spread along each diagonal segment (zero-width relays) -- so the output is
continuous, piecewise linear along a branch, and non-negative masses give monotone branches.

Beyond [-1, 1] every relay is saturated; the model continues as the straight line of slope
``F(1, -1)`` (the major loop's mean slope), so compensators do not flatten outside the fitting
range and the inverse exists for every output.

State: the staircase ``x = [-1, s_1, ..., s_n-1]`` (clipped inputs). ``x0=None`` is the
demagnetised state (AC-demagnetised: ``S+ = {alpha + beta < 0}``, drawn as a staircase of
``L - 1`` steps); ``[-1]`` is negative saturation. A new extremum wipes out every earlier one it
reaches. The kernels keep it in a buffer of ``capacity`` entries; when it is about to fill, the
innermost closed loop is forgotten (an output change of twice the weight inside that loop's
rectangle, small because nested loops shrink).

Loop state. The family protocol needs a state of fixed length, so ``FAMILY`` (``family.py``)
and the compiled loop block store the staircase *packed*: ``[n, s_0, .., s_{n-1}, 0, ..]``,
``capacity + 1`` floats (:func:`pack_state`). The functions of this module take and return the
plain staircase.
"""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._docs import docfiller
from .._run import Runs, family_runs
from .._validation import check_size
from . import kernels
from .records import (
    INVERT_TOL,
    MAX_CAPACITY,
    MAX_LEVELS,
    MAX_VALUE,
    MIN_RISE,
    PreisachParams,
    PreisachStructure,
    antisymmetric,
    everett,
    everett_from_masses,
    grid,
    masses_from_everett,
)
from .staircase import (
    check_state,
    demagnetised_state,
    pack_state,
    prepare_run,
    staircase_terms,
    start_staircase,
    unpack_state,
    update_staircase,
)

fill_doc = docfiller("PreisachStructure", "PreisachParams", state="x_staircase")

__all__ = [
    "MAX_CAPACITY",
    "MAX_LEVELS",
    "MAX_VALUE",
    "MIN_RISE",
    "PreisachParams",
    "PreisachStructure",
    "antisymmetric",
    "cell_regressors",
    "check_rise",
    "check_state",
    "demagnetised_state",
    "everett",
    "everett_from_masses",
    "grid",
    "invert",
    "invert_step",
    "kernel_parts",
    "masses_from_everett",
    "output_bound",
    "pack_state",
    "prepare_run",
    "simulate",
    "simulate_reference",
    "staircase_terms",
    "start_staircase",
    "step",
    "unpack_state",
    "update_staircase",
]

def _slope(params: PreisachParams) -> float:
    return float(params.everett[-1, 0])


@fill_doc
def kernel_parts(params: PreisachParams) -> tuple[np.ndarray, bool, np.ndarray, float]:
    """What the compiled kernels run on: tables (1, L, L), weighted (False), output polynomial
    (the offset) and the slope of the straight-line extension.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    tables : numpy.ndarray, shape (1, L, L)
        The antisymmetric Everett table.
    weighted : bool
        False: no input-dependent weight.
    poly : numpy.ndarray, shape (1,)
        The output offset.
    slope : float
        Slope of the straight-line extension.
    """
    return (antisymmetric(params.everett)[None], False, np.array([params.offset]),
            _slope(params))


@fill_doc
def step(structure: PreisachStructure, params: PreisachParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample: update the staircase with the normalised input ``u``, then the output (eq. 9.13
    + extension; ``x_next``: the staircase after the sample).

    %(step)s
    """
    x_next = update_staircase(x, u, structure.capacity)
    u_clip = x_next[-1]
    y = staircase_terms(params.everett, x_next) + params.offset + _slope(params) * (u - u_clip)
    return y, x_next


def _check(structure: PreisachStructure, params: PreisachParams, inverse: bool) -> None:
    check_size(params.levels, structure.levels, "levels")


def _forward(structure: PreisachStructure, params: PreisachParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    tables, weighted, poly, slope = kernel_parts(params)
    return kernels.forward(u, x, tables, weighted, poly, slope, structure.capacity)


def _inverse(structure: PreisachStructure, params: PreisachParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    check_rise(_slope(params), np.abs(params.masses()).sum(), "Preisach")
    tables, weighted, poly, slope = kernel_parts(params)
    return kernels.invert(y, x, tables, weighted, poly, slope, structure.capacity, INVERT_TOL)


RUNS = Runs(label="preisach", step=step, forward=_forward, inverse=_inverse, check=_check,
            start=start_staircase)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the classical Preisach model",
    notes="Amortised O(1) per sample. The state is the staircase, not a vector of floats: "
          "``x0=None`` is the demagnetised state (the first sample moves it to ``u[0]``), "
          "``[-1.0]`` negative saturation; a float is not accepted. Inputs beyond [-1, 1] "
          "follow the straight-line extension.",
    inverse_notes="By monotone search per sample. From the present state the branch ``y(u)`` "
                  "is monotone (non-decreasing in ``u``) when the cell masses are non-negative; "
                  "its side of the present output picks the rising or falling branch and "
                  "bisection on ``u`` in [-1, 1] finds the input closest to the present one (to "
                  "``INVERT_TOL``, then one exact linear step inside the piecewise-linear "
                  "branch). Outputs beyond the saturated ones are inverted on the straight-line "
                  "extension. For weights of mixed sign the branch may fold; bisection still "
                  "returns an input that reproduces the output. FitDivergedError if "
                  "``F(1, -1) <= 0``: the major loop does not rise, so no inverse exists.")


def check_rise(rise: float, mass: float, model: str) -> None:
    """Raise FitDivergedError unless the major loop rises by at least ``MIN_RISE`` of the
    total mass: the inverse continues beyond saturation with slope ``1 / rise``.

    Parameters
    ----------
    rise : float
        Rise of the major loop, ``F(1, -1)``.
    mass : float
        Total absolute mass of the weights.
    model : str
        Model name for the message.

    Raises
    ------
    FitDivergedError
        The major loop does not rise enough.
    """
    if not rise >= MIN_RISE * max(mass, 1e-300):
        raise FitDivergedError(f"the {model} model's major loop does not rise (rise {rise:.4g} "
                               f"for a total mass {mass:.4g}, at least {MIN_RISE:g} of it is "
                               f"needed); it has no inverse")


@fill_doc
def output_bound(params: PreisachParams, u_max: float) -> float:
    """``|y_0| + sum |m| max(1, u_max)``: no output of a run with ``|u| <= u_max`` exceeds it
    (each cell contributes at most ``|m|``; beyond [-1, 1] the line of slope ``F(1, -1)``).

    %(params_bound)s
    """
    return float(abs(params.offset) + np.abs(params.masses()).sum() * max(1.0, u_max))


@fill_doc
def invert_step(structure: PreisachStructure, params: PreisachParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of :func:`invert` from the staircase ``x``: ``(u_hat, x_next)``.

    %(invert_step)s
    """
    u_hat, x_next = invert(structure, params, np.array([float(y)]), x0=x)
    return float(u_hat[0]), x_next


def cell_regressors(levels: int, u: np.ndarray, x0: np.ndarray | None = None,
                    capacity: int = 1024) -> np.ndarray:
    """Relay output of each unit-mass cell: the model is ``Phi @ masses.flat + offset``.

    Columns follow the lower triangle (incl. diagonal) of the (L-1, L-1) mass array in row
    order (``np.tril_indices(L - 1)``); entry ``2 * (fraction of the cell's mass switched
    up) - 1``, computed by the same staircase kernel as the model. Inputs outside [-1, 1]
    are clipped: the straight-line extension is not part of ``Phi``.

    Parameters
    ----------
    levels : int
        Grid levels ``L``.
    u : numpy.ndarray, shape (n,)
        Normalised input.
    x0 : numpy.ndarray, optional
        Initial staircase; None is the demagnetised state.
    capacity : int, default 1024
        Staircase buffer size.

    Returns
    -------
    array, shape (n, L (L - 1) / 2)
    """
    rows, cols = np.tril_indices(levels - 1)
    units = np.zeros((rows.size, levels - 1, levels - 1))
    units[np.arange(rows.size), rows, cols] = 1.0
    tables = np.stack([antisymmetric(everett_from_masses(m)) for m in units])
    x = demagnetised_state(levels - 1) if x0 is None else check_state(x0, capacity)
    phi, _ = kernels.run_tables(np.ascontiguousarray(u, dtype=float), x, tables, capacity)
    return phi
