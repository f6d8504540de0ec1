"""HTML injection: every page kind built from hostile files, a fuzz of its text fields, the
escaping helpers of reports.safehtml, and the page modules read for unescaped HTML.

A page passes when nothing from a file became markup: no <script> but the JSON island the
batch page writes, no event-handler attribute, no javascript: link, no tag microcyl does not
write. Where a reader refuses a hostile file (a schema check), the refusal must be a clean
ValueError, and a page is then not required.
"""

import ast
import json
import os
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from reports import safehtml  # noqa: E402
from reports.report import build_report  # noqa: E402
from reports.report.markup import Markup, nav, page  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports.report.sec_fit import section_fit  # noqa: E402
from reports.report.sections import run_section  # noqa: E402
from reports.report.settings import QUALITIES, Section  # noqa: E402
from reports.report_batch import write_batch_page  # noqa: E402
from reports.report_measured import measured_page, overview_table  # noqa: E402
from reports_standin import Lambert, StandinThread  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT))
#: What a hostile file holds in every text and number field.
P = "<script>alert(1)</script>"
#: More payloads: an attribute break-out, a link scheme, an entity that must stay text.
PAYLOADS = [P, '"><img src=x onerror=alert(1)>', "javascript:alert(1)", "' onmouseover='x",
            "&lt;script&gt;", "</section><script>alert(2)</script>"]
#: The tags microcyl writes; anything else on a page came from data.
TAGS = {"html", "head", "meta", "title", "style", "body", "nav", "h1", "h2", "h3", "p", "a",
        "b", "i", "small", "code", "sub", "section", "figure", "figcaption", "img", "table",
        "thead", "tbody", "tr", "th", "td", "ul", "li", "div", "span", "footer", "br",
        "script"}
_COLUMNS = ("median", "lo68", "hi68", "lo95", "hi95", "tau", "rhat", "ess")


class _Inert(HTMLParser):
    """Collects what a page would run: foreign tags, on* attributes, script links."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.bad, self.texts, self.in_script = [], [], None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag not in TAGS:
            self.bad.append(f"tag <{tag}>")
        if tag == "script" and a.get("type") != "application/json":
            self.bad.append(f"script {attrs}")
        self.in_script = tag if tag in ("script", "style") else None
        for k, v in attrs:
            if k.startswith("on") or k in ("srcdoc", "formaction"):
                self.bad.append(f"attribute {k}={v!r} on <{tag}>")
            if k in ("href", "src") and v and v.strip().lower().startswith(
                    ("javascript:", "data:", "vbscript:")):
                self.bad.append(f"link {k}={v!r}")
            if v is not None:
                self.texts.append(v)

    def handle_endtag(self, tag):
        self.in_script = None

    def handle_data(self, data):
        if self.in_script is None:
            self.texts.append(data)


def assert_inert(doc: str, where: str = "") -> _Inert:
    """No markup from data in ``doc``; returns the parser (its texts: what a reader sees)."""
    lower = doc.lower()
    assert lower.count("<script") == lower.count('<script type="application/json"'), where
    assert lower.count("</script") == lower.count("<script"), where
    p = _Inert()
    p.feed(doc)
    p.close()
    assert p.bad == [], f"{where}: {p.bad}"
    return p


def written_pages(root: Path) -> list[Path]:
    return sorted(root.rglob("*.html"))


def read(path: Path) -> str:
    """A page's text as written (no newline translation: a "\r" from data stays)."""
    return path.read_bytes().decode("utf-8")


def hostile_results(path: Path, value=P, numbers=None) -> Path:
    """A results.json whose every string field is ``value``, and every number field too
    (``numbers`` None) or ``numbers``: a file a schema check would pass."""
    n = value if numbers is None else numbers
    doc = {"schema": "microcyl-fit", "schema_version": 2,
           "converged": value if numbers is None else False, "reason": value,
           "parameters": {value: {c: n for c in _COLUMNS} | {"unit": value}},
           "fit": {"steps": n if numbers is None else 100},
           "quality": {"rms_residual": n}, "plots": {value: value} if numbers is None else {}}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


