"""Text from files reaches the terminal escaped (issue 35, item 6): a table's metadata in
`microcyl info`, a CSV column name in a read error, a fit_config.json free name in `export`'s
"no median" error, loo.npz's table in `compare`, a table's file name in `fit-batch`'s lines.
Each is a field or a name holding an ESC sequence (set the title, clear the screen), BEL and
U+202E, run as a user types it; no control byte reaches stdout or stderr and the escaped text
is shown (:func:`gonio.terminal.shown`)."""

import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from _fitmodels import fabric_table
from gonio.progress import progress_bar, progress_line
from gonio.terminal import shown
from test_cli_fit import _write_csv

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
FIT = ["--fabric", "silk_crepe_de_chine", "--free", "gamma_s1,kd1", "--tie", "none",
       "--check-every", "20", "--ensembles", "2"]
HOSTILE = "\x1b]0;pwned\x07\x1b[2J\u202e"
#: HOSTILE as it must be shown, written out by hand (not by the code under test)
SHOWN = r"\x1b]0;pwned\x07\x1b[2J\u202e"
#: bytes a terminal obeys: ESC, BEL, CSI (C1), DEL, the bidirectional controls and marks
CONTROLS = ("\x1b", "\x07", "\x9b", "\x7f", "\u202a", "\u202b", "\u202c", "\u202d", "\u202e",
            "\u2066", "\u2067", "\u2068", "\u2069", "\u200e", "\u200f", "\u061c")
ROW = "30,0,30,180,0.1,0.1,0.1\n"
HEADER = "theta_i,phi_i,theta_o,phi_o,r,g,b"
#: a column name that clears the screen, blinks, rings and reverses (no ';': a delimiter),
#: and as it must be shown, lower case (column names are read in any case)
COLUMN = "x\x1b[2J\x1b[5mblink\x07\u202e\u009b2J"
COLUMN_SHOWN = r"x\x1b[2j\x1b[5mblink\x07\u202e\x9b2j"


def microcyl(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, timeout=600, cwd=cwd)


def clean(p, *visible):
    """stdout and stderr decoded strictly, holding no control and each of ``visible``."""
    out = p.stdout.decode("utf-8") + p.stderr.decode("utf-8")
    found = [ascii(c) for c in CONTROLS if c in out]
    assert not found, f"{found} reached the terminal: {out[-2000:]!r}"
    for v in visible:
        assert v in out, f"{v!r} not in {out[-2000:]!r}"
    return out


def test_shown_escapes_every_terminal_control_and_keeps_text():
    for c in CONTROLS + ("\n", "\r", "\x00", "\x85", "\u2028", "\udcff"):
        assert shown(f"a{c}b") == "a" + ascii(c)[1:-1] + "b"
    assert shown("silk crêpe: 0.5 ± 0.1 τ") == "silk crêpe: 0.5 ± 0.1 τ"
    assert shown(HOSTILE) == SHOWN
    assert shown("a\x1b\nb", lines=True) == "a\\x1b\nb"


def test_info_shows_the_metadata_escaped(tmp_path):
    t = tmp_path / "t.csv"
    t.write_text(f"# file_format: {json.dumps(HOSTILE)}\n# units: {json.dumps(HOSTILE)}\n"
                 f"{HEADER}\n{ROW}", encoding="utf-8")
    p = microcyl("info", t)
    assert p.returncode == 0, p.stderr
    out = clean(p)
    assert f"format: {SHOWN}\n" in out and f"units: {SHOWN}\n" in out


def test_a_warning_naming_a_hostile_file_is_escaped(tmp_path):
    t = tmp_path / f"{HOSTILE}.csv"
    t.write_text(f"{HEADER}\n0.5,0,0.5,3.1,0.1,0.1,0.1\n")      # radians: a TableWarning
    p = microcyl("info", t)
    assert p.returncode == 0, p.stderr
    clean(p, f"microcyl info: warning: {tmp_path}/{SHOWN}.csv: every angle is within the "
             f"range of radians")


