"""mpl-g from the command line on the virtual sensor: fit, compensate, evaluate, stream, export,
and the document's sec. 7.2 loop (table II's noise column as S_r, mpl-g as S_m^comp)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose

from hystkit.cli import main
from hystkit.compensation import load_compensator
from hystkit.io import read_recording


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mpl-g-cli")
    for excitation, seed in (("noise", 1), ("sine", 2)):
        assert main(["simulate-sensor", "--excitation", excitation, "--seed", str(seed),
                     "--out", str(folder / f"{excitation}.csv")]) == 0
    model = folder / "mpl-g.json"
    assert main(["fit", str(folder / "noise.csv"), "--model", "mpl-g", "--cells", "2",
                 "--out", str(model)]) == 0  # 0: the fit passed its guards
    return folder, model


def test_fit_writes_a_two_cell_model_in_the_gauge(files):
    _, model = files
    comp = load_compensator(model)
    assert comp.model == "mpl-g" and comp.structure.n_cells == 2
    assert comp.params.w[0] == 1.0 and comp.params.v_b == 0.0
    # a better fit than the straight line, on the training data
    assert comp.fit_info["training_r2"] > comp.fit_info["training_linear_r2"]


def test_compensate_writes_the_offline_estimate(files, capsys):
    folder, model = files
    out = folder / "estimate.csv"
    assert main(["compensate", str(model), str(folder / "sine.csv"), "--out", str(out)]) == 0
    written = pd.read_csv(out)["position_estimate"].to_numpy()
    ref = load_compensator(model).estimate(read_recording(folder / "sine.csv"))
    assert_allclose(written, ref, rtol=0, atol=1e-9 * np.max(np.abs(ref)))
    capsys.readouterr()


def test_evaluate_scores_the_compensator(files, capsys):
    folder, model = files
    scores = folder / "scores.json"
    assert main(["evaluate", str(model), str(folder / "sine.csv"), "--json", str(scores)]) == 0
    assert scores.exists() and json.loads(scores.read_text())
    capsys.readouterr()


def test_stream_gives_the_offline_estimate(files, capsys):
    folder, model = files
    rec = read_recording(folder / "sine.csv")
    lines = folder / "sensor.txt"
    pairs = zip(rec.time[:400], rec.sensor[:400], strict=True)
    lines.write_text("".join(f"{float(t)!r},{float(s)!r}\n" for t, s in pairs))
    assert main(["stream", str(model), "--in", str(lines)]) == 0
    rows = capsys.readouterr().out.splitlines()
    assert rows[0] == "time,position_estimate,flags,position_lower,position_upper"
    printed = np.array([[float(v) for v in row.split(",")[1:]] for row in rows[1:]])
    ref = load_compensator(model).estimate_with_band(rec)
    for column, expected in ((0, ref.estimate), (2, ref.lower), (3, ref.upper)):
        assert_allclose(printed[:, column], expected[:400], rtol=0,
                        atol=1e-9 * np.max(np.abs(ref.estimate)))


def test_export_writes_c_and_matlab(files, capsys):
    folder, model = files
    assert main(["export", str(model), "--out", str(folder / "c"), "--double"]) == 0
    assert main(["export", str(model), "--lang", "matlab", "--out", str(folder / "m")]) == 0
    assert any((folder / "c").glob("*.c")) and any((folder / "m").glob("*.m"))
    capsys.readouterr()


def test_document_loop_with_table_ii_noise_as_the_sensor(tmp_path, capsys):
    """Sec. 7.2: S_r = table II's noise column, S_m^comp = mpl-g fitted on S_r's response to
    eq. 7.3's sine. Three cells: bounded, and below the document's e_p,max (6.94e-4 m, eq. 7.6);
    one cell, the document's N = 1, runs away (docs/models/mpl_g.md says why)."""
    out = tmp_path / "three"
    assert main(["control", "--scheme", "direct", "--experiment", "sine", "--sensor",
                 "table-ii-noise", "--model", "mpl-g", "--model-size", "3", "--out",
                 str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["bounded"] and metrics["e_p_max"] < 6.94e-4
    capsys.readouterr()
