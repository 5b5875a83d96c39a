"""Finding the distinct voltage levels of an encoder channel (merged: 4, logic: 2).

The merged signal of sec. 4.2.1 sits on one of four levels except during edges; a logic
channel on one of two. A level is a cluster of the value histogram: a run of bins that each
hold at least ``min_fraction`` of the samples. Edge samples and spikes are too few to make
one, and the noise bump of one level is never split (gaps of up to 3 bins are bridged).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

__all__ = ["LevelSurvey"]


@dataclass(frozen=True)
class LevelSurvey:
    """Distinct levels seen so far: value clusters as (centre, low, high, weight) rows.

    Use :meth:`add` chunk by chunk (it returns a new survey) until :attr:`n_levels` reaches the
    number wanted. A chunk's clusters are runs of histogram bins holding at least ``min_fraction``
    of the chunk; isolated samples (edges, spikes) never make a cluster.

    Parameters
    ----------
    clusters : tuple of (float, float, float, int)
        (centre [V], low [V], high [V], samples) of each level found, ascending; empty to
        start.
    n_samples : int
        Samples surveyed so far.
    n_bins : int
        Histogram bins per chunk.
    min_fraction : float
        Share of a chunk's samples a bin must hold to belong to a level.
    """

    clusters: tuple[tuple[float, float, float, int], ...] = ()
    n_samples: int = 0
    n_bins: int = 256
    min_fraction: float = 1e-3

    @property
    def n_levels(self) -> int:
        """Number of distinct levels found."""
        return len(self.clusters)

    @property
    def centres(self) -> np.ndarray:
        """Level centres [V], ascending."""
        return np.array([c[0] for c in self.clusters])

    def add(self, x: np.ndarray) -> LevelSurvey:
        """Survey one more chunk."""
        x = np.asarray(x, dtype=float)
        if x.size == 0:
            return self
        merged = list(self.clusters)
        for cluster in self._chunk_clusters(x):
            merged = _merge_cluster(merged, cluster)
        return replace(self, clusters=tuple(sorted(merged)), n_samples=self.n_samples + x.size)

    def _chunk_clusters(self, x: np.ndarray) -> list[tuple[float, float, float, int]]:
        lo, hi = float(x.min()), float(x.max())
        if hi - lo <= 1e-12 * max(1.0, abs(hi)):
            return [(lo, lo, hi, int(x.size))]
        counts, edges = np.histogram(x, bins=self.n_bins, range=(lo, hi))
        occupied = counts >= max(2, self.min_fraction * x.size)
        found: list[tuple[float, float, float, int]] = []
        start = None
        gap = 0
        for j in range(self.n_bins + 1):
            if j < self.n_bins and occupied[j]:
                start = j if start is None else start
                gap = 0
                end = j
                continue
            if start is None:
                continue
            gap += 1
            # A bin or three dipping under the threshold inside one level's noise bump is not a
            # gap between levels (those are tens of bins wide).
            if gap <= 3 and j < self.n_bins:
                continue
            w = counts[start:end + 1]
            centres = 0.5 * (edges[start:end + 1] + edges[start + 1:end + 2])
            found.append((float(np.dot(w, centres) / w.sum()), float(edges[start]),
                          float(edges[end + 1]), int(w.sum())))
            start, gap = None, 0
        return found


def _merge_cluster(clusters: list, new: tuple) -> list:
    """Merge `new` into the overlapping cluster of `clusters` (intervals widened by a quarter)."""
    c, lo, hi, w = new
    pad = 0.25 * (hi - lo)
    for i, (c2, lo2, hi2, w2) in enumerate(clusters):
        pad2 = 0.25 * (hi2 - lo2)
        if lo - pad <= hi2 + pad2 and lo2 - pad2 <= hi + pad:
            total = w + w2
            clusters[i] = ((c * w + c2 * w2) / total, min(lo, lo2), max(hi, hi2), total)
            return clusters
    return clusters + [new]
