"""Virtual differential 3D-printed strain gauge: the lab's recordings without the lab.

A physically motivated simulator of the document's sensor (ch. 3-4), deliberately *not* built
from the mPL model it is used to test:

1. Beam: the actuator imposes tip displacement ``x`` [mm]; the top gauge R1 sees strain
   ``+kappa x``, the bottom gauge R2 ``-kappa x`` (thin-beam surface strain, linear in ``x``).
2. Conductive network strain ``m`` of each gauge, the strain its carbon-black filler network
   follows: a Prony series (standard-linear-solid retardation) makes part of it lag the imposed
   strain with time constants from 0.3 s to 30 s (rate dependence, creep), and Prandtl-Ishlinskii
   play operators (inter-particle friction) add rate-independent hysteresis with non-local memory.
3. Piezoresistance: tunnelling between filler particles gives ``R = R_0 exp(gamma m)``, a
   non-linear law, with unequal gauge factors and base resistances for the two gauges (the
   gauge asymmetry of table 3.1; 22.4 kOhm / 15.7 kOhm in paper 9.1).
4. Slow effects: cyclic softening of the filler network (a Mullins-type baseline shift that
   grows with the accumulated strain travel and saturates, unequal in the two gauges, so it
   depends on the excitation and survives the differential measurement), a common temperature excursion (Ornstein-Uhlenbeck, tau = 60 s) acting through
   unequal temperature coefficients, and the post-print resistance settling of sec. 3.5.1
   (exponential drop over about a day), which is differential because the gauges differ.
5. Measurement: resistance noise, a 5 um quadrature encoder for position, the document's
   20 Hz zero-phase Butterworth filter, downsampling to 40 Hz, and dR/R about the recording
   mean (eq. 4.4-4.5); the output is ``dR1/R1 - dR2/R2``.

Steps 2-4 are computed by the per-sample laws of :mod:`._physics`, which the causal loop model
(:mod:`._loop_model`, the sensor as ``S_r`` of the closed loop) shares.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .._docfill import docfiller
from ..io import Recording
from ..preprocess import downsample, lowpass_zero_phase
from ..signals import excitation
from ._physics import (
    instant_fraction,
    network_step,
    piezoresistance,
    prony_decay,
    softening_factor,
    travel_step,
)

__all__ = ["VirtualSensor", "simulate_experiment"]

# What the simulated experiments take (%(experiment)s).
EXPERIMENT_ENTRIES = {
    "experiment": """name : str
    Excitation (sine, decay, chirp, noise).
