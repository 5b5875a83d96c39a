"""Generalised ("non-linear") Preisach model of Mayergoyz and Friedman (sec. 2.1.2, eq. 2.2).

Eq. 2.2 adds two things to the classical model (``models/preisach``): the relay weight depends on
the present input, ``mu(alpha, beta, u(t))``, and a fully reversible part made of step
operators ``lambda_a`` (+1 for ``u >= a``, -1 below) with weight ``nu(a)``::

    y = integral_T mu(a, b, u) gamma_ab[u] da db + integral nu(a) lambda_a[u] da + y_0

Implemented forms (the document leaves both functions open):

- ``mu`` is affine in the present input -- the lowest order that relaxes congruency -- written
  as the interpolation ``mu = (1 - w) mu_- + w mu_+`` with ``w = (1 + u) / 2`` between a weight
  valid at ``u = -1`` and one valid at ``u = +1``. Each is a classical Preisach weight stored
  as an Everett table (same grid and bilinear interpolation as ``models/preisach``), so the relay
  part is ``(1 - w) P_-[u] + w P_+[u]`` with ``P_+-`` the classical outputs of eq. 9.13 on one
  shared staircase. Non-negativity of ``mu`` for every ``u`` in the range is just
  ``mu_- , mu_+ >= 0``.
- ``nu`` is a polynomial of degree ``d`` on [-1, 1] in the Bernstein basis, ``nu = sum_k nu_k
  B_k^d``, zero outside. Then the reversible part is a polynomial of degree ``d + 1`` in
  ``u``: ``R(u) = 2 int_{-1}^{u} nu - int_{-1}^{1} nu
  = sum_k nu_k 2 / (d + 1) (2 sum_{j > k} B_j^{d+1}(u) - 1)``, non-decreasing when all
  ``nu_k >= 0``.

The state is the classical staircase (wiping-out and return-point memory hold; minor loops
between the same extrema are no longer congruent when ``mu_- != mu_+``). Outside [-1, 1] the
model continues as a straight line with the mean slope of its major loop,
``(y(+sat) - y(-sat)) / 2``, as the classical one does. The compiled loops, the packed loop
state and the protocol methods are the classical model's (``hystkit.models.preisach``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import comb

import numpy as np
from numpy.polynomial import Polynomial

from .._docs import docfiller
from .._protocol import Record
from .._run import Runs, family_runs
from .._validation import check_magnitude
from ..preisach import (
    INVERT_TOL,
    MAX_VALUE,
    PreisachParams,
    PreisachStructure,
    antisymmetric,
    check_rise,
    kernels,
    staircase_terms,
    start_staircase,
    update_staircase,
)

fill_doc = docfiller("GPreisachStructure", "GPreisachParams", state="x_staircase")

__all__ = [
    "GPreisachParams",
    "GPreisachStructure",
    "invert",
    "invert_step",
    "kernel_parts",
    "major_slope",
    "output_bound",
    "reversible",
    "reversible_basis",
    "simulate",
    "simulate_reference",
    "step",
]


@dataclass(frozen=True)
class GPreisachStructure(Record):
    """What does not get fitted.

    Parameters
    ----------
    levels, dt, capacity, smoothing, orientation
        As in ``PreisachStructure``: grid levels ``L`` of both Everett tables, sample time [s],
        staircase buffer size, and the fit's smoothness weight and loop orientation.
    degree : int
        Degree ``d`` of the reversible weight ``nu`` (``d + 1`` Bernstein coefficients; the
        reversible output is of degree ``d + 1``).
    """

    levels: int = 16
    dt: float = 0.025
    capacity: int = 1024
    smoothing: float = 1e-5
    orientation: str = "auto"
    degree: int = 2

    def __post_init__(self) -> None:
        PreisachStructure(levels=self.levels, dt=self.dt, capacity=self.capacity,
                          smoothing=self.smoothing, orientation=self.orientation)  # validates
        if int(self.degree) != self.degree or not 0 <= self.degree <= 8:
            raise ValueError(f"degree must be an integer in 0..8, got {self.degree!r}")


def _bernstein(n: int, j: int) -> Polynomial:
    x = Polynomial([0.5, 0.5])  # (1 + u) / 2 maps [-1, 1] onto [0, 1]
    return comb(n, j) * x ** j * (1 - x) ** (n - j)


@lru_cache(maxsize=16)  # the per-sample reference step asks for it every sample
def reversible_basis(degree: int) -> tuple[Polynomial, ...]:
    """``R_k(u)``: reversible output of ``nu = B_k^d`` (module docstring), ``d + 1`` of them."""
    scale = 2.0 / (degree + 1)
    return tuple(scale * (2 * sum((_bernstein(degree + 1, j) for j in range(k + 1, degree + 2)),
                                  Polynomial([0.0])) - 1) for k in range(degree + 1))


def reversible(nu: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Reversible part ``int nu(a) lambda_a[u] da`` of eq. 2.2 at inputs ``u`` (clipped).

    Parameters
    ----------
    nu : numpy.ndarray, shape (d + 1,)
        Bernstein coefficients of ``nu``.
    u : numpy.ndarray
        Inputs; clipped to [-1, 1].

    Returns
    -------
    numpy.ndarray
        The reversible output, same shape as `u`.
    """
    nu = np.asarray(nu, dtype=float)
    u = np.clip(np.asarray(u, dtype=float), -1.0, 1.0)
    return sum(c * b(u) for c, b in zip(nu, reversible_basis(nu.size - 1)))


