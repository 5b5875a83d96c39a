"""Table 2.2 of the reference document on the virtual sensor: RMSE statistics over repeats.

Table 2.2 (from [5], the PL authors' comparison with Kuhnen's model) fits each model on a
training set and scores it on a test set, many times, and reports the minimum, mean and
variance of the RMSE of the normalised output on the training and on the test sets.

Here repeat ``r`` draws a fresh training and test recording from the virtual sensor (seeds
``seed + 2 r`` and ``seed + 2 r + 1``; for the ``noise`` excitation each seed is also a new
trajectory), and :func:`hystkit.studies.generalization_matrix` (the ``generalize`` command's
matrix) fits a direct compensator (sensor -> position) of each model on the training recording
and scores it on both. The RMSE is that of the position estimate normalised by the training
data's max |position| (eq. 5.10-5.11: ``e_rms_pct / 100``), with the compensator's own
(deployable) centring, and again under the paper's protocol (the recording's own means,
labelled oracle). The document's PL is hystkit's ``pl``; Kuhnen's modified Prandtl-Ishlinskii
model with creep is ``pi``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..sensors import simulate_experiment
from ._generalize import generalization_matrix

__all__ = ["DOCUMENT_NAMES", "DOCUMENT_TABLE_2_2", "TABLE_2_2_COLUMNS", "measure_table_2_2",
           "rmse_statistics"]

# Table 2.2 of the reference document: model -> set -> (min, mean, variance) of the RMSE.
DOCUMENT_TABLE_2_2 = {
    "pl": {"training": (5.7e-3, 6.0e-3, 1.15e-7), "test": (6.9e-3, 8.2e-3, 7.78e-7)},
    "pi": {"training": (5.6e-3, 7.1e-3, 9.49e-7), "test": (6.5e-3, 12.3e-3, 1.73e-5)},
}
DOCUMENT_NAMES = {"pl": "Power-Law", "pi": "Kuhnen"}

TABLE_2_2_COLUMNS = (("model", "model"), ("set", "set"), ("centring", "centring"),
                     ("n", "n"), ("min_rmse", "min RMSE"), ("mean_rmse", "mean RMSE"),
                     ("variance_rmse", "variance RMSE"),
                     ("document_min_rmse", "document min"),
                     ("document_mean_rmse", "document mean"),
                     ("document_variance_rmse", "document variance"))


def rmse_statistics(values: Sequence[float]) -> dict:
    """Minimum, mean and sample variance (ddof = 1) of RMSE values; ``n`` counts them.

    None entries (failed repeats) are left out; fewer than two values give variance None.

    Parameters
    ----------
    values : sequence of float or None
        RMSE of each repeat.

    Returns
    -------
    dict
        ``n``, ``min_rmse``, ``mean_rmse``, ``variance_rmse`` (None when not defined), in the
        units of `values`.
    """
    v = np.array([x for x in values if x is not None], dtype=float)
    return {"n": int(v.size), "min_rmse": float(v.min()) if v.size else None,
            "mean_rmse": float(v.mean()) if v.size else None,
            "variance_rmse": float(v.var(ddof=1)) if v.size > 1 else None}


def measure_table_2_2(repeats: int = 10, seed: int = 1, *, excitation: str = "noise",
                      models: Sequence[str] = ("pl", "pi", "mpl"),
                      sizes: dict[str, int] | None = None, executor: Any = None,
                      progress: Callable[[str], None] = lambda _: None) -> dict:
    """Fit each model on `repeats` fresh training recordings and score it on fresh test ones.

    Parameters
    ----------
    repeats : int
        Number of training/test pairs (>= 2, for a variance).
    seed : int
        Repeat r uses seeds ``seed + 2 r`` (training) and ``seed + 2 r + 1`` (test).
    excitation : str
        Experiment of every recording (``noise``: a new trajectory per seed).
    models : sequence of str
        Model families (default: ``pl``, ``pi`` (Kuhnen's), ``mpl``).
    sizes : dict, optional
        Family -> size; default each family's ``default_size``.
    executor : hystkit.parallel.Executor, optional
        Where each repeat's fits run (default: serial).
    progress : callable
        Receives one line per repeat.

    Returns
    -------
    dict
        ``settings``; ``repeats``: per repeat its seeds and, per model, the RMSEs (training,
        test; deployable and oracle), errors and notes; ``rows``: the statistics per model, set
        and centring with the document's numbers beside them (None where it has none);
        ``n_flagged`` counts repeats whose fit failed or was disqualified (collapsed, worse than
        its straight line: its scores are kept, as ``generalize`` keeps them).
    """
    if repeats < 2:
        raise ValueError(f"repeats must be >= 2 for a variance, got {repeats}")
    per_repeat = []
    for r in range(repeats):
        seeds = (seed + 2 * r, seed + 2 * r + 1)
        train = simulate_experiment(excitation, seeds[0])
        test = simulate_experiment(excitation, seeds[1])
        matrix = generalization_matrix({"training": train}, {"training": train, "test": test},
                                       list(models), sizes, executor=executor)
        entry = {"training_seed": seeds[0], "test_seed": seeds[1], "models": {}}
        for name, m in matrix.items():
            entry["models"][name] = {
                f"{where}_rmse{suffix}": _rmse(m[f"e_rms_pct{suffix}"]["training"][where])
                for where in ("training", "test") for suffix in ("", "_oracle")}
            entry["models"][name].update(errors=m["errors"], notes=m["notes"])
        per_repeat.append(entry)
        progress(f"  repeat {r + 1}/{repeats}: seeds {seeds[0]} (training), {seeds[1]} (test)")
    rows = []
    for name in models:
        for where in ("training", "test"):
            for suffix, centring in (("", "fit (deployable)"), ("_oracle", "recording (oracle)")):
                stats = rmse_statistics([e["models"][name][f"{where}_rmse{suffix}"]
                                         for e in per_repeat])
                document = DOCUMENT_TABLE_2_2.get(name, {}).get(where, (None, None, None))
                flagged = sum(bool(e["models"][name]["errors"]) for e in per_repeat)
                rows.append({"model": name, "set": where, "centring": centring, **stats,
                             "n_flagged": flagged,
                             "document_model": DOCUMENT_NAMES.get(name),
                             "document_min_rmse": document[0],
                             "document_mean_rmse": document[1],
                             "document_variance_rmse": document[2]})
    return {"settings": {"repeats": repeats, "seed": seed, "excitation": excitation,
                         "models": list(models), "sizes": dict(sizes or {})},
            "repeats": per_repeat, "rows": rows}


def _rmse(e_rms_pct: float | None) -> float | None:
    """RMSE of the normalised output from the percent score of eq. 5.11."""
    return None if e_rms_pct is None else e_rms_pct / 100.0
