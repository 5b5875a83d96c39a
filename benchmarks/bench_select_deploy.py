"""Does `select`'s winner hold on a *different* run? Selection on training runs vs a full compare.

For every shared real data set with separate runs, and for virtual-sensor runs whose offset,
gain or excitation changes between training and use: `select` sees the training run(s) only
(left-out recording with several, interleaved cycles with one); its winner is then run
deployably on a different run. Beside it: the best family of a full `compare` fitted on the
first training run and scored on that different run, which *has* looked at it to be named
best. The difference says how much a user loses by trusting `select`.

Run: ``python benchmarks/bench_select_deploy.py [--workers 2] [--cases NAME ...]``; the table of
docs/selection.md comes from it (benchmarks/last_run_select.txt).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from hystkit.compensation import evaluate, folds, protocol
from hystkit.io import Recording
from hystkit.parallel import open_executor
from hystkit.sensors import simulate_experiment
from hystkit.studies import candidates, compare_models, select_model

# the shared real data's separate runs, as the centring example pairs them
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from centring_evidence import real_cases


def _changed(rec: Recording, name: str, offset: float = 0.0, gain: float = 1.0) -> Recording:
    """The run with its sensor's resting level moved by `offset` spans and scaled by `gain`
    (a soft sensor between two sessions)."""
    s = rec.sensor
    return Recording(time=rec.time, sensor=gain * s + offset * float(np.ptp(s)),
                     position=rec.position, source=name)


# The virtual runs all start alike (the same excitation from the same position), so a tare at
# their start compares like with like; the real data's other runs are windows of a run in
# motion or records that start elsewhere (a tare there zeroes on motion): `fit` only.
VIRTUAL_CENTERS = "fit,tare"


def cases():
    """(name, training recordings, a different run)."""
    sine = [simulate_experiment("sine", seed) for seed in (1, 2, 3)]
    yield "virtual sine -> sine, offset +30 %", sine[:1], _changed(sine[2], "run +30 %", 0.3)
    yield ("virtual 2 runs (offsets 0, -20 %) -> offset +30 %",
           [sine[0], _changed(sine[1], "run -20 %", -0.2)], _changed(sine[2], "run +30 %", 0.3))
    yield "virtual sine -> sine, gain x1.1", sine[:1], _changed(sine[2], "gain 1.1", gain=1.1)
    yield ("virtual noise -> sine", [simulate_experiment("noise", 1)],
           simulate_experiment("sine", 2))
    yield from real_cases()


def _best_of_compare(train: list[Recording], test: Recording, executor) -> tuple[str, float]:
    # compare takes one fitting recording: the first training run
    table = compare_models(train[0], test, executor=executor)
    best = ("-", float("-inf"))
    for name, m in table.items():
        for key, mode in (("r2_direct", "direct"), ("r2_compensated", "inverse")):
            value = m.get(key)
            if value is not None and value > best[1]:
                best = (f"{name} {mode}", value)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cases", nargs="*", help="substrings of the case names to run")
    parser.add_argument("--centers", help="centrings select tries (default: fit,tare on the "
                                          "virtual runs, fit on the real ones)")
    args = parser.parse_args()
    print("| case | protocol | select's winner | its R² on the other run | best of compare on "
          "it | its R² | difference | select s |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    with open_executor(args.workers) as executor:
        for name, train, test in cases():
            if args.cases and not any(c in name for c in args.cases):
                continue
            fit_samples = min(f.n_train for f in folds(train))
            centers = args.centers or (VIRTUAL_CENTERS if name.startswith("virtual") else "fit")
            cands = candidates(centers=centers.split(","), fit_samples=fit_samples,
                               dt=train[0].dt)
            t0 = time.perf_counter()
            result = select_model(train, cands, executor=executor)
            seconds = time.perf_counter() - t0
            if result["winner"] is None:
                chosen, score = f"refused: {result['refusal'][:60]}", None
            else:
                chosen = result["winner"]["candidate"]
                score = evaluate(result["compensator"], test)["r2"]
            best_name, best = _best_of_compare(train, test, executor)
            shown = "n/a" if score is None else f"{score:.4f}"
            diff = "n/a" if score is None else f"{score - best:+.4f}"
            print(f"| {name} | {protocol(train)} | {chosen} | {shown} | {best_name} | "
                  f"{best:.4f} | {diff} | {seconds:.0f} |", flush=True)


if __name__ == "__main__":
    main()
