"""hystkit select: folds use training data only, the winner is an ordinary model file."""

import json

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import DEFAULT_CENTER, evaluate, fit_compensator, load_compensator
from hystkit.compensation._param_vector import flatten_params
from hystkit.errors import FitDivergedError
from hystkit.io import Recording
from hystkit.models import FAMILIES
from hystkit.reports import _select
from hystkit.reports._select import Candidate, folds, select_model
from hystkit.sensors import simulate_experiment


def test_time_folds_partition_one_recording():
    rec = simulate_experiment("sine", 1)
    pairs = folds([rec])
    held = np.concatenate([h.sensor for _, h in pairs])
    np.testing.assert_array_equal(held, rec.sensor)
    for train, h in pairs:
        assert len(train) == 2 and all(t.sensor.size + h.sensor.size < rec.n_samples + 1
                                       for t in train)


def test_leave_one_recording_out():
    recs = [simulate_experiment(n, 1) for n in ("sine", "noise", "chirp")]
    pairs = folds(recs)
    assert [h is r for (_, h), r in zip(pairs, recs, strict=True)] == [True] * 3
    assert all(h not in train for train, h in pairs)


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_every_family_round_trips_through_the_flat_vector(name):
    comp = fit_compensator(simulate_experiment("sine", 1), model=name, diagnose=False)
    theta, rebuild = flatten_params(comp.params)
    # the fitted numbers plus those the family's fit holds fixed (mpl-g's gauge w[0], v_b)
    fixed = FAMILIES[name].fixed_params(comp.structure, comp.params)
    assert theta.size == comp.fit_info["n_params"] + len(fixed)
    assert comp.fit_info["n_params"] > 0
    assert rebuild(theta) == comp.params


def test_select_writes_the_winner_and_its_table(tmp_path, capsys):
    data = tmp_path / "noise.csv"
    assert main(["simulate-sensor", "--excitation", "noise", "--seed", "1", "--out",
                 str(data)]) == 0
    out, report = tmp_path / "best.json", tmp_path / "rep"
    code = main(["select", str(data), "--models", "mpl", "--out", str(out), "--report",
                 str(report)])
    assert code == 0
    summary = json.loads((report / "selection.json").read_text())
    ranking = summary["ranking"]
    assert {r["candidate"] for r in ranking} == {"mpl:1:direct:fit", "mpl:1:inverse:fit",
                                                  "mpl:3:direct:fit", "mpl:3:inverse:fit"}
    scores = [r["cv_r2"] for r in ranking if "error" not in r and not r["guard_failed"]]
    assert scores == sorted(scores, reverse=True)
    winner = summary["winner"]
    assert winner["cv_r2"] == scores[0] and winner["cv_r2"] > winner["cv_linear_r2"]
    comp = load_compensator(out)
    assert (comp.model, comp.structure.n_cells, comp.mode) == ("mpl", winner["size"],
                                                             winner["mode"])
    # the winner also holds on a recording select never saw
    assert evaluate(comp, simulate_experiment("noise", 2))["r2"] > 0.95
    assert (report / "selection.csv").is_file() and (report / "selection.png").is_file()
    assert main(["select", str(data), "--models", "mpl", "--out", str(out), "--report",
                 str(report)]) == 2  # exists: needs --force
    capsys.readouterr()


def test_a_rest_block_trains_but_is_not_scored():
    rec = simulate_experiment("sine", 1)
    still = rec.position.copy()
    still[: rec.n_samples // 3 + 1] = 0.0  # the first block is at rest
    pairs = folds([Recording(time=rec.time, sensor=rec.sensor, position=still)])
    assert len(pairs) == 2
    assert all(np.ptp(held.position) > 0 for _, held in pairs)
    assert all(len(train) == 2 for train, _ in pairs)


def test_a_winner_whose_refit_fails_gives_way_to_the_next(monkeypatch):
    rec = simulate_experiment("sine", 1)
    cands = [Candidate("mpl", 1, "direct", DEFAULT_CENTER),
             Candidate("bobbio", 10, "direct", DEFAULT_CENTER)]
    first, second = select_model([rec], cands)["ranking"]
    real_fit = _select.fit_compensator

    def refit_of_the_first_fails(recordings, size, **kw):
        # the fold fits pass diagnose=False; the refit on all recordings does not
        if "diagnose" not in kw and kw["model"] == first["model"]:
            raise FitDivergedError("diverged on purpose")
        return real_fit(recordings, size, **kw)

    monkeypatch.setattr(_select, "fit_compensator", refit_of_the_first_fails)
    result = select_model([rec], cands)
    assert result["ranking"][0]["error_final"] == "diverged on purpose"
    assert result["winner"]["candidate"] == second["candidate"]
    assert result["compensator"].model == second["model"]