@dataclass(frozen=True, eq=False)
class GPreisachParams(Record):
    """Fitted quantities of eq. 2.2.

    Parameters
    ----------
    everett_minus, everett_plus : array, shape (L, L)
        Everett tables of ``mu_-`` (weight at ``u = -1``) and ``mu_+`` (at ``u = +1``), in the
        format of ``PreisachParams.everett``.
    nu : array, shape (d + 1,)
        Bernstein coefficients of the reversible weight ``nu``.
    offset : float
        Output offset ``y_0``.

    Notes
    -----
    Domain (checked here): both tables as ``PreisachParams`` (``|F| <= 1e6``, at most 128
    levels), ``|nu_k|, |y_0| <= 1e6``. Then ``|y - y_0| <= B max(1, |u|)`` with
    ``B = max(sum |m_-|, sum |m_+|) + 2 sum |nu_k| / (d + 1)`` (:func:`output_bound`). The
    inverse needs a rising major loop (``preisach.check_rise``).
    """

    everett_minus: np.ndarray
    everett_plus: np.ndarray
    nu: np.ndarray
    offset: float = 0.0

    def __post_init__(self) -> None:
        for name in ("everett_minus", "everett_plus"):
            table = PreisachParams(everett=getattr(self, name)).everett  # validates
            object.__setattr__(self, name, table)
        if self.everett_minus.shape != self.everett_plus.shape:
            raise ValueError("everett_minus and everett_plus must have the same shape")
        nu = np.array(self.nu, dtype=float).reshape(-1)
        if not 1 <= nu.size <= 9 or not np.all(np.isfinite(nu)):
            raise ValueError("nu must be 1..9 finite Bernstein coefficients")
        if not np.isfinite(self.offset):
            raise ValueError("offset must be finite")
        check_magnitude(nu, "nu", MAX_VALUE)
        check_magnitude(self.offset, "offset", MAX_VALUE)
        nu.setflags(write=False)
        object.__setattr__(self, "nu", nu)
        object.__setattr__(self, "offset", float(self.offset))

    @property
    def levels(self) -> int:
        return self.everett_minus.shape[0]

    # The tables are stored as lower-triangle rows, as PreisachParams does (the file format).
    def to_dict(self) -> dict:
        return {"everett_minus": PreisachParams(self.everett_minus).to_dict()["everett"],
                "everett_plus": PreisachParams(self.everett_plus).to_dict()["everett"],
                "nu": self.nu.tolist(), "offset": self.offset}

    @classmethod
    def from_dict(cls, d: dict) -> GPreisachParams:
        tables = [PreisachParams.from_dict({"everett": d[name], "offset": 0.0}).everett
                  for name in ("everett_minus", "everett_plus")]
        return cls(everett_minus=tables[0], everett_plus=tables[1], nu=d["nu"],
                   offset=d["offset"])


@fill_doc
def major_slope(params: GPreisachParams) -> float:
    """Mean slope of the major loop, ``(y(+sat) - y(-sat)) / 2``: the extension beyond +-1.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    float
        The mean slope.
    """
    rise = params.everett_plus[-1, 0] + params.everett_minus[-1, 0]
    return float(0.5 * (rise + reversible(params.nu, 1.0) - reversible(params.nu, -1.0)))


def _mass(params: GPreisachParams) -> float:
    """``max(sum |m_-|, sum |m_+|) + 2 sum |nu_k| / (d + 1)``: the most the relay and the
    reversible part move the output over [-1, 1] (each ``|R_k| <= 2 / (d + 1)``)."""
    relay = max(np.abs(PreisachParams(t).masses()).sum()
                for t in (params.everett_minus, params.everett_plus))
    return float(relay + 2.0 * np.abs(params.nu).sum() / params.nu.size)


