"""``hystkit fit --loss/--f-scale/--weights`` (issue 14.4): provenance in the model file and
one-line errors before any work."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main

from ..cli_support import run_cli


def test_cli_losses_are_the_library_losses():
    from hystkit.cli._fit_cost_options import LOSSES as CLI_LOSSES
    from hystkit.identification import LOSSES

    assert CLI_LOSSES == LOSSES


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    """The virtual sensor's sine run with a weights column 'w' (all 1)."""
    folder = tmp_path_factory.mktemp("costs")
    path = folder / "sine.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(path)]) == 0
    frame = pd.read_csv(path)
    frame["w"] = 1.0
    frame.to_csv(path, index=False)
    return path


def _with_weight(recording: Path, folder: Path, row: int, value: object) -> Path:
    frame = pd.read_csv(recording)
    frame["w"] = frame["w"].astype(object)
    frame.loc[row, "w"] = value
    out = folder / "bad.csv"
    frame.to_csv(out, index=False)
    return out


def test_robust_weighted_fit_is_recorded_and_summarised(recording, tmp_path, capsys):
    model = tmp_path / "m.json"
    code, out, err = run_cli(capsys, "fit", recording, "--cells", 1, "--loss", "huber",
                          "--f-scale", 0.05, "--weights", "w", "--out", model)
    assert code == 0, err
    assert "minimised the huber cost (f_scale 0.05, weighted by column 'w')" in out
    assert "R², AIC and BIC are on the plain SSE" in out
    fit = json.loads(model.read_text())["fit"]
    assert (fit["loss"], fit["f_scale"], fit["weights"]) == ("huber", 0.05, "w")
    # AIC from the plain SSE: n log(SSE / n) + 2 k
    n, k = fit["training_samples"], fit["n_params"]
    assert fit["aic"] == pytest.approx(n * math.log(fit["cost"] / n) + 2 * k, rel=1e-12)
    assert fit["objective"] < fit["cost"]  # huber counts the large residuals less
    # the standard errors are the plain SSE's: labelled as indicative in the output, the
    # model file and the report alike
    caveat = ("standard errors of the plain SSE at these parameters, indicative only: the fit "
              "minimised the huber cost (f_scale 0.05, weighted by column 'w')")
    assert fit["standard_errors"]["caveat"] == caveat
    lines = out.splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("  standard errors"))
    assert lines[at + 1] == f"    ({caveat})"
    import html

    from hystkit.compensation import load_compensator
    from hystkit.studies._report_model import fit_section

    assert f"Caveat: {caveat}." in html.unescape(fit_section(load_compensator(model)).to_html())


def test_robust_loss_without_f_scale_warns_once(recording, tmp_path, capsys):
    code, _, err = run_cli(capsys, "fit", recording, "--cells", 1, "--loss", "cauchy", "--out",
                        tmp_path / "m.json")
    assert code in (0, 3)
    warnings = [line for line in err.splitlines() if "without --f-scale" in line]
    expected = ("hystkit: warning: --loss cauchy without --f-scale: f_scale 1 leaves a robust "
                "loss close to the SSE on the normalised data (max |.| = 1); set --f-scale to "
                "5-10 times the plain fit's RMS residual")
    assert warnings == [expected]
    _, _, err = run_cli(capsys, "fit", recording, "--cells", 1, "--loss", "cauchy", "--f-scale",
                     0.05, "--out", tmp_path / "m2.json")
    assert "without --f-scale" not in err


def test_plain_fit_records_the_sse(recording, tmp_path, capsys):
    model = tmp_path / "m.json"
    code, out, err = run_cli(capsys, "fit", recording, "--cells", 1, "--out", model)
    assert code == 0, err
    assert "minimised" not in out and "indicative only" not in out
    fit = json.loads(model.read_text())["fit"]
    assert (fit["loss"], fit["weights"], fit["objective_label"]) == ("linear", None, "SSE")
    assert fit["objective"] == fit["cost"]
    assert "caveat" not in fit["standard_errors"]


