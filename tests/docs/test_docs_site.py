"""The documentation site builds with warnings as errors (issue 30).

One build, as ``docs/index.md`` documents it (``python -m sphinx -W --keep-going -b html docs
OUT``, here from a copy of ``docs/`` into a temporary folder), then what it must show: the API
pages of ``fit_compensator``, ``Stream`` and ``CompensatorEstimator``, a section per subcommand that
``hystkit --help`` lists, the tutorial and every example script run by sphinx-gallery with
their output and figures (an example that raises fails the build), and no link to a missing
page. A Sphinx
warning, a broken cross-reference (``nitpicky``) or a page the build leaves out fails it.
Skipped when the docs packages are not installed (``pip install ".[docs]"``; the ``test``
extra brings them).
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PACKAGES = ("sphinx", "numpydoc", "myst_parser", "pydata_sphinx_theme", "sphinx_gallery")
MISSING = [name for name in PACKAGES if importlib.util.find_spec(name) is None]

pytestmark = pytest.mark.skipif(
    bool(MISSING), reason=f"the docs packages are not installed ({', '.join(MISSING)}): "
                          "pip install '.[docs]'")

_LINK = re.compile(r'(?:href|src)="([^"]+)"')
_ID = re.compile(r'\bid="([^"]+)"')


# What a build writes into its source folder (the API pages, sphinx-gallery's pages): left out
# of the copy the test builds from, so a build never sees an earlier one's pages.
GENERATED = frozenset({"_build", "gallery", "tutorial", "reference/api", "sg_execution_times.rst"})


def _generated(folder: str, names: list[str]) -> list[str]:
    return [n for n in names if (Path(folder) / n).relative_to(DOCS).as_posix() in GENERATED]


def source_copy(root: Path) -> Path:
    """``docs/`` copied into `root`, the repository's other entries linked beside it (the pages
    link to ``../examples`` and ``../benchmarks``): the build writes into the copy, never into
    the checkout, so two test runs at once (``pytest -n``, two checkouts) cannot collide."""
    root.mkdir()
    for entry in ROOT.iterdir():
        if entry.name != "docs" and not entry.name.startswith("."):
            (root / entry.name).symlink_to(entry)
    shutil.copytree(DOCS, root / "docs", ignore=_generated)
    return root / "docs"


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The built site's HTML folder; the build's output is in the failure message."""
    out = tmp_path_factory.mktemp("site")
    docs = source_copy(out / "source")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html",
         "-d", str(out / "doctrees"), str(docs), str(out / "html")],
        capture_output=True, text=True, timeout=900, check=False, cwd=ROOT)
    problems = [line for line in (proc.stdout + proc.stderr).splitlines()
                if "WARNING" in line or "ERROR" in line]
    assert proc.returncode == 0 and not problems, "\n".join(problems) or proc.stderr[-3000:]
    return out / "html"


def test_api_pages_name_the_main_objects(site):
    generated = site / "reference" / "api" / "generated"
    for name in ("hystkit.compensation.fit_compensator", "hystkit.live.Stream",
                 "hystkit.compensation.CompensatorEstimator"):
        page = generated / f"{name}.html"
        assert page.is_file(), f"no API page {page.name}"
        assert name.rpartition(".")[2] in page.read_text(encoding="utf-8")
    top = (site / "reference" / "api" / "hystkit.html").read_text(encoding="utf-8")
    for name in ("read", "fit", "evaluate", "compensate", "compare", "load", "save"):
        assert f"hystkit.{name}.html" in top, f"hystkit.{name} missing from the API reference"
    assert not list(generated.glob("hystkit._*")), "a private module's page"


def test_cli_reference_has_every_subcommand(site):
    from hystkit.cli._main import _parser

    page = (site / "reference" / "cli.html").read_text(encoding="utf-8")
    sections = set(re.findall(r'<section id="cli-([^"]+)"', page))

    def commands(parser: argparse.ArgumentParser, prefix: str) -> list[str]:
        sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)),
                   None)
        if sub is None:
            return []
        found = []
        for name, child in sub.choices.items():
            found += [f"{prefix}{name}", *commands(child, f"{prefix}{name} ")]
        return found

    expected = commands(_parser(), "")
    assert len(expected) > 20
    missing = [c for c in expected
               if re.sub(r"[^a-z0-9]+", "-", c.lower()).strip("-") not in sections]
    assert not missing, f"subcommands missing from the CLI reference: {missing}"
    assert "--columns" in page and "--slope-cap" in page  # options, with their help


