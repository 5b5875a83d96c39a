"""The operators of the Prandtl-Ishlinskii model (eq. 2.6-2.19): play, dead zone, and the
closed-form inverses of a PI operator and of a dead-zone superposition with their play states.
They know nothing of the model's records; :mod:`.model` composes them.
"""

from __future__ import annotations

import numpy as np


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
