"""Bobbio-Marrucci spring/piston chain, sec. 2.1.4 (fig. 2.6-2.8, eq. 2.5).

Topology (fig. 2.6): the applied force ``F`` (the input ``u``) pulls the free end of a chain of
``N`` linear springs; between spring ``k`` and spring ``k+1`` sits piston ``k``, held by Coulomb
friction against a fixed floor; spring ``N`` ends at the wall. ``F_k`` is the force in spring
``k`` (so ``F_1 = F``). Piston ``k`` feels ``F_k - F_k+1`` and sticks while

    |F_k - F_k+1| <= a_k,            k = 1 .. N-1                                  (eq. 2.5)

The output is the deformation of the spring sequence, ``Y = sum_k Y_k = sum_k c_k F_k`` with
``c_k = 1 / k_k`` the compliance of spring ``k``, plus an offset ``b`` (the position reference).
The document's eq. 2.5 runs to ``k = N``; with ``N - 1`` pistons it ends at ``N - 1``. Its
``U_k`` ("forcing variables") are the spring forces ``F_k``, and its unit constants become the
thresholds ``a_k`` and compliances ``c_k`` here.

Quasi-static evolution, exact and event-free: velocity does not change the friction (sec.
2.1.4), so the state after a sample depends only on the input values, not on their timing.
Between samples the input moves monotonically; a piston starts sliding only when the one before
it slides, and then sits at its threshold, so one pass from the loaded end inwards,

    F_k+1 <- clip(F_k+1, F_k - a_k, F_k + a_k),      k = 1 .. N-1

gives the new equilibrium. Each force is thus a play operator (eq. 2.11) of the previous one,
and, play operators composing by adding their radii, ``F_k = H_{A_k}[F]`` with
``A_k = a_1 + .. + a_k-1``: the chain is a Prandtl-Ishlinskii model with non-negative weights,
rate-independent, with non-local memory (fig. 2.8) and wiping-out of minor loops.

The state ``x`` is ``(F_2, .., F_N)``; ``F_1`` is the input itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import FitDivergedError
from .._docs import docfiller
from .._protocol import Record
from .._run import Runs, family_runs
from .._validation import (
    check_dt,
    check_positive_int,
    check_signal,
    check_size,
    finite_floats,
    freeze_arrays,
)
from . import kernels

fill_doc = docfiller("BobbioStructure", "BobbioParams")

__all__ = [
    "MAX_SPRINGS",
    "MAX_VALUE",
    "BobbioParams",
    "BobbioStructure",
    "forces",
    "invert",
    "invert_step",
    "output_bound",
    "rest_state",
    "simulate",
    "simulate_reference",
    "step",
]


MAX_SPRINGS = 1000  # simulate and fit hold n x (N - 1) forces: 8 kB a sample at the cap
MAX_VALUE = 1e6  # compliances, thresholds and |offset| in normalised units (fit: <= ~10)


@dataclass(frozen=True)
class BobbioStructure(Record):
    """What does not get fitted.

    Parameters
    ----------
    n_springs : int
        Springs ``N``, ``1 <= N <= MAX_SPRINGS`` (1000: ``simulate`` and the fit hold the
        ``N - 1`` spring forces of every sample, 8 kB a sample, 8 GB a million samples, at
        the cap); there are ``N - 1`` pistons.
    dt : float
        Sample time [s]; the model is rate-independent and does not use it.
    """

    n_springs: int = 10
    dt: float = 0.025

    def __post_init__(self) -> None:
        # the cap first: nothing is allocated or looped over before it holds (inf, 1e12)
        if not (isinstance(self.n_springs, int | float) and self.n_springs <= MAX_SPRINGS):
            raise ValueError(f"n_springs must be an integer in [1, {MAX_SPRINGS}], got "
                             f"{self.n_springs!r}")
        check_positive_int(self.n_springs, "n_springs")
        check_dt(self.dt)

    @property
    def n_params(self) -> int:
        return 2 * self.n_springs


@dataclass(frozen=True, eq=False)
class BobbioParams(Record):
    """Spring compliances, piston thresholds and output offset.

    Parameters
    ----------
    compliance : array, shape (N,)
        ``c_k = 1 / k_k`` in ``[0, MAX_VALUE]`` (0 is a rigid spring) [output units per input
        unit].
    friction : array, shape (N - 1,)
        Piston thresholds ``a_k`` in ``(0, MAX_VALUE]`` [input units], eq. 2.5.
    offset : float
        Output offset ``b``, ``|b| <= MAX_VALUE``.

    Notes
    -----
    The domain (``MAX_VALUE = 1e6``, normalised units; the fit's values are below ~10) keeps
    every run finite and bounded: each spring force is a play of the input, so
    ``|y| <= sum(c) max(|u|, |x0|) + |b|`` (:func:`output_bound`). The inverse divides by
    the compliances that move, so tiny ones give huge forces: it returns finite values or
    raises ``FitDivergedError``.
    """

    compliance: np.ndarray
    friction: np.ndarray
    offset: float = 0.0
    n_springs: int = field(init=False)

    def __post_init__(self) -> None:
        n = np.size(self.compliance)
        object.__setattr__(self, "n_springs", int(n))
        freeze_arrays(self, compliance=n, friction=n - 1)
        finite_floats(self, "offset")
        if np.any(self.compliance < 0):
            raise ValueError("compliance must be >= 0 (springs have positive stiffness)")
        if np.any(self.friction <= 0):
            raise ValueError("friction thresholds a_k must be positive (eq. 2.5)")
        for name, values in (("compliance", self.compliance), ("friction", self.friction),
                             ("offset", np.abs(self.offset))):
            if np.any(values > MAX_VALUE):
                raise ValueError(f"{name} must be at most {MAX_VALUE:g} in magnitude (the "
                                 f"domain where runs stay bounded), got "
                                 f"{float(np.max(values)):g}")

    @property
    def radii(self) -> np.ndarray:
        """Play radii ``A_k = a_1 + .. + a_k-1`` of the forces ``F_2 .. F_N``."""
        return np.cumsum(self.friction)


def output_bound(params: BobbioParams, u_max: float) -> float:
    """``sum(c) u_max + |b|``: no output of a run whose inputs and initial forces stay within
    ``u_max`` in magnitude exceeds it (every spring force is a play of the input).

    Parameters
    ----------
    params : BobbioParams
        Its parameters.
    u_max : float
        Bound on the magnitude of the inputs and the initial forces.

    Returns
    -------
    float
        ``sum(c) u_max + |b|``.
    """
    return float(params.compliance.sum() * u_max + abs(params.offset))


@fill_doc
def step(structure: BobbioStructure, params: BobbioParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """Apply force ``u``: project the spring forces onto eq. 2.5, then read the deformation.

    Parameters
    ----------
    %(structure)s
    x : numpy.ndarray
        State before the sample.
    u : float
        Applied force of the sample.

    Returns
    -------
    y : float
        Deformation with the projected forces.
    %(x_next)s
    """
    x_next = np.array(x, dtype=float)
    prev = u
    for k in range(x_next.size):
        x_next[k] = min(max(x_next[k], prev - params.friction[k]), prev + params.friction[k])
        prev = x_next[k]
    y = params.compliance[0] * u + params.compliance[1:] @ x_next + params.offset
    return float(y), x_next


@fill_doc
def invert_step(structure: BobbioStructure, params: BobbioParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of :func:`invert`: the force that gives ``y`` from the forces ``x``, and the
    forces it leaves; NaN (and a NaN state) where no force gives ``y``, as the loop block.

    Parameters
    ----------
    %(structure)s
    x : numpy.ndarray
        State before the sample.
    %(y_step)s

    Returns
    -------
    u : float
        Force that gives `y` from the present forces; NaN where none does.
    %(x_next)s
    """
    x = np.array(x, dtype=float)
    x_next = x.copy()
    f = kernels.invert_sample(x, x_next, 0, float(y), params.compliance, params.friction,
                              params.offset)
    return float(f), np.full_like(x, np.nan) if np.isnan(f) else x_next


def _rest_force(params: BobbioParams, y: float) -> float:
    total = params.compliance.sum()
    return (y - params.offset) / total if total > 0 else 0.0


@fill_doc
def rest_state(structure: BobbioStructure, params: BobbioParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Every spring carrying the force ``value`` (``inverse``: the force ``(value - b) / sum(c)``
    that gives the deformation ``value``), no piston loaded: the start of ``simulate`` /
    ``invert`` with ``x0=None``.

    %(rest_state)s
    """
    force = _rest_force(params, value) if inverse else float(value)
    return np.full(params.n_springs - 1, force)


def _check(structure: BobbioStructure, params: BobbioParams, inverse: bool) -> None:
    check_size(params.n_springs, structure.n_springs, "springs")


@fill_doc
def forces(structure: BobbioStructure, params: BobbioParams, u: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Spring forces ``F_2 .. F_N`` after each sample, shape (n, N - 1), and the final state.

    The output is linear in them: ``y = c_1 u + forces @ c[1:] + b`` (the fit uses this).

    Parameters
    ----------
    %(structure)s
    u : numpy.ndarray, shape (n,)
        Applied force, one value per sample.
    x0 : numpy.ndarray, float or None, optional
        Initial forces ``F_2 .. F_N``, as for :func:`simulate`.

    Returns
    -------
    forces : numpy.ndarray, shape (n, N - 1)
        ``F_2 .. F_N`` after each sample.
    x_end : numpy.ndarray, shape (N - 1,)
        The forces after the last sample.
    """
    _check(structure, params, False)
    u = check_signal(u, "u")
    return kernels.forces(u, RUNS.initial(structure, params, x0, u[0], False), params.friction)


def _forward(structure: BobbioStructure, params: BobbioParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.simulate(u, x, params.friction, params.compliance, float(params.offset))


def _inverse(structure: BobbioStructure, params: BobbioParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u_hat, x_end, n_bad = kernels.invert(y, x, params.compliance, params.friction,
                                         params.offset)
    if n_bad >= 0:
        raise FitDivergedError(f"no applied force gives the deformation at sample {n_bad} "
                               f"(all compliances are zero)")
    return u_hat, x_end


RUNS = Runs(label="Bobbio-Marrucci", step=step,
            n_state=lambda structure, params: structure.n_springs - 1, rest_state=rest_state,
            forward=_forward, inverse=_inverse, check=_check)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the Bobbio-Marrucci chain",
    notes="The input is the applied force (only the values matter, not ``dt``), the output "
          "the deformation ``Y`` and the state the forces ``F_2 .. F_N``. A given state obeying "
          "eq. 2.5 with ``F_1 = u_0`` is an equilibrium, others are projected at the first "
          "sample; at rest every spring carries ``u_0`` and no piston is loaded.",
    inverse_notes="The chain under displacement control. Given the state, ``Y(F)`` is "
                  "continuous, piecewise linear and non-decreasing in ``F``: slope ``c_1`` while "
                  "piston 1 sticks, and each further piston that starts sliding adds its "
                  "spring's compliance. The inverse walks these segments (O(N) per sample, "
                  "breakpoints ``F_k +- A_k`` sorted by eq. 2.5) and then updates the state like "
                  "the forward model, so ``simulate(invert(y)) == y``. If ``c_1 = 0`` and ``Y`` "
                  "stays on a flat segment, the middle of the band ``F_2 +- a_1`` is returned; "
                  "with every compliance zero no force gives the output. The rest start is the "
                  "force ``(y_0 - b) / sum(c)``.")
