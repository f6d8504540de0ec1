"""HTML of the report: tables, number formatting, swatches, navigation and the page frame.

Every value reaches a page through :mod:`reports.safehtml` (escaped text in literal
templates); the builders here return :class:`~reports.safehtml.Markup`, and :func:`page`
escapes a body that is not Markup.
"""

from __future__ import annotations

import datetime

import numpy as np

from gonio.jsonplain import plain
from reports.colour import fabric_colour
from reports.safehtml import Markup, html, join, table, text, url

__all__ = ["plain_json", "table", "fmt", "swatch", "nav", "page", "now", "not_available",
           "html", "join", "text", "url", "Markup"]

_CSS = Markup("""
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
""")


def plain_json(obj):
    """Strict-JSON data of ``obj`` (NaN and infinities as null): :func:`gonio.jsonplain.plain`."""
    return plain(obj, nonfinite="null")


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


def not_available(reason: str) -> Markup:
    """The paragraph a section shows when it cannot be built for a fabric.

    Examples
    --------
    >>> not_available("no <fit>")
    Markup('<p class="na">Not available: no &lt;fit&gt;</p>')
    """
    return html('<p class="na">Not available: {}</p>', reason)


def swatch(fab) -> Markup:
    """A square in the fabric's sRGB colour (:func:`reports.colour.fabric_colour`)."""
    r, g, b = (int(round(255 * c)) for c in fabric_colour(fab))
    return html('<span class="swatch" style="background:rgb({},{},{})"></span>', r, g, b)


def nav(names, current=None, measured=False) -> Markup:
    """Links to the overview, every fabric page and (when present) the measured-fits page.

    Examples
    --------
    >>> nav(["a:b"], "a:b")
    Markup('<a href="index.html">overview</a><a href="a%3Ab.html"><b>a:b</b></a>')
    """
    links = [Markup('<a href="index.html">overview</a>')]
    for n in names:
        label = html("<b>{}</b>", n) if n == current else text(n)
        links.append(html('<a href="{}">{}</a>', url(f"{n}.html"), label))
    if measured:
        label = (Markup("<b>measured fits</b>") if current == "measured"
                 else Markup("measured fits"))
        links.append(html('<a href="measured.html">{}</a>', label))
    return join(links)


def now() -> str:
    """The current time, UTC, to the minute."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def page(title: str, nav_html: Markup, body: Markup) -> str:
    """A whole HTML page: title, navigation, body and a dated footer.

    ``nav_html`` and ``body`` are Markup (a plain ``str`` is shown as text, escaped).

    Examples
    --------
    >>> "<h1>a&lt;b</h1>&lt;p&gt;" in page("a<b", Markup(""), "<p>")
    True
    """
    return str(html('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                    "<title>{title}</title><style>{css}</style></head><body>"
                    "<nav>{nav}</nav><h1>{title}</h1>{body}"
                    "<footer><p><small>microcyl report, {now}</small></p></footer>"
                    "</body></html>\n", title=title, css=_CSS, nav=nav_html, body=body,
                    now=now()))
