"""A family written outside hystkit (the toy plugin folder, tests/plugins/toy_lag), registered
at run time in this process (``register``), is fitted, saved and loaded, runs in both closed-loop
schemes and as compiled blocks, with no edit anywhere else. Compare, select, stability, stream,
report and export of the same folder are checked by tests/plugins/test_adding_a_family.py,
through the entry point in fresh processes."""

from __future__ import annotations

import json

import pytest
from numpy.testing import assert_allclose

from hystkit import control as hc
from hystkit.cli import main
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


@pytest.fixture(scope="module")
def inverse_model(recording, tmp_path_factory):
    """The toy fitted in inverse mode by ``hystkit fit`` in this process (registered at run
    time, not through an entry point)."""
    family = register(LagFamily())
    try:
        path = tmp_path_factory.mktemp("toy-fit") / "toy.json"
        code = main(["fit", str(recording), "--model", "toy-lag", "--mode", "inverse", "--out",
                     str(path)])
    finally:
        unregister(family.name)
    assert code == 0
    return path


def test_toy_family_is_fitted_saved_and_loaded(toy, inverse_model):
    comp = load_compensator(inverse_model)
    assert comp.model == "toy-lag" and isinstance(comp.params, LagParams)
    assert json.loads(inverse_model.read_text())["model"] == "toy-lag"


@pytest.mark.parametrize("scheme", ["direct", "weighting"])
def test_toy_family_in_the_closed_loop(toy, inverse_model, tmp_path, capsys, scheme):
    slot = "--compensator" if scheme == "direct" else "--model-file"
    code, _out, err = run_cli(capsys, "control", "--scheme", scheme, "--experiment", "sine", slot,
                          inverse_model, "--out", tmp_path / "loop")
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
