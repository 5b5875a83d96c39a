"""Every numeric field of a model file, set to a hostile value (issue 25.5 and 25.10).

The fuzz edits one field at a time of a small compensator of every family (direct, and inverse
where the family has one; the centrings fit, tare, track and none in turn) to 0, +-1e+-308, a
subnormal or NaN, loads it in-process and runs it offline and as a stream. Each case must end
in a clean refusal -- an InputError of one line naming the file and the key -- or in finite
estimates within the runaway guard's bounds (|p| <= MAX_NORMALISED, |estimate| <=
MAX_MAGNITUDE), with the stream giving the offline numbers or the same refusal. A few cases
run end to end through the command line: ``compensate``, ``evaluate``, ``stream``, ``report``
and ``export`` all refuse a tampered scale with exit 2 and one line.
"""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hystkit.compensation import Compensator, compensator_from_dict, compensator_to_dict
from hystkit.compensation._compensator import MAX_NORMALISED
from hystkit.compensation._conventions import LinearBaseline, prepare_training_data
from hystkit.errors import FitDivergedError, InputError
from hystkit.io import read_recording
from hystkit.io._recording import MAX_MAGNITUDE
from hystkit.live._stream import Stream
from hystkit.models import FAMILIES

from .conftest import assert_model_file_refused, snapshot

SOURCE = "fuzzed.json"
HOSTILE = [0.0, 1e308, -1e308, 1e-308, -1e-308, 5e-324, -5e-324, float("nan")]
CENTERS = ("fit", "tare", "track", "none")
N_SAMPLES = 400  # 10 s of the sine: every model's run, cheap enough for ~4000 cases


@pytest.fixture(scope="module")
def recording(good: dict[str, Path]):
    rec = read_recording(good["val"])
    return replace(rec, time=rec.time[:N_SAMPLES], sensor=rec.sensor[:N_SAMPLES],
                   position=rec.position[:N_SAMPLES])


def _base_models(rec) -> list[dict]:
    """One valid model file's contents per family and mode (random parameters from the
    family's documented domain, the recording's own conventions)."""
    out = []
    for i, (name, family) in enumerate(sorted(FAMILIES.items())):
        structure = family.make_structure(rec.dt, family.default_size)
        for j, mode in enumerate(("direct", "inverse") if family.has_inverse else ("direct",)):
            center = CENTERS[(i + j) % len(CENTERS)]
            conventions, _, _ = prepare_training_data([rec], center)
            comp = _valid(family, structure, rec, mode, center, conventions)
            out.append(compensator_to_dict(comp))
    return out


def _valid(family, structure, rec, mode: str, center: str, conventions: dict) -> Compensator:
    """The first random parameter set whose compensator runs on `rec`."""
    for seed in range(50):
        try:
            comp = Compensator(structure=structure,
                               params=family.random_params(structure,
                                                           np.random.default_rng(seed)),
                               mode=mode, center=center, baseline=LinearBaseline(1.0, 0.0),
                               model=family.name, training_range=(-1.0, 1.0),
                               position_range=(float(rec.position.min()),
                                               float(rec.position.max())), **conventions)
            comp.estimate(rec)
            return comp
        except (ValueError, FitDivergedError):
            continue
    raise AssertionError(f"no runnable {family.name} {mode} compensator in 50 draws")


def _numeric_paths(d: dict) -> list[tuple]:
    """Key paths of every numeric field (of long lists the first and last item)."""
    def walk(value, path):
        if isinstance(value, dict):
            for key, item in value.items():
                yield from walk(item, (*path, key))
        elif isinstance(value, list):
            for i in sorted({0, len(value) - 1}) if value else ():
                yield from walk(value[i], (*path, i))
        elif isinstance(value, int | float) and not isinstance(value, bool):
            yield path

    return [path for key in d if key not in ("fit", "schema_version", "fit_seconds")
            for path in walk(d[key], (key,))]


def _edited(d: dict, path: tuple, value: float) -> dict:
    out = json.loads(json.dumps(d))
    target = out
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return out


def _name(path: tuple) -> str:
    """``params.w`` for ``("params", "w", 1)``: the key path a message names."""
    return ".".join(str(k) for k in path if not isinstance(k, int))


