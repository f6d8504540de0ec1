"""`microcyl fit -o DIR` writes only where fits wrote before (issue 35, item 7): a folder of
the user's files (the measurement itself as results.csv, a corner.png) is refused, naming
them, and left as it was; a table inside the output folder is refused; the folder of an
earlier fit (listed in its .microcyl-fit, or an older fit's without it) resumes."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from _fitmodels import fabric_table
from analysis.fit.outputs import FIT_MARKER
from test_cli_fit import _write_csv

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--fabric", "silk_crepe_de_chine", "--free", "gamma_s1,kd1", "--tie", "none",
       "--check-every", "20", "--ensembles", "2", "--no-progress"]


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=600)


def refused(p, *names):
    err = p.stderr.strip()
    assert p.returncode == 1, (p.returncode, err[-2000:])
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in names:
        assert str(n) in err, f"{n!r} not in {err!r}"
    return err


def snapshot(folder):
    return {p.name: p.read_bytes() for p in Path(folder).iterdir()}


@pytest.fixture(scope="module")
def silk(tmp_path_factory):
    d = tmp_path_factory.mktemp("outputs")
    table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=4)
    _write_csv(table, d / "silk.csv")
    return d / "silk.csv"


def test_fit_never_writes_over_its_table_or_the_users_files(silk, tmp_path):
    mine = tmp_path / "DIR"
    mine.mkdir()
    shutil.copy(silk, mine / "results.csv")               # the measurement, so named
    (mine / "corner.png").write_bytes(b"\x89PNG a figure of mine")
    before = snapshot(mine)
    err = refused(microcyl("fit", mine / "results.csv", *FIT, "--max-steps", "40", "-o", mine),
                  mine / "results.csv", "lies in the output folder")
    assert "choose another output folder" in err
    err = refused(microcyl("fit", silk, *FIT, "--max-steps", "40", "-o", mine),
                  mine, "files a fit did not write (corner.png, results.csv)")
    assert snapshot(mine) == before                     # nothing written, nothing replaced
    # a folder holding only a figure of the user's: refused too, before the table is read
    (tmp_path / "figs").mkdir()
    (tmp_path / "figs" / "corner.png").write_bytes(b"mine")
    refused(microcyl("fit", tmp_path / "missing.csv", *FIT, "-o", tmp_path / "figs"),
            "corner.png")
    assert snapshot(tmp_path / "figs") == {"corner.png": b"mine"}


def test_the_folder_of_an_earlier_fit_resumes_and_refuses_what_the_user_adds(silk, tmp_path):
    out = tmp_path / "fit"
    first = microcyl("fit", silk, *FIT, "--max-steps", "40", "-o", out)
    assert first.returncode == 0, first.stderr
    marker = json.loads((out / FIT_MARKER).read_text())
    assert marker["kind"] == "microcyl fit"
    written = {p.name for p in out.iterdir()} - {FIT_MARKER}
    assert {"results.json", "results.csv", "checkpoint.h5", "corner.png"} <= written
    assert written <= set(marker["files"])             # every file it wrote was claimed
    again = microcyl("fit", silk, *FIT, "--max-steps", "60", "--no-plots", "-o", out)
    assert again.returncode == 0, again.stderr         # the resume takes its files as its own
    assert json.loads((out / "results.json").read_text())["fit"]["steps"] == 60
    (out / "notes.txt").write_text("mine")
    refused(microcyl("fit", silk, *FIT, "--max-steps", "80", "--no-plots", "-o", out),
            "files a fit did not write (notes.txt)")
    assert (out / "notes.txt").read_text() == "mine"
    # the table copied into the fit's folder is refused by name, even where the fit has a
    # file of that name
    shutil.copy(silk, out / "results.csv")
    os.remove(out / "notes.txt")
    refused(microcyl("fit", out / "results.csv", *FIT, "--max-steps", "80", "--no-plots",
                     "-o", out), "lies in the output folder")


def test_an_older_fits_folder_without_the_marker_resumes(silk, tmp_path):
    out = tmp_path / "old"
    first = microcyl("fit", silk, *FIT, "--max-steps", "40", "--no-plots", "-o", out)
    assert first.returncode == 0, first.stderr
    os.remove(out / FIT_MARKER)                          # as a microcyl before it wrote one
    again = microcyl("fit", silk, *FIT, "--max-steps", "60", "--no-plots", "-o", out)
    assert again.returncode == 0, again.stderr
    assert "results.json" in json.loads((out / FIT_MARKER).read_text())["files"]
