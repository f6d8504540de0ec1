"""Tests of the ``microcyl energy`` and ``microcyl reciprocity`` verbs."""

import json

import brdf
from reports.cli import main


def test_bad_fabric_one_line_listing_presets(capsys):
    assert main(["energy", "bogus"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bogus" in err[0] and all(p in err[0] for p in brdf.PRESETS)
    assert main(["reciprocity", "bogus"]) == 1
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_bad_variant(capsys):
    assert main(["energy", "linen_plain", "--variants", "nope"]) == 1
    assert "nope" in capsys.readouterr().err


def test_energy_small_json(tmp_path, capsys):
    out = tmp_path / "e.json"
    rc = main(["energy", "silk_shot", "--variants", "default", "--theta-step", "45",
               "--phi", "0", "--no-furnace", "--no-hemispherical", "--workers", "1",
               "--quiet", "--json", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "silk_shot" in text and "+-" in text
    d = json.loads(out.read_text())
    assert d["settings"]["theta_deg"] == [0.0, 45.0, 85.0, 89.0]
    assert len(d["curves"]) == 2
    assert not list(tmp_path.glob(".*tmp"))


def test_reciprocity_small_json(tmp_path, capsys):
    out = tmp_path / "r.json"
    rc = main(["reciprocity", "velvet", "-n", "300", "--grid-step", "45", "--no-felts",
               "--variants", "default,gap_outgoing", "--json", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "velvet" in text and "median" in text
    d = json.loads(out.read_text())
    assert [r["variant"] for r in d["rows"]] == ["default", "gap_outgoing"]
    assert "geometry" in d["rows"][0]


def test_json_folder_missing(tmp_path, capsys):
    rc = main(["reciprocity", "velvet", "-n", "10", "--no-felts", "--grid-step", "0",
               "--json", str(tmp_path / "no" / "r.json")])
    assert rc == 1
    assert "does not exist" in capsys.readouterr().err


def test_sanity_all_presets_as_a_user_runs_it(tmp_path):
    """``microcyl sanity all --json`` in a subprocess: every preset of the paper is finite and
    non-negative at the edges, the JSON holds each check, the exit status says so."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    repo = Path(__file__).resolve().parents[1]
    out = tmp_path / "sanity.json"
    p = subprocess.run([sys.executable, "-m", "reports", "sanity", "all", "--json", str(out)],
                       cwd=repo, env=dict(os.environ, PYTHONPATH=str(repo)), capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    doc = json.loads(out.read_text())
    assert set(doc) == set(brdf.PRESETS) and all(d["ok"] for d in doc.values())
    assert all(len(d["checks"]) > 100 for d in doc.values())
    assert p.stdout.count(": ok (") == len(brdf.PRESETS)


def test_sanity_reports_a_broken_fabric(monkeypatch, capsys):
    """A fabric whose eval returns a NaN at grazing incidence is caught, and the exit is 1."""
    import numpy as np
    import analysis.sanity

    class Broken:
        def eval(self, wi, wo):
            wi = np.asarray(wi)
            f = np.full(np.broadcast_shapes(wi.shape, np.shape(wo)), 0.1)
            f[wi[..., 2] < 1e-3] = np.nan
            return f

    real = analysis.sanity.sanity_scan
    monkeypatch.setattr(analysis.sanity, "sanity_scan",
                        lambda name, **kw: real(Broken(), **kw) if name == "velvet" else real(name))
    assert main(["sanity", "velvet"]) == 1
    out = capsys.readouterr().out
    assert "velvet: VIOLATIONS" in out and "non-finite" in out


def test_energy_prints_a_summary_first_and_the_tables_with_verbose(tmp_path):
    """As a user runs it: the summary names velvet's reflectance above 1 at grazing incidence
    in a few lines; --verbose adds the full tables."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    base = [sys.executable, "-m", "reports", "energy", "velvet", "--variants", "default",
            "--theta-step", "45", "--phi", "0", "--no-furnace", "--no-hemispherical",
            "--workers", "1", "--quiet"]
    short = subprocess.run(base, capture_output=True, text=True, env=env, cwd=tmp_path)
    assert short.returncode == 0, short.stderr
    lines = short.stdout.strip().splitlines()
    assert len(lines) <= 6
    assert lines[1].startswith("velvet (default): ENERGY CREATED: reflectance exceeds 1 "
                               "from theta_i = 89 deg")
    assert "Directional albedo maxima" not in short.stdout
    full = subprocess.run(base + ["--verbose"], capture_output=True, text=True, env=env,
                          cwd=tmp_path)
    assert full.returncode == 0, full.stderr
    assert full.stdout.startswith(short.stdout.split("\n(")[0])
    assert "Directional albedo maxima" in full.stdout and "Findings" in full.stdout
