"""``hystkit generalize``: a direct compensator of each model trained on each recording and
tested on every recording (the matrix that table 2.2 takes statistics of)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from ..compensation import evaluate, fit_compensator
from ..io import Recording
from ..parallel import Executor, SerialExecutor, fit_cost
from ._compare import DISQUALIFYING, FAMILY_FAILURES

__all__ = ["GRID_KEYS", "generalization_matrix"]

# e_rms_pct: the normalised RMS error (eq. 5.11) that table 2.2 takes statistics of
GRID_KEYS = ("r2", "r2_oracle", "linear_r2", "e_rms_pct", "e_rms_pct_oracle")


def generalization_matrix(train: Mapping[str, Recording], test: Mapping[str, Recording],
                          models: Sequence[str], sizes: Mapping[str, int] | None = None,
                          progress: Callable[[str], None] = lambda _: None,
                          executor: Executor | None = None) -> dict:
    """Train a direct compensator on each training recording, test it on every test recording.

    One piece of work for `executor` (default: serial) per model, its fits on every training
    recording and their tests, so that a worker loads a family's kernels once; or per model
    and training recording when one model's share of the estimated work (`fit_cost`) is more
    than a worker's share of all of it. The matrix is the same whichever executor ran them.

    Parameters
    ----------
    train : mapping of str to Recording
        Training recordings by name (the matrix's rows).
    test : mapping of str to Recording
        Test recordings by name (its columns).
    models : sequence of str
        Family names.
    sizes : mapping of str to int, optional
        Size per family name; a family not in it gets its default size.
    progress : callable, optional
        Called with one line of text as each model is trained on a recording (default:
        nothing).
    executor : Executor, optional
        Runs the pieces of work; None: serially, here.

    Returns
    -------
    dict
        ``{model: {"r2", "r2_oracle", "linear_r2", "e_rms_pct", "e_rms_pct_oracle": {train:
        {test: value}}, "errors": {train: reason}, "notes": {train: reason}}}``: deployable and
        oracle R² and RMS error (% of the training range, eq. 5.11); a failed fit or run
        gives None and its reason in ``errors``, as does a collapsed fit or one worse than its
        line (its scores are kept); parameters on bounds or an exhausted budget are ``notes``.
    """
    executor = executor or SerialExecutor()
    train, test = dict(train), dict(test)

    def cost(piece: tuple[str, int | None, tuple[str, ...]]) -> float:
        return sum(fit_cost(piece[0], piece[1], train[t].sensor.size) for t in piece[2])

    whole = [(name, (sizes or {}).get(name), tuple(train)) for name in models]
    total = sum(cost(piece) for piece in whole)
    if max(map(cost, whole), default=0.0) <= total / executor.n_workers:
        pieces = whole
    else:  # e.g. one model: its recordings on several workers
        pieces = [(name, size, (t,)) for name, size, names in whole for t in names]

    def done(i: int, _: list) -> None:
        for train_name in pieces[i][2]:
            progress(f"  {pieces[i][0]}: trained on {train_name}")

    results = executor.map(_generalize_rows, pieces, shared={"train": train, "test": test},
                           on_done=done, cost=cost)
    out = {name: {**{key: {} for key in GRID_KEYS}, "errors": {}, "notes": {}}
           for name in models}
    for (name, _, train_names), piece_rows in zip(pieces, results, strict=True):
        for train_name, (rows, errors, notes) in zip(train_names, piece_rows, strict=True):
            for key in GRID_KEYS:
                out[name][key][train_name] = rows[key]
            out[name]["errors"].update(errors)
            out[name]["notes"].update(notes)
    return out


def _generalize_rows(piece: tuple[str, int | None, tuple[str, ...]], *,
                     train: Mapping[str, Recording],
                     test: Mapping[str, Recording]) -> list[tuple[dict, dict, dict]]:
    """One model trained on each of the recordings ``piece[2]`` in turn, each tested on every
    test recording: `_generalize_piece`'s result for each."""
    name, size, train_names = piece
    return [_generalize_piece((name, size, t), train=train, test=test) for t in train_names]


def _generalize_piece(piece: tuple[str, int | None, str], *, train: Mapping[str, Recording],
                      test: Mapping[str, Recording]) -> tuple[dict, dict, dict]:
    """One model trained on one recording, tested on each: (rows of each grid, errors, notes)."""
    name, size, train_name = piece
    rows = {key: dict.fromkeys(test) for key in GRID_KEYS}
    errors, notes = {}, {}
    try:
        comp = fit_compensator(train[train_name], size, model=name, diagnose=False)
    except FAMILY_FAILURES as exc:
        errors[train_name] = f"fit: {exc}"
        return rows, errors, notes
    status = comp.fit_info["status"]
    if status != "ok":
        # collapsed / worse than the line disqualify the row; bounds and budget are notes
        target = errors if status in DISQUALIFYING else notes
        target[train_name] = f"fit {status}: {comp.fit_info['status_message']}"
    for test_name, val_rec in test.items():
        try:
            scores = evaluate(comp, val_rec)
        except FAMILY_FAILURES as exc:
            errors[f"{train_name} -> {test_name}"] = str(exc)
            continue
        for key in GRID_KEYS:
            rows[key][test_name] = scores[key]
    return rows, errors, notes
