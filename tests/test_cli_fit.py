"""Tests of ``microcyl fit`` (reports.cli.fit) end to end on small simulated tables."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import reports.cli.fit as cmd_fit
from gonio.table import Table
from reports.cli import main
from _fitmodels import fabric_table


def _write_csv(table, path):
    """CSV in gonio's table format: angles in degrees, r,g,b and sigma_r,g,b columns."""
    a = np.degrees(table.angles)
    cols = np.concatenate([a, table.values, table.sigma], axis=1)
    with open(path, "w") as fh:
        fh.write("# microcyl BRDF table\n")
        fh.write("theta_i,phi_i,theta_o,phi_o,r,g,b,sigma_r,sigma_g,sigma_b\n")
        for row in cols:
            fh.write(",".join(f"{x:.17g}" for x in row) + "\n")


def _read_csv(path, sample=None):
    d = np.loadtxt(path, delimiter=",", comments="#", skiprows=2)
    t, p = np.radians(d[:, 0:4:2]), np.radians(d[:, 1:4:2])
    w = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    return Table(w[:, 0], w[:, 1], d[:, 4:7], sigma=d[:, 7:10])


@pytest.fixture
def table_file(tmp_path, monkeypatch):
    import gonio
    if not hasattr(gonio, "read"):          # until gonio's readers are merged
        monkeypatch.setattr(cmd_fit, "read_table", _read_csv)
    table, _ = fabric_table("silk_crepe_de_chine", n=150, seed=9)
    path = tmp_path / "silk.csv"
    _write_csv(table, path)
    return path


def test_fit_writes_results_and_plots(table_file, tmp_path, capsys):
    out = tmp_path / "fit"
    args = ["fit", str(table_file), "--fabric", "silk_crepe_de_chine", "--free", "gamma_s1,kd1",
            "--tie", "none", "--max-steps", "60", "--check-every", "30",
            "--no-progress", "-o", str(out)]
    assert main(args) == 0
    doc = json.loads((out / "results.json").read_text())
    par = doc["parameters"]
    assert set(par) == {"gamma_s1", "kd1"} and isinstance(doc["converged"], bool)
    for k in ("median", "lo68", "hi68", "lo95", "hi95", "tau", "rhat", "ess"):
        assert np.isfinite(par["kd1"][k])
    assert par["gamma_s1"]["lo95"] < 5.0 < par["gamma_s1"]["hi95"]
    assert doc["quality"]["albedo_delta_e2000"] < 2.0   # same model, 5% noise: barely visible
    assert set(doc["plots"]) == {"corner", "traces", "lobes", "residuals", "adequacy", "pit"}
    for name in ("corner", "traces", "lobes", "residuals", "adequacy", "pit"):
        assert (out / f"{name}.png").stat().st_size > 1000
    assert (out / "results.csv").exists() and (out / "loo.npz").exists()
    assert doc["loo"]["elpd"] == pytest.approx(float(np.load(out / "loo.npz")["elpd_i"].sum()))
    # the model that made the table describes it; both informed, nothing at a bound
    assert doc["adequate"] is True and doc["quality"]["adequacy"]["tests"]["distribution"]["p"]
    assert doc["warnings"] == []
    text = capsys.readouterr().out
    assert "gamma_s1" in text and "results:" in text
    assert f"PSIS-LOO: elpd {doc['loo']['elpd']:.1f} ± {doc['loo']['se']:.1f}" in text
    lines = text.splitlines()
    verdict = next(i for i, line in enumerate(lines) if line.startswith("CONVERGED") or
                   "step limit" in line)
    assert lines[verdict + 1].startswith("ADEQUATE: no test rejects the model")
    # same command again: resumes (no new optimisation), same folder accepted
    assert main(args[:-2] + ["--no-plots", "-o", str(out)]) == 0


