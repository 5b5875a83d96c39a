"""A family written outside hystkit (the toy plugin folder, tests/plugins/toy_lag), registered
at run time in this process, works in fit, compare, control and stability with no edit anywhere
else: the point of the family protocol. tests/plugins/test_adding_a_family.py runs the same
folder through the entry point in fresh processes."""

from __future__ import annotations

import json

import pytest
from numpy.testing import assert_allclose

from hystkit import control as hc
from hystkit.compensation import load_compensator
from hystkit.io import write_recording
from hystkit.models import register, unregister
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli
from ..plugins.toy_lag.family import LagFamily, LagParams, LagStructure


@pytest.fixture
def toy():
    family = register(LagFamily())
    yield family
    unregister(family.name)


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("toy") / "noise.csv"
    write_recording(simulate_experiment("noise", 1), path)
    return path


def test_toy_family_is_fitted_saved_and_loaded(toy, recording, tmp_path, capsys):
    model = tmp_path / "toy.json"
    code, _out, err = run_cli(capsys, "fit", recording, "--model", "toy-lag", "--out", model)
    assert code == 0, err
    comp = load_compensator(model)
    assert comp.model == "toy-lag" and isinstance(comp.params, LagParams)
    assert json.loads(model.read_text())["model"] == "toy-lag"


def test_toy_family_in_compare(toy, recording, tmp_path, capsys):
    code, out, err = run_cli(capsys, "compare", recording, recording, "--models", "toy-lag,mpl",
                          "--out", tmp_path / "cmp")
    assert code == 0, err
    table = json.loads((tmp_path / "cmp" / "compare.json").read_text())
    assert "toy-lag" in json.dumps(table) and "toy-lag" in out


@pytest.mark.parametrize("scheme", ["direct", "weighting"])
def test_toy_family_in_the_closed_loop(toy, recording, tmp_path, capsys, scheme):
    model = tmp_path / "toy.json"
    run_cli(capsys, "fit", recording, "--model", "toy-lag", "--mode", "inverse", "--out", model)
    slot = "--compensator" if scheme == "direct" else "--model-file"
    code, _out, err = run_cli(capsys, "control", "--scheme", scheme, "--experiment", "sine", slot,
                          model, "--out", tmp_path / "loop")
    assert code == 0, err
    metrics = json.loads((tmp_path / "loop" / "metrics.json").read_text())
    assert metrics["bounded"] and metrics["e_p_max"] < 3e-3


def test_toy_family_blocks_run_compiled_like_the_readable_loop(toy):
    params, structure = LagParams(2.0, 0.8, 0.3, 0.01), LagStructure(0.025)
    models = hc.fit_sensor_models()
    comp = hc.SensorBlock(structure, params, True, 0.0, 1.0, 0.0, 1e-3)
    loop = hc.build_loop("direct", hc.SensorModels(models.sensor, comp, models.model,
                                                   models.sensor_gain))
    r = hc.sine_reference(2000)
    assert_allclose(hc.simulate_loop(loop, r).y, hc.simulate_loop_reference(loop, r).y,
                    rtol=0, atol=1e-12)


def test_toy_family_in_stability(toy, recording, tmp_path, capsys):
    model = tmp_path / "toy.json"
    run_cli(capsys, "fit", recording, "--model", "toy-lag", "--out", model)
    code, out, err = run_cli(capsys, "stability", model)
    assert code == 0, err
    rate = load_compensator(model).params.rate
    # one state, x+ = (1 - rate dt) x + ...: its eigenvalue, exactly
    assert f"max |lambda| {abs(1 - rate * 0.025):.6g}" in out
