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
from pathlib import Path

__all__ = ["register"]


def _export(args: argparse.Namespace) -> int:
    from ..compensation import load_compensator
    from ..export import COMPILE_LINE, export_compensator, float_warning

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


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``export`` subcommand to the ``hystkit`` parser."""
    from ._common import number

    p = sub.add_parser("export", help="write a fitted compensator as dependency-free C99 or "
                                      "as MATLAB/Octave code")
    p.add_argument("model", type=Path, help="model JSON file written by 'hystkit fit'")
    p.add_argument("--lang", choices=("c", "matlab"), default="c",
                   help="target language (default: c)")
    p.add_argument("--out", type=Path, required=True,
                   help="folder to write (refused if it exists, unless --force)")
    p.add_argument("--double", action="store_true",
                   help="C only: double arithmetic (default float, for single-precision FPUs); "
                        "refused with --lang matlab, whose code is always double")
    p.add_argument("--name", help="name of the generated functions (default: from the model "
                                  "file name)")
    p.add_argument("--level", type=number(0, 1, low_open=True, high_open=True), default=None,
                   help="nominal coverage of the exported prediction band, in (0, 1) (default: "
                        "the model's own, 0.90 unless fitted otherwise); refused for a model "
                        "without a band")
    p.set_defaults(run=_export)
