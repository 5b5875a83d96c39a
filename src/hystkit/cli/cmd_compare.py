"""``hystkit compare`` and ``hystkit generalize``: all model families side by side (issue 4)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..io import check_output_path, read_recording, write_json
from ..models import FAMILIES
from ._common import UsageError

__all__ = ["register"]


def _models(text: str | None) -> list[str]:
    if text is None:
        return sorted(FAMILIES)
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in FAMILIES]
    if unknown:
        raise UsageError(f"unknown model(s) {', '.join(unknown)}; known: "
                         f"{', '.join(sorted(FAMILIES))}")
    return names


def _sizes(pairs: list[str]) -> dict[str, int]:
    out = {}
    for pair in pairs:
        name, _, value = pair.partition("=")
        if name not in FAMILIES or not value.isdigit() or int(value) < 1:
            raise UsageError(f"--size expects MODEL=N with a known model and N >= 1, got {pair!r}")
        out[name] = int(value)
    return out


def _compare(args: argparse.Namespace) -> int:
    # Matplotlib and the fits load only for this command.
    from ..reports._compare import compare_models, format_compare

    models = _models(args.models)
    out = args.out
    if out is not None:
        check_output_path(out / "compare.json", args.force)
    fit_rec, val_rec = read_recording(args.data_fit), read_recording(args.data_val)
    print(f"comparing {len(models)} models: fit on {args.data_fit}, validate on {args.data_val} "
          f"(centring: recording)")
    table = compare_models(fit_rec, val_rec, models, _sizes(args.size), progress=print)
    print(format_compare(table))
    print("R² fwd: forward model position -> sensor; R² inv: its inverse as compensator; "
          "R² dir: a compensator fitted sensor -> position; line: straight line")
    if out is not None:
        write_json(table, out / "compare.json", force=args.force)
        print(f"wrote {out / 'compare.json'}")
    return 0


def _generalize(args: argparse.Namespace) -> int:
    from ..reports._compare import generalization_matrix, plot_generalization
    from ..sensors import simulate_experiment
    from ..signals import EXPERIMENTS

    models = _models(args.models)
    out = args.out or Path("hystkit-generalize")
    for name in ("generalize.json", "generalize.png"):
        check_output_path(out / name, args.force)
    recordings = {name: (simulate_experiment(name, 1), simulate_experiment(name, 2))
                  for name in EXPERIMENTS}
    print(f"train on each of {', '.join(recordings)}, test on each (virtual sensor, direct-mode "
          f"compensators, centring: recording)")
    matrix = generalization_matrix(recordings, models, _sizes(args.size), progress=print)
    for name, entry in matrix.items():
        print(f"\n{name}: R² (rows: trained on, columns: tested on)")
        print(f"{'':<8}" + "".join(f"{t:>9}" for t in recordings))
        for train, row in entry["r2"].items():
            print(f"{train:<8}" + "".join(f"{'fail' if v is None else f'{v:.4f}':>9}"
                                          for v in row.values()))
    write_json(matrix, out / "generalize.json", force=args.force)
    plot_generalization(matrix).savefig(out / "generalize.png", dpi=110)
    print(f"\nwrote {out / 'generalize.json'}, {out / 'generalize.png'}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``compare`` and ``generalize``."""
    models_help = f"comma-separated models (default: all: {', '.join(sorted(FAMILIES))})"
    p = sub.add_parser("compare", help="fit every model on one recording, score on another")
    p.add_argument("data_fit", type=Path)
    p.add_argument("data_val", type=Path)
    p.add_argument("--models", help=models_help)
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N",
                   help="model size, e.g. --size mpl=3 (repeatable)")
    p.add_argument("--out", type=Path, help="folder for compare.json")
    p.set_defaults(run=_compare)

    p = sub.add_parser("generalize", help="train on each excitation, test on each (4x4 R²)")
    p.add_argument("--models", help=models_help)
    p.add_argument("--size", action="append", default=[], metavar="MODEL=N")
    p.add_argument("--out", type=Path, help="output folder (default hystkit-generalize)")
    p.set_defaults(run=_generalize)
