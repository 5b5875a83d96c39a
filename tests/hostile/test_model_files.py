"""Hostile model files: every problem is one error line naming the file and the key path.

Each case mutates the valid 1-cell mPL model of the ``good`` fixture and runs ``evaluate``
(with ``--json``) and ``compensate`` on it: exit 2, one ``hystkit: error:`` line naming the
file (and the key where there is one), no traceback, nothing written.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

import pytest

from hystkit.compensation._model_checks import MAX_MODEL_BYTES

from .conftest import snapshot


def _set(path: str, value: object) -> Callable[[dict], None]:
    """A mutation setting ``a.b.c`` (list items as integers) to `value`."""
    def mutate(d: dict) -> None:
        *parents, last = path.split(".")
        for key in parents:
            d = d[int(key)] if isinstance(d, list) else d[key]
        if isinstance(d, list):
            d[int(last)] = value
        else:
            d[last] = value
    return mutate


def _drop(path: str) -> Callable[[dict], None]:
    def mutate(d: dict) -> None:
        *parents, last = path.split(".")
        for key in parents:
            d = d[key]
        del d[last]
    return mutate


# (case id, mutation of the model dict, fragments the error line must hold)
CONTENT_CASES = [
    ("param-string", _set("params.v_b", "abc"), ["params.v_b", "number"]),
    ("param-list-string", _set("params.w.1", "abc"), ["params.w[1]"]),
    ("param-nan", _set("params.i_s", [float("nan")]), ["params.i_s[0]", "finite"]),
    ("param-inf", _set("params.v_b", float("inf")), ["params.v_b", "finite"]),
    ("param-missing", _drop("params.w"), ["params", "w"]),
    ("param-wrong-length", _set("params.w", [1.0]), ["params"]),
    ("param-bool", _set("params.v_b", True), ["params.v_b"]),
    ("structure-huge", _set("structure.n_cells", 20_000_000), ["structure.n_cells", "limit"]),
    ("structure-string", _set("structure.n_cells", "abc"), ["structure.n_cells"]),
    ("structure-unknown-key", _set("structure.bogus", 1), ["structure"]),
    ("structure-not-object", _set("structure", [1, 2]), ["structure", "object"]),
    ("scale-zero", _set("normalisation.sensor_scale", 0.0), ["normalisation.sensor_scale"]),
    ("scale-string", _set("normalisation.position_scale", "x"),
     ["normalisation.position_scale"]),
    ("baseline-missing", _drop("baseline.slope"), ["baseline"]),
    ("range-short", _set("training_range", [1.0]), ["training_range"]),
    ("range-nan", _set("position_range", [0.0, float("nan")]), ["position_range[1]"]),
    ("polarity-string", _set("polarity", "up"), ["polarity"]),
    ("polarity-two", _set("polarity", 2.0), ["key 'polarity'"]),
    ("tare-negative", _set("tare_seconds", -1.0), ["key 'tare_seconds'"]),
    ("range-reversed", _set("training_range", [0.5, -0.5]), ["key 'training_range'"]),
    ("unknown-family", _set("model", "nope"), ["model", "nope"]),
    ("model-not-string", _set("model", 3), ["model", "string"]),
    ("unknown-mode", _set("mode", "sideways"), ["mode"]),
    ("future-schema", _set("schema_version", 99), ["schema_version", "newer"]),
    ("no-schema", _drop("schema"), ["not a hystkit compensator"]),
    ("missing-params", _drop("params"), ["params", "missing"]),
    ("fit-not-object", _set("fit", [1]), ["fit"]),
    ("boucwen-substeps", lambda d: d.update(
        model="boucwen", structure={"dt": d["dt"], "substeps": 10**12},
        params={"m": 1.0, "c": 1.0, "k": 1.0, "alpha": 0.5, "beta": 1.0, "gamma": 0.5,
                "nu": 1.0}), ["structure.substeps", "limit"]),
    ("huge-int", _set("params.v_b", 10**400), ["params.v_b", "finite"]),
]


def _write_model(good: dict[str, Path], folder: Path, mutate: Callable[[dict], None]) -> Path:
    d = json.loads(good["model"].read_text())
    mutate(d)
    path = folder / "bad.json"
    path.write_text(json.dumps(d))  # NaN/inf written as JSON's NaN/Infinity extensions
    return path


def _assert_refused(cli, good, folder: Path, model: Path, fragments: list) -> None:
    before = snapshot(folder)
    for argv in (["evaluate", model, good["val"], "--json", folder / "scores.json"],
                 ["compensate", model, good["val"], "--out", folder / "out.csv"]):
        run = cli(*argv)
        assert run.code == 2, run.err
        run.error_line(model.name, *fragments)
        assert snapshot(folder) == before


@pytest.mark.parametrize("mutate, fragments", [c[1:] for c in CONTENT_CASES],
                         ids=[c[0] for c in CONTENT_CASES])
def test_bad_contents(cli, good, tmp_path, mutate, fragments):
    model = _write_model(good, tmp_path, mutate)
    _assert_refused(cli, good, tmp_path, model, fragments)


FILE_CASES = [
    ("invalid-json", lambda p: p.write_text('{"schema": "hystkit.compensator", '),
     ["not JSON"]),
    ("empty", lambda p: p.write_bytes(b""), ["not JSON"]),
    ("binary", lambda p: p.write_bytes(bytes(range(256)) * 4), ["cannot read"]),
    ("json-array", lambda p: p.write_text("[1, 2, 3]"), ["not a hystkit compensator"]),
    ("deep-nesting", lambda p: p.write_text("[" * 200_000 + "]" * 200_000), ["nested"]),
    ("folder", lambda p: p.mkdir(), ["folder"]),
    ("huge", lambda p: (p.touch(), os.truncate(p, MAX_MODEL_BYTES + 1)), ["larger than"]),
]


@pytest.mark.parametrize("make, fragments", [c[1:] for c in FILE_CASES],
                         ids=[c[0] for c in FILE_CASES])
def test_bad_files(cli, good, tmp_path, make, fragments):
    model = tmp_path / "bad.json"
    make(model)
    _assert_refused(cli, good, tmp_path, model, fragments)


def test_missing_file(cli, good, tmp_path):
    _assert_refused(cli, good, tmp_path, tmp_path / "absent.json", ["not found"])


def test_valid_model_still_loads(cli, good, tmp_path):
    """The checks refuse nothing a fit wrote (the unchanged model evaluates)."""
    model = _write_model(good, tmp_path, lambda d: None)
    run = cli("evaluate", model, good["val"], "--json", tmp_path / "scores.json")
    assert run.code == 0, run.err
    scores = json.loads((tmp_path / "scores.json").read_text())
    assert scores["r2"] is not None