def _assert_clean_refusal(message: str, path: tuple) -> None:
    assert "\n" not in message and message.startswith(f"{SOURCE}: "), message
    assert not re.search(r"__init__|positional argument|Traceback", message), message
    if path[0] in ("params", "structure"):  # the family's own checks name its fields
        assert re.search(r"keys? '(params|structure)", message), message
    else:
        assert _name(path) in message, message


def _assert_in_range(comp: Compensator, estimate: np.ndarray) -> None:
    assert np.all(np.isfinite(estimate))
    assert np.max(np.abs(estimate)) <= MAX_MAGNITUDE
    # the normalised output within the guard: |estimate - offset| <= MAX_NORMALISED * scale
    offset = comp.position_offset()
    assert np.max(np.abs(estimate - offset)) <= MAX_NORMALISED * comp.scaling.position_scale \
        * (1 + 1e-12)
    if comp.position_range is not None:  # and within 1e6 extents of the training positions
        lo, hi = comp.position_range
        pad = MAX_NORMALISED * max(hi - lo, abs(lo), abs(hi))
        shift = offset - comp.scaling.position_offset
        assert np.all((estimate >= lo + shift - pad) & (estimate <= hi + shift + pad))


def _run(comp: Compensator, rec) -> tuple[np.ndarray | None, str | None]:
    try:
        return comp.estimate(rec), None
    except FitDivergedError as exc:
        return None, str(exc)


def _run_stream(comp: Compensator, rec) -> tuple[np.ndarray | None, str | None]:
    try:
        return Stream(comp, label=rec.source).process(rec.sensor), None
    except FitDivergedError as exc:
        return None, str(exc)


def test_every_numeric_field_refused_or_in_range(recording):
    """4224 edits of 21 compensators: a refusal naming file and key, or finite estimates
    within the guard, offline and streamed alike. (Before issue 25: position_scale 1e308 gave
    1e308 mm, a subnormal sensor_scale an internal error, tare_seconds 1e308 an
    OverflowError.)"""
    counts = {"refused": 0, "ran": 0, "diverged": 0}
    for base in _base_models(recording):
        for path in _numeric_paths(base):
            for value in HOSTILE:
                d = _edited(base, path, value)
                try:
                    comp = compensator_from_dict(d, SOURCE)
                except InputError as exc:
                    _assert_clean_refusal(str(exc), path)
                    counts["refused"] += 1
                    continue
                estimate, error = _run(comp, recording)
                if error is not None:
                    assert SOURCE in error and "\n" not in error, error
                    counts["diverged"] += 1
                else:
                    _assert_in_range(comp, estimate)
                    counts["ran"] += 1
                if comp.center == "recording" or not getattr(comp.structure, "limit", True):
                    continue
                streamed, stream_error = _run_stream(comp, recording)
                assert (streamed is None) == (estimate is None), (path, value, stream_error)
                if streamed is not None:
                    _assert_in_range(comp, streamed)
    # the fuzz reached every outcome: not all refused, not all accepted
    assert min(counts.values()) > 0, counts


def test_a_valid_file_of_every_family_loads(recording):
    """The domain checks refuse nothing a fit writes (all families, both modes, each centring
    in turn): the fuzz's base models load and run unchanged."""
    for base in _base_models(recording):
        comp = compensator_from_dict(json.loads(json.dumps(base)), SOURCE)
        _assert_in_range(comp, comp.estimate(recording))


# -- end to end: the examples through the command line ----------------------------


def _write(good: dict[str, Path], folder: Path, edit) -> Path:
    d = json.loads(good["model"].read_text())
    edit(d)
    path = folder / "tampered.json"
    path.write_text(json.dumps(d))
    return path


def _set(section: str, key: str, value: float):
    return lambda d: d[section].__setitem__(key, value)


TAMPERED = [
    ("position-scale-1e308", _set("normalisation", "position_scale", 1e308),
     "normalisation.position_scale"),
    ("sensor-scale-subnormal", _set("normalisation", "sensor_scale", 1e-320),
     "normalisation.sensor_scale"),
    ("sensor-offset-1e308", _set("normalisation", "sensor_offset", -1e308),
     "normalisation.sensor_offset"),
    ("position-offset-1e308", _set("normalisation", "position_offset", 1e308),
     "normalisation.position_offset"),
    ("baseline-slope", _set("baseline", "slope", 1e300), "baseline.slope"),
    ("missing-scale", lambda d: d["normalisation"].pop("position_scale"),
     "normalisation.position_scale"),
    ("unknown-baseline-key", _set("baseline", "bogus", 1.0), "baseline.bogus"),
    ("dt-disagrees", lambda d: d.__setitem__("dt", 1.0), "dt"),
    ("track-window", lambda d: d.__setitem__("track_seconds", 1e308), "track_seconds"),
]


