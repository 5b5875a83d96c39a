"""An adapting stream's per-stream constants and steps (:class:`_Plan`): the plain stream's
path, the regressors of the output parameters, the prior, one reference learnt, the band's
quantile tracking and the parameters' domain (:mod:`._adaptive` says what they do)."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..compensation import Compensator
from ..errors import InputError
from ._adaptive_records import (
    BAND_STEP,
    LINEARITY_TOLERANCE,
    MAX_BAND_FACTOR,
    MAX_MULTIPLIER,
    Adaptation,
    AdaptiveState,
    Plausible,
)
from ._readable import _Path, _sensor_offset
from ._rls import RlsState, rls_bound, rls_start, rls_update
from ._stream_state import StreamState

__all__ = ["_Plan"]


class _Plan:
    """Per-stream constants: the plain stream's path, the regressors' recipe, the prior."""

    def __init__(self, comp: Compensator, adaptation: Adaptation,
                 rest_position: float | None, level: float | None = None) -> None:
        self.path = _Path(comp, rest_position, level)
        self.alpha = None if comp.band is None else 1.0 - (
            comp.band.level if level is None else level)
        self.adaptation = adaptation
        if adaptation.parameters == "weights":
            self.unit_params = _unit_weight_params(comp)
            scale = comp.scaling.position_scale
            self.contribution = scale * np.asarray(comp.params.w, dtype=np.float64)
            # estimate = sum_k c_k + constant, the constant from the bias and the centring
            self.constant = self.path.position_offset - scale * float(comp.params.v_b)
            n_mult = self.contribution.size
        else:
            self.constant = 0.0
            n_mult = 1
        span = (None if comp.position_range is None
                else comp.position_range[1] - comp.position_range[0])
        offset_std = adaptation.prior_offset or (0.1 * span if span else 1.0)
        multipliers = ("gain",) if n_mult == 1 else tuple(f"a_{k}" for k in range(n_mult))
        self.names = (*multipliers, "offset_mm")
        self.start = rls_start(np.r_[np.ones(n_mult), 0.0],
                               np.r_[np.full(n_mult, adaptation.prior_gain), offset_std])
        self.max_trace = float(np.trace(self.start.cov))
        self.plausible = Plausible.of(comp, self.path.position_offset, adaptation)

    def update(self, rls: RlsState, phi: np.ndarray, r: float) -> RlsState:
        """Learn one reference [mm] (``P`` bounded by the prior's trace: no wind-up while the
        references repeat one position)."""
        return rls_bound(rls_update(rls, phi, r - self.constant, self.adaptation.forgetting),
                         self.max_trace)

    def learn(self, state: AdaptiveState, phi: np.ndarray, r: float,
              estimate: float, half: float | None = None) -> AdaptiveState:
        """``state`` after the reference `r` [mm] of a sample estimated at `estimate` [mm]
        with band half-width `half` [mm] (None: no band): updated, or unchanged but for a
        count if `r` is implausible (rejected) or the update would leave the parameters'
        domain (refused). A plausible reference also moves the band's multiplier."""
        if self.plausible.why_not(r, estimate) is not None:
            return dataclasses.replace(state, n_rejected=state.n_rejected + 1)
        if half is not None:
            state = self.track_band(state, abs(r - estimate) > half)
        with np.errstate(all="ignore"):  # a non-finite result is refused just below
            rls = self.update(state.rls, phi, r)
        if not self.in_domain(rls.theta):
            return dataclasses.replace(state, n_refused=state.n_refused + 1)
        return dataclasses.replace(state, rls=rls)

    def track_band(self, state: AdaptiveState, miss: bool) -> AdaptiveState:
        """One step of the band's quantile tracking (module docstring)."""
        limit = float(np.log(MAX_BAND_FACTOR))
        log_factor = state.band_log_factor + BAND_STEP * (float(miss) - self.alpha)
        return dataclasses.replace(state, band_log_factor=min(max(log_factor, -limit), limit),
                                   n_band_misses=state.n_band_misses + int(miss),
                                   n_band_checks=state.n_band_checks + 1)

    @staticmethod
    def untouched(state: AdaptiveState) -> bool:
        """No reference has moved the output parameters or the band yet."""
        return state.rls.n_updates == 0 and state.n_band_checks == 0

    def half_width(self, state: AdaptiveState, plain_half: np.ndarray) -> np.ndarray:
        """The adapted band's half-width [mm] from the plain stream's."""
        gain = abs(float(state.rls.theta[0])) if self.adaptation.parameters == "gain" else 1.0
        return plain_half * (gain * float(np.exp(state.band_log_factor)))

    def in_domain(self, theta: np.ndarray) -> bool:
        """Whether output parameters ``theta`` lie in their domain (module docstring)."""
        if not np.all(np.isfinite(theta)) or abs(theta[-1]) > self.plausible.extent:
            return False
        multipliers = theta[:-1]
        if self.adaptation.parameters == "gain":
            return bool(1.0 / MAX_MULTIPLIER <= multipliers[0] <= MAX_MULTIPLIER)
        if not np.all(np.abs(multipliers) <= MAX_MULTIPLIER):
            return False
        comp = self.path.comp
        try:  # the weights and bias the update stands for, in the family's domain
            w = multipliers * np.asarray(comp.params.w, dtype=np.float64)
            v_b = float(comp.params.v_b) - theta[-1] / comp.scaling.position_scale
            dataclasses.replace(comp.params, w=w, v_b=v_b)
        except ValueError:
            return False
        return True

    def regressors(self, state: StreamState, sensor: np.ndarray,
                   estimate: np.ndarray) -> np.ndarray:
        """Regressors [mm], shape (n, p): the last column is the offset's (ones)."""
        ones = np.ones(sensor.size)
        if self.adaptation.parameters == "gain":
            return np.column_stack([estimate, ones])
        comp = self.path.comp
        # the normalised sensor exactly as _advance computes it (same operations, same bits)
        offset, _ = _sensor_offset(self.path, state, sensor)
        s = comp.polarity * (sensor - offset) / comp.scaling.sensor_scale
        x0 = None if state.x is None else np.array(state.x)
        cells = [comp.family.simulate(comp.structure, p, s, x0)[0] for p in self.unit_params]
        return np.column_stack([c * y for c, y in zip(self.contribution, cells, strict=True)]
                               + [ones])

    def predict(self, rls: RlsState, phi: np.ndarray, plain: np.ndarray) -> np.ndarray:
        """Estimates [mm] from ``theta``: the plain ones until the first reference."""
        if rls.n_updates == 0:
            return plain
        # a sum in a fixed order, element by element: a chunk gives the bits of single samples
        out = phi[:, 0] * rls.theta[0]
        for k in range(1, rls.theta.size):
            out = out + phi[:, k] * rls.theta[k]
        return out + self.constant


