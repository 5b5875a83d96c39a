"""hystkit select: folds use training data only, the winner is an ordinary model file."""

import json

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.compensation import DEFAULT_CENTER, evaluate, fit_compensator, load_compensator
from hystkit.compensation._folds import EXTRAPOLATION_NOTE, folds, protocol
from hystkit.compensation._param_vector import flatten_params
from hystkit.errors import FitDivergedError
from hystkit.io import Recording
from hystkit.models import FAMILIES
from hystkit.sensors import simulate_experiment
from hystkit.studies import _select
from hystkit.studies._select import Candidate, select_model


def test_interleaved_folds_partition_one_recording_and_cover_its_range():
    rec = simulate_experiment("sine", 1)
    fold_list = folds([rec])
    assert len(fold_list) == 3
    held = np.array([f.held for f in fold_list])
    np.testing.assert_array_equal(held.sum(axis=0), np.ones(rec.n_samples))  # a partition
    for f in fold_list:
        assert f.scored is rec and f.train == [rec]
        assert f.n_train == rec.n_samples - int(f.held.sum())
        # held-out pieces are spread over the run: their positions lie inside the range the
        # fold is fitted on (a block per fold would not: it would score extrapolation)
        assert f.extrapolated() < EXTRAPOLATION_NOTE
        assert np.count_nonzero(np.diff(f.held.astype(int)) == 1) >= 3


def test_leave_one_recording_out():
    recs = [simulate_experiment(n, 1) for n in ("sine", "noise", "chirp")]
    fold_list = folds(recs)
    assert [f.scored is r for f, r in zip(fold_list, recs, strict=True)] == [True] * 3
    assert all(f.held is None and f.scored not in f.train and len(f.train) == 2
               for f in fold_list)
    assert protocol(recs) == "left-out recording"
    assert protocol(recs[:1]) == "interleaved cycles of the training recording"


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
    # every deployable centring by default
    assert {r["candidate"] for r in ranking} == {f"mpl:{n}:{mode}:{center}" for n in (1, 3)
                                                 for mode in ("direct", "inverse")
                                                 for center in ("fit", "tare", "track")}
    scores = [r["cv_r2"] for r in ranking if "error" not in r and not r["guard_failed"]
              and r["verdict"] == "ok"]
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


def test_a_rest_piece_trains_but_is_not_scored():
    rec = simulate_experiment("sine", 1)
    still = rec.position.copy()
    held = folds([rec])[0].held
    still[held] = 0.0  # every piece of the first fold is at rest
    fold_list = folds([Recording(time=rec.time, sensor=rec.sensor, position=still)])
    assert len(fold_list) == 2
    assert all(np.ptp(still[f.held]) > 0 and not np.any(f.held & held) for f in fold_list)


def test_a_winner_whose_refit_fails_gives_way_to_the_next(monkeypatch):
    rec = simulate_experiment("sine", 1)
    cands = [Candidate("mpl", 1, "direct", DEFAULT_CENTER),
             Candidate("pi", 10, "direct", DEFAULT_CENTER)]
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
