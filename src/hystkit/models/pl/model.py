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

The state ``x`` is the vector of capacitor voltages ``u_k``. Everything here is pure.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import FitDivergedError
from .._cells import DT_RANGE, MAX_CELLS, SLOPE_CAP_MIN, state_bound
from .._protocol import Record
from .._validation import (
    check_dt,
    check_finite_run,
    check_magnitude,
    check_range,
    check_signal,
    check_slope_cap,
    check_structure_size,
    finite_floats,
    freeze_arrays,
    initial_state,
    run_steps,
)
from . import kernels

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


# Limits and the documented parameter domain (normalised units, eq. 5.10). The fit's box
# (I_T in [1e-6, 1e4], V_T in [1e-3, 2], a_j >= 0.05 with sum a_j = M, |w| <= 100) lies
# inside. A_RANGE is what keeps the output bounded: y = f^-1(u) divides by the slopes a_j, so
# a = 1e-30 turned |u| <= 1 into |y| = 1e29.
MAX_BASIS = 1000
POWER_RANGE = (1.01, 1000.0)
I_T_RANGE = (1e-12, 1e12)
V_T_RANGE = (1e-9, 1e6)
A_RANGE = (1e-3, 1e3)


@dataclass(frozen=True)
class PlStructure(Record):
    """Structural (not least-squares) parameters: N, p, M, S of the exhaustive search, and dt.

    Parameters
    ----------
    n_cells : int
        Cells ``N`` (>= 1).
    power : float
        Exponent ``p`` (> 1) of the cell resistors' middle part, eq. 2.16.
    n_basis : int
        Number ``M`` (>= 1) of PWL basis functions of the output resistor, eq. 2.17.
    smoothing : float
        ``S`` (>= 0): weight of the penalty on slope changes of ``f`` between neighbouring basis
        segments in the weight fit (per sample, relative to the mean squared equation error);
        it has no effect on simulation. Table 5.1 uses 0.001.
    dt : float
        Sample time [s].
    slope_cap : float
        ``G dt`` of the straight branches, the largest Euler slope (< 2, eq. 5.28; 1: no overshoot).

    Notes
    -----
    Limits (checked first, before anything is allocated): ``1 <= n_cells <= 1000``,
    ``1 <= n_basis <= MAX_BASIS`` (1000), ``power`` in ``POWER_RANGE`` (1.01 .. 1000), ``dt``
    in 1e-9 .. 1e6 s, ``slope_cap`` at least 1e-6.
    """

    n_cells: int = 1
    power: float = 21.0
    n_basis: int = 1
    smoothing: float = 0.001
    dt: float = 0.025
    slope_cap: float = 1.0

    def __post_init__(self) -> None:
        check_structure_size(self.n_cells, "n_cells", MAX_CELLS)
        check_structure_size(self.n_basis, "n_basis", MAX_BASIS)
        check_range(self.power, "power p", *POWER_RANGE, " (eq. 2.16 divides by p - 1)")
        if not (np.isfinite(self.smoothing) and self.smoothing >= 0):
            raise ValueError(f"smoothing S must be >= 0, got {self.smoothing!r}")
        check_dt(self.dt)
        check_range(self.dt, "dt", *DT_RANGE, " s")
        check_slope_cap(self.slope_cap)
        check_range(self.slope_cap, "slope_cap", SLOPE_CAP_MIN, 2.0, " (below 2: eq. 5.28)")

    @property
    def n_params(self) -> int:
        """Parameters as table 5.1 counts them: w_0..w_N, V_b, a_1..a_M, I_T, V_T (N + M + 4).

        One of them is redundant: scaling ``w``, ``V_b`` and ``a`` together leaves ``i`` unchanged;
        the fit fixes the mean slope of ``f`` to 1.
        """
        return self.n_cells + self.n_basis + 4