def test_bad_input_is_one_line(table_file, tmp_path, capsys):
    out = str(tmp_path / "x")
    base = ["fit", str(table_file), "--fabric", "silk_crepe_de_chine", "--no-progress", "-o", out]
    assert main(base + ["--free", "eta1,kd9"]) == 1
    err = capsys.readouterr().err
    assert "unknown free parameter 'kd9'" in err and "gamma_s1" in err and len(
        err.strip().splitlines()) == 1
    assert main(base[:3] + ["velour"] + base[4:]) == 1
    assert "unknown fabric 'velour'" in capsys.readouterr().err
    spec = tmp_path / "s.toml"
    spec.write_text('free = ["gamma_s1"]\n[bounds]\ngamma_s1 = [6.0, 30.0]\n')
    assert main(base + ["--spec", str(spec)]) == 1
    assert "start value of gamma_s1" in capsys.readouterr().err


def test_a_refused_fit_leaves_no_new_folder(tmp_path, capsys):
    """Refusals that need the table (too few values, chains larger than memory): no new
    folder left (nor its new parent), an existing folder left as it was."""
    table, _ = fabric_table("silk_crepe_de_chine", n=1, seed=3)     # 3 values
    few = tmp_path / "few.csv"
    _write_csv(table, few)
    silk = tmp_path / "silk.csv"
    _write_csv(fabric_table("silk_crepe_de_chine", n=40, seed=4)[0], silk)
    cases = [
        (few, ["--free", "gamma_s1,kd1,eta1", "--tie", "none"], "3 valid values"),
        (silk, ["--free", "kd1", "--walkers", "2000000", "--max-steps", "20000"], "memory"),
    ]
    existing = tmp_path / "existing"      # empty: a folder of the user's files is refused
    existing.mkdir()                      # before the table is read (test_cli_fit_outputs)
    for table_path, extra, message in cases:
        new = tmp_path / "new" / "deeper"
        for out in (new, existing):
            args = ["fit", str(table_path), "--fabric", "silk_crepe_de_chine",
                    "--no-progress", "--no-plots", "-o", str(out)] + extra
            assert main(args) == 1
            err = capsys.readouterr().err
            assert message in err and len(err.strip().splitlines()) == 1, err
            assert not (tmp_path / "new").exists(), (extra, sorted(tmp_path.iterdir()))
            assert sorted(p.name for p in existing.iterdir()) == []


def test_fit_prints_each_warning_after_the_verdict(tmp_path):
    """As a user runs it (a subprocess, progress bar on): a table whose k_d1 is 0, fitted from
    the preset (k_d1 = 0.2): the verdict, then the adequacy line, then one line per warning,
    the at_bound of kd1 among them, and results.json holds the same."""
    import brdf
    silk = brdf.fabric("silk_crepe_de_chine")
    t1, t2 = silk.threads
    kd0 = silk.replace(threads=(t1.replace(kd=0.0), t2))
    table, _ = fabric_table("silk", n=150, seed=4, fab=kd0)
    path = tmp_path / "kd0.csv"
    _write_csv(table, path)
    out = tmp_path / "fit"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    p = subprocess.run([sys.executable, "-m", "reports", "fit", str(path), "--fabric",
                        "silk_crepe_de_chine", "--free", "kd1,gamma_s1", "--tie", "none",
                        "--max-steps", "100", "--no-plots", "-o", str(out)],
                       env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    lines = p.stdout.splitlines()
    k = next(i for i, line in enumerate(lines) if "step limit" in line or "CONVERGED" in line)
    assert lines[k + 1].startswith(("ADEQUATE: ", "NOT ADEQUATE: "))
    doc = json.loads((out / "results.json").read_text())
    printed = lines[k + 2:k + 2 + len(doc["warnings"])]
    assert printed == [f"warning ({w['kind']}): {w['message']}" for w in doc["warnings"]]
    assert any(w["kind"] == "at_bound" and w["parameters"] == ["kd1"] for w in doc["warnings"])
    assert lines[k + 2 + len(doc["warnings"])].startswith("residuals at the posterior median")
