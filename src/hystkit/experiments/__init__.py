"""The reference document's tables and the creep check, measured on the virtual sensor.

- :mod:`.table_5_4`: SINAD and loop area of the lab's signals (raw recordings, preprocessed);
- :mod:`.table_2_2`: RMSE statistics over repeated training and test recordings;
- :mod:`.creep`: a long step-and-hold experiment and the compensators' creep error.

Each returns a dict with the settings, ``rows`` (the table, the document's numbers beside
hystkit's) and the details; :func:`write_table` writes it as JSON + CSV. Names are imported on
first use (PEP 562), so ``hystkit table --help`` loads nothing heavy.
"""

from .._lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_output": ("format_markdown", "output_names", "write_table"),
     "table_5_4": ("DOCUMENT_TABLE_5_4", "SAME_CENTRING_NOTE", "TABLE_5_4_COLUMNS",
                   "Table54Settings", "measure_table_5_4", "signal_scores"),
     "table_2_2": ("DOCUMENT_TABLE_2_2", "TABLE_2_2_COLUMNS", "measure_table_2_2",
                   "rmse_statistics"),
     "creep": ("CREEP_COLUMNS", "CreepPlan", "creep_experiment", "creep_trajectory",
               "hold_levels")},
    first=())