@dataclass(frozen=True, eq=False)
class PlParams(Record):
    """Least-squares parameters of a PL model.

    Parameters
    ----------
    i_t : float
        Current ``I_T`` (> 0) of eq. 2.16 [1/s with C = 1 and normalised voltages].
    v_t : float
        Threshold step ``V_T`` (> 0); cell ``k`` has its threshold at ``k V_T``.
    w : array, shape (N + 1,)
        VCVS weights ``w_0 .. w_N``, eq. 2.18.
    v_b : float
        Bias ``V_b``, eq. 2.18.
    a : array, shape (M,)
        Slopes ``a_j`` (> 0) of the output resistor on its M segments, eq. 2.17.

    Notes
    -----
    Domain (checked here): ``I_T`` in ``I_T_RANGE`` (1e-12 .. 1e12), ``V_T`` in ``V_T_RANGE``
    (1e-9 .. 1e6), ``a_j`` in ``A_RANGE`` (1e-3 .. 1e3), ``|w_k|, |V_b| <= 1e6``, at most 1000
    cells and basis slopes. Every Euler step moves a cell towards its input, so
    ``|y| <= (sum |w| B + |V_b|) / min(a)`` with ``B = max(max|x0|, max|u| max(1,
    slope_cap / (2 - slope_cap)))`` (:func:`output_bound`).
    """

    i_t: float
    v_t: float
    w: np.ndarray
    v_b: float = 0.0
    a: np.ndarray = (1.0,)
    n_cells: int = field(init=False)
    n_basis: int = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_cells", int(np.size(self.w)) - 1)
        object.__setattr__(self, "n_basis", int(np.size(self.a)))
        if self.n_cells < 1 or self.n_basis < 1:
            raise ValueError("w needs N + 1 >= 2 values and a at least one")
        check_structure_size(self.n_cells, "the number of cells (size of w minus 1)", MAX_CELLS)
        check_structure_size(self.n_basis, "the number of basis slopes (size of a)", MAX_BASIS)
        freeze_arrays(self, w=self.n_cells + 1, a=self.n_basis)
        finite_floats(self, "i_t", "v_t", "v_b")
        check_range(self.i_t, "i_t", *I_T_RANGE, " (eq. 2.16)")
        check_range(self.v_t, "v_t", *V_T_RANGE, " (eq. 2.16)")
        check_range(self.a, "a (output resistor slopes)", *A_RANGE,
                    ": y = f^-1(u) divides by them")
        check_magnitude(self.w, "w")
        check_magnitude(self.v_b, "v_b")


