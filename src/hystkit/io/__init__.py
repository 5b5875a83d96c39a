"""Reading, validating and writing recordings; JSON result files; raw scope recordings."""

from .._read_options import ReadOptions
from ._raw import RAW_COLUMNS, RawChunk, RawFormat, RawReader, RawWriter, open_raw
from ._raw_config import (
    CONFIG_KEYS,
    find_raw_config,
    read_raw_config,
    write_raw_config,
)
from ._recording import Recording, Sampled, read_recording
from ._writing import (
    atomic_folder,
    atomic_output,
    atomic_outputs,
    check_output_folder,
    check_output_path,
    write_json,
    write_recording,
)

__all__ = ["CONFIG_KEYS", "RAW_COLUMNS", "RawChunk", "RawFormat", "RawReader", "RawWriter",
           "ReadOptions",
           "Recording", "Sampled", "atomic_folder", "atomic_output", "atomic_outputs",
           "check_output_folder",
           "check_output_path", "find_raw_config", "open_raw",
           "read_raw_config", "read_recording", "write_json", "write_raw_config", "write_recording"]
