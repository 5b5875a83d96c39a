"""A family written in one module, registered at run time, works in fit, compare, control and
stability with no edit anywhere else: the point of the family protocol."""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest
from numba import njit
from numpy.testing import assert_allclose

from hystkit import control as hc
from hystkit.compensation import load_compensator
from hystkit.identification import FitResult, check_fit_data
from hystkit.io import write_recording
from hystkit.models import Block, Family, Record, register, unregister
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli

RATES = np.geomspace(0.05, 20.0, 25)  # candidate lag rates [1/s] for the grid search


@dataclass(frozen=True)
class LagStructure(Record):
    dt: float = 0.025


@dataclass(frozen=True, eq=False)
class LagParams(Record):
    rate: float
    w0: float
    w1: float
    bias: float = 0.0


@njit
def _lag_forward(body, x, xn, off, u):
    xn[off] = x[off] + body[0] * body[4] * (u - x[off])
    return body[1] * u + body[2] * x[off] + body[3]


@njit
def _lag_inverse(body, x, xn, off, y):
    u = (y - body[2] * x[off] - body[3]) / body[1]
    xn[off] = x[off] + body[0] * body[4] * (u - x[off])
    return u


class LagFamily(Family):
    """y = w0 u + w1 x + bias with a first-order lag x' = rate (u - x): a toy, not hysteresis."""

    name = "toy-lag"
    title = "first-order lag (a toy family defined in a test)"
    size_help = "ignored"
    Structure = LagStructure
    Params = LagParams

    def make_structure(self, dt, size, **options):
        return LagStructure(dt)

    def rest_state(self, structure, params, value, inverse=False):
        if inverse:
            value = (value - params.bias) / (params.w0 + params.w1)
        return np.array([float(value)])

    def step(self, structure, params, x, u):
        y = params.w0 * u + params.w1 * x[0] + params.bias
        return float(y), np.array([x[0] + params.rate * structure.dt * (u - x[0])])

    def invert_step(self, structure, params, x, y):
        u = (y - params.w1 * x[0] - params.bias) / params.w0
        return float(u), np.array([x[0] + params.rate * structure.dt * (u - x[0])])

    def run_cli(self, step, structure, params, u, x0, inverse):
        u = np.asarray(u, dtype=float)
        x = self.rest_state(structure, params, float(u[0]), inverse) if x0 is None else x0
        y = np.empty_like(u)
        for k, u_k in enumerate(u):
            y[k], x = step(structure, params, x, u_k)
        return y, x

    def simulate(self, structure, params, u, x0=None):
        return self.run_cli(self.step, structure, params, u, x0, False)

    def invert(self, structure, params, y, x0=None):
        return self.run_cli(self.invert_step, structure, params, y, x0, True)

    def fit(self, u, y, structure, *, accept=None, accept_reason="", **options):
        u, y = check_fit_data(u, y)
        best = None
        for rate in RATES:
            lag = self.simulate(structure, LagParams(rate, 0.0, 1.0), u)[0]
            coef = np.linalg.lstsq(np.column_stack([u, lag, np.ones_like(u)]), y, rcond=None)[0]
            x = LagParams(rate, *coef)
            cost = float(np.sum((self.simulate(structure, x, u)[0] - y) ** 2))
            if best is None or cost < best[0]:
                best = (cost, x)
        return FitResult(structure=structure, params=best[1], cost=best[0],
                         n_evaluations=RATES.size, seconds=0.0, converged=True,
                         message="grid search", n_starts=RATES.size)

    def block(self, structure, params, inverse=False):
        body = np.array([params.rate, params.w0, params.w1, params.bias, structure.dt])
        return Block(_lag_inverse if inverse else _lag_forward, body, 1)


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
