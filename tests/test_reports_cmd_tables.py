"""`microcyl convert` and `microcyl info`."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import gonio
from reports.cli import main
from tests._gonio_helpers import random_table

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT))


def microcyl(*args, cwd):
    """The command line as a user runs it (a subprocess in ``cwd``)."""
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          cwd=cwd, capture_output=True, text=True, timeout=300)


def test_convert_and_info(tmp_path, capsys):
    src = tmp_path / "t.exr"
    gonio.write(random_table(0), src)
    assert main(["convert", str(src), str(tmp_path / "t.csv")]) == 0
    back = gonio.read(tmp_path / "t.csv")
    assert len(back) == 50
    capsys.readouterr()
    assert main(["info", str(tmp_path / "t.csv")]) == 0
    out = capsys.readouterr().out
    assert "source: test" in out and "rows: 50" in out
    assert "missing values: 2 of 150 (NaN 1, negative 1" in out
    theta_i = np.degrees(back.angles[:, 0])
    assert f"theta_i: {theta_i.min():.4g} .. {theta_i.max():.4g} deg" in out



SOURCE = {"type": "Fabric", "name": "linen_plain", "options": {"masking": True},
          "note": "it's"}


def test_info_prints_the_source_as_json(tmp_path, capsys):
    """A measured table's source is a dict: ``info`` prints it as JSON (it printed the
    Python repr, ``{'type': 'Fabric', ...}``), ``info --json`` as the object."""
    src = tmp_path / "t.csv"
    gonio.write(random_table(0).replace(meta={"source": SOURCE}), src)
    assert main(["info", str(src)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("source:"))
    assert json.loads(line.removeprefix("source: ")) == SOURCE
    assert main(["info", str(src), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["source"] == SOURCE

def test_curet_info(shared_data, capsys):
    assert main(["info", str(shared_data / "curet" / "abrdf.dat"), "--sample", "44"]) == 0
    out = capsys.readouterr().out
    assert "CUReT sample 44" in out and "rows: 205" in out and "relative" in out


def test_curet_info_takes_the_dataset_name(shared_data, capsys):
    """``--sample curet_44_linen`` (fit-measured's name) reads sample 44."""
    assert main(["info", str(shared_data / "curet" / "abrdf.dat"), "--sample",
                 "curet_44_linen"]) == 0
    assert "CUReT sample 44" in capsys.readouterr().out


def test_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("theta_i,phi_i,theta_o,phi_o,value\n0,0,0,0,1\n1,2,3\n")
    assert main(["convert", str(bad), str(tmp_path / "out.exr")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.csv: line 3" in err
    assert not (tmp_path / "out.exr").exists()
    assert main(["info", str(tmp_path / "x.unknown")]) == 1
    assert "known: .exr" in capsys.readouterr().err
    good = tmp_path / "t.csv"
    gonio.write(random_table(0), good)
    for argv, message in ((["info", str(good), "--stride", "2"],
                           "--stride applies to a MERL .binary only, not to t.csv; drop it"),
                          (["convert", str(good), str(tmp_path / "o.exr"), "--step", "5"],
                           "--step applies to an RGL .bsdf only, not to t.csv; drop it")):
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.strip().endswith(f"error: {message}"), err
    assert not (tmp_path / "o.exr").exists()


def test_convert_alta_param(tmp_path, capsys):
    src = tmp_path / "t.exr"
    gonio.write(random_table(0), src)
    out = tmp_path / "t.alta"
    assert main(["convert", str(src), str(out), "--alta-param", "RUSIN_TH_PH_TD_PD"]) == 0
    assert "#PARAM_IN RUSIN_TH_PH_TD_PD" in out.read_text()
    assert gonio.read(out).meta["alta_param"] == "RUSIN_TH_PH_TD_PD"
    assert main(["convert", str(src), str(out), "--alta-param", "NOPE"]) == 1
    assert "param 'NOPE' is not supported" in capsys.readouterr().err


def test_info_of_a_measured_merl_file_stays_above_the_horizon(tmp_path, capsys):
    """A MERL file lists every bin, the empty ones below the horizon too; the angle ranges
    that info prints are those of the bins that hold data: theta at most 90 degrees."""
    out = tmp_path / "m.binary"
    assert main(["measure", "velvet", "--geometry", "merl:6", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    for name in ("theta_i", "theta_o"):
        line = next(ln for ln in text.splitlines() if ln.startswith(name + ":"))
        assert float(line.split("..")[1].split()[0]) <= 90.0 and "(rows with data)" in line


def test_info_json(tmp_path, capsys):
    src = tmp_path / "t.csv"
    table = random_table(0)
    gonio.write(table, src)
    assert main(["info", str(src), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    back = gonio.read(src)
    assert doc["rows"] == 50 and doc["missing"]["nan"] == 1 and doc["missing"]["negative"] == 1
    theta_o = np.degrees(back.angles[:, 2])
    assert doc["angles_deg"]["theta_o"] == [theta_o.min(), theta_o.max()]
    g = back.values[back.valid[:, 1], 1]
    assert doc["values"]["G"] == [g.min(), g.max()]



def test_tables_as_people_write_them(tmp_path):
    """Names in capitals and semicolons read; radians read as degrees with one warning line
    (also with -q); an unknown delimiter named in one error line."""
    (tmp_path / "sheet.csv").write_text("THETA_I;Phi_I;theta_O;PHI_O;R;G;B\n"
                                        "30;0;45;180;0.1;0.2;0.3\n60;90;20;-90;0.4;0.5;0.6\n")
    r = microcyl("info", "sheet.csv", cwd=tmp_path)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "rows: 2" in r.stdout and "theta_o: 20 .. 45 deg" in r.stdout
    (tmp_path / "rad.csv").write_text("theta_i,phi_i,theta_o,phi_o,value\n"
                                      "0.5236,0,0.7854,3.1416,0.1\n")
    for flags in ([], ["-q"]):
        r = microcyl(*flags, "info", "rad.csv", cwd=tmp_path)
        assert r.returncode == 0 and "rows: 1" in r.stdout
        assert r.stderr.count("\n") == 1 and r.stderr.startswith(
            "microcyl info: warning: rad.csv: every angle is within the range of radians"), \
            r.stderr
    (tmp_path / "pipe.csv").write_text("theta_i|phi_i|theta_o|phi_o|value\n30|0|30|0|0.1\n")
    r = microcyl("convert", "pipe.csv", "pipe.exr", cwd=tmp_path)
    assert r.returncode == 1 and r.stderr == (
        "microcyl convert: error: pipe.csv: line 1: found '|' between the column names; "
        "expected comma, semicolon or tab\n")
    assert not (tmp_path / "pipe.exr").exists()


def test_measured_exr_to_csv_and_alta(tmp_path):
    """measure -> EXR (float32) -> CSV: angles as written (``15``, ``180``, not
    ``15.0000004``), the same float32 values read back; the source as JSON in info, the CSV
    comments and the ALTA header."""
    r = microcyl("measure", "velvet", "--geometry", "plane:warp:15:15", "-o", "m.exr",
                 "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    for out in ("m.csv", "m.alta"):
        assert microcyl("convert", "m.exr", out, cwd=tmp_path).returncode == 0
    r = microcyl("info", "m.exr", cwd=tmp_path)
    source = json.loads(next(ln for ln in r.stdout.splitlines()
                             if ln.startswith("source: ")).removeprefix("source: "))
    assert source["type"] == "Fabric" and source["name"] == "velvet"
    text = (tmp_path / "m.csv").read_text()
    assert f"# source: {json.dumps(source, sort_keys=True)}\n" in text
    rows = [ln.split(",") for ln in text.splitlines() if not ln.startswith(("#", "theta"))]
    assert {row[0] for row in rows} == {"15"}
    assert {row[2] for row in rows} == {"0", "15", "30", "45", "60", "75"}
    assert "15.0000004" not in text and "180" in {row[3] for row in rows}
    exr, csv = gonio.read(tmp_path / "m.exr"), gonio.read(tmp_path / "m.csv")
    assert np.array_equal(csv.values.astype(np.float32), exr.values.astype(np.float32))
    assert np.array_equal(csv.angles[:, :3].astype(np.float32),
                          exr.angles[:, :3].astype(np.float32))
    first = (tmp_path / "m.alta").read_text().splitlines()[0]
    assert json.loads(first.removeprefix("# source: ")) == source
