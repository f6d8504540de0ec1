"""The one way a value reaches an HTML page: escaped text and literal templates.

Every page microcyl writes (a report's fabric pages and overview, ``measured.html``, a batch's
``index.html``) is assembled from :class:`Markup`: HTML that microcyl itself wrote. Anything
else (a ``str``, a number, a list, above all anything read from a file such as results.json,
measured.json, summary.json or a fabric's JSON) is text, and becomes HTML only through
:func:`text`, which formats it and escapes it: directly, or through :func:`html` (a literal
template whose every argument goes through :func:`text`), :func:`join` and :func:`table`.
A page's frame takes Markup, and a plain ``str`` given where Markup is expected is escaped
as text, so a forgotten escape shows tags on the page instead of running them.

Only literal strings become ``Markup`` or templates: ``Markup("<hr>")`` and
``html("<p>{}</p>", value)``, never ``Markup(f"...")`` or ``html(f"...")`` (the tests read the
sources of the page modules for it). ``Markup`` is MarkupSafe's, the escaping core of Jinja2,
so fragments pass unchanged through a Jinja2 template with autoescape.

Examples
--------
>>> html('<td class="{}">{:.3g}</td>', "a<b", 3.14159)
Markup('<td class="a&lt;b">3.14</td>')
>>> html("<td>{:.3g}</td>", "<script>")       # a non-number keeps its text, escaped
Markup('<td>&lt;script&gt;</td>')
"""

from __future__ import annotations

import json
import numbers
import string
from urllib.parse import quote

from markupsafe import Markup, escape

__all__ = ["Markup", "text", "html", "join", "table", "url", "json_script"]


def _is_number(value) -> bool:
    return isinstance(value, numbers.Number) and not isinstance(value, bool)


def _format(value, spec: str) -> str:
    """``format(value, spec)`` for a number; for anything else (or a spec that does not fit
    the value) ``str(value)``: a value read from a file never makes a page fail."""
    if spec and _is_number(value):
        try:
            return format(value, spec)
        except (TypeError, ValueError):
            pass
    return str(value)


def text(value, spec: str = "") -> Markup:
    """``value`` as HTML: Markup as it is; a number formatted with ``spec``; anything else
    as ``str(value)``; then escaped (``& < > " '``).

    Parameters
    ----------
    value : object
        Markup, or any value (text, number, None, a list, ...).
    spec : str
        A format spec (``".4g"``) for a number; ignored for anything else.

    Examples
    --------
    >>> text("<b>"), text(0.123456, ".2f"), text("x", ".2f"), text(Markup("<i>i</i>"))
    (Markup('&lt;b&gt;'), Markup('0.12'), Markup('x'), Markup('<i>i</i>'))
    """
    if hasattr(value, "__html__"):
        if spec:
            raise ValueError(f"a format spec ({spec!r}) for Markup")
        return escape(value)
    return escape(_format(value, spec))


class _Formatter(string.Formatter):
    """str.format whose every field goes through :func:`text`."""

    def format_field(self, value, format_spec):
        return text(value, format_spec)


_FORMATTER = _Formatter()


def html(template: str, /, *args, **kwargs) -> Markup:
    """The literal HTML ``template`` with its ``{}`` fields filled by :func:`text` of the
    arguments (format specs apply to numbers; conversions ``!r``, ``!s`` are escaped too).

    Parameters
    ----------
    template : str
        A literal written in the code (never one built from a value); braces doubled.

    Examples
    --------
    >>> html('<a href="{}">{name}</a>', url("a b.html"), name="'x'")
    Markup('<a href="a%20b.html">&#39;x&#39;</a>')
    """
    return Markup(_FORMATTER.vformat(template, args, kwargs))


def join(parts, sep: str = "") -> Markup:
    """The fragments ``parts`` one after the other, ``sep`` (a literal) between them; a part
    that is not Markup is escaped as text.

    Examples
    --------
    >>> join([Markup("<br>"), "<br>"])
    Markup('<br>&lt;br&gt;')
    """
    return Markup(sep).join(text(p) for p in parts)


def table(header, rows) -> Markup:
    """An HTML table of ``rows`` (sequences of cells) under ``header``; every cell through
    :func:`text` (a Markup cell, such as a link, is kept).

    Examples
    --------
    >>> table(["a"], [[1]])
    Markup('<table><thead><tr><th>a</th></tr></thead><tbody><tr><td>1</td></tr></tbody></table>')
    """
    head = join(html("<th>{}</th>", h) for h in header)
    body = join(html("<tr>{}</tr>", join(html("<td>{}</td>", c) for c in row)) for row in rows)
    return html("<table><thead><tr>{}</tr></thead><tbody>{}</tbody></table>", head, body)


def url(path) -> str:
    """A relative link to the file ``path`` (``/``-separated), every other character that is
    not a letter, digit or ``_.-~`` percent-encoded: a name read from a file can neither
    start a scheme (``javascript:``), a query nor a fragment. Escaped when it is inserted.

    Examples
    --------
    >>> url("javascript:alert(1)//x.html"), url("a/b c.png")
    ('javascript%3Aalert%281%29//x.html', 'a/b%20c.png')
    """
    return quote(str(path), safe="/")


def json_script(data, element_id: str) -> Markup:
    """``data`` as JSON in ``<script type="application/json" id=...>``: ``<``, ``>`` and
    ``&`` written as ``\\u`` escapes, so the element cannot be closed early and the text
    reads back as the same JSON (an HTML escape would not: a script's text is raw).

    Examples
    --------
    >>> json_script({"a": "</script>"}, "d")
    Markup('<script type="application/json" id="d">{"a": "\\\\u003c/script\\\\u003e"}</script>')
    """
    body = (json.dumps(data).replace("&", "\\u0026").replace("<", "\\u003c")
            .replace(">", "\\u003e"))
    return html('<script type="application/json" id="{}">', element_id) + Markup(body) \
        + Markup("</script>")
