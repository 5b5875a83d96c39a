"""The demo's report.html: the numbers of metrics.json, the figures of loops.png and
time_series.png, every fit, and nothing loaded from outside."""

from __future__ import annotations

import base64
import json
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from hystkit.studies import DEMO_FILES, run_demo
from hystkit.studies._demo import REPORT_DEMO_FILES

from .screenshots import n_close, n_colours, needs_chromium, screenshot


class Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self.refs: list[str] = []
        self.tags: set[str] = set()
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list) -> None:
        self.tags.add(tag)
        self.refs += [v or "" for k, v in attrs if k in ("src", "href", "srcset", "data")]
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


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("demo") / "demo"
    run_demo(out, n_cells=1, report=True, progress=lambda _: None)
    return out


def test_demo_writes_its_report_beside_its_files(demo: Path) -> None:
    assert sorted(p.name for p in demo.iterdir()) == sorted(DEMO_FILES + REPORT_DEMO_FILES)


def test_demo_page_holds_metrics_json(demo: Path) -> None:
    metrics = json.loads((demo / "metrics.json").read_text(encoding="utf-8"))
    page = Page()
    page.feed((demo / "report.html").read_text(encoding="utf-8"))
    deployable, oracle = [t for t in page.tables if t[0][:2] == ["excitation", "mPL R²"]][:2]
    for rows, suffix in ((deployable, ""), (oracle, "_oracle")):
        assert [r[0] for r in rows[1:]] == list(metrics)
        for row in rows[1:]:
            m = metrics[row[0]]
            assert float(row[1]) == pytest.approx(m[f"r2{suffix}"], abs=5e-5)
            assert float(row[2]) == pytest.approx(m[f"linear_r2{suffix}"], abs=5e-5)
            assert float(row[3]) == pytest.approx(m[f"e_rms_pct{suffix}"], abs=5e-3)
    # one fit report per excitation, with its parameters
    assert len([t for t in page.tables if t[0][0] == "parameter"]) == len(metrics)


def test_demo_page_embeds_the_figure_files_and_nothing_else(demo: Path) -> None:
    text = (demo / "report.html").read_text(encoding="utf-8")
    page = Page()
    page.feed(text)
    assert all(r.startswith("data:image/png;base64,") for r in page.refs) and page.refs
    assert not page.tags & {"script", "link", "iframe", "object", "embed"}
    embedded = [base64.b64decode(m) for m in
                re.findall(r'src="data:image/png;base64,([^"]+)"', text)]
    assert embedded == [(demo / n).read_bytes() for n in ("loops.png", "time_series.png")]


@needs_chromium
def test_chromium_renders_the_demo_page(demo: Path, tmp_path: Path) -> None:
    shot = tmp_path / "demo.png"
    pixels = screenshot(demo / "report.html", shot, 5000)
    assert n_colours(pixels) > 2000
    for rgb in ((255, 127, 14), (148, 103, 189)):  # mPL traces, sensor loops
        assert n_close(pixels, rgb) > 2000, rgb
