"""Reading, validating and writing recordings; JSON result files; raw scope recordings.

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`): reading a CSV
recording should not pay for the raw scope reader or the ``.mat`` machinery (pandas, scipy.io).
"""

from .._lazy import lazy_exports
from .._read_options import ReadOptions as ReadOptions  # cheap: no numpy

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_csv_layout": ("CsvLayout", "csv_layout"),
     "_mat_reader": ("MatContents", "load_mat"),
     "_mat_writer": ("matlab_name", "write_mat"),
     "_other_columns": ("read_other_columns",),
     "_pieces": ("read_pieces",),
     "_raw_format": ("RAW_COLUMNS", "RawChunk", "RawFormat"),
     "_raw_reader": ("RawReader", "open_raw"),
     "_raw_writer": ("RawWriter",),
     "_raw_config": ("CONFIG_KEYS", "find_raw_config", "read_raw_config", "write_raw_config"),
     "_recording": ("MAX_MAGNITUDE", "Recording", "Sampled", "read_recording"),
     "_resample": ("time_gaps",),
     "_training_reading": ("remember_reading", "training_reading", "training_units"),
     "_recording_config": ("find_recording_config", "options_for", "read_recording_config",
                           "settings_for"),
     "_atomic": ("atomic_folder", "atomic_output", "atomic_outputs"),
     "_output_checks": ("check_output_folder", "check_output_format", "check_output_path"),
     "_writing": ("RECORDING_SUFFIXES", "sidecar_path", "units_settings_text", "write_json",
                  "write_recording")},
    first=("ReadOptions",))
