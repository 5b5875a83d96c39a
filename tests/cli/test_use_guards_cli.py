"""Use-time guards on the command line: flags, counts, non-finite estimates, fit exit code."""

import json
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import hystkit.compensation._compensator as compensator
import hystkit.compensation._fitting as fitting
from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.io import write_recording
from hystkit.models import get_family
from hystkit.models.mpl import MplParams
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def decay_model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("guards")
    comp = fit_compensator(simulate_experiment("decay", 1), 1, diagnose=False)
    return comp, save_compensator(comp, folder / "decay.json")


def test_compensate_flags_samples_outside_training(decay_model, tmp_path, capsys):
    """A decay-trained (2 mm) compensator on a 3 mm sine: flags per sample, counts in JSON."""
    comp, model = decay_model
    sine = simulate_experiment("sine", 2)
    data = write_recording(sine, tmp_path / "sine.csv")
    out = tmp_path / "out.csv"
    assert main(["compensate", str(model), str(data), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "outside the sensor range" in err
    table = pd.read_csv(out)
    s = comp.normalised_sensor(sine.sensor)
    lo, hi = comp.training_range
    pad = 0.05 * (hi - lo)
    np.testing.assert_array_equal(table["sensor_outside"], (s < lo - pad) | (s > hi + pad))
    assert main(["evaluate", str(model), str(data), "--json", str(tmp_path / "e.json")]) == 0
    scores = json.loads((tmp_path / "e.json").read_text())
    assert scores["n_sensor_outside"] == int(table["sensor_outside"].sum()) > 0
    assert scores["n_estimate_outside"] == int(table["estimate_outside"].sum())


def _patched(monkeypatch, **overrides):
    """The mpl family with some of its functions replaced (a constructed bad model)."""
    real = get_family("mpl")
    fake = SimpleNamespace(**{k: getattr(real, k) for k in (
        "name", "title", "default_size", "size_help", "make_structure", "simulate", "invert",
        "no_inverse_reason", "fit", "reductions")})
    for key, value in overrides.items():
        setattr(fake, key, value)
    for module in (compensator, fitting):
        monkeypatch.setattr(module, "get_family", lambda name: fake)
    return real


def test_non_finite_estimate_is_an_error_not_output(decay_model, tmp_path, capsys,
                                                    monkeypatch):
    _comp, model = decay_model
    real = get_family("mpl")

    def nan_after_100(structure, params, u, x0=None):
        y, x = real.simulate(structure, params, u, x0)
        return np.where(np.arange(y.size) >= 100, np.nan, y), x

    _patched(monkeypatch, simulate=nan_after_100)
    data = write_recording(simulate_experiment("decay", 2), tmp_path / "d.csv")
    out = tmp_path / "out.csv"
    assert main(["compensate", str(model), str(data), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "sample 100" in err and "not finite" in err
    assert not out.exists()


def test_fit_that_collapses_exits_non_zero(tmp_path, capsys, monkeypatch):
    """A constructed collapsed fit (all output weights zero) is reported, exit code 3."""
    real = get_family("mpl")

    def collapsed_fit(u, y, structure, **kwargs):
        result = real.fit(u, y, structure, **kwargs)
        flat = MplParams(i_s=result.params.i_s, v_t=result.params.v_t,
                         w=np.zeros(structure.n_cells + 1), v_b=0.0)
        return replace(result, params=flat)

    _patched(monkeypatch, fit=collapsed_fit)
    data = write_recording(simulate_experiment("sine", 1), tmp_path / "sine.csv")
    code = main(["fit", str(data), "--cells", "1", "--out", str(tmp_path / "m.json")])
    err = capsys.readouterr().err
    assert code == 3 and "hystkit: fit collapsed" in err and "do not use it" in err
    info = json.loads((tmp_path / "m.json").read_text())["fit"]
    assert info["status"] == "collapsed"
