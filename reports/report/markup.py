"""HTML of the report: tables, number formatting, swatches, navigation and the page frame.

Every value reaches a page through :mod:`reports.safehtml` (escaped text in literal
templates); the builders here return :class:`~reports.safehtml.Markup`, and :func:`page`
escapes a body that is not Markup.
"""

from __future__ import annotations

import datetime
import importlib.metadata
from importlib import resources

import numpy as np

from gonio.jsonplain import plain
from reports.safehtml import Markup, html, join, table, text, url

__all__ = ["plain_json", "table", "fmt", "swatch", "nav", "page", "now", "not_available",
           "html", "join", "text", "url", "Markup", "CSS_NAME", "stylesheet", "version",
           "run_header"]

#: The report's stylesheet (package data), copied beside the pages as :data:`CSS_NAME`.
CSS_NAME = "report.css"


def stylesheet() -> str:
    """The text of the report's one stylesheet, ``reports/report/report.css``."""
    return resources.files("reports.report").joinpath(CSS_NAME).read_text(encoding="utf-8")


def version() -> str:
    """microcyl's installed version, or "unknown (not installed)"."""
    try:
        return importlib.metadata.version("microcyl")
    except importlib.metadata.PackageNotFoundError:
        return "unknown (not installed)"


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


def swatch(colour) -> Markup:
    """A square in ``colour``: a fabric's colour in the plots (``#rrggbb``, from
    :func:`reports.plots.common.series_styles`), so that a swatch and its curve match.

    Examples
    --------
    >>> swatch("#0072B2")
    Markup('<span class="swatch" style="background:#0072B2"></span>')
    >>> swatch((1.0, 0.5, 0.0))
    Markup('<span class="swatch" style="background:#ff8000"></span>')
    """
    if not isinstance(colour, str):
        colour = "#" + "".join(f"{int(round(255 * min(max(float(c), 0.0), 1.0))):02x}"
                               for c in colour)
    if not (len(colour) == 7 and colour[0] == "#" and
            all(c in "0123456789abcdefABCDEF" for c in colour[1:])):
        raise ValueError(f"swatch colour must be #rrggbb; got {colour!r}")
    return html('<span class="swatch" style="background:{}"></span>', colour)


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


def run_header(title: str, lede, run: dict, mark: Markup = Markup("")) -> Markup:
    """The top of a page: its title (after ``mark``, e.g. a swatch), a lede (Markup or
    text) and what was run (label -> value, each shown as text; a value of
    ``("code", text)`` in code type)."""
    rows = join(html("<dt>{}</dt><dd>{}</dd>", k,
                     html("<code>{}</code>", v[1]) if isinstance(v, tuple) else v)
                for k, v in run.items())
    return html('<header class="run"><h1>{}{}</h1>{}<dl class="runinfo">{}</dl></header>',
                mark, title,
                html('<p class="lede">{}</p>', lede) if lede else Markup(""), rows)


def page(title: str, nav_html: Markup, body: Markup, header: Markup | None = None) -> str:
    """A whole HTML page: title, navigation, header (default the title alone), body and a
    dated footer, styled by :data:`CSS_NAME` beside it.

    ``nav_html``, ``body`` and ``header`` are Markup (a plain ``str`` is shown as text,
    escaped).

    Examples
    --------
    >>> "<h1>a&lt;b</h1>" in page("a<b", Markup(""), "<p>") and "&lt;p&gt;" in page("t", "", "<p>")
    True
    """
    if header is None:
        header = html('<header class="run"><h1>{}</h1></header>', title)
    return str(html('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                    '<meta name="viewport" content="width=device-width, initial-scale=1">'
                    '<title>{title}</title><link rel="stylesheet" href="{css}"></head><body>'
                    "<nav>{nav}</nav><main>{header}{body}"
                    "<footer><p>microcyl {version} report, {now}</p></footer>"
                    "</main></body></html>\n", title=title, css=CSS_NAME, nav=nav_html,
                    header=header, body=body, version=version(), now=now()))