@fill_doc
def output_bound(params: GPreisachParams, u_max: float) -> float:
    """``|y_0| + B max(1, u_max)`` (class Notes): no output of a run with ``|u| <= u_max``
    exceeds it.

    %(params_bound)s
    """
    return float(abs(params.offset) + _mass(params) * max(1.0, u_max))


def _poly(params: GPreisachParams) -> np.ndarray:
    """Monomial coefficients of ``R(u) + y_0`` for the kernels."""
    # on the coefficient arrays, in the order Polynomial's sum adds them (the same numbers),
    # without its objects: every simulate builds this (40 -> ~5 us)
    coef = np.zeros(params.nu.size + 1)
    for c, b in zip(params.nu, reversible_basis(params.nu.size - 1)):
        coef[: b.coef.size] += c * b.coef
    coef[0] += params.offset
    return coef


def _tables(params: GPreisachParams) -> np.ndarray:
    return np.stack([antisymmetric(params.everett_minus), antisymmetric(params.everett_plus)])


def _combine(params: GPreisachParams, relay: np.ndarray, u: np.ndarray) -> np.ndarray:
    u_clip = np.clip(u, -1.0, 1.0)
    w = 0.5 * (1.0 + u_clip)
    return ((1.0 - w) * relay[..., 0] + w * relay[..., 1] + reversible(params.nu, u_clip)
            + params.offset + major_slope(params) * (u - u_clip))


@fill_doc
def step(structure: GPreisachStructure, params: GPreisachParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample: update the staircase with the normalised input ``u``, then the output of eq.
    2.2 (``x_next``: the staircase after the sample).

    %(step)s
    """
    x_next = update_staircase(x, u, structure.capacity)
    relay = np.array([staircase_terms(params.everett_minus, x_next),
                      staircase_terms(params.everett_plus, x_next)])
    return float(_combine(params, relay, np.asarray(float(u)))), x_next


def _check(structure: GPreisachStructure, params: GPreisachParams, inverse: bool) -> None:
    if params.levels != structure.levels or params.nu.size != structure.degree + 1:
        raise ValueError(f"params (levels {params.levels}, {params.nu.size} nu) do not match "
                         f"the structure (levels {structure.levels}, degree {structure.degree})")


@fill_doc
def kernel_parts(params: GPreisachParams) -> tuple[np.ndarray, bool, np.ndarray, float]:
    """What the compiled kernels run on: the two tables, weighted (True), the monomial
    coefficients of ``R(u) + y_0`` and the slope of the straight-line extension.

    Parameters
    ----------
    %(params)s

    Returns
    -------
    tables : numpy.ndarray
        The Everett tables of ``mu_-`` and ``mu_+``, stacked (antisymmetric form).
    weighted : bool
        True: the relay part is weighted by the present input.
    poly : numpy.ndarray
        Monomial coefficients of ``R(u) + y_0``.
    slope : float
        Slope of the straight-line extension (:func:`major_slope`).
    """
    return _tables(params), True, _poly(params), major_slope(params)


def _forward(structure: GPreisachStructure, params: GPreisachParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    tables, weighted, poly, slope = kernel_parts(params)
    return kernels.forward(u, x, tables, weighted, poly, slope, structure.capacity)


def _inverse(structure: GPreisachStructure, params: GPreisachParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    tables, weighted, poly, slope = kernel_parts(params)
    check_rise(slope, _mass(params), "generalised Preisach")
    return kernels.invert(y, x, tables, weighted, poly, slope, structure.capacity, INVERT_TOL)


RUNS = Runs(label="gpreisach", step=step, forward=_forward, inverse=_inverse, check=_check,
            start=start_staircase)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the generalised Preisach model",
    notes="Amortised O(1) per sample. The state is the staircase (as for "
          "``preisach.simulate``): ``x0=None`` is the demagnetised state. Inputs beyond "
          "[-1, 1] follow the straight-line extension.",
    inverse_notes="By bisection on each branch (``preisach.invert``). The branches are "
                  "continuous, so the search always returns an input reproducing the output; it "
                  "is the unique one where the branch is monotone. The input-dependent weight can "
                  "fold a branch even for non-negative weights (the term ``dw/du (P_+ - P_-)``); "
                  "the search then returns the solution nearest to the present input on the side "
                  "the target lies. FitDivergedError if the major loop does not rise (mean slope "
                  "<= 0): no inverse exists.")


@fill_doc
def invert_step(structure: GPreisachStructure, params: GPreisachParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of :func:`invert` from the staircase ``x``: ``(u_hat, x_next)``.

    %(invert_step)s
    """
    u_hat, x_next = invert(structure, params, np.array([float(y)]), x0=x)
    return float(u_hat[0]), x_next
