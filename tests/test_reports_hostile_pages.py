"""HTML injection: every page kind (fabric pages, overview, fit sections, measured.html, a
batch's index.html) built from hostile files, and a fuzz of their text and number fields.

A page passes when nothing from a file became markup: no <script> but the JSON island the
batch page writes, no event-handler attribute, no javascript: link, no tag microcyl does not
write (tests/_html_checks.py). Where a reader refuses a hostile file (a schema check), the
refusal must be one clean line, and a page is then not required.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from _html_checks import (P, PAYLOADS, Inert, assert_inert, read, texts, values,  # noqa: E402
                          written_pages)
from reports import safehtml  # noqa: E402
from reports.report import build_report  # noqa: E402
from reports.report.markup import nav, page  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports.report.sections import run_section  # noqa: E402
from reports.report.settings import QUALITIES  # noqa: E402
from reports.report_batch import write_batch_page  # noqa: E402
from reports.report_measured import measured_page, overview_table  # noqa: E402
from reports_standin import Lambert, StandinThread  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT))

_COLUMNS = ("median", "lo68", "hi68", "lo95", "hi95", "tau", "rhat", "ess")


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
    fit = velvet.split('<section id="fit"')[1].split("</section>")[0]
    # the table (parameter name, unit), or the reader's refusal quoting the bad field
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in fit


@pytest.mark.parametrize("numbers", [None, 1])
def test_fit_section_builder_escapes_every_field(tmp_path, numbers):
    """A results.json with markup in every field (or in every text field, numbers valid):
    the section shows it as text, or says Not available quoting it as text."""
    path = hostile_results(tmp_path / "results.json", numbers=numbers)
    run = run_section("fit", Page(tmp_path, "f", Lambert(), QUALITIES["fast"],
                                  fit_results=path))
    seen = assert_inert(page("t", nav(["f"], "f"), run.html("f")))
    assert any(P in t for t in seen.texts)
    if numbers is not None:
        assert run.status == "ok", run.status      # a valid file: its table, names as text
        assert P in seen.texts                     # the parameter's name, a cell of its own


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

FUZZ = settings(max_examples=40, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


def _shows(seen: Inert, value) -> bool:
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
