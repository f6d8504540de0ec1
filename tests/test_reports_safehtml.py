"""reports.safehtml, the one way a value reaches a page: its helpers, and the page modules
read for any way around it."""

import ast
import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _html_checks import TAGS, assert_inert, read, texts, values
from reports import safehtml
from reports.report.markup import Markup, page
from reports.report.settings import Section

ROOT = Path(__file__).resolve().parents[1]



@given(value=values, spec=st.sampled_from(["", ".4g", ".0f", "d", ".2%", "+.1e"]))
@settings(max_examples=200, deadline=None)
def test_text_never_fails_and_round_trips(value, spec):
    out = safehtml.text(value, spec)
    assert isinstance(out, Markup)
    assert "<" not in out and ">" not in out and '"' not in out
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not spec:
        assert out.unescape() == str(value)


def test_templates_escape_arguments_not_the_template():
    out = safehtml.html('<a href="{}" title="{t}">{:.2f}</a>', "x\" onclick=\"y", 1.234,
                        t=Markup("<i>kept</i>"))
    assert out == '<a href="x&#34; onclick=&#34;y" title="<i>kept</i>">1.23</a>'
    assert safehtml.join(["<b>", Markup("<b>")]) == "&lt;b&gt;<b>"
    assert Section("<p>").html == "&lt;p&gt;"         # a str given as HTML is text
    assert "&lt;p&gt;" in page("t", "<nav>", "<p>")    # so is a page body
    with pytest.raises(ValueError, match="format spec"):
        safehtml.text(Markup("<i>"), ".2f")


@given(value=st.text(max_size=30))
@settings(max_examples=100, deadline=None)
def test_url_is_a_relative_link_that_keeps_the_name(value):
    from urllib.parse import unquote, urlsplit
    link = safehtml.url(f"{value}.html")
    parts = urlsplit(link)
    assert parts.scheme == "" and parts.query == "" and parts.fragment == ""
    assert unquote(link) == f"{value}.html"


@given(data=st.dictionaries(texts, st.one_of(st.integers(), texts), max_size=4))
@settings(max_examples=100, deadline=None)
def test_json_script_reads_back(data):
    doc = str(safehtml.json_script(data, "d"))
    assert_inert(doc)
    assert json.loads(doc.split('id="d">', 1)[1].rsplit("</script>", 1)[0]) == data


# -- the sources: no way around the one escaping path -------------------------------------------

PAGE_MODULES = sorted((ROOT / "reports" / "report").glob("*.py")) + [
    ROOT / "reports" / "report_batch.py", ROOT / "reports" / "report_measured.py"]


@pytest.mark.parametrize("path", PAGE_MODULES, ids=lambda p: p.name)
def test_page_modules_have_one_escaping_path(path):
    """No stdlib html module, no f-string or variable made Markup or a template, no f-string
    that writes a tag (it would reach a page escaped as text, or unescaped past the helpers)."""
    tree = ast.parse(read(path))
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            mods = [a.name for a in node.names] if isinstance(node, ast.Import) \
                else [node.module or ""]
            bad += [f"line {node.lineno}: imports {m}" for m in mods
                    if m in ("html", "markupsafe")]
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                node.func.id in ("Markup", "html") and node.args:
            if not (isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value,
                                                                          str)):
                bad.append(f"line {node.lineno}: {node.func.id}() of a non-literal")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and \
                node.func.attr == "format" and isinstance(node.func.value, ast.Constant) and \
                "<" in str(node.func.value.value):
            bad.append(f"line {node.lineno}: str.format writes a tag")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod) and isinstance(
                node.left, ast.Constant) and "<" in str(node.left.value):
            bad.append(f"line {node.lineno}: % writes a tag")
        if isinstance(node, ast.JoinedStr):
            lits = "".join(v.value for v in node.values if isinstance(v, ast.Constant))
            if any(f"<{t}" in lits for t in TAGS | {"/"}):
                bad.append(f"line {node.lineno}: an f-string writes a tag")
    assert bad == []