def output_bound(structure: PlStructure, params: PlParams, u_max: float,
                 x0_max: float | None = None) -> float:
    """Largest ``|y|`` of a forward run with ``|u| <= u_max`` from ``|x0| <= x0_max``
    (default: at rest, ``x0_max = u_max``); see the Notes of :class:`PlParams`.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    u_max : float
        Largest input magnitude.
    x0_max : float, optional
        Largest initial state magnitude; default `u_max` (a start at rest).

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    b = state_bound(u_max if x0_max is None else x0_max, u_max, structure.slope_cap)
    u = abs(params.w[0]) * u_max + np.abs(params.w[1:]).sum() * b + abs(params.v_b)
    return float(u / np.min(params.a))


def basis_breakpoints(n_basis: int) -> np.ndarray:
    """Breakpoints ``b_0 .. b_M`` of the output basis: M equal segments of [-1, 1], eq. 2.17.

    Parameters
    ----------
    n_basis : int
        Number ``M`` of segments.

    Returns
    -------
    numpy.ndarray, shape (M + 1,)
        The breakpoints, from -1 to 1.
    """
    return np.linspace(-1.0, 1.0, n_basis + 1)


def _cells(structure: PlStructure, params: PlParams) -> tuple[np.ndarray, np.ndarray, float]:
    """Thresholds ``k V_T``, knees (where the power law's slope reaches G) and G."""
    g_lin = structure.slope_cap / structure.dt
    p = structure.power
    thr = params.v_t * np.arange(1, structure.n_cells + 1)
    # d'(v) = p I_T / ((p - 1) thr) (v / thr)^(p - 1) = G  at  v = knee
    with np.errstate(over="ignore"):  # inf for p near 1: the slope never reaches G inside
        knee = thr * (g_lin * (p - 1) * thr / (p * params.i_t)) ** (1.0 / (p - 1))
    return thr, np.minimum(knee, thr), g_lin


def resistor_current(structure: PlStructure, params: PlParams, v: np.ndarray) -> np.ndarray:
    """Cell-resistor currents ``d_k(v)`` (eq. 2.16 with the straight branches).

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    v : array, shape (..., N)
        Voltage across each cell's resistor.

    Returns
    -------
    array, shape (..., N)
    """
    v = np.asarray(v, dtype=float)
    thr, knee, g_lin = _cells(structure, params)
    a = np.abs(v)
    scale = params.i_t / (structure.power - 1)
    inside = scale * (np.minimum(a, knee) / thr) ** structure.power
    return np.sign(v) * (inside + g_lin * np.maximum(a - knee, 0.0))


def resistor_slope(structure: PlStructure, params: PlParams, v: np.ndarray) -> np.ndarray:
    """Slopes ``d'_k(v)``, shape (..., N): ``p I_T / ((p - 1) k V_T) |v / k V_T|^(p - 1)``
    inside the knee, ``G`` on the straight branches (the cells' rates in a linearisation).

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    v : numpy.ndarray, shape (..., N)
        Voltage across each cell's resistor.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        The slopes.
    """
    v = np.asarray(v, dtype=float)
    thr, knee, g_lin = _cells(structure, params)
    p = structure.power
    inside = p * params.i_t / ((p - 1) * thr) * (np.abs(v) / thr) ** (p - 1)
    return np.where(np.abs(v) <= knee, inside, g_lin)

def output_resistor(params: PlParams, i: np.ndarray) -> np.ndarray:
    """``u = f(i) = sum_j a_j phi_j(i)`` (eq. 2.17), shape of ``i``.

    Parameters
    ----------
    params : PlParams
        The model's parameters.
    i : numpy.ndarray
        Output current.

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


def output_resistor_inverse(params: PlParams, u: np.ndarray) -> np.ndarray:
    """``i = f^-1(u)`` (eq. 2.18), exact: ``f`` is PWL and strictly increasing.

    Parameters
    ----------
    params : PlParams
        The model's parameters.
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


def output_resistor_slope(params: PlParams, i: np.ndarray) -> np.ndarray:
    """``f'(i)``: the slope ``a_j`` of the segment holding ``i`` (the left one at a breakpoint
    inside, as the outermost segments extend to infinity).

    Parameters
    ----------
    params : PlParams
        The model's parameters.
    i : numpy.ndarray
        Output current.

    Returns
    -------
    numpy.ndarray
        ``f'(i)``, same shape as `i`.
    """
    i = np.asarray(i, dtype=float)
    seg = np.searchsorted(basis_breakpoints(params.n_basis)[1:-1], i)
    return params.a[seg]


def rest_state(structure: PlStructure, params: PlParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Cells at rest, each equal to the source (``d_k(0) = 0``), shape (N,).

    Forward: the source is the constant input ``value``. Inverse (``value`` a constant output
    current): ``e_0 = (f(value) + V_b) / sum w`` (0 if ``sum w = 0``), the source at which the
    model rests with that output. :func:`simulate` / :func:`invert` start here for ``x0=None``.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    value : float
        Constant input (with `inverse`: output) the model rests at.
    inverse : bool, default False
        Rest state of the inverse: `value` is an output.

    Returns
    -------
    numpy.ndarray
        The state at rest.
    """
    if inverse:
        w_sum = params.w.sum()
        u = float(output_resistor(params, value))
        value = (u + params.v_b) / w_sum if w_sum != 0 else 0.0
    return np.full(structure.n_cells, float(value))

def step(structure: PlStructure, params: PlParams, x: np.ndarray,
         e: float) -> tuple[float, np.ndarray]:
    """One sample: output ``i = f^-1(w_0 e + sum w_k u_k - V_b)`` from the present state
    (eq. 2.18), then the forward-Euler update of the cell voltages.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Capacitor voltages before the sample.
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


def invert_step(structure: PlStructure, params: PlParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse: ``u = f(i)`` (eq. 2.17), ``e = (u + V_b - sum w_k u_k) / w_0``
    from the present state (eq. 2.20), then the cell update driven by ``e``.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Capacitor voltages before the sample.
    y : float
        Output current to reach at this sample.

    Returns
    -------
    u : float
        Input that gives `y` from the present state.
    x_next : numpy.ndarray
        State after the sample.
    """
    x = np.asarray(x, dtype=float)
    e = (float(output_resistor(params, y)) + params.v_b - params.w[1:] @ x) / params.w[0]
    return e, x + resistor_current(structure, params, e - x) * structure.dt

def _check(structure: PlStructure, params: PlParams, u: np.ndarray, name: str) -> np.ndarray:
    if params.n_cells != structure.n_cells or params.n_basis != structure.n_basis:
        raise ValueError(f"params have N = {params.n_cells}, M = {params.n_basis}; the structure "
                         f"has N = {structure.n_cells}, M = {structure.n_basis}")
    return check_signal(u, name)


def kernel_args(structure: PlStructure, params: PlParams) -> tuple:
    """``(I_T, thresholds, knees, p, G, dt)``: the cell arguments of the compiled kernels.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.

    Returns
    -------
    tuple
        ``(I_T, thresholds, knees, p, G, dt)``.
    """
    thr, knee, g_lin = _cells(structure, params)
    return params.i_t, thr, knee, float(structure.power), g_lin, structure.dt


def simulate(structure: PlStructure, params: PlParams, u: np.ndarray,
             x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the forward model (compiled kernel).

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    u : array, shape (n,)
        Source voltage ``e`` every ``structure.dt``.
    x0 : array, shape (N,), float or None
        Initial capacitor voltages; ``None`` starts at rest at the first input (``u_k = e_0``).

    Returns
    -------
    y : array, shape (n,)
        Output current ``i``.
    x_end : array, shape (N,)
        State after the last sample; passing it as ``x0`` continues the run exactly.
    """
    u = _check(structure, params, u, "u")
    x = initial_state(structure.n_cells, x0, u[0])  # = rest_state(..., u[0]) for x0=None
    y, x_end = kernels.simulate(u, x, *kernel_args(structure, params), params.w, params.v_b,
                                basis_breakpoints(structure.n_basis), params.a)
    return check_finite_run(y, "pl"), x_end  # finite in the domain; inputs near 1e308 are not


def simulate_reference(structure: PlStructure, params: PlParams, u: np.ndarray,
                       x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step` (the readable reference).

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Source voltage sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial capacitor voltages, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    u = _check(structure, params, u, "u")
    x = initial_state(structure.n_cells, x0, u[0])
    return run_steps(step, structure, params, u, x)


def states(structure: PlStructure, params: PlParams, u: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Capacitor voltages at every sample, shape (n, N), and the final state (weights unused).

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Source voltage sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial capacitor voltages, as for :func:`simulate`.

    Returns
    -------
    states : numpy.ndarray, shape (n, N)
        Capacitor voltages at every sample.
    x_end : numpy.ndarray, shape (N,)
        Capacitor voltages after the last sample.
    """
    u = _check(structure, params, u, "u")
    x = initial_state(structure.n_cells, x0, u[0])
    return kernels.states(u, x, *kernel_args(structure, params))


def invert(structure: PlStructure, params: PlParams, y: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Analytical inverse (compensator): ``u = f(i)`` (closed form, eq. 2.17), then eq. 2.20
    ``e = (u + V_b - sum w_k u_k) / w_0`` from the present state, then the cell update.

    Parameters
    ----------
    structure : PlStructure
        The model's structure.
    params : PlParams
        Its parameters.
    y : array, shape (n,)
        Output current ``i`` every ``structure.dt``.
    x0 : array, shape (N,), float or None
        Initial capacitor voltages; ``None``: at rest, ``u_k = e_0 = (f(i_0) + V_b) / sum(w)``.

    Returns
    -------
    e_hat : array, shape (n,)
    x_end : array, shape (N,)

    Raises
    ------
    FitDivergedError
        If ``w_0 = 0`` or the inverse leaves the finite range (its cells see the estimate, whose
        feedback through ``-w_k / w_0`` is not stable for every weight set).
    """
    y = _check(structure, params, y, "y")
    if params.w[0] == 0:
        raise FitDivergedError("the model has w_0 = 0, so it has no inverse (eq. 2.20)")
    if x0 is None:
        x = rest_state(structure, params, y[0], inverse=True)
    else:
        x = initial_state(structure.n_cells, x0, 0.0)
    e_hat, x_end, n_bad = kernels.invert(y, x, *kernel_args(structure, params), params.w,
                                         params.v_b, basis_breakpoints(structure.n_basis),
                                         params.a)
    if n_bad >= 0:
        raise FitDivergedError(f"the inverse PL model diverged at sample {n_bad} of {y.size}; "
                               f"the fitted weights make the compensator unstable on this data")
    return e_hat, x_end
