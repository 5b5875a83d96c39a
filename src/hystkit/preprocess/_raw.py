"""From a raw scope recording to a fit-ready 40 Hz recording, in one streaming pass.

The document's MATLAB post-processing (sec. 4.3.1-4.3.2, appendix 9.7-9.8) as a pipeline whose
memory is bounded by the chunk size, not the recording length:

1. read a chunk (:func:`hystkit.io.open_raw`: CSV, Parquet, .mat);
2. bridge voltages -> gauge resistances R1, R2 at the scope rate (eq. 4.3), after checking
   ``0 < V_m < V0`` and counting samples stuck at a channel's extreme (clipping); V0 is the
   nominal supply, or with ``supply_channel`` the measured supply ``v0`` of each sample (the
   reference channel of sec. 4.2.1), which removes the supply's drift from R1 and R2;
3. encoder -> counts (level survey, debounce, quadrature state machine: :mod:`._encoder`);
4. R1, R2 and the count go through stateful FIR decimation stages (:mod:`._decimate`) to an
   intermediate rate ``fs_mid`` of about ``mid_factor * fs_out`` (400 Hz by default);
5. on that small signal, the document's zero-phase Butterworth (eq. 4.1; 2nd order, 20 Hz),
   then every ``fs_mid / fs_out``-th sample (or linear interpolation onto the ``fs_out`` grid
   when the rates are not integer multiples);
6. position [mm] = counts * um_per_count / 1000 + offset, relative to the first sample;
   dR/R per gauge about its mean (eq. 4.4-4.5), the differential output dR1/R1 - dR2/R2 and the
   gauge symmetry 2 (R1 - R2) / (R1 + R2); optional mean removal and normalisation (eq. 5.10).

Converting to resistance before filtering (not after) keeps the non-linear eq. 4.3 from
biasing the result with the scope noise. Unless the levels are given, the encoder column is
first surveyed from the start until all four levels have been seen (usually within the first
chunk; at worst the column is read twice). A reader thread decodes the next chunk while the
current one is processed.
"""

from __future__ import annotations

import math
import os
import sys
import time as _time
import warnings

import numpy as np
from tqdm import tqdm

from ..io import RawFormat, RawReader, Recording, open_raw
from ._bridge import clipped_channels, gauge_symmetry
from ._chain import SupplyStats, bridge_resistances, flush_chain, prefetch, run_chain
from ._decimate import (
    Decimator,
    decimator_init,
    design_chain,
)
from ._encoder import EncoderSettings, EncoderState, decode_flush, decode_step, encoder_init
from ._encoder_survey import encoder_setup
from ._filters import lowpass_zero_phase
from ._quadrature import ab_to_code
from ._raw_records import PreprocessReport, PreprocessResult, PreprocessSettings, RawDataWarning

__all__ = ["preprocess_raw"]

