"""``hystkit report`` of result folders written by the real commands: compare, generalize,
select --report and control. The page's tables hold the folders' numbers, figures are drawn on
an honest scale, a control run's own figures are embedded byte for byte."""

from __future__ import annotations

import base64
import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest

from hystkit.cli import cmd_select, main
from hystkit.errors import InputError
from hystkit.io import Recording, write_recording
from hystkit.sensors import simulate_experiment
from hystkit.studies import Candidate, build_report, write_report
from hystkit.studies._report_control import stability_verdict
from hystkit.studies._report_folders import folder_kind, plot_unexplained

from .screenshots import n_close, n_colours, needs_chromium, screenshot

N_SHORT = 2400  # 60 s at 40 Hz: enough for every fold of select, quick to fit


class Tables(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list) -> None:
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)


def tables(page: str) -> list[list[list[str]]]:
    parser = Tables()
    parser.feed(page)
    return parser.tables


def _short(name: str, seed: int) -> Recording:
    rec = simulate_experiment(name, seed)
    return Recording(time=rec.time[:N_SHORT], sensor=rec.sensor[:N_SHORT],
                     position=rec.position[:N_SHORT])


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Output folders of the four commands, run through ``main`` on short recordings."""
    root = tmp_path_factory.mktemp("folders")
    fit = write_recording(_short("sine", 1), root / "fit.csv")
    val = write_recording(_short("chirp", 2), root / "val.csv")
    out = {name: root / name for name in ("cmp", "gen", "sel", "ctl")}
    assert main(["compare", str(fit), str(val), "--models", "mpl,pi", "--out",
                 str(out["cmp"])]) == 0
    assert main(["generalize", str(fit), str(val), "--models", "mpl", "--out",
                 str(out["gen"])]) == 0
    with pytest.MonkeyPatch.context() as patch:  # two candidates instead of every family
        # the name select calls (imported at the top of cmd_select): patching the package's
        # would leave this process's select with two candidates for every later test
        patch.setattr(cmd_select, "candidates", lambda *a, **k: [
            Candidate("mpl", 1, "direct", "fit"), Candidate("mpl", 2, "direct", "fit")])
        assert main(["select", str(fit), "--out", str(root / "sel.json"), "--report",
                     str(out["sel"]), "--workers", "1"]) == 0  # serial: no cluster to start
    assert main(["control", "--scheme", "direct", "--experiment", "sine", "--bode", "--out",
                 str(out["ctl"])]) == 0
    return out


@pytest.fixture(scope="module")
def page(folders: dict[str, Path]) -> Path:
    content = build_report(list(folders.values()))
    return write_report(content, folders["cmp"].parent / "folders.html")[0]


def test_each_folder_is_recognised(folders: dict[str, Path], tmp_path: Path) -> None:
    assert {name: folder_kind(f) for name, f in folders.items()} == {
        "cmp": "compare", "gen": "generalize", "sel": "select", "ctl": "control"}
    with pytest.raises(InputError, match="not a result folder"):
        folder_kind(tmp_path)


def test_compare_table_holds_compare_json(folders: dict[str, Path], page: Path) -> None:
    data = json.loads((folders["cmp"] / "compare.json").read_text(encoding="utf-8"))
    found = next(t for t in tables(page.read_text(encoding="utf-8"))
                 if t[0][:4] == ["model", "params", "fit s", "R² fwd"])
    for row in found[1:]:
        m = data[row[0]]
        assert [float(x) for x in row[3:7]] == pytest.approx(
            [m["r2_forward"], m["r2_compensated"], m["r2_direct"], m["linear_r2"]], abs=5e-5)


def test_generalize_tables_hold_both_grids(folders: dict[str, Path], page: Path) -> None:
    data = json.loads((folders["gen"] / "generalize.json").read_text(encoding="utf-8"))
    grids = [t for t in tables(page.read_text(encoding="utf-8")) if t[0][0] == "trained on"]
    assert len(grids) == 2  # mpl deployable, then oracle
    for grid, key in zip(grids, ("r2", "r2_oracle")):
        assert grid[0][1:] == ["fit", "val"]
        for row in grid[1:]:
            expected = [data["mpl"][key][row[0]][t] for t in ("fit", "val")]
            assert [float(x) for x in row[1:]] == pytest.approx(expected, abs=5e-5)


def test_select_names_the_winner_and_ranks(folders: dict[str, Path], page: Path) -> None:
    data = json.loads((folders["sel"] / "selection.json").read_text(encoding="utf-8"))
    text = page.read_text(encoding="utf-8")
    assert f"winner: {data['winner']['candidate']}" in text
    ranking = next(t for t in tables(text) if t[0][:2] == ["candidate", "held-out R²"])
    assert [r[0] for r in ranking[1:]] == [r["candidate"] for r in data["ranking"]]
    assert [float(r[1]) for r in ranking[1:]] == pytest.approx(
        [r["cv_r2"] for r in data["ranking"]], abs=5e-5)


def test_control_figures_are_the_runs_own_files(folders: dict[str, Path], page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    embedded = [base64.b64decode(m) for m in
                re.findall(r'src="data:image/png;base64,([^"]+)"', text)]
    for name in ("response.png", "bode.png"):
        assert (folders["ctl"] / name).read_bytes() in embedded, name
    metrics = json.loads((folders["ctl"] / "metrics.json").read_text(encoding="utf-8"))
    verdict, _ = stability_verdict(metrics["linear"])
    assert verdict in text
    cases = next(t for t in tables(text) if t[0][0] == "case")
    assert float(cases[1][1]) == pytest.approx(metrics["cases"]["sine"]["e_p_max"], rel=2e-3)


def test_stability_verdicts() -> None:
    assert stability_verdict({"closed_loop_stable": True}) == (
        "closed loop stable (linearised at rest)", "good")
    text, kind = stability_verdict({"closed_loop_stable": False, "marginal": True})
    assert kind == "note" and text.startswith("closed loop marginally stable")
    text, kind = stability_verdict({"closed_loop_stable": False, "marginal": False,
                                    "max_pole_radius": 1.25, "growth_time_s": 0.0123})
    assert kind == "bad"
    assert text == ("closed loop UNSTABLE (linearised at rest): max |pole| 1.2500000000, grows "
                    "e-fold in 0.0123 s")


def test_unexplained_plot_puts_each_r2_at_one_minus_r2_on_a_log_axis() -> None:
    values = {"a": {"model": 0.998, "line": 0.94}, "b": {"model": -2390.0, "line": None},
              "c": {"model": 0.999999, "line": 0.5}}
    fig = plot_unexplained(list(values.items()), "1 - R²")
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    model, line = ax.get_lines()[:2]
    assert model.get_xdata() == pytest.approx([0.002, 2391.0, 1e-4])  # floor at 1e-4
    assert line.get_xdata() == pytest.approx([0.06, 0.5])  # None is left out
    labels = sorted(t.get_text() for t in ax.texts)
    assert labels == sorted(["0.998", "-2390", "1", "0.94", "0.5"])


def test_a_damaged_result_file_is_one_error_naming_the_folder(
        folders: dict[str, Path], tmp_path: Path) -> None:
    broken = tmp_path / "cmp"
    shutil.copytree(folders["cmp"], broken)
    data = json.loads((broken / "compare.json").read_text(encoding="utf-8"))
    del data["mpl"]["r2_direct"]
    (broken / "compare.json").write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(InputError, match=rf"{re.escape(str(broken))}: its compare result "
                                         r"cannot be read \(KeyError"):
        build_report([broken])
    (broken / "compare.json").write_text("{not json", encoding="utf-8")
    with pytest.raises(InputError, match="compare.json: not JSON"):
        build_report([broken])


@needs_chromium
def test_chromium_renders_the_folders_page(page: Path, tmp_path: Path) -> None:
    shot = tmp_path / "folders.png"
    pixels = screenshot(page, shot, 6000)
    assert n_colours(pixels) > 2000
    # viridis cells of the generalisation matrix and the Bode plot's blue trace
    for rgb in ((31, 119, 180),):
        assert n_close(pixels, rgb) > 2000


def test_a_loop_unstable_only_over_days_is_a_note_not_a_failure() -> None:
    text, kind = stability_verdict({"closed_loop_stable": False, "marginal": False,
                                    "max_pole_radius": 1.0000000006, "growth_time_s": 8.1e5})
    assert kind == "note" and text.startswith("closed loop unstable only over days")
    assert "a factor 1.0004 over a 5-minute run" in text
