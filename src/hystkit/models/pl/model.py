"""Power-Law (PL) model of hysteresis and creep as published (Biggio, Oliveri, Stellino, Parodi,
Storace), sec. 2.1.7 of the reference document, eq. 2.16-2.18 and table 5.1.

Sub-circuit (a): ``N`` cells, each a capacitor ``C = 1`` charged from the source ``e`` through a
non-linear resistor ``d_k``; sub-circuit (b): VCVS weights, a bias and a non-linear output
resistor ``u = f(i)``::

    du_k/dt = d_k(e - u_k)                                                  # KCL, C = 1
    d_k(v)  = I_T / (p - 1) sign(v) |v / (k V_T)|^p        for |v| <= k V_T  # eq. 2.16
            = d_k(k V_T) sign(v) + G (|v| - k V_T) sign(v) beyond            # straight branch
    u       = w_0 e + sum_k w_k u_k - V_b                                   # eq. 2.18
    f(i)    = sum_j a_j phi_j(i)                                            # eq. 2.17
    y = i   = f^-1(u)                                                       # model output

Readings of the text (documented in docs/models/pl.md):

* eq. 2.16 writes ``(u_k / k V_t)^p`` with "p odd"; the odd extension ``sign(v) |v|^p`` is used so
  that any real ``p > 1`` (the toolbox's p = 20 of table 5.1 included) gives an odd, increasing
  resistor. The voltage is the resistor's, ``e - u_k`` (eq. 5.5 of the mPL descendant).
* The thresholds ``k V_T`` grow linearly with the cell index (the driving points of fig. 2.17b).
  Outside them the characteristic is "linear": its slope ``G`` is the steepest one forward Euler
  tolerates, ``G = slope_cap / dt`` -- the discrete stand-in for the near-vertical branches of
  the PWL ladder resistor (fig. 2.11), so that a cell driven beyond its threshold follows the
  input within a sample (play-operator hysteresis, eq. 2.11) and creeps inside it.
* Stability (eq. 5.28-5.29 of the mPL, applied here): where the power law's own slope would
  exceed ``G`` (below the threshold, for a large ``I_T``), the straight branch starts earlier, at
  the knee where the slopes are equal. With ``slope_cap <= 1`` each Euler step is monotone and
  contracting, so every ``u_k`` stays within the range of the input and the initial state.
* eq. 2.17 writes ``phi_j(t)``; the basis functions are functions of the current ``i``. They are
  the M "segment ramps" of a uniform partition of [-1, 1] (normalised data, eq. 5.10):
  ``phi_j(i) = clip(i, b_j-1, b_j) - clip(0, b_j-1, b_j)``, the outermost two unbounded. So
  ``f`` is the continuous PWL function through ``f(0) = 0`` whose slope on segment ``j`` is
  ``a_j``; ``a_j > 0`` makes it strictly increasing, and ``f^-1`` exists in closed form.

The state ``x`` is the vector of capacitor voltages ``u_k``. Everything here is pure. The
records (structure, parameters, their domain) are in :mod:`.records` and importable from here.
"""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._docs import ENTRIES, docfiller
from .._run import Runs, family_runs
from .._validation import check_signal
from . import kernels
from .records import (
    A_RANGE,
    I_T_RANGE,
    MAX_BASIS,
    POWER_RANGE,
    V_T_RANGE,
    PlParams,
    PlStructure,
    basis_breakpoints,
    output_bound,
)

# The Parameters section of the output resistor's functions of its current (f and f').
_ENTRIES = {"output_current": "Parameters\n----------\n" + ENTRIES["params"] + """
i : numpy.ndarray
    Output current."""}
fill_doc = docfiller("PlStructure", "PlParams", state="x_capacitors", entries=_ENTRIES)

__all__ = [
    "A_RANGE",
    "I_T_RANGE",
    "MAX_BASIS",
    "POWER_RANGE",
    "V_T_RANGE",
    "PlParams",
    "PlStructure",
    "basis_breakpoints",
    "invert",
    "invert_step",
    "kernel_args",
    "output_bound",
    "output_resistor",
    "output_resistor_inverse",
    "output_resistor_slope",
    "resistor_current",
    "resistor_slope",
    "rest_state",
    "simulate",
    "simulate_reference",
    "states",
    "step",
]


