"""The README's figure: a compensator fitted on one real run, applied to another (issue 30).

Data: the piezo micromanipulator excerpts shipped with hystkit (Aye & Ang 2018, MIT; see
docs/real_data.md). The "sensor" is the capacitive sensor's displacement [um], the "position"
the drive voltage [V] that caused it: the compensator learns which drive gave a displacement,
the inverse hysteresis a feedforward needs. It is fitted on the identification run and its
excitation's feed-forward run (left-out recording band), and drawn on the uncompensated part of
the test run, which it never saw.

Run from the repository's root (writes docs/_static/readme_figure.png; --force to replace it):

    python docs/_scripts/readme_figure.py --force
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import hystkit as hk
from hystkit.datasets import load_excerpt

OUT = Path(__file__).resolve().parents[1] / "_static" / "readme_figure.png"
NAME = "piezo_micromanipulator"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--force", action="store_true", help="replace an existing figure")
    args = parser.parse_args(argv)
    if args.out.exists() and not args.force:
        sys.exit(f"readme_figure.py: {args.out} exists (--force replaces it)")

    runs = {v: load_excerpt(NAME, v).to_recording()
            for v in ("identification", "test_feedforward", "test_uncompensated")}
    comp = hk.fit([runs["identification"], runs["test_feedforward"]], "mpl", size=1)
    new_run = runs["test_uncompensated"]
    scores = hk.evaluate(comp, new_run)
    out = hk.compensate(comp, new_run)

    # The straight line a plain calibration would use, fitted on the same two runs.
    train = [runs["identification"], runs["test_feedforward"]]
    gain, offset = np.polyfit(np.concatenate([r.sensor for r in train]),
                              np.concatenate([r.position for r in train]), 1)
    line = gain * new_run.sensor + offset
    truth = new_run.position
    line_r2 = 1 - np.sum((truth - line) ** 2) / np.sum((truth - truth.mean()) ** 2)
    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.8), layout="constrained", sharey=True)
    for ax, estimate, label, r2 in (
            (axes[0], line, "straight-line calibration", line_r2),
            (axes[1], out["position_estimate"], "hystkit's mPL compensator", scores["r2"])):
        ax.plot(truth, estimate, lw=0.9, color="C0" if ax is axes[1] else "0.35")
        ax.plot([truth.min(), truth.max()], [truth.min(), truth.max()], color="k", lw=0.6,
                ls=":", label="perfect")
        ax.set(xlabel="true drive [V]", title=f"{label}: R² {r2:.4f}")
        ax.set_aspect("equal")
    axes[0].set_ylabel("drive estimated from the sensor [V]")
    axes[0].legend(loc="upper left", frameon=False)
    fig.suptitle("Piezo micromanipulator, real data: a run neither was fitted on",
                 fontsize=10)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}: R² {scores['r2']:.4f} (straight line {line_r2:.4f}), band "
          f"coverage {scores['band_coverage']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
