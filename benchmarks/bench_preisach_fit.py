"""The Preisach-family fits: the bounded least-squares solve before and after issue 28's nnls.

Run:  python benchmarks/bench_preisach_fit.py [--rounds N]
      (writes benchmarks/last_run_preisach_fit.txt)

``preisach`` and ``gpreisach`` are fitted (``family.fit``, both loop orientations, as the
family contract test does: sensor -> position on the first 1600 samples of the virtual noise
run, normalised) at their default size and twice it, with the old solve (scipy's
``lsq_linear(method="bvls")`` on the reduced problem, as before) and the new one
(``preisach.fit.bounded_lstsq``: ``nnls`` on the problem with the free columns split, checked
by the KKT conditions, BVLS only as the fallback). Each round fits every case with both,
alternating (A B, then B A), so load bursts hit both alike; process CPU time (the solves run
with one BLAS thread), medians over rounds and the median of the per-round ratios old / new.
``SSE`` is the fit's cost (equal to the printed digits when both find the same minimum),
``max |dx|`` the largest difference of the fitted weights (Everett tables, ``nu``, offset).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import statistics
import time
from pathlib import Path

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import scipy
from scipy.optimize import lsq_linear

from hystkit.models import get_family
from hystkit.models.preisach import fit as pfit
from hystkit.sensors import simulate_experiment

HERE = Path(__file__).resolve().parent
N_FIT = 1600  # the family contract test's data
CASES = (("preisach", 1), ("preisach", 2), ("gpreisach", 1), ("gpreisach", 2))
FIELDS = ("everett", "everett_minus", "everett_plus", "nu", "offset")


def _bvls(r: np.ndarray, b: np.ndarray, nonneg: np.ndarray) -> tuple[np.ndarray, str, bool]:
    """The solve before issue 28 (``solve_regularised``'s former body after the QR)."""
    sol = lsq_linear(r, b, bounds=(np.where(nonneg, 0.0, -np.inf), np.inf), method="bvls",
                     tol=1e-12)
    x = sol.x.copy()
    x[nonneg] = np.maximum(x[nonneg], 0.0)
    return x, str(sol.message), bool(sol.success)


@contextlib.contextmanager
def _solver(old: bool):
    new = pfit.bounded_lstsq
    pfit.bounded_lstsq = _bvls if old else new  # solve_regularised looks it up at each call
    try:
        yield
    finally:
        pfit.bounded_lstsq = new


def _data() -> tuple[float, np.ndarray, np.ndarray]:
    rec = simulate_experiment("noise", 1)
    s = rec.sensor[:N_FIT] - rec.sensor[:N_FIT].mean()
    p = rec.position[:N_FIT] - rec.position[:N_FIT].mean()
    return rec.dt, s / np.max(np.abs(s)), p / np.max(np.abs(p))


def _fit(name: str, structure, s: np.ndarray, p: np.ndarray, old: bool):
    with _solver(old):
        t0 = time.process_time()
        result = get_family(name).fit(s, p, structure)
        return time.process_time() - t0, result


def _max_diff(a, b) -> float:
    return max(float(np.max(np.abs(np.asarray(getattr(a, f)) - np.asarray(getattr(b, f)))))
               for f in FIELDS if hasattr(a, f))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="paired rounds (>= 3)")
    args = parser.parse_args()
    dt, s, p = _data()
    structures = {}
    for name, factor in CASES:
        family = get_family(name)
        structures[name, factor] = family.make_structure(dt, factor * family.default_size)
        _fit(name, structures[name, factor], s, p, old=False)  # numba's kernels loaded
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    lines = [(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
              f"{load}; python {platform.python_version()}, numpy {np.__version__}, scipy "
              f"{scipy.__version__}; {N_FIT} samples of the noise run (seed 1); {args.rounds} "
              f"rounds alternating old new / new old; CPU s per fit (both orientations), "
              f"medians; ratio: median of per-round old / new")]
    print(lines[0], flush=True)
    cpu = {(case, old): [] for case in CASES for old in (True, False)}
    results = {}
    for k in range(args.rounds):
        for case in CASES:
            for old in ((True, False) if k % 2 == 0 else (False, True)):
                seconds, results[case, old] = _fit(case[0], structures[case], s, p, old)
                cpu[case, old].append(seconds)
    lines.append(f"{'model':<10} {'size':>5} {'columns':>8} {'old CPU s':>10} "
                 f"{'new CPU s':>10} {'ratio':>7} {'SSE old':>18} {'SSE new':>18} "
                 f"{'max |dx|':>9}  new solver")
    print(lines[-1], flush=True)
    for case in CASES:
        old, new = results[case, True], results[case, False]
        ratio = statistics.median(a / b for a, b in zip(cpu[case, True], cpu[case, False],
                                                         strict=True))
        size = structures[case].levels
        columns = (size * (size - 1) // 2 + 1 if case[0] == "preisach"
                   else (size - 1) * (size - 2) + structures[case].degree + 2)
        lines.append(f"{case[0]:<10} {size:>5} {columns:>8} "
                     f"{statistics.median(cpu[case, True]):>10.3f} "
                     f"{statistics.median(cpu[case, False]):>10.3f} {ratio:>7.1f} "
                     f"{old.cost:>18.14f} {new.cost:>18.14f} "
                     f"{_max_diff(old.params, new.params):>9.1e}  "
                     f"{new.message.split('; ', 1)[1]}")
        print(lines[-1], flush=True)
    lines.append(f"# load at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(lines[-1])
    (HERE / "last_run_preisach_fit.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
