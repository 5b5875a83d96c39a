"""From raw lab signals to fit-ready recordings: bridge, encoder, filters and resampling."""

from ._bridge import (
    bridge_kernel,
    bridge_resistance,
    bridge_voltage,
    clipped_channels,
    first_invalid_bridge_sample,
    gauge_symmetry,
    relative_change,
)
from ._decimate import (
    Decimator,
    DecimatorState,
    decimator_flush,
    decimator_init,
    decimator_step,
    design_chain,
)
from ._encoder import (
    DEFAULT_STATES,
    EncoderSettings,
    EncoderState,
    ab_to_code,
    code_to_ab,
    count_to_code,
    decode,
    decode_flush,
    decode_reference,
    decode_step,
    encoder_init,
    parse_states,
)
from ._filters import downsample, lowpass_zero_phase
from ._levels import LevelSurvey
from ._raw import (
    PreprocessReport,
    PreprocessResult,
    PreprocessSettings,
    RawDataWarning,
    preprocess_raw,
)
from ._spectrum import (
    CutoffRule,
    Spectrum,
    butterworth_response,
    noise_floor,
    raw_gauge_changes,
    spectrum,
    welch_psd,
)

__all__ = ["DEFAULT_STATES", "CutoffRule", "Decimator", "DecimatorState", "EncoderSettings",
           "EncoderState", "LevelSurvey", "PreprocessReport", "PreprocessResult",
           "PreprocessSettings", "RawDataWarning", "Spectrum", "ab_to_code", "bridge_kernel",
           "bridge_resistance", "bridge_voltage", "butterworth_response",
           "clipped_channels", "code_to_ab",
           "count_to_code", "decimator_flush", "decimator_init", "decimator_step", "decode",
           "decode_flush", "decode_reference", "decode_step", "design_chain", "downsample",
           "encoder_init", "first_invalid_bridge_sample", "gauge_symmetry", "lowpass_zero_phase",
           "noise_floor", "parse_states", "preprocess_raw", "raw_gauge_changes",
           "relative_change", "spectrum", "welch_psd"]
