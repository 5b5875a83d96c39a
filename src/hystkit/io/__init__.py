"""Reading, validating and writing recordings; JSON result files."""

from hystkit.io._recording import (
                                  Recording,
                                  check_output_path,
                                  read_recording,
                                  write_json,
                                  write_recording,
)

__all__ = ["Recording", "check_output_path", "read_recording", "write_json", "write_recording"]