class HostileFabric(Lambert):
    """A user's BRDF whose thread fields and options are text (albedo and area stay numbers:
    the swatch's colour is computed from them)."""

    def __init__(self, value=P):
        super().__init__()
        self.threads = (StandinThread(eta=value, kd=value, gamma_s=value, gamma_v=value,
                                      offsets=(value, value), lengths=(value,)),)
        self.options = {value: value}


def measured_entry(value=P, numbers=None, results="ds/results.json") -> dict:
    """An entry of measured.json with every string field ``value``, and every number field
    too (``numbers`` None) or ``numbers``."""
    n = value if numbers is None else numbers
    return {"title": value, "source": value, "pairs": n, "values_used": n, "preset": value,
            "ties": [value], "converged": value if numbers is None else False,
            "reason": value, "steps": n,
            "quality": {"rms_residual": n, "rms_normalized": n}, "albedo_delta_e2000": n,
            "results": results}


def _build(tmp: Path, kind: str, fabrics, numbers=None, **kw) -> tuple[Path | None, str]:
    """A report of ``kind`` (its own folder under ``tmp``) from hostile files: the output
    folder, or None and the reader's refusal (which must be one line)."""
    d = tmp / f"{kind}-{numbers}"
    if kind == "fit":
        kw["fit_results"] = {n: hostile_results(d / n.replace("/", "_") / "results.json",
                                                numbers=numbers) for n in fabrics}
    if kind == "measured":
        m = d / "measured"
        for ds in ("ds", "ds2"):
            hostile_results(m / ds / "results.json", numbers=0.5 if numbers is None else numbers)
        (m / "measured.json").write_text(json.dumps({"datasets": {
            ds: measured_entry(numbers=numbers, results=f"{ds}/results.json")
            for ds in ("ds", "ds2")}}))
        kw["measured"] = m
    try:
        index = build_report(fabrics, d / "report", sections=["parameters", "fit"],
                             progress=False, quality="fast", title=P, **kw)
    except ValueError as exc:
        assert "\n" not in str(exc) and "Traceback" not in str(exc)
        return None, str(exc)
    return index.parent, ""


# -- every page kind from hostile files ---------------------------------------------------------

NAME = "<script>alert(1)<\\script>"       # a page's name cannot hold "/"


@pytest.fixture(scope="module")
def hostile_report(tmp_path_factory):
    """Every page kind of the report built from hostile data: fabric pages and overview (a
    user's BRDF named with markup, its thread fields and options text), the fit sections
    (results.json with markup in every field) and measured.html (measured.json likewise).
    A file a reader refuses is built again with numbers where numbers belong (markup in every
    text field), which a reader must accept. Kind -> output folder; and the refusals."""
    tmp = tmp_path_factory.mktemp("hostile")
    fabrics = {"velvet": None, NAME: HostileFabric()}
    out, refused = {}, {}
    out["pages"], _ = _build(tmp, "pages", fabrics)
    for kind in ("fit", "measured"):
        out[kind], refused[kind] = _build(tmp, kind, fabrics if kind == "fit" else
                                          {"velvet": None})
        if out[kind] is None:
            out[kind], again = _build(tmp, kind, fabrics if kind == "fit" else
                                      {"velvet": None}, numbers=1)
            assert out[kind] is not None, again
    return out, refused


def test_a_fabric_name_with_a_slash_is_refused_cleanly(tmp_path):
    with pytest.raises(ValueError, match="cannot name a report page"):
        build_report({P: Lambert()}, tmp_path / "r", sections=["parameters"], progress=False)


@pytest.mark.parametrize("kind", ["pages", "fit", "measured"])
def test_report_pages_from_hostile_files_hold_no_markup_from_them(hostile_report, kind):
    root = hostile_report[0][kind]
    pages = {p.name: p for p in written_pages(root)}
    assert {"index.html", "velvet.html"} <= set(pages)
    for p in pages.values():
        seen = assert_inert(read(p), p.name)
        assert any(P in t for t in seen.texts), f"{p.name} does not show the text"
    if kind != "measured":
        fabric = read(pages[f"{NAME}.html"])
        assert "&lt;script&gt;alert(1)&lt;\\script&gt;" in fabric     # its name
        assert "&lt;script&gt;alert(1)&lt;/script&gt;" in fabric       # options or fit
        assert f'href="{safehtml.url(NAME)}.html"' in read(pages["index.html"])


