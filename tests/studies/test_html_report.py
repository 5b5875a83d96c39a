"""``hystkit report`` of a model file on recordings: the page's numbers are evaluate()'s and the
fit's, the page is self-contained, and headless Chromium renders it (not blank) without asking
for anything but the page."""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from hystkit.compensation import evaluate, fit_compensator, load_compensator, save_compensator
from hystkit.io import write_recording
from hystkit.sensors import simulate_experiment
from hystkit.studies import build_report, write_report
from hystkit.studies._html import Section, render_page, table
from hystkit.studies._report_model import named_parameters

from .screenshots import n_close, n_colours, needs_chromium, screenshot


class PageParser(HTMLParser):
    """Tables (rows of cell texts), every attribute value, and the text of <style>/<script>."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self.attributes: list[tuple[str, str, str]] = []
        self.tags: set[str] = set()
        self.style = ""
        self._cell: list[str] | None = None
        self._in_style = False

    def handle_starttag(self, tag: str, attrs: list) -> None:
        self.tags.add(tag)
        self.attributes += [(tag, name, value or "") for name, value in attrs]
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []
        self._in_style = tag == "style"

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None
        if tag == "style":
            self._in_style = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)
        if self._in_style:
            self.style += data


def parse(page: str) -> PageParser:
    parser = PageParser()
    parser.feed(page)
    return parser


def external_references(page: str) -> list[str]:
    """Every reference the page could load: src/href/srcset/poster/data attributes and CSS
    url() / @import, except data: URIs and in-page anchors."""
    parser = parse(page)
    refs = [value for _, name, value in parser.attributes
            if name in ("src", "href", "srcset", "poster", "data", "action", "background")]
    refs += re.findall(r"url\(\s*['\"]?([^'\")]+)", parser.style)
    refs += ["@import" for _ in re.finditer(r"@import", parser.style)]
    return [r for r in refs if not r.startswith(("data:", "#"))]


def render_logged(page: Path, tmp_path: Path) -> tuple[np.ndarray, list[str]]:
    """One Chromium run of `page`: its screenshot (1280 x 4000 px, RGB pixels) and the URLs
    the page itself asked for meanwhile, from Chromium's net log.

    The page's requests carry its (opaque, file://) origin as initiator, "null"; the browser's
    own background requests say "not an origin". Data URIs never reach the network stack.
    """
    log = tmp_path / f"{page.stem}-net.json"
    shot = screenshot(page, tmp_path / f"{page.stem}-shot.png", 4000, f"--log-net-log={log}")
    events = json.loads(log.read_text(encoding="utf-8"))
    names = {v: k for k, v in events["constants"]["logEventTypes"].items()}
    return shot, [e["params"]["url"] for e in events["events"]
                  if names[e["type"]] == "URL_REQUEST_START_JOB" and "url" in e.get("params", {})
                  and e["params"].get("initiator") != "not an origin"]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """A 1-cell model fitted on the sine (seed 1), its file, and two validation recordings."""
    folder = tmp_path_factory.mktemp("report")
    comp = fit_compensator(simulate_experiment("sine", 1), 1)
    model = save_compensator(comp, folder / "model.json")
    recs = {}
    for name in ("sine", "chirp"):
        recs[f"{name}.csv"] = rec = simulate_experiment(name, 2)
        write_recording(rec, folder / f"{name}.csv")
    return {"folder": folder, "model": model, "recordings": recs,
            "comp": load_compensator(model)}


@pytest.fixture(scope="module")
def page(fitted: dict) -> Path:
    folder = fitted["folder"]
    content = build_report([fitted["model"], *(folder / n for n in fitted["recordings"])])
    return write_report(content, folder / "report.html")[0]


@pytest.fixture(scope="module")
def rendered(page: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[np.ndarray, list]:
    """The report rendered once by Chromium (a start costs seconds): screenshot, requests."""
    return render_logged(page, tmp_path_factory.mktemp("rendered"))


def _rows(tables: list, header_start: tuple[str, ...]) -> list[list[list[str]]]:
    return [t for t in tables if tuple(t[0][:len(header_start)]) == header_start]


def test_scores_are_evaluates_deployable_first_then_oracle(fitted: dict, page: Path) -> None:
    tables = _rows(parse(page.read_text(encoding="utf-8")).tables, ("recording", "", "R²"))
    assert len(tables) == 2  # deployable, then oracle
    html_text = page.read_text(encoding="utf-8")
    assert html_text.index("Deployable: centring fit") < html_text.index("Oracle: centring "
                                                                         "recording (oracle)")
    for table_rows, suffix in zip(tables, ("", "_oracle")):
        body = table_rows[1:]
        for name, rec in fitted["recordings"].items():
            scores = evaluate(fitted["comp"], rec)
            model_row = next(r for r in body if r[:2] == [name, "mpl"])
            line_row = next(r for r in body if r[:2] == [name, "straight line"])
            assert float(model_row[2]) == pytest.approx(scores[f"r2{suffix}"], abs=5e-5)
            assert float(line_row[2]) == pytest.approx(scores[f"linear_r2{suffix}"], abs=5e-5)
            assert float(model_row[3]) == pytest.approx(scores[f"e_rms_pct{suffix}"], abs=5e-4)
            assert float(model_row[4]) == pytest.approx(scores[f"e_max_pct{suffix}"], abs=5e-4)


def test_parameters_and_standard_errors_are_the_model_files(fitted: dict, page: Path) -> None:
    se = json.loads(fitted["model"].read_text(encoding="utf-8"))["fit"]["standard_errors"]
    # the names follow the order of the fit's vector: each name's value is the SE's value
    assert [v for _, v in named_parameters(fitted["comp"].params.to_dict())] == se["values"]
    rows = _rows(parse(page.read_text(encoding="utf-8")).tables, ("parameter",))[0]
    assert rows[0] == ["parameter", "value", "standard error", "relative"]
    assert [r[0] for r in rows[1:]] == ["i_s[0]", "v_t[0]", "w[0]", "w[1]", "v_b"]
    for row, value, error in zip(rows[1:], se["values"], se["standard_errors"]):
        assert float(row[1]) == pytest.approx(value, rel=1e-5)   # printed with 6 digits
        assert float(row[2]) == pytest.approx(error, rel=1e-5)


def test_provenance_and_status(fitted: dict, page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    assert "fit status: ok" in text and "Do not use" not in text
    for expected in ("model.json", "centring</dt><dd>fit", "written by hystkit",
                     "fit date</dt><dd>not stored in the model file", "sine.csv",
                     "mode</dt><dd>direct"):
        assert expected in text, expected


def test_a_failed_fit_and_missing_standard_errors_are_said(fitted: dict, tmp_path: Path) -> None:
    d = json.loads(fitted["model"].read_text(encoding="utf-8"))
    d["fit"]["status"], d["fit"]["status_message"] = "on_bounds", "1 parameter(s) on a bound"
    del d["fit"]["standard_errors"]
    model = tmp_path / "old.json"
    model.write_text(json.dumps(d), encoding="utf-8")
    folder = fitted["folder"]
    text = render_page("t", build_report([model, folder / "sine.csv"]).sections)
    assert "fit status: on bounds: 1 parameter(s) on a bound. Do not use this model" in text
    rows = _rows(parse(text).tables, ("parameter",))[0]
    assert {r[2] for r in rows[1:]} == {"not stored"}
    assert "Standard errors are not stored in this model file" in text


def test_the_page_loads_nothing_from_outside(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    parser = parse(text)
    assert external_references(text) == []
    assert not parser.tags & {"script", "link", "iframe", "object", "embed", "base"}
    images = [v for tag, name, v in parser.attributes if tag == "img" and name == "src"]
    assert len(images) == 2 and all(v.startswith("data:image/png;base64,") for v in images)


def test_reference_check_finds_what_it_looks_for() -> None:
    """The checker above is not vacuous: it reports each kind of outside reference."""
    page = ('<html><head><style>body{background:url("http://x/a.png")} @import "y.css";'
            '</style><link href="s.css"></head><body><img src="https://x/b.png">'
            '<img src="data:image/png;base64,AAAA"><a href="#top">t</a></body></html>')
    assert external_references(page) == ["s.css", "https://x/b.png", "http://x/a.png",
                                         "@import"]


def test_tables_escape_their_text() -> None:
    html_text = table(("a<b",), [("<script>",)])
    assert "<script>" not in html_text and "&lt;script&gt;" in html_text
    assert "<script" not in render_page("<t>", [Section("<s>").add(html_text)])


@needs_chromium
def test_chromium_renders_the_page_with_its_figures(rendered: tuple) -> None:
    pixels, _ = rendered
    colours = n_colours(pixels)
    assert colours > 2000, colours  # text alone gives a few hundred grey levels
    non_white = np.mean(np.any(pixels < 250, axis=1))
    assert non_white > 0.05, non_white
    # the figures' traces: tab:orange (the model), tab:purple (the sensor loop); text and
    # table borders are grey, so these pixels come from the embedded images only
    for rgb in ((255, 127, 14), (148, 103, 189)):
        close = n_close(pixels, rgb)
        assert close > 2000, (rgb, close)


@needs_chromium
def test_chromium_requests_nothing_for_the_page(rendered: tuple, tmp_path: Path) -> None:
    assert rendered[1] == []
    # the check sees a page's request when there is one
    canary = tmp_path / "canary.html"
    canary.write_text('<html><body><img src="http://example.invalid/a.png"></body></html>',
                      encoding="utf-8")
    assert render_logged(canary, tmp_path)[1] == ["http://example.invalid/a.png"]
