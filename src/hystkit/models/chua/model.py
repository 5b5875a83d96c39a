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
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import FitDivergedError
from .._protocol import Record
from .._validation import (
    broadcast_state,
    check_cells,
    check_finite_run,
    check_signal,
    check_size,
    freeze_arrays,
    run_steps,
)
from . import kernels

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

_FIELDS = ("k0", "k_inf", "y_s", "g", "v_g", "delta")
MAX_ELEMENTS = 100  # O(N) a sample; the fit's Jacobian holds 6 N columns: 4.8 kB a sample
# Allowed range of each parameter (normalised units, eq. 5.10), wide around the fit's bounds
# (slopes and scales 1e-2 .. 1e2, G 1e-3 .. 100 / dt, V_g 1e-3 .. 1e3, delta 0 .. 1): within
# it the restoring function, its inverse and the limited sinh cannot overflow.
DOMAIN = {"k0": (1e-6, 1e6), "k_inf": (1e-6, 1e6), "y_s": (1e-6, 1e6), "g": (1e-9, 1e12),
          "v_g": (1e-6, 1e6), "delta": (0.0, 1e6)}


@dataclass(frozen=True)
class ChuaStructure(Record):
    """What does not get fitted.

    Parameters
    ----------
    n_elements : int
        Elements in series, ``1 <= N <= MAX_ELEMENTS`` (100: a sample costs O(N), the fit's
        finite-difference Jacobian holds ``6 N`` columns, 4.8 kB a sample, at the cap); 1 is
        eq. 2.3 itself.
    dt : float
        Sample time [s].
    slope_cap : float
        Largest allowed Euler slope ``dt g' f'`` (stable below 2; <= 1 gives no overshoot).
    """

    n_elements: int = 1
    dt: float = 0.025
    slope_cap: float = 1.0

    def __post_init__(self) -> None:
        # the cap first: nothing is allocated or looped over before it holds (inf, 1e12)
        if not (isinstance(self.n_elements, int | float) and self.n_elements <= MAX_ELEMENTS):
            raise ValueError(f"n_elements must be an integer in [1, {MAX_ELEMENTS}], got "
                             f"{self.n_elements!r}")
        check_cells(self.n_elements, self.dt, self.slope_cap, "n_elements")

    @property
    def n_params(self) -> int:
        return 6 * self.n_elements


@dataclass(frozen=True, eq=False)
class ChuaParams(Record):
    """Restoring and dissipation functions of each element, arrays of shape (N,).

    Parameters
    ----------
    k0, k_inf : array
        Slopes of ``f`` at 0 and far from 0 (> 0) [input units per output unit].
    y_s : array
        Output scale of the transition between the two slopes (> 0).
    g : array
        Slope ``G`` of ``g`` at the edge of its dead band (> 0) [output units per s per input
        unit].
    v_g : array
        Input scale of the sinh in ``g`` (> 0); large means linear.
    delta : array
        Half-width of the dead band of ``g`` (>= 0); 0 is the document's model.

    Notes
    -----
    The optimiser sees ``[log k0, log k_inf, log y_s, log g, log v_g, delta]`` per element.

    Domain (:data:`DOMAIN`): ``k_0, k_inf, y_s, V_g`` in ``[1e-6, 1e6]``, ``G`` in
    ``[1e-9, 1e12]``, ``delta`` in ``[0, 1e6]``. Within it every element stays within
    ``(max(|u|, |f(x0)|) + delta) / min(k_0, k_inf)`` of 0 (``slope_cap <= 1``: between
    ``f^-1(min u - delta)`` and ``f^-1(max u + delta)`` or its start), times
    ``s / (2 - s)`` for a slope cap ``s > 1`` (:func:`output_bound`). The inverse amplifies by ``1 / (dt g')``: it returns finite values
    or raises ``FitDivergedError``.
    """

    k0: np.ndarray
    k_inf: np.ndarray
    y_s: np.ndarray
    g: np.ndarray
    v_g: np.ndarray
    delta: np.ndarray
    n_elements: int = field(init=False)

    def __post_init__(self) -> None:
        n = np.size(self.k0)
        object.__setattr__(self, "n_elements", int(n))
        freeze_arrays(self, **dict.fromkeys(_FIELDS, n))
        for name in _FIELDS[:5]:
            if np.any(getattr(self, name) <= 0):
                raise ValueError(f"{name} must be positive (f and g strictly increasing, eq. 2.3)")
        if np.any(self.delta < 0):
            raise ValueError("delta (dead band of g) must be >= 0")
        for name, (low, high) in DOMAIN.items():
            values = getattr(self, name)
            bad = values[(values < low) | (values > high)]
            if bad.size:
                raise ValueError(f"{name} must lie in [{low:g}, {high:g}] (the domain where "
                                 f"runs stay bounded), got {float(bad[0]):g}")

    def to_vector(self) -> np.ndarray:
        cols = [np.log(getattr(self, name)) for name in _FIELDS[:5]] + [self.delta]
        return np.column_stack(cols).reshape(-1)

    @classmethod
    def from_vector(cls, theta: np.ndarray, n_elements: int) -> ChuaParams:
        t = np.asarray(theta, dtype=float).reshape(n_elements, 6)
        return cls(*np.exp(t[:, :5]).T, delta=t[:, 5])


