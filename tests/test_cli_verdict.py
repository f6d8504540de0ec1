"""A fit's verdict (adequacy, warnings, Pareto k) everywhere the fit appears, as a user runs
it: a short `fit-measured` of CUReT velvet by the microcylinder and by lambert (both
inadequate: 60 steps, and velvet's residuals are structured), then `compare` of the two
folders, the measured page, `report --fabric FITDIR` and `plot table --fit`."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import gonio
from analysis.fit.loo import k_threshold, load_loo
from analysis.measured import load_measured
from reports.fitwords import SEPARATION_SE, gap_sentence
from analysis.measuredjson import check_measured_doc
from reports.report_measured import measured_page, models_table, read_measured

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
VELVET = "curet_07_velvet"


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def measured(velvet_two_models):
    """The short fit-measured run of conftest (shared with test_cli_fit_models)."""
    return velvet_two_models


def _results(out, folder):
    return json.loads((out / folder / "results.json").read_text())


def test_fit_measured_prints_each_fits_verdict_and_warnings_as_fit_does(measured):
    out, stdout, stderr = measured
    for folder in (VELVET, f"{VELVET}-lambert"):
        doc = _results(out, folder)
        assert doc["adequate"] is False                 # 60 steps of velvet: not adequate
        # the lines `microcyl fit` prints (format_warnings), from results.json's own text
        assert f"NOT ADEQUATE: {doc['adequate_reason']}" in stdout
        for w in doc["warnings"]:
            assert f"warning ({w['kind']}): {w['message']}" in stdout
        # the line of the batch as each fit ends says so too, not only "converged at step"
        line = next(x for x in stderr.splitlines() + stdout.splitlines()
                    if x.startswith(f"{folder}: ") and " at step " in x)
        n = len(doc["warnings"])
        assert "NOT ADEQUATE" in line and f"{n} warning{'s' * (n != 1)}" in line
    assert len(_results(out, VELVET)["warnings"]) >= 3


def test_measured_json_keeps_the_verdict_per_dataset_and_model(measured, tmp_path):
    out, _, _ = measured
    entry = json.loads((out / "measured.json").read_text())["datasets"][VELVET]
    doc = _results(out, VELVET)
    assert entry["adequate"] is doc["adequate"] is False
    assert entry["adequate_reason"] == doc["adequate_reason"]
    assert [w["kind"] for w in entry["warnings"]] == [w["kind"] for w in doc["warnings"]]
    for model, folder in (("microcylinder", VELVET), ("lambert", f"{VELVET}-lambert")):
        m, res = entry["models"][model], _results(out, folder)
        assert m["adequate"] is res["adequate"]
        assert [w["message"] for w in m["warnings"]] == [w["message"] for w in res["warnings"]]
        loo = load_loo(out / folder)                   # the pointwise values behind them
        assert m["pareto_k_max"] == pytest.approx(float(loo.pareto_k.max()))
        threshold = min(1 - 1 / math.log10(loo.draws), 0.7)
        assert m["k_threshold"] == pytest.approx(threshold)
        assert m["n_high_k"] == int((loo.pareto_k > threshold).sum())
    # the page's models table shows each fit's warnings and its Pareto k
    body, _ = measured_page(tmp_path / "page", read_measured(out))
    text = str(body)
    assert "Pareto k max (values above)" in text and "<th>warnings</th>" in text
    mk = entry["models"]["microcylinder"]
    assert (f"{mk['pareto_k_max']:.2f} ({mk['n_high_k']} &gt; {mk['k_threshold']:.2f})"
            in text)
    # an old measured.json (no verdict kept) still reads, its verdict shown as unknown
    old = json.loads((out / "measured.json").read_text())
    for e in [old["datasets"][VELVET], *old["datasets"][VELVET]["models"].values()]:
        for k in ("adequate", "adequate_reason", "warnings", "pareto_k_max", "n_high_k",
                  "k_threshold", "d_se_block", "d_lag1"):
            e.pop(k, None)
    check_measured_doc(old, "old.json")
    rows = str(models_table(old["datasets"][VELVET]["models"]))
    assert "<td>-</td>" in rows and "&gt; 0.62" not in rows


def test_compare_has_adequacy_and_the_words_of_the_measured_page(measured, tmp_path):
    out, _, _ = measured
    folders = [out / VELVET, out / f"{VELVET}-lambert"]
    r = microcyl("compare", *folders, "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    assert [row["adequate"] for row in rows] == [False, False]
    best, other = rows
    # the block se and lag-1 autocorrelation beside the naive se, from the loo files
    a, b = (load_loo(Path(best["fit"])), load_loo(Path(other["fit"])))
    d = a.elpd_i - b.elpd_i
    assert other["d_se"] == pytest.approx(math.sqrt(d.size * d.var()), rel=1e-9)
    assert -1 <= other["d_lag1"] <= 1 and other["d_se_block"] > 0
    text = microcyl("compare", *folders)
    assert text.returncode == 0, text.stderr
    head = text.stdout.splitlines()[0].split()
    assert head[-1] == "adequate" and text.stdout.splitlines()[1].split()[-1] == "NO"
    words = gap_sentence(f"{best['fit']} ({best['model']})", f"{other['fit']} "
                         f"({other['model']})", other["d_elpd"], other["d_se"],
                         block_se=other["d_se_block"], lag1=other["d_lag1"])
    assert words in text.stdout
    z = other["d_elpd"] / other["d_se"]
    assert ("cannot separate" in words) == (z <= SEPARATION_SE)
    assert "behind" not in text.stdout
    # the measured page words the same gap the same way (the same function)
    entry = json.loads((out / "measured.json").read_text())["datasets"][VELVET]["models"]
    first = min(entry, key=lambda m: entry[m]["rank"])
    second = max(entry, key=lambda m: entry[m]["rank"])
    assert first == best["model"] and second == other["model"]
    body, _ = measured_page(tmp_path / "page2", read_measured(out))
    page_words = gap_sentence(first, second, entry[second]["d_elpd"], entry[second]["d_se"],
                              block_se=entry[second]["d_se_block"],
                              lag1=entry[second]["d_lag1"])
    assert page_words in str(body)
    assert page_words.split(first)[0] == words.split(best["fit"])[0]    # same verdict


def test_report_of_a_fit_folder_shows_its_fit_section(measured, tmp_path):
    out, _, _ = measured
    r = microcyl("report", "--fabric", out / VELVET, "--quality", "fast", "--engine",
                 "builtin", "-q", "-o", tmp_path / "rep")
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "rep" / f"{VELVET}.html").read_text()
    assert "no fitting results for this fabric" not in page
    assert "Adequate (the model describes the data): False" in page
    assert "its fit is NOT adequate" in page               # the page's first sentence
    doc = _results(out, VELVET)
    for w in doc["warnings"]:
        assert f"<td>{w['kind']}</td>" in page
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert json.dumps(summary).count('"adequate": false') >= 1


def test_plot_table_of_an_inadequate_fit_says_so(measured, tmp_path, shared_data):
    out, _, _ = measured
    gonio.write(load_measured(VELVET, shared_data), tmp_path / "velvet.csv")
    r = microcyl("plot", "table", tmp_path / "velvet.csv", "--fit", out / VELVET,
                 "-o", tmp_path / "t.png")
    assert r.returncode == 0, r.stderr
    kinds = sorted({w["kind"] for w in _results(out, VELVET)["warnings"]})
    assert ("NOT ADEQUATE (the model does not describe the table to within its noise)"
            in r.stdout)
    assert f"{len(kinds)} kinds of warning: {', '.join(kinds)}" in r.stdout
    assert (tmp_path / "t.png").stat().st_size > 20_000


def test_the_k_threshold_of_the_fits_is_that_of_their_draws(measured):
    out, _, _ = measured
    loo = load_loo(out / VELVET)
    doc = _results(out, VELVET)
    assert doc["loo"]["k_threshold"] == pytest.approx(k_threshold(loo.draws))
    assert doc["loo"]["draws"] == loo.draws
    high = [w for w in doc["warnings"] if w["kind"] == "pareto_k"]
    if (loo.pareto_k > k_threshold(loo.draws)).any():
        assert high and f"Pareto k > {k_threshold(loo.draws):.2f}" in high[0]["message"]
    else:
        assert not high
