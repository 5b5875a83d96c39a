"""``datasets export`` carries the data set's units, so a voltage is never labelled a position
in mm downstream (issue 11: piezo_micromanipulator's actuator command is in V)."""

from __future__ import annotations

import json

from scipy.io import loadmat

from hystkit.cli import main
from hystkit.datasets import load_excerpt
from hystkit.io import options_for, read_recording

MM = "piezo_micromanipulator"


def test_exported_units_reach_fit_and_compensate(tmp_path, capsys):
    out = tmp_path / "pm.csv"
    assert main(["datasets", "export", MM, "--excerpt", "--out", str(out)]) == 0
    ds = load_excerpt(MM)
    assert (ds.input_unit, ds.output_unit) == ("V", "um")
    options, settings = options_for(out)
    assert settings == tmp_path / "pm.toml"
    assert dict(read_recording(out, options=options).units) == {"position": "V",
                                                                "sensor": "um"}
    model = tmp_path / "m.json"
    assert main(["fit", str(out), "--cells", "1", "--out", str(model)]) in (0, 3)
    assert json.loads(model.read_text())["fit"]["units"] == {"position": "V", "sensor": "um"}
    capsys.readouterr()
    assert main(["compensate", str(model), str(out), "--out", str(tmp_path / "c.csv")]) == 0
    assert "'position_estimate' [V]" in capsys.readouterr().out


def test_export_to_mat_and_parquet_keeps_units(tmp_path):
    mat, parquet = tmp_path / "pm.mat", tmp_path / "pm.parquet"
    for out in (mat, parquet):
        assert main(["datasets", "export", MM, "--excerpt", "--out", str(out)]) == 0
    assert loadmat(mat, simplify_cells=True)["units"] == {"position": "V", "sensor": "um"}
    assert dict(read_recording(parquet).units) == {"position": "V", "sensor": "um"}
    assert dict(read_recording(mat).units) == {"position": "V", "sensor": "um"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pm.mat", "pm.mat.json",
                                                          "pm.parquet", "pm.parquet.json"]
