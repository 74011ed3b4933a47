"""The HTML page and its parts, for every page gyrocomp writes (the model's report, a unit's certificate, a
fleet's report, the demo's): text escaped for a page, tables, figures embedded as PNGs, and the self-contained page
around sections."""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
from dataclasses import dataclass

import numpy as np

from .._version import __version__
from ..errors import printable
from . import figures

_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
h1 { font-size: 1.6em; } h2 { border-bottom: 2px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }
th { background: #eef; } td:first-child, th:first-child, td.text { text-align: left; }
img { max-width: 100%; display: block; margin: 0.6em 0; border: 1px solid #ddd; }
.note { color: #555; font-size: 0.9em; } nav a { margin-right: 1em; }
.lead { font-size: 1.15em; }
"""


def escape_text(text: str) -> str:
    """``text`` for a page: HTML-escaped (quotes too), with control and bidirectional characters shown as escapes
    (:func:`gyrocomp.errors.printable`; a serial holding a right-to-left override is shown as it is, not reversed)."""
    return html.escape(printable(str(text), lines=True))


@dataclass(frozen=True)
class Report:
    """The report's HTML text and the ids of its sections, in order."""

    html: str
    sections: tuple[str, ...]


def _png(fig) -> str:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90)
    figures._pyplot().close(fig)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def figure_html(fig, alt: str) -> str:
    """A matplotlib figure as an ``<img>`` with the PNG inside the page (``alt`` escaped)."""
    return f'<img src="{_png(fig)}" alt="{escape_text(alt)}">'


def table_html(header: list[str], rows: list[list], caption: str | None = None) -> str:
    """A table as the report draws them (every text escaped; numbers right-aligned)."""
    out = ["<table>"]
    if caption:
        out.append(f"<caption>{escape_text(caption)}</caption>")
    out.append("<tr>" + "".join(f"<th>{escape_text(str(h))}</th>" for h in header) + "</tr>")
    for row in rows:
        out.append("<tr>" + "".join(f"<td{_cell_class(v)}>{escape_text(cell_text(v))}</td>" for v in row) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _cell_class(value) -> str:
    """Words are left-aligned, numbers (and numbers with units) right-aligned."""
    if isinstance(value, str) and value and not value.lstrip("+-")[:1].isdigit():
        return ' class="text"'
    return ""


def cell_text(value) -> str:
    """A table cell's text: a float at four significant figures, None or a non-finite float as ``-``."""
    if isinstance(value, float):
        return "-" if not np.isfinite(value) else f"{value:.4g}"
    return "-" if value is None else str(value)


def html_page(title: str, heading: str, note: str, sections: dict[str, tuple[str, str]], css: str = "") -> str:
    """A self-contained page: ``title``, the ``heading``, the time and version with ``note`` (HTML) beside them, a
    navigation bar, and ``sections`` (id -> (title, HTML body)) in order; ``css``: more style (the page's own)."""
    created = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    nav = " ".join(f'<a href="#{sid}">{escape_text(name)}</a>' for sid, (name, _) in sections.items())
    page = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{escape_text(title)}</title>",
        f"<style>{_CSS}{css}</style></head><body>",
        f"<h1>{escape_text(heading)}</h1><p class=note>{created}, gyrocomp {__version__}"
        + (f"; {note}" if note else "")
        + "</p>",
        f"<nav>{nav}</nav>",
    ]
    for sid, (name, body) in sections.items():
        page.append(f'<section id="{sid}"><h2>{escape_text(name)}</h2>\n{body}\n</section>')
    page.append("</body></html>")
    return "\n".join(page) + "\n"


__all__ = ["Report", "cell_text", "escape_text", "figure_html", "html_page", "table_html"]