def output_bound(structure: ChuaStructure, params: ChuaParams, u_max: float) -> float:
    """``q sum_k (u_max + delta_k) / min(k_0, k_inf)_k`` with ``q = max(1, s / (2 - s))``,
    ``s`` the slope cap: no output of a run whose inputs, and the restoring forces
    ``f_k(x0_k)`` of its start, stay within ``u_max`` in magnitude exceeds it.

    Each element's band of equilibria lies within ``E_k = (u_max + delta_k) / min(k_0,
    k_inf)`` of 0 (``|f^-1(v)| <= |v| / min(k_0, k_inf)``), and a step multiplies the distance
    to it by ``1 - dt g' f'`` in ``[1 - s, 1]``: no overshoot for ``s <= 1``; beyond, an
    overshoot of at most ``s - 1`` times the distance, whose worst alternation settles at
    ``s E_k / (2 - s)``.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    u_max : float
        Bound on the magnitude of the inputs and of the start's restoring forces.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    q = max(1.0, structure.slope_cap / (2.0 - structure.slope_cap))
    return float(q * np.sum((u_max + params.delta) / np.minimum(params.k0, params.k_inf)))


def limits(structure: ChuaStructure, params: ChuaParams) -> tuple[np.ndarray, np.ndarray]:
    """Per element: the cap on ``g'`` and the knee ``|v|`` beyond which ``g`` is straight.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.

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


def restoring(params: ChuaParams, y: np.ndarray) -> np.ndarray:
    """``f_k(y_k)``; ``y`` of shape (..., N).

    Parameters
    ----------
    params : ChuaParams
        The model's parameters.
    y : numpy.ndarray, shape (..., N)
        Element outputs.

    Returns
    -------
    numpy.ndarray, shape (..., N)
        ``f_k(y_k)``.
    """
    y = np.asarray(y, dtype=float)
    return params.k_inf * y + (params.k0 - params.k_inf) * params.y_s * np.tanh(y / params.y_s)


def restoring_inverse(params: ChuaParams, u: float) -> np.ndarray:
    """``f_k^-1(u)`` for every element, shape (N,), by bisection to float resolution.

    ``|f(y) - k_inf y| <= |k_0 - k_inf| y_s`` brackets the root.

    Parameters
    ----------
    params : ChuaParams
        The model's parameters.
    u : float
        Input.

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``f_k^-1(u)``.
    """
    return kernels.restoring_inverse(float(u), params.k0, params.k_inf, params.y_s)


