"""Every refusal (exit 3) of fit, evaluate and select ends with one line ``next: try ...``,
chosen by the refusal's reason (issue 27.5); each mapping on a real refusal case: the labelled
corpus of tests/compensation/test_verdict_corpus.py, the micromanipulator excerpt, and the MR
damper from the shared data where it is here."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from hystkit.cli._common import GUARD_EXIT
from hystkit.cli._next_step import next_step
from hystkit.io import read_recording, write_recording

from ..cli_support import run_cli
from ..compensation.test_verdict_corpus import data  # noqa: F401 (the labelled corpus)
from ..studies.test_compare_failures import broken_chua  # noqa: F401 (a family that raises)
from .test_use_guards_cli import _patched


def _next(out: str) -> str:
    """The refusal's last line (on stdout, after the refusal's own line on stderr)."""
    last = out.strip().splitlines()[-1]
    assert last.startswith("next: try "), out
    return last


def _fit(capsys, data, tmp_path, train, *options):  # noqa: F811 (the fixture's values)
    model = tmp_path / "model.json"
    return run_cli(capsys, "fit", data[train], "--out", model, *options)


@pytest.mark.parametrize(("train", "options", "status", "step"), [
    # the micromanipulator's 2-cell mpl-g pins a conductance on its floor
    ("ident", ("--model", "mpl-g", "--size", "2"), "on bounds", "next: try --size 1 "),
    ("sine1", ("--cells", "4"), "not converged", "next: try --cells 3 (a smaller model"),
    ("ident", ("--cells", "4"), "not converged", "next: try --cells 3 (a smaller model"),
    # Bouc-Wen is the virtual sensor's straight line, 1e-4 below it in training
    ("sine1", ("--model", "boucwen"), "worse than line",
     "next: try --model auto (mpl with 1-3 cells"),
    ("noise_only", ("--model", "mpl"), "no signal", "next: try checking the columns"),
    # the line explains nothing either: a sensor problem, whatever the status's name
    ("unrelated", ("--model", "mpl"), "", "next: try checking the columns"),
    ("sine1", ("--no-limit",), "no limit", "next: try the fit without --no-limit"),
])
def test_a_refused_fit_names_what_to_try(data, tmp_path, capsys, train, options, status,  # noqa: F811
                                         step):
    code, out, err = _fit(capsys, data, tmp_path, train, *options)
    assert code == GUARD_EXIT, err
    assert f"hystkit: fit {status}" in err
    assert _next(out).startswith(step)


def test_mpl_on_bounds_is_sent_to_mpl_poly_or_fewer_cells(tmp_path, capsys):
    """The issue's case on real data: the MR damper's 3-cell mPL ends 'on bounds' (w[2]);
    the guided fit's winner there is mpl-poly (test_guided_fit)."""
    from hystkit.datasets import load
    from hystkit.errors import InputError

    try:
        rec = load("mr_damper", "10mm_1Hz_0.5A").to_recording()
    except InputError as exc:
        pytest.skip(f"shared data absent: {exc}")
    path = write_recording(rec, tmp_path / "mr.csv")
    code, out, err = run_cli(capsys, "fit", path, "--cells", "3", "--out", tmp_path / "m.json")
    assert code == GUARD_EXIT and "hystkit: fit on bounds" in err
    assert _next(out).startswith("next: try --model mpl-poly (a curved static curve in one "
                                 "cell) or --cells 2; --model auto")


def test_a_collapsed_fit_is_sent_to_the_guided_fit_and_the_columns(tmp_path, capsys,
                                                                   monkeypatch):
    """A constructed collapse (all output weights zero), as tests/cli/test_use_guards_cli."""
    from hystkit.models import get_family
    from hystkit.models.mpl import MplParams
    from hystkit.sensors import simulate_experiment

    real = get_family("mpl")

    def collapsed_fit(u, y, structure, **kwargs):
        result = real.fit(u, y, structure, **kwargs)
        return replace(result, params=MplParams(i_s=result.params.i_s, v_t=result.params.v_t,
                                                w=np.zeros(structure.n_cells + 1), v_b=0.0))

    _patched(monkeypatch, fit=collapsed_fit)
    path = write_recording(simulate_experiment("sine", 1), tmp_path / "sine.csv")
    code, out, err = run_cli(capsys, "fit", path, "--model", "mpl", "--out", tmp_path / "m.json")
    assert code == GUARD_EXIT and "hystkit: fit collapsed" in err
    assert _next(out).startswith("next: try --model auto")
    assert "if every model collapses, checking the columns" in _next(out)