def test_fit_section_shows_hostile_results_as_text(hostile_report):
    velvet = read(hostile_report[0]["fit"] / "velvet.html")
    fit = velvet.split('<section id="fit"')[1]
    # the parameter's name and unit and the fit's reason, as text in the table
    assert fit.count("&lt;script&gt;alert(1)&lt;/script&gt;") >= 2


def test_measured_page_from_a_hostile_measured_json(hostile_report):
    doc = read(hostile_report[0]["measured"] / "measured.html")
    assert_inert(doc, "measured.html")
    esc = "&lt;script&gt;alert(1)&lt;/script&gt;"
    assert doc.count(f"Table: {esc}") == 2 and doc.count(f"Start preset <b>{esc}</b>") == 2
    if not hostile_report[1]["measured"]:
        # pairs, values_used, the residuals and ΔE2000 (issue 24) reach the page as text
        assert doc.count(f"{esc} pairs, {esc} values used") == 2
        assert f"Residual rms {esc}" in doc and f"ΔE2000 {esc}" in doc


def test_measured_page_builder_escapes_every_field(tmp_path):
    for value in PAYLOADS:
        entry = measured_entry(value) | {"results": json.loads(
            hostile_results(tmp_path / "r.json", value).read_text()), "folder": tmp_path,
            "plot_files": {}, "data_files": []}
        measured = {value: entry}
        body, summary = measured_page(tmp_path / "root", measured)
        seen = assert_inert(page("t", nav([], None, True), body), value)
        assert sum(value in t for t in seen.texts) >= 8, value
        assert_inert(str(overview_table(measured)))
        json.dumps(summary)


def _batch_folder(out: Path, value=P) -> Path:
    """A batch folder whose summary.json holds ``value`` in every field of its rows."""
    out.mkdir(parents=True, exist_ok=True)
    rows = [{"name": value, "status": value, "error": value, "steps": value, "wall_s": value,
             "folder": "t1", "path": value, "kd1_median": value, "kd1_lo95": value,
             "kd1_hi95": value, f"{value}_median": value},
            {"name": "t2", "status": "converged", "error": None, "steps": 100, "wall_s": 3.5,
             "folder": value, "path": value},
            {"name": "t3", "status": "error", "error": value, "steps": None, "wall_s": None,
             "folder": "t3"}]
    (out / "summary.json").write_text(json.dumps({"schema": "microcyl-batch", "version": 1,
                                                  "tables": rows}))
    hostile_results(out / "t1" / "results.json", value)
    doc = json.loads((out / "t1" / "results.json").read_text())
    doc["plots"] = {value: "x.png", "corner": f"{value}.png"}
    (out / "t1" / "results.json").write_text(json.dumps(doc))
    (out / "t1" / "x.png").write_bytes(b"png")
    return out


@pytest.mark.parametrize("value", PAYLOADS)
def test_batch_page_from_a_hostile_summary(tmp_path, value):
    out = _batch_folder(tmp_path / "b", value)
    try:
        page_ = write_batch_page(out)
    except ValueError as exc:                    # a schema check refused the summary
        assert "\n" not in str(exc) and ("summary.json" in str(exc)
                                         or "results.json" in str(exc))
        return
    doc = read(page_)
    seen = assert_inert(doc)
    assert sum(value in t for t in seen.texts) >= 5
    # the JSON island reads back as the counts, whatever the statuses hold
    island = doc.split('<script type="application/json" id="summary">')[1].split("</script>")[0]
    assert json.loads(island) == {value: 1, "converged": 1, "error": 1}


