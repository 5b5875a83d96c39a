"""``hystkit report`` on the command line: outputs, --figures/--format, refusals."""

from __future__ import annotations

import base64
import re
from pathlib import Path

import pytest

from hystkit.compensation import fit_compensator, save_compensator
from hystkit.io import write_recording
from hystkit.sensors import simulate_experiment

from ..cli_support import run_cli


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("report-cli")
    model = save_compensator(fit_compensator(simulate_experiment("sine", 1), 1),
                             folder / "model.json")
    data = write_recording(simulate_experiment("sine", 2), folder / "val.csv")
    return {"model": model, "data": data}


def test_report_writes_a_page_and_figure_files(inputs: dict, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    out, figures = tmp_path / "r.html", tmp_path / "figs"
    code, stdout, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out", out,
                             "--figures", figures, "--format", "svg")
    assert (code, err) == (0, "")
    assert f"wrote {out}" in stdout
    assert sorted(p.name for p in figures.iterdir()) == ["loops.png", "loops.svg",
                                                         "time_series.png", "time_series.svg"]
    page = out.read_text(encoding="utf-8")
    embedded = [base64.b64decode(m) for m in
                re.findall(r'src="data:image/png;base64,([^"]+)"', page)]
    # the page embeds exactly the PNG files' bytes, in order
    assert embedded == [(figures / n).read_bytes() for n in ("loops.png", "time_series.png")]
    for name in ("loops.svg", "time_series.svg"):
        text = (figures / name).read_text(encoding="utf-8")
        assert text.startswith("<?xml") and "<svg" in text and text.rstrip().endswith("</svg>")


def test_pdf_figures(inputs: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out",
                        tmp_path / "r.html", "--figures", tmp_path / "f", "--format", "pdf")
    assert (code, err) == (0, "")
    for name in ("loops.pdf", "time_series.pdf"):
        assert (tmp_path / "f" / name).read_bytes().startswith(b"%PDF-")


def test_existing_page_is_refused_without_force(inputs: dict, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "r.html"
    out.write_text("precious", encoding="utf-8")
    code, _, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out", out,
                        "--figures", tmp_path / "figs")
    assert code == 2
    assert err.startswith("hystkit: error: ") and "--force" in err and err.count("\n") == 1
    assert out.read_text(encoding="utf-8") == "precious"
    assert not (tmp_path / "figs").exists()
    code, _, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out", out,
                        "--force")
    assert (code, err) == (0, "")
    assert out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_existing_figure_file_is_refused_and_nothing_written(
        inputs: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    figures = tmp_path / "figs"
    figures.mkdir()
    (figures / "time_series.png").write_bytes(b"precious")
    out = tmp_path / "r.html"
    code, _, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out", out,
                        "--figures", figures)
    assert code == 2 and "time_series.png" in err and "--force" in err
    assert not out.exists()
    assert sorted(p.name for p in figures.iterdir()) == ["time_series.png"]
    assert (figures / "time_series.png").read_bytes() == b"precious"


@pytest.mark.parametrize("argv, fragment", [
    (["--format", "svg"], "give --figures DIR too"),
    (["--format", "gif"], "invalid choice"),
])
def test_bad_options_are_one_line(argv: list, fragment: str, inputs: dict, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "report", inputs["model"], inputs["data"], "--out",
                        tmp_path / "r.html", *argv)
    assert code == 2 and fragment in err and err.count("\n") == 1
    assert not (tmp_path / "r.html").exists()


def test_bad_inputs_are_one_line(inputs: dict, tmp_path: Path,
                                 capsys: pytest.CaptureFixture[str]) -> None:
    cases = [
        ([inputs["data"], inputs["model"]], "expected a model file"),
        ([inputs["model"]], "give one or more recordings"),
        ([inputs["model"], tmp_path], "a folder among files"),
        ([tmp_path], "not a result folder hystkit can report on"),
        ([inputs["model"], inputs["data"], inputs["data"]], "two recordings named 'val.csv'"),
        ([inputs["model"], tmp_path / "missing.csv"], "file not found"),
    ]
    for given, fragment in cases:
        code, _, err = run_cli(capsys, "report", *given, "--out", tmp_path / "r.html")
        assert code == 2, given
        assert fragment in err and err.count("\n") == 1, (given, err)
    assert not (tmp_path / "r.html").exists()


def test_own_column_names_label_the_sensor_axis(inputs: dict, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """--columns reads a user's file, and the loop figure labels the sensor by its column."""
    text = inputs["data"].read_text(encoding="utf-8").splitlines()
    text[0] = text[0].replace("sensor", "resistance_ohm").replace("position", "disp_mm")
    own = tmp_path / "own.csv"
    own.write_text("\n".join(text) + "\n", encoding="utf-8")
    out, figures = tmp_path / "r.html", tmp_path / "f"
    code, _, err = run_cli(capsys, "report", inputs["model"], own, "--out", out, "--columns",
                        "sensor=resistance_ohm,position=disp_mm", "--figures", figures,
                        "--format", "svg")
    assert (code, err) == (0, "")
    assert "resistance_ohm" in (figures / "loops.svg").read_text(encoding="utf-8")


def test_a_failure_while_writing_leaves_nothing(inputs: dict, tmp_path: Path) -> None:
    """The disk fills while the last figure file is written: neither the page nor any figure
    file appears, and no temporary file stays behind."""
    from hystkit.errors import OutputError
    from hystkit.studies import build_report, write_report

    content = build_report([inputs["model"], inputs["data"]])

    def full_disk(*args: object, **kwargs: object) -> None:
        raise OSError(28, "No space left on device")

    content.figures["time_series"].savefig = full_disk
    out, figures = tmp_path / "r.html", tmp_path / "figs"
    with pytest.raises(OutputError, match="No space left on device"):
        write_report(content, out, figures=figures, fmt="pdf")
    assert sorted(p.name for p in tmp_path.rglob("*")) == []


def test_a_training_recording_is_pointed_out(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    from hystkit.io import read_recording

    fit = write_recording(simulate_experiment("sine", 1), tmp_path / "train.csv")
    val = write_recording(simulate_experiment("sine", 2), tmp_path / "val.csv")
    model = save_compensator(fit_compensator(read_recording(fit), 1), tmp_path / "m.json")
    out = tmp_path / "r.html"
    code, _, err = run_cli(capsys, "report", model, fit, val, "--out", out)
    assert (code, err) == (0, "")
    page = out.read_text(encoding="utf-8")
    assert "train.csv: the file name of a recording the model was fitted on" in page
    assert "val.csv: the file name" not in page
