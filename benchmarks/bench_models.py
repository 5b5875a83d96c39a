"""Cost of every registered model family: simulation per sample and fit time (issue 4).

For each family in ``hystkit.models.FAMILIES`` at its default size:

- simulation: ns per sample of ``family.simulate`` on a 100 000-sample normalised input (a sine
  with decaying minor loops plus noise), min of 7 repeats after a warm-up run (which pays for any
  numba compilation); also at 2x the default size, to show whether the cost grows with the size
  knob (Preisach and PI should be O(memory) per sample, not O(grid));
- fit: wall time of ``family.fit`` on the virtual sensor's 8000-sample sine fitting recording
  (direct mode data: normalised sensor -> normalised position), median of 3 after a warm-up.

Prints a table; no pass/fail. Run: ``python benchmarks/bench_models.py``.
"""

from __future__ import annotations

import platform
import statistics
import time

import numpy as np

from hystkit.compensation import centre_and_scale
from hystkit.models import FAMILIES
from hystkit.sensors import simulate_experiment


def _input(n: int) -> np.ndarray:
    t = np.arange(n) * 0.025
    rng = np.random.default_rng(0)
    return 0.8 * np.sin(0.5 * t) * (0.6 + 0.4 * np.cos(0.031 * t)) + 0.05 * rng.standard_normal(n)


def _simulation_ns(family, size: int, u: np.ndarray) -> float:
    structure = family.make_structure(0.025, size)
    # Any target will do: we only need a valid parameter set of this structure, so a short fit
    # (grid models at 2x size have thousands of weights; their full fit is timed separately).
    params = family.fit(u[:500], np.tanh(u[:500]), structure).params
    family.simulate(structure, params, u)  # warm-up
    best = min(_timed(lambda: family.simulate(structure, params, u)) for _ in range(7))
    return best / u.size * 1e9


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main() -> None:
    print(f"{platform.platform()}; python {platform.python_version()}")
    rec = simulate_experiment("sine", 1)
    _, s, p = centre_and_scale(rec, "recording")
    u = _input(100_000)
    print(f"\n{'model':<10}{'size':>6}{'sim ns/sample':>15}{'at 2x size':>12}{'fit s':>8}"
          f"{'cost':>10}")
    for name, family in FAMILIES.items():
        size = family.default_size
        try:
            ns = _simulation_ns(family, size, u)
            ns4 = _simulation_ns(family, 2 * size, u)
            structure = family.make_structure(rec.dt, size)
            family.fit(s, p, structure)  # warm-up
            runs = [family.fit(s, p, structure) for _ in range(3)]
            fit_s = statistics.median(r.seconds for r in runs)
            print(f"{name:<10}{size:>6}{ns:>15.1f}{ns4:>12.1f}{fit_s:>8.3f}{runs[0].cost:>10.4g}")
        except Exception as exc:  # noqa: BLE001 -- report and go on: one family must not hide the others
            print(f"{name:<10}{size:>6}  failed: {type(exc).__name__}: {exc}")


if __name__ == "__main__":
    main()