def _cells(structure: PlStructure, params: PlParams) -> tuple[np.ndarray, np.ndarray, float]:
    """Thresholds ``k V_T``, knees (where the power law's slope reaches G) and G."""
    g_lin = structure.slope_cap / structure.dt
    p = structure.power
    thr = params.v_t * np.arange(1, structure.n_cells + 1)
    # d'(v) = p I_T / ((p - 1) thr) (v / thr)^(p - 1) = G  at  v = knee
    with np.errstate(over="ignore"):  # inf for p near 1: the slope never reaches G inside
        knee = thr * (g_lin * (p - 1) * thr / (p * params.i_t)) ** (1.0 / (p - 1))
    return thr, np.minimum(knee, thr), g_lin


@fill_doc
def resistor_current(structure: PlStructure, params: PlParams, v: np.ndarray) -> np.ndarray:
    """Cell-resistor currents ``d_k(v)`` (eq. 2.16 with the straight branches).

    %(cell_voltages)s
    """
    v = np.asarray(v, dtype=float)
    thr, knee, g_lin = _cells(structure, params)
    a = np.abs(v)
    scale = params.i_t / (structure.power - 1)
    inside = scale * (np.minimum(a, knee) / thr) ** structure.power
    return np.sign(v) * (inside + g_lin * np.maximum(a - knee, 0.0))


@fill_doc
def resistor_slope(structure: PlStructure, params: PlParams, v: np.ndarray) -> np.ndarray:
    """Slopes ``d'_k(v)``, shape (..., N): ``p I_T / ((p - 1) k V_T) |v / k V_T|^(p - 1)``
    inside the knee, ``G`` on the straight branches (the cells' rates in a linearisation).

    %(cell_voltages)s
    """
    v = np.asarray(v, dtype=float)
    thr, knee, g_lin = _cells(structure, params)
    p = structure.power
    inside = p * params.i_t / ((p - 1) * thr) * (np.abs(v) / thr) ** (p - 1)
    return np.where(np.abs(v) <= knee, inside, g_lin)

@fill_doc
def output_resistor(params: PlParams, i: np.ndarray) -> np.ndarray:
    """``u = f(i) = sum_j a_j phi_j(i)`` (eq. 2.17), shape of ``i``.

    %(output_current)s

    Returns
    -------
    numpy.ndarray
        ``f(i)``, same shape as `i`.
    """
    i = np.asarray(i, dtype=float)
    brk = basis_breakpoints(params.n_basis)
    lo = np.r_[-np.inf, brk[1:-1]]
    hi = np.r_[brk[1:-1], np.inf]
    phi = np.clip(i[..., None], lo, hi) - np.clip(0.0, lo, hi)
    return phi @ params.a


@fill_doc
def output_resistor_inverse(params: PlParams, u: np.ndarray) -> np.ndarray:
    """``i = f^-1(u)`` (eq. 2.18), exact: ``f`` is PWL and strictly increasing.

    Parameters
    ----------
    %(params)s
    u : numpy.ndarray
        Voltage across the output resistor.

    Returns
    -------
    numpy.ndarray
        ``f^-1(u)``, same shape as `u`.
    """
    u = np.asarray(u, dtype=float)
    if params.n_basis == 1:
        return u / params.a[0]
    knots = basis_breakpoints(params.n_basis)[1:-1]
    f_knots = output_resistor(params, knots)
    seg = np.searchsorted(f_knots, u)  # segment j holds f values between f(b_j-1) and f(b_j)
    ref = np.maximum(seg - 1, 0)  # a knot on segment j: its left end, or b_1 for the first
    return knots[ref] + (u - f_knots[ref]) / params.a[seg]


@fill_doc
def output_resistor_slope(params: PlParams, i: np.ndarray) -> np.ndarray:
    """``f'(i)``: the slope ``a_j`` of the segment holding ``i`` (the left one at a breakpoint
    inside, as the outermost segments extend to infinity).

    %(output_current)s

    Returns
    -------
    numpy.ndarray
        ``f'(i)``, same shape as `i`.
    """
    i = np.asarray(i, dtype=float)
    seg = np.searchsorted(basis_breakpoints(params.n_basis)[1:-1], i)
    return params.a[seg]


