"""Does `select` find the best model? Selection on training data vs a full compare.

For every shared real data set (and the virtual sensor): `select` sees the training part only
and picks family x size x mode by cross-validation; its winner is scored on the held-out part
(deployable centring). Beside it: the best single family of a full `compare` (every family,
direct and inverse, default size), which *has* looked at the held-out part to be named best.
Run: ``python examples/selection_evidence.py`` (writes the table of docs/selection.md).
"""

from __future__ import annotations

import time

from centring_evidence import cases

from hystkit.compensation import evaluate
from hystkit.reports import candidates, compare_models, select_model


def _best_of_compare(train, test) -> tuple[str, float]:
    # compare takes one fitting recording: the first training run
    table = compare_models(train[0], test)
    best = ("-", float("-inf"))
    for name, m in table.items():
        for key, mode in (("r2_direct", "direct"), ("r2_compensated", "inverse")):
            value = m.get(key)
            if value is not None and value > best[1]:
                best = (f"{name} {mode}", value)
    return best


def main() -> None:
    print("| case | select's winner (CV on training) | its held-out R² | oracle | best single "
          "family in compare | its held-out R² | difference | seconds |")
    print("|---|---|---|---|---|---|---|---|")
    for name, train, test in cases():
        if name.startswith("virtual") and name != "virtual noise":
            continue
        t0 = time.perf_counter()
        result = select_model(train, candidates(), jobs=2)
        seconds = time.perf_counter() - t0
        if result["winner"] is None:
            chosen, score, oracle = "none passed", float("nan"), float("nan")
        else:
            s = evaluate(result["compensator"], test)
            chosen, score, oracle = result["winner"]["candidate"], s["r2"], s["r2_oracle"]
        best_name, best = _best_of_compare(train, test)
        print(f"| {name} | {chosen} | {score:.4f} | {oracle:.4f} | {best_name} | {best:.4f} | "
              f"{score - best:+.4f} | {seconds:.0f} |", flush=True)


if __name__ == "__main__":
    main()
