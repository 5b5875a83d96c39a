"""``hystkit fit --model auto``: the guided first fit (issue 27.5), both directions: a real
device comes out ``ok`` with the choice explained in three lines and a model file usable on its
next run; a noise-only sensor never does. No timing here (measured in the report of the
commit; the budget's mechanics are checked by what they skip)."""

from __future__ import annotations

import json

import pytest

from hystkit.cli._common import GUARD_EXIT
from hystkit.compensation import load_compensator
from hystkit.datasets import load_excerpt
from hystkit.io import write_recording
from hystkit.studies._guided import SHORT_LIST

from ..cli_support import run_cli
from ..compensation.test_verdict_corpus import data  # noqa: F401 (the labelled corpus)


@pytest.fixture(scope="module")
def device(tmp_path_factory):
    """The micromanipulator's identification and test runs (real, shipped excerpts)."""
    folder = tmp_path_factory.mktemp("device")
    return {name: write_recording(load_excerpt("piezo_micromanipulator", variant)
                                  .to_recording(), folder / f"{name}.csv")
            for name, variant in (("ident", "identification"), ("test", "test_uncompensated"))}


def test_a_real_device_gets_a_usable_model_and_three_lines(device, tmp_path, capsys):
    model = tmp_path / "auto.json"
    code, out, err = run_cli(capsys, "fit", device["ident"], "--model", "auto", "--out", model)
    assert code == 0, err
    lines = out.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("chose "))
    chose, score, others = lines[first:first + 3]
    comp = load_compensator(model)
    # what won, its held-out score under the protocol's name, the runner-up and the others
    assert chose.startswith(f"chose {comp.model} (size ")
    assert "deployable R² " in score and "interleaved cycles of the training recording" in score
    assert others.startswith("  runner-up ")
    size = int(chose.split("(size ")[1].split(",")[0])
    losers = {f"{name}:{n}" for name, n in SHORT_LIST} - {f"{comp.model}:{size}"}
    assert len(losers) == len(SHORT_LIST) - 1 and all(f"{c} " in others for c in losers)
    assert "status: ok" in out and comp.fit_info["status"] == "ok"
    assert comp.fit_info["selection"] == [chose, score, others]
    assert comp.band is not None  # written as select writes its winner
    assert json.loads(model.read_text())["reading"] is not None  # the reading remembered
    # usable on the device's next run, as a model fitted by name would be
    code, out, err = run_cli(capsys, "evaluate", model, device["test"])
    assert code == 0 and "verdict: ok" in out, err


def test_a_noise_only_sensor_is_never_ok(data, tmp_path, capsys):  # noqa: F811
    model = tmp_path / "auto.json"
    code, out, err = run_cli(capsys, "fit", data["noise_only"], "--model", "auto", "--out",
                             model)
    assert code == GUARD_EXIT and not model.exists()
    assert "status: ok" not in out
    refusal = err.strip().splitlines()[-1]
    assert refusal.startswith("hystkit: fit: no usable model among ") and "no signal" in refusal
    assert out.strip().splitlines()[-1].startswith("next: try checking the columns")


@pytest.mark.parametrize("option", [("--cells", "3"), ("--slope-cap", "0.5"), ("--init", "list"),
                                    ("--loss", "huber"), ("--no-limit",)])
def test_a_model_option_without_a_model_is_one_line(data, tmp_path, capsys, option):  # noqa: F811
    code, _, err = run_cli(capsys, "fit", data["sine1"], "--model", "auto", *option, "--out",
                           tmp_path / "m.json")
    assert code == 2 and err.count("\n") == 1
    assert f"{option[0]} applies to a named model" in err
    assert not (tmp_path / "m.json").exists()


def test_budget_belongs_to_the_guided_fit(data, tmp_path, capsys):  # noqa: F811
    code, _, err = run_cli(capsys, "fit", data["sine1"], "--model", "mpl", "--budget", "30",
                           "--out", tmp_path / "m.json")
    assert code == 2 and "--budget applies to --model auto" in err


def test_without_model_the_guided_fit_and_an_option_of_a_named_model_means_mpl(
        data, tmp_path, capsys):  # noqa: F811
    """fit without --model is the guided fit (_core_options.DEFAULT_MODEL, issue 27.5); --cells
    3 alone is still the 3-cell mpl (as the issue's user typed it)."""
    from hystkit.cli import cmd_fit
    from hystkit.cli._main import _parser

    def chosen(*argv):
        return cmd_fit._chosen_model(_parser().parse_args(["fit", "x.csv", "--out", "m.json",
                                                            *argv]))

    assert chosen() == "auto" and chosen("--model", "pi") == "pi"
    assert chosen("--cells", "3") == chosen("--loss", "huber") == "mpl"
    code, out, err = run_cli(capsys, "fit", data["sine1"], "--cells", "1", "--out",
                             tmp_path / "m.json")
    assert code == 0 and out.startswith("fitting mpl (cells N (3N + 2 params): 1,"), err
