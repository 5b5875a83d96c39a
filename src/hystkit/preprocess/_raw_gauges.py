"""dR/R of the two gauges from a raw recording at an analysis rate, for :func:`~._spectrum.spectrum`:
eq. 4.3 per sample, then the preprocessing's streaming FIR decimation (no Butterworth).
"""

from __future__ import annotations

import os

import numpy as np

from ..io import RawFormat, open_raw
from ._bridge import relative_change
from ._chain import bridge_resistances, flush_chain, run_chain
from ._decimate import decimator_init, design_chain
from ._raw_records import PreprocessSettings

__all__ = ["raw_gauge_changes"]


def raw_gauge_changes(path: str | os.PathLike[str], settings: PreprocessSettings,
                      fmt: RawFormat | None = None, fs_analysis: float = 1000.0
                      ) -> tuple[dict[str, np.ndarray], float]:
    """dR/R of each gauge and the differential from a raw recording, at about `fs_analysis`.

    Eq. 4.3 per sample (with the measured ``v0`` when ``settings.supply_channel``), then the
    preprocessing's streaming FIR decimation, flat to 0.4 of the output rate; no Butterworth.
    Only ``r_bridge``, ``v_supply``, ``supply_channel`` and ``chunk_size`` of `settings` are used.

    Parameters
    ----------
    path : str or path-like
        Raw recording (``.csv``, ``.parquet``, ``.mat``); see :mod:`hystkit.io`.
    settings : PreprocessSettings
        Bridge and supply settings.
    fmt : RawFormat, optional
        Column names, time unit and metadata of the file.
    fs_analysis : float
        Wanted output rate [Hz].

    Returns
    -------
    rows : dict
        ``dr1``, ``dr2``, ``differential`` [-] (eq. 4.4-4.5).
    fs : float
        Their sample rate [Hz] (the scope rate over a whole factor).

    Raises
    ------
    InputError
        As :func:`preprocess_raw` for the bridge and supply channels.
    """
    reader = open_raw(path, fmt, settings.chunk_size,
                      extra=("v0",) if settings.supply_channel else ())
    factor = max(1, round(reader.fs / fs_analysis))
    fs_a = reader.fs / factor
    chain = design_chain(reader.fs, factor, 0.4 * fs_a)
    states = [decimator_init(stage, 2) for stage in chain]
    ext = np.array([-np.inf, 0, np.inf, 0] * 2, dtype=float)
    parts = []
    for chunk in reader.chunks(columns=("v1", "v2", "v0")):
        r, ext = bridge_resistances(reader, chunk, settings.r_bridge, settings.v_supply, ext)
        parts.append(run_chain(chain, states, r))
    parts.append(flush_chain(chain, states, 2))
    dr1, dr2 = relative_change(np.concatenate(parts, axis=1), axis=1)
    return {"dr1": dr1, "dr2": dr2, "differential": dr1 - dr2}, fs_a
