"""Checks of fitting data before any fit, and finite outputs of a compensator."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from hystkit.compensation import check_fitting_data, evaluate, fit_compensator
from hystkit.compensation._training_checks import count_fitted
from hystkit.errors import FitDivergedError, InputError
from hystkit.io import Recording
from hystkit.models import get_family

DT = 0.025


def _rec(position, sensor, source="r.csv") -> Recording:
    n = len(position)
    return Recording(time=np.arange(n) * DT, position=position, sensor=sensor, source=source)


def _sine(n=400) -> np.ndarray:
    return np.sin(np.linspace(0, 4 * np.pi, n))


def test_a_moving_recording_passes():
    check_fitting_data([_rec(_sine(), 0.1 * _sine())])


@pytest.mark.parametrize("position, sensor, match", [
    (np.full(400, 2.0), _sine(), "'position' is constant"),
    (_sine(), np.full(400, -1.0), "'sensor' is constant"),
    (1e90 + 1e-3 * _sine(), _sine(), "'position' is constant"),  # rounds to one value
    (_sine(), 1e14 + _sine(), "'sensor' varies by only"),
    (np.eye(1, 400, 200)[0], _sine(), "'position' leaves its resting level in only 1 of 400"),
])
def test_degenerate_columns_are_refused(position, sensor, match):
    with pytest.raises(InputError, match=match):
        check_fitting_data([_rec(position, sensor)])


def test_parameters_are_counted_before_the_fit():
    family = get_family("mpl")
    assert count_fitted(family, family.make_structure(DT, 2)) == 8  # 3 N + 2
    # a family without a documented domain: counted after its fit instead
    undocumented = SimpleNamespace(random_params=lambda *a: (_ for _ in ()).throw(
        NotImplementedError("no domain")))
    assert count_fitted(undocumented, None) is None


def test_too_short_for_the_family_is_refused_before_fitting(monkeypatch):
    """The samples-per-parameter check runs before the family's fit is ever called."""
    family = get_family("preisach")
    monkeypatch.setattr(type(family), "fit", lambda *a, **k: pytest.fail("fit was called"))
    with pytest.raises(InputError, match=r"per parameter, preisach has \d+"):
        fit_compensator(_rec(_sine(100), _sine(100)), model="preisach", diagnose=False)


def test_scores_stay_json_safe_on_absurd_positions():
    """Positions at the recordings' magnitude limit (1e100) and a constant one: every score is
    a finite number or None."""
    rec = _rec(_sine(), 0.1 * _sine())
    comp = fit_compensator(rec, 1, diagnose=False)
    for position in (1e100 * _sine(), np.zeros(400)):
        scores = evaluate(comp, _rec(position, 0.1 * _sine(), source="odd.csv"))
        json.dumps(scores, allow_nan=False)  # no inf or NaN anywhere


def test_a_run_away_estimate_is_refused():
    rec = _rec(_sine(), 0.1 * _sine())
    comp = fit_compensator(rec, 1, diagnose=False)
    wild = _rec(_sine(), 1e9 * _sine(), source="wild.csv")
    with pytest.raises(FitDivergedError, match=r"wild.csv: column 'sensor', sample \d+: .*beyond"):
        comp.estimate(wild)
