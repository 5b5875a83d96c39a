"""The model file's ``reading`` key: how the training data were read (issue 27, item 3).

Optional (a file without it loads, remembering nothing), checked like every field: a bad
value is one InputError naming the file and the key path.
"""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from hystkit.compensation import (
    compensator_from_dict,
    compensator_to_dict,
    fit_compensator,
    load_compensator,
    save_compensator,
)
from hystkit.errors import InputError
from hystkit.io import ReadOptions
from hystkit.sensors import simulate_experiment

READING = ReadOptions(columns={"time": "t_ms", "position": "x_mm", "sensor": "R_ohm"},
                      time_unit="ms", units_row=True, units={"position": "mm"})


@pytest.fixture(scope="module")
def model() -> dict:
    rec = simulate_experiment("sine", seed=1)
    comp = fit_compensator([rec], 1)
    return compensator_to_dict(replace(comp, reading=READING))


def test_the_reading_is_written_and_read_back(model, tmp_path):
    assert model["reading"] == {"time_unit": "ms", "units_row": True,
                                "columns": {"time": "t_ms", "position": "x_mm",
                                            "sensor": "R_ohm"},
                                "units": {"position": "mm"}}
    assert compensator_from_dict(json.loads(json.dumps(model))).reading == READING
    comp = compensator_from_dict(model)
    for suffix in (".json", ".mat"):
        path = save_compensator(comp, tmp_path / f"m{suffix}")
        assert load_compensator(path).reading == READING, suffix


def test_the_default_reading_leaves_out_empty_tables(model, tmp_path):
    comp = replace(compensator_from_dict(model), reading=ReadOptions())
    assert compensator_to_dict(comp)["reading"] == {"time_unit": "s", "units_row": False}
    path = save_compensator(comp, tmp_path / "m.mat")  # no empty struct in MATLAB
    assert load_compensator(path).reading == ReadOptions()


@pytest.mark.parametrize("stored", ["absent", None])
def test_a_file_without_it_loads_remembering_nothing(model, stored):
    d = dict(model)
    if stored == "absent":
        del d["reading"]
    else:
        d["reading"] = stored
    assert compensator_from_dict(d).reading is None


@pytest.mark.parametrize("reading, key, fragment", [
    ("ms", "reading", "must be null or a JSON object"),
    ({"bogus": 1}, "reading.bogus", "unknown key (expected columns, time_unit"),
    ({"time_unit": "h"}, "reading.time_unit", "must be one of s, ms, us, ns, min"),
    ({"time_unit": 1e-3}, "reading.time_unit", "must be one of"),
    ({"units_row": "yes"}, "reading.units_row", "must be true or false"),
    ({"columns": ["t_ms"]}, "reading.columns", "must be a JSON object"),
    ({"columns": {"pos": "x"}}, "reading.columns.pos", "unknown key (expected time, position"),
    ({"columns": {"time": 3}}, "reading.columns.time", "must be a non-empty text"),
    ({"columns": {"time": " "}}, "reading.columns.time", "must be a non-empty text"),
    ({"columns": {"time": "a", "sensor": "a"}}, "reading.columns",
     "time and sensor would both be read from column 'a'"),
    ({"columns": {"position": "sensor", "sensor": "position"}}, "reading.columns",
     "the file's columns crossed"),
    ({"units": {"position": ["mm"]}}, "reading.units.position", "must be a non-empty text"),
    ({"units": {"position": "m" * 1001}}, "reading.units.position", "at most 1000"),
])
def test_a_bad_value_is_refused_naming_the_key(model, reading, key, fragment):
    d = {**model, "reading": reading}
    with pytest.raises(InputError) as info:
        compensator_from_dict(d, source="m.json")
    message = str(info.value)
    assert message.startswith(f"m.json: key {key!r}: "), message
    assert fragment in message and "\n" not in message
