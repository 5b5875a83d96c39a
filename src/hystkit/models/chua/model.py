"""Chua-Stromsmoe hysteresis model, sec. 2.1.3 (eq. 2.3-2.4) of the reference document.

One element relates input ``u`` and output ``y`` by ``dy/dt = g(u - f(y))`` (eq. 2.3), with a
restoring function ``f`` (energy storage; the i-lambda curve of Chua's iron-core inductor) and
a dissipation function ``g`` (the v-i curve of its resistor). The forms used here::

    f(y) = k_inf y + (k_0 - k_inf) y_s tanh(y / y_s)            odd, slope k_0 at 0, k_inf far
    g(v) = G V_g sinh(d(v) / V_g),  d(v) = sign(v) max(|v| - delta, 0)

``f`` is strictly increasing, onto and has slopes between ``k_0`` and ``k_inf`` (softening for
``k_0 > k_inf``, stiffening otherwise), as eq. 2.3 requires. With ``delta = 0``, ``g`` is the
document's strictly increasing dissipation function; the model then has local memory (the
future depends on the past only through the present ``y``), loops that widen with frequency
and, as the document says, no hysteresis at DC: slowly, ``y -> f^-1(u)``. A dead band
``delta > 0`` is an extension: inside it the element does not move, so at DC it becomes the
play operator ``y = f^-1(H_delta[u])`` (eq. 2.11) and keeps a rate-independent loop.
Solved for the input, eq. 2.3 is the document's eq. 2.4, ``x = f(y) + g^-1(dy/dt)``, which
names the input ``x`` (Chua and Stromsmoe's notation) where eq. 2.3 says ``u``; for a cosine
``y`` and odd ``f``, ``g`` the two terms are the even and odd parts ``x_e``, ``x_o`` of the
input. The identity holds exactly for every step of the discrete model below.

``size`` elements in series (the flux linkages of inductors carrying one current add) give
``y = sum_k y_k`` with one ``(f_k, g_k)`` per element; one element is eq. 2.3 itself.

Discretisation: forward Euler ``y_k <- y_k + dt g_k(u_n - f_k(y_k))``, and the output at sample
``n`` is the state *after* the step that uses ``u_n`` (eq. 2.3 has no feed-through, so this is
what makes the inverse causal). Stability limit, as the mPL's (eq. 5.28-5.29): the step's
slope is ``1 - dt g'(v) f'(y)`` and ``f' <= max(k_0, k_inf)``, so ``g`` is continued by a
straight line beyond the knee where ``g' = slope_cap / (dt max(k_0, k_inf))``. With
``slope_cap <= 1`` every step is monotone: ``y_k`` never overshoots its equilibrium and stays
between ``f^-1(min u - delta)`` and ``f^-1(max u + delta)`` (or its start) for any parameters.

The records (structure, parameters, their domain) are in :mod:`.records`, importable from here.
"""

from __future__ import annotations

import numpy as np

from ...errors import FitDivergedError
from .._docs import docfiller
from .._run import Runs, family_runs
from .._validation import check_size
from . import kernels
from .records import (
    DOMAIN,
    MAX_ELEMENTS,
    ChuaParams,
    ChuaStructure,
    output_bound,
)

fill_doc = docfiller("ChuaStructure", "ChuaParams", state="""\
x : numpy.ndarray, shape (N,)
    Element outputs ``y_k`` before the step.""")

__all__ = [
    "DOMAIN",
    "MAX_ELEMENTS",
    "ChuaParams",
    "ChuaStructure",
    "dissipation",
    "dissipation_slope",
    "invert",
    "invert_step",
    "kernel_args",
    "limits",
    "output_bound",
    "rest_state",
    "restoring",
    "restoring_inverse",
    "simulate",
    "simulate_reference",
    "step",
]

@fill_doc
def limits(structure: ChuaStructure, params: ChuaParams) -> tuple[np.ndarray, np.ndarray]:
    """Per element: the cap on ``g'`` and the knee ``|v|`` beyond which ``g`` is straight.

    %(records_parameters)s

    Returns
    -------
    cap : numpy.ndarray, shape (N,)
        Largest slope ``g'``: ``slope_cap / (dt max(k_0, k_inf))``.
    knee : numpy.ndarray, shape (N,)
        ``|v|`` beyond which ``g`` is a straight line.
    """
    cap = structure.slope_cap / (structure.dt * np.maximum(params.k0, params.k_inf))
    ratio = cap / params.g
    knee = params.delta + np.where(ratio > 1, params.v_g * np.arccosh(np.maximum(ratio, 1.0)),
                                   0.0)
    return cap, knee


