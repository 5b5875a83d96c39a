"""hystkit.batch: manifests, the folder convention, resuming an interrupted batch, failures."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

import hystkit.batch._run as batch_run
from hystkit.batch import RESULT_COLUMNS, SensorJob, jobs_from_folder, read_manifest, run_batch
from hystkit.compensation import evaluate, load_compensator
from hystkit.errors import InputError, OutputError
from hystkit.io import Recording, read_recording, write_recording
from hystkit.sensors import simulate_experiment

TIMES = ("fit_seconds", "seconds")


def _head(rec: Recording, n: int = 2400) -> Recording:
    return Recording(time=rec.time[:n], sensor=rec.sensor[:n], position=rec.position[:n],
                     source=rec.source)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three virtual sensors (different seeds), a fit and a validation recording each, and
    ``manifest.csv`` listing them with a 1-cell mPL."""
    folder = tmp_path_factory.mktemp("fleet")
    lines = ["sensor,fit,validate,size"]
    for k in range(3):
        write_recording(_head(simulate_experiment("sine", 10 + k)), folder / f"s{k}_fit.csv")
        write_recording(_head(simulate_experiment("sine", 20 + k)), folder / f"s{k}_val.csv")
        lines.append(f"s{k},s{k}_fit.csv,s{k}_val.csv,1")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder


