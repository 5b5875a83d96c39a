"""Kuhnen's modified Prandtl-Ishlinskii model with creep, sec. 2.1.6 of the reference document.

Operators (eq. 2.6-2.15), for an input ``x`` sampled every ``dt``::

    play      p_i(t) = max(x - r_i, min(x + r_i, p_i(t-)))       0 = r_0 < r_1 < ...   eq. 2.11
    PI        H[x]   = sum_i w_Hi p_i                                                   eq. 2.7
    creep     z_j(t) = z_j(t-) + c_j (x - z_j(t-)),  c_j = 1 - exp(-a_j dt)             eq. 2.14
              K[x]   = sum_j w_Kj z_j
    dead zone S_d(v) = max(v - d, 0) (d > 0),  v (d = 0),  min(v - d, 0) (d < 0)
    output    y      = S[H[x] + K[x] + b] = sum_k w_Sk S_dk(H[x] + K[x] + b)            eq. 2.12

The play recursion is exact for the input interpolated linearly between samples (only turning
points matter: rate independence). Each creep operator is Kuhnen's linear creep operator
``dz/dt = a (x - z)``, discretised exactly for an input held over the sample that ends at ``t``;
eigenvalues a decade apart give a step response linear in ``log t`` (fig. 2.13).

Deliberate readings of the document (details and reasons in ``docs/models/pi.md``): eq. 2.11's
third argument is the previous output ``y``; the stray ``· i`` of eq. 2.14-2.15 is dropped;
creep enters *inside* ``S`` (``S[H + K]``, eq. 2.15 prints ``S[H] + K``), which keeps
Kuhnen's generalised-error identification linear with creep; the creep thresholds ``r_K`` are 0;
eq. 2.19 swaps the operators -- the inverse is ``H^-1[S^-1[y]]``, dead zones first; an offset
``b`` inside ``S`` (like ``V_b`` of eq. 5.2) absorbs the mean centred data leave.

Inverse (eq. 2.19). A PI operator whose partial sums ``W_i = w_0 + .. + w_i`` are all positive
is inverted by the PI operator with ``r'_i = sum_{j<=i} w_j (r_i - r_j)``, ``w'_0 = 1/w_0``,
``w'_i = -w_i / (W_i W_{i-1})`` and play states ``q_i = W_i p_i + sum_{j>i} w_j p_j``; ``S``
by the same formulas on each side of ``d = 0``. Within a sample ``K`` adds ``kappa x``
(``kappa = sum_j w_Kj c_j``) plus a part the past fixed, and ``kappa x`` is a play of threshold
0, so ``H~ = H + kappa x`` is again a PI operator: per sample the inverse solves exactly
``H~[x] = S^-1[y] - b - sum_j w_Kj (1 - c_j) z_j`` (creep applied to the estimated input, no
iteration), and ``compensator o model`` is the identity to rounding, with or without creep.

State ``x = [p_0 .. p_{n-1}, z_1 .. z_m]`` (play outputs, creep states), for :func:`simulate`
and :func:`invert` alike, so model and compensator can be synchronised.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ...errors import FitDivergedError
from .._protocol import Record
from .._validation import (
    check_dt,
    check_finite_run,
    check_signal,
    finite_floats,
    freeze_arrays,
    frozen_array,
    initial_state,
    run_steps,
)
from . import kernels

__all__ = ["MAX_CREEP", "MAX_DEADZONES", "MAX_PLAYS", "MAX_VALUE", "InverseParts", "PiParams", "PiStructure", "deadzone", "instantaneous_weights",
           "inverse_parts", "inverse_pi", "inverse_play_states", "inverse_superposition",
           "invert", "invert_step", "not_invertible_reason", "output_bound", "play", "rest_input", "rest_state",
           "simulate", "simulate_reference", "step"]


# Sizes: a sample costs O(plays + dead zones + creep operators); the fit's regressor matrix
# holds n_play + 2 n_creep + 2 n_deadzone + 1 columns, 10 kB a sample at the caps.
MAX_PLAYS = 1000
MAX_DEADZONES = 100  # per side
MAX_CREEP = 20
MAX_VALUE = 1e6  # weights, thresholds and |b| in normalised units (fit: slopes <= ~100)
INVERSE_MIN_SLOPE = 1 / MAX_VALUE  # smallest slope partial sum with an inverse (fit: >= 0.01)


def _check_count(values, maximum: int, name: str) -> None:
    """Refuse more than ``maximum`` values before any array is built from them."""
    if np.ndim(values) > 0 and len(values) > maximum:
        raise ValueError(f"{name} may hold at most {maximum} values, got {len(values)}")


def _check_magnitude(values, name: str) -> None:
    if np.any(np.abs(values) > MAX_VALUE):
        raise ValueError(f"{name} must be at most {MAX_VALUE:g} in magnitude (the domain where "
                         f"runs stay bounded), got {float(np.max(np.abs(values))):g}")


def _float_tuple(values, name: str) -> tuple[float, ...]:
    return tuple(frozen_array(values, None, name).tolist())


@dataclass(frozen=True)
class PiStructure(Record):
    """What does not get fitted: operator thresholds, creep eigenvalues and the sample time.

    Parameters
    ----------
    play_thresholds : tuple of float
        ``r_0 = 0 < r_1 < ... <= MAX_VALUE`` in input units (eq. 2.11); their number is the
        model size, at most ``MAX_PLAYS`` (1000).
    n_deadzone : int
        One-sided dead-zone operators on *each* side of ``d = 0`` (eq. 2.12), at most
        ``MAX_DEADZONES`` (100); 0 makes ``S`` linear. Their thresholds are fitted (they follow from the output range), so they live
        in :class:`PiParams`.
    creep_rates : tuple of float
        Eigenvalues ``a_j`` [1/s] of the linear creep operators (eq. 2.14), at most
        ``MAX_CREEP`` (20); empty for the rate-independent model. At the size caps a sample
        costs about 1300 operator updates and the fit's regressors 10 kB.
    dt : float
        Sample time [s]. The plays are rate independent; the creep operators are not, and
        their per-sample gains :attr:`creep_gains` follow from the rates and ``dt``, so the
        same structure at another ``dt`` is the same continuous-time model.
    """

    play_thresholds: tuple[float, ...] = (0.0,)
    n_deadzone: int = 0
    creep_rates: tuple[float, ...] = ()
    dt: float = 0.025

    def __post_init__(self) -> None:
        _check_count(self.play_thresholds, MAX_PLAYS, "play_thresholds")
        _check_count(self.creep_rates, MAX_CREEP, "creep_rates")
        if not (isinstance(self.n_deadzone, int | float) and self.n_deadzone <= MAX_DEADZONES):
            raise ValueError(f"n_deadzone must be an integer in [0, {MAX_DEADZONES}], got "
                             f"{self.n_deadzone!r}")
        r = _float_tuple(self.play_thresholds, "play_thresholds")
        _check_magnitude(r, "play_thresholds")
        object.__setattr__(self, "play_thresholds", r)
        if r[0] != 0.0 or np.any(np.diff(r) <= 0):
            raise ValueError(f"play_thresholds must start at 0 and increase strictly, got {r}")
        rates = _float_tuple(self.creep_rates, "creep_rates")
        object.__setattr__(self, "creep_rates", rates)
        if any(a <= 0 for a in rates):
            raise ValueError(f"creep_rates must be positive eigenvalues [1/s], got {rates}")
        if int(self.n_deadzone) != self.n_deadzone or self.n_deadzone < 0:
            raise ValueError(f"n_deadzone must be a non-negative integer, got {self.n_deadzone!r}")
        check_dt(self.dt)

    @property
    def n_play(self) -> int:
        return len(self.play_thresholds)

    @property
    def n_creep(self) -> int:
        return len(self.creep_rates)

    @property
    def creep_gains(self) -> np.ndarray:
        """``c_j = 1 - exp(-a_j dt)``: the fraction of the gap a creep state closes per sample."""
        return -np.expm1(-np.asarray(self.creep_rates, dtype=float) * self.dt)


@dataclass(frozen=True, eq=False)
class PiParams(Record):
    """Fitted quantities of a modified PI model.

    Parameters
    ----------
    w_h : array, shape (n_play,)
        Play weights ``w_H`` (eq. 2.7).
    w_s : array, shape (2 n_deadzone + 1,)
        Dead-zone weights ``w_S`` (eq. 2.12); the middle one belongs to ``d = 0``.
    d_s : array, shape (2 n_deadzone + 1,)
        Dead-zone thresholds ``d_-m < .. < d_0 = 0 < .. < d_m`` in units of ``H + K + b``.
    w_k : array, shape (n_creep,)
        Creep weights ``w_K`` (eq. 2.14).
    b : float
        Offset inside ``S``.

    Notes
    -----
    Domain: every weight, threshold and ``|b|`` at most ``MAX_VALUE`` (1e6, normalised units;
    the fit's slopes are at most ~100). Plays and creep states stay within ``M = max(|u|,
    |x0|)`` and ``|S_d(v)| <= |v|``, so ``|y| <= sum |w_S| ((sum |w_H| + sum |w_K|) M + |b|)``
    (:func:`output_bound`). The inverse returns finite values or raises ``FitDivergedError``.
    """

    w_h: np.ndarray
    w_s: np.ndarray = (1.0,)
    d_s: np.ndarray = (0.0,)
    w_k: np.ndarray = ()
    b: float = 0.0
    n_play: int = field(init=False)
    n_deadzone: int = field(init=False)
    n_creep: int = field(init=False)

    def __post_init__(self) -> None:
        _check_count(self.w_h, MAX_PLAYS, "w_h")
        _check_count(self.w_s, 2 * MAX_DEADZONES + 1, "w_s")
        _check_count(self.w_k, MAX_CREEP, "w_k")
        freeze_arrays(self, w_h=None, w_s=None)
        freeze_arrays(self, d_s=self.w_s.size, w_k=None)
        finite_floats(self, "b")
        for name in ("w_h", "w_s", "d_s", "w_k", "b"):
            _check_magnitude(getattr(self, name), name)
        m = (self.d_s.size - 1) // 2
        if self.w_h.size < 1 or self.d_s.size % 2 == 0 or self.d_s[m] != 0.0 \
                or np.any(np.diff(self.d_s) <= 0):
            raise ValueError(f"need at least one play weight, and dead-zone thresholds that "
                             f"increase strictly with 0 in the middle (eq. 2.12), got w_h "
                             f"{self.w_h.tolist()}, d_s {self.d_s.tolist()}")
        object.__setattr__(self, "n_play", int(self.w_h.size))
        object.__setattr__(self, "n_deadzone", int(m))
        object.__setattr__(self, "n_creep", int(self.w_k.size))

    def to_dict(self) -> dict:
        """Record's dict, with the centre threshold ``d_0 = 0`` written as the integer 0: it is
        structural, not fitted, and generic parameter vectors keep integers fixed
        (``compensation._param_vector``). Same keys and values as before (``0 == 0.0``)."""
        d = super().to_dict()
        d["d_s"][self.n_deadzone] = 0
        return d


def output_bound(params: PiParams, u_max: float) -> float:
    """``sum |w_S| ((sum |w_H| + sum |w_K|) u_max + |b|)``: no output of a run whose inputs
    and initial states stay within ``u_max`` in magnitude exceeds it.

    Parameters
    ----------
    params : PiParams
        Its parameters.
    u_max : float
        Bound on the magnitude of the inputs and the initial states.

    Returns
    -------
    float
        The bound on ``|y|``.
    """
    inner = (np.abs(params.w_h).sum() + np.abs(params.w_k).sum()) * u_max + abs(params.b)
    return float(np.abs(params.w_s).sum() * inner)


def play(x: np.ndarray | float, y_prev: np.ndarray | float,
         r: np.ndarray | float) -> np.ndarray:
    """Elementary play operator ``max(x - r, min(x + r, y_prev))`` (eq. 2.11).

    Parameters
    ----------
    x : numpy.ndarray or float
        Input.
    y_prev : numpy.ndarray or float
        Previous play output.
    r : numpy.ndarray or float
        Threshold.

    Returns
    -------
    numpy.ndarray
        The play output, the broadcast shape.
    """
    return np.maximum(np.subtract(x, r), np.minimum(np.add(x, r), y_prev))


def deadzone(v: np.ndarray | float, d: np.ndarray | float) -> np.ndarray:
    """One-sided dead-zone operator ``S_d(v)`` (eq. 2.12); broadcasts over ``v`` and ``d``.

    Parameters
    ----------
    v : numpy.ndarray or float
        Operator input.
    d : numpy.ndarray or float
        Thresholds.

    Returns
    -------
    numpy.ndarray
        ``S_d(v)``, the broadcast shape.
    """
    v, d = np.broadcast_arrays(np.asarray(v, dtype=float), np.asarray(d, dtype=float))
    return np.where(d > 0, np.maximum(v - d, 0.0), np.where(d < 0, np.minimum(v - d, 0.0), v))


def inverse_pi(r: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Thresholds and weights, shape (n,) each, of the inverse PI operator (eq. 2.19, Kuhnen).

    For thresholds ``0 = r_0 < r_1 < ...`` and weights whose partial sums ``W_i`` (the slopes
    of the initial loading curve between ``r_i`` and ``r_{i+1}``) are all positive:
    ``r'_i = sum_{j<=i} w_j (r_i - r_j)`` (the loading curve at ``r_i``), ``w'_0 = 1 / w_0``,
    ``w'_i = -w_i / (W_i W_{i-1})`` (slopes ``1 / W_i``).

    Parameters
    ----------
    r : numpy.ndarray, shape (n,)
        Thresholds, ``0 = r_0 < r_1 < ...``.
    w : numpy.ndarray, shape (n,)
        Weights with positive partial sums.

    Returns
    -------
    r_inv, w_inv : numpy.ndarray, shape (n,)
        Thresholds and weights of the inverse.
    """
    r, w = np.asarray(r, dtype=float), np.asarray(w, dtype=float)
    big_w = np.cumsum(w)
    r_inv = np.concatenate([[0.0], np.cumsum(big_w[:-1] * np.diff(r))])
    w_inv = np.diff(1.0 / big_w, prepend=0.0)
    return r_inv, w_inv


