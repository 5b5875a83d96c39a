"""The band through the commands: fit stores it, compensate and stream write the same bits,
evaluate scores it."""

from __future__ import annotations

import io
import json
import sys

import numpy as np
import pandas as pd
import pytest

from hystkit.cli import main
from hystkit.compensation import evaluate, load_compensator
from hystkit.io import read_recording
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("band")
    train, test = folder / "train.csv", folder / "test.csv"
    simulate_experiment("chirp", 1).to_frame().to_csv(train, index=False)
    simulate_experiment("chirp", 2).to_frame().to_csv(test, index=False)
    model = folder / "m.json"
    assert main(["fit", str(train), "--model", "mpl", "--out", str(model)]) == 0
    return {"train": train, "test": test, "model": model, "folder": folder}


def test_fit_stores_a_band_and_says_so(files, capsys):
    comp = load_compensator(files["model"])
    assert comp.band is not None and comp.band.level == 0.9
    assert comp.band.protocol == "interleaved cycles of the training recording"
    model = files["folder"] / "none.json"
    assert main(["fit", str(files["train"]), "--model", "mpl", "--no-band", "--out",
                 str(model)]) == 0
    assert load_compensator(model).band is None


def test_compensate_and_stream_give_the_same_band(files, capsys, monkeypatch):
    out = files["folder"] / "c.csv"
    assert main(["compensate", str(files["model"]), str(files["test"]), "--level", "0.8",
                 "--out", str(out)]) == 0
    written = pd.read_csv(out)
    lines = "time,sensor\n" + "".join(f"{t!r},{s!r}\n" for t, s in
                                      zip(written["time"], written["sensor"], strict=True))
    monkeypatch.setattr(sys, "stdin", io.StringIO(lines))
    capsys.readouterr()
    assert main(["stream", str(files["model"]), "--level", "0.8"]) == 0
    streamed = pd.read_csv(io.StringIO(capsys.readouterr().out))
    assert streamed.columns.tolist() == ["time", "position_estimate", "flags",
                                         "position_lower", "position_upper"]
    for name in ("position_estimate", "position_lower", "position_upper"):
        np.testing.assert_array_equal(streamed[name].to_numpy(), written[name].to_numpy())
    assert (written["position_lower"] < written["position_estimate"]).all()


def test_evaluate_reports_coverage_width_and_interval_score(files, capsys):
    scores_file = files["folder"] / "scores.json"
    assert main(["evaluate", str(files["model"]), str(files["test"]), "--json",
                 str(scores_file)]) == 0
    out = capsys.readouterr().out
    assert "band 90%: coverage" in out and "interval score" in out
    scores = json.loads(scores_file.read_text())
    assert 0.85 <= scores["band_coverage"] <= 1.0
    assert scores["band_width_mean"] > 0 and scores["interval_score"] >= scores["band_width_mean"]


def test_level_without_a_band_is_refused(files, capsys):
    model = files["folder"] / "bare.json"
    assert main(["fit", str(files["train"]), "--model", "mpl", "--no-band", "--out",
                 str(model)]) == 0
    code = main(["compensate", str(model), str(files["test"]), "--level", "0.8", "--out",
                 str(files["folder"] / "x.csv")])
    assert code == 2 and "has no prediction band" in capsys.readouterr().err
    assert not (files["folder"] / "x.csv").exists()


def test_report_shades_the_band_and_tables_its_coverage(files, capsys):
    page = files["folder"] / "report.html"
    assert main(["report", str(files["model"]), str(files["test"]), "--out", str(page)]) == 0
    html = page.read_text()
    assert "Shaded: the 90% prediction band" in html
    assert "Prediction band (deployable)" in html
    scores = evaluate(load_compensator(files["model"]), read_recording(files["test"]))
    assert f"<td>{scores['band_coverage']:.3f}</td>" in html  # evaluate's, to the table's digits


def test_export_bakes_the_level_in_and_refuses_it_without_a_band(files, capsys):
    out = files["folder"] / "c_code"
    assert main(["export", str(files["model"]), "--out", str(out), "--level", "0.8"]) == 0
    assert "80% prediction band" in capsys.readouterr().out
    assert "#define M_BAND_LEVEL 0.8\n" in (out / "m.h").read_text()
    bare = files["folder"] / "bare_export.json"
    assert main(["fit", str(files["train"]), "--model", "mpl", "--no-band", "--out",
                 str(bare)]) == 0
    assert main(["export", str(bare), "--out", str(files["folder"] / "c2"), "--level",
                 "0.8"]) == 2
    assert "no prediction band" in capsys.readouterr().err
    assert not (files["folder"] / "c2").exists()
