"""The oscilloscope of the lab (sec. 4.2.1, 4.3): its settings, the merged encoder's levels,
and the channels it records in one block of samples (bridge voltages, encoder, supply).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..preprocess import bridge_voltage, code_to_ab, count_to_code
from ._virtual import VirtualSensor

__all__ = ["ScopeSettings", "merged_levels", "scope_block", "spline_at"]


@dataclass(frozen=True)
class ScopeSettings:
    """The lab's instruments in the raw simulation (SI units).

    Defaults: the Picoscope set-up of sec. 4.3.1 (R_br = 10 kOhm, V0 = 2 V) at 1 MHz, 0.5 mV
    RMS scope noise, a 5 V hex buffer (4.8 V high, 0.1 V low, 30 Ohm) driving the 1 kOhm / 2 kOhm
    merger into the scope's 1 MOhm, 20 mV noise on the merged channel, 0.5 us edges, 1 %
    logic-supply drift over 100 s (``supply_drift``, ``drift_period``: the encoder's buffer).
    The bridge supply is steady unless ``bridge_supply_drift`` (relative amplitude of a sine of
    period ``bridge_drift_period`` [s]) is set; ``supply_channel`` adds the measured bridge
    supply as a column ``v0``.

    Parameters
    ----------
    fs : float
        Scope sample rate [Hz].
    r_bridge : float
        Bridge resistor R_br [Ohm].
    v_supply : float
        Bridge supply V0 [V].
    bridge_noise_v : float
        RMS scope noise on v1, v2 (and v0) [V].
    encoder_mode : {"merged", "ab"}
        One merged 4-level encoder channel, or the logic channels ``enc_a``, ``enc_b``.
    logic_high, logic_low : float
        Output voltages of the hex buffer [V].
    r_d1, r_d2 : float
        Divider resistors of A and B [Ohm].
    r_buffer : float
        Output resistance of the buffer [Ohm].
    r_scope : float
        Input resistance of the scope [Ohm].
    encoder_noise_v : float
        RMS noise on the encoder channel(s) [V].
    edge_tau : float
        Time constant of the encoder edges [s].
    supply_drift : float
        Relative amplitude of the logic supply's sine drift [-].
    drift_period : float
        Its period [s].
    bridge_supply_drift : float
        Relative amplitude of the bridge supply's sine drift [-], in [0, 1).
    bridge_drift_period : float
        Its period [s].
    supply_channel : bool
        Write the measured bridge supply as a column ``v0``.
    n_missed_states : int
        Encoder states to hide (each an illegal double transition).
    n_spikes : int
        One-sample spikes to inject into the (first) encoder channel.

    Raises
    ------
    ValueError
        If a resistance, rate or period is not positive, a noise, drift or fault count is
        negative, `bridge_supply_drift` is not in [0, 1), or `encoder_mode` is unknown.
    """

    fs: float = 1e6
    r_bridge: float = 10e3
    v_supply: float = 2.0
    bridge_noise_v: float = 0.5e-3
    encoder_mode: str = "merged"
    logic_high: float = 4.8
    logic_low: float = 0.1
    r_d1: float = 1e3
    r_d2: float = 2e3
    r_buffer: float = 30.0
    r_scope: float = 1e6
    encoder_noise_v: float = 0.02
    edge_tau: float = 0.5e-6
    supply_drift: float = 0.01
    drift_period: float = 100.0
    bridge_supply_drift: float = 0.0
    bridge_drift_period: float = 30.0
    supply_channel: bool = False
    n_missed_states: int = 0
    n_spikes: int = 0

    def __post_init__(self) -> None:
        if self.encoder_mode not in ("merged", "ab"):
            raise ValueError(f"encoder_mode must be 'merged' or 'ab', got {self.encoder_mode!r}")
        for name in ("fs", "r_bridge", "v_supply", "r_d1", "r_d2", "r_scope", "drift_period",
                     "bridge_drift_period"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)}")
        if min(self.bridge_noise_v, self.encoder_noise_v, self.edge_tau, self.r_buffer,
               self.supply_drift, self.n_missed_states, self.n_spikes) < 0:
            raise ValueError("noise, edge time, drift and fault counts must be >= 0")
        if not 0 <= self.bridge_supply_drift < 1:
            raise ValueError(f"bridge_supply_drift must lie in [0, 1), got "
                             f"{self.bridge_supply_drift}")

    def bridge_supply(self, t: np.ndarray) -> np.ndarray:
        """The bridge supply V0(t) [V] at times `t` [s]."""
        return self.v_supply * (1 + self.bridge_supply_drift
                                * np.sin(2 * np.pi * np.asarray(t) / self.bridge_drift_period))


def merged_levels(scope: ScopeSettings, supply_scale: float = 1.0) -> np.ndarray:
    """Merged encoder voltage [V] of A/B codes 0..3 (``2 A + B``): the divider of sec. 4.2.1.

    Parameters
    ----------
    scope : ScopeSettings
        Buffer voltages and the divider's resistances.
    supply_scale : float
        Factor on the logic voltages (the logic supply's drift) [-].

    Returns
    -------
    numpy.ndarray, shape (4,)
        The level of each code [V].
    """
    g_a, g_b = 1 / (scope.r_d1 + scope.r_buffer), 1 / (scope.r_d2 + scope.r_buffer)
    a, b = code_to_ab(np.arange(4))
    v_a = np.where(a, scope.logic_high, scope.logic_low) * supply_scale
    v_b = np.where(b, scope.logic_high, scope.logic_low) * supply_scale
    return (v_a * g_a + v_b * g_b) / (g_a + g_b + 1 / scope.r_scope)


def scope_block(ts: np.ndarray, start: int, noise: np.random.Generator, coef: np.ndarray,
               sensor: VirtualSensor, scope: ScopeSettings, missed: list, spikes: np.ndarray,
               columns: tuple[str, ...], edge_state: np.ndarray, a_edge: float
               ) -> dict[str, np.ndarray]:
    """The scope's channels at times `ts` (samples from `start` on); `edge_state` carries the
    encoder edges' filter state from block to block (updated in place)."""
    step = sensor.encoder_mm
    pos, r1, r2 = spline_at(coef, sensor.fs_internal, ts)
    counts = np.round(pos / step).astype(np.int64)
    codes = count_to_code(counts)
    for t_missed, hidden, direction in missed:
        hide = (counts == hidden) & (np.abs(ts - t_missed) < 0.5 / sensor.fs_internal)
        codes[hide] = count_to_code(np.array([hidden - direction]))[0]
    chunk = {"time": ts}
    # Without drift the supply is exactly V0 (x 1.0), so the file is the one written before the
    # drift existed.
    v_supply = scope.bridge_supply(ts)
    for g, rg in enumerate((r1, r2)):
        chunk[f"v{g + 1}"] = (bridge_voltage(rg, scope.r_bridge, v_supply)
                              + scope.bridge_noise_v * noise.standard_normal(ts.size))
    scale = 1 + scope.supply_drift * np.sin(2 * np.pi * ts / scope.drift_period)
    local = spikes[(spikes >= start) & (spikes < start + ts.size)] - start
    if scope.encoder_mode == "merged":
        ideal = np.take_along_axis(
            merged_levels(scope)[np.newaxis], codes[np.newaxis], 1)[0] * scale
        signals = [ideal]
    else:
        signals = [np.where(bit, scope.logic_high, scope.logic_low) * scale
                   for bit in code_to_ab(codes)]
    for j, (col, ideal) in enumerate(zip(columns[3:3 + len(signals)], signals)):
        shaped = _one_pole(ideal, a_edge, edge_state[j])
        edge_state[j] = shaped[-1]
        if local.size and j == 0:  # spikes: one sample jumps to another level
            shaped[local] = ideal[local] + np.where(ideal[local] > ideal.mean(), -1, 1) \
                * 0.6 * (scope.logic_high - scope.logic_low)
        chunk[col] = shaped + scope.encoder_noise_v * noise.standard_normal(ts.size)
    if scope.supply_channel:  # drawn last: the other channels' noise is as without it
        chunk["v0"] = v_supply + scope.bridge_noise_v * noise.standard_normal(ts.size)
    return chunk


@njit(cache=True)
def spline_at(coef, fs_internal, ts):
    """Evaluate cubic splines (rows of CubicSpline.c stacked) on a uniform knot grid at `ts`."""
    n_rows, _, n_knots = coef.shape
    out = np.empty((n_rows, ts.size))
    h = 1.0 / fs_internal
    for j in range(ts.size):
        i = min(int(ts[j] * fs_internal), n_knots - 1)
        dx = ts[j] - i * h
        for r in range(n_rows):
            out[r, j] = ((coef[r, 0, i] * dx + coef[r, 1, i]) * dx + coef[r, 2, i]) * dx \
                + coef[r, 3, i]
    return out


@njit(cache=True)
def _one_pole(u, a, y0):
    """First-order lag ``y[n] = a y[n-1] + (1 - a) u[n]`` from state y0 (NaN: start at u[0])."""
    y = np.empty_like(u)
    prev = u[0] if np.isnan(y0) else y0
    for n in range(u.size):
        prev = a * prev + (1.0 - a) * u[n]
        y[n] = prev
    return y
