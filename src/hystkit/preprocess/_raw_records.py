"""What :func:`~._raw.preprocess_raw` is told and what it hands back: its settings, its report
(plain numbers, strings and lists, JSON-ready) and its result; the warning it issues.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..io import Recording
from ._encoder import EncoderSettings
from ._quadrature import DEFAULT_STATES

__all__ = ["MAX_CHUNK_SIZE", "PreprocessReport", "PreprocessResult", "PreprocessSettings",
           "RawDataWarning"]

# Memory is about 200 bytes per chunk sample; as the CLI's --chunk-size limit.
MAX_CHUNK_SIZE = 1 << 27


class RawDataWarning(UserWarning):
    """Raw data that were processed but deserve a look (clipping, illegal transitions)."""


@dataclass(frozen=True)
class PreprocessSettings:
    """Settings of :func:`preprocess_raw` (SI units unless noted).

    Parameters
    ----------
    r_bridge, v_supply : float
        Bridge resistor R_br [Ohm] and supply V0 [V] of eq. 4.2 (no defaults: the document used
        10 kOhm / 2 V and 560 Ohm / 1 V, and a wrong value silently scales dR/R).
    supply_channel : bool
        Use the file's measured supply column ``v0`` [V] in eq. 4.3 instead of `v_supply`
        (which is then only the nominal value the report compares the measurement with).
    um_per_count : float
        Encoder resolution [um] (5; eq. 9.16 calibrates it to 5.1).
    position_offset_mm : float
        Added to the position [mm] (the encoder counts from the first sample).
    fs_out, cutoff, order
        Output rate [Hz], Butterworth cut-off [Hz] (<= fs_out / 2) and one-way order.
    encoder_states : tuple of 4 int
        A/B code ``2 A + B`` of the merged levels in ascending order.
    encoder_levels : tuple of 4 float, optional
        The merged levels [V]; found in the data when None.
    encoder_dwell_us : float
        A new encoder level must persist this long [us] (at least 2 samples).
    illegal : {"continue", "hold"}
        Counts added by a double transition: 2 in the last direction, or none.
    max_illegal_fraction : float
        Above this share of illegal state changes (and 10 of them) the position is refused.
    remove_mean, normalise : bool
        Subtract the mean of position and sensor; divide them by their max |.| (eq. 5.10).
    chunk_size : int
        Samples per chunk (2**18; 1 to ``MAX_CHUNK_SIZE``); memory is about 200 bytes per chunk
        sample. Larger chunks are no faster: they fall out of the CPU caches between the passes
        over a chunk. The results do not depend on it, bit for bit.
    mid_factor : int
        The intermediate rate is about ``mid_factor * fs_out``.
    """

    r_bridge: float
    v_supply: float
    supply_channel: bool = False
    um_per_count: float = 5.0
    position_offset_mm: float = 0.0
    fs_out: float = 40.0
    cutoff: float = 20.0
    order: int = 2
    encoder_states: tuple[int, int, int, int] = DEFAULT_STATES
    encoder_levels: tuple[float, ...] | None = None
    encoder_dwell_us: float = 4.0
    illegal: str = "continue"
    max_illegal_fraction: float = 0.01
    remove_mean: bool = False
    normalise: bool = False
    chunk_size: int = 1 << 18
    mid_factor: int = 10

    def __post_init__(self) -> None:
        for name in ("r_bridge", "v_supply", "um_per_count", "fs_out", "cutoff",
                     "encoder_dwell_us"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number, got {value!r}")
        if self.cutoff > self.fs_out / 2:
            raise ValueError(f"cutoff {self.cutoff:g} Hz is above fs_out / 2 = "
                             f"{self.fs_out / 2:g} Hz: the output would alias")
        if not (1 <= self.order <= 20 and 1 <= self.chunk_size <= MAX_CHUNK_SIZE
                and self.mid_factor >= 4):
            raise ValueError(f"order must lie in [1, 20], chunk_size in [1, {MAX_CHUNK_SIZE}] "
                             f"and mid_factor be >= 4 (got {self.order}, {self.chunk_size}, "
                             f"{self.mid_factor})")
        if not 0 <= self.max_illegal_fraction <= 1:
            raise ValueError("max_illegal_fraction must lie in [0, 1]")
        EncoderSettings(states=self.encoder_states, illegal=self.illegal)  # validates both
        if self.encoder_levels is not None and (
                len(self.encoder_levels) != 4 or not np.all(np.diff(self.encoder_levels) > 0)):
            raise ValueError(f"encoder_levels must be four ascending voltages, "
                             f"got {self.encoder_levels}")


@dataclass(frozen=True)
class PreprocessReport:
    """What :func:`preprocess_raw` found; every field is a plain number, string or list.

    Parameters
    ----------
    source : str
        The raw file.
    n_samples : int
        Raw samples per channel.
    fs : float
        Raw sample rate [Hz].
    duration_s : float
        ``n_samples / fs`` [s].
    fs_mid : float
        Intermediate rate after the FIR decimation [Hz].
    fs_out : float
        Output rate [Hz].
    n_out : int
        Output samples.
    decimation : list of [int, int]
        (factor, taps) of each FIR decimation stage.
    encoder_kind : {"merged", "ab"}
        One merged 4-level channel, or separate A and B channels.
    encoder_levels, encoder_levels_end : list of float
        The four levels at the start and, tracked, at the end [V] (for A/B channels the
        codes 0, 1, 2, 3, not voltages).
    encoder_dwell_samples : int
        The encoder dwell [samples].
    n_edges : int
        Accepted encoder state changes.
    n_illegal : int
        Of them, double transitions.
    first_illegal_s : float or None
        Time of the first double transition [s]; None if there was none.
    n_rejected : int
        Short encoder excursions that returned to the stable level.
    r1_mean_ohm, r2_mean_ohm : float
        Mean gauge resistances of the output [Ohm].
    symmetry : float
        Gauge symmetry ``2 (R1 - R2) / (R1 + R2)`` [-].
    clipped : dict of str to int
        Samples at the extreme of each clipped channel, such as ``{"v1_max": 1200}``.
    supply : {"nominal", "measured"}
        Whether eq. 4.3 used the nominal V0 or the measured supply column.
    v0_mean_v, v0_min_v, v0_max_v : float or None
        Mean, minimum and maximum of the measured supply [V]; None when nominal.
    warnings : list of str
        The :class:`RawDataWarning` messages issued.
    seconds : float
        Wall time of the run [s].
    encoder_thresholds_v : list of float or None
        For A/B channels, the logic threshold of ``enc_a`` and of ``enc_b`` [V] (midway
        between each channel's two levels); None for a merged channel.
    """

    source: str
    n_samples: int
    fs: float
    duration_s: float
    fs_mid: float
    fs_out: float
    n_out: int
    decimation: list[list[int]]
    encoder_kind: str
    encoder_levels: list[float]
    encoder_levels_end: list[float]
    encoder_dwell_samples: int
    n_edges: int
    n_illegal: int
    first_illegal_s: float | None
    n_rejected: int
    r1_mean_ohm: float
    r2_mean_ohm: float
    symmetry: float
    clipped: dict[str, int]
    supply: str = "nominal"
    v0_mean_v: float | None = None
    v0_min_v: float | None = None
    v0_max_v: float | None = None
    warnings: list[str] = field(default_factory=list)
    seconds: float = 0.0
    encoder_thresholds_v: list[float] | None = None

    def to_dict(self) -> dict:
        """The report as a JSON-ready dict."""
        return asdict(self)


@dataclass(frozen=True, eq=False)
class PreprocessResult:
    """Output of :func:`preprocess_raw`.

    Parameters
    ----------
    recording : Recording
        Time [s], position [mm], sensor dR1/R1 - dR2/R2 [-] at ``fs_out``.
    extra : dict of str to numpy.ndarray
        ``r1``, ``r2`` [Ohm] and ``dr1``, ``dr2`` [-] on the same time grid.
    report : PreprocessReport
        Counts, levels, symmetry and warnings.
    """

    recording: Recording
    extra: dict[str, np.ndarray]
    report: PreprocessReport
