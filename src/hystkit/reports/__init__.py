"""Figures, tables and reports: the demo, compare / generalize, select."""

from ._compare import (
    compare_models,
    format_compare,
    generalization_matrix,
    plot_generalization,
)
from ._demo import DEMO_FILES, DOCUMENT_TABLE_5_5, format_table, run_demo
from ._figures import plot_loops, plot_time_series
from ._report_model import ReportContent, model_report
from ._report_page import FIGURE_FORMATS, build_report, write_report
from ._select import Candidate, candidates, folds, plot_selection, select_model

__all__ = ["DEMO_FILES", "DOCUMENT_TABLE_5_5", "FIGURE_FORMATS", "Candidate", "ReportContent",
           "build_report", "candidates", "compare_models", "folds", "format_compare",
           "format_table", "generalization_matrix", "model_report", "plot_generalization",
           "plot_loops", "plot_selection", "plot_time_series", "run_demo", "select_model",
           "write_report"]
