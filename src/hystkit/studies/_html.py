"""One self-contained HTML page: CSS inline, figures as ``data:`` PNG, nothing loaded from outside.

A page is a title and a list of sections; a section holds blocks of HTML built by the helpers
here (paragraphs, tables, figures, notes), every text escaped. No template engine, no script:
the page must open from a mail attachment or an archive, years later, with no network.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from matplotlib.figure import Figure

__all__ = ["Section", "definition_list", "figure_png", "note", "number", "paragraph",
           "png_block", "render_page", "table"]

# Plain system fonts only: a web font would be a load from outside.
_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       margin: 0 auto; max-width: 1240px; padding: 1em 1.5em; color: #1b1b1b;
       background: #fff; line-height: 1.4; }
h1 { font-size: 1.6em; border-bottom: 2px solid #345; padding-bottom: 0.2em; }
h2 { font-size: 1.25em; margin-top: 1.6em; border-bottom: 1px solid #bbb; }
h3 { font-size: 1.05em; margin-top: 1.2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: right; }
th { background: #eef2f6; }
td.text, th.text { text-align: left; }
tr.oracle td { color: #666; font-style: italic; }
.note { background: #fff7e0; border-left: 4px solid #e0a800; padding: 0.4em 0.8em; }
.bad { background: #fdecea; border-left: 4px solid #c62828; padding: 0.4em 0.8em; }
.good { background: #eaf6ec; border-left: 4px solid #2e7d32; padding: 0.4em 0.8em; }
figure { margin: 0.8em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
dl { display: grid; grid-template-columns: max-content auto; gap: 0.15em 1em; }
dt { font-weight: 600; }
dd { margin: 0; }
footer { margin-top: 2em; font-size: 0.85em; color: #666; }
"""


@dataclass
class Section:
    """A heading (level 2, or 3 with ``sub``) and its blocks of HTML, in order."""

    title: str
    blocks: list[str] = field(default_factory=list)
    sub: bool = False

    def add(self, *blocks: str) -> Section:
        self.blocks.extend(blocks)
        return self

    def to_html(self) -> str:
        tag = "h3" if self.sub else "h2"
        return f"<section><{tag}>{html.escape(self.title)}</{tag}>\n" + "\n".join(
            self.blocks) + "</section>"


def number(value: object, spec: str = ".4f") -> str:
    """A table cell's text: numbers formatted by `spec`, None as "–" (undefined), bools as
    yes / no, anything else as text."""
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return format(value, spec)
    return str(value)


def paragraph(text: str) -> str:
    return f"<p>{html.escape(text)}</p>"


def note(text: str, kind: str = "note") -> str:
    """A highlighted paragraph: ``note`` (caution), ``bad`` (a failure), ``good``."""
    return f'<p class="{kind}">{html.escape(text)}</p>'


def definition_list(items: Iterable[tuple[str, object]]) -> str:
    rows = "".join(f"<dt>{html.escape(k)}</dt><dd>{html.escape(number(v))}</dd>"
                   for k, v in items)
    return f"<dl>{rows}</dl>"


def table(header: Sequence[str], rows: Iterable[Sequence[object]], *, spec: str = ".4f",
          text_columns: int = 1, row_classes: Sequence[str] | None = None) -> str:
    """An HTML table; the first `text_columns` columns are left-aligned text, numbers go
    through :func:`number`. ``row_classes`` (e.g. ``"oracle"``) style whole rows."""
    def cell(tag: str, i: int, value: object) -> str:
        css = ' class="text"' if i < text_columns else ""
        return f"<{tag}{css}>{html.escape(number(value, spec))}</{tag}>"

    head = "<tr>" + "".join(cell("th", i, h) for i, h in enumerate(header)) + "</tr>"
    body = []
    for k, row in enumerate(rows):
        css = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        body.append(f"<tr{css}>" + "".join(cell("td", i, v) for i, v in enumerate(row))
                    + "</tr>")
    return f"<table>{head}{''.join(body)}</table>"


def figure_png(fig: Figure, dpi: int = 100) -> bytes:
    """The figure as PNG bytes (Agg, via the Figure itself: no pyplot, no global state)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def png_block(png: bytes, caption: str, alt: str | None = None) -> str:
    """A figure from PNG bytes, embedded as a ``data:`` URI."""
    if not png.startswith(b"\x89PNG\r\n\x1a\n"):
        raise ValueError("png_block needs PNG bytes")
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure><img alt="{html.escape(alt or caption)}" '
            f'src="data:image/png;base64,{data}"><figcaption>{html.escape(caption)}'
            f"</figcaption></figure>")


def render_page(title: str, sections: Iterable[Section], footer: str = "") -> str:
    """The whole page as one string: inline CSS, no script, no external reference."""
    body = "\n".join(s.to_html() for s in sections)
    foot = f"<footer>{html.escape(footer)}</footer>" if footer else ""
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head>\n"
            f"<body><h1>{html.escape(title)}</h1>\n{body}\n{foot}</body></html>\n")
