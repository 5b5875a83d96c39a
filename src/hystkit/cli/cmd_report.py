"""``hystkit report``: one self-contained HTML page of a fit on the user's recordings, or of the
result folders of ``compare``, ``generalize``, ``select --report`` and ``control``."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import UsageError, add_read_options
from ._own_layout import add_trained_note, options_as_trained

__all__ = ["register"]

FORMATS = ("png", "svg", "pdf")  # as reports.FIGURE_FORMATS, without loading the library


def _report(args: argparse.Namespace) -> int:
    from ..io import check_output_path
    from ..io._atomic import check_folder_writable
    from ..studies import build_report, write_report

    if args.format != "png" and args.figures is None:
        raise UsageError("--format chooses the figure files' format; give --figures DIR too")
    check_output_path(args.out, args.force, inputs=args.inputs, formats=(".html", ".htm"),
                      what="the report (one HTML page)")
    if args.figures is not None:
        if args.figures.exists() and not args.figures.is_dir():
            raise UsageError(f"--figures {args.figures}: is a file, not a folder")
        check_folder_writable(args.figures)
    # each recording with its settings file, the command line's reading options on top, or
    # as the model's training data were read
    reading = _model_reading(args.inputs)
    content = build_report(args.inputs,
                           options=lambda path: options_as_trained(args, path, reading))
    paths = write_report(content, args.out, figures=args.figures, fmt=args.format,
                         force=args.force)
    size = paths[0].stat().st_size
    print(f"wrote {paths[0]} ({size / 1e6:.2f} MB, {len(content.pngs)} figure(s) embedded)")
    if len(paths) > 1:
        print(f"wrote {len(paths) - 1} figure file(s) to {args.figures}/")
    png_only = sorted(set(content.pngs) - set(content.figures))
    if args.figures is not None and args.format != "png" and png_only:
        print(f"  as PNG only (a control run's own figures): {', '.join(png_only)}")
    return 0


def _model_reading(inputs: list[Path]):
    """How the training data of the model file among `inputs` (the first, before
    recordings) were read; None for result folders (the page's builder names a wrong mix)."""
    from ..compensation import MODEL_SUFFIXES, load_compensator

    first = inputs[0]
    if len(inputs) < 2 or first.suffix.lower() not in MODEL_SUFFIXES or not first.is_file():
        return None
    return load_compensator(first).reading


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``hystkit report``."""
    p = sub.add_parser(
        "report", help="one self-contained HTML page of a fit on your recordings, or of "
                       "compare / generalize / select / control output folders",
        description="MODEL.json RECORDING... : the model file's provenance, fit (parameters "
                    "with standard errors, bound hits, status), deployable and oracle scores, "
                    "loops with the error against the position, whole time series with the "
                    "error. FOLDER... : the tables and figures of compare, generalize, "
                    "select --report or control output folders. Figures are embedded; the "
                    "page loads nothing from outside.")
    p.add_argument("inputs", type=Path, nargs="+", metavar="INPUT",
                   help="a model file (from 'hystkit fit') followed by one or more recordings "
                        "(CSV/Parquet/.mat with a position column), or one or more result "
                        "folders")
    p.add_argument("--out", type=Path, required=True, help="HTML file to write (.html)")
    p.add_argument("--figures", type=Path, metavar="DIR",
                   help="also write every figure as PNG (and --format) files into DIR")
    p.add_argument("--format", choices=FORMATS, default="png",
                   help="format of the figure files beside PNG: svg or pdf (default png only; "
                        "needs --figures)")
    add_read_options(p)
    add_trained_note(p)
    p.set_defaults(run=_report)