def preprocess_raw(path: str | os.PathLike[str], settings: PreprocessSettings,
                   fmt: RawFormat | None = None, *, progress: bool = False) -> PreprocessResult:
    """Turn a raw scope recording into position and dR/R at ``settings.fs_out``.

    Parameters
    ----------
    path : str or path-like
        Raw recording (``.csv``, ``.parquet``, ``.mat``); see :mod:`hystkit.io`.
    settings : PreprocessSettings
    fmt : RawFormat, optional
        Column names, time unit and metadata (``fs``, ``n_samples``) of the file.
    progress : bool
        Show a progress bar on stderr (only on a terminal).

    Returns
    -------
    PreprocessResult

    Raises
    ------
    InputError
        Unreadable, truncated or inconsistent file; bridge voltage outside (0, V0); a flat
        encoder, fewer or more than four merged levels; too many illegal transitions; a
        recording too short for the filters. Named by file, column and row.

    Warns
    -----
    RawDataWarning
        A channel that looks clipped, or illegal encoder transitions (with their count).
    """
    t_start = _time.perf_counter()
    reader = open_raw(path, fmt, settings.chunk_size,
                      extra=("v0",) if settings.supply_channel else ())
    fs = reader.fs
    factor = max(1, round(fs / (settings.mid_factor * settings.fs_out)))
    fs_mid = fs / factor
    if fs_mid < 4 * settings.fs_out or settings.cutoff >= fs_mid / 2:
        raise reader.fail(f"sample rate {fs:.6g} Hz is too low for fs_out = "
                          f"{settings.fs_out:g} Hz (need at least {4 * settings.fs_out:g} Hz)")
    chain = design_chain(fs, factor, min(2 * settings.cutoff, fs_mid / 4))
    dwell = max(2, math.ceil(settings.encoder_dwell_us * 1e-6 * fs - 1e-9))
    enc_settings, levels, logic = encoder_setup(reader, settings, dwell)
    enc_state = encoder_init(levels)

    # R and the count run through separate decimator states: each stream's output k is centred
    # on raw sample k * factor however far the stream has got, so the few samples the decoder
    # holds back (pending its dwell decision) need no re-alignment.
    r_states = [decimator_init(stage, 2) for stage in chain]
    c_states = [decimator_init(stage, 1) for stage in chain]
    mid_r: list[np.ndarray] = []
    mid_c: list[np.ndarray] = []
    extremes = np.array([-np.inf, 0, np.inf, 0] * 2, dtype=float)
    supply = SupplyStats()
    t0 = 0.0
    bar = tqdm(total=reader.n_samples, unit="sample", unit_scale=True, file=sys.stderr,
               disable=None if progress else True, mininterval=0.5, desc="preprocess")
    for chunk in prefetch(reader.chunks()):
        if chunk.start == 0 and chunk.time is not None:
            t0 = float(chunk.time[0])
        r, extremes = bridge_resistances(reader, chunk, settings.r_bridge, settings.v_supply,
                                         extremes)
        supply.add(chunk.v0)
        x = chunk.encoder if logic is None else ab_to_code(chunk.enc_a, chunk.enc_b, *logic)
        counts, enc_state = decode_step(enc_settings, enc_state, x)
        mid_r.append(run_chain(chain, r_states, r))
        mid_c.append(run_chain(chain, c_states, counts[np.newaxis].astype(float)))
        bar.update(chunk.n)
    bar.close()
    mid_c.append(run_chain(chain, c_states, decode_flush(enc_state)[np.newaxis].astype(float)))
    mid_r.append(flush_chain(chain, r_states, 2))
    mid_c.append(flush_chain(chain, c_states, 1))
    mid = np.vstack([np.concatenate(mid_r, axis=1), np.concatenate(mid_c, axis=1)])
    return _finish(reader, settings, mid, t0, reader.fs, factor, chain, enc_settings, enc_state,
                   levels, logic, extremes, supply, reader.n_samples or 0, t_start)


# --------------------------------------------------------------------------- pieces


