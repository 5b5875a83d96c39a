"""Tests for hystkit.datasets and ``hystkit datasets``: loaders, excerpts, CLI, the pipeline.

Two kinds of test. Those on the shipped excerpts and on synthetic data always run. Those that
need the public data in ``shared/data`` (see its README.md) take the ``shared_root`` fixture,
which skips them cleanly when the data are absent. Golden values: the linear-fit residuals
~2.5 and ~0.33 (sensor units) quoted in the micromanipulator's README.txt.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hystkit.compensation import fit_compensator
from hystkit.datasets import (
    DATASETS,
    EXCERPT_DIR,
    EXCERPTS,
    Dataset,
    MissingDependencyError,
    Provenance,
    _boucwen,
    _excerpts,
    _files,
    find_root,
    list_datasets,
    load,
    load_excerpt,
    load_piezo_micromanipulator,
)
from hystkit.errors import InputError
from hystkit.io import Recording, read_recording

from ..cli_support import run_cli

MM = "piezo_micromanipulator"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "piezo_micromanipulator.py"


# --------------------------------------------------------------------------- helpers


def shared_root_or_skip(root: str | Path | None = None) -> Path:
    """The shared data root if every registered folder is there, else skip the test."""
    try:
        for info in list_datasets():
            _files.data_folder(info.folder, root)
    except InputError as exc:
        pytest.skip(f"shared data absent: {exc}")
    return find_root(root)[0]


@pytest.fixture(scope="module")
def shared_root() -> Path:
    return shared_root_or_skip()


def _tiny(**changes: object) -> Dataset:
    n = 50
    t = np.arange(n) * 0.01
    fields = {"name": "tiny", "variant": "v", "time": t, "input": np.sin(t),
              "output": np.cos(t), "input_name": "drive", "input_unit": "V",
              "output_name": "disp", "output_unit": "um", "description": "d",
              "provenance": Provenance("r", "c" * 40, ("p",), "MIT", "L", "x"),
              "time_note": "synthetic", "segments": {"first": (0.0, 0.2)},
              "channels": {"ref": 2 * t}, "channel_units": {"ref": "um"}}
    return Dataset(**(fields | changes))


def _one_error_line(err: str, *fragments: object) -> None:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: "), err
    for fragment in fragments:
        assert str(fragment) in lines[0], (fragment, lines[0])


def _example():
    spec = importlib.util.spec_from_file_location("piezo_micromanipulator_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while being built
    spec.loader.exec_module(module)
    return module


# --------------------------------------------------------------------------- Dataset


def test_dataset_stores_read_only_copies_and_maps_roles() -> None:
    source = np.arange(50) * 0.01
    ds = _tiny(time=source)
    source[0] = -1.0
    assert ds.time[0] == 0.0 and not ds.time.flags.writeable
    assert not ds.channels["ref"].flags.writeable
    rec = ds.to_recording()
    assert isinstance(rec, Recording) and rec.source == "dataset tiny/v"
    assert np.array_equal(rec.position, ds.input) and np.array_equal(rec.sensor, ds.output)
    fwd = ds.to_recording(role="forward")
    assert np.array_equal(fwd.position, ds.output) and np.array_equal(fwd.sensor, ds.input)
    assert ds.columns("forward")["sensor"].startswith("drive [V]")
    with pytest.raises(ValueError, match="role"):
        ds.to_recording(role="sideways")


@pytest.mark.parametrize(("changes", "fragment"), [
    ({"output": np.zeros(49)}, "different lengths"),
    ({"input": np.r_[np.nan, np.zeros(49)]}, "input: non-finite value nan at sample 1"),
    ({"time": np.r_[np.arange(25) * 0.01, 0.3 + np.arange(25) * 0.01]},
     "non-uniform sampling at sample 26"),
    ({"time": np.zeros(50)}, "not strictly increasing"),
    ({"channel_units": {}}, "no unit given for channel(s) ['ref']"),
    ({"output": np.array(["a"] * 50)}, "output is not real numbers"),
])
def test_dataset_refuses_invalid_data(changes: dict, fragment: str) -> None:
    with pytest.raises(InputError, match="dataset tiny/v") as info:
        _tiny(**changes)
    assert fragment in str(info.value)


def test_segments_and_windows_keep_times_and_say_so() -> None:
    ds = _tiny()
    first = ds.segment("first")
    assert first.n_samples == 20 and first.time[0] == 0.0
    assert np.array_equal(first.channels["ref"], ds.channels["ref"][:20])
    assert "segment 'first': 0-0.2 s of the run, 20 samples" in first.notes
    later = ds.window(0.3, 10.0)
    assert later.time[0] == pytest.approx(0.3) and later.segments == {}  # 'first' not inside
    with pytest.raises(InputError, match="no segment 'last'; segments: first"):
        ds.segment("last")
    with pytest.raises(InputError, match="holds 0 sample"):
        ds.window(5.0, 6.0)


# --------------------------------------------------------------------------- registry, root


def test_registry_entries_are_consistent() -> None:
    assert list(DATASETS) == ["piezo_micromanipulator", "piezo_actuator", "mr_damper",
                              "bh_loops", "boucwen"]
    for info in list_datasets():
        names = [v.name for v in info.variants]
        assert len(set(names)) == len(names) and info.default_variant in names
        assert all(v.n_samples >= 2 for v in info.variants)
        assert info.input_unit and info.output_unit and info.licence
    with pytest.raises(InputError, match="no variant 'x'; variants: identification, test"):
        DATASETS[MM].variant("x")
    with pytest.raises(InputError, match="no dataset 'nope'; datasets: piezo_micromanipulator"):
        load("nope")


def test_absent_data_raise_input_error_naming_the_expected_path(tmp_path: Path) -> None:
    with pytest.raises(InputError) as info:
        load_piezo_micromanipulator("test", root=tmp_path)
    message = str(info.value)
    assert str(tmp_path / "piezo_micromanipulator_capsensor") in message
    assert "data folder not found" in message and "root argument" in message


def test_environment_variable_is_used_and_never_silently_replaced(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HYSTKIT_SHARED_DATA", str(tmp_path / "elsewhere"))
    assert find_root() == (tmp_path / "elsewhere", "$HYSTKIT_SHARED_DATA")
    with pytest.raises(InputError, match=r"\$HYSTKIT_SHARED_DATA"):
        load("bh_loops")


def test_search_failure_says_how_to_point_at_the_data(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("HYSTKIT_SHARED_DATA", raising=False)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(_files, "__file__", str(tmp_path / "pkg" / "_files.py"))
    with pytest.raises(InputError, match="shared data not found.*HYSTKIT_SHARED_DATA"):
        find_root()


def _write_dat(path: Path, rows: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join("\t".join(f"{v:.6f}" for v in row) + "\n" for row in rows),
                    encoding="utf-8")


def test_micromanipulator_loader_applies_the_authors_alignment(tmp_path: Path) -> None:
    rows = np.zeros((5, 11))
    rows[:, 0] = [1.0, 1.1, 1.2, 1.3, 1.4]  # drive [V]
    rows[:, 4] = [-90.0, -91.0, -92.0, -93.0, -94.0]  # sensor
    rows[:, 8] = [0.0, 1.0, 2.0, 3.0, 4.0]  # desired [um]
    _write_dat(tmp_path / "piezo_micromanipulator_capsensor" / "Test_Vi_Do_Di.dat", rows)
    ds = load_piezo_micromanipulator("test", root=tmp_path)
    # Output row k+1 belongs to input row k: 4 pairs, last input row dropped.
    assert np.array_equal(ds.input, [1.0, 1.1, 1.2, 1.3])
    assert np.array_equal(ds.output, [-91.0, -92.0, -93.0, -94.0])
    assert np.array_equal(ds.channels["desired_displacement"], [0.0, 1.0, 2.0, 3.0])
    assert np.allclose(ds.time, np.arange(4) / 200.0) and "no time column" in ds.time_note
    assert ds.provenance.files == ("piezo_micromanipulator_capsensor/Test_Vi_Do_Di.dat",)


def test_bad_data_files_name_file_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "piezo_micromanipulator_capsensor" / "Model_Vi_Do.dat"
    _write_dat(path, np.ones((3, 6)))
    with pytest.raises(InputError, match="expected 7 columns, found 6"):
        load_piezo_micromanipulator(root=tmp_path)
    lines = ["\t".join(["1.0"] * 7)] * 3
    lines[2] = "\t".join(["1.0"] * 4 + ["abc"] + ["1.0"] * 2)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"Model_Vi_Do.dat: line 3, column 5: not a number"):
        load_piezo_micromanipulator(root=tmp_path)
    path.unlink()
    with pytest.raises(InputError, match=r"Model_Vi_Do.dat: file not found"):
        load_piezo_micromanipulator(root=tmp_path)


def test_tests_needing_shared_data_skip_when_it_is_absent(tmp_path: Path) -> None:
    with pytest.raises(pytest.skip.Exception, match="shared data absent"):
        shared_root_or_skip(tmp_path)


def test_hdf5_without_h5py_is_a_clear_error(tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "h5py", None)  # makes 'import h5py' raise ImportError
    with pytest.raises(MissingDependencyError, match=r"needs the optional package h5py.*"
                                                     "val_multisine and val_sinesweep"):
        _boucwen._read_h5(tmp_path / "train.h5", "multisine")


# --------------------------------------------------------------------------- excerpts


@pytest.mark.parametrize("spec", EXCERPTS, ids=lambda s: s.variant)
def test_excerpts_load_with_units_provenance_and_licence(spec: _excerpts.ExcerptSpec) -> None:
    ds = load_excerpt(spec.name, spec.variant)
    assert (ds.name, ds.variant, ds.input_unit, ds.output_unit) == (MM, spec.variant, "V", "um")
    assert ds.n_samples == round((spec.t1 - spec.t0) * 200)
    assert ds.time[0] == spec.t0 and ds.dt == pytest.approx(0.005, rel=1e-9)
    assert ds.input.shape == ds.output.shape == ds.time.shape
    prov = ds.provenance
    assert prov.repository == "github.com/yan9a/DiscreteBacklashOperator"
    assert len(prov.commit) == 40 and prov.licence == "MIT"
    folder = EXCERPT_DIR / spec.name
    assert "MIT License" in (folder / prov.licence_file).read_text(encoding="utf-8")
    assert prov.credit in (folder / "README.txt").read_text(encoding="utf-8")
    assert any(n.startswith(f"excerpt of run '{spec.source_variant}'") for n in ds.notes)
    if spec.source_variant == "test":
        assert set(ds.channels) == {"desired_displacement"}
        assert ds.channel_units["desired_displacement"] == "um"
    ds.to_recording()  # validates as a Recording


def test_excerpts_are_small() -> None:
    total = sum(p.stat().st_size for p in EXCERPT_DIR.rglob("*") if p.is_file())
    assert total < 200_000


def test_unknown_excerpts_list_the_shipped_ones() -> None:
    with pytest.raises(InputError, match="excerpts exist for: piezo_micromanipulator"):
        load_excerpt("mr_damper")
    with pytest.raises(InputError, match="excerpts: identification, test_uncompensated"):
        load_excerpt(MM, "test")


# --------------------------------------------------------------------------- the pipeline


def test_micromanipulator_pipeline_runs_on_the_excerpts() -> None:
    example = _example()
    ident = load_excerpt(MM, "identification")
    unc, ff = load_excerpt(MM, "test_uncompensated"), load_excerpt(MM, "test_feedforward")
    rows, comps = example.compare(ident, unc, ff, n_cells=(1,))
    assert [r.segment for r in rows] == ["2-6 s", "2-6 s", "62-66 s", "2-6 s"]
    assert [r.protocol for r in rows] == [example.DEPLOYABLE, example.AUTHOR, example.AUTHOR,
                                          example.CALIBRATED]  # the deployable score first
    assert comps[1].structure.dt == pytest.approx(unc.dt)  # same rate, or estimate refuses
    assert comps[1].center == "fit"
    deployable, uncompensated, author, ours = rows
    for row in rows:
        assert np.isfinite([row.e_rms, row.e_max]).all() and row.span == pytest.approx(40.0)
    # Loose: the excerpt is 6 s of fitting data; on it any inverse must beat no inverse.
    assert author.e_rms < 0.2 * uncompensated.e_rms
    assert ours.e_rms < 0.5 * uncompensated.e_rms
    # calibrating on the scored segment can only remove error (least squares over gain, offset)
    assert ours.e_rms <= deployable.e_rms


def test_the_deployable_score_uses_no_test_position() -> None:
    """Its error is estimate minus applied drive over the drive map's gain, nothing fitted."""
    example = _example()
    unc = load_excerpt(MM, "test_uncompensated")
    gain, offset = example.drive_map(unc)
    d = unc.channels["desired_displacement"]
    assert np.max(np.abs(unc.input - offset - gain * d)) < 1e-5
    estimate = unc.input + 0.05 * gain  # an estimate 0.05 um of desired too high everywhere
    row = example.score_deployable("x", "s", estimate, unc.input, d, gain)
    assert row.e_rms == pytest.approx(0.05) and row.e_max == pytest.approx(0.05)
    # the calibrated score would call the same constant error zero: that is why it is an oracle
    assert example.score("x", "s", offset + gain * d + 0.05 * gain, d).e_rms < 1e-9


