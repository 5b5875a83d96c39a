"""Every field of a model file's band, edited to hostile values: one InputError naming the
key, or a band that still loads and gives finite bounds; never another exception."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from hystkit.compensation import fit_compensator, load_compensator, save_compensator, with_band
from hystkit.errors import InputError
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment

HOSTILE = [None, True, "x", -1, 0, 1e308, -1e308, [], {}, [1, 2], 1.5, 2, 1e-320, 0.5]


@pytest.fixture(scope="module")
def banded(tmp_path_factory):
    train = simulate_experiment("sine", 1)
    comp = with_band(fit_compensator(train, 1, diagnose=False), [train], 1)
    path = save_compensator(comp, tmp_path_factory.mktemp("band") / "m.json")
    return json.loads(path.read_text()), simulate_experiment("sine", 2)


def _edits(d: dict):
    for key in [*d["band"], None]:
        for value in HOSTILE:
            edited = copy.deepcopy(d)
            if key is None:
                edited["band"] = value
            else:
                edited["band"][key] = value
            yield f"band.{key}" if key else "band", edited
    for i in (0, 100, 200):
        for value in HOSTILE:
            edited = copy.deepcopy(d)
            edited["band"]["quantiles"][i] = value
            yield f"band.quantiles[{i}]", edited


def test_hostile_band_fields_are_refused_or_harmless(banded, tmp_path):
    d, rec = banded
    path = tmp_path / "edited.json"
    n = 0
    for where, edited in _edits(d):
        path.write_text(json.dumps(edited))
        n += 1
        try:
            comp = load_compensator(path)
        except InputError as exc:
            assert str(exc).count("\n") == 0 and str(path) in str(exc), where
            continue
        if comp.band is not None:
            _, lower, upper = comp.estimate_with_band(rec)
            assert np.all(np.isfinite(lower)) and np.all(np.isfinite(upper)), where
            assert Stream(comp).step_flagged(float(rec.sensor[0])).lower is not None
    assert n == (len(d["band"]) + 1 + 3) * len(HOSTILE)