def _finish(reader: RawReader, settings: PreprocessSettings, mid: np.ndarray, t0: float,
            fs: float, factor: int, chain: tuple[Decimator, ...], enc: EncoderSettings,
            state: EncoderState, levels: np.ndarray, logic: tuple | None, extremes: np.ndarray,
            supply: SupplyStats, n: int, t_start: float) -> PreprocessResult:
    fs_mid = fs / factor
    notes = []
    n_illegal, n_edges = state.n_illegal, state.n_edges
    first_illegal = None if state.first_illegal < 0 else t0 + state.first_illegal / fs
    if n_illegal >= 10 and n_illegal > settings.max_illegal_fraction * n_edges:
        raise reader.fail(f"{n_illegal} of {n_edges} state changes are illegal double "
                          f"transitions (first at t = {first_illegal:.6g} s): the position "
                          "cannot be trusted; the sample rate may be too low for the motion, "
                          "or the encoder levels, --encoder-states or --encoder-dwell wrong",
                          "encoder" if logic is None else "enc_a")
    if n_illegal:
        policy = ("added 2 counts in the direction of travel" if enc.illegal == "continue"
                  else "added nothing")
        notes.append(f"{reader.source}: encoder: {n_illegal} illegal double transition(s) of "
                     f"{n_edges} state changes (first at t = {first_illegal:.6g} s); "
                     f"{policy} for each, so the position may be off by up to "
                     f"{2 * n_illegal} counts ({2 * n_illegal * settings.um_per_count:g} um)")
    if n_edges == 0:  # only possible with given levels; the survey refuses a flat channel
        notes.append(f"{reader.source}: encoder: no state change in {n} samples, so the "
                     "position is constant: a flat encoder channel, or wrong --encoder-levels?")
    clipped = clipped_channels(extremes, n)
    for key, (count, value) in clipped.items():
        column, side = key.split("_")
        notes.append(f"{reader.source}: column {column!r}: {count} samples "
                     f"({100 * count / n:.3g} %) sit exactly at the channel's {side}imum "
                     f"{value:.6g} V: the scope channel looks clipped, and dR/R is wrong there")
    for note in notes:
        warnings.warn(note, RawDataWarning, stacklevel=3)

    try:
        smooth = lowpass_zero_phase(mid, fs_mid, settings.cutoff, settings.order)
    except ValueError as exc:
        raise reader.fail(f"recording too short for the {settings.cutoff:g} Hz filter "
                          f"({mid.shape[1]} samples at {fs_mid:.6g} Hz; {exc})") from exc
    ratio = fs_mid / settings.fs_out
    if abs(ratio - round(ratio)) < 1e-6 * ratio:
        out = smooth[:, ::round(ratio)]
        # The nominal grid: fs estimated from float time stamps is off by ~1e-12, which would
        # only print as 0.025000000000000612.
        t = t0 + np.arange(out.shape[1]) / settings.fs_out
    else:
        t_mid = np.arange(mid.shape[1]) / fs_mid
        t = np.arange(math.floor(t_mid[-1] * settings.fs_out + 1e-9) + 1) / settings.fs_out
        out = np.vstack([np.interp(t, t_mid, row) for row in smooth])
        t = t0 + t
    r1, r2, counts = out
    if out.shape[1] < 2:
        raise reader.fail(f"recording too short: {n} samples give {out.shape[1]} output sample(s)")
    dr1, dr2 = (r1 - r1.mean()) / r1.mean(), (r2 - r2.mean()) / r2.mean()  # eq. 4.4-4.5
    position = counts * settings.um_per_count * 1e-3 + settings.position_offset_mm
    sensor = dr1 - dr2
    if settings.remove_mean:
        position, sensor = position - position.mean(), sensor - sensor.mean()
    if settings.normalise:
        position = position / _max_abs(position)
        sensor = sensor / _max_abs(sensor)
    recording = Recording(time=t, sensor=sensor, position=position, source=reader.source)
    report = PreprocessReport(
        source=reader.source, n_samples=n, fs=fs, duration_s=n / fs, fs_mid=fs_mid,
        fs_out=settings.fs_out, n_out=int(t.size),
        decimation=[[s.factor, int(s.taps.size)] for s in chain],
        encoder_kind=reader.encoder_kind, encoder_levels=[float(v) for v in levels],
        encoder_levels_end=[float(v) for v in state.levels],
        encoder_dwell_samples=enc.dwell, n_edges=n_edges, n_illegal=n_illegal,
        first_illegal_s=first_illegal, n_rejected=state.n_rejected,
        r1_mean_ohm=float(r1.mean()), r2_mean_ohm=float(r2.mean()),
        symmetry=gauge_symmetry(r1, r2), clipped={k: c for k, (c, _) in clipped.items()},
        **supply.fields(), warnings=notes,
        seconds=_time.perf_counter() - t_start,
        encoder_thresholds_v=None if logic is None else [float(v) for v in logic])
    return PreprocessResult(recording, {"r1": r1, "r2": r2, "dr1": dr1, "dr2": dr2}, report)


def _max_abs(x: np.ndarray) -> float:
    peak = float(np.max(np.abs(x)))
    return peak if peak > 0 else 1.0