def dissipation(structure: ChuaStructure, params: ChuaParams, v: np.ndarray) -> np.ndarray:
    """Limited ``g_k(v_k)`` (dead band, sinh, straight line beyond the knee); shape (..., N).

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
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


def dissipation_slope(structure: ChuaStructure, params: ChuaParams,
                      v: np.ndarray) -> np.ndarray:
    """``g_k'(v_k)`` of the limited dissipation function: 0 in the dead band, the sinh's slope
    up to the knee, ``cap`` beyond (on a kink, the inner side's).

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
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


def step(structure: ChuaStructure, params: ChuaParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One Euler step with input ``u``; the output is the sum of the updated element states.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Element outputs ``y_k`` before the step.
    u : float
        Input of the sample.

    Returns
    -------
    y : float
        Output: the sum of the updated element states.
    x_next : numpy.ndarray
        State after the sample.
    """
    x = np.asarray(x, dtype=float)
    x_next = x + structure.dt * dissipation(structure, params, u - restoring(params, x))
    return float(np.sum(x_next)), x_next


def invert_step(structure: ChuaStructure, params: ChuaParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """The input that makes :func:`step` return ``y``, and the state it leaves.

    ``sum_k g_k(u - f_k(x_k)) = (y - sum_k x_k) / dt`` is solved by bisection (its left side is
    non-decreasing in ``u``); where it is flat (no element moves, dead bands) the middle of the
    flat interval is taken. An output within ``REST_TOL max(1, |y|, sum |x_k|)`` of the present
    ``sum x_k`` is that output (``r = 0``): rounding must not decide which edge of a dead band
    the input jumps to.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    x : numpy.ndarray, shape (N,)
        Element outputs ``y_k`` before the step.
    y : float
        Output to reach at this sample.

    Returns
    -------
    u : float
        Input that gives `y` from the present state.
    x_next : numpy.ndarray
        State after the sample.
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


def _check(structure: ChuaStructure, params: ChuaParams, u: np.ndarray,
           name: str) -> np.ndarray:
    check_size(params.n_elements, structure.n_elements, "elements")
    return check_signal(u, name)


def rest_state(structure: ChuaStructure, params: ChuaParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """Element outputs at rest (``g = 0``) under a constant input ``value``, ``f_k^-1(value)``;
    with ``inverse``, for a constant output ``value``: the common input ``u`` with
    ``sum_k f_k^-1(u) = value`` first. These are the starts of ``simulate`` / ``invert`` with
    ``x0=None``.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
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
        value = kernels.rest_input(float(value), params.k0, params.k_inf, params.y_s)
    return restoring_inverse(params, value)


def _initial_state(structure: ChuaStructure, params: ChuaParams,
                   x0: np.ndarray | float | None, u0: float) -> np.ndarray:
    if x0 is None:
        return rest_state(structure, params, u0)
    return broadcast_state(x0, params.n_elements)


def kernel_args(structure: ChuaStructure, params: ChuaParams) -> tuple:
    """The compiled kernels' parameter arguments, in their order.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.

    Returns
    -------
    tuple
        ``(k_0, k_inf, y_s, G, V_g, delta, knee, cap, dt)``; knee and cap from :func:`limits`.
    """

    cap, knee = limits(structure, params)
    return (params.k0, params.k_inf, params.y_s, params.g, params.v_g, params.delta, knee, cap,
            structure.dt)


def simulate(structure: ChuaStructure, params: ChuaParams, u: np.ndarray,
             x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the model over an input sequence (compiled kernel).

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    u : array, shape (n,)
        Input sampled every ``structure.dt``.
    x0 : array, shape (N,), float or None
        Initial element outputs ``y_k``; ``None`` starts every element at rest at the first
        input, ``y_k = f_k^-1(u_0)`` (``g = 0``).

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (N,)
        Element outputs after the last sample; feeding them back as ``x0`` continues the run.
    """
    u = _check(structure, params, u, "u")
    x = _initial_state(structure, params, x0, u[0])
    y, x_end = kernels.simulate(u, x, *kernel_args(structure, params))
    return check_finite_run(y, "Chua-Stromsmoe"), x_end


def simulate_reference(structure: ChuaStructure, params: ChuaParams, u: np.ndarray,
                       x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step`.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Input sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial element outputs, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    u = _check(structure, params, u, "u")
    x = _initial_state(structure, params, x0, u[0])
    return run_steps(step, structure, params, u, x)


def invert(structure: ChuaStructure, params: ChuaParams, y: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Exact inverse of :func:`simulate`: the input sequence that produces ``y``.

    Each sample solves the Euler step for its input by bisection (:func:`invert_step`), so
    ``simulate(invert(y))`` returns ``y``. The input is unique wherever some element moves;
    with dead bands and a constant output it is any point of the band, and the middle is
    returned. An output equal to the present one to rounding (relative ``REST_TOL = 1e-12``
    of ``max(1, |y|, sum |y_k|)``) counts as constant: otherwise the rounding of the state's
    sum would pick one edge of the band or the other (a jump of ``2 delta``), and a constant
    output from the start would not come back from ``simulate``'s rest start. The inverse amplifies output noise by ``1 / (dt g')``.

    Parameters
    ----------
    structure : ChuaStructure
        The model's structure.
    params : ChuaParams
        Its parameters.
    y : array, shape (n,)
    x0 : array, shape (N,), float or None
        Initial element outputs; ``None`` splits ``y_0`` over the elements as their rest
        state for a common input ``u`` with ``sum_k f_k^-1(u) = y_0``.

    Returns
    -------
    u : numpy.ndarray, shape (n,)
        Input that gives `y`.
    x_end : numpy.ndarray
        State after the last sample.

    Raises
    ------
    FitDivergedError
        If the input estimate leaves the finite range (|u| > 1e6 (1 + max |y|)).
    """
    y = _check(structure, params, y, "y")
    if x0 is None:
        x = rest_state(structure, params, y[0], inverse=True)
    else:
        x = _initial_state(structure, params, x0, 0.0)
    u_hat, x_end, n_bad = kernels.invert(y, x, *kernel_args(structure, params))
    if n_bad >= 0:
        raise FitDivergedError(f"the inverse Chua-Stromsmoe model diverged at sample {n_bad} "
                               f"of {y.size}")
    return check_finite_run(u_hat, "Chua-Stromsmoe", "inverse"), x_end
