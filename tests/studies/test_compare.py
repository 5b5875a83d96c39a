"""compare / generalize and the measured table 2.1 properties."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.io import Recording
from hystkit.parallel import SerialExecutor
from hystkit.sensors import simulate_experiment
from hystkit.studies._compare import compare_models
from hystkit.studies._generalize import generalization_matrix
from hystkit.studies._properties import measure_properties


def _family(simulate) -> SimpleNamespace:
    """Just what measure_properties uses of a family."""
    return SimpleNamespace(name="toy", simulate=simulate)


def _play(structure, params, u, x0=None, r=0.3):
    y, out = 0.0 if x0 is None else x0, np.empty_like(u)
    for i, v in enumerate(u):
        y = max(v - r, min(v + r, y))
        out[i] = y
    return out, y


def _lag(structure, params, u, x0=None, a=0.05):
    x, out = u[0] if x0 is None else x0, np.empty_like(u)
    for i, v in enumerate(u):
        out[i] = x
        x += a * (v - x)
    return out, x


def test_play_operator_is_rate_independent_with_return_point_memory():
    props = measure_properties(_family(_play), None, None)
    assert not props["rate_dependent"] and props["rate_difference"] < 1e-12
    assert props["return_point_memory"] and props["minor_loops_close"]
    assert props["major_loop_area_pct"] > 10  # a play of radius 0.3 on +-1: a fat loop


def test_first_order_lag_is_rate_dependent_without_return_point_memory():
    props = measure_properties(_family(_lag), None, None)
    assert props["rate_dependent"]
    assert props["return_point_memory"] is False  # the minor loop leaves a trace


def test_static_map_has_no_loop_so_memory_is_undetermined():
    props = measure_properties(_family(lambda s, p, u, x0=None: (np.tanh(u), None)), None, None)
    assert not props["rate_dependent"]
    assert props["return_point_memory"] is None and props["minor_loops_close"] is None


@pytest.fixture(scope="module")
def noise():
    return simulate_experiment("noise", 1), simulate_experiment("noise", 2)


def test_compare_mpl_on_the_virtual_sensor(noise):
    table = compare_models(*noise, ["mpl"], {"mpl": 2})
    m = table["mpl"]
    assert m["n_params"] == 8  # 3N + 2
    assert m["r2_forward"] > 0.95 and m["r2_direct"] > m["linear_r2"]
    assert m["r2_compensated"] is None or m["r2_compensated"] > m["linear_r2"]


def test_generalization_matrix_shape():
    names = ("sine", "noise")
    out = generalization_matrix({n: simulate_experiment(n, 1) for n in names},
                                {n: simulate_experiment(n, 2) for n in names}, ["mpl"])
    grid = out["mpl"]["r2"]
    assert set(grid) == {"sine", "noise"} and all(set(row) == {"sine", "noise"}
                                                  for row in grid.values())
    assert grid["noise"]["sine"] > out["mpl"]["linear_r2"]["noise"]["sine"]


def test_compare_cli_writes_json(tmp_path, capsys):
    f, v = tmp_path / "f.csv", tmp_path / "v.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "1", "--out", str(f)]) == 0
    assert main(["simulate-sensor", "--excitation", "sine", "--seed", "2", "--out", str(v)]) == 0
    assert main(["compare", str(f), str(v), "--models", "mpl", "--out", str(tmp_path)]) == 0
    table = json.loads((tmp_path / "compare.json").read_text())
    assert {"n_params", "fit_seconds", "r2_forward", "r2_compensated", "e_rms_pct",
            "e_max_pct"} <= set(table["mpl"])
    assert main(["compare", str(f), str(v), "--models", "nope"]) == 2
    assert "unknown model(s) nope" in capsys.readouterr().err


class _Recorded(SerialExecutor):
    """Runs the pieces here, as the serial executor, and keeps them; claims `n_workers`."""

    def __init__(self, n_workers: int):
        self.n_workers, self.pieces = n_workers, []

    def map(self, func, items, **kwargs):
        self.pieces.append(list(items))
        return super().map(func, items, **kwargs)


def test_generalize_pieces_whole_models_unless_one_outweighs_a_worker():
    def head(rec: Recording) -> Recording:  # 50 s: the fits take a moment
        return Recording(time=rec.time[:2000], sensor=rec.sensor[:2000],
                         position=rec.position[:2000], source=rec.source)

    train = {n: head(simulate_experiment(n, 1)) for n in ("sine", "noise")}
    test = {n: head(simulate_experiment(n, 2)) for n in ("noise", "sine")}
    models = ["mpl", "pi", "bobbio", "mpl-g"]
    runs = {n: _Recorded(n) for n in (1, 2, 8)}
    matrices = {n: generalization_matrix(train, test, models, {"mpl": 1}, executor=ex)
                for n, ex in runs.items()}
    # 1 or 2 workers: no model holds half the estimated work, so one piece per model (a
    # worker loads its kernels once); 8 workers: each model's share is over 1/8, so one piece
    # per model and training recording
    for n in (1, 2):
        assert runs[n].pieces == [[(m, 1 if m == "mpl" else None, ("sine", "noise"))
                                   for m in models]]
    assert runs[8].pieces == [[(m, 1 if m == "mpl" else None, (t,)) for m in models
                               for t in ("sine", "noise")]]
    # the same matrix, to the order of every key, whichever way the work was cut
    assert json.dumps(matrices[1]) == json.dumps(matrices[2]) == json.dumps(matrices[8])
    assert list(matrices[8]["pi"]["r2"]["noise"]) == ["noise", "sine"]
