"""Studies of fitted models: the demo, compare / generalize, select, the HTML report, and the
reference document's tables and creep check measured on the virtual sensor.

- reports: :func:`run_demo`, :func:`compare_models`, :func:`select_model`, :func:`build_report`;
- the document's tables (:mod:`.table_5_4`, :mod:`.table_2_2`) and the creep check
  (:mod:`.creep`), each a dict with the settings, ``rows`` (the document's numbers beside
  hystkit's) and the details; :func:`write_table` writes it as JSON + CSV.

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`): ``compare``
and ``select`` need no part of the demo, whose preprocessing imports scipy.signal (~1 s), and
``hystkit table --help`` loads nothing heavy.
"""

from .._lazy import lazy_exports

# What drawing a figure and saving it as PNG imports (~0.3 s): a parallel command loads them
# while its workers run (`hystkit.parallel.loading_meanwhile`).
FIGURE_MODULES = ("matplotlib.figure", "matplotlib.backends.backend_agg")

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_compare": ("compare_models", "format_compare"),
     "_generalize": ("generalization_matrix",),
     "_generalization_plot": ("plot_generalization",),
     "_demo": ("DEMO_FILES", "DOCUMENT_TABLE_5_5", "format_table", "run_demo"),
     "_figures": ("plot_loops", "plot_time_series"),
     "_guided": ("explain_choice", "guided_candidates", "guided_select", "selection_status"),
     "_report_model": ("ReportContent", "model_report"),
     "_report_page": ("FIGURE_FORMATS", "build_report", "write_report"),
     "_select": ("Candidate", "candidates", "plot_selection", "select_model"),
     "_text_table": ("format_number", "text_table"),
     "_output": ("format_markdown", "output_names", "write_table"),
     "table_5_4": ("DOCUMENT_TABLE_5_4", "SAME_CENTRING_NOTE", "TABLE_5_4_COLUMNS",
                   "Table54Settings", "measure_table_5_4", "signal_scores"),
     "table_2_2": ("DOCUMENT_TABLE_2_2", "TABLE_2_2_COLUMNS", "measure_table_2_2",
                   "rmse_statistics"),
     "creep": ("CREEP_COLUMNS", "CreepPlan", "creep_experiment", "creep_trajectory",
               "hold_levels")},
    first=("FIGURE_MODULES",))