def test_straightness_residual_removes_gain_and_offset_only() -> None:
    example = _example()
    d = np.linspace(-20, 20, 101)
    assert np.allclose(example.straightness_residual(3.0 * d - 7.0, d), 0.0, atol=1e-12)
    bump = 0.1 * (d**2 - np.mean(d**2))  # orthogonal to the line: survives, divided by a = 2
    assert np.allclose(example.straightness_residual(2.0 * d + bump, d), bump / 2.0)


def test_example_prints_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert _example().main(["--excerpt", "--cells", "1"]) == 0
    out = capsys.readouterr().out
    assert "sample rates: identification 200 Hz, test 200 Hz" in out
    assert out.count("| hystkit mPL inverse, 1 cell(s)") == 2
    assert out.index("| deployable |") < out.index("| calibrated on the segment (oracle) |")


# --------------------------------------------------------------------------- CLI


def test_cli_list_shows_every_data_set_and_the_excerpts(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, err = run_cli(capsys, "datasets", "list", "--root", tmp_path)
    assert (code, err) == (0, "")
    assert f"shared data: {tmp_path} (root argument)" in out
    for info in list_datasets():
        line = next(line for line in out.splitlines() if line.startswith(info.name + " "))
        assert line.endswith(f" no    {info.licence}"), line  # 'here' column: absent
    assert "shipped excerpts (--excerpt, always available): piezo_micromanipulator" in out
    code, out, _ = run_cli(capsys, "datasets", "list", "mr_damper")
    assert code == 0 and "earthquake_0.2A" in out and "25mm_0.1Hz_0.75A" in out


def test_cli_export_round_trips_through_read_recording(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "ff.csv"
    code, stdout, err = run_cli(capsys, "datasets", "export", MM, "--excerpt", "--variant",
                             "test_feedforward", "--out", out)
    assert (code, err) == (0, ""), err
    ds = load_excerpt(MM, "test_feedforward")
    rec = read_recording(out)
    for column, expected in (("time", ds.time), ("position", ds.input), ("sensor", ds.output)):
        assert np.array_equal(getattr(rec, column), expected), column  # bit-exact round trip
    assert list(pd.read_csv(out).columns) == ["time", "position", "sensor",
                                              "desired_displacement"]
    meta = json.loads(out.with_name("ff.csv.json").read_text(encoding="utf-8"))
    assert meta["columns"]["position"] == "actuator command [V] (system input)"
    assert meta["dataset"]["provenance"]["licence"] == "MIT" and meta["role"] == "inverse"
    assert "position              actuator command [V] (system input)" in stdout
    # The exported file is usable by fit as it is.
    fit_compensator(rec, 1)


def test_cli_export_refuses_overwrite_unless_forced(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "id.csv"
    args = ("datasets", "export", MM, "--excerpt", "--out", out)
    assert run_cli(capsys, *args)[0] == 0
    before = out.read_bytes()
    code, _, err = run_cli(capsys, *args, "--role", "forward")
    assert code == 2 and out.read_bytes() == before
    _one_error_line(err, out, "--force")
    for forced in (("datasets", "export", MM, "--excerpt", "--role", "forward", "--out", out,
                    "--force"), ("datasets", "--force", "export", MM, "--excerpt", "--out", out)):
        assert run_cli(capsys, *forced)[0] == 0
    forward = read_recording(out)  # the last run was role inverse again
    assert np.array_equal(forward.position, load_excerpt(MM).input)


@pytest.mark.parametrize(("args", "out_name", "fragments"), [
    (("--variant", "nope", "--root", "{tmp}"), "x.csv",
     ("no variant 'nope'", "variants: identification, test")),
    (("--excerpt", "--segment", "nope"), "x.csv", ("no segment 'nope'; segments: author_cycle",)),
    (("--variant", "test", "--root", "{tmp}"), "x.csv",
     ("{tmp}/piezo_micromanipulator_capsensor: data folder not found",)),
    (("--excerpt",), "x.txt",
     ("x.txt: a recording is written as .csv, .parquet or .mat, not '.txt'",)),
])
def test_cli_export_errors_are_one_line_and_write_nothing(
        capsys: pytest.CaptureFixture[str], tmp_path: Path, args: tuple[str, ...],
        out_name: str, fragments: tuple[str, ...]) -> None:
    args = tuple(a.replace("{tmp}", str(tmp_path)) for a in args)
    code, _, err = run_cli(capsys, "datasets", "export", MM, *args, "--out", tmp_path / out_name)
    assert code == 2
    _one_error_line(err, *(f.replace("{tmp}", str(tmp_path)) for f in fragments))
    assert list(tmp_path.iterdir()) == [], "nothing may be written"


# --------------------------------------------------------------------------- full shared data


def test_every_variant_loads_as_registered(shared_root: Path) -> None:
    has_h5py = importlib.util.find_spec("h5py") is not None
    for info in list_datasets():
        for variant in info.variants:
            if variant.name == "train_multisine" and not has_h5py:  # HDF5, optional h5py
                with pytest.raises(MissingDependencyError):
                    load(info.name, variant.name, root=shared_root)
                continue
            ds = load(info.name, variant.name, root=shared_root)
            where = ds.label
            assert ds.n_samples == variant.n_samples, where
            rate = 1.0 if variant.fs is None else variant.fs  # nominal 1 s per point
            assert ds.fs == pytest.approx(rate, rel=1e-3), where  # file time jitter < 0.02 %
            assert (ds.input_unit, ds.output_unit) == (info.input_unit, info.output_unit)
            assert ds.provenance.licence and len(ds.provenance.commit) == 40, where
            assert (shared_root / info.folder / ds.provenance.licence_file).is_file(), where
            for file in ds.provenance.files:
                assert (shared_root / file).is_file(), where
            ds.to_recording()


def test_micromanipulator_matches_its_readme(shared_root: Path) -> None:
    test = load(MM, "test", root=shared_root)
    unc, ff = test.segment("uncompensated"), test.segment("feedforward")
    assert (unc.n_samples, ff.n_samples) == (3200, 2400)
    assert load(MM, root=shared_root).segment("author_cycle").n_samples == 200
    # README: uncompensated drive is a linear map of the desired displacement.
    d = unc.channels["desired_displacement"]
    slope, offset = np.polyfit(d, unc.input, 1)
    assert np.max(np.abs(unc.input - slope * d - offset)) < 1e-5  # 6-decimal file values
    assert (slope, offset) == pytest.approx((0.0797, 1.83), abs=1e-4)
    # README: linear-fit residual ~2.5 (0-16 s) and ~0.33 (58-70 s) with the 1-sample lag.
    for seg, golden in ((unc, 2.5), (ff, 0.33)):
        d = seg.channels["desired_displacement"]
        a, b = np.polyfit(d, seg.output, 1)
        rms = np.sqrt(np.mean((seg.output - a * d - b) ** 2))
        assert rms == pytest.approx(golden, rel=0.03), seg.label  # README gives 2 digits


def test_shipped_excerpts_equal_the_full_data(shared_root: Path) -> None:
    for spec in EXCERPTS:
        shipped, cut = load_excerpt(spec.name, spec.variant), _excerpts.excerpt_of(spec)
        for key in ("time", "input", "output"):
            assert np.array_equal(getattr(shipped, key), getattr(cut, key)), (spec, key)
        assert shipped.channels.keys() == cut.channels.keys()
        for key in cut.channels:
            assert np.array_equal(shipped.channels[key], cut.channels[key]), (spec, key)
        assert shipped.metadata() == json.loads(json.dumps(cut.metadata()))


def test_other_loaders_match_their_readmes(shared_root: Path) -> None:
    act = load("piezo_actuator", root=shared_root)
    fit = act.segment("authors_fit")
    assert fit.n_samples == 10000 and fit.time[0] == pytest.approx(7.0)  # rows 35000:45000
    assert np.all(act.segment("rest").input == 0.0) and np.max(np.abs(act.input)) == 150.0
    eq = [load("mr_damper", f"earthquake_{c:g}A", root=shared_root) for c in (0.2, 1.0)]
    assert np.array_equal(eq[0].input, eq[1].input)  # one displacement record, five currents
    run = load("mr_damper", "25mm_0.1Hz_0.75A", root=shared_root)
    assert dict(run.conditions) == {"amplitude_mm": 25.0, "frequency_Hz": 0.1,
                                    "current_A": 0.75}
    for variant in DATASETS["bh_loops"].variants:
        loop = load("bh_loops", variant.name, root=shared_root)
        amplitude = float(variant.name.rsplit("_H", 1)[1])
        assert np.max(np.abs(loop.input)) == pytest.approx(amplitude, rel=0.01), variant.name
    sweep = load("boucwen", "val_sinesweep", root=shared_root)
    assert np.max(np.abs(sweep.input)) == pytest.approx(40.0)  # 40 N amplitude


def test_cli_exports_a_full_data_segment(shared_root: Path, tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "unc.parquet"
    code, _, err = run_cli(capsys, "datasets", "export", MM, "--variant", "test", "--segment",
                        "uncompensated", "--root", shared_root, "--out", out)
    assert (code, err) == (0, "")
    rec = read_recording(out)
    assert rec.n_samples == 3200 and rec.fs == pytest.approx(200.0)
