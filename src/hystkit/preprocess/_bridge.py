"""Half-bridge readout of the two strain gauges (sec. 4.3.1, appendix 9.8, eq. 4.2-4.5).

Each gauge R_S sits in series with a bridge resistor R_br across the supply V0; the scope
measures the voltage V_m across R_br (eq. 4.2). The document's two set-ups are
R_br = 10 kOhm, V0 = 2 V (Picoscope, sine) and R_br = 560 Ohm, V0 = 1 V (Handyscope, paper 9.2).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._kernel_inputs import read_only

__all__ = ["bridge_kernel", "bridge_resistance", "bridge_voltage", "clipped_channels",
           "first_invalid_bridge_sample", "gauge_symmetry", "relative_change"]


def bridge_voltage(r_s: np.ndarray, r_bridge: float, v_supply: float | np.ndarray) -> np.ndarray:
    """Voltage across the bridge resistor [V], eq. 4.2: ``V_m = R_br / (R_br + R_S) * V0``.

    Parameters
    ----------
    r_s : array
        Gauge resistance R_S [Ohm], any shape.
    r_bridge : float
        Bridge resistor R_br [Ohm].
    v_supply : float or array
        Supply voltage V0 [V]: one nominal value, or the measured supply broadcast against
        `r_s` (sec. 4.2.1's reference channel).

    Returns
    -------
    numpy.ndarray
        V_m [V], `r_s` and `v_supply` broadcast together.
    """
    return r_bridge / (r_bridge + np.asarray(r_s, dtype=float)) * v_supply


def bridge_resistance(v_m: np.ndarray, r_bridge: float, v_supply: float | np.ndarray) -> np.ndarray:
    """Gauge resistance [Ohm] from the bridge voltage, eq. 4.3: ``R_S = R_br (V0 - V_m) / V_m``.

    Defined only for ``0 < V_m < V0``; outside that range the result is negative or infinite,
    so callers check with :func:`first_invalid_bridge_sample` first.

    Parameters
    ----------
    v_m : array
        Voltage measured across the bridge resistor [V], any shape.
    r_bridge : float
        R_br [Ohm].
    v_supply : float or array
        V0 [V]: the nominal supply, or the measured supply of each sample (broadcast against
        `v_m`), which removes the supply's drift from R_S.

    Returns
    -------
    numpy.ndarray
        R_S [Ohm], `v_m` and `v_supply` broadcast together.
    """
    v_m = np.asarray(v_m, dtype=float)
    # (V0/V_m - 1) costs one division and one subtraction per sample: this runs at scope rate.
    return r_bridge * (v_supply / v_m - 1.0)


def first_invalid_bridge_sample(v_m: np.ndarray, v_supply: float | np.ndarray) -> int:
    """Index of the first sample with ``V_m <= 0`` or ``V_m >= V0`` (eq. 4.3 undefined), or -1.

    Parameters
    ----------
    v_m : numpy.ndarray, shape (n,)
        Voltage measured across the bridge resistor [V].
    v_supply : float or numpy.ndarray
        One V0, or the measured supply of each sample [V].

    Returns
    -------
    int
        Index of the first invalid sample, -1 if all are valid.
    """
    v_m = np.asarray(v_m)
    bad = (v_m <= 0.0) | (v_m >= v_supply)
    if not bad.any():
        return -1
    return int(np.argmax(bad))


def relative_change(r: np.ndarray, axis: int = -1) -> np.ndarray:
    """Relative resistance change about the mean, eq. 4.4-4.5: ``(R - mean R) / mean R``.

    Parameters
    ----------
    r : array
        Resistance [Ohm]; the mean is taken along `axis` (the samples of one recording).
    axis : int
        Axis of the samples.

    Returns
    -------
    numpy.ndarray
        ``(R - mean R) / mean R`` [-], the shape of `r`.
    """
    r = np.asarray(r, dtype=float)
    mean = r.mean(axis=axis, keepdims=True)
    return (r - mean) / mean


def gauge_symmetry(r1: float | np.ndarray, r2: float | np.ndarray) -> float:
    """Gauge symmetry ``2 (R1 - R2) / (R1 + R2)`` of the mean resistances (table 3.1) [-].

    0 for a perfectly symmetric sensor; the document's paper-9.1 sample (22.4 / 15.7 kOhm)
    gives 0.35.

    Parameters
    ----------
    r1, r2 : float or numpy.ndarray
        Resistances of gauge 1 and gauge 2 [Ohm]; each is averaged over all its entries.

    Returns
    -------
    float
        The symmetry [-].
    """
    m1, m2 = float(np.mean(r1)), float(np.mean(r2))
    return 2.0 * (m1 - m2) / (m1 + m2)


def clipped_channels(extremes: np.ndarray, n: int) -> dict[str, tuple[int, float]]:
    """Clipped channels from the extreme statistics of :func:`bridge_kernel`.

    An extreme holding at least 100 samples and 1e-4 of the `n` samples is a scope channel
    pinned at its limit. Noise makes the exact extreme of an unclipped channel rare (a coarse
    8-bit scope on a slow signal can still trip this).

    Parameters
    ----------
    extremes : numpy.ndarray, shape (8,)
        The ``ext`` statistics of :func:`bridge_kernel`: [max, samples at max, min, samples
        at min] of v1, then v2.
    n : int
        Samples the statistics were taken over.

    Returns
    -------
    dict of str to (int, float)
        ``{"v1_max": (samples, value [V]), ...}`` for each clipped extreme; empty if none.
    """
    out = {}
    for g in range(2):
        for side, k in (("max", 0), ("min", 2)):
            value, count = extremes[4 * g + k], int(extremes[4 * g + k + 1])
            if count >= max(100, 1e-4 * n):
                out[f"v{g + 1}_{side}"] = (count, float(value))
    return out


_OPEN_GAUGE = 1e-12


@njit(cache=True, nogil=True)
def _bridge_row(v, v0, stride, out, r_bridge, ext, at):
    """eq. 4.3 for one channel into `out`, with supply ``v0[i * stride]`` (stride 0: one nominal
    V0; 1: the measured supply of each sample); updates [max, n at max, min, n at min] at
    ext[at:]."""
    hi, n_hi, lo, n_lo = ext[at], ext[at + 1], ext[at + 2], ext[at + 3]
    for i in range(v.size):
        vi = float(v[i])
        v_supply = float(v0[i * stride])
        # Below 1e-12 V0, R_S = R_br (V0 / V_m - 1) would pass 1e12 R_br (or overflow): an open
        # gauge or a broken sample, not a reading.
        if not (_OPEN_GAUGE * v_supply < vi < v_supply):
            return i
        out[i] = r_bridge * (v_supply / vi - 1.0)
        if vi >= hi:
            n_hi = n_hi + 1.0 if vi == hi else 1.0
            hi = vi
        if vi <= lo:
            n_lo = n_lo + 1.0 if vi == lo else 1.0
            lo = vi
    ext[at], ext[at + 1], ext[at + 2], ext[at + 3] = hi, n_hi, lo, n_lo
    return -1


@njit(cache=True, nogil=True)
def _bridge_both(v1, v2, v0, stride, r_bridge, ext):
    ext = ext.copy()
    r = np.empty((2, v1.size))
    bad = np.empty(2, dtype=np.int64)
    bad[0] = _bridge_row(v1, v0, stride, r[0], r_bridge, ext, 0)
    bad[1] = _bridge_row(v2, v0, stride, r[1], r_bridge, ext, 4)
    return r, bad, ext


def bridge_kernel(v1: np.ndarray, v2: np.ndarray, r_bridge: float, v_supply: float,
                  ext: np.ndarray, v0: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """eq. 4.3 for both gauges at the scope rate, fused with the checks.

    Parameters
    ----------
    v1, v2 : array, shape (n,)
        Bridge voltages [V] (float32 or float64).
    r_bridge, v_supply : float
        R_br [Ohm] and the nominal supply V0 [V].
    ext : ndarray, shape (8,)
        Running [max, samples at max, min, samples at min] of v1, then v2; start with
        ``[-inf, 0, inf, 0] * 2``.
    v0 : array, shape (n,), optional
        The measured supply [V] of each sample (the reference channel of sec. 4.2.1); used in
        eq. 4.3 instead of `v_supply` when given.

    Returns
    -------
    r : ndarray, shape (2, n)
        R1, R2 [Ohm] (valid up to the first invalid sample).
    bad : ndarray of int64, shape (2,)
        First sample with ``V_m <= 1e-12 V0`` or ``V_m >= V0`` per channel, -1 if none.
    ext : ndarray, shape (8,)
        Updated statistics.
    """
    if v0 is None:
        return _bridge_both(read_only(v1), read_only(v2), read_only(np.array([float(v_supply)])),
                            0, float(r_bridge), ext)
    if np.shape(v0) != np.shape(v1):
        raise ValueError(f"v0 has shape {np.shape(v0)}, the bridge voltages {np.shape(v1)}")
    return _bridge_both(read_only(v1), read_only(v2), read_only(v0), 1, float(r_bridge), ext)
