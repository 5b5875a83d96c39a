"""Figures, tables and the demo report."""

from ._demo import DEMO_FILES, DOCUMENT_TABLE_5_5, format_table, run_demo
from ._figures import plot_loops, plot_time_series

__all__ = ["DEMO_FILES", "DOCUMENT_TABLE_5_5", "format_table", "plot_loops", "plot_time_series",
           "run_demo"]
