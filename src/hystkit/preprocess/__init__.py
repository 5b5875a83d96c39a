"""From raw lab signals to fit-ready recordings: bridge, encoder, filters and resampling.

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`): the virtual
sensor needs only the filters, not the raw-file reader (pandas, ~1 s to import).
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_bridge": ("bridge_kernel", "bridge_resistance", "bridge_voltage", "clipped_channels",
                 "first_invalid_bridge_sample", "gauge_symmetry", "relative_change"),
     "_decimate": ("Decimator", "DecimatorState", "decimator_flush", "decimator_init",
                   "decimator_step", "design_chain"),
     "_encoder": ("EncoderSettings", "EncoderState", "decode", "decode_flush",
                  "decode_reference", "decode_step", "encoder_init"),
     "_filters": ("downsample", "lowpass_zero_phase"),
     "_levels": ("LevelSurvey",),
     "_quadrature": ("DEFAULT_STATES", "ab_to_code", "code_to_ab", "count_to_code",
                     "parse_states"),
     "_raw": ("preprocess_raw",),
     "_raw_records": ("PreprocessReport", "PreprocessResult", "PreprocessSettings",
                      "RawDataWarning"),
     "_spectrum": ("CutoffRule", "Spectrum", "butterworth_response", "noise_floor", "spectrum",
                   "welch_psd"),
     "_raw_gauges": ("raw_gauge_changes",),
     },
    first=())