seed : int
    Seeds the noise, the temperature drift and, for ``noise``, the trajectory.""",
}
fill_experiment_doc = docfiller(EXPERIMENT_ENTRIES.__getitem__)


@dataclass(frozen=True)
class VirtualSensor:
    """Material, gauge and instrument parameters of the simulated sensor (SI unless noted).

    The defaults give a TPU cantilever of about 1 % surface strain at 3 mm tip deflection with
    EEL-like gauges; they are plausible, not fitted to the document's (unpublished) data.

    Parameters
    ----------
    strain_per_mm : float
        Surface strain per mm of tip deflection, kappa [1/mm].
    prony_fractions : tuple of float
        Share of the imposed strain each Prony term retards [-].
    prony_taus : tuple of float
        Their time constants [s].
    play_radii : tuple of float
        Radii of the play operators [strain].
    play_weights : tuple of float
        Their weights [-]; Prony fractions and play weights sum to less than 1 (the rest is
        followed at once).
    softening : (float, float)
        Saturated relative resistance rise of cyclic softening, R1 and R2 [-].
    softening_travel : float
        Accumulated strain travel per e-fold of the softening [strain].
    gauge_factors : (float, float)
        gamma of R1 (top) and R2 (bottom) in ``R = R_0 exp(gamma m)`` [-].
    base_resistance : (float, float)
        R_0 of R1 and R2 [Ohm] (paper 9.1).
    temp_coefficients : (float, float)
        Temperature coefficients of R1 and R2 [1/K].
    temp_std : float
        Standard deviation of the slow temperature excursion [K].
    temp_tau : float
        Its time constant [s].
    age_hours : float
        Time since printing at the start [h] (sec. 3.5.1).
    settle_drop : (float, float)
        Fractional resistance drop of R1 and R2 once settled [-].
    settle_tau_hours : float
        Time constant of the settling [h].
    noise_rel : float
        Resistance noise, relative, per internal sample [-].
    encoder_mm : float
        Encoder resolution [mm per count].
    fs_internal : float
        Simulation rate [Hz].
    fs_out : float
        Rate of the recordings [Hz] (as in paper 9.2).
    cutoff : float
        Cut-off of the zero-phase Butterworth [Hz] (eq. 4.1).

    Raises
    ------
    ValueError
        If the Prony or play tuples differ in length, or their shares sum to 1 or more.
    """

    strain_per_mm: float = 3.3e-3                   # surface strain per mm of tip deflection
    prony_fractions: tuple[float, ...] = (0.20, 0.15, 0.10)
    prony_taus: tuple[float, ...] = (0.3, 3.0, 30.0)  # s
    play_radii: tuple[float, ...] = (0.3e-3, 1.0e-3, 2.5e-3)  # strain
    play_weights: tuple[float, ...] = (0.12, 0.12, 0.10)
    softening: tuple[float, float] = (0.030, 0.015)  # saturated relative resistance rise
    softening_travel: float = 1.0                    # accumulated |strain| travel per e-fold
    gauge_factors: tuple[float, float] = (14.0, 10.5)  # gamma of R1 (top), R2 (bottom)
    base_resistance: tuple[float, float] = (22.4e3, 15.7e3)  # Ohm, paper 9.1
    temp_coefficients: tuple[float, float] = (2.0e-3, 2.6e-3)  # 1/K
    temp_std: float = 0.3                            # K, slow temperature excursion
    temp_tau: float = 60.0                           # s
    age_hours: float = 48.0                          # time since printing (sec. 3.5.1)
    settle_drop: tuple[float, float] = (0.35, 0.45)  # fractional resistance drop when settled
    settle_tau_hours: float = 10.0
    noise_rel: float = 1e-3                          # resistance noise, relative, per sample
    encoder_mm: float = 0.005                        # 5 um per count
    fs_internal: float = 400.0                       # Hz, simulation rate
    fs_out: float = 40.0                             # Hz, as in paper 9.2
    cutoff: float = 20.0                             # Hz, eq. 4.1

    def __post_init__(self) -> None:
        if len(self.prony_fractions) != len(self.prony_taus):
            raise ValueError("prony_fractions and prony_taus differ in length")
        if len(self.play_radii) != len(self.play_weights):
            raise ValueError("play_radii and play_weights differ in length")
        if sum(self.prony_fractions) + sum(self.play_weights) >= 1:
            raise ValueError("Prony fractions and play weights must sum to less than 1")

    def network_strain(self, strain: np.ndarray) -> np.ndarray:
        """Strain followed by the conductive network, for imposed ``strain`` at ``fs_internal``."""
        c = instant_fraction(self.prony_fractions, self.play_weights)
        decay = prony_decay(self.prony_taus, 1.0 / self.fs_internal)
        return _network_strain(np.ascontiguousarray(strain, dtype=float), c,
                               np.asarray(self.prony_fractions, float), decay,
                               np.asarray(self.play_weights, float),
                               np.asarray(self.play_radii, float))

    def resistances(self, x: np.ndarray, t: np.ndarray,
                    rng: np.random.Generator) -> np.ndarray:
        """Gauge resistances [Ohm], shape (2, n), for tip deflection ``x`` [mm] at times ``t``."""
        strain = self.strain_per_mm * np.asarray(x, dtype=float)
        temp = _ornstein_uhlenbeck(t.size, 1.0 / self.fs_internal, self.temp_tau, self.temp_std,
                                   rng)
        age = self.age_hours + t / 3600.0
        travel = _strain_travel(np.ascontiguousarray(strain))
        out = np.empty((2, t.size))
        for g, sign in enumerate((1.0, -1.0)):
            m = self.network_strain(sign * strain)
            # .py_func: the same law through numpy's exp, which numba's vectorised exp differs
            # from by an ulp; keeps the recordings bit-identical to earlier releases
            softened = softening_factor.py_func(travel, self.softening[g], self.softening_travel)
            settle = 1.0 + self.settle_drop[g] * np.exp(-age / self.settle_tau_hours)
            out[g] = (self.base_resistance[g] * settle * softened
                      * piezoresistance.py_func(m, self.gauge_factors[g])
                      * (1.0 + self.temp_coefficients[g] * temp)
                      * (1.0 + self.noise_rel * rng.standard_normal(t.size)))
        return out

    def record(self, t: np.ndarray, x: np.ndarray, seed: int,
               source: str = "<virtual sensor>") -> Recording:
        """Run the sensor and the lab's processing chain; ``t``, ``x`` at ``fs_internal``."""
        rng = np.random.default_rng(seed)
        r = self.resistances(x, t, rng)
        counts = np.round(np.asarray(x) / self.encoder_mm)
        raw = np.vstack([r, counts * self.encoder_mm])
        filtered = lowpass_zero_phase(raw, self.fs_internal, self.cutoff)
        r1, r2, position = downsample(filtered, self.fs_internal, self.fs_out)
        rel1 = (r1 - r1.mean()) / r1.mean()  # eq. 4.4-4.5
        rel2 = (r2 - r2.mean()) / r2.mean()
        time = downsample(t, self.fs_internal, self.fs_out)
        return Recording(time=time - time[0], position=position, sensor=rel1 - rel2,
                         source=source)


