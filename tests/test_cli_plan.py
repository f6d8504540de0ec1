"""`microcyl plan` as a user runs it: a subprocess with the progress bar on, a real output
folder, options in any order; the plan file read back by `microcyl measure --geometry
pairs:FILE`; the same seed gives the same bytes; bad options are one line before any work."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import gonio
from gonio.geomspec import read_pairs_csv
from gonio.pairsfile import read_pairs_header
from reports.cli import main

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100", SOURCE_DATE_EPOCH="1767225600")


def microcyl(*args):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=300)


def test_plan_writes_a_plan_that_measure_reads(tmp_path):
    out = tmp_path / "day1"
    out.mkdir()
    r = microcyl("plan", "--budget", 12, "-o", out / "plan.csv", "--snr", 25, "--free",
                 "kd1,gamma_s1", "--candidates", "full:15:30", "velvet", "--seed", 3,
                 "--max-theta", 75, "--min-separation", 10)
    assert r.returncode == 0, r.stderr
    assert "plan:" in r.stderr                                       # the progress bar
    assert "uniform 12" in r.stdout and "uniform 36" in r.stdout and "gamma_s1" in r.stdout
    png = out / "plan.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    head = read_pairs_header(out / "plan.csv")
    assert head["fabric"] == "velvet" and head["free"] == "kd1,gamma_s1"
    assert head["budget"] == "12" and head["seed"] == "3" and head["date"] == "2026-01-01"
    assert "kd1=" in head["expected_sd"] and "gamma_s1=" in head["expected_sd"]
    geo = read_pairs_csv(out / "plan.csv")
    assert len(geo) == 12
    th = np.degrees(np.arccos(np.concatenate([geo.wi[:, 2], geo.wo[:, 2]])))
    assert th.max() <= 75 + 1e-9
    # the operator's measurement: measure reads the plan file as it is
    m = microcyl("measure", "velvet", "--geometry", f"pairs:{out / 'plan.csv'}", "--snr", 25,
                 "--seed", 1, "--max-theta", 75, "-o", out / "measured.csv")
    assert m.returncode == 0, m.stderr
    table = gonio.read(out / "measured.csv")
    assert len(table) == 12 and np.allclose(table.wi, geo.wi) and np.allclose(table.wo, geo.wo)
    # the same seed gives the same bytes; the next plan after the measured table
    again = tmp_path / "again"
    again.mkdir()
    r2 = microcyl("plan", "--fabric", "velvet", "--free", "kd1,gamma_s1", "--budget", 12,
                  "--snr", 25, "--candidates", "full:15:30", "--seed", 3, "--max-theta", 75,
                  "--min-separation", 10, "-o", again / "plan.csv", "--no-progress")
    assert r2.returncode == 0, r2.stderr
    assert (again / "plan.csv").read_bytes() == (out / "plan.csv").read_bytes()
    r3 = microcyl("plan", "velvet", "--free", "kd1,gamma_s1", "--budget", 6, "--snr", 25,
                  "--candidates", "full:15:30", "--from", out / "measured.csv", "-q", "--grey",
                  "-o", tmp_path / "next.csv")
    assert r3.returncode == 0, r3.stderr
    assert "6 pairs after 12 measured" in r3.stdout
    nxt = read_pairs_header(tmp_path / "next.csv")
    assert nxt["measured_before"] == "12" and nxt["readings"].startswith("grey")


def test_bad_options_are_one_line_before_any_work(tmp_path, capsys):
    out = tmp_path / "p.csv"
    for args, words in (
            (("--free", "kd1,gamma_zz", "--budget", "5", "--snr", "20"), "gamma_zz"),
            (("--free", "kd1", "--budget", "0", "--snr", "20"), "--budget"),
            (("--free", "kd1", "--budget", "5", "--snr", "20", "--candidates", "full:0.5"),
             "candidates"),
            (("--budget", "5"), "--snr"),
            (("--budget", "5", "--snr", "20", "--max-theta", "100"), "--max-theta"),
    ):
        assert main(["plan", "velvet", "-o", str(out), *args]) == 1, args
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], err
    # as typed: argparse's own refusal, one line, exit status 2
    r = microcyl("plan", "velvet", "--snr", 20, "-o", out, "--budget", "five")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "--budget" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists() and not out.with_suffix(".png").exists()