def test_gallery_and_tutorial_are_run_with_their_figures(site):
    """Every script of examples/ has its gallery page; those the build runs (conf.py's
    filename_pattern) show their output and figures, the others say why they are not run;
    the tutorial runs and shows the figures it makes."""
    sys.path.insert(0, str(DOCS))
    try:
        conf = importlib.import_module("conf")
    finally:
        sys.path.remove(str(DOCS))
    pattern = re.compile(conf.sphinx_gallery_conf["filename_pattern"])
    scripts = sorted((ROOT / "examples").glob("*.py"))
    assert scripts
    index = (site / "gallery" / "index.html").read_text(encoding="utf-8")
    run = 0
    for script in scripts:
        page = site / "gallery" / f"{script.stem}.html"
        assert page.is_file(), f"no gallery page for {script.name}"
        assert f"{script.stem}.html" in index, f"{script.name} missing from the gallery index"
        html = page.read_text(encoding="utf-8")
        if pattern.search(f"/{script.name}"):
            run += 1
            assert "sphx-glr-script-out" in html or "sphx-glr-single-img" in html, \
                f"{script.name} is run by the build but shows no output"
        else:
            assert "Not run when the site is built" in html, \
                f"{script.name} is not run by the build and does not say why"
    assert run >= 3
    figures = [p for p in (site / "_images").glob("sphx_glr_plot_*") if p.suffix == ".png"]
    assert len(figures) >= 3, "the plot_ examples made no figures"
    tutorial = (site / "tutorial" / "plot_first_recording.html").read_text(encoding="utf-8")
    assert tutorial.count("sphx-glr-single-img") >= 4, "the tutorial's figures are missing"
    for command in ("hystkit fit", "hystkit evaluate", "hystkit select", "hystkit compensate",
                    "hystkit report"):
        assert f"$ {command} " in tutorial, f"the tutorial's output of {command} is missing"


def test_every_page_is_built_and_no_link_is_broken(site):
    sources = {p.relative_to(DOCS).with_suffix("").as_posix() for p in DOCS.rglob("*.md")
               if "_build" not in p.parts}
    sources |= {f"gallery/{p.stem}" for p in (ROOT / "examples").glob("*.py")}
    sources |= {f"tutorial/{p.stem}" for p in (DOCS / "tutorial_src").glob("*.py")}
    built = {p.relative_to(site).with_suffix("").as_posix() for p in site.rglob("*.html")}
    assert not sources - built, f"pages left out of the site: {sorted(sources - built)}"
    broken, anchors = broken_links(site)
    assert anchors > 100  # the check ran: the API and CLI pages alone link hundreds of sections
    assert not broken, "broken internal links:\n" + "\n".join(broken[:20])


def broken_links(site: Path) -> tuple[list[str], int]:
    """The internal links of `site`'s pages to a missing file or to no element of the page
    they point to (``page -> target``), and how many links to a section anchor were checked.

    A link's verdict depends only on its page's folder (on the page itself for ``#...`` and
    ``?...``): the sidebar's ~600 links repeat on every API page, so each is checked once per
    folder."""
    ids: dict[Path, set[str]] = {}
    verdicts: dict[tuple[Path, str], tuple[bool, str]] = {}
    broken, anchors = [], 0
    for page in (p for p in site.rglob("*.html") if "_static" not in p.parts):
        for target in _LINK.findall(page.read_text(encoding="utf-8")):
            key = (page if target.startswith(("#", "?")) else page.parent, target)
            if key not in verdicts:
                verdicts[key] = _link_verdict(page, target, ids)
            is_anchor, problem = verdicts[key]
            anchors += is_anchor
            if problem:
                broken.append(f"{page.relative_to(site)} -> {target}{problem}")
    return broken, anchors


def _link_verdict(page: Path, target: str, ids: dict[Path, set[str]]) -> tuple[bool, str]:
    """Whether `target` (a link on `page`) points to a section anchor of a page, and what is
    wrong with it: "" (nothing, or a link this check leaves alone: another site, no path nor
    anchor), " (no such file)" or " (no such anchor)"."""
    parsed = urlparse(target)
    if parsed.scheme or parsed.netloc or not (parsed.path or parsed.fragment):
        return False, ""
    dest = page.parent / unquote(parsed.path) if parsed.path else page
    if not dest.exists():
        return False, " (no such file)"
    if not (parsed.fragment and dest.suffix == ".html"):
        return False, ""
    # a section anchor (#...) must name an element of the page it points to
    if dest not in ids:
        ids[dest] = set(_ID.findall(dest.read_text(encoding="utf-8")))
    return True, "" if unquote(parsed.fragment) in ids[dest] else " (no such anchor)"


def test_broken_links_finds_missing_pages_and_anchors(tmp_path):
    """The link check on a small site: sound links pass, a missing page and an anchor no
    element has are reported, on each page that has them."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "index.html").write_text(
        '<h1 id="top">x</h1><a href="sub/a.html#sec">ok</a> <a href="#top">ok</a> '
        '<a href="https://example.org/gone.html">elsewhere</a> <img src="sub/a.html">'
        '<a href="sub/gone.html">missing</a> <a href="sub/a.html#nowhere">bad anchor</a>',
        encoding="utf-8")
    (tmp_path / "sub" / "a.html").write_text(
        '<p id="sec">a</p><a href="../index.html#top">ok</a> <a href="#sec">ok</a> '
        '<a href="#top">bad anchor</a> <a href="gone.html">missing</a>', encoding="utf-8")
    (tmp_path / "sub" / "b.html").write_text(
        '<p id="top">b</p><a href="#top">ok here</a> <a href="gone.html">missing</a>',
        encoding="utf-8")
    broken, anchors = broken_links(tmp_path)
    assert sorted(broken) == ["index.html -> sub/a.html#nowhere (no such anchor)",
                              "index.html -> sub/gone.html (no such file)",
                              "sub/a.html -> #top (no such anchor)",
                              "sub/a.html -> gone.html (no such file)",
                              "sub/b.html -> gone.html (no such file)"]
    assert anchors == 7
