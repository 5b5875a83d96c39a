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

from ..compensation import load_compensator
from ..export import COMPILE_LINE, export_compensator, float_warning

__all__ = ["run_export"]


def run_export(args: argparse.Namespace) -> int:
    """``hystkit export``: the compensator as a C or MATLAB folder."""
    comp = load_compensator(args.model)
    plan, files = export_compensator(comp, args.out, args.lang, double=args.double, name=args.name,
                                     force=args.force, level=args.level)
    band = ("" if comp.band is None else
            f" (with the {comp.band.level if args.level is None else args.level:.0%} "
            f"prediction band: lower, upper)")
    print(f"wrote {args.out}: {', '.join(sorted(files))}{band}")
    if args.lang == "c":
        precision = "double" if args.double else "float"
        print(f"{precision} arithmetic; build the example with: cd {args.out} && {COMPILE_LINE}")
        if not args.double and float_warning(plan):
            print(f"hystkit: warning: {float_warning(plan)}", file=sys.stderr)
    if plan.sync_note:
        print(plan.sync_note)
    return 0
