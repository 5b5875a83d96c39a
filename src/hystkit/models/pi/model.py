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
and :func:`invert` alike, so model and compensator can be synchronised. The records are in
:mod:`.records`, the operators in :mod:`.operators`; both are importable from here.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...errors import FitDivergedError
from .._docs import docfiller
from .._run import Runs, family_runs
from .._validation import check_finite_run
from . import kernels
from .operators import (
    deadzone,
    inverse_pi,
    inverse_play_states,
    inverse_superposition,
    play,
)
from .records import (
    INVERSE_MIN_SLOPE,
    MAX_CREEP,
    MAX_DEADZONES,
    MAX_PLAYS,
    MAX_VALUE,
    PiParams,
    PiStructure,
    output_bound,
)

fill_doc = docfiller("PiStructure", "PiParams", state="""\
x : numpy.ndarray, shape (n_play + n_creep,)
    Play outputs then creep states before the sample.""")

__all__ = ["MAX_CREEP", "MAX_DEADZONES", "MAX_PLAYS", "MAX_VALUE", "InverseParts", "PiParams", "PiStructure", "deadzone", "instantaneous_weights",
           "inverse_parts", "inverse_pi", "inverse_play_states", "inverse_superposition",
           "invert", "invert_step", "not_invertible_reason", "output_bound", "play", "rest_input", "rest_state",
           "simulate", "simulate_reference", "step"]


@fill_doc
def instantaneous_weights(structure: PiStructure, params: PiParams) -> np.ndarray:
    """Play weights of ``H~ = H + kappa x``, the operator one sample of ``H + K`` applies.

    %(records_parameters)s

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


@fill_doc
def inverse_parts(structure: PiStructure, params: PiParams) -> InverseParts:
    """The inverse operators: polarity ``sign`` of ``H~`` (the polarity lives in ``H``, ``S``
    increases), its weights ``w_inst``, the inverse plays of ``sign * H~`` and ``S^-1``.

    %(records_parameters)s

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


