"""compare / generalize survive a failing family: listed with its reason, others scored."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

import hystkit.compensation._compensator as compensator
import hystkit.compensation._fitting as fitting
import hystkit.studies._compare as compare
from hystkit.cli import main
from hystkit.models import get_family

BROKEN = "mpl-poly"


@pytest.fixture
def broken_chua(monkeypatch):
    """One family ("mpl-poly" here) whose fit raises what a collapsed fit raised in the field
    (studies/_properties)."""
    real = get_family

    def patched(name):
        family = real(name)
        if name != BROKEN:
            return family

        def fit(*args, **kwargs):
            raise ValueError("x and y must not be constant")

        return SimpleNamespace(**{k: getattr(family, k) for k in (
            "name", "title", "default_size", "size_help", "make_structure", "simulate",
            "invert", "no_inverse_reason", "random_params")}, fit=fit)

    monkeypatch.setattr(compare, "get_family", patched)
    monkeypatch.setattr(fitting, "get_family", patched)
    monkeypatch.setattr(compensator, "get_family", patched)


def test_compare_with_a_failing_family_still_writes_its_table(broken_chua, tmp_path, capsys):
    f, v = tmp_path / "f.csv", tmp_path / "v.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "1", "--out", str(f)]) == 0
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "2", "--out", str(v)]) == 0
    code = main(["compare", str(f), str(v), "--models", "mpl,mpl-poly", "--out", str(tmp_path)])
    out = capsys.readouterr()
    assert code == 3 and "1 model(s) failed: mpl-poly" in out.err
    table = json.loads((tmp_path / "compare.json").read_text())
    assert "x and y must not be constant" in table["mpl-poly"]["error"]
    assert table["mpl"]["r2_direct"] > table["mpl"]["linear_r2"]
    assert {"r2_direct_oracle", "linear_r2_oracle", "center"} <= set(table["mpl"])
    assert "FAILED: ValueError" in out.out


def test_generalize_on_own_recordings_lists_the_failure(broken_chua, tmp_path, capsys):
    paths = []
    for name, seed in (("sine", 1), ("noise", 2), ("chirp", 3)):
        paths.append(tmp_path / f"{name}.csv")
        assert main(["simulate-sensor", "--excitation", name, "--seed", str(seed), "--out",
                     str(paths[-1])]) == 0
    code = main(["generalize", *map(str, paths), "--models", "mpl,mpl-poly", "--out",
                 str(tmp_path / "g")])
    assert code == 3
    matrix = json.loads((tmp_path / "g" / "generalize.json").read_text())
    grid = matrix["mpl"]["r2"]
    assert set(grid) == {"sine", "noise", "chirp"}
    assert all(np.isfinite(v) for row in grid.values() for v in row.values())
    assert set(matrix["mpl"]["r2_oracle"]) == set(grid)
    assert all(v is None for row in matrix["mpl-poly"]["r2"].values() for v in row.values())
    assert set(matrix["mpl-poly"]["errors"]) == {"sine", "noise", "chirp"}
    assert "deployable R²" in capsys.readouterr().out


def test_a_forward_model_that_runs_away_leaves_the_table_writable(monkeypatch, tmp_path):
    """A family whose forward run gives inf on validation fails in its row (exit 3), and
    compare.json is still written."""
    real = get_family

    def patched(name):
        family = real(name)
        if name != "mpl":
            return family
        fields = ("name", "title", "default_size", "size_help", "make_structure", "fit",
                  "invert", "no_inverse_reason", "random_params")

        def simulate(structure, params, u):  # compare's forward runs (the fit uses its own)
            y, x = family.simulate(structure, params, u)
            return np.full_like(y, np.inf), x

        return SimpleNamespace(**{k: getattr(family, k) for k in fields}, simulate=simulate)

    monkeypatch.setattr(compare, "get_family", patched)
    f, v = tmp_path / "f.csv", tmp_path / "v.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "1", "--out", str(f)]) == 0
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "2", "--out", str(v)]) == 0
    code = main(["compare", str(f), str(v), "--models", "mpl", "--out", str(tmp_path / "c")])
    assert code == 3
    row = json.loads((tmp_path / "c" / "compare.json").read_text())["mpl"]
    assert "infinite" in row["error"]
