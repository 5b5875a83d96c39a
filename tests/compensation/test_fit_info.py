"""The fit's report (``Compensator.fit_info``) is a frozen record: read like a mapping, never
edited; a later step makes a new one; the model file writes its entries as they were."""

from __future__ import annotations

import json
import pickle
from dataclasses import replace

import pytest

from hystkit.compensation import FitInfo, fit_compensator, load_compensator, save_compensator
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def comp():
    return fit_compensator(simulate_experiment("sine", 1), 1)


def test_the_fitted_report_is_a_frozen_record_read_like_a_mapping(comp):
    info = comp.fit_info
    assert isinstance(info, FitInfo)
    assert info["status"] == info.get("status") == "ok"
    assert {**info}["training_r2"] == info["training_r2"]
    with pytest.raises(TypeError):
        info["band"] = "edited"
    with pytest.raises(TypeError):
        info.entries["band"] = "edited"
    assert "band" not in info


def test_a_later_step_makes_a_new_record_and_leaves_the_fitted_one(comp):
    info = comp.fit_info
    noted = info.with_entries(band="no band", units={"position": "mm"})
    assert noted["band"] == "no band" and list(noted)[:len(info)] == list(info)
    assert "band" not in info and len(noted) == len(info) + 2


def test_the_record_copies_what_it_is_made_from():
    source = {"status": "ok", "notes": ["a"]}
    info = FitInfo(source)
    source["status"] = "collapsed"
    assert info["status"] == "ok"
    plain = info.to_dict()
    plain["notes"].append("b")  # a deep copy: the record's list is not the dict's
    assert info["notes"] == ["a"] and info == {"status": "ok", "notes": ["a"]}


def test_the_model_file_keeps_the_fit_section_key_for_key(comp, tmp_path):
    first, second = tmp_path / "a.json", tmp_path / "b.json"
    save_compensator(comp, first)
    section = json.loads(first.read_text())["fit"]
    assert list(section) == list(comp.fit_info) and section == comp.fit_info
    loaded = load_compensator(first)
    assert isinstance(loaded.fit_info, FitInfo) and loaded.fit_info == comp.fit_info
    save_compensator(loaded, second)
    assert second.read_text() == first.read_text()


def test_a_compensator_pickles_with_its_report(comp):
    back = pickle.loads(pickle.dumps(comp))
    assert isinstance(back.fit_info, FitInfo) and back.fit_info == comp.fit_info


def test_a_dict_given_to_a_compensator_becomes_a_record(comp):
    other = replace(comp, fit_info={"status": "ok"})
    assert isinstance(other.fit_info, FitInfo) and other.fit_info == {"status": "ok"}
    assert FitInfo() == {} and FitInfo({"a": 1}) != {"a": 2}