@fill_doc
def rest_state(structure: PlStructure, params: PlParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cells at rest, each equal to the source (``d_k(0) = 0``), shape (N,).

    Forward: the source is the constant input ``value``. Inverse (``value`` a constant output
    current): ``e_0 = (f(value) + V_b) / sum w`` (0 if ``sum w = 0``), the source at which the
    model rests with that output. :func:`simulate` / :func:`invert` start here for ``x0=None``.

    %(rest_state)s
    """
    if inverse:
        w_sum = params.w.sum()
        u = float(output_resistor(params, value))
        value = (u + params.v_b) / w_sum if w_sum != 0 else 0.0
    return np.full(structure.n_cells, float(value))

@fill_doc
def step(structure: PlStructure, params: PlParams, x: np.ndarray,
         e: float) -> tuple[float, np.ndarray]:
    """One sample: output ``i = f^-1(w_0 e + sum w_k u_k - V_b)`` from the present state
    (eq. 2.18), then the forward-Euler update of the cell voltages.

    Parameters
    ----------
    %(structure)s
    %(state)s
    e : float
        Source voltage of the sample.

    Returns
    -------
    y : float
    x_next : array, shape (N,)
    """
    x = np.asarray(x, dtype=float)
    u = params.w[0] * e + params.w[1:] @ x - params.v_b
    y = float(output_resistor_inverse(params, u))
    return y, x + resistor_current(structure, params, e - x) * structure.dt


@fill_doc
def invert_step(structure: PlStructure, params: PlParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse: ``u = f(i)`` (eq. 2.17), ``e = (u + V_b - sum w_k u_k) / w_0``
    from the present state (eq. 2.20), then the cell update driven by ``e``.

    Parameters
    ----------
    %(structure)s
    %(state)s
    y : float
        Output current to reach at this sample.

    Returns
    -------
    %(u_step)s
    %(x_next)s
    """
    x = np.asarray(x, dtype=float)
    e = (float(output_resistor(params, y)) + params.v_b - params.w[1:] @ x) / params.w[0]
    return e, x + resistor_current(structure, params, e - x) * structure.dt

def _check(structure: PlStructure, params: PlParams, inverse: bool) -> None:
    if params.n_cells != structure.n_cells or params.n_basis != structure.n_basis:
        raise ValueError(f"params have N = {params.n_cells}, M = {params.n_basis}; the structure "
                         f"has N = {structure.n_cells}, M = {structure.n_basis}")
    if inverse and params.w[0] == 0:
        raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 2.20)")


@fill_doc
def kernel_args(structure: PlStructure, params: PlParams) -> tuple:
    """``(I_T, thresholds, knees, p, G, dt)``: the cell arguments of the compiled kernels.

    %(records_parameters)s

    Returns
    -------
    tuple
        ``(I_T, thresholds, knees, p, G, dt)``.
    """
    thr, knee, g_lin = _cells(structure, params)
    return params.i_t, thr, knee, float(structure.power), g_lin, structure.dt


def _forward(structure: PlStructure, params: PlParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.simulate(u, x, *kernel_args(structure, params), params.w, params.v_b,
                            basis_breakpoints(structure.n_basis), params.a)


def _inverse(structure: PlStructure, params: PlParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e_hat, x_end, n_bad = kernels.invert(y, x, *kernel_args(structure, params), params.w,
                                         params.v_b, basis_breakpoints(structure.n_basis),
                                         params.a)
    if n_bad >= 0:
        raise FitDivergedError(f"the inverse PL model diverged at sample {n_bad} of {y.size}; "
                               f"the fitted weights make the compensator unstable on this data")
    return e_hat, x_end


RUNS = Runs(label="pl", step=step, n_state=lambda structure, params: structure.n_cells,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=_check)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the Power-Law model",
    notes="The input is the source voltage ``e``, the output the current ``i`` and the state "
          "the capacitor voltages ``u_k`` (at rest: ``u_k = e_0``).",
    inverse_notes="``u = f(i)`` (closed form, eq. 2.17), then eq. 2.20 "
                  "``e = (u + V_b - sum w_k u_k) / w_0`` from the present state, then the cell "
                  "update. No inverse exists for ``w_0 = 0``; the cells see the estimate, whose "
                  "feedback through ``-w_k / w_0`` is not stable for every weight set.")


@fill_doc
def states(structure: PlStructure, params: PlParams, u: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Capacitor voltages at every sample, shape (n, N), and the final state (weights unused).

    Parameters
    ----------
    %(structure)s
    %(u_source)s
    %(x0_capacitors)s

    Returns
    -------
    states : numpy.ndarray, shape (n, N)
        Capacitor voltages at every sample.
    %(x_end_capacitors)s
    """
    _check(structure, params, False)
    u = check_signal(u, "u")
    x = RUNS.initial(structure, params, x0, u[0], False)
    return kernels.states(u, x, *kernel_args(structure, params))
