"""Every model family on the same recordings: ``hystkit compare`` and ``hystkit generalize``.

The document chose its model by argument (table 2.1); here each family is fitted and scored on
the same data, with table 2.1's properties measured on the fitted model.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..compensation import (
    centre_and_scale,
    check_excursion,
    check_fitting_data,
    evaluate,
    fit_compensator,
    use_verdict,
)
from ..errors import HystkitError
from ..io import Recording
from ..metrics import e_max_pct, e_rms_pct, r2
from ..models import FAMILIES, get_family
from ..parallel import Executor, SerialExecutor, fit_cost
from ._properties import measure_properties

if TYPE_CHECKING:  # matplotlib loads in plot_generalization: compare draws nothing (~0.3 s)
    from matplotlib.figure import Figure

__all__ = ["compare_models", "format_compare", "generalization_matrix", "plot_generalization"]


# What a failing family can raise: our own errors, the numerical ones of a fit gone
# degenerate (e.g. a collapsed model whose properties cannot be measured), and whatever else
# one family's code raises on odd data: one family never takes the others down.
FAMILY_FAILURES = (Exception,)
# Fit statuses (compensation guards) that make a model unusable, not merely suspicious.
DISQUALIFYING = ("collapsed", "no_signal", "worse_than_line")


def _forward_scores(name: str, size: int | None, fit_rec: Recording,
                    val_rec: Recording) -> dict:
    """Fit position -> sensor; score the forward prediction and the inverse on validation.

    The inverse is scored twice: deployable (the fitting recording's offsets) and oracle (the
    validation recording's own means, the paper's protocol).
    """
    family = get_family(name)
    scaling, s_fit, p_fit = centre_and_scale(fit_rec, "fit")
    structure = family.make_structure(fit_rec.dt, structure_size(family, size))
    check_fitting_data([fit_rec], family, structure)
    result = family.fit(p_fit, s_fit, structure)
    offsets = {"": (scaling.sensor_offset, scaling.position_offset),
               "_oracle": (val_rec.sensor.mean(), val_rec.position.mean())}
    out = {"size": structure_size(family, size), "size_help": family.size_help,
           "n_params": _count_numbers(result.params.to_dict()), "fit_seconds": result.seconds,
           "converged": result.converged, "compensated_note": ""}
    for suffix, (s_off, p_off) in offsets.items():
        s_val = (val_rec.sensor - s_off) / scaling.sensor_scale
        p_val = (val_rec.position - p_off) / scaling.position_scale
        s_hat, _ = family.simulate(structure, result.params, p_val)
        out[f"r2_forward{suffix}"] = r2(s_val, s_hat)
        if suffix == "":
            out["e_rms_pct"] = e_rms_pct(s_val, s_hat, scale=1.0)
            out["e_max_pct"] = e_max_pct(s_val, s_hat, scale=1.0)
        out[f"r2_compensated{suffix}"] = None
        if family.invert is None:
            out["compensated_note"] = family.no_inverse_reason
            continue
        try:
            p_hat, _ = family.invert(structure, result.params, s_val)
            out[f"r2_compensated{suffix}"] = r2(p_val, p_hat)
        except HystkitError as exc:
            out["compensated_note"] = f"inverse failed: {exc}"
    try:
        out.update(measure_properties(family, structure, result.params))
    except FAMILY_FAILURES as exc:
        out.update(rate_dependent=None, return_point_memory=None, minor_loops_close=None,
                   properties_note=f"not measurable: {exc}")
    return out


def structure_size(family, size: int | None) -> int:
    return family.default_size if size is None else size


def _count_numbers(tree) -> int:
    """Fitted numbers in a params dict (nested lists and scalars)."""
    if isinstance(tree, dict):
        return sum(_count_numbers(v) for v in tree.values())
    if isinstance(tree, list | tuple):
        return sum(_count_numbers(v) for v in tree)
    return 1 if isinstance(tree, int | float) and not isinstance(tree, bool) else 0


def compare_models(fit_rec: Recording, val_rec: Recording, models: Sequence[str] | None = None,
                   sizes: Mapping[str, int] | None = None,
                   progress: Callable[[str], None] = lambda _: None,
                   executor: Executor | None = None) -> dict:
    """Fit every model on ``fit_rec`` and score it on ``val_rec``.

    Each family is one piece of work for `executor` (default: serial): its forward model and
    its direct compensator; the table is the same whichever executor ran them.

    Parameters
    ----------
    fit_rec : Recording
        The recording every family is fitted on.
    val_rec : Recording
        The recording every fit is scored on.
    models : sequence of str, optional
        Family names; None: every registered family (``hystkit.models.FAMILIES``), sorted.
    sizes : mapping of str to int, optional
        Size per family name; a family not in it gets its default size.
    progress : callable, optional
        Called with one line of text as each family is done (default: nothing).
    executor : Executor, optional
        Runs the pieces of work; None: serially, here.

    Returns
    -------
    dict
        ``{model: {n_params, fit_seconds, r2_forward, r2_compensated (None if no inverse, with
        compensated_note), r2_direct (a compensator fitted sensor -> position), linear_r2,
        the same four with an ``_oracle`` suffix (paper's protocol), center, direct_status,
        verdict and verdict_message (the shared verdict on the direct compensator's deployable
        validation scores, :func:`hystkit.compensation.verdict`), e_rms_pct, e_max_pct (forward, % of the normalised range), rate_dependent,
        return_point_memory, minor_loops_close, ...}}``, in the order of `models`; a model
        whose fit fails has ``error`` (the others are still scored).

    Raises
    ------
    InputError
        Fitting data no family can be fitted to (too short, constant, a spike), or validation
        data no family can be scored on (constant, a spike); checked once before any fit. Too
        few samples for one family's parameters is that family's error.
    """
    check_fitting_data([fit_rec])
    check_excursion([val_rec])
    models = sorted(FAMILIES) if models is None else list(models)
    # One piece per family, its two fits together: a worker then loads one family's compiled
    # kernels once, where two pieces of the same family on two workers loaded them twice.
    pieces = [(name, (sizes or {}).get(name)) for name in models]
    n_done = 0

    def done(i: int, _: dict) -> None:
        nonlocal n_done
        n_done += 1
        progress(f"  {pieces[i][0]}: fitted and scored ({n_done}/{len(models)})")

    results = (executor or SerialExecutor()).map(
        _compare_family, pieces, shared={"fit_rec": fit_rec, "val_rec": val_rec},
        on_done=done, cost=lambda piece: 2 * fit_cost(piece[0], piece[1], fit_rec.sensor.size))
    return dict(zip(models, results, strict=True))


def _compare_family(piece: tuple[str, int | None], *, fit_rec: Recording,
                    val_rec: Recording) -> dict:
    """One family's forward scores and its direct compensator's, or the first ``error``
    (the forward fit's, as when the two ran one after the other)."""
    name, size = piece
    forward, direct = (_compare_piece((name, size, part), fit_rec=fit_rec, val_rec=val_rec)
                       for part in ("forward", "direct"))
    return next((part for part in (forward, direct) if "error" in part),
                {**forward, **direct})


def _compare_piece(piece: tuple[str, int | None, str], *, fit_rec: Recording,
                   val_rec: Recording) -> dict:
    """One family's forward scores or its direct compensator's; a failure is an ``error``."""
    name, size, part = piece
    try:
        if part == "forward":
            return _forward_scores(name, size, fit_rec, val_rec)
        comp = fit_compensator(fit_rec, size, model=name, diagnose=False)
        direct = evaluate(comp, val_rec)
        use, why = use_verdict(comp, val_rec, direct, "validation (deployable)")
        entry = {"center": direct["center"], "direct_status": comp.fit_info["status"],
                 "verdict": use, "verdict_message": why}
        for suffix in ("", "_oracle"):
            entry[f"r2_direct{suffix}"] = direct[f"r2{suffix}"]
            entry[f"linear_r2{suffix}"] = direct[f"linear_r2{suffix}"]
        return entry
    except FAMILY_FAILURES as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}


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


def plot_generalization(matrix: Mapping[str, dict]) -> Figure:
    """One heat map per model: rows = trained on, columns = tested on, each cell's R² written
    in it. The colour is the unexplained fraction 1 - R² on a log scale shared by all panels,
    so 0.99, 0.876 and -2390 all look different (a linear scale clipped at 0.9 made the last
    two alike); failed cells stay blank.

    Parameters
    ----------
    matrix : mapping of str to dict
        :func:`generalization_matrix`'s result (its ``"r2"`` grids are drawn).

    Returns
    -------
    matplotlib.figure.Figure
        Up to three panels a row, one per model, with a shared colour bar on the right.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter

    grids = {name: _r2_grid(entry["r2"]) for name, entry in matrix.items()}
    layout = _PanelLayout.fit(
        len(matrix), [label for rows, _, _ in grids.values() for label in rows],
        [label for _, names, _ in grids.values() for label in names],
        max((len(names) for _, names, _ in grids.values()), default=1))
    fig = Figure(figsize=layout.figsize)
    worst = max([np.nanmax(1 - v) for _, _, v in grids.values() if np.isfinite(v).any()],
                default=1.0)
    norm = LogNorm(vmin=_UNEXPLAINED_FLOOR, vmax=max(1.0, worst))
    image = None
    for k, (name, (rows, names, values)) in enumerate(grids.items()):
        ax = fig.add_axes(layout.panel(k))
        unexplained = np.clip(1 - values, _UNEXPLAINED_FLOOR, None)
        image = ax.imshow(unexplained, norm=norm, cmap="viridis_r")
        for i in range(len(rows)):
            for j in range(len(names)):
                failed = np.isnan(values[i, j])
                dark = not failed and norm(unexplained[i, j]) > 0.6  # viridis_r: dark when bad
                ax.text(j, i, "fail" if failed else f"{values[i, j]:.3f}", ha="center",
                        va="center", fontsize="small", color="w" if dark else "k")
        ax.set(xticks=range(len(names)), xticklabels=names, yticks=range(len(rows)),
               yticklabels=rows, xlabel="tested on", ylabel="trained on",
               title=f"{name} (deployable R²)")
        ax.tick_params(axis="x", labelrotation=layout.column_rotation)
    if image is not None:
        bar = fig.colorbar(image, cax=fig.add_axes(layout.colour_bar()),
                           label="1 - R² (log scale)\n1: no better than the mean")
        # Decades as plain text (10⁻⁴), without minor ticks: matplotlib's default 10^-4 labels
        # set up its maths typesetter, ~0.14 s of the figure's first drawing, and its minor
        # ticks ~0.08 s more
        bar.ax.yaxis.set_major_formatter(FuncFormatter(_decade_label))
        bar.minorticks_off()
    return fig


_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _decade_label(value: float, _position: int) -> str:
    """``10⁻⁴`` for 1e-4 and the other powers of ten; nothing between them."""
    exponent = round(np.log10(value)) if value > 0 else None
    if exponent is None or not np.isclose(value, 10.0 ** exponent, rtol=1e-9):
        return ""
    return "10" + str(exponent).translate(_SUPERSCRIPTS)


class _PanelLayout:
    """Where the generalisation figure's panels and colour bar go, worked out once from the
    fonts' sizes and the longest recording names (no drawing): up to three panels a row, each
    a 2.7 x 2.2 in axes box (the image square inside it) with room for its labels, and the
    colour bar on the right. Matplotlib's constrained layout found such places by drawing the
    figure an extra time: ~0.5 s of the ~1 s that saving the 10-model figure took, serial work
    after ``generalize``'s parallel map."""

    AXES = (2.7, 2.2)  # inches of a panel's axes box; the labels go around it
    BAR_SPACE = 1.4  # inches right of the panels: the colour bar, its ticks and its label
    PAD = 0.1  # inches between a panel's labels and the next panel or the figure's edge

    def __init__(self, n_panels: int, margins: tuple[float, float, float],
                 column_rotation: float):
        self.n_cols = min(3, max(n_panels, 1))
        self.n_rows = max(-(-n_panels // self.n_cols), 1)
        self.left, self.bottom, self.top = margins
        self.column_rotation = column_rotation
        self.cell = (self.left + self.AXES[0] + self.PAD, self.bottom + self.AXES[1] + self.top)
        self.figsize = (self.cell[0] * self.n_cols + self.BAR_SPACE, self.cell[1] * self.n_rows)

    @classmethod
    def fit(cls, n_panels: int, row_labels: Sequence[str], column_labels: Sequence[str],
            n_columns: int) -> _PanelLayout:
        """Margins that hold the longest of `row_labels` (tick labels left of a panel) and of
        `column_labels` (below it, turned upright when wider than a column of `n_columns`)."""
        import matplotlib as mpl
        from matplotlib.font_manager import FontProperties
        from matplotlib.textpath import TextToPath

        rc, measure = mpl.rcParams, TextToPath()

        def extent(texts: Sequence[str], size: str | float) -> tuple[float, float]:
            """Widest width and one line's height of `texts` at font `size` [points]."""
            font = FontProperties(size=size)
            widths = [measure.get_text_width_height_descent(t, font, ismath=False)[0]
                      for t in texts]
            line = measure.get_text_width_height_descent("Tg", font, ismath=False)[1] * 1.2
            return max(widths, default=0.0), line

        label = extent([], rc["axes.labelsize"])[1] + rc["axes.labelpad"]
        ticks = max(rc["ytick.major.size"], rc["xtick.major.size"]) + max(
            rc["ytick.major.pad"], rc["xtick.major.pad"])
        row_width, _ = extent(row_labels, rc["ytick.labelsize"])
        column_width, line = extent(column_labels, rc["xtick.labelsize"])
        # A column's share of the image (square cells in the axes box's height) [points]
        upright = column_width > 0.9 * 72 * cls.AXES[1] / max(n_columns, 1)
        bottom = label + ticks + (column_width if upright else line)
        top = extent([], rc["axes.titlesize"])[1] + rc["axes.titlepad"]
        margins = (cls.PAD + (label + ticks + row_width) / 72, cls.PAD + bottom / 72,
                   cls.PAD + top / 72)
        return cls(n_panels, margins, 90.0 if upright else 0.0)

    def panel(self, k: int) -> tuple[float, float, float, float]:
        """Axes rectangle (left, bottom, width, height; figure fractions) of panel `k`, row by
        row from the top left."""
        (width, height), (cell_w, cell_h) = self.figsize, self.cell
        x0 = (k % self.n_cols) * cell_w + self.left
        y0 = (self.n_rows - 1 - k // self.n_cols) * cell_h + self.bottom
        return x0 / width, y0 / height, self.AXES[0] / width, self.AXES[1] / height

    def colour_bar(self) -> tuple[float, float, float, float]:
        """The colour bar's rectangle: 0.2 in wide, 80 % of the figure's height, centred."""
        width = self.figsize[0]
        return (self.cell[0] * self.n_cols + 0.25) / width, 0.1, 0.2 / width, 0.8


# 1 - R² below this (R² above 0.9999) shows as the best colour
_UNEXPLAINED_FLOOR = 1e-4


def _r2_grid(grid: Mapping[str, Mapping[str, float | None]]) -> tuple[list, list, np.ndarray]:
    """Row names, column names and the R² values of one model (NaN where it failed)."""
    rows = list(grid)
    names = list(next(iter(grid.values()))) if grid else []
    values = np.array([[np.nan if grid[a][b] is None else grid[a][b] for b in names]
                       for a in rows], dtype=float).reshape(len(rows), len(names))
    return rows, names, values


def _fmt(x: float | None, spec: str = ".4f") -> str:
    # the leading space keeps a value wider than its column (R² -2390.9675) apart from the next
    return " -" if x is None else " " + format(x, spec)


def _yes_no(flag: bool | None) -> str:
    return "n/a" if flag is None else ("yes" if flag else "no")


def format_compare(table: Mapping[str, dict]) -> str:
    """Plain-text table of :func:`compare_models`' result: deployable, then oracle scores.

    Parameters
    ----------
    table : mapping of str to dict
        :func:`compare_models`' result.

    Returns
    -------
    str
        One line per model (``FAILED`` and its error for a failed one), then why R² inv is
        missing where it is.
    """
    head = (f"{'model':<10}{'params':>7}{'fit s':>7}{'R² fwd':>8}{'R² inv':>8}{'R² dir':>8}"
            f"{'line':>8} | oracle:{'R² inv':>8}{'R² dir':>8}{'line':>8}{'e_rms%':>8}"
            f"  rate-dep  ret.point  minor  direct fit  verdict on validation")
    lines = [head]
    for name, m in table.items():
        if "error" in m:
            lines.append(f"{name:<10}  FAILED: {m['error']}")
            continue
        lines.append(
            f"{name:<10}{_fmt(m['n_params'], 'd'):>7}{_fmt(m['fit_seconds'], '.2f'):>7}"
            f"{_fmt(m['r2_forward']):>8}{_fmt(m['r2_compensated']):>8}{_fmt(m['r2_direct']):>8}"
            f"{_fmt(m['linear_r2']):>8} |        {_fmt(m['r2_compensated_oracle']):>8}"
            f"{_fmt(m['r2_direct_oracle']):>8}{_fmt(m['linear_r2_oracle']):>8}"
            f"{_fmt(m['e_rms_pct'], '.2f'):>8}"
            f"  {_yes_no(m['rate_dependent']):>8}  {_yes_no(m['return_point_memory']):>9}"
            f"  {_yes_no(m['minor_loops_close']):>5}  {m['direct_status']:<10}"
            f"  {m.get('verdict', 'n/a')}")
    notes = [f"  {name}: no R² inv: {m['compensated_note']}" for name, m in table.items()
             if "error" not in m and m["r2_compensated"] is None]
    return "\n".join(lines + (["why some R² inv are missing:"] + notes if notes else []))
