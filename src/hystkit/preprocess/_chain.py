"""The streaming pieces preprocessing and the spectrum share, chunk by chunk.

Eq. 4.3 on a chunk with the bridge-voltage check (:func:`bridge_resistances`,
:func:`raise_bridge`), the running statistics of a measured supply (:class:`SupplyStats`), the
stateful FIR decimation chain run and flushed (:func:`run_chain`, :func:`flush_chain`), and a
reader thread that decodes the next chunk meanwhile (:func:`prefetch`). Used by
:func:`~hystkit.preprocess.preprocess_raw` and :func:`~hystkit.preprocess.raw_gauge_changes`.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Iterator

import numpy as np

from ..io import RawChunk, RawReader
from ._bridge import bridge_kernel
from ._decimate import Decimator, decimator_flush, decimator_step

__all__ = ["SupplyStats", "bridge_resistances", "flush_chain", "prefetch", "raise_bridge",
           "run_chain"]


def bridge_resistances(reader: RawReader, chunk: RawChunk, r_bridge: float, v_supply: float,
                       extremes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauge resistances R1, R2 [Ohm] of a chunk (eq. 4.3), or the reader's error at the first
    bridge voltage outside (0, V0); `extremes` carries the clipping statistics across chunks.

    Parameters
    ----------
    reader : RawReader
        The file's reader (names file, column and row in errors).
    chunk : RawChunk
        Bridge voltages ``v1``, ``v2`` [V] and, when measured, the supply ``v0`` [V].
    r_bridge : float
        Bridge resistor R_br [Ohm].
    v_supply : float
        Nominal supply V0 [V] (used when the chunk has no ``v0``).
    extremes : numpy.ndarray, shape (8,)
        Running extremes and their counts from the previous chunk.

    Returns
    -------
    r : numpy.ndarray, shape (2, chunk.n)
        R1, R2 [Ohm].
    extremes : numpy.ndarray, shape (8,)
        Updated running extremes.
    """
    r, bad, extremes = bridge_kernel(chunk.v1, chunk.v2, float(r_bridge), float(v_supply),
                                     extremes, chunk.v0)
    for g in range(2):
        if bad[g] >= 0:
            raise_bridge(reader, g, chunk, int(bad[g]), v_supply)
    return r, extremes


def raise_bridge(reader: RawReader, g: int, chunk: RawChunk, i: int, v_supply: float) -> None:
    """Raise the reader's error for gauge `g`'s bad bridge voltage at chunk sample `i`."""
    v = (chunk.v1, chunk.v2)[g][i]
    if chunk.v0 is not None:
        v0 = chunk.v0[i]
        if v0 <= 0:
            raise reader.fail(f"measured supply {v0:.6g} V is not positive; is this the supply "
                              "channel, and its polarity right?", "v0", chunk.start + i)
        if v >= v0:
            raise reader.fail(f"measured supply {v0:.6g} V is not above the bridge voltage "
                              f"v{g + 1} = {v:.6g} V, so R_S = R_br (V0 - V_m) / V_m (eq. 4.3) "
                              "is undefined; is this the supply channel (and v1, v2 the bridge "
                              "voltages across R_br)?", "v0", chunk.start + i)
        raise reader.fail(f"bridge voltage {v:.6g} V outside (0, v0 = {v0:.6g} V), where "
                          "R_S = R_br (V0 - V_m) / V_m (eq. 4.3) is undefined (or, within "
                          "1e-12 V0 of 0, absurd); check the channel and its polarity",
                          f"v{g + 1}", chunk.start + i)
    raise reader.fail(f"bridge voltage {v:.6g} V outside (0, V0 = {v_supply:g} V), where "
                      "R_S = R_br (V0 - V_m) / V_m (eq. 4.3) is undefined (or, within 1e-12 V0 "
                      "of 0, absurd); check the channel, its polarity and --v-supply",
                      f"v{g + 1}", chunk.start + i)


class SupplyStats:
    """Running sum, minimum and maximum of the measured supply v0 [V] (nothing when absent)."""

    def __init__(self) -> None:
        self.n, self.total, self.low, self.high = 0, 0.0, np.inf, -np.inf

    def add(self, v0: np.ndarray | None) -> None:
        if v0 is not None and v0.size:
            self.n += v0.size
            self.total += float(np.sum(v0, dtype=float))
            self.low, self.high = min(self.low, float(v0.min())), max(self.high, float(v0.max()))

    def fields(self) -> dict:
        """The report's supply fields."""
        if not self.n:
            return {"supply": "nominal"}
        return {"supply": "measured", "v0_mean_v": self.total / self.n, "v0_min_v": self.low,
                "v0_max_v": self.high}


def run_chain(chain: tuple[Decimator, ...], states: list, x: np.ndarray) -> np.ndarray:
    """Run rows `x` through the decimation stages, updating their `states` in place."""
    for i, stage in enumerate(chain):
        x, states[i] = decimator_step(stage, states[i], x)
    return x


def flush_chain(chain: tuple[Decimator, ...], states: list, n_rows: int) -> np.ndarray:
    """Flush stage by stage: each stage's tail runs through the stages after it."""
    tail = np.zeros((n_rows, 0))
    for i, stage in enumerate(chain):
        if tail.shape[1]:
            tail, states[i] = decimator_step(stage, states[i], tail)
        tail = np.concatenate([tail, decimator_flush(stage, states[i])], axis=1)
    return tail


def prefetch(chunks: Iterator[RawChunk]) -> Iterator[RawChunk]:
    """Read the next chunk in a thread while this one is processed (parsing and decoding
    release the GIL, as do the numba kernels), so two cores share the work."""
    done = object()
    box: queue.Queue = queue.Queue(maxsize=1)
    stop = threading.Event()

    def put(item: object) -> bool:
        while not stop.is_set():
            try:
                box.put(item, timeout=0.1)
                return True
            except queue.Full:
                continue
        return False  # the consumer has gone

    def work() -> None:
        try:
            for item in chunks:
                if not put(item):
                    return
            put(done)
        except Exception as exc:  # noqa: BLE001 -- handed to the consumer, raised there
            put(exc)

    thread = threading.Thread(target=work, daemon=True, name="hystkit-raw-reader")
    thread.start()
    try:
        while True:
            item = box.get()
            if item is done:
                return
            if isinstance(item, Exception):
                raise item
            yield item
    finally:
        stop.set()
        thread.join(timeout=5)
