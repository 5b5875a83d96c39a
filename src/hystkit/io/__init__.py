"""Reading, validating and writing recordings; JSON result files; raw scope recordings."""

from .._read_options import ReadOptions
from ._mat_reader import MatContents, load_mat
from ._mat_writer import matlab_name, write_mat
from ._other_columns import read_other_columns
from ._raw import RAW_COLUMNS, RawChunk, RawFormat, RawReader, RawWriter, open_raw
from ._raw_config import (
    CONFIG_KEYS,
    find_raw_config,
    read_raw_config,
    write_raw_config,
)
from ._recording import Recording, Sampled, read_recording
from ._recording_config import find_recording_config, options_for, read_recording_config
from ._writing import (
    RECORDING_SUFFIXES,
    atomic_folder,
    atomic_output,
    atomic_outputs,
    check_output_folder,
    check_output_format,
    check_output_path,
    sidecar_path,
    units_settings_text,
    write_json,
    write_recording,
)

__all__ = [
    "CONFIG_KEYS",
    "RAW_COLUMNS",
    "RECORDING_SUFFIXES",
    "MatContents",
    "RawChunk",
    "RawFormat",
    "RawReader",
    "RawWriter",
    "ReadOptions",
    "Recording",
    "Sampled",
    "atomic_folder",
    "atomic_output",
    "atomic_outputs",
    "check_output_folder",
    "check_output_format",
    "check_output_path",
    "find_raw_config",
    "find_recording_config",
    "load_mat",
    "matlab_name",
    "open_raw",
    "options_for",
    "read_other_columns",
    "read_raw_config",
    "read_recording",
    "read_recording_config",
    "sidecar_path",
    "units_settings_text",
    "write_json",
    "write_mat",
    "write_raw_config",
    "write_recording",
]
