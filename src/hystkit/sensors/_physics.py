"""The virtual sensor's causal physics, one sample at a time (compiled).

One implementation of each step of :class:`~hystkit.sensors.VirtualSensor`'s model (steps 2-4
of its docstring), shared by the recording simulator (``_virtual.py``, whole arrays at
``fs_internal``) and by the loop model (``_loop_model.py``, sample by sample at any ``dt``), so
that the two cannot drift apart.

The functions are numba ``njit``: callable from Python and inlined into compiled loops.
``softening_factor`` and ``piezoresistance`` also take arrays.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["instant_fraction", "network_step", "piezoresistance", "prony_decay",
           "softening_factor", "travel_step"]


def instant_fraction(fractions, weights) -> float:
    """Share of the imposed strain the network follows at once: what the Prony terms and the
    play operators leave."""
    return 1.0 - sum(fractions) - sum(weights)


def prony_decay(taus, dt: float) -> np.ndarray:
    """Per-sample decay ``exp(-dt / tau)`` of each Prony state at sample time ``dt``."""
    return np.exp(-dt / np.asarray(taus, dtype=float))


@njit(cache=True)
def network_step(s, c, fractions, decay, weights, radii, q, play, q_next, play_next):
    """Network strain of one gauge for imposed strain ``s`` (step 2), and the next state.

    ``m = c s + sum_i f_i q_i + sum_j w_j p_j``: an instant part, Prony retardation states
    ``q`` seen *before* their update (exact exponential update for a held input,
    ``decay = exp(-dt / tau)``) and play operators (eq. 2.6) seen *after* theirs (rate
    independent: they follow the present input). Writes ``q_next``, ``play_next``, which may be
    ``q``, ``play`` themselves (each entry is read before it is written).
    """
    acc = c * s
    for i in range(fractions.size):
        acc += fractions[i] * q[i]
        q_next[i] = s + decay[i] * (q[i] - s)
    for j in range(radii.size):
        play_next[j] = max(s - radii[j], min(s + radii[j], play[j]))  # eq. 2.6 play operator
        acc += weights[j] * play_next[j]
    return acc


@njit(cache=True)
def travel_step(travel, s, s_prev):
    """Accumulated strain travel after the step ``s_prev -> s`` (drives cyclic softening)."""
    return travel + abs(s - s_prev)


@njit(cache=True)
def softening_factor(travel, amount, travel_scale):
    """Mullins-type resistance rise ``1 + a (1 - exp(-travel / scale))`` (step 4)."""
    return 1.0 + amount * (1.0 - np.exp(-travel / travel_scale))


@njit(cache=True)
def piezoresistance(m, gauge_factor):
    """Tunnelling law ``R / R_0 = exp(gamma m)`` for network strain ``m`` (step 3)."""
    return np.exp(gauge_factor * m)