@fill_doc
def restoring(params: ChuaParams, y: np.ndarray) -> np.ndarray:
    """``f_k(y_k)``; ``y`` of shape (..., N).

    Parameters
    ----------
    %(params)s
    y : numpy.ndarray, shape (..., N)
        Element outputs.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        ``f_k(y_k)``.
    """
    y = np.asarray(y, dtype=float)
    return params.k_inf * y + (params.k0 - params.k_inf) * params.y_s * np.tanh(y / params.y_s)


@fill_doc
def restoring_inverse(params: ChuaParams, u: float) -> np.ndarray:
    """``f_k^-1(u)`` for every element, shape (N,), by bisection to float resolution.

    ``|f(y) - k_inf y| <= |k_0 - k_inf| y_s`` brackets the root.

    Parameters
    ----------
    %(params)s
    u : float
        Input.

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``f_k^-1(u)``.
    """
    return kernels.restoring_inverse(float(u), params.k0, params.k_inf, params.y_s)


@fill_doc
def dissipation(structure: ChuaStructure, params: ChuaParams, v: np.ndarray) -> np.ndarray:
    """Limited ``g_k(v_k)`` (dead band, sinh, straight line beyond the knee); shape (..., N).

    Parameters
    ----------
    %(structure)s
    v : numpy.ndarray, shape (..., N)
        Argument ``u - f_k(y_k)`` per element.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        ``g_k(v_k)``.
    """
    v = np.asarray(v, dtype=float)
    cap, knee = limits(structure, params)
    a = np.abs(v)
    inner = np.clip(a, params.delta, knee) - params.delta
    mag = params.g * params.v_g * np.sinh(inner / params.v_g) + cap * np.maximum(a - knee, 0.0)
    return np.sign(v) * mag


@fill_doc
def dissipation_slope(structure: ChuaStructure, params: ChuaParams,
                      v: np.ndarray) -> np.ndarray:
    """``g_k'(v_k)`` of the limited dissipation function: 0 in the dead band, the sinh's slope
    up to the knee, ``cap`` beyond (on a kink, the inner side's).

    Parameters
    ----------
    %(structure)s
    v : numpy.ndarray, shape (..., N)
        Argument per element.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        ``g_k'(v_k)``.
    """
    v = np.asarray(v, dtype=float)
    cap, knee = limits(structure, params)
    a = np.abs(v)
    inner = params.g * np.cosh((np.minimum(a, knee) - params.delta) / params.v_g)
    return np.where(a <= params.delta, 0.0, np.where(a <= knee, inner, cap))


