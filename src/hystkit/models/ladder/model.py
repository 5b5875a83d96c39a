"""PWL ladder circuit of Parodi, Storace and Cincotti, sec. 2.1.5 (fig. 2.10-2.11).

The electrical transfer of the Bobbio-Marrucci chain (sec. 2.1.4): spring forces become
capacitor voltages, pistons become piecewise-linear resistors whose dead band plays the
friction threshold. Circuit: the source ``e`` (input) drives a ladder of ``N`` sections; section
``k`` is a PWL resistor ``R_k`` from node ``k-1`` to node ``k`` (node 0 is the source) and a
linear capacitor ``C = 1`` from node ``k`` to ground. With ``U_k`` the capacitor voltages::

    i_k     = G_k d_k(U_k-1 - U_k),     d_k(v) = sign(v) max(|v| - E_k, 0)       (fig. 2.11)
    dU_k/dt = i_k - i_k+1,              U_0 = e,  i_N+1 = 0
    y       = w_0 e + sum_k w_k U_k - V_b

Each resistor passes no current while ``|U_k-1 - U_k| <= E_k``: eq. 2.5 with ``U_k`` as the
"forcing variables". For inputs slow compared with the resistors' time constants every node
follows the play operator of the one before, ``U_k = H_{E_k}[U_k-1]`` (eq. 2.11), and the
circuit becomes the rate-independent Bobbio-Marrucci chain with ``a_k = E_k`` (the document's
table 2.1 lists the ladder as rate-independent); faster inputs add a lag, rate dependence. The read-out is the
one of the Power-Law circuit that descends from this ladder (eq. 2.18, VCVS weights and bias)
with the linear output resistor ``R = 1`` of the mPL (eq. 5.2), so ``y`` is the current through
it; the document does not give the 1994 circuit's read-out. ``C = 1`` as in the mPL, since only
``G / C`` matters once the weights are free.

Discretisation: forward Euler at ``dt``, output from the present state first, then the update
(as the mPL, fig. 5.12). Stability limit in the spirit of eq. 5.28-5.29: a node's Euler slope
is ``1 - dt (G_k + G_k+1)`` where both resistors conduct, so each conductance is limited to
``slope_cap / (2 dt)`` (the straight PWL branches simply get the capped slope). With
``slope_cap <= 1`` the step is monotone in every node voltage, so all ``U_k`` stay between the
extremes of the input and the initial state for any parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import FitDivergedError
from .._cells import CellStructure
from .._docs import docfiller
from .._protocol import Record
from .._run import Runs, family_runs
from .._validation import (
    check_signal,
    check_size,
    finite_floats,
    freeze_arrays,
)
from . import kernels

fill_doc = docfiller("LadderStructure", "LadderParams", state="x_capacitors")

__all__ = [
    "MAX_CELLS",
    "MAX_VALUE",
    "LadderParams",
    "LadderStructure",
    "conductance_limit",
    "effective_conductance",
    "invert",
    "invert_step",
    "output_bound",
    "rest_state",
    "simulate",
    "simulate_reference",
    "states",
    "step",
]


MAX_CELLS = 1000  # simulate and fit hold n x N voltages: 8 kB a sample at the cap
MAX_VALUE = 1e6  # bands, |w|, |V_b| in normalised units (fit: bands <= 1.5, |w| <= 100)


@dataclass(frozen=True)
class LadderStructure(CellStructure):
    """What does not get fitted (:class:`~hystkit.models._cells.CellStructure`): ``n_cells``
    ladder sections, each a PWL resistor and a capacitor; the slope cap bounds the Euler slope
    ``dt (G_k + G_k+1)`` at a node.

    ``1 <= n_cells <= MAX_CELLS`` (1000: ``simulate`` and the fit hold every sample's node
    voltages, 8 kB a sample, 8 GB a million samples, at the cap) and ``0 < slope_cap <= 1``:
    the step matrix ``I - dt L`` (``L`` the ladder's conductance Laplacian) has eigenvalues
    down to ``1 - 2 slope_cap``, so beyond 1 a long ladder of conducting resistors oscillates
    and diverges (2 sections from 1.53, 5 from about 1.3), unlike one mPL cell.

    Parameters
    ----------
    n_cells : int, default 2
        Ladder sections ``N``.
    dt : float, default 0.025
        Sample time [s].
    slope_cap : float, default 1.0
        Largest Euler slope ``dt (G_k + G_k+1)`` at a node.
    """

    n_cells: int = 2

    def __post_init__(self) -> None:
        # the cap first: nothing is allocated or looped over before it holds (inf, 1e12)
        if not (isinstance(self.n_cells, int | float) and self.n_cells <= MAX_CELLS):
            raise ValueError(f"n_cells must be an integer in [1, {MAX_CELLS}], got "
                             f"{self.n_cells!r}")
        super().__post_init__()
        if self.slope_cap > 1:
            raise ValueError(f"slope_cap must lie in (0, 1] for the ladder (a node couples two "
                             f"resistors; beyond 1 the Euler step diverges), got "
                             f"{self.slope_cap!r}")

    @property
    def n_params(self) -> int:
        return 3 * self.n_cells + 2


@dataclass(frozen=True, eq=False)
class LadderParams(Record):
    """Resistor characteristics and read-out weights.

    Parameters
    ----------
    band : array, shape (N,)
        Dead-band half-width ``E_k`` of each resistor (>= 0) [input units].
    conductance : array, shape (N,)
        Slope ``G_k`` of the straight branches (> 0) [1/s, with C = 1].
    w : array, shape (N + 1,)
        Read-out weights ``w_0 .. w_N`` (eq. 2.18).
    v_b : float
        Bias ``V_b`` (eq. 2.18).

    Notes
    -----
    Domain: ``0 <= E_k <= MAX_VALUE``, ``G_k > 0`` (any: the step uses it limited to
    :func:`conductance_limit`), ``|w_k|, |V_b| <= MAX_VALUE`` (1e6, normalised units; the
    fit's are at most 1.5 and 100). With ``slope_cap <= 1`` every node voltage stays within
    the extremes of the input and the initial state, so
    ``|y| <= sum |w| max(|u|, |x0|) + |V_b|`` (:func:`output_bound`). The inverse divides by
    ``w_0`` and its stability depends on the weights: it returns finite values or raises
    ``FitDivergedError``.
    """

    band: np.ndarray
    conductance: np.ndarray
    w: np.ndarray
    v_b: float = 0.0
    n_cells: int = field(init=False)

    def __post_init__(self) -> None:
        n = np.size(self.band)
        object.__setattr__(self, "n_cells", int(n))
        freeze_arrays(self, band=n, conductance=n, w=n + 1)
        finite_floats(self, "v_b")
        if np.any(self.band < 0):
            raise ValueError("band (resistor dead band E_k) must be >= 0")
        if np.any(self.conductance <= 0):
            raise ValueError("conductance must be positive")
        for name, values in (("band", self.band), ("w", np.abs(self.w)),
                             ("v_b", np.abs(self.v_b))):
            if np.any(values > MAX_VALUE):
                raise ValueError(f"{name} must be at most {MAX_VALUE:g} in magnitude (the "
                                 f"domain where runs stay bounded), got "
                                 f"{float(np.max(values)):g}")


def output_bound(params: LadderParams, u_max: float) -> float:
    """``sum |w| u_max + |V_b|``: no output of a run whose inputs and initial voltages stay
    within ``u_max`` in magnitude exceeds it (``slope_cap <= 1``: monotone Euler steps).

    Parameters
    ----------
    params : LadderParams
        Its parameters.
    u_max : float
        Bound on the magnitude of the inputs and the initial voltages.

    Returns
    -------
    float
        ``sum |w| u_max + |V_b|``.
    """
    return float(np.abs(params.w).sum() * u_max + abs(params.v_b))


@fill_doc
def conductance_limit(structure: LadderStructure) -> float:
    """Largest effective ``G`` [1/s]: two conducting resistors at a node reach ``slope_cap``.

    %(structure_parameters)s

    Returns
    -------
    float
        ``slope_cap / (2 dt)`` [1/s].
    """
    return structure.slope_cap / (2.0 * structure.dt)


@fill_doc
def effective_conductance(structure: LadderStructure, params: LadderParams) -> np.ndarray:
    """``G_k`` limited to :func:`conductance_limit`, what the Euler step uses.

    %(records_parameters)s

    Returns
    -------
    numpy.ndarray, shape (N,)
        The limited conductances [1/s].
    """
    return np.minimum(params.conductance, conductance_limit(structure))


@fill_doc
def step(structure: LadderStructure, params: LadderParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """Output from the present capacitor voltages, then one Euler step with the source voltage
    ``u``.

    %(step)s
    """
    x = np.asarray(x, dtype=float)
    y = params.w[0] * u + params.w[1:] @ x - params.v_b
    v = np.concatenate([[u], x[:-1]]) - x
    i = effective_conductance(structure, params) * np.sign(v) * np.maximum(
        np.abs(v) - params.band, 0.0)
    return float(y), x + structure.dt * (i - np.append(i[1:], 0.0))


@fill_doc
def invert_step(structure: LadderStructure, params: LadderParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of :func:`invert`: ``e = (y + V_b - sum_k w_k U_k) / w_0`` from the present
    voltages, then the Euler step with ``e``.

    %(invert_step)s
    """
    x = np.asarray(x, dtype=float)
    e = (y + params.v_b - params.w[1:] @ x) / params.w[0]
    return float(e), step(structure, params, x, e)[1]


def _rest_input(params: LadderParams, y: float) -> float:
    w_sum = params.w.sum()
    return (y + params.v_b) / w_sum if w_sum != 0 else 0.0


@fill_doc
def rest_state(structure: LadderStructure, params: LadderParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Every capacitor at the source voltage ``value``, no current (``inverse``: at the source
    ``(value + V_b) / sum(w)`` that gives the output ``value``): the start of ``simulate`` /
    ``invert`` with ``x0=None``.

    %(rest_state)s
    """
    return np.full(params.n_cells, _rest_input(params, value) if inverse else float(value))


def _check(structure: LadderStructure, params: LadderParams, inverse: bool) -> None:
    check_size(params.n_cells, structure.n_cells, "cells")
    if inverse and params.w[0] == 0:
        raise FitDivergedError("the ladder model has w_0 = 0, so it has no inverse")


@fill_doc
def states(structure: LadderStructure, params: LadderParams, u: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Capacitor voltages seen by each sample's output, shape (n, N), and the final state.

    The output is linear in them: ``y = w_0 u + states @ w[1:] - V_b`` (the fit uses this).

    Parameters
    ----------
    %(structure)s
    %(u_source)s
    %(x0_capacitors)s

    Returns
    -------
    states : numpy.ndarray, shape (n, N)
        Capacitor voltages each sample's output is computed from.
    %(x_end_capacitors)s
    """
    _check(structure, params, False)
    u = check_signal(u, "u")
    x = RUNS.initial(structure, params, x0, u[0], False)
    return _states(structure, params, u, x)


def _states(structure: LadderStructure, params: LadderParams, u: np.ndarray,
            x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.states(u, x, params.band, effective_conductance(structure, params),
                          structure.dt)


def _forward(structure: LadderStructure, params: LadderParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.simulate(u, x, params.band, effective_conductance(structure, params),
                            params.w, params.v_b, structure.dt)


def _inverse(structure: LadderStructure, params: LadderParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u_hat, x_end, n_bad = kernels.invert(y, x, params.band,
                                         effective_conductance(structure, params),
                                         params.w, params.v_b, structure.dt)
    if n_bad >= 0:
        raise FitDivergedError(f"the inverse ladder model diverged at sample {n_bad} of "
                               f"{y.size}; the weights make it unstable on this data")
    return u_hat, x_end


RUNS = Runs(label="ladder", step=step, n_state=lambda structure, params: structure.n_cells,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=_check)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the ladder circuit",
    notes="The input is the source voltage ``e`` and the state the capacitor voltages ``U_k``; "
          "the rest start (``U_k = e_0``, no current) is the synchronised start of "
          "eq. 2.21-2.22.",
    inverse_notes="``e = (y + V_b - sum_k w_k U_k) / w_0``, then the state update: the mPL's "
                  "eq. 5.13-5.14 in the order of fig. 5.12. No inverse exists for ``w_0 = 0``; "
                  "an unstable inverse (``|e| >= 1e6 (1 + max |y|)``) is refused. It follows "
                  "the path its rounding picks, so :func:`invert_step` looped over the samples "
                  "may leave that range where this stays bounded, or the other way round.")
