"""Public data a user does not have (issue 27.8): every data set says where its files come
from (repository, commit, paths there, licence, credit) and where they go, without reading
them; ``hystkit datasets list/show/export``, the loaders and the examples end in one line
when the data are not there, never a traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from hystkit.datasets import (
    DataNotFoundError,
    _files,
    find_root,
    list_datasets,
    load,
    load_piezo_actuator,
)
from hystkit.errors import InputError

from ..cli_support import run_cli

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture
def empty_root(tmp_path, monkeypatch) -> Path:
    root = tmp_path / "shared_data"
    root.mkdir()
    monkeypatch.setenv("HYSTKIT_SHARED_DATA", str(root))
    return root


def test_every_run_has_a_source_known_without_its_files():
    for info in list_datasets():
        for variant in info.variants:
            source = info.provenance(variant.name)
            assert source.repository.startswith("github.com/"), info.name
            assert len(source.commit) == 40 and source.licence and source.licence_file
            assert source.credit and len(source.paths) == len(source.files) >= 1
            assert all(f.startswith(f"{info.folder}/") for f in source.files)
        assert set(info.files()) == {f for v in info.variants
                                     for f in info.provenance(v.name).files}


def test_the_sources_name_the_files_the_loaders_read():
    try:
        root = find_root()[0]
    except InputError as exc:
        pytest.skip(f"shared data absent: {exc}")
    for info in list_datasets():
        missing = [f for f in info.files() if not (root / f).is_file()]
        if missing:
            pytest.skip(f"shared data incomplete: {missing[0]}")
        assert (root / info.folder / info.provenance().licence_file).is_file(), info.name
        if info.name != "boucwen" or info.default_variant != "train_multisine":
            ds = load(info.name)
            assert ds.provenance == info.provenance(), info.name


def test_list_says_what_is_missing_and_where_to_look(capsys, empty_root):
    code, out, err = run_cli(capsys, "datasets", "list")
    assert (code, err) == (0, "")
    names = ", ".join(info.name for info in list_datasets())
    assert out.splitlines()[-1] == (f"not here: {names}; where each comes from and where to put "
                                    "it: hystkit datasets show NAME")
    code, out, _ = run_cli(capsys, "datasets", "list", "piezo_actuator")
    assert code == 0
    assert ("  source github.com/chandratue/SmartHysteresis; the files and where they go: "
            "hystkit datasets show piezo_actuator") in out


@pytest.mark.parametrize("info", list_datasets(), ids=lambda info: info.name)
def test_show_lists_source_licence_and_every_file(capsys, empty_root, info):
    code, out, err = run_cli(capsys, "datasets", "show", info.name)
    assert (code, err) == (0, "")
    source = info.provenance()
    assert f"  source:  {source.repository}" in out
    assert f"  licence: {source.licence}; keep {source.licence_file}" in out
    assert f"  credit:  {source.credit}" in out
    for local in info.files():
        assert f"      -> {empty_root}/{local}  (missing)" in out
    assert f"  here: 0 of {len(info.files())} file(s)" in out
    assert f"  shared data root: {empty_root} ($HYSTKIT_SHARED_DATA)" in out


def test_show_marks_the_files_that_are_here(capsys, empty_root):
    folder = empty_root / "piezo_actuator_150V_1Hz"
    folder.mkdir()
    (folder / "hysteresis_v_150_1hz.csv").write_text("")
    code, out, _ = run_cli(capsys, "datasets", "show", "piezo_actuator")
    assert code == 0
    assert f"      -> {folder}/hysteresis_v_150_1hz.csv\n" in out
    assert "  here: 1 of 1 file(s)" in out


@pytest.mark.parametrize("info", list_datasets(), ids=lambda info: info.name)
def test_export_without_the_data_is_one_line_saying_where_they_come_from(
        capsys, empty_root, tmp_path, info):
    code, out, err = run_cli(capsys, "datasets", "export", info.name, "--out",
                          tmp_path / "x.csv")
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    source = info.provenance()
    assert lines[0].startswith(f"hystkit: error: {empty_root / info.folder}: data folder not "
                               "found (shared data root")
    assert f"{info.name} comes from {source.repository} (commit {source.commit[:7]}" in lines[0]
    assert lines[0].endswith(f"('hystkit datasets show {info.name}' lists the files)")
    assert not (tmp_path / "x.csv").exists()


def test_a_missing_file_in_a_present_folder(empty_root):
    (empty_root / "mr_damper_utfsm").mkdir()
    with pytest.raises(DataNotFoundError) as err:
        load("mr_damper", "25mm_0.1Hz_0.75A")
    assert str(err.value) == (
        f"{empty_root}/mr_damper_utfsm/train_sinusoids/25mm0x1Hz0x75A.txt: file not found; "
        "mr_damper comes from github.com/DanielMaurelE/vRTHS_AMBC_MRdamper (commit 08753ff, "
        "Cap7_ModeloMR/BoucWen Ajuste 2/Preprocesamiento-sinusoidales/Preprocesados/"
        "25mm0x1Hz0x75A.txt; licence MIT): put train_sinusoids/25mm0x1Hz0x75A.txt in "
        "mr_damper_utfsm/ of the shared data root ('hystkit datasets show mr_damper' lists "
        "the files)")


def test_no_shared_data_anywhere(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("HYSTKIT_SHARED_DATA", raising=False)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(_files, "__file__", str(tmp_path / "pkg" / "_files.py"))
    with pytest.raises(DataNotFoundError, match=r"^shared data not found: .*HYSTKIT_SHARED_DATA"
                                                r".*; piezo_actuator comes from github.com/"
                                                r"chandratue/SmartHysteresis"):
        load_piezo_actuator()
    code, out, err = run_cli(capsys, "datasets", "show", "piezo_actuator")
    assert (code, err) == (0, "")
    assert "      -> SHARED_DATA/piezo_actuator_150V_1Hz/hysteresis_v_150_1hz.csv  (missing)" in out
    assert "  shared data root: shared data not found" in out


@pytest.mark.parametrize("script, start", [
    ("piezo_micromanipulator.py", ("piezo_micromanipulator.py: {root}/"
                                  "piezo_micromanipulator_capsensor: data folder not found")),
    ("boucwen_benchmark.py", ("boucwen_benchmark.py: {root}/boucwen_benchmark/train.h5: file "
                             "not found (and 4 more); the benchmark's files come from "
                             "github.com/forgi86/dynonet")),
])
def test_examples_end_in_one_line_without_the_data(tmp_path, script, start):
    env = {**os.environ, "HYSTKIT_SHARED_DATA": str(tmp_path)}
    run = subprocess.run([sys.executable, str(EXAMPLES / script)], check=False,
                         capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
    assert run.returncode == 1 and run.stdout == ""
    lines = run.stderr.splitlines()
    assert len(lines) == 1, run.stderr
    assert lines[0].startswith(start.format(root=tmp_path))
    assert "hystkit datasets show" in lines[0]
