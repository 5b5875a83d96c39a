"""Figures, tables and reports: the demo, compare / generalize, select.

Names are imported on first use (PEP 562, :func:`hystkit._lazy.lazy_exports`): ``compare``
and ``select`` need no part of the demo, whose preprocessing imports scipy.signal (~1 s).
"""

from .._lazy import lazy_exports

# What drawing a figure and saving it as PNG imports (~0.3 s): a parallel command loads them
# while its workers run (`hystkit.parallel.loading_meanwhile`).
FIGURE_MODULES = ("matplotlib.figure", "matplotlib.backends.backend_agg")

__getattr__, __dir__ = lazy_exports(
    __name__, globals(),
    {"_compare": ("compare_models", "format_compare", "generalization_matrix",
                  "plot_generalization"),
     "_demo": ("DEMO_FILES", "DOCUMENT_TABLE_5_5", "format_table", "run_demo"),
     "_figures": ("plot_loops", "plot_time_series"),
     "_report_model": ("ReportContent", "model_report"),
     "_report_page": ("FIGURE_FORMATS", "build_report", "write_report"),
     "_select": ("Candidate", "candidates", "plot_selection", "select_model"),
     "_text_table": ("format_number", "text_table"),
     },
    first=("FIGURE_MODULES",))