@pytest.mark.parametrize(("test", "cells", "status", "step"), [
    # far below its own line on another excitation, the line itself good
    ("chirp2", "1", "worse_than_line", "next: try refitting on recordings like these"),
    # the scored file's sensor and position swapped, or the sensor wired the other way
    ("swapped", "1", "no_signal", "next: try checking that this file's columns"),
    ("flipped", "1", "worse_than_line", "next: try checking that this file's columns"),
])
def test_a_refused_evaluation_names_what_to_try(data, tmp_path, capsys, test, cells,  # noqa: F811
                                                status, step):
    code, _, err = _fit(capsys, data, tmp_path, "sine1", "--cells", cells)
    assert code == 0, err
    scores = tmp_path / "scores.json"
    code, out, err = run_cli(capsys, "evaluate", tmp_path / "model.json", data[test],
                             "--json", scores)
    assert code == GUARD_EXIT and json.loads(scores.read_text())["verdict"] == status
    assert err.strip().splitlines()[-1].startswith("hystkit: evaluate: ")
    assert _next(out).startswith(step)


def test_an_extrapolating_evaluation_asks_for_data_that_cover_the_range(data, tmp_path,  # noqa: F811
                                                                         capsys):
    assert _fit(capsys, data, tmp_path, "decay_tail", "--model", "mpl")[0] == 0
    code, out, err = run_cli(capsys, "evaluate", tmp_path / "model.json", data["sine2"])
    assert code == GUARD_EXIT and "extrapolated" in err
    assert _next(out).startswith("next: try refitting on recordings that cover this range")


def test_a_refused_selection_names_what_to_try(data, tmp_path, capsys):  # noqa: F811
    out_model = tmp_path / "best.json"
    code, out, err = run_cli(capsys, "select", data["noise_only"], "--models", "mpl,pi",
                             "--centers", "fit", "--out", out_model)
    assert code == GUARD_EXIT and "no usable model" in err and not out_model.exists()
    assert _next(out).startswith("next: try checking the columns")
    # Bouc-Wen alone on the virtual sensor: its straight line, which explains the position
    code, out, err = run_cli(capsys, "select", data["sine1"], "--models", "boucwen",
                             "--centers", "fit", "--out", out_model, "--force")
    assert code == GUARD_EXIT and "beats its straight line" in err
    assert _next(out).startswith("next: try --centers track (an offset that drifts)")


def test_a_partly_failed_comparison_names_what_to_try(broken_chua, tmp_path, capsys):  # noqa: F811
    """failures_exit, the exit of compare and generalize, with a family whose fit raises."""
    from hystkit.sensors import simulate_experiment

    f = write_recording(simulate_experiment("sine", 1), tmp_path / "f.csv")
    v = write_recording(simulate_experiment("sine", 2), tmp_path / "v.csv")
    code, out, err = run_cli(capsys, "compare", f, v, "--models", "mpl,mpl-poly", "--out",
                             tmp_path / "cmp")
    assert code == GUARD_EXIT and "1 model(s) failed: mpl-poly" in err
    assert _next(out).startswith("next: try one failed family alone, 'hystkit fit DATA "
                                 "--model NAME")


def test_data_far_outside_the_training_range_ask_for_a_refit_whatever_the_score(
        data, tmp_path, capsys):  # noqa: F811
    """A run at eight times the training amplitude: the model loses to its straight line
    there, but the reason is that the data left the range it learnt, so the next step is data
    that cover it (not the columns, which are right)."""
    assert _fit(capsys, data, tmp_path, "sine1", "--model", "mpl")[0] == 0
    sine2 = read_recording(data["sine2"])
    big = tmp_path / "big.csv"
    write_recording(replace(sine2, sensor=8 * sine2.sensor, position=8 * sine2.position), big)
    scores = tmp_path / "scores.json"
    code, out, _ = run_cli(capsys, "evaluate", tmp_path / "model.json", big, "--json", scores)
    assert code == GUARD_EXIT
    assert json.loads(scores.read_text())["verdict"] in ("worse_than_line", "no_signal",
                                                          "extrapolated")
    assert _next(out).startswith("next: try refitting on recordings that cover this range")