def _unit_weight_params(comp: Compensator) -> list[Any]:
    """The model's parameters with one output weight 1 and the others and the bias 0, after
    checking on a probe run that the output is linear in ``w`` and ``v_b``."""
    params = comp.params
    why = ""
    if comp.mode != "direct":
        why = "an inverse compensator's output is not linear in its weights"
    elif not comp.family.capabilities.output_is_linear(comp.structure):
        why = (f"the {comp.model} model's output is not linear in w and v_b (its family "
               f"does not declare a linear output)")
    if why:
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': {why}; "
                         f"use 'gain'")
    w = np.asarray(params.w, dtype=np.float64)
    try:
        units = [dataclasses.replace(params, w=np.eye(w.size)[k], v_b=0.0)
                 for k in range(w.size)]
    except ValueError as exc:  # the family's parameter checks refuse unit weights
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': the "
                         f"{comp.model} model cannot run one weight at a time ({exc}); "
                         f"use 'gain'") from None
    probe = np.sin(np.linspace(0.0, 6.0 * np.pi, 300)) * np.linspace(0.2, 1.0, 300)
    simulate = comp.family.simulate
    whole = simulate(comp.structure, params, probe)[0]
    parts = sum(wk * simulate(comp.structure, p, probe)[0] for wk, p in zip(w, units,
                                                                            strict=True))
    if not np.allclose(parts - params.v_b, whole, rtol=LINEARITY_TOLERANCE,
                       atol=LINEARITY_TOLERANCE * np.max(np.abs(whole))):
        raise InputError(f"{comp.source or 'compensator'}: adaptation 'weights': the "
                         f"{comp.model} model's output is not linear in w and v_b; use 'gain'")
    return units
