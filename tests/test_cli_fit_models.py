"""`microcyl fit --model` as a user runs it: a Lambert table fitted by `lambert` and by `charlie`
(subprocesses, progress on, real folders), then the fit folders everywhere a FABRIC goes (plot
lobes, plot table --fit, energy, reciprocity, compare), the refusals (another model resuming a
folder, --fabric or a variant flag with a baseline, export, the masking view), and
`fit-measured --models` on one CUReT dataset with its measured page."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gonio
from brdf.baselines import Lambert

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
SHORT = ["--max-steps", "60", "--check-every", "30"]
TRUE_BASE = (0.3, 0.5, 0.7)


def microcyl(*args, env=None):
    return subprocess.run([sys.executable, "-m", "reports", *map(str, args)],
                          env=dict(ENV, **(env or {})), capture_output=True, text=True,
                          timeout=600)


@pytest.fixture(scope="module")
def fits(tmp_path_factory):
    """lam.csv: a Lambert of base (0.3, 0.5, 0.7) in the warp plane every 10 degrees, SNR 30;
    fitted by lambert (with plots) and charlie (without)."""
    d = tmp_path_factory.mktemp("models")
    t = gonio.measure(Lambert(base=TRUE_BASE), "plane:warp:10", gonio.Instrument(snr=30),
                      seed=1, progress=False)
    gonio.write(t, d / "lam.csv")
    r = microcyl("fit", d / "lam.csv", "--model", "lambert", *SHORT, "-o", d / "lambert")
    assert r.returncode == 0, r.stderr
    assert "model: lambert" in r.stdout and "PSIS-LOO: elpd" in r.stdout
    assert "emcee" in r.stderr                  # the progress lines
    r = microcyl("fit", d / "lam.csv", "--model", "charlie", *SHORT, "--no-plots",
                 "-o", d / "charlie")
    assert r.returncode == 0, r.stderr
    return d


def test_results_name_the_model_and_the_medians_are_the_truth(fits):
    doc = json.loads((fits / "lambert" / "results.json").read_text())
    assert doc["model"] == "lambert"
    assert set(doc["parameters"]) == {"base_r", "base_g", "base_b"}
    med = [doc["parameters"][f"base_{c}"]["median"] for c in "rgb"]
    np.testing.assert_allclose(med, TRUE_BASE, rtol=0.05)
    cfg = json.loads((fits / "lambert" / "fit_config.json").read_text())["config"]
    assert cfg["model"] == "lambert" and "fabric" not in cfg.get("extra", {})
    assert {"lobes.png", "corner.png"} <= {p.name for p in (fits / "lambert").iterdir()}
    assert json.loads((fits / "charlie" / "results.json").read_text())["model"] == "charlie"


def test_fit_folders_of_baselines_go_where_a_fabric_goes(fits, tmp_path):
    r = microcyl("plot", "lobes", fits / "lambert", fits / "charlie", "velvet",
                 "-o", tmp_path / "lobes.png")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "lobes.png").stat().st_size > 10_000
    r = microcyl("plot", "table", fits / "lam.csv", "--fit", fits / "lambert",
                 "-o", tmp_path / "table.png", "--data", tmp_path / "table.csv")
    assert r.returncode == 0, r.stderr
    assert "fit (lambert)" in (tmp_path / "table.csv").read_text()
    r = microcyl("energy", fits / "lambert", "--no-furnace", "--json", tmp_path / "e.json")
    assert r.returncode == 0, r.stderr
    curves = json.loads((tmp_path / "e.json").read_text())["curves"]
    assert {c["variant"] for c in curves} == {"default"}     # variants are the fabric's
    # a Lambertian albedo is its base at every angle (the fit's medians, near the truth)
    for c in curves:
        np.testing.assert_allclose(np.asarray(c["value"]).reshape(-1, 3).max(0), TRUE_BASE,
                                   rtol=0.05)
    r = microcyl("reciprocity", fits / "lambert", "--no-felts", "-n", "2000")
    assert r.returncode == 0, r.stderr
    assert "lambert" in r.stdout
    r = microcyl("compare", fits / "charlie", fits / "lambert", "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    assert {row["model"] for row in rows} == {"lambert", "charlie"}
    text = microcyl("compare", fits / "charlie", fits / "lambert").stdout
    assert "model" in text.splitlines()[0] and "(lambert)" in text and "(charlie)" in text


@pytest.mark.parametrize("args, message", [
    (("fit", "{t}", "--model", "charlie", *SHORT, "-o", "{d}/lambert"),
     "holds a fit of model lambert, not charlie"),
    (("fit", "{t}", "--model", "lambert", "--fabric", "velvet", "-o", "{d}/x"),
     "--fabric applies to --model microcylinder only"),
    (("fit", "{t}", "--model", "lambert", "--masking", "off", "-o", "{d}/x"),
     "--model lambert takes no fabric variant option (masking)"),
    (("fit", "{t}", "-o", "{d}/x"), "--fabric PRESET is required for --model microcylinder"),
    (("fit", "{t}", "--model", "lambert", "--free", "eta1", "-o", "{d}/x"),
     "unknown free parameter 'eta1'"),
    (("export", "{d}/lambert", "-o", "{d}/x.json"), "is a fit of model lambert"),
    (("plot", "masking", "{d}/lambert", "-o", "{d}/m.png"), "is no microcylinder fabric"),
    (("plot", "lobes", "{d}/lambert", "--masking", "off", "-o", "{d}/m.png"),
     "a fit of model lambert takes no model option"),
])
def test_refusals_are_one_line(fits, args, message):
    r = microcyl(*[a.format(t=fits / "lam.csv", d=fits) for a in args])
    assert r.returncode != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], r.stderr
    assert not (fits / "x").exists() and not (fits / "x.json").exists()


def test_fit_measured_ranks_the_models_of_a_dataset(velvet_two_models, tmp_path):
    out, stdout, _ = velvet_two_models      # conftest's run, shared with test_cli_verdict
    assert "of 2 fits converged" in stdout
    entry = json.loads((out / "measured.json").read_text())["datasets"]["curet_07_velvet"]
    models = entry["models"]
    assert set(models) == {"microcylinder", "lambert"}
    assert sorted(m["rank"] for m in models.values()) == [1, 2]
    assert (out / "curet_07_velvet-lambert" / "results.json").is_file()
    lam = models["lambert"]
    # CUReT is grey and relative: the base fixed, the scale free, and said so
    assert any("relative table" in n for n in lam["identifiability"])
    doc = json.loads((out / "curet_07_velvet-lambert" / "results.json").read_text())
    assert set(doc["parameters"]) == {"scale", "log_noise"}
    worse = max(models.values(), key=lambda m: m["rank"])
    best = min(models.values(), key=lambda m: m["rank"])
    assert worse["d_elpd"] == pytest.approx(best["elpd"] - worse["elpd"], abs=1e-6)
    # the measured page: a table of the models under a verdict sentence
    from reports.report_measured import measured_page, read_measured
    body, summary = measured_page(tmp_path / "page", read_measured(out))
    text = str(body)
    assert "<h3>Models</h3>" in text and "best − this" in text
    assert ("is preferred over" in text) or ("cannot separate" in text) or (
        "a close call" in text)
    assert summary["curet_07_velvet"]["models"]["lambert"]["rank"] in (1, 2)


def test_a_hostile_models_entry_is_escaped_or_refused(tmp_path):
    from reports.report_measured import measured_page, read_measured
    evil = "<script>alert(1)</script>"
    models = {"lambert": {"rank": 1, "elpd": 10.0, "se": 1.0, "d_elpd": 0.0, "d_se": 0.0,
                          "converged": True, "adequate": None, "error": evil,
                          "identifiability": [evil]},
              "charlie": {"rank": 2, "elpd": 2.0, "se": 1.0, "d_elpd": 8.0, "d_se": 2.0,
                        "converged": False}}
    doc = {"datasets": {"curet_07_velvet": {"title": evil, "models": models}}}
    (tmp_path / "measured.json").write_text(json.dumps(doc))
    body, _ = measured_page(tmp_path / "page", read_measured(tmp_path))
    text = str(body)
    assert "<script>" not in text and "&lt;script&gt;" in text
    assert "lambert is preferred over charlie by 8.0 ± 2.0 (4.0 se)" in text
    for field, value, allowed in (("elpd", "x", "a finite number or null"),
                                  ("rank", -1, "an integer >= 0 or null"),
                                  ("identifiability", [1], "a list of strings")):
        bad = json.loads(json.dumps(doc))
        bad["datasets"]["curet_07_velvet"]["models"]["lambert"][field] = value
        (tmp_path / "measured.json").write_text(json.dumps(bad))
        with pytest.raises(ValueError) as info:
            read_measured(tmp_path)
        msg = str(info.value)
        assert f"datasets.curet_07_velvet.models.lambert.{field} must be {allowed}" in msg
        assert "\n" not in msg
    for name in ("../x", "b<i>x"):        # a model's name is a safe file name or refused
        bad = dict(doc, datasets={"curet_07_velvet": {"models": {name: {}}}})
        (tmp_path / "measured.json").write_text(json.dumps(bad))
        with pytest.raises(ValueError, match="models: name .* refused"):
            read_measured(tmp_path)


def test_fit_batch_fits_a_baseline_model(fits, tmp_path):
    """`fit-batch --model lambert` (options after the inputs, in any order) fits every table by
    the model and records it; --fabric with a baseline and a microcylinder batch without
    --fabric are one-line refusals."""
    r = microcyl("fit-batch", fits / "lam.csv", "-o", tmp_path / "b", *SHORT, "--model",
                 "lambert", "--workers", "1", "--no-plots")
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "b" / "lam" / "results.json").read_text())
    assert doc["model"] == "lambert" and set(doc["parameters"]) == {"base_r", "base_g", "base_b"}
    for args, message in ((["--model", "lambert", "--fabric", "velvet"], "--fabric applies"),
                          ([], "--fabric PRESET is required")):
        r = microcyl("fit-batch", fits / "lam.csv", "-o", tmp_path / "c", *args)
        assert r.returncode != 0 and message in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
