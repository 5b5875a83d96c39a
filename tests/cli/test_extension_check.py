"""An output whose extension does not match its format is refused, before any work (issue 11).

Before, ``evaluate --json s.mat`` and ``fit --out x.xlsx`` quietly wrote JSON under those names.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from hystkit.cli import main
from hystkit.errors import OutputError, OutputExistsError
from hystkit.io import check_output_format, check_output_path, write_json

from ..cli_support import run_cli


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("ext")
    rec = folder / "rec.csv"
    assert main(["simulate-sensor", "--excitation", "sine", "--out", str(rec)]) == 0
    model = folder / "m.json"
    assert main(["fit", str(rec), "--cells", "1", "--out", str(model)]) == 0
    return {"rec": rec, "model": model}


# (argv with OUT for the output, its name, the accepted extensions the message lists)
CASES = {
    "fit-xlsx": (["fit", "{rec}", "--cells", "1", "--out", "OUT"], "x.xlsx", ".json or .mat"),
    "fit-no-extension": (["fit", "{rec}", "--cells", "1", "--out", "OUT"], "model",
                         ".json or .mat"),
    "fit-csv": (["fit", "{rec}", "--cells", "1", "--out", "OUT"], "m.csv", ".json or .mat"),
    "evaluate-json-named-mat": (["evaluate", "{model}", "{rec}", "--json", "OUT"], "s.mat",
                                ".json"),
    "evaluate-out-csv": (["evaluate", "{model}", "{rec}", "--out", "OUT"], "s.csv",
                         ".json or .mat"),
    "compensate-json": (["compensate", "{model}", "{rec}", "--out", "OUT"], "c.json",
                        ".csv, .parquet or .mat"),
    "compensate-xlsx": (["compensate", "{model}", "{rec}", "--out", "OUT"], "c.xlsx",
                        ".csv, .parquet or .mat"),
    "simulate-json": (["simulate-sensor", "--excitation", "sine", "--out", "OUT"], "s.json",
                      ".csv, .parquet or .mat"),
    "datasets-export-json": (["datasets", "export", "mr_damper", "--excerpt", "--out", "OUT"],
                             "d.json", ".csv, .parquet or .mat"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_wrong_extension_is_one_line_before_work(case, inputs, tmp_path, capsys):
    template, name, accepted = CASES[case]
    out = tmp_path / name
    argv = [str(out) if a == "OUT" else a.format(**inputs) for a in template]
    code, stdout, err = run_cli(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: "), err
    suffix = Path(name).suffix or "no extension"
    assert str(out) in lines[0] and accepted in lines[0] and suffix in lines[0], lines[0]
    assert stdout == "", "refused before any work"
    assert list(tmp_path.iterdir()) == []


def test_check_output_format_is_case_blind_and_returns_the_suffix(tmp_path):
    assert check_output_format(tmp_path / "A.MAT", (".json", ".mat")) == ".mat"
    with pytest.raises(OutputError, match=r"a\.txt: scores is written as \.json, not '\.txt'"):
        check_output_format(tmp_path / "a.txt", (".json",), "scores")


def test_check_output_path_checks_formats_after_existence(tmp_path):
    taken = tmp_path / "taken.txt"
    taken.write_text("x")
    with pytest.raises(OutputExistsError, match="already exists"):  # the first problem named
        check_output_path(taken, formats=(".json",))
    with pytest.raises(OutputError, match=r"not '\.txt'"):
        check_output_path(taken, True, formats=(".json",))
    assert check_output_path(tmp_path / "new.json", formats=(".json",)) == tmp_path / "new.json"


def test_write_json_refuses_another_extension(tmp_path):
    with pytest.raises(OutputError, match=r"s\.mat: a JSON file is written as \.json"):
        write_json({"a": 1}, tmp_path / "s.mat")
    assert list(tmp_path.iterdir()) == []