def test_report_batch_as_a_user_runs_it(tmp_path):
    """`microcyl report --batch` on a hostile folder: exit 0 with an inert page, or 1 with
    one line naming summary.json. (`report --measured` builds the pages of
    test_measured_page_from_a_hostile_measured_json; as a subprocess it costs ~15 s of
    CPU for the fabric's sections.)"""
    out = _batch_folder(tmp_path / "b")
    r = subprocess.run([sys.executable, "-m", "reports", "report", "--batch", str(out)],
                       env=ENV, capture_output=True, text=True, timeout=300)
    assert r.returncode in (0, 1), r.stderr
    if r.returncode == 0:
        assert_inert(read(out / "index.html"))
    else:
        assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
        assert "summary.json" in r.stderr or "results.json" in r.stderr, r.stderr


# -- fuzz ---------------------------------------------------------------------------------------

texts = st.one_of(st.text(max_size=40), st.sampled_from(PAYLOADS),
                  st.text(alphabet="<>&\"'/=: scriptimgonerrorjavascript", max_size=40))
values = st.one_of(texts, st.floats(allow_nan=True), st.integers(), st.none(), st.booleans())
FUZZ = settings(max_examples=40, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


def _shows(seen: _Inert, value) -> bool:
    return value == "" or any(str(value) in t for t in seen.texts)


@FUZZ
@given(name=texts, fields=st.dictionaries(st.sampled_from(
    ["title", "source", "pairs", "values_used", "preset", "reason", "steps",
     "albedo_delta_e2000"]), values), quality=st.dictionaries(
         st.sampled_from(["rms_residual", "rms_normalized"]), values), unit=texts)
def test_fuzz_measured_page(tmp_path, name, fields, quality, unit):
    results = {"parameters": {"p": {c: 1.0 for c in _COLUMNS} | {"unit": unit}}, "plots": {}}
    entry = fields | {"quality": quality, "results": results, "folder": tmp_path,
                      "plot_files": {}, "data_files": []}
    try:
        body, _ = measured_page(tmp_path / "root", {name: entry})
    except (ValueError, OSError) as exc:          # a name that cannot name a folder
        assert "\n" not in str(exc)
        return
    seen = assert_inert(page("t", nav([], None, True), body), repr(name))
    assert _shows(seen, name) and _shows(seen, unit)
    for k in ("title", "source", "preset", "reason"):
        if isinstance(fields.get(k), str):
            assert _shows(seen, fields[k]), k


@FUZZ
@given(name=texts, status=texts, error=texts, steps=values, wall=values, median=values,
       reason=texts, plot=texts)
def test_fuzz_batch_page(tmp_path_factory, name, status, error, steps, wall, median, reason,
                         plot):
    out = tmp_path_factory.mktemp("fb")
    (out / "t").mkdir()
    (out / "t" / "results.json").write_text(json.dumps(
        {"schema": "microcyl-fit", "reason": reason, "parameters": {}, "plots": {plot: "a.png"}}))
    (out / "t" / "a.png").write_bytes(b"png")
    row = {"name": name, "status": status, "error": error, "steps": steps, "wall_s": wall,
           "folder": "t", "kd1_median": median, "kd1_lo95": median, "kd1_hi95": median}
    (out / "summary.json").write_text(json.dumps({"schema": "microcyl-batch",
                                                  "tables": [row]}))
    try:
        doc = read(write_batch_page(out))
    except ValueError as exc:                     # a schema check refused the row
        assert "\n" not in str(exc)
        return
    seen = assert_inert(doc, repr(row))
    for v in (name, status, error) + ((plot,) if status != "error" else ()):
        assert _shows(seen, v), v


@FUZZ
@given(name=texts, converged=values, parameter=texts, median=values, reason=texts)
def test_fuzz_fit_section_and_fabric_page(tmp_path_factory, name, converged, parameter, median,
                                          reason):
    d = tmp_path_factory.mktemp("ff")
    path = d / "results.json"
    path.write_text(json.dumps({"schema": "microcyl-fit", "converged": converged,
                                "reason": reason, "parameters": {parameter: {"median": median}},
                                "plots": {}}))
    run = run_section("fit", Page(d, "f", Lambert(), QUALITIES["fast"], fit_results=path))
    body = run.html(name)
    seen = assert_inert(page(name, nav([name], name), body), repr(name))
    assert _shows(seen, name)
    if run.status == "ok":
        assert _shows(seen, parameter)


# -- the helpers --------------------------------------------------------------------------------

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