@fill_experiment_doc
def simulate_experiment(name: str, seed: int = 0,
                        sensor: VirtualSensor | None = None) -> Recording:
    """One recording of the document's experiment ``name`` (sine, decay, chirp, noise).

    ``seed`` draws the noise, the temperature drift and, for ``noise``, the trajectory itself:
    use different seeds for the fitting and the validation recording.

    Parameters
    ----------
    %(experiment)s
    sensor : VirtualSensor, optional
        The simulated sensor; the defaults when None.

    Returns
    -------
    Recording
        Time [s], position [mm] and sensor dR1/R1 - dR2/R2 [-] at the sensor's ``fs_out``.

    Raises
    ------
    ValueError
        If `name` is not a known excitation.
    """
    sensor = VirtualSensor() if sensor is None else sensor
    t, x = excitation(name, sensor.fs_internal, seed)  # refuses an unknown name
    return sensor.record(t, x, seed, source=f"<virtual sensor: {name}, seed {seed}>")


def _ornstein_uhlenbeck(n: int, dt: float, tau: float, std: float,
                        rng: np.random.Generator) -> np.ndarray:
    """Stationary OU process, exact discretisation, started from its stationary law."""
    a = np.exp(-dt / tau)
    kicks = rng.standard_normal(n) * std * np.sqrt(1 - a * a)
    kicks[0] = std * rng.standard_normal()
    return _ar1(kicks, a)


@njit(cache=True)
def _ar1(kicks, a):
    out = np.empty_like(kicks)
    acc = 0.0
    for i in range(kicks.size):
        acc = a * acc + kicks[i] if i else kicks[0]
        out[i] = acc
    return out


@njit(cache=True)
def _network_strain(strain, c, fractions, decay, weights, radii):
    """Step 2 over a whole run, from the Prony states at ``strain[0]`` and virgin plays."""
    q = np.full(fractions.size, strain[0])
    play = np.zeros(radii.size)
    out = np.empty_like(strain)
    for n in range(strain.size):
        out[n] = network_step(strain[n], c, fractions, decay, weights, radii, q, play, q, play)
    return out


@njit(cache=True)
def _strain_travel(strain):
    """Accumulated strain travel at every sample, 0 at the first."""
    out = np.empty_like(strain)
    acc = 0.0
    for n in range(strain.size):
        acc = travel_step(acc, strain[n], strain[n - 1]) if n else 0.0
        out[n] = acc
    return out