def test_a_poor_compensator_asks_for_recordings_like_the_one_judged(tmp_path, capsys):
    """Ferrite loops: fitted on the 80 A/m loop, judged on the 16 A/m one inside it, R² 0.19
    above a line at -0.31 (it was 'ok'): poor, and the next step is data like these."""
    from hystkit.datasets import load
    from hystkit.errors import InputError

    try:
        train, test = (load("bh_loops", f"MnZn_ferrite_H{h}").to_recording() for h in (80, 16))
    except InputError as exc:
        pytest.skip(f"shared data absent: {exc}")
    paths = [write_recording(rec, tmp_path / f"{name}.csv")
             for rec, name in ((train, "h80"), (test, "h16"))]
    model = tmp_path / "m.json"
    assert run_cli(capsys, "fit", paths[0], "--model", "mpl-poly", "--out", model)[0] == 0
    code, out, err = run_cli(capsys, "evaluate", model, paths[1])
    assert code == GUARD_EXIT and "hystkit: evaluate: poor: " in err
    assert _next(out).startswith("next: try refitting on recordings like these")
    assert "holds only in part here" in _next(out)


def test_a_fit_that_explains_too_little_is_sent_to_other_models_then_the_sensor(tmp_path,
                                                                                capsys):
    """A sensor whose noise is as large as its signal: one mPL cell explains ~60 % of the
    position in training (poor)."""
    from hystkit.io import Recording
    from hystkit.sensors import simulate_experiment

    rec = simulate_experiment("sine", 1)
    noise = np.std(rec.sensor) * np.random.default_rng(5).normal(size=rec.n_samples)
    noisy = write_recording(Recording(time=rec.time, position=rec.position, source="noisy",
                                      sensor=rec.sensor + noise), tmp_path / "noisy.csv")
    code, out, err = run_cli(capsys, "fit", noisy, "--model", "mpl", "--out", tmp_path / "m.json")
    assert code == GUARD_EXIT and "hystkit: fit poor" in err
    step = _next(out)
    assert step.startswith("next: try --model auto") and "explains too little" in step
    assert step.endswith("check the columns (--columns position=NAME,sensor=NAME)")


@pytest.mark.parametrize(("command", "start"), [
    ("select", "more recordings of the device (one per run) or --models with more families"),
    ("guided", "more recordings of the device (one per run) or 'hystkit select DATA --models"),
])
def test_a_selection_with_only_poor_candidates_asks_for_data_or_more_families(command, start):
    assert next_step("poor", command=command, model="mpl", size=1).startswith(start)


@pytest.mark.parametrize(("training_line_r2", "start"), [
    (0.94, "checking that this file's columns"),  # the line worked in training: wiring?
    (None, "checking that this file's columns"),  # a model file without it: as before
    # an MR damper: force against displacement is no line in training either (0.006), so a
    # line at 0.005 on the judged run says nothing about its columns (25 mm, 1 A, fitted at
    # 0.5 Hz, judged at 0.25 Hz: R² -20.4)
    (0.006, "refitting on recordings like these"),
])
def test_columns_are_suspected_only_where_the_line_worked_in_training(training_line_r2, start):
    step = next_step("worse_than_line", command="evaluate", line_r2=0.005,
                     training_line_r2=training_line_r2)
    assert step.startswith(start)


def test_a_guided_refusal_whose_refit_failed_also_names_select_with_every_family():
    # bh_loops MnZn_HP_ferrite_H80 (129 samples): the guided list's best (mpl:3) failed its
    # refit, while select's full list found a usable inverse Preisach
    step = next_step("refit", command="guided", model="mpl", size=3)
    assert step.startswith("'hystkit fit DATA --model mpl --size 3' (the best candidate)")
    assert step.endswith("or 'hystkit select DATA --out m.json' (every family, both modes)")
    assert "hystkit select" not in next_step("refit", command="select", model="mpl", size=3)
