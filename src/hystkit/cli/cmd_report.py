"""``hystkit report``: one self-contained HTML page of a fit on the user's recordings, or of the
result folders of ``compare``, ``generalize``, ``select --report`` and ``control``."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..compensation import MODEL_SUFFIXES, load_compensator
from ..io import check_output_path
from ..io._atomic import check_folder_writable
from ..studies import build_report, write_report
from ._common import UsageError
from ._read_args import given_read_options
from ._reading import Reader

__all__ = ["run_report"]


def run_report(args: argparse.Namespace) -> int:
    """``hystkit report``: one HTML page of a fit on recordings, or of result folders."""
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
    reading, reader = _model_reading(args.inputs), Reader(given_read_options(args))
    content = build_report(args.inputs, options=lambda path: reader.as_trained(path, reading))
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
    first = inputs[0]
    if len(inputs) < 2 or first.suffix.lower() not in MODEL_SUFFIXES or not first.is_file():
        return None
    return load_compensator(first).reading
