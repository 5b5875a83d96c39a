"""Does the prediction band hold on runs it was not calibrated on? Coverage and width.

Every case trains on one run (or several) and scores on a different run: the virtual
sensor's cross-excitation matrix (train on each excitation, test on each, another seed), once
with one training run (the band from interleaved cycles of it) and once with two (the band from
left-out recordings), virtual runs whose sensor offset or gain changed (centring ``fit`` and
``track``), and the shared real data sets with separate runs. For each, the default compensator
(``hystkit fit``: mPL, 1 cell) and a PI (5 operators) are fitted with their band (``with_band``:
the validation folds of ``select``) and run on the test run as in use; the table gives the band's coverage at the nominal 0.90, whether it lies in
[0.85, 0.95], and the median half-width against the estimate's RMS error (target <= 3 where the
model works). Run: ``python benchmarks/bench_band.py [--quick]``; the output is
``benchmarks/last_run_band.txt`` and the table in ``docs/band.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from hystkit.compensation import fit_compensator, interval_scores, with_band
from hystkit.errors import HystkitError
from hystkit.io import Recording
from hystkit.metrics import r2
from hystkit.sensors import simulate_experiment

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from centring_evidence import real_cases  # the shared real runs, in one place

EXCITATIONS = ("sine", "decay", "chirp", "noise")
MODELS = (("mpl", 1), ("pi", 5))
LEVEL = 0.90
GOOD = (0.85, 0.95)


def _changed(rec: Recording, *, offset: float = 0.0, gain: float = 1.0, label: str) -> Recording:
    """The run with its sensor's offset moved by `offset` of its range, or scaled by `gain`."""
    mid = float(np.mean(rec.sensor))
    sensor = mid + gain * (rec.sensor - mid) + offset * float(np.ptp(rec.sensor))
    return Recording(time=rec.time, sensor=sensor, position=rec.position,
                     source=f"{rec.source} {label}")


def cases(quick: bool):
    """(group, name, training recordings, test recording, centring)."""
    trains = EXCITATIONS[:2] if quick else EXCITATIONS
    for n_runs, seeds in ((1, (1,)), (2, (1, 3))):
        for train in trains:
            for test in EXCITATIONS:
                yield (f"virtual cross-excitation, {n_runs} training run(s)",
                       f"{train} -> {test}", [simulate_experiment(train, s) for s in seeds],
                       simulate_experiment(test, 2), "fit")
    base = simulate_experiment("noise", 2)
    for center in ("fit", "track"):
        for label, change in (("offset +5 % of range", {"offset": 0.05}),
                              ("offset +20 % of range", {"offset": 0.20}),
                              ("gain x 1.1", {"gain": 1.1}), ("gain x 0.8", {"gain": 0.8})):
            yield (f"virtual sensor changed, centring {center}, 2 training runs",
                   f"noise -> noise, {label}",
                   [simulate_experiment("noise", s) for s in (1, 3)],
                   _changed(base, label=label, **change), center)
    if not quick:
        for name, train, test in real_cases():
            yield "shared real data", name, train, test, "fit"


def run_case(model: str, size: int, train: list[Recording], test: Recording,
             center: str) -> dict:
    comp = fit_compensator(train, size, model=model, center=center, diagnose=False)
    comp = with_band(comp, train, size, level=LEVEL)
    if comp.band is None:
        return {"note": comp.fit_info["band"]}
    estimate, lower, upper = comp.estimate_with_band(test)
    scores = interval_scores(test.position, lower, upper, LEVEL)
    rms = float(np.sqrt(np.mean((estimate - test.position) ** 2)))
    return {"r2": r2(test.position, estimate), "coverage": scores["band_coverage"],
            "ratio": scores["band_width_median"] / 2 / rms if rms > 0 else float("nan"),
            "protocol": comp.band.protocol}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a few cases, no real data")
    args = parser.parse_args()
    t0 = time.perf_counter()
    print(f"nominal level {LEVEL}; coverage in [{GOOD[0]}, {GOOD[1]}] is marked ok; 'half/rms': "
          f"median half-width / RMS error of the estimate on the test run\n")
    print("| group | case | model | test R² | coverage | in range | half/rms |")
    print("|---|---|---|---|---|---|---|")
    tally: dict[str, list[float]] = {}
    for group, name, train, test, center in cases(args.quick):
        for model, size in MODELS:
            try:
                row = run_case(model, size, train, test, center)
            except HystkitError as exc:
                print(f"| {group} | {name} | {model} {size} | fails: {str(exc)[:60]} | | | |")
                continue
            if "note" in row:
                print(f"| {group} | {name} | {model} {size} | {row['note']} | | | |")
                continue
            ok = GOOD[0] <= row["coverage"] <= GOOD[1]
            tally.setdefault(group, []).append(row["coverage"])
            print(f"| {group} | {name} | {model} {size} | {row['r2']:.3f} | "
                  f"{row['coverage']:.3f} | {'ok' if ok else 'no'} | {row['ratio']:.2f} |",
                  flush=True)
    print()
    for group, rows in tally.items():
        within = sum(GOOD[0] <= c <= GOOD[1] for c in rows)
        safe = sum(c >= GOOD[0] for c in rows)
        print(f"{group}: {within} of {len(rows)} within [{GOOD[0]}, {GOOD[1]}], {safe} at "
              f"{GOOD[0]} or more")
    print(f"\n{time.perf_counter() - t0:.0f} s (numpy {np.__version__})")


if __name__ == "__main__":
    main()
