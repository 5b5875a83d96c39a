"""A/B codes of a quadrature encoder: the four states, their order in the cycle, and the
conversions between counts, codes and logic channels (sec. 4.2.1, 4.3.2).
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEFAULT_STATES", "PHASE", "ab_to_code", "code_to_ab", "count_to_code",
           "parse_states"]

# A/B state code q = 2 A + B of the merged levels in ascending voltage: with the divider, A
# (1 kOhm) weighs twice as much as B (2 kOhm), so the levels are (2A + B)/3 of the logic swing.
DEFAULT_STATES = (0b00, 0b01, 0b10, 0b11)
# Position in the quadrature cycle of each code, for A leading B counting up: 00, 10, 11, 01.
PHASE = np.array([0, 3, 1, 2], dtype=np.int64)
_CODE_OF_PHASE = np.array([0b00, 0b10, 0b11, 0b01], dtype=np.int64)


def parse_states(text: str | list[str] | tuple) -> tuple[int, int, int, int]:
    """A/B states of the four levels in ascending order from text like ``"00,01,10,11"``.

    Each item is ``AB`` with A and B in {0, 1}; the four items must be the four states.

    Parameters
    ----------
    text : str or sequence of str
        Comma-separated ``AB`` pairs, or the pairs themselves.

    Returns
    -------
    tuple of 4 int
        The A/B code ``2 A + B`` of each level, in ascending voltage.

    Raises
    ------
    ValueError
        If there are not four ``AB`` pairs of 0/1, or a state is missing or repeated.
    """
    items = [s.strip() for s in text.split(",")] if isinstance(text, str) else list(text)
    if len(items) != 4 or any(len(str(s)) != 2 or set(str(s)) - {"0", "1"} for s in items):
        raise ValueError(f"encoder states must be four A/B pairs like 00,01,10,11; got {text!r}")
    codes = tuple(int(str(s), 2) for s in items)
    if sorted(codes) != [0, 1, 2, 3]:
        raise ValueError(f"encoder states must name each of 00, 01, 10, 11 once; got {text!r}")
    return codes  # type: ignore[return-value]


def ab_to_code(a: np.ndarray, b: np.ndarray, threshold_a: float,
               threshold_b: float) -> np.ndarray:
    """A/B codes ``2 A + B`` from logic channels; a channel is 1 above its threshold.

    Parameters
    ----------
    a, b : numpy.ndarray
        Channels A and B [V].
    threshold_a, threshold_b : float
        Logic thresholds of A and B [V].

    Returns
    -------
    numpy.ndarray of float
        The codes (as float, for :func:`decode` with levels 0, 1, 2, 3), the shape of `a`
        and `b` broadcast.
    """
    return 2.0 * (np.asarray(a) > threshold_a) + (np.asarray(b) > threshold_b)


def count_to_code(counts: np.ndarray) -> np.ndarray:
    """A/B code ``2 A + B`` an encoder shows at position `counts` (count 0 shows A = B = 0).

    Parameters
    ----------
    counts : numpy.ndarray of int
        Positions [counts].

    Returns
    -------
    numpy.ndarray of int64
        The codes, the shape of `counts`.
    """
    return _CODE_OF_PHASE[np.mod(np.asarray(counts, dtype=np.int64), 4)]


def code_to_ab(codes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Logic levels A and B (0 or 1) of A/B codes.

    Parameters
    ----------
    codes : numpy.ndarray of int
        A/B codes ``2 A + B``.

    Returns
    -------
    a, b : numpy.ndarray of int64
        Levels of A and B, the shape of `codes`.
    """
    codes = np.asarray(codes, dtype=np.int64)
    return codes >> 1, codes & 1