@pytest.mark.parametrize(("row", "value", "shown"), [(10, -1.0, "-1"), (20, "", "nan"),
                                                      (30, "abc", "'abc'")])
def test_bad_weight_names_file_column_and_row(recording, tmp_path, capsys, row, value, shown):
    bad = _with_weight(recording, tmp_path, row, value)
    code, _, err = run_cli(capsys, "fit", bad, "--weights", "w", "--out", tmp_path / "m.json")
    assert code == 2
    line = err.strip()
    assert line.startswith(f"hystkit: error: {bad}: column 'w', row {row + 1}: weight "), line
    assert shown in line and "\n" not in line
    assert not (tmp_path / "m.json").exists()


def test_missing_weights_column(recording, tmp_path, capsys):
    code, _, err = run_cli(capsys, "fit", recording, "--weights", "v", "--out", tmp_path / "m.json")
    assert code == 2
    assert err.strip() == f"hystkit: error: {recording}: no weights column 'v' (its other " \
                          f"columns: 'w')"


def test_all_zero_weights(recording, tmp_path, capsys):
    frame = pd.read_csv(recording)
    frame["w"] = 0.0
    zero = tmp_path / "zero.csv"
    frame.to_csv(zero, index=False)
    code, _, err = run_cli(capsys, "fit", zero, "--weights", "w", "--out", tmp_path / "m.json")
    assert code == 2 and "every value of the weights column 'w' is 0" in err


@pytest.mark.parametrize(("argv", "message"), [
    (["--loss", "l1"], "argument --loss: invalid choice: 'l1'"),
    (["--loss", "huber", "--model", "preisach"],
     ("model 'preisach' fits the plain SSE only (the losses its family declares); "
     "the huber loss is not available")),
    (["--f-scale", "0.1"], "--f-scale applies to a robust --loss"),
    (["--loss", "cauchy", "--f-scale", "0"], "argument --f-scale"),
    (["--weights", "w", "--weight-sum-max", "100"], "--weight-sum-max is solved on the SSE"),
])
def test_refused_before_any_work(recording, tmp_path, capsys, argv, message):
    code, out, err = run_cli(capsys, "fit", recording, *argv, "--out", tmp_path / "m.json")
    assert code == 2
    assert message in err
    assert "fitting" not in out  # refused before the data were read


def test_weights_drop_samples_for_a_linear_least_squares_model(recording, tmp_path, capsys):
    """preisach takes weights: zero weights on a block of samples make their targets
    irrelevant (the same model whatever they hold)."""
    frame = pd.read_csv(recording)
    frame.loc[1000:1400, "w"] = 0.0
    block = frame.loc[1000:1400, "position"].to_numpy()
    models = []
    # reversed in time: the block's mean and extremes (the centring and scaling) stay
    for name, values in (("same", block), ("reversed", block[::-1])):
        moved = frame.copy()
        moved.loc[1000:1400, "position"] = values
        path = tmp_path / f"{name}.csv"
        moved.to_csv(path, index=False)
        out = tmp_path / f"{name}.json"
        code, _, err = run_cli(capsys, "fit", path, "--model", "preisach", "--weights", "w",
                            "--out", out)
        assert code in (0, 3), err
        models.append(json.loads(out.read_text()))
    assert models[0]["fit"]["objective"] == pytest.approx(models[1]["fit"]["objective"],
                                                          rel=1e-9)
    assert models[0]["fit"]["cost"] != pytest.approx(models[1]["fit"]["cost"], rel=1e-3)
    np.testing.assert_allclose(_numbers(models[0]["params"]), _numbers(models[1]["params"]),
                               atol=1e-9)


def _numbers(value) -> list[float]:
    """Every number in a JSON value, depth first."""
    if isinstance(value, dict):
        return [x for key in sorted(value) for x in _numbers(value[key])]
    if isinstance(value, list):
        return [x for item in value for x in _numbers(item)]
    return [float(value)] if isinstance(value, (int, float)) else []
