"""``hystkit fit --init / --no-limit / --weight-sum-max`` (issue 14.4): the document's own
fitting setups from the command line, and the reproduction of the unlimited model's
divergence (sec. 5.3.3)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from hystkit.cli import main
from hystkit.cli._fit_checks import parse_init
from hystkit.errors import InputError
from hystkit.models import get_family

from ..cli_support import run_cli

MPL = get_family("mpl")


def _one_error(err: str, *fragments: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.fixture(scope="module")
def recordings(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("setups")
    paths = {name: folder / f"{name}.csv" for name in ("sine", "chirp")}
    for name, path in paths.items():
        assert main(["simulate-sensor", "--excitation", name, "--out", str(path)]) == 0
    return paths


# --------------------------------------------------------------------------- the parser


def test_json_key_value_and_preset_give_the_same_params():
    structure = MPL.make_structure(0.025, 1)
    as_json = parse_init('{"I_S": 0.1, "v_t": 0.2, "w": [1, 0.4], "V_b": -0.6}', MPL,
                         structure)
    as_pairs = parse_init("i_s=0.1, v_t=0.2, w=1:0.4, v_b=-0.6", MPL, structure)
    as_preset = parse_init("table-5.2", MPL, structure)
    assert as_json == as_pairs == as_preset == MPL.presets()["table-5.2"][1]


def test_a_single_value_is_repeated_over_the_cells():
    params = parse_init("i_s=0.1,v_t=0.2:0.3,w=1:0.4:0.2,v_b=0", MPL,
                        MPL.make_structure(0.025, 2))
    assert_allclose(params.i_s, [0.1, 0.1])
    assert_allclose(params.v_t, [0.2, 0.3])


def test_mpl_poly_matrix_rows_and_its_table_i_preset():
    family = get_family("mpl-poly")
    structure = family.make_structure(0.025, 1)
    table_i = family.presets()["paper-9.2-table-i"][1]
    text = ",".join(f"{k}={':'.join(map(str, np.ravel(v)))}"
                    for k, v in table_i.to_dict().items())
    assert parse_init(text, family, structure) == table_i
    two = parse_init("f=0:1:0:1;0:2:0:1,g=0:1:0:0,w=1:0.5:0.5,v_b=0", family,
                     family.make_structure(0.025, 2))
    assert_allclose(two.f, [[0, 1, 0, 1], [0, 2, 0, 1]])


@pytest.mark.parametrize(("text", "fragments"), [
    ("i_s=0.1,v_t=0.2", ("needs i_s, v_t, w, v_b", "missing w, v_b")),
    ("i_s=0.1,v_t=0.2,w=1:0.4,v_b=0,q=1", ("no parameter 'q'",)),
    ("i_s=0.1,v_t=abc,w=1:0.4,v_b=0", ("v_t", "not a number")),
    ("i_s=0.1,v_t=0.2,w=1:0.4:3,v_b=0", ("w", "shape (2,)")),
    ("i_s=-1,v_t=0.2,w=1:0.4,v_b=0", ("i_s",)),
    ('{"i_s": 0.1', ("not valid JSON",)),
    ("[1, 2]", ("the JSON must be an object", "got a list")),
    ("table-9.9", ("table-9.9", "presets: table-5.2")),
])
def test_bad_init_is_one_clear_line(text, fragments):
    with pytest.raises(InputError) as info:
        parse_init(text, MPL, MPL.make_structure(0.025, 1))
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


# --------------------------------------------------------------------------- the command


@pytest.mark.parametrize("model", ["mpl", "mpl-poly", "mpl-g"])
def test_init_list_prints_the_presets_of_the_model_wherever_it_stands(capsys, model):
    # the listing needs neither recordings nor --out, and --model may come after --init
    for argv in (["--model", model, "--init", "list"], ["--init", "list", "--model", model]):
        code, out, err = run_cli(capsys, "fit", *argv)
        assert code == 0 and not err
        presets = get_family(model).presets()
        assert presets  # the premise: every family that takes --init has presets
        listed = [line.split(":")[0] for line in out.splitlines() if not line.startswith(" ")]
        assert listed == list(presets)
        for name, (_, _, info) in presets.items():
            assert f"{name}: {info['source']}" in out


def test_mpl_g_weight_sum_floor_is_refused_before_the_data_are_read(recordings, tmp_path,
                                                                    capsys, monkeypatch):
    from hystkit.cli import _reading

    def unread(*args, **kwargs):
        raise AssertionError("the data were read")

    # the names the CLI reads with (imported at the top of cli._reading)
    monkeypatch.setattr(_reading, "read_recording", unread)
    monkeypatch.setattr(_reading, "read_pieces", unread)
    code, _, err = run_cli(capsys, "fit", recordings["sine"], "--model", "mpl-g",
                        "--weight-sum-max", "1", "--out", tmp_path / "g.json")
    assert code == 2
    _one_error(err, "--weight-sum-max for mpl-g must be above 1", "w_0 = 1")


def test_no_limit_fit_warns_saves_the_flag_and_its_divergence_is_reported(
        recordings, tmp_path, capsys):
    model = tmp_path / "free.json"
    code, out, err = run_cli(capsys, "fit", recordings["sine"], "--no-limit", "--init",
                          "table-5.2", "--out", model)
    assert code == 3  # written for inspection: a guard, not a compensator to use
    assert "can diverge (sec. 5.3.3" in err and "not for use" in err
    assert "hystkit: fit no limit: fitted without the stability limit (eq. 5.29" in err
    assert json.loads(model.read_text())["structure"]["limit"] is False
    # sec. 5.3.3 reproduced: trained on the sine, the unlimited model diverges on the chirp;
    # evaluate and compensate say so in one line (exit 2) and write no NaN
    code, out, err = run_cli(capsys, "evaluate", model, recordings["chirp"])
    _one_error(err, "diverged at sample", "sec. 5.3.3")
    assert code == 2 and "nan" not in out.lower()
    estimate = tmp_path / "estimate.csv"
    code, _, err = run_cli(capsys, "compensate", model, recordings["chirp"], "--out", estimate)
    assert code == 2 and "diverged at sample" in err.splitlines()[-1]
    assert not estimate.exists()


def test_clipped_start_is_reported(recordings, tmp_path, capsys):
    code, out, _ = run_cli(capsys, "fit", recordings["sine"], "--init", "table-5.2-fitted",
                        "--out", tmp_path / "m.json")
    assert code == 0
    assert "--init: log_G[1] = " in out and "outside the fit's box" in out


def test_weight_sum_max_bounds_the_saved_weights(recordings, tmp_path, capsys):
    model = tmp_path / "c.json"
    code, out, _ = run_cli(capsys, "fit", recordings["sine"], "--weight-sum-max", "1.2", "--out",
                        model)
    w = json.loads(model.read_text())["params"]["w"]
    assert_allclose(np.abs(w).sum(), 1.2, rtol=1e-8)
    assert "SLSQP under sum |w| <= 1.2 (active" in out
    assert code in (0, 3)  # the guards judge the constrained fit like any other
    # at an active constraint the SSE is not stationary: its standard errors are labelled
    caveat = json.loads(model.read_text())["fit"]["standard_errors"]["caveat"]
    assert caveat.endswith("the fit ended on its active constraint sum |w| <= 1.2, where the "
                           "SSE is not stationary")
    assert f"    ({caveat})" in out.splitlines()
    _, out, _ = run_cli(capsys, "fit", recordings["sine"], "--weight-sum-max", "100", "--out",
                     tmp_path / "free.json")
    assert "(inactive" in out and "indicative only" not in out


@pytest.mark.parametrize(("argv", "fragments"), [
    (["--model", "preisach", "--no-limit"], ("--no-limit applies to", "mpl-poly")),
    (["--model", "preisach", "--weight-sum-max", "100"], ("--weight-sum-max applies to mpl",)),
    (["--model", "mpl-poly", "--weight-sum-max", "100"], ("not 'mpl-poly'",)),
    (["--model", "pi", "--init", "table-5.2"], ("--init applies to mpl",)),
    (["--init", "i_s=0.1"], ("missing v_t, w, v_b",)),
    (["--weight-sum-max", "0"], ("--weight-sum-max",)),
    (["--init", "i_s=nan,v_t=0.2,w=1:0.4,v_b=-0.6"], ("error: --init: i_s must be finite",)),
])
def test_bad_options_exit_2_with_one_line(recordings, tmp_path, capsys, argv, fragments):
    code, _, err = run_cli(capsys, "fit", recordings["sine"], *argv, "--out", tmp_path / "m.json")
    assert code == 2
    _one_error(err, *fragments)
    assert not (tmp_path / "m.json").exists()
