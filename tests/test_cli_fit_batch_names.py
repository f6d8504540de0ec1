"""`microcyl fit-batch` with tables named after the batch's own files (issue 35, item 9):
``summary.json.csv`` made the folder ``summary.json/``, the batch failed and every rerun said
"cannot read the batch summary". A table's folder now avoids the batch's files (case
ignored), the batch and its rerun succeed, and a job or a summary row named so is refused."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from _fitmodels import fabric_table
from analysis.batch import BatchJob, run_batch
from analysis.batch.jobs import table_names
from analysis.batch.summary import BATCH_FILES, BatchSummary
from reports.report_batch import PAGE
from test_cli_fit import _write_csv

pytest.importorskip("distributed")
ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--fabric", "silk_crepe_de_chine", "--free", "kd1", "--tie", "none", "--max-steps",
       "40", "--check-every", "20", "--no-plots", "--workers", "1"]
#: the batch's own files, written out here (not taken from the code under test)
OWN = {"summary.json", "summary.csv", "index.html", "measured.json"}


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=600)


def test_the_batch_files_are_the_ones_it_writes():
    assert set(BATCH_FILES) == OWN and PAGE in BATCH_FILES


def test_table_names_avoid_the_batch_files_case_ignored():
    names = table_names([(Path(f"/d/{n}.csv"), None) for n in
                         ("summary.json", "SUMMARY.CSV", "index.html", "measured.json", "t")])
    assert names[-1] == "t"
    for name, stem in zip(names, ("summary.json", "SUMMARY.CSV", "index.html", "measured.json")):
        assert name.casefold() not in OWN and name.startswith(f"{stem}-"), name
    assert len({n.casefold() for n in names}) == 5


def test_fit_batch_with_tables_named_after_its_files_and_the_rerun(tmp_path):
    src = tmp_path / "in"
    src.mkdir()
    for k, stem in enumerate(("summary.json", "Index.HTML")):
        table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=k)
        _write_csv(table, src / f"{stem}.csv")
    out = tmp_path / "out"
    r = microcyl("fit-batch", src, *FIT, "-o", out)
    assert r.returncode == 0, r.stderr[-3000:]
    assert (out / "summary.json").is_file() and (out / "index.html").is_file()
    rows = json.loads((out / "summary.json").read_text())["tables"]
    names = sorted(row["name"] for row in rows)
    assert [n.split("-")[0] for n in names] == ["Index.HTML", "summary.json"]
    assert all((out / n / "results.json").is_file() for n in names)
    again = microcyl("fit-batch", src, *FIT, "-o", out)
    assert again.returncode == 0, again.stderr[-3000:]
    assert "cannot read the batch summary" not in again.stderr


def test_a_folder_left_where_the_summary_goes_is_named(tmp_path):
    (tmp_path / "out" / "summary.json").mkdir(parents=True)
    with pytest.raises(ValueError, match=r"summary.json is a folder, not the batch summary.*"
                                         r"move it away"):
        BatchSummary(tmp_path / "out")


def test_a_job_or_a_summary_row_named_after_a_batch_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="'Summary.CSV' is the name of a file of the batch"):
        run_batch([BatchJob("Summary.CSV", str(tmp_path / "t.csv"))], tmp_path / "out",
                  progress=False)
    assert not (tmp_path / "out").exists()
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "summary.json").write_text(json.dumps(
        {"schema": "microcyl-batch", "version": 1,
         "tables": [{"name": "index.html", "status": "converged", "steps": 4}]}))
    with pytest.raises(ValueError, match=r"tables\[0\].name: 'index.html' is the name of a "
                                         r"file of the batch"):
        BatchSummary(tmp_path / "b")