def test_a_column_name_in_a_read_error_is_escaped(tmp_path):
    t = tmp_path / "t.csv"
    t.write_text(f"{HEADER},{COLUMN}\n{ROW.strip()},1\n", encoding="utf-8")
    for verb in (("info",), ("fit", *FIT, "-o", tmp_path / "fit")):
        p = microcyl(verb[0], t, *verb[1:])
        assert p.returncode == 1
        err = clean(p, f"unknown column(s) {COLUMN_SHOWN};")
        assert len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "fit" / "results.json").exists()


@pytest.fixture(scope="module")
def fit(tmp_path_factory):
    """A short finished fit of a silk table (40 steps, no plots)."""
    d = tmp_path_factory.mktemp("terminal")
    table, _ = fabric_table("silk_crepe_de_chine", n=60, seed=4)
    _write_csv(table, d / "silk.csv")
    p = microcyl("fit", d / "silk.csv", *FIT, "--max-steps", "40", "--no-plots", "-o",
                 d / "fit")
    assert p.returncode == 0, p.stderr
    return d / "fit"


def _edit_json(path, change):
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def test_a_free_name_without_a_median_is_escaped(fit, tmp_path):
    bad = tmp_path / "bad"
    shutil.copytree(fit, bad)
    _edit_json(bad / "fit_config.json",
               lambda d: d["config"]["spec"]["free"].append(HOSTILE))
    p = microcyl("export", bad, "-o", tmp_path / "x.json")
    assert p.returncode == 1
    err = clean(p, "no median for free parameter(s)", SHOWN)
    assert len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "x.json").exists()


def _relabel_loo(folder, table):
    with np.load(folder / "loo.npz") as z:
        arrays = dict(z)
    arrays["table"] = np.array(table)
    np.savez(folder / "loo.npz", **arrays)
    _edit_json(folder / "fit_config.json", lambda d: d["config"].__setitem__("table", table))


def test_compare_shows_the_table_of_loo_npz_escaped(fit, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    for f in (a, b):
        shutil.copytree(fit, f)
        _relabel_loo(f, HOSTILE)
    p = microcyl("compare", a, b)
    assert p.returncode == 0, p.stderr
    clean(p, f"values of table {SHOWN};")
    _relabel_loo(b, HOSTILE + "\u2066")           # another table: refused, escaped
    p = microcyl("compare", a, b)
    assert p.returncode == 1
    clean(p, f"(digest {SHOWN}\\u2066)", f"(digest {SHOWN})")


def test_fit_batch_lines_show_a_hostile_file_name_escaped(tmp_path):
    pytest.importorskip("distributed")
    src = tmp_path / "in"
    src.mkdir()
    (src / f"{HOSTILE}.csv").write_text(f"{HEADER},{COLUMN}\n{ROW.strip()},1\n",
                                        encoding="utf-8")
    out = tmp_path / "out"
    p = microcyl("fit-batch", src, *FIT, "--workers", "1", "-o", out)
    assert p.returncode == 1, p.stderr                   # the table's fit failed
    text = clean(p, f"{SHOWN}.csv", "error")
    # the line of the failed table names its file and the bad column, escaped
    line = next(x for x in text.splitlines() if ": error: " in x)
    assert f"{src}/{SHOWN}.csv: line 1: unknown column(s) {COLUMN_SHOWN};" in line
    assert line.count(SHOWN) == 1                 # the file named once
    assert "1 errors" in text


def test_a_progress_label_and_line_are_escaped(monkeypatch):
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with progress_bar(2, desc=f"{HOSTILE}: fit", unit="table") as bar:
        bar.update(2)
    progress_line(f"{HOSTILE}: step 20")
    out = err.getvalue()
    assert not [c for c in CONTROLS if c in out], repr(out)
    assert f"{SHOWN}: fit: 100%" in out and f"{SHOWN}: step 20\n" in out
