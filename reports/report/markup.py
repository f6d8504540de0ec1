"""HTML of the report: tables, number formatting, swatches, navigation and the page frame."""

from __future__ import annotations

import datetime
import html

import numpy as np

from gonio.jsonplain import plain
from reports.colour import fabric_colour

__all__ = ["plain_json", "table", "fmt", "swatch", "nav", "page", "now", "not_available"]

_CSS = """
body{font-family:system-ui,sans-serif;max-width:1400px;margin:1em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
section{display:grid;grid-template-columns:repeat(auto-fill,minmax(min(100%,560px),1fr));
gap:.4em 1.2em;align-items:start}section>:not(figure){grid-column:1/-1}
figure{margin:0;min-width:0}
figure a{display:block;cursor:zoom-in}figure img{width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.85em;color:#555}
table{border-collapse:collapse;font-size:.9em;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .5em}
th{background:#f4f4f4}.na{color:#a33}nav a{margin-right:1em}.swatch{display:inline-block;width:1em;
height:1em;border:1px solid #999;vertical-align:middle;margin-right:.3em}
"""


def plain_json(obj):
    """Strict-JSON data of ``obj`` (NaN and infinities as null): :func:`gonio.jsonplain.plain`."""
    return plain(obj, nonfinite="null")


def table(header, rows) -> str:
    """An HTML table of ``rows`` (sequences of cells) under ``header``; cells are escaped.

    Examples
    --------
    >>> table(["a"], [[1]])
    '<table><thead><tr><th>a</th></tr></thead><tbody><tr><td>1</td></tr></tbody></table>'
    """
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def fmt(v) -> str:
    """A value as short text: floats to 4 significant digits, sequences in parentheses.

    Examples
    --------
    >>> fmt([1.0, 2.123456]), fmt("x")
    ('(1, 2.123)', 'x')
    """
    if isinstance(v, (list, tuple, np.ndarray)):
        return "(" + ", ".join(fmt(x) for x in v) + ")"
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.4g}"
    return str(v)


def not_available(reason: str) -> str:
    """The paragraph a section shows when it cannot be built for a fabric."""
    return f'<p class="na">Not available: {html.escape(reason)}</p>'


def swatch(fab) -> str:
    """A square in the fabric's sRGB colour (:func:`reports.colour.fabric_colour`)."""
    r, g, b = (int(round(255 * c)) for c in fabric_colour(fab))
    return f'<span class="swatch" style="background:rgb({r},{g},{b})"></span>'


def nav(names, current=None, measured=False) -> str:
    """Links to the overview, every fabric page and (when present) the measured-fits page."""
    links = ['<a href="index.html">overview</a>']
    for n in names:
        label = f"<b>{html.escape(n)}</b>" if n == current else html.escape(n)
        links.append(f'<a href="{html.escape(n)}.html">{label}</a>')
    if measured:
        label = "<b>measured fits</b>" if current == "measured" else "measured fits"
        links.append(f'<a href="measured.html">{label}</a>')
    return "".join(links)


def now() -> str:
    """The current time, UTC, to the minute."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def page(title: str, nav_html: str, body: str) -> str:
    """A whole HTML page: title, navigation, body and a dated footer."""
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
            f"<nav>{nav_html}</nav><h1>{html.escape(title)}</h1>{body}"
            f"<footer><p><small>microcyl report, {html.escape(now())}</small></p></footer>"
            f"</body></html>\n")
