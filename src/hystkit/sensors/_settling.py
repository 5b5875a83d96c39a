"""Resistance-over-time logs of freshly printed conductive traces (sec. 3.5.1, fig. 3.5).

The document logs the resistance of printed blocks of conductive filament once a minute for
days after printing (Keithley 2000, 4-wire). Non-annealed blocks rise steeply during the first
hours, then drop until they saturate after about 2-3 days; annealed ones (16 h at 150 C) are
about 5-10 times lower and only drop a little, without the peak. The measured data behind
fig. 3.5 are not part of the document, so this module *generates* such logs from a law with
known parameters, for testing :func:`hystkit.analysis.fit_settling` and for the docs:

``R(t) = R_final + drop * exp(-t / tau_drop) - rise * exp(-t / tau_rise)``, t in hours since
printing, ``tau_rise < tau_drop``: the fast term lifts R from ``R_final + drop - rise`` towards
a peak, the slow one brings it down to ``R_final``. ``rise = 0`` is a plain exponential drop.

The presets (:data:`PRINTED_BLOCK`, :data:`ANNEALED_BLOCK`) are chosen to match the document's
*description* (peak after a few hours, saturation at 2-3 days, annealing about 5 times lower
for PI-ETPU); they are not fitted to the unpublished measurement. :func:`simulate_settling_log`
also logs the two gauges of the :class:`VirtualSensor` at rest, whose own settling law (a plain
drop, ``settle_drop``, ``settle_tau_hours``) and temperature drift it runs unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ._virtual import VirtualSensor

__all__ = ["ANNEALED_BLOCK", "PRINTED_BLOCK", "SettlingLaw", "simulate_settling_log"]


@dataclass(frozen=True)
class SettlingLaw:
    """Resistance after printing, ``R_final + drop e^(-t/tau_drop) - rise e^(-t/tau_rise)``.

    Parameters
    ----------
    r_final : float
        Settled resistance [Ohm], > 0.
    drop : float
        Amplitude of the slow drop [Ohm], >= 0.
    tau_drop_h : float
        Its time constant [h], > 0.
    rise : float
        Amplitude of the fast rise [Ohm], >= 0 (0: no rise).
    tau_rise_h : float
        Its time constant [h], > 0 and < `tau_drop_h`.
    """

    r_final: float
    drop: float
    tau_drop_h: float
    rise: float = 0.0
    tau_rise_h: float = 1.0

    def __post_init__(self) -> None:
        if not (self.r_final > 0 and self.drop >= 0 and self.rise >= 0
                and 0 < self.tau_rise_h < self.tau_drop_h):
            raise ValueError("need r_final > 0, drop >= 0, rise >= 0 and "
                             f"0 < tau_rise_h < tau_drop_h, got {self}")
        if self.r_final + self.drop - self.rise <= 0:
            raise ValueError("the resistance at t = 0 (r_final + drop - rise) must be > 0")

    def resistance(self, t_h: np.ndarray) -> np.ndarray:
        """R(t) [Ohm] at hours `t_h` since printing."""
        t = np.asarray(t_h, dtype=float)
        return (self.r_final + self.drop * np.exp(-t / self.tau_drop_h)
                - self.rise * np.exp(-t / self.tau_rise_h))


# Non-annealed PI-ETPU block: starts at 14 kOhm, peaks near 18 kOhm after 3.7 h, settles to
# 10 kOhm; 99 % of the drop is gone after 69 h (2.9 days).
PRINTED_BLOCK = SettlingLaw(r_final=10e3, drop=12e3, tau_drop_h=15.0, rise=8e3, tau_rise_h=2.0)
# Annealed block: 5 times lower, a 5 % drop over a few hours, no peak.
ANNEALED_BLOCK = SettlingLaw(r_final=2e3, drop=100.0, tau_drop_h=5.0)


def simulate_settling_log(duration_h: float = 96.0, interval_min: float = 1.0, seed: int = 0,
                          *, sensor: VirtualSensor | None = None,
                          blocks: dict[str, SettlingLaw] | None = None,
                          noise_rel: float = 2e-3) -> dict[str, np.ndarray]:
    """A resistance log from printing on: the sensor's gauges at rest and printed blocks.

    Parameters
    ----------
    duration_h : float
        Length of the log [h] (the document logged for days).
    interval_min : float
        Time between readings [min] (the document: 1).
    seed : int
        Seeds all noise.
    sensor : VirtualSensor, optional
        Its gauges R1, R2 are logged at rest (tip deflection 0) from the end of printing
        (``age_hours`` 0): settling law, temperature drift and noise of the sensor itself, with
        the temperature process sampled at the log's interval.
    blocks : dict of str to SettlingLaw, optional
        Further columns; default ``{"block": PRINTED_BLOCK, "block_annealed": ANNEALED_BLOCK}``.
    noise_rel : float
        Relative white noise of the block readings (the sensor has its own).

    Returns
    -------
    dict of str to ndarray, shape (n,)
        ``time_h`` [h], ``r1``, ``r2`` and one column per block [Ohm].
    """
    if not (duration_h > 0 and interval_min > 0 and noise_rel >= 0):
        raise ValueError("duration_h and interval_min must be > 0 and noise_rel >= 0")
    n = int(np.floor(duration_h * 60.0 / interval_min + 1e-9)) + 1
    if n < 8:
        raise ValueError(f"{n} readings: the log needs at least 8 (longer duration_h?)")
    t_h = np.arange(n) * interval_min / 60.0
    sensor = VirtualSensor() if sensor is None else sensor
    # The sensor's temperature process runs at its internal rate: here one step per reading.
    at_rest = replace(sensor, age_hours=0.0, fs_internal=60.0 / interval_min / 3600.0)
    rng = np.random.default_rng(seed)
    r = at_rest.resistances(np.zeros(n), t_h * 3600.0, rng)
    log = {"time_h": t_h, "r1": r[0], "r2": r[1]}
    blocks = {"block": PRINTED_BLOCK, "block_annealed": ANNEALED_BLOCK} if blocks is None \
        else blocks
    for name, law in blocks.items():
        log[name] = law.resistance(t_h) * (1.0 + noise_rel * rng.standard_normal(n))
    return log
