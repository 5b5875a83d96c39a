"""Quadrature encoder decoding: the merged 4-level signal of sec. 4.2.1 back to a count.

The lab merges the actuator's encoder channels A+ and B+ through a 1 kOhm / 2 kOhm divider into
one analog channel with four levels, one per A/B state (sec. 4.2.1); with separate channels the
two logic signals are recorded directly (sec. 4.3.2). Decoding has three steps:

1. **Levels.** :class:`~._levels.LevelSurvey` finds the four levels (clusters in the value histogram) in
   the first chunks of a recording. While decoding, each level is re-estimated from the samples
   sitting firmly on it, once per block of ``track_block`` samples, so slow drift of the logic
   supply is followed. Blocks count global samples, so the result does not depend on chunking.
2. **Debounce.** A sample's level (nearest level) becomes the new state only once it has
   persisted for ``dwell`` consecutive samples. This drops samples caught mid-edge (a 1/3 -> 1
   transition of the merged signal passes the 2/3 level, which would look like a double A/B
   change) and short noise spikes; the samples of a rejected run keep the old count, the samples
   of an accepted run all get the new one (the edge is placed where the new level began).
3. **State machine.** Each accepted state change moves the count by +1 or -1 (A leading B is
   positive: (A,B) = 00 -> 10 -> 11 -> 01 -> 00). A change of both A and B at once (an "illegal"
   double transition: a state was missed) is counted and reported. Policy ``"continue"`` then
   adds 2 counts in the direction of the last legal step (a missed state during monotone motion,
   the only way to lose a state without a reversal, which would show no change at all);
   ``"hold"`` adds nothing.

State is explicit (:class:`EncoderState`), so a recording decoded in chunks gives exactly the
samples and counts of decoding it whole.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numba import njit

from .._kernel_inputs import read_only
from ._quadrature import DEFAULT_STATES, PHASE, parse_states

__all__ = ["EncoderSettings", "EncoderState", "decode", "decode_flush", "decode_reference",
           "decode_step", "encoder_init"]

_POLICIES = ("continue", "hold")


@dataclass(frozen=True)
class EncoderSettings:
    """How the encoder signal is decoded.

    Parameters
    ----------
    states : tuple of 4 int
        A/B code ``2 A + B`` of each level in ascending voltage (default 00, 01, 10, 11).
    dwell : int
        Samples a new level must persist to count as a state change (>= 1). Choose it longer
        than an edge and shorter than the shortest state at the fastest motion:
        ``preprocess`` uses 4 us of samples, at least 2.
    illegal : {"continue", "hold"}
        What a double transition adds to the count: 2 in the last direction, or nothing.
    track_block : int
        Samples per level re-estimation block (0 disables tracking).
    track_gain : float
        Fraction of the way each level moves toward its block mean, in (0, 1].
    """

    states: tuple[int, int, int, int] = DEFAULT_STATES
    dwell: int = 4
    illegal: str = "continue"
    track_block: int = 65536
    track_gain: float = 0.5

    def __post_init__(self) -> None:
        parse_states([format(q, "02b") for q in self.states])
        if self.dwell < 1:
            raise ValueError(f"dwell must be at least 1 sample, got {self.dwell}")
        if self.illegal not in _POLICIES:
            raise ValueError(f"illegal must be one of {_POLICIES}, got {self.illegal!r}")
        if self.track_block < 0 or not 0 < self.track_gain <= 1:
            raise ValueError("track_block must be >= 0 and track_gain in (0, 1]")


@dataclass(frozen=True, eq=False)
class EncoderState:
    """Decoder memory between chunks (all counts since the start of the recording).

    Parameters
    ----------
    levels : numpy.ndarray, shape (4,)
        The four levels [V], ascending (tracked while decoding).
    stable : int
        The accepted A/B code (-1 before the first sample).
    count : int
        The position [counts].
    candidate : int
        The A/B code waiting out its dwell (-1 if none).
    run : int
        How long `candidate` has waited [samples]; these samples are pending (not yet
        emitted).
    direction : int
        Direction of the last legal step: +1, -1, or 0 before the first.
    n_edges : int
        Accepted state changes.
    n_illegal : int
        Accepted changes that were double transitions.
    n_rejected : int
        Short excursions that returned to the stable level.
    in_excursion : int
        1 while the signal is away from the stable level without an accepted change, else 0.
    n_seen : int
        Samples consumed.
    first_illegal : int
        Sample of the first double transition, -1 if none.
    sums, n_firm : numpy.ndarray, shape (4,)
        Sum [V] and number of the samples firmly on each level in the current tracking
        block.
    """

    levels: np.ndarray
    stable: int = -1
    count: int = 0
    candidate: int = -1
    run: int = 0
    direction: int = 0
    n_edges: int = 0
    n_illegal: int = 0
    n_rejected: int = 0
    in_excursion: int = 0
    n_seen: int = 0
    first_illegal: int = -1
    sums: np.ndarray = field(default_factory=lambda: np.zeros(4))
    n_firm: np.ndarray = field(default_factory=lambda: np.zeros(4))

    @property
    def n_pending(self) -> int:
        """Samples consumed but not yet emitted (they wait for the dwell decision)."""
        return self.run


_INT_FIELDS = ("stable", "count", "candidate", "run", "direction", "n_edges", "n_illegal",
               "n_rejected", "in_excursion", "n_seen", "first_illegal")


def encoder_init(levels: np.ndarray | list[float]) -> EncoderState:
    """Fresh decoder state for four ascending `levels` [V] (the first sample sets the state).

    Parameters
    ----------
    levels : array_like, shape (4,)
        The four levels of the merged signal [V], strictly ascending.

    Returns
    -------
    EncoderState
        State before the first sample, at count 0.

    Raises
    ------
    ValueError
        If `levels` are not four strictly ascending values.
    """
    levels = np.asarray(levels, dtype=float)
    if levels.shape != (4,) or not np.all(np.diff(levels) > 0):
        raise ValueError(f"need four strictly ascending levels, got {levels.tolist()}")
    return EncoderState(levels=levels.copy())


def decode_step(settings: EncoderSettings, state: EncoderState,
                x: np.ndarray) -> tuple[np.ndarray, EncoderState]:
    """Decode one chunk of the merged signal.

    Parameters
    ----------
    settings : EncoderSettings
    state : EncoderState
        From :func:`encoder_init` or the previous call.
    x : array, shape (n,)
        Encoder samples [V] following those already consumed.

    Returns
    -------
    counts : ndarray of int64, shape (state.n_pending + n - new_state.n_pending,)
        Position in counts of the oldest not-yet-emitted samples, in order: the pending samples
        of `state` first. The caller pairs them with its own buffered samples.
    new_state : EncoderState
    """
    ints = np.array([getattr(state, f) for f in _INT_FIELDS], dtype=np.int64)
    floats = np.concatenate([state.levels, state.sums, state.n_firm])
    counts, ints, floats = _decode_kernel(
        read_only(np.ascontiguousarray(x, dtype=np.float64)), np.asarray(settings.states, dtype=np.int64),
        PHASE, ints, floats, settings.dwell, settings.track_block, settings.track_gain,
        settings.illegal == "continue")
    new = replace(state, levels=floats[0:4].copy(), sums=floats[4:8].copy(),
                  n_firm=floats[8:12].copy(), **{f: int(v) for f, v in zip(_INT_FIELDS, ints)})
    return counts, new


def decode_flush(state: EncoderState) -> np.ndarray:
    """Counts of the pending samples at the end of a recording (a run too short to count).

    Parameters
    ----------
    state : EncoderState
        State after the last chunk.

    Returns
    -------
    numpy.ndarray of int64, shape (state.n_pending,)
        The stable count, once per pending sample.
    """
    return np.full(state.run, state.count, dtype=np.int64)


def decode(x: np.ndarray, levels: np.ndarray | list[float],
           settings: EncoderSettings | None = None) -> tuple[np.ndarray, EncoderState]:
    """Decode a whole merged signal: counts for every sample, and the final state.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Encoder samples [V].
    levels : array_like, shape (4,)
        The four levels [V], strictly ascending (:class:`LevelSurvey` finds them).
    settings : EncoderSettings, optional
        Decoding settings; the defaults when omitted.

    Returns
    -------
    counts : numpy.ndarray of int64, shape (n,)
        Position of each sample [counts].
    state : EncoderState
        The final state (edge, double-transition and rejection counts).
    """
    settings = EncoderSettings() if settings is None else settings
    counts, state = decode_step(settings, encoder_init(levels), x)
    return np.concatenate([counts, decode_flush(state)]), state


# --------------------------------------------------------------------------- kernels


@njit(cache=True, nogil=True)  # nogil: the reader thread parses meanwhile
def _decode_kernel(x, level_code, phase, ints, floats, dwell, block, gain, continue_illegal):
    """Classify, debounce and count; see the module docstring. Returns copies of the state."""
    ints = ints.copy()
    floats = floats.copy()
    stable, count, cand, run, direc = ints[0], ints[1], ints[2], ints[3], ints[4]
    n_edges, n_illegal, n_rejected, exc, n_seen, first_illegal = (
        ints[5], ints[6], ints[7], ints[8], ints[9], ints[10])
    lev = floats[0:4]
    sums = floats[4:8]
    nfirm = floats[8:12]
    t0 = 0.5 * (lev[0] + lev[1])
    t1 = 0.5 * (lev[1] + lev[2])
    t2 = 0.5 * (lev[2] + lev[3])
    firm = 0.25 * min(lev[1] - lev[0], min(lev[2] - lev[1], lev[3] - lev[2]))
    out = np.empty(x.size + run, dtype=np.int64)
    m = 0
    for i in range(x.size):
        v = x[i]
        k = 0
        if v > t0:
            k = 1
        if v > t1:
            k = 2
        if v > t2:
            k = 3
        if block > 0 and abs(v - lev[k]) < firm:
            sums[k] += v
            nfirm[k] += 1.0
        q = level_code[k]
        if stable < 0:
            stable = q
        if q == stable:
            for _ in range(run):  # a run that did not last: noise or bounce, old count
                out[m] = count
                m += 1
            run = 0
            cand = -1
            if exc:
                n_rejected += 1
                exc = 0
            out[m] = count
            m += 1
        else:
            exc = 1
            if q == cand:
                run += 1
            else:
                for _ in range(run):  # caught mid-edge on the way to another level
                    out[m] = count
                    m += 1
                cand = q
                run = 1
            if run >= dwell:
                d = (phase[q] - phase[stable]) & 3
                if d == 1:
                    count += 1
                    direc = 1
                elif d == 3:
                    count -= 1
                    direc = -1
                else:
                    n_illegal += 1
                    if first_illegal < 0:
                        first_illegal = n_seen
                    if continue_illegal:
                        count += 2 * direc
                n_edges += 1
                stable = q
                for _ in range(run):
                    out[m] = count
                    m += 1
                run = 0
                cand = -1
                exc = 0
        n_seen += 1
        if block > 0 and n_seen % block == 0:
            ok = True
            new = lev.copy()
            for j in range(4):
                if nfirm[j] >= 16.0:
                    new[j] += gain * (sums[j] / nfirm[j] - new[j])
                sums[j] = 0.0
                nfirm[j] = 0.0
            for j in range(3):
                if new[j + 1] <= new[j]:
                    ok = False
            if ok:
                lev[:] = new
                t0 = 0.5 * (lev[0] + lev[1])
                t1 = 0.5 * (lev[1] + lev[2])
                t2 = 0.5 * (lev[2] + lev[3])
                firm = 0.25 * min(lev[1] - lev[0], min(lev[2] - lev[1], lev[3] - lev[2]))
    ints[0], ints[1], ints[2], ints[3], ints[4] = stable, count, cand, run, direc
    ints[5], ints[6], ints[7], ints[8], ints[9], ints[10] = (
        n_edges, n_illegal, n_rejected, exc, n_seen, first_illegal)
    return out[:m], ints, floats


# --------------------------------------------------------------------------- reference


def decode_reference(x: np.ndarray, levels: np.ndarray | list[float],
                     settings: EncoderSettings | None = None) -> tuple[np.ndarray, dict]:
    """Plain-NumPy/Python decoder over runs of equal levels, without level tracking.

    The readable statement of what the kernel does (a test asserts both agree): classify by the
    nearest level; runs of one code shorter than ``dwell`` are not states (the first run of the
    recording always is); every long run of a new code is a transition, and all its samples get
    the new count; the samples of short runs get the count of the stable state before them.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Encoder samples [V].
    levels : array_like, shape (4,)
        The four levels [V], ascending.
    settings : EncoderSettings, optional
        Decoding settings (``track_block`` and ``track_gain`` are ignored); the defaults when
        omitted.

    Returns
    -------
    counts : ndarray of int64, shape (n,)
    report : dict
        ``n_edges``, ``n_illegal``, ``n_rejected``, ``first_illegal``.
    """
    settings = EncoderSettings() if settings is None else settings
    levels = np.asarray(levels, dtype=float)
    x = np.asarray(x, dtype=float)
    k = np.searchsorted(0.5 * (levels[1:] + levels[:-1]), x, side="left")
    codes = np.asarray(settings.states)[k]
    starts = np.flatnonzero(np.diff(codes, prepend=-1))
    lengths = np.diff(np.append(starts, x.size))
    counts = np.empty(x.size, dtype=np.int64)
    stable, count, direction, excursion = int(codes[0]), 0, 0, False
    report = {"n_edges": 0, "n_illegal": 0, "n_rejected": 0, "first_illegal": -1}
    for start, length in zip(starts, lengths):
        q = int(codes[start])
        if q == stable:
            report["n_rejected"] += excursion
            excursion = False
        elif length >= settings.dwell:
            step = (int(PHASE[q]) - int(PHASE[stable])) % 4
            if step == 2:
                report["n_illegal"] += 1
                if report["first_illegal"] < 0:
                    report["first_illegal"] = int(start + settings.dwell - 1)
                count += 2 * direction if settings.illegal == "continue" else 0
            else:
                direction = 1 if step == 1 else -1
                count += direction
            report["n_edges"] += 1
            stable, excursion = q, False
        else:
            excursion = True
        counts[start:start + length] = count
    return counts, report
