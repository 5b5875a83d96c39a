"""A labelled corpus for the verdicts (issue 24): good fits come out ``ok`` with exit 0 and stay
usable on another run; bad cases never come out ``ok``. Both directions, through the command
line as a user meets them.

A case is *good* when the model, fitted with default options, also beats its straight line on
a run it was not fitted on (the second half of each good case checks exactly that); *bad*
cases are built so that no model should be trusted on them.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hystkit.cli import main
from hystkit.cli._common import GUARD_EXIT
from hystkit.datasets import load_excerpt
from hystkit.io import Recording
from hystkit.models import FAMILIES
from hystkit.sensors import simulate_experiment


def _write(rec: Recording, path: Path) -> Path:
    np.savetxt(path, np.column_stack([rec.time, rec.position, rec.sensor]), delimiter=",",
               header="time,position,sensor", comments="")
    return path


def _replace(rec: Recording, name: str, **columns) -> Recording:
    fields = {"time": rec.time, "sensor": rec.sensor, "position": rec.position, **columns}
    return Recording(**fields, source=name)


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("corpus")
    sine1, sine2 = simulate_experiment("sine", 1), simulate_experiment("sine", 2)
    decay = simulate_experiment("decay", 1)
    tail = slice(2 * decay.n_samples // 3, None)  # the decay's last third: a small amplitude
    rng = np.random.default_rng(3)
    recs = {
        "sine1": sine1, "sine2": sine2,
        "noise2": simulate_experiment("noise", 2), "chirp2": simulate_experiment("chirp", 2),
        "ident": load_excerpt("piezo_micromanipulator", "identification").to_recording(),
        "test": load_excerpt("piezo_micromanipulator", "test_uncompensated").to_recording(),
        # bad data
        "noise_only": _replace(sine1, "noise-only", sensor=rng.normal(size=sine1.n_samples)),
        "unrelated": _replace(sine1, "unrelated", position=np.convolve(
            rng.normal(size=sine1.n_samples), np.ones(40) / 40, "same")),
        "swapped": _replace(sine2, "swapped", sensor=sine2.position, position=sine2.sensor),
        "sine1_swapped": _replace(sine1, "sine1 swapped", sensor=sine1.position,
                                  position=sine1.sensor),
        "flipped": _replace(sine2, "flipped", sensor=-sine2.sensor),
        "short": _replace(sine1, "short", time=sine1.time[:150], sensor=sine1.sensor[:150],
                          position=sine1.position[:150]),
        "decay_tail": _replace(decay, "decay tail", time=decay.time[tail] - decay.time[tail][0],
                               sensor=decay.sensor[tail], position=decay.position[tail]),
    }
    recs["ident_swapped"] = _replace(recs["ident"], "ident swapped",
                                     sensor=recs["ident"].position,
                                     position=recs["ident"].sensor)
    return {name: _write(rec, folder / f"{name}.csv") for name, rec in recs.items()}


def _fit(data, tmp_path, train, *options) -> tuple[int, Path]:
    model = tmp_path / "model.json"
    return main(["fit", str(data[train]), "--out", str(model), *options]), model


def _evaluate(data, tmp_path, model, test) -> tuple[int, dict]:
    scores = tmp_path / "scores.json"
    code = main(["evaluate", str(model), str(data[test]), "--json", str(scores)])
    return code, json.loads(scores.read_text())


# Not good on the virtual sensor, as the verdicts say and another run confirms: the direct
# Bouc-Wen, Bobbio and Chua models are its straight line, the inverse ladder diverges.
NOT_GOOD_ON_SINE = {("boucwen", "direct"), ("bobbio", "direct"), ("chua", "direct"),
                    ("ladder", "inverse")}
GOOD = [(name, mode, "sine1", "sine2", ()) for name in sorted(FAMILIES)
        for mode in ("direct", "inverse")
        if (mode == "direct" or FAMILIES[name].has_inverse)
        and (name, mode) not in NOT_GOOD_ON_SINE]
GOOD += [("mpl", "direct", "sine1", "sine2", ("--cells", "3")),
         ("mpl", "direct", "sine1", "sine2", ("--cells", "2")),
         ("chua", "inverse", "ident", "test", ()), ("ladder", "direct", "ident", "test", ()),
         ("ladder", "inverse", "ident", "test", ()), ("pl", "direct", "ident", "test", ()),
         ("bobbio", "inverse", "ident", "test", ()), ("pi", "direct", "ident", "test", ()),
         ("preisach", "direct", "ident", "test", ())]


@pytest.mark.parametrize(("model", "mode", "train", "test", "options"), GOOD,
                         ids=[f"{m}-{mode}-{tr}{''.join(o)}" for m, mode, tr, _, o in GOOD])
def test_a_good_fit_is_ok_and_usable_on_another_run(data, tmp_path, capsys, model, mode,
                                                     train, test, options):
    code, path = _fit(data, tmp_path, train, "--model", model, "--mode", mode, *options)
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "status: ok" in out.out
    code, scores = _evaluate(data, tmp_path, path, test)
    err = capsys.readouterr().err
    assert code == 0 and scores["verdict"] == "ok", err
    assert scores["r2"] > scores["linear_r2"]


def test_the_good_corpus_covers_every_family_but_bouc_wen():
    # Bouc-Wen fits its own benchmark (tests/datasets), not these sensors: on both it is
    # the straight line (worse than it by 1e-4 in training), which the verdict says
    assert {m for m, *_ in GOOD} == set(FAMILIES) - {"boucwen"}
    assert len(GOOD) >= 20


def test_bad_noise_only_sensor(data, tmp_path, capsys):
    for model in ("mpl", "pi", "preisach", "mpl-poly"):
        code, _ = _fit(data, tmp_path, "noise_only", "--model", model, "--force")
        err = capsys.readouterr().err
        assert code == GUARD_EXIT and "no signal" in err, (model, err)


def test_bad_position_unrelated_to_the_sensor(data, tmp_path, capsys):
    code, _ = _fit(data, tmp_path, "unrelated", "--model", "mpl")
    assert code == GUARD_EXIT and "no signal" in capsys.readouterr().err


def test_bad_recording_too_short_for_its_size(data, tmp_path, capsys):
    code, model = _fit(data, tmp_path, "short", "--model", "preisach")
    err = capsys.readouterr().err
    assert code == 2 and "samples" in err and not model.exists()


@pytest.mark.parametrize(("test", "cells", "status"), [
    ("swapped", "1", "no_signal"),  # sensor and position columns swapped in the scored file
    ("flipped", "1", "worse_than_line"),  # the sensor wired the other way round
    ("noise2", "3", "worse_than_line"),  # far below its line on another excitation
    ("chirp2", "1", "worse_than_line"),
])
def test_bad_use_is_never_ok(data, tmp_path, capsys, test, cells, status):
    code, model = _fit(data, tmp_path, "sine1", "--cells", cells)
    assert code == 0
    capsys.readouterr()
    code, scores = _evaluate(data, tmp_path, model, test)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == GUARD_EXIT and scores["verdict"] == status
    assert err[-1].startswith(f"hystkit: evaluate: {status.replace('_', ' ')}")


@pytest.mark.parametrize("train", ["sine1", "ident"])
def test_bad_columns_read_crossed(data, tmp_path, capsys, train):
    """--columns position=sensor,sensor=position on a file that names them: refused in one
    line naming both columns, before any fit (the swapped fit alone would look fine)."""
    code, model = _fit(data, tmp_path, train, "--columns", "position=sensor,sensor=position")
    err = capsys.readouterr().err
    assert code == 2 and not model.exists()
    assert len(err.splitlines()) == 1
    assert "position would be read from column 'sensor' and sensor from column 'position'" in err


@pytest.mark.parametrize(("train", "test", "model"), [
    ("sine1_swapped", "sine2", "mpl"), ("ident_swapped", "test", "mpl"),
    ("ident_swapped", "test", "pi"),
])
def test_bad_fit_on_swapped_data_used_as_laid_out(data, tmp_path, capsys, train, test, model):
    """A file whose header is right and whose data are swapped fits as well as the right
    layout (it is the forward model, a layout hystkit supports: datasets export --role
    forward), so the fit cannot tell; used on the next run as laid out, it is not ok: its
    estimate is in the sensor's units (R² near 0 on the sine, where no signal and worse than
    line differ by 1e-3; about -1e6 on the piezo)."""
    code, path = _fit(data, tmp_path, train, "--model", model)
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    code, scores = _evaluate(data, tmp_path, path, test)
    assert code == GUARD_EXIT and scores["verdict"] in ("no_signal", "worse_than_line")
    assert scores["r2"] < 0.1
    assert capsys.readouterr().err.strip().splitlines()[-1].startswith(
        f"hystkit: evaluate: {scores['verdict'].replace('_', ' ')}")


def test_bad_extrapolation_far_beyond_the_training_range(data, tmp_path, capsys):
    """Trained on the decay's small last third, used on a full-amplitude sine: most samples
    lie far outside what the model has seen; however it scores there, it is not 'ok'."""
    code, model = _fit(data, tmp_path, "decay_tail", "--model", "mpl")
    assert code == 0
    capsys.readouterr()
    code, scores = _evaluate(data, tmp_path, model, "sine2")
    assert code == GUARD_EXIT and scores["verdict"] == "extrapolated"
    assert "far outside" in capsys.readouterr().err


def test_bad_select_on_a_noise_only_sensor(data, tmp_path, capsys):
    out = tmp_path / "best.json"
    code = main(["select", str(data["noise_only"]), "--models", "mpl,pi", "--out", str(out)])
    assert code == GUARD_EXIT and not out.exists()
    assert "no usable model" in capsys.readouterr().err


@pytest.mark.parametrize("cells", [1, 2, 3])
@pytest.mark.parametrize("excitation", ["sine", "decay", "chirp", "noise"])
def test_default_mpl_fits_end_ok(excitation, cells):
    """The default mPL fit of the virtual sensor's recordings, 1 to 3 cells, is usable (a
    3-cell fit on the sine used to stop 'on bounds' with its slowest cell at the rate floor:
    over 200 s that cell integrates, and only w G is identified)."""
    from hystkit.compensation import fit_compensator

    info = fit_compensator(simulate_experiment(excitation, 1), cells, diagnose=False).fit_info
    assert info["status"] == "ok", info["status_message"]
    assert info["converged"] and info["training_r2"] > info["training_linear_r2"]