@pytest.mark.parametrize("edit, key", [c[1:] for c in TAMPERED], ids=[c[0] for c in TAMPERED])
def test_tampered_field_refused_by_every_command(cli, good, tmp_path, edit, key):
    """Exit 2, one line naming the file and the key, nothing written: compensate, evaluate
    (before: 1e308 mm estimates with exit 0 or an internal error), stream, report, export."""
    model = _write(good, tmp_path, edit)
    assert_model_file_refused(cli, good, model, tmp_path, key)
    before = snapshot(tmp_path)
    for argv in (["stream", model, "--in", good["val"]],
                 ["report", model, good["val"], "--out", tmp_path / "r.html"],
                 ["export", model, "--out", tmp_path / "exported"]):
        run = cli(*argv)
        assert run.code == 2, (argv[0], run.err)
        run.error_line(model.name, key)
        assert snapshot(tmp_path) == before


def test_missing_key_named_not_python_internals(cli, good, tmp_path):
    """``Scaling.__init__() missing 1 required positional argument`` became the key path."""
    model = _write(good, tmp_path, lambda d: d["normalisation"].pop("sensor_scale"))
    run = cli("compensate", model, good["val"], "--out", tmp_path / "out.csv")
    line = run.error_line(model.name, "'normalisation.sensor_scale' is missing")
    assert "__init__" not in line and "positional" not in line


def test_missing_structure_size_is_named(cli, good, tmp_path):
    """A structure key left out takes its default; when that default does not fit the
    parameters, the message says which key was missing."""
    d = json.loads(good["model"].read_text())
    d["params"] = {k: (v * 2 if isinstance(v, list) and k != "w" else v)
                   for k, v in d["params"].items()}
    d["params"]["w"] = d["params"]["w"][:1] * 3
    d["structure"].pop("n_cells")
    model = tmp_path / "tampered.json"
    model.write_text(json.dumps(d))
    run = cli("compensate", model, good["val"], "--out", tmp_path / "out.csv")
    assert run.code == 2
    run.error_line(model.name, "structure.n_cells (default 1)", "missing")


def test_estimate_beyond_any_recording_is_refused(cli, good, tmp_path):
    """The runaway guard after de-normalisation: a file without ``position_range`` (older
    files) and a scale within its limit, whose estimates pass 1e100 mm, is refused at the
    first such sample (before: written with exit 0)."""
    def edit(d):
        d.pop("position_range")
        d.pop("band")  # older files have neither (a band needs the position range)
        d["normalisation"]["position_scale"] = 2e100

    model = _write(good, tmp_path, edit)
    before = snapshot(tmp_path)
    run = cli("compensate", model, good["val"], "--out", tmp_path / "out.csv")
    assert run.code == 2
    run.error_line("val.csv", "sample", model.name, "beyond the largest magnitude 1e+100")
    assert snapshot(tmp_path) == before
    run = cli("stream", model, "--in", good["val"])
    rows = [line.split(",") for line in run.out.splitlines()[1:]]
    assert rows and all(abs(float(row[1])) <= MAX_MAGNITUDE for row in rows)
    assert "ran away" in run.err


def test_scale_that_does_not_fit_the_positions_is_refused_at_use(cli, good, tmp_path):
    """A position scale within its limits but 1e50 times the training positions' extent: the
    runaway guard after de-normalisation refuses its estimates (before: 1e50 mm, exit 0)."""
    model = _write(good, tmp_path, _set("normalisation", "position_scale", 1e50))
    before = snapshot(tmp_path)
    for argv in (["compensate", model, good["val"], "--out", tmp_path / "out.csv"],
                 ["evaluate", model, good["val"]]):
        run = cli(*argv)
        assert run.code == 2, run.err
        run.error_line("val.csv", "sample", model.name, "beyond 1e+06 times the training range")
    assert snapshot(tmp_path) == before
