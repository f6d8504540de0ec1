"""`microcyl convert` and `microcyl info`."""

import numpy as np

import gonio
from reports.cli import main
from tests._gonio_helpers import random_table


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


def test_curet_info(shared_data, capsys):
    assert main(["info", str(shared_data / "curet" / "abrdf.dat"), "--sample", "44"]) == 0
    out = capsys.readouterr().out
    assert "CUReT sample 44" in out and "rows: 205" in out and "relative" in out


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
    import json
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