def inverse_superposition(d: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Thresholds and weights of the inverse superposition operator ``S^-1`` (eq. 2.19).

    Each side of ``d_0 = 0`` is a PI-like initial loading curve: the inverse has thresholds
    ``d'_k = S(d_k)`` and weights from the inverse slopes, as :func:`inverse_pi`. Needs the
    partial sums ``w_0 + .. + w_k`` (k >= 0) and ``w_0 + .. + w_-k`` all positive.

    Parameters
    ----------
    d : numpy.ndarray, shape (2 m + 1,)
        Dead-zone thresholds, ``d_0 = 0`` in the middle.
    w : numpy.ndarray, shape (2 m + 1,)
        Their weights.

    Returns
    -------
    d_inv, w_inv : numpy.ndarray, shape (2 m + 1,)
        Thresholds and weights of ``S^-1``.
    """
    d, w = np.asarray(d, dtype=float), np.asarray(w, dtype=float)
    m = (d.size - 1) // 2
    d_inv, w_inv = np.empty_like(d), np.empty_like(w)
    for side in (slice(m, None), slice(m, None, -1)):  # centre outwards, each direction
        d_inv[side], w_inv[side] = inverse_pi(np.abs(d[side]), w[side])
    d_inv[:m] *= -1.0
    return d_inv, w_inv


def inverse_play_states(w: np.ndarray, p: np.ndarray) -> np.ndarray:
    """States ``q_i = W_i p_i + sum_{j>i} w_j p_j`` of the inverse plays that continue a PI
    operator with weights ``w`` and play states ``p`` (both shape (n,)).

    Parameters
    ----------
    w : numpy.ndarray, shape (n,)
        Weights of the PI operator.
    p : numpy.ndarray, shape (n,)
        Its play states.

    Returns
    -------
    numpy.ndarray, shape (n,)
        The inverse plays' states ``q``.
    """
    w, p = np.asarray(w, dtype=float), np.asarray(p, dtype=float)
    tail = np.concatenate([np.cumsum((w * p)[::-1])[::-1][1:], [0.0]])
    return np.cumsum(w) * p + tail


def instantaneous_weights(structure: PiStructure, params: PiParams) -> np.ndarray:
    """Play weights of ``H~ = H + kappa x``, the operator one sample of ``H + K`` applies.

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.

    Returns
    -------
    numpy.ndarray, shape (n_play,)
        ``w_H`` with ``kappa = sum_j w_Kj c_j`` added to ``w_0``.
    """
    w = params.w_h.copy()
    w[0] += params.w_k @ structure.creep_gains
    return w


class InverseParts(NamedTuple):
    """What one inverse sample needs (eq. 2.19 with creep), see :func:`inverse_parts`.

    Parameters
    ----------
    sign : float
        Polarity of ``H~`` (+1 or -1).
    w_inst : numpy.ndarray, shape (n_play,)
        Weights of ``H~`` (:func:`instantaneous_weights`).
    r_inv, w_inv : numpy.ndarray, shape (n_play,)
        Thresholds and weights of the inverse of ``sign * H~``.
    d_inv, ws_inv : numpy.ndarray, shape (2 n_deadzone + 1,)
        Thresholds and weights of ``S^-1``.
    """

    sign: float
    w_inst: np.ndarray
    r_inv: np.ndarray
    w_inv: np.ndarray
    d_inv: np.ndarray
    ws_inv: np.ndarray


def inverse_parts(structure: PiStructure, params: PiParams) -> InverseParts:
    """The inverse operators: polarity ``sign`` of ``H~`` (the polarity lives in ``H``, ``S``
    increases), its weights ``w_inst``, the inverse plays of ``sign * H~`` and ``S^-1``.

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.

    Returns
    -------
    InverseParts
        The inverse operators.
    """
    w_inst = instantaneous_weights(structure, params)
    sign = 1.0 if w_inst[0] > 0 else -1.0
    r_inv, w_inv = inverse_pi(np.asarray(structure.play_thresholds), sign * w_inst)
    d_inv, ws_inv = inverse_superposition(params.d_s, params.w_s)
    return InverseParts(sign, w_inst, r_inv, w_inv, d_inv, ws_inv)


def rest_input(params: PiParams, y0: float) -> float:
    """The input at rest at output ``y0``: ``(S^-1(y0) - b) / (sum w_H + sum w_K)``.

    Parameters
    ----------
    params : PiParams
        The model's parameters.
    y0 : float
        Output at rest.

    Returns
    -------
    float
        The input.

    Raises
    ------
    FitDivergedError
        If the static gain ``sum w_H + sum w_K`` is (nearly) 0.
    """
    gain = params.w_h.sum() + params.w_k.sum()
    if not abs(gain) >= INVERSE_MIN_SLOPE:  # 1 / gain would leave the domain (or the float range)
        raise FitDivergedError(f"the model's static gain sum(w_H) + sum(w_K) = {gain:g} is "
                               f"(nearly) 0: no input is at rest at y[0]; pass x0")
    d_inv, ws_inv = inverse_superposition(params.d_s, params.w_s)
    return (float(ws_inv @ deadzone(y0, d_inv)) - params.b) / gain


def rest_state(structure: PiStructure, params: PiParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """State at rest: every play and creep state at the input ``value`` (where :func:`simulate`
    starts), or for ``inverse`` at the input at rest at the output ``value`` (:func:`invert`'s
    start, :func:`rest_input`).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
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
    u = rest_input(params, float(value)) if inverse else float(value)
    return np.full(structure.n_play + structure.n_creep, u)


def _superposition(params: PiParams, v: float) -> float:
    return float(params.w_s @ deadzone(v, params.d_s))


def step(structure: PiStructure, params: PiParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model (the readable reference of the kernel).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.
    x : numpy.ndarray, shape (n_play + n_creep,)
        Play outputs then creep states before the sample.
    u : float
        Input of the sample.

    Returns
    -------
    y : float
        ``S[H[u] + K[u] + b]`` with the states after this sample (eq. 2.12-2.15).
    x_next : array, shape (n_play + n_creep,)
    """
    x = np.asarray(x, dtype=float)
    p = play(u, x[: structure.n_play], np.asarray(structure.play_thresholds))
    z = x[structure.n_play:] + structure.creep_gains * (u - x[structure.n_play:])
    y = _superposition(params, params.w_h @ p + params.w_k @ z + params.b)
    return y, np.concatenate([p, z])


def invert_step(structure: PiStructure, params: PiParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse model on the forward state (the reference of the kernel).

    The instantaneous operator ``H~`` is inverted with inverse plays built from the present
    play states; the estimate then advances the forward state as :func:`step` would.
    Needs an invertible model (see :func:`invert`).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.
    x : numpy.ndarray, shape (n_play + n_creep,)
        Play outputs then creep states before the sample. (the forward state)
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
    n, c = structure.n_play, structure.creep_gains
    sign, w_inst, r_inv, w_inv, d_inv, ws_inv = inverse_parts(structure, params)
    v = float(ws_inv @ deadzone(y, d_inv)) - params.b - params.w_k @ ((1 - c) * x[n:])
    q = play(sign * v, inverse_play_states(sign * w_inst, x[:n]), r_inv)
    u_hat = float(w_inv @ q)
    return u_hat, step(structure, params, x, u_hat)[1]


def _initial_state(structure: PiStructure, x0: np.ndarray | float | None,
                   at_rest: float) -> np.ndarray:
    return initial_state(structure.n_play + structure.n_creep, x0, at_rest,
                         layout="plays, then creep states")


def _check_params(structure: PiStructure, params: PiParams) -> None:
    ours = (params.n_play, params.n_deadzone, params.n_creep)
    theirs = (structure.n_play, structure.n_deadzone, structure.n_creep)
    if ours != theirs:
        raise ValueError(f"params have (plays, dead zones per side, creep operators) = {ours}, "
                         f"the structure {theirs}")


def simulate(structure: PiStructure, params: PiParams, u: np.ndarray,
             x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the forward model over an input sequence (compiled kernel).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.
    u : array, shape (n,)
        Input sampled every ``structure.dt``.
    x0 : array, shape (n_play + n_creep,), float or None
        Initial play outputs then creep states. A float puts every state there; ``None``
        starts at rest at the first input (all states ``= u[0]``), the state a decaying
        oscillation about ``u[0]`` leaves behind (the demagnetised state, shifted).

    Returns
    -------
    y : array, shape (n,)
    x_end : array, shape (n_play + n_creep,)
        State after the last sample; feeding it back as ``x0`` continues the run exactly.
    """
    _check_params(structure, params)
    u = check_signal(u, "u")
    x = _initial_state(structure, x0, u[0])
    n = structure.n_play
    y, p, z = kernels.simulate(u, x[:n].copy(), x[n:].copy(),
                               np.asarray(structure.play_thresholds), params.w_h, params.d_s,
                               params.w_s, structure.creep_gains, params.w_k, params.b)
    return check_finite_run(y, "PI"), np.concatenate([p, z])


def simulate_reference(structure: PiStructure, params: PiParams, u: np.ndarray,
                       x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Same as :func:`simulate`, as a plain loop over :func:`step` (the readable reference).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.
    u : numpy.ndarray, shape (n,)
        Input sampled every ``structure.dt``.
    x0 : numpy.ndarray, float or None, optional
        Initial play outputs then creep states, as for :func:`simulate`.

    Returns
    -------
    y : numpy.ndarray, shape (n,)
        Output.
    x_end : numpy.ndarray
        State after the last sample.
    """
    _check_params(structure, params)
    u = check_signal(u, "u")
    x = _initial_state(structure, x0, u[0])
    return run_steps(step, structure, params, u, x)


def not_invertible_reason(structure: PiStructure, params: PiParams) -> str:
    """Why the model has no inverse, or ``""`` if it has one.

    The instantaneous play weights ``w~`` need partial sums of one sign (a strictly monotone
    loading curve, either polarity) and the dead-zone weights partial sums that are positive
    from ``d = 0`` outwards (an increasing ``S``), all at least ``INVERSE_MIN_SLOPE`` (1e-6) in
    magnitude so that the inverse's slopes stay below 1e6 (the fit's are below 100).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.

    Returns
    -------
    str
        The reason, or ``""``.
    """
    _check_params(structure, params)
    sums = np.cumsum(instantaneous_weights(structure, params))
    if not (np.all(sums >= INVERSE_MIN_SLOPE) or np.all(sums <= -INVERSE_MIN_SLOPE)):
        return (f"the partial sums of the instantaneous play weights {sums.tolist()} change "
                f"sign or come within {INVERSE_MIN_SLOPE:g} of 0, so H + K is not invertible "
                f"(eq. 2.19) within the domain (inverse slopes up to {1 / INVERSE_MIN_SLOPE:g})")
    m = params.n_deadzone
    for side in (params.w_s[m:], params.w_s[m::-1]):
        if np.any(np.cumsum(side) < INVERSE_MIN_SLOPE):
            return (f"the partial sums of the dead-zone weights {params.w_s.tolist()} are not "
                    f"all at least {INVERSE_MIN_SLOPE:g} from d = 0 outwards, so S is not invertible "
                    f"(eq. 2.19) within the domain")
    return ""


def invert(structure: PiStructure, params: PiParams, y: np.ndarray,
           x0: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the analytical inverse (compensator) over an output sequence (eq. 2.19 with creep).

    Parameters
    ----------
    structure : PiStructure
        The model's structure.
    params : PiParams
        Its parameters.
    y : array, shape (n,)
        Model output (e.g. the sensor signal), sampled every ``structure.dt``.
    x0 : array, shape (n_play + n_creep,), float or None
        Initial *forward* state (as for :func:`simulate`). ``None`` starts at rest at the
        input ``u_0`` that gives ``y[0]`` at rest, ``u_0 = (S^-1(y_0) - b) / (sum w_H + sum
        w_K)``. The inverse is exact when the play states are reachable ones (for example the
        default, a float or any ``x_end``).

    Returns
    -------
    u_hat : array, shape (n,)
        Estimated input.
    x_end : array, shape (n_play + n_creep,)
        Forward state after the last sample (continues :func:`simulate` or :func:`invert`).

    Raises
    ------
    FitDivergedError
        If the model is not invertible (:func:`not_invertible_reason`) or the inverse leaves
        the finite range (negative creep weights beyond what the fit's constraints allow).
    """
    reason = not_invertible_reason(structure, params)
    if reason:
        raise FitDivergedError(f"the model has no inverse: {reason}")
    y = check_signal(y, "y")
    n = structure.n_play
    x = _initial_state(structure, x0, rest_input(params, y[0]) if x0 is None else 0.0)
    sign, w_inst, r_inv, w_inv, d_inv, ws_inv = inverse_parts(structure, params)
    q0 = inverse_play_states(sign * w_inst, x[:n])
    # The kernel inverts sign * H~; feeding it sign * (everything on the right-hand side) is
    # the same as negating b, the creep weights and S^-1.
    u_hat, q, z, n_bad = kernels.invert(y, q0, x[n:].copy(), r_inv, w_inv, d_inv,
                                        sign * ws_inv, structure.creep_gains,
                                        sign * params.w_k, sign * params.b)
    if n_bad >= 0:
        raise FitDivergedError(
            f"the inverse model diverged at sample {n_bad} of {y.size} (|u_hat| > 1e6 times the "
            f"output range); its creep weights make the compensator unstable on this data")
    x_end = np.concatenate([_play_states_from_inverse(sign * w_inst, q), z])
    return check_finite_run(u_hat, "PI", "inverse"), check_finite_run(x_end, "PI", "state")


def _play_states_from_inverse(w: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Inverse of :func:`inverse_play_states`: ``q_i - q_{i+1} = W_i (p_i - p_{i+1})``."""
    big_w = np.cumsum(w)
    steps = np.append(-np.diff(q) / big_w[:-1], q[-1] / big_w[-1])
    return np.cumsum(steps[::-1])[::-1]