@fill_doc
def step(structure: ChuaStructure, params: ChuaParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One Euler step with input ``u``; the output ``y`` is the sum of the updated element
    states.

    %(step)s
    """
    x = np.asarray(x, dtype=float)
    x_next = x + structure.dt * dissipation(structure, params, u - restoring(params, x))
    return float(np.sum(x_next)), x_next


@fill_doc
def invert_step(structure: ChuaStructure, params: ChuaParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """The input that makes :func:`step` return ``y``, and the state it leaves.

    ``sum_k g_k(u - f_k(x_k)) = (y - sum_k x_k) / dt`` is solved by bisection (its left side is
    non-decreasing in ``u``); where it is flat (no element moves, dead bands) the middle of the
    flat interval is taken. An output within ``REST_TOL max(1, |y|, sum |x_k|)`` of the present
    ``sum x_k`` is that output (``r = 0``): rounding must not decide which edge of a dead band
    the input jumps to.

    %(invert_step)s
    """
    x = np.asarray(x, dtype=float)
    fx = restoring(params, x)
    total = float(np.sum(x))
    if abs(y - total) <= kernels.REST_TOL * max(1.0, abs(y), float(np.sum(np.abs(x)))):
        y = total
    r = (y - total) / structure.dt
    cap, knee = limits(structure, params)
    n_el = x.size
    brackets = [_g_inverse(r / n_el, params, cap, knee, upper) + fx for upper in (False, True)]
    lo, hi = float(np.min(brackets[0])), float(np.max(brackets[1]))
    ends = []
    for first in (True, False):
        a, b = lo, hi
        while b - a > 1e-14 * (1.0 + abs(a) + abs(b)):
            m = 0.5 * (a + b)
            h = float(np.sum(dissipation(structure, params, m - fx)))
            if h > r or (first and h == r):
                b = m
            else:
                a = m
        ends.append(b if first else a)
    e = 0.5 * (ends[0] + ends[1])
    return e, x + structure.dt * dissipation(structure, params, e - fx)


def _g_inverse(r: float, params: ChuaParams, cap: np.ndarray, knee: np.ndarray,
               upper: bool) -> np.ndarray:
    if r == 0:
        return params.delta if upper else -params.delta
    g_knee = params.g * params.v_g * np.sinh((knee - params.delta) / params.v_g)
    a = abs(r)
    inside = params.delta + params.v_g * np.arcsinh(a / (params.g * params.v_g))
    return np.sign(r) * np.where(a <= g_knee, inside, knee + (a - g_knee) / cap)


def _check(structure: ChuaStructure, params: ChuaParams, inverse: bool) -> None:
    check_size(params.n_elements, structure.n_elements, "elements")


@fill_doc
def rest_state(structure: ChuaStructure, params: ChuaParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Element outputs at rest (``g = 0``) under a constant input ``value``, ``f_k^-1(value)``;
    with ``inverse``, for a constant output ``value``: the common input ``u`` with
    ``sum_k f_k^-1(u) = value`` first. These are the starts of ``simulate`` / ``invert`` with
    ``x0=None``.

    %(rest_state)s
    """
    if inverse:
        value = kernels.rest_input(float(value), params.k0, params.k_inf, params.y_s)
    return restoring_inverse(params, value)


@fill_doc
def kernel_args(structure: ChuaStructure, params: ChuaParams) -> tuple:
    """The compiled kernels' parameter arguments, in their order.

    %(records_parameters)s

    Returns
    -------
    tuple
        ``(k_0, k_inf, y_s, G, V_g, delta, knee, cap, dt)``; knee and cap from :func:`limits`.
    """

    cap, knee = limits(structure, params)
    return (params.k0, params.k_inf, params.y_s, params.g, params.v_g, params.delta, knee, cap,
            structure.dt)


def _forward(structure: ChuaStructure, params: ChuaParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return kernels.simulate(u, x, *kernel_args(structure, params))


def _inverse(structure: ChuaStructure, params: ChuaParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u_hat, x_end, n_bad = kernels.invert(y, x, *kernel_args(structure, params))
    if n_bad >= 0:
        raise FitDivergedError(f"the inverse Chua-Stromsmoe model diverged at sample {n_bad} "
                               f"of {y.size}")
    return u_hat, x_end


RUNS = Runs(label="Chua-Stromsmoe", step=step,
            n_state=lambda structure, params: params.n_elements, rest_state=rest_state,
            forward=_forward, inverse=_inverse, check=_check)
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the Chua-Stromsmoe model",
    notes="The state is the element outputs ``y_k``; at rest every element sits at "
          "``y_k = f_k^-1(u_0)`` (``g = 0``).",
    inverse_notes="The exact inverse of ``simulate``: each sample solves the Euler step for its "
                  "input by bisection (:func:`invert_step`), so ``simulate(invert(y))`` returns "
                  "``y``. The input is unique wherever some element moves; with dead bands and a "
                  "constant output it is any point of the band, and the middle is returned. An "
                  "output equal to the present one to rounding (relative ``REST_TOL = 1e-12`` of "
                  "``max(1, |y|, sum |y_k|)``) counts as constant, so that a constant output "
                  "from the start comes back from ``simulate``'s rest start. The rest start "
                  "splits ``y_0`` over the elements for a common input ``u`` with "
                  "``sum_k f_k^-1(u) = y_0``. The inverse amplifies output noise by "
                  "``1 / (dt g')``.")
