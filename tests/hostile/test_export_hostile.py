"""``export`` against racing writers, hostile folder names and options it cannot honour
(issue 25.9 and 25.10, ``--double --lang matlab``).

- Two exports to the same new ``--out`` (C and MATLAB) both exited 0 and merged their files
  into one folder: now exactly one succeeds and the other refuses in one line, leaving the
  winner's files alone.
- The model file's path (and what the model file says of its fit) went unescaped into the
  generated comments: a folder named ``x*`` put ``*/`` into the C comment and broke the build,
  a newline in a folder name became an executable line in every ``.m`` file.
- ``--double`` with ``--lang matlab`` was silently ignored.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import hystkit.export._write as export_write
from hystkit.compensation import load_compensator
from hystkit.export import export_compensator

from .conftest import entries, run_subprocess, snapshot

C_FILES = {"hyst.c", "hyst.h", "example_main.c", "README"}
M_FILES = {"hyst.m", "hyst_block.m", "hyst_init.m", "hyst_sync.m"}
# The export tests' flags (tests/export/export_support.py): any warning fails the build.
STRICT_FLAGS = ["-O2", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
# Folder names that broke the generated code: "*/" ends a C comment, a newline ends a MATLAB
# one (the next line runs), "??/" is a C99 trigraph (a backslash), "/*" inside a C comment is
# a warning with -Wall, U+2028 is a line break for some editors.
HOSTILE_FOLDERS = ["x*", "new\nexit(1)\n", "q??", "t\r\u2028*"]


def _model_in(folder: Path, good: dict[str, Path]) -> Path:
    folder.mkdir(parents=True)
    model = folder / "model.json"
    shutil.copyfile(good["model"], model)
    return model


# ---- two exports to one new folder -----------------------------------------------------------

def test_an_export_racing_another_into_the_same_new_folder_refuses(monkeypatch, cli, good,
                                                                    tmp_path: Path):
    """Deterministic race: the C export publishes while the MATLAB one is building."""
    out = tmp_path / "E"
    real = export_write.matlab_files

    def meanwhile_c(plan):
        assert export_compensator(load_compensator(good["model"]), out, "c",
                                  name="hyst")[1].keys() == C_FILES
        return real(plan)

    monkeypatch.setattr(export_write, "matlab_files", meanwhile_c)
    run = cli("export", good["model"], "--lang", "matlab", "--out", out, "--name", "hyst")
    assert run.code == 2, run.err
    run.error_line(out, "already exists", "created while hystkit was writing it")
    assert set(entries(out)) == C_FILES  # the winner's folder, nothing merged into it
    assert entries(tmp_path) == sorted(["E", *(f"E/{name}" for name in C_FILES)])  # no temp


def test_two_concurrent_export_processes_one_wins(good, tmp_path: Path):
    procs = [subprocess.Popen([sys.executable, "-m", "hystkit", "export", str(good["model"]),
                               "--lang", lang, "--out", "E", "--name", "hyst"], cwd=tmp_path,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for lang in ("c", "matlab")]
    results = [(proc.wait(timeout=120), *proc.communicate()) for proc in procs]
    codes = sorted(code for code, _, _ in results)
    assert codes == [0, 2], results
    loser = next(err for code, _, err in results if code == 2)
    assert "Traceback" not in loser and len(loser.strip().splitlines()) == 1, loser
    assert loser.startswith("hystkit: error: E ") and "exists" in loser
    winner = C_FILES if results[0][0] == 0 else M_FILES
    assert set(entries(tmp_path / "E")) == winner
    assert not any(".tmp-" in name for name in entries(tmp_path))


# ---- hostile folder names in the generated comments ------------------------------------------

@pytest.mark.skipif(shutil.which("cc") is None, reason="cc is not installed")
@pytest.mark.parametrize("folder", HOSTILE_FOLDERS, ids=["star", "newline", "trigraph", "cr"])
def test_c_export_from_a_hostile_folder_compiles(cli, good, tmp_path: Path, folder: str):
    model = _model_in(tmp_path / "models" / folder, good)
    out = tmp_path / "c"
    assert cli("export", model, "--lang", "c", "--out", out, "--name", "hyst").code == 0
    build = subprocess.run(["cc", *STRICT_FLAGS, "hyst.c", "example_main.c", "-lm", "-o",
                            "estimate"], cwd=out, capture_output=True, text=True, timeout=120,
                           check=False)
    assert build.returncode == 0, build.stderr
    estimate = subprocess.run([str(out / "estimate")], input="0.5\n0.6\n0.7\n",
                              capture_output=True, text=True, timeout=60, check=True)
    assert len(estimate.stdout.split()) == 3
    for name in ("hyst.c", "hyst.h"):
        head = (out / name).read_text(encoding="utf-8").split("*/", 1)[0]
        assert "source file  : " in head and "fit date" in head  # the comment ends after them


@pytest.mark.parametrize("folder", HOSTILE_FOLDERS, ids=["star", "newline", "trigraph", "cr"])
def test_matlab_export_from_a_hostile_folder_keeps_its_comments_comments(cli, good,
                                                                        tmp_path: Path,
                                                                        folder: str):
    model = _model_in(tmp_path / "models" / folder, good)
    out = tmp_path / "m"
    assert cli("export", model, "--lang", "matlab", "--out", out, "--name", "hyst").code == 0
    for name in M_FILES:
        lines = (out / name).read_text(encoding="utf-8").split("\n")
        code = next(i for i, line in enumerate(lines) if line.startswith("function "))
        assert all(line.startswith("%") for line in lines[:code]), (name, lines[:code])
        source = next(line for line in lines[:code] if line.startswith("% source file"))
        assert source.endswith("model.json"), source  # the whole path on its line
        assert not any(ch in "".join(lines) for ch in "\r\u2028")
        assert "exit(1)" not in "\n".join(lines[code:])


@pytest.mark.skipif(shutil.which("cc") is None, reason="cc is not installed")
def test_a_fit_date_from_the_model_file_stays_in_its_comment(good, tmp_path: Path):
    """What the model file says of its fit is quoted too: same escaping."""
    comp = dataclasses.replace(load_compensator(good["model"]),
                               fit_info={"fit_date": "2026 */ #error broken\nexit(1) /* ??/"})
    export_compensator(comp, tmp_path / "c", "c", name="hyst")
    build = subprocess.run(["cc", *STRICT_FLAGS, "-c", "hyst.c"], cwd=tmp_path / "c",
                           capture_output=True, text=True, timeout=120, check=False)
    assert build.returncode == 0, build.stderr
    assert "fit date     : 2026 *\\/ #error broken\\nexit(1) /\\* ?\\?/" in \
        (tmp_path / "c" / "hyst.c").read_text(encoding="utf-8")
    export_compensator(comp, tmp_path / "m", "matlab", name="hyst")
    text = (tmp_path / "m" / "hyst.m").read_text(encoding="utf-8")
    assert "% fit date     : 2026 */ #error broken\\nexit(1) /* ??/\n" in text


# ---- --double with MATLAB ---------------------------------------------------------------------

def test_double_with_matlab_is_refused_not_ignored(good, tmp_path: Path):
    run = run_subprocess("export", good["model"], "--lang", "matlab", "--double", "--out", "M",
                         cwd=tmp_path)
    assert run.code == 2
    run.error_line("--double applies to --lang c only")
    assert snapshot(tmp_path) == {} and entries(tmp_path) == []
