"""Reading, validating and writing recordings; JSON result files."""

from hystkit.io._recording import Recording, read_recording, write_json, write_recording

__all__ = ["Recording", "read_recording", "write_json", "write_recording"]
