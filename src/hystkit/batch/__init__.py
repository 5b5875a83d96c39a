"""``hystkit batch``: a fleet of sensors fitted from a manifest or a folder of recordings, one
model file per sensor and one results table, resumable, in parallel on `hystkit.parallel`."""

from ._manifest import RECORDING_SUFFIXES, SensorJob, jobs_from_folder, read_manifest
from ._run import RESULT_COLUMNS, fit_sensor, pending, run_batch

__all__ = ["RECORDING_SUFFIXES", "RESULT_COLUMNS", "SensorJob", "fit_sensor",
           "jobs_from_folder", "pending", "read_manifest", "run_batch"]
