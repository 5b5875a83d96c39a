"""Hostile model files for the mpl, mpl-poly, pl, preisach and gpreisach families (issue 10).

``good["model"]`` is a 1-cell mPL; a tiny model of each other family is fitted once from the
command line on the first 1500 rows of ``good["fit"]``. Each case edits one value of a model
file to something outside the family's documented domain or size limits -- the issue's own
examples first (mpl-poly resting 1e10 away, pl with ``a = 1e-30``, 20 M mPL cells, Preisach
with 512 levels) -- and runs ``evaluate`` and ``compensate`` on it: exit 2, one
``hystkit: error:`` line naming the file and the parameter, no traceback, nothing written.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from hystkit.cli import main

from .conftest import assert_model_file_refused

SIZES = {"mpl-poly": 1, "pl": 1, "preisach": 6, "gpreisach": 6}


@pytest.fixture(scope="module")
def models(good: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    """The JSON of a small fitted model of each family (the mPL one is ``good["model"]``)."""
    folder = tmp_path_factory.mktemp("models_a")
    short = folder / "fit.csv"  # 37 s of the sine: enough for these sizes, 4x faster
    short.write_text("".join(good["fit"].read_text().splitlines(keepends=True)[:1501]))
    out = {"mpl": json.loads(good["model"].read_text())}
    for name, size in SIZES.items():
        path = folder / f"{name}.json"
        assert main(["fit", str(short), "--model", name, "--size", str(size), "--out",
                     str(path)]) in (0, 3)  # 3: written, flagged by a guard
        out[name] = json.loads(path.read_text())
    return out


def _edit(model: dict, key: str, value: object) -> None:
    """Set ``key`` (dotted, list positions as integers) of `model` to `value`."""
    *path, last = key.split(".")
    for part in path:
        model = model[int(part)] if isinstance(model, list) else model[part]
    model[int(last) if isinstance(model, list) else last] = value


# (family, case, [(key, value), ...], fragments the error line holds besides the file name)
CASES = [
    # issue 10's examples
    ("mpl-poly", "linear-0-rest-1e10", [("params.f.0", [0.0, 0.0, 1.0, 1e-10])],
     ["params.f", "rest voltage", "-1e+10"]),
    ("pl", "a-1e-30", [("params.a.0", 1e-30)], ["params.a", "1e-30", "[0.001, 1000]"]),
    ("mpl", "cells-20M", [("structure.n_cells", 20_000_000)], ["structure.n_cells"]),
    ("preisach", "levels-512", [("structure.levels", 512), ("structure.capacity", 1026)],
     ["structure.levels", "512"]),
    # sizes
    ("mpl", "cells-1001", [("structure.n_cells", 1001)],
     ["structure.n_cells", "[1, 1000]", "1001"]),
    ("mpl-poly", "cells-1e12", [("structure.n_cells", 1e12)], ["structure.n_cells"]),
    ("pl", "basis-1e9", [("structure.n_basis", 10**9)], ["structure.n_basis"]),
    ("gpreisach", "levels-200", [("structure.levels", 200), ("structure.capacity", 402)],
     ["structure.levels", "[2, 128]"]),
    ("preisach", "capacity-1e12", [("structure.capacity", 10**12)], ["structure.capacity"]),
    ("preisach", "capacity-below-levels", [("structure.capacity", 3)],
     ["structure.capacity", "2 L + 2 = 14"]),
    ("mpl", "dt-1e-300", [("structure.dt", 1e-300)], ["structure.dt", "1e-300"]),
    ("mpl-poly", "slope-cap-1e-300", [("structure.slope_cap", 1e-300)],
     ["structure.slope_cap", "1e-06"]),
    ("pl", "power-1", [("structure.power", 1.0)], ["structure.power", "1.01"]),
    # parameter values
    ("mpl", "i_s-negative", [("params.i_s.0", -1.0)], ["params.i_s", "-1.0"]),
    ("mpl", "i_s-zero", [("params.i_s.0", 0.0)], ["params.i_s", "[1e-12, 1e+12]"]),
    ("mpl", "v_t-nan", [("params.v_t.0", math.nan)], ["params.v_t"]),
    ("mpl", "w-1e300", [("params.w.0", 1e300)], ["params.w", "1e+06"]),
    ("mpl", "v_b-abc", [("params.v_b", "abc")], ["params.v_b"]),
    ("mpl-poly", "c3-zero", [("params.f.0.3", 0.0)], ["params.f", "cubic coefficient"]),
    ("mpl-poly", "g3-subnormal", [("params.g.3", 5e-324)], ["params.g", "1e-200"]),
    ("mpl-poly", "w-inf", [("params.w.1", math.inf)], ["params.w"]),
    ("pl", "i_t-zero", [("params.i_t", 0.0)], ["params.i_t", "[1e-12, 1e+12]"]),
    ("pl", "v_t-abc", [("params.v_t", "abc")], ["params.v_t"]),
    ("preisach", "everett-1e300", [("params.everett.4.0", 1e300)], ["params.everett", "1e+06"]),
    ("preisach", "offset-nan", [("params.offset", math.nan)], ["params.offset"]),
    ("gpreisach", "nu-1e300", [("params.nu.0", -1e300)], ["params.nu", "1e+06"]),
    ("gpreisach", "offset-huge", [("params.offset", 1e7)], ["params.offset", "1e+06"]),
]


@pytest.mark.parametrize("family, case, edits, fragments", CASES,
                         ids=[f"{family}-{case}" for family, case, _, _ in CASES])
def test_model_file_outside_the_domain_is_one_error_line(cli, good, models, tmp_path, family,
                                                         case, edits, fragments):
    model = json.loads(json.dumps(models[family]))
    for key, value in edits:
        _edit(model, key, value)
    path = tmp_path / f"{family}-{case}.json"
    path.write_text(json.dumps(model))  # NaN and inf as JSON's NaN / Infinity
    assert_model_file_refused(cli, good, path, tmp_path, *fragments)


@pytest.mark.parametrize("family", ["mpl", *SIZES])
def test_the_unedited_models_evaluate_cleanly(cli, good, models, tmp_path, family):
    """The cases above fail for their edit alone: the fitted files lie inside the domains."""
    path = tmp_path / f"{family}.json"
    path.write_text(json.dumps(models[family]))
    run = cli("evaluate", path, good["val"], "--json", tmp_path / "scores.json")
    run.clean()
    assert run.code == 0, run.err
    text = (tmp_path / "scores.json").read_text()
    assert "NaN" not in text and "Infinity" not in text and json.loads(text)
