"""Exhaustive structural search of the Power-Law model over N, p, M, S (sec. 2.2, table 5.1),
used by ``hystkit pl-search``: every combination of a grid is fitted with :func:`fit.fit_pl`."""

from __future__ import annotations

import itertools
import time
from collections.abc import Mapping, Sequence

import numpy as np

from ...metrics import e_max_pct, e_rms_pct
from ...parallel import Executor, SerialExecutor, fit_cost
from . import model as pl
from .fit import fit_pl
from .grid import DEFAULT_GRID

__all__ = ["DEFAULT_GRID", "format_search_table", "structural_search"]



def structural_search(u: np.ndarray, y: np.ndarray, dt: float,
                      grid: Mapping[str, Sequence] | None = None,
                      slope_cap: float = 1.0, executor: Executor | None = None) -> list[dict]:
    """Exhaustive search over N, p, M, S (sec. 2.2, table 5.1): fit every combination.

    Each combination is one piece of work for `executor` (default: serial); the rows are the
    same whichever executor ran them (but for ``seconds``, each fit's own time).

    Parameters
    ----------
    u, y : array, shape (n,)
        Model input and output every ``dt`` [s]; centred on their means and scaled to
        max |.| = 1 here (eq. 5.10), so the errors are those of eq. 5.11 on normalised data.
    dt : float
        Sample time [s].
    grid : mapping with keys "n", "p", "m", "s", optional
        Values to try for each structural parameter; :data:`DEFAULT_GRID` fills missing keys.
    slope_cap : float, default 1.0
        Slope cap of every structure tried.
    executor : hystkit.parallel.Executor, optional
        Runs the fits; serial if None.

    Returns
    -------
    list of dict
        One row per combination, in grid order: ``n_cells, power, n_basis, smoothing,
        n_params, e_rms_pct, e_max_pct, seconds``, and ``structure`` / ``params`` (dicts).
    """
    grid = {**DEFAULT_GRID, **(grid or {})}
    u = np.asarray(u, dtype=float) - np.mean(u)
    y = np.asarray(y, dtype=float) - np.mean(y)
    u, y = u / np.max(np.abs(u)), y / np.max(np.abs(y))
    structures = [pl.PlStructure(n_cells=int(n), power=float(p), n_basis=int(m),
                                 smoothing=float(s), dt=dt, slope_cap=slope_cap)
                  for n, p, m, s in itertools.product(grid["n"], grid["p"], grid["m"],
                                                      grid["s"])]
    return (executor or SerialExecutor()).map(
        _fit_structure, structures, shared={"u": u, "y": y},
        cost=lambda s: fit_cost("pl", s.n_cells, u.size) * s.n_basis)


def _fit_structure(structure: pl.PlStructure, *, u: np.ndarray, y: np.ndarray) -> dict:
    """One row of the search: `structure` fitted to normalised ``u -> y``."""
    t0 = time.perf_counter()
    result = fit_pl(u, y, structure)
    seconds = time.perf_counter() - t0
    y_hat = pl.simulate(structure, result.params, u)[0]
    return {"n_cells": structure.n_cells, "power": structure.power,
            "n_basis": structure.n_basis, "smoothing": structure.smoothing,
            "n_params": structure.n_params, "e_rms_pct": e_rms_pct(y, y_hat, 1.0),
            "e_max_pct": e_max_pct(y, y_hat, 1.0), "seconds": seconds,
            "structure": structure.to_dict(), "params": result.params.to_dict()}


def format_search_table(rows: Sequence[dict], best_only_per_n: bool = False) -> str:
    """The search result laid out like table 5.1 (one line per structure, or the best per N).

    Parameters
    ----------
    rows : sequence of dict
        Rows of :func:`structural_search`.
    best_only_per_n : bool, default False
        Show only the row with the lowest RMS error per cell count.

    Returns
    -------
    str
        The table.
    """
    if best_only_per_n:
        best: dict[int, dict] = {}
        for r in rows:
            if r["n_cells"] not in best or r["e_rms_pct"] < best[r["n_cells"]]["e_rms_pct"]:
                best[r["n_cells"]] = r
        rows = [best[n] for n in sorted(best)]
    head = (f"{'Model':<10} {'Cells (N)':>9} {'No. pars':>8} {'e_rms %':>8} {'e_max %':>8} "
            f"{'M':>3} {'S':>7} {'p':>5} {'fit s':>6}")
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(f"{'Power-Law':<10} {r['n_cells']:>9d} {r['n_params']:>8d} "
                     f"{r['e_rms_pct']:>8.3f} {r['e_max_pct']:>8.3f} {r['n_basis']:>3d} "
                     f"{r['smoothing']:>7g} {r['power']:>5g} {r['seconds']:>6.2f}")
    return "\n".join(lines)