@pytest.fixture(scope="module")
def whole(fleet: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[list, Path]:
    """The fleet's manifest run once, uninterrupted: its table and output folder (read only)."""
    out = tmp_path_factory.mktemp("whole") / "out"
    return run_batch(read_manifest(fleet / "manifest.csv", {}), out), out


def _untimed(table: list[dict]) -> list[dict]:
    return [{k: v for k, v in row.items() if k not in TIMES} for row in table]


def test_csv_and_toml_manifests_list_the_same_jobs(fleet):
    toml = fleet / "manifest.toml"
    toml.write_text("[defaults]\nsize = 1\n" + "".join(
        f'[[sensor]]\nid = "s{k}"\nfit = "s{k}_fit.csv"\nvalidate = ["s{k}_val.csv"]\n'
        for k in range(3)))
    from_csv = read_manifest(fleet / "manifest.csv", {})
    assert read_manifest(toml, {}) == from_csv
    assert from_csv[1] == SensorJob("s1", (fleet / "s1_fit.csv",), (fleet / "s1_val.csv",),
                                    model="mpl", size=1)


@pytest.mark.parametrize(("text", "message"), [
    ("sensor,fit,validate,model\na,f.csv,v.csv,mpl\nb,f.csv,v.csv,nope\n",
     "line 3: sensor 'b': unknown model 'nope'"),
    ("sensor,fit,validate\na,f.csv,v.csv\na,g.csv,w.csv\n",
     "sensor id 'a' appears twice (line 2 and line 3)"),
    ("sensor,fit,validate\n../x,f.csv,v.csv\n", "line 2: sensor id '../x'"),
    ("sensor,fit\na,f.csv\n", "line 1: missing column(s) validate"),
    ("sensor,fit,validate,size\na,f.csv,v.csv,0\n", "line 2: sensor 'a': size 0"),
    ("sensor,fit,validate\na,,v.csv\n", "line 2: sensor 'a': column 'fit'"),
])
def test_a_bad_manifest_is_one_error_naming_its_row(tmp_path, text, message):
    path = tmp_path / "m.csv"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        read_manifest(path, {})
    assert str(err.value).startswith(f"{path}: ") or "appears twice" in message
    assert message in str(err.value)


def test_folder_convention(tmp_path, fleet):
    (tmp_path / "a").mkdir()
    for name in ("fit1.csv", "fit2.csv", "val.csv", "notes.txt"):
        (tmp_path / "a" / name).write_text("x")
    (tmp_path / "b.csv").write_text("x")
    jobs = jobs_from_folder(tmp_path, {"model": "pi"})
    assert [(j.sensor, [p.name for p in j.fit], [p.name for p in j.validate], j.split, j.model)
            for j in jobs] == [("a", ["fit1.csv", "fit2.csv"], ["val.csv"], False, "pi"),
                               ("b", ["b.csv"], [], True, "pi")]


def test_a_split_recording_fits_its_first_half_and_scores_its_second(tmp_path, fleet):
    rec = read_recording(fleet / "s0_fit.csv")
    write_recording(rec, tmp_path / "in" / "solo.csv")
    [row] = run_batch(jobs_from_folder(tmp_path / "in", {"size": 1}), tmp_path / "out")
    comp = load_compensator(tmp_path / "out" / "models" / "solo.json")
    half = rec.n_samples // 2
    second = Recording(time=rec.time[half:] - rec.time[half], sensor=rec.sensor[half:],
                       position=rec.position[half:], source="second half")
    assert comp.fit_info["training_samples"] == half
    assert row["r2_deployable"] == evaluate(comp, second)["r2"]


def test_batch_writes_models_and_a_table_of_their_scores(fleet, whole):
    jobs = read_manifest(fleet / "manifest.csv", {})
    table, out = whole
    assert [r["sensor"] for r in table] == ["s0", "s1", "s2"]
    for row, job in zip(table, jobs):
        # the row's scores are those of the written model file on the validation recording
        scores = evaluate(load_compensator(out / row["model_file"]),
                          read_recording(job.validate[0]))
        assert row["status"] == "ok" and row["error"] is None
        assert (row["r2_deployable"], row["r2_oracle"], row["e_rms_pct_deployable"]) == \
            (scores["r2"], scores["r2_oracle"], scores["e_rms_pct"])
        # the written model carries its band, scored like evaluate's
        assert (row["band_coverage"], row["band_width_median"]) == \
            (scores["band_coverage"], scores["band_width_median"])
        assert 0.5 < row["band_coverage"] <= 1.0
    for name in ("results.parquet", "results.csv"):
        read = getattr(pd, f"read_{name.split('.')[1]}")(out / name)
        assert list(read.columns) == list(RESULT_COLUMNS)
        # empty cells read back as NaN (CSV) or None (Parquet): compare them as None
        assert read.astype(object).where(read.notna(), None).to_dict("records") == table


def test_an_interrupted_batch_resumed_gives_the_uninterrupted_table(tmp_path, fleet, whole,
                                                                    monkeypatch):
    jobs = read_manifest(fleet / "manifest.csv", {})
    whole_table, whole_out = whole

    real_fit = batch_run.fit_compensator

    def stopped_at_s1(recs, *args, **kwargs):
        if recs[0].source.endswith("s1_fit.csv"):  # the second sensor
            raise KeyboardInterrupt
        return real_fit(recs, *args, **kwargs)

    monkeypatch.setattr(batch_run, "fit_compensator", stopped_at_s1)
    with pytest.raises(KeyboardInterrupt):
        run_batch(jobs, tmp_path / "resumed")
    out = tmp_path / "resumed"
    assert sorted(p.name for p in (out / "sensors").iterdir()) == ["s0.json"]
    assert not (out / "results.csv").exists()
    first = json.loads((out / "sensors" / "s0.json").read_text())["row"]
    s0_model = (out / "models" / "s0.json").stat().st_mtime_ns

    monkeypatch.setattr(batch_run, "fit_compensator", real_fit)
    said = []
    resumed = run_batch(jobs, out, progress=said.append)
    assert said[0].startswith("3 sensors: 1 finished before, 2 to fit")
    assert resumed[0] == first  # s0 not refitted: its row (and time) from the first run
    assert (out / "models" / "s0.json").stat().st_mtime_ns == s0_model
    assert _untimed(resumed) == _untimed(whole_table)
    assert pd.read_csv(out / "results.csv").drop(columns=list(TIMES)).equals(
        pd.read_csv(whole_out / "results.csv").drop(columns=list(TIMES)))


def test_a_changed_recording_is_fitted_again(tmp_path, fleet):
    folder = tmp_path / "fleet"
    folder.mkdir()
    for p in fleet.glob("s*.csv"):
        (folder / p.name).write_bytes(p.read_bytes())
    (folder / "manifest.csv").write_text((fleet / "manifest.csv").read_text())
    jobs = read_manifest(folder / "manifest.csv", {})
    run_batch(jobs, tmp_path / "out")
    write_recording(_head(simulate_experiment("sine", 30)), folder / "s2_fit.csv", force=True)
    said = []
    run_batch(read_manifest(folder / "manifest.csv", {}), tmp_path / "out",
              progress=said.append)
    assert said[0].startswith("3 sensors: 2 finished before, 1 to fit")
    assert said[1].startswith("[3/3] s2: ok")


def test_a_broken_recording_fails_its_sensor_only(tmp_path, fleet):
    (tmp_path / "broken.csv").write_text("time,position,sensor\n0,1,2\n0.025,x,3\n")
    lines = (fleet / "manifest.csv").read_text().splitlines()
    lines[2] = f"s1,{tmp_path / 'broken.csv'},{fleet / 's1_val.csv'},1"
    lines = [lines[0], lines[2]] + [line.replace(",s", f",{fleet}/s") for line in
                                    (lines[1], lines[3])]
    (tmp_path / "m.csv").write_text("\n".join(lines) + "\n")
    table = run_batch(read_manifest(tmp_path / "m.csv", {}), tmp_path / "out")
    assert [(r["sensor"], r["status"]) for r in table] == [("s1", "failed"), ("s0", "ok"),
                                                          ("s2", "ok")]
    assert "broken.csv" in table[0]["error"] and "'position'" in table[0]["error"]
    assert table[0]["r2_deployable"] is None and table[0]["model_file"] is None
    assert sorted(p.name for p in (tmp_path / "out" / "models").iterdir()) == \
        ["s0.json", "s2.json"]


def test_a_folder_that_is_not_a_batch_is_refused(tmp_path, fleet):
    (tmp_path / "mine.txt").write_text("keep")
    with pytest.raises(OutputError, match="not a hystkit batch folder"):
        run_batch(read_manifest(fleet / "manifest.csv", {}), tmp_path)
    assert [p.name for p in tmp_path.iterdir()] == ["mine.txt"]


def test_a_sensor_worse_than_its_line_on_validation_is_not_ok(tmp_path):
    """A 3-cell mPL fitted on a sine passes its guards, but on the noise run it loses to its
    straight line (R² 0.57 against 0.88): the row says so, as `evaluate` would (issue 24)."""
    write_recording(simulate_experiment("sine", 1), tmp_path / "fit.csv")
    write_recording(simulate_experiment("noise", 2), tmp_path / "val.csv")
    write_recording(simulate_experiment("sine", 2), tmp_path / "val_sine.csv")
    jobs = [SensorJob("a", (tmp_path / "fit.csv",), (tmp_path / "val.csv",), size=3),
            SensorJob("b", (tmp_path / "fit.csv",), (tmp_path / "val_sine.csv",), size=3)]
    table = run_batch(jobs, tmp_path / "out")
    bad, good = table
    assert bad["status"] == "worse_than_line" and "validation" in bad["guards"]
    assert bad["r2_deployable"] < bad["linear_r2_deployable"]
    assert good["status"] == "ok" and good["guards"] is None
