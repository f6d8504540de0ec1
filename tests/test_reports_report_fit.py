"""Tests of reports.report.sec_fit: the fit section shows the verdicts and the warnings."""

import json

from reports.report.page import Page
from reports.report.sec_fit import section_fit


def test_fit_section_lists_adequacy_and_warnings_escaped(tmp_path):
    doc = {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "ok",
           "adequate": False, "adequate_reason": "residuals differ <between> sides",
           "warnings": [{"kind": "at_bound", "parameters": ["eta1"],
                         "message": "eta1: 95% interval <script>x</script>"}],
           "parameters": {"eta1": {"median": 1.05, "lo68": 1.02, "hi68": 1.08, "lo95": 1.011,
                                   "hi95": 1.1, "tau": 3.0, "rhat": 1.0, "ess": 900.0}}}
    path = tmp_path / "results.json"
    path.write_text(json.dumps(doc))
    sec = section_fit(Page(tmp_path, "f", None, {}, fit_results=path))
    html = sec.html
    assert "Adequate (the model describes the data): False" in html
    assert "residuals differ &lt;between&gt; sides" in html
    assert "<td>at_bound</td><td>eta1</td>" in html and "<script>" not in html
    doc.update(adequate=True, adequate_reason="fine", warnings=[])
    path.write_text(json.dumps(doc))
    html2 = section_fit(Page(tmp_path, "f", None, {}, fit_results=path))
    html2 = html2.html
    assert "No warnings." in html2 and "Adequate (the model describes the data): True" in html2
    assert "<p>Model: microcylinder</p>" in html2          # a results.json from before models
    doc.update(model="zeltner", parameters={"roughness": doc["parameters"]["eta1"]})
    path.write_text(json.dumps(doc))
    assert "<p>Model: zeltner</p>" in section_fit(Page(tmp_path, "f", None, {},
                                                       fit_results=path)).html
