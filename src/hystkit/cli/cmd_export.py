"""``hystkit export MODEL --lang c|matlab --out DIR``: the compensator as code (issue 12).

C99 without dependencies for microcontrollers (``float`` unless ``--double``), or MATLAB /
Octave functions (chunk, init and a persistent-state variant for Simulink). The folder is
written atomically; an existing one only with ``--force`` (also one created by another export
while this one built its files). A family or mode without a translation, and ``--double``
with MATLAB, are refused with the reason (exit 2).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

from ..compensation import load_compensator
from ..export import COMPILE_LINE, export_compensator, float_warning

__all__ = ["ExportOptions", "export", "run_export"]


@dataclass(frozen=True)
class ExportOptions:
    """``hystkit export``'s options, as parsed."""

    model: Path
    lang: str  # "c" or "matlab"
    out: Path
    double: bool
    name: str | None
    level: float | None
    force: bool

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ExportOptions:
        """The options of a parsed ``export`` command line."""
        return cls(args.model, args.lang, args.out, args.double, args.name, args.level,
                   args.force)


def run_export(args: argparse.Namespace) -> int:
    """``hystkit export``: the compensator as a C or MATLAB folder."""
    return export(ExportOptions.from_args(args))


def export(opts: ExportOptions) -> int:
    """Write the compensator of ``opts.model`` as a C or MATLAB folder."""
    comp = load_compensator(opts.model)
    plan, files = export_compensator(comp, opts.out, opts.lang, double=opts.double,
                                     name=opts.name, force=opts.force, level=opts.level)
    band = ("" if comp.band is None else
            f" (with the {comp.band.level if opts.level is None else opts.level:.0%} "
            f"prediction band: lower, upper)")
    print(f"wrote {opts.out}: {', '.join(sorted(files))}{band}")
    if opts.lang == "c":
        precision = "double" if opts.double else "float"
        print(f"{precision} arithmetic; build the example with: cd {opts.out} && {COMPILE_LINE}")
        warning = "" if opts.double else float_warning(plan)
        if warning:
            print(f"hystkit: warning: {warning}", file=sys.stderr)
    if plan.sync_note:
        print(plan.sync_note)
    return 0