@fill_doc
def rest_input(params: PiParams, y0: float) -> float:
    """The input at rest at output ``y0``: ``(S^-1(y0) - b) / (sum w_H + sum w_K)``.

    Parameters
    ----------
    %(params)s
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


@fill_doc
def rest_state(structure: PiStructure, params: PiParams, value: float,
               inverse: bool = False) -> np.ndarray:
    """State at rest: every play and creep state at the input ``value`` (where :func:`simulate`
    starts), or for ``inverse`` at the input at rest at the output ``value`` (:func:`invert`'s
    start, :func:`rest_input`).

    %(rest_state)s
    """
    u = rest_input(params, float(value)) if inverse else float(value)
    return np.full(structure.n_play + structure.n_creep, u)


def _superposition(params: PiParams, v: float) -> float:
    return float(params.w_s @ deadzone(v, params.d_s))


@fill_doc
def step(structure: PiStructure, params: PiParams, x: np.ndarray,
         u: float) -> tuple[float, np.ndarray]:
    """One sample of the forward model (the readable reference of the kernel): output ``y =
    S[H[u] + K[u] + b]`` with the states after this sample (eq. 2.12-2.15).

    %(step)s
    """
    x = np.asarray(x, dtype=float)
    p = play(u, x[: structure.n_play], np.asarray(structure.play_thresholds))
    z = x[structure.n_play:] + structure.creep_gains * (u - x[structure.n_play:])
    y = _superposition(params, params.w_h @ p + params.w_k @ z + params.b)
    return y, np.concatenate([p, z])


@fill_doc
def invert_step(structure: PiStructure, params: PiParams, x: np.ndarray,
                y: float) -> tuple[float, np.ndarray]:
    """One sample of the inverse model on the forward state (the reference of the kernel).

    The instantaneous operator ``H~`` is inverted with inverse plays built from the present
    play states; the estimate then advances the forward state as :func:`step` would.
    Needs an invertible model (see :func:`invert`).

    %(invert_step)s
    """
    x = np.asarray(x, dtype=float)
    n, c = structure.n_play, structure.creep_gains
    sign, w_inst, r_inv, w_inv, d_inv, ws_inv = inverse_parts(structure, params)
    v = float(ws_inv @ deadzone(y, d_inv)) - params.b - params.w_k @ ((1 - c) * x[n:])
    q = play(sign * v, inverse_play_states(sign * w_inst, x[:n]), r_inv)
    u_hat = float(w_inv @ q)
    return u_hat, step(structure, params, x, u_hat)[1]


def _check_params(structure: PiStructure, params: PiParams) -> None:
    ours = (params.n_play, params.n_deadzone, params.n_creep)
    theirs = (structure.n_play, structure.n_deadzone, structure.n_creep)
    if ours != theirs:
        raise ValueError(f"params have (plays, dead zones per side, creep operators) = {ours}, "
                         f"the structure {theirs}")


def _check(structure: PiStructure, params: PiParams, inverse: bool) -> None:
    if not inverse:
        _check_params(structure, params)
        return
    reason = not_invertible_reason(structure, params)
    if reason:
        raise FitDivergedError(f"the model has no inverse: {reason}")


def _forward(structure: PiStructure, params: PiParams, u: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = structure.n_play
    y, p, z = kernels.simulate(u, x[:n].copy(), x[n:].copy(),
                               np.asarray(structure.play_thresholds), params.w_h, params.d_s,
                               params.w_s, structure.creep_gains, params.w_k, params.b)
    return y, np.concatenate([p, z])


def _inverse(structure: PiStructure, params: PiParams, y: np.ndarray,
             x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = structure.n_play
    sign, w_inst, r_inv, w_inv, d_inv, ws_inv = inverse_parts(structure, params)
    # The kernel inverts sign * H~; feeding it sign * (everything on the right-hand side) is
    # the same as negating b, the creep weights and S^-1. It carries the forward state, as
    # the family's block does, so a stream of blocks gives these bits.
    u_hat, p, z, n_bad = kernels.invert(y, x[:n].copy(), x[n:].copy(),
                                        np.asarray(structure.play_thresholds), r_inv, w_inv,
                                        sign * w_inst, d_inv, sign * ws_inv,
                                        structure.creep_gains, sign * params.w_k,
                                        sign * params.b)
    if n_bad >= 0:
        raise FitDivergedError(
            f"the inverse model diverged at sample {n_bad} of {y.size} (|u_hat| > 1e6 times the "
            f"output range); its creep weights make the compensator unstable on this data")
    x_end = np.concatenate([p, z])
    return check_finite_run(u_hat, "PI", "inverse"), check_finite_run(x_end, "PI", "state")


@fill_doc
def not_invertible_reason(structure: PiStructure, params: PiParams) -> str:
    """Why the model has no inverse, or ``""`` if it has one.

    The instantaneous play weights ``w~`` need partial sums of one sign (a strictly monotone
    loading curve, either polarity) and the dead-zone weights partial sums that are positive
    from ``d = 0`` outwards (an increasing ``S``), all at least ``INVERSE_MIN_SLOPE`` (1e-6) in
    magnitude so that the inverse's slopes stay below 1e6 (the fit's are below 100).

    %(records_parameters)s

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


RUNS = Runs(label="PI", step=step,
            n_state=lambda structure, params: structure.n_play + structure.n_creep,
            rest_state=rest_state, forward=_forward, inverse=_inverse, check=_check,
            layout="plays, then creep states")
simulate, simulate_reference, invert = family_runs(
    RUNS, __name__, "the Prandtl-Ishlinskii model with creep",
    notes="The state is the play outputs, then the creep states. At rest (``x0=None``) every "
          "state is ``u[0]``, the state a decaying oscillation about ``u[0]`` leaves behind "
          "(the demagnetised state, shifted).",
    inverse_notes="eq. 2.19 with creep. The state is the *forward* state (as for ``simulate``), "
                  "so model and compensator can be synchronised; the inverse is exact when the "
                  "play states are reachable ones (the rest start, a float or any ``x_end``). The "
                  "rest start is the input at rest at ``y[0]``, ``u_0 = (S^-1(y_0) - b) / "
                  "(sum w_H + sum w_K)`` (:func:`rest_input`). FitDivergedError when the model "
                  "is not invertible (:func:`not_invertible_reason`) or negative creep weights "
                  "beyond the fit's constraints make it unstable.")
