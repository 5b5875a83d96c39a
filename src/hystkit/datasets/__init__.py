"""Public hysteresis data sets (``shared/data``) loaded into one structure, `Dataset`.

Every loader returns time [s], the system's physical input and output with units, a
description and the provenance (repository, commit, path, licence, credit) of the files.
``Dataset.to_recording()`` gives a hystkit `Recording` with ``position`` = input and
``sensor`` = output, so `~hystkit.compensation.fit_compensator` learns output -> input (a
sensor compensator, or the inverse model of an actuator's feedforward).

The full data are not part of the package: loaders look for them via ``root=``, then
``$HYSTKIT_SHARED_DATA``, then a folder ``shared/data`` above the current directory or the
source tree. Every data set says where its files come from and where they go
(`DatasetInfo.provenance`, ``hystkit datasets show NAME``); a loader that does not find them
raises `DataNotFoundError`, one line saying so. Small excerpts are shipped
(:func:`load_excerpt`) for tests and examples.
"""

from ._bh_loops import load_bh_loops
from ._boucwen import load_boucwen
from ._dataset import ROLES, Dataset, DatasetInfo, MissingDependencyError, Provenance, VariantInfo
from ._excerpts import EXCERPT_DIR, EXCERPTS, ExcerptSpec, list_excerpts, load_excerpt
from ._files import ENV_VAR, DataNotFoundError, find_root
from ._micromanipulator import load_piezo_micromanipulator
from ._mr_damper import load_mr_damper
from ._piezo_actuator import load_piezo_actuator
from ._registry import DATASETS, dataset_info, list_datasets, load, shared_data_status

__all__ = ["DATASETS", "ENV_VAR", "EXCERPTS", "EXCERPT_DIR", "ROLES", "DataNotFoundError",
           "Dataset", "DatasetInfo", "ExcerptSpec", "MissingDependencyError", "Provenance", "VariantInfo", "dataset_info",
           "find_root", "list_datasets", "list_excerpts", "load", "load_bh_loops",
           "load_boucwen", "load_excerpt", "load_mr_damper", "load_piezo_actuator",
           "load_piezo_micromanipulator", "shared_data_status"]
