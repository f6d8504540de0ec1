"""Tests of analysis.measured, ``microcyl fit-measured`` and the report's measured-fits page."""

import html
import json
import re

import numpy as np
import pytest

from analysis.measured import MEASURED, load_measured, measured_spec
from reports.cli import main


def test_datasets_cover_the_issue_list(shared_data):
    kinds = {d.kind for d in MEASURED.values()}
    assert kinds == {"rgl", "curet"}
    assert {d.sample for d in MEASURED.values() if d.kind == "curet"} == {1, 2, 7, 42, 44, 46}
    t = load_measured("curet_42_corduroy", shared_data)
    assert len(t) == 205 and t.meta["units"] == "relative"
    t = load_measured("rgl_pink_felt", shared_data, rgl_step=30.0)
    assert t.sigma is None and np.all(t.values[t.valid] > 0)
    # the isotropic felt files mirror phi_o: one half of the azimuths, each pair once.
    # 7 incidence nodes below 90 degrees; outgoing theta 15..75 by 15 times phi 0..180 by 15,
    # plus the normal
    t = load_measured("rgl_white_felt", shared_data, rgl_step=15.0)
    assert len(t) == 7 * (5 * 13 + 1)
    assert np.all(t.wo[:, 1] >= -1e-9)
    assert len(np.unique(np.round(np.c_[t.wi, t.wo], 9), axis=0)) == len(t)
    spec, fab = measured_spec("rgl_pink_felt")
    assert {"albedo1_r", "albedo1_g", "albedo1_b"} <= set(spec.free)
    assert spec.ties["albedo2_g"] == ("albedo1_g", "equal") and fab.name == "linen_plain"
    with pytest.raises(ValueError, match="unknown measured dataset 'silk'.*rgl_white_felt"):
        load_measured("silk", shared_data)
    with pytest.raises(FileNotFoundError):
        load_measured("curet_01_felt", shared_data / "nowhere")


@pytest.fixture(scope="module")
def fitted(tmp_path_factory, shared_data):
    out = tmp_path_factory.mktemp("measured")
    status = main(["fit-measured", "curet_44_linen", "--data", str(shared_data),
                   "--max-steps", "60",
                   "--no-progress", "-o", str(out)])
    return out, status


def test_fit_measured_writes_results_and_summary(fitted):
    out, status = fitted
    assert status == 1                      # 60 steps: not converged, and the exit says so
    doc = json.loads((out / "measured.json").read_text())
    e = doc["datasets"]["curet_44_linen"]
    assert e["preset"] == "linen_plain" and e["values_used"] == 205    # grey: once per point
    assert not e["converged"] and "step limit 60" in e["reason"]
    res = json.loads((out / "curet_44_linen" / "results.json").read_text())
    assert res["schema"] == "microcyl-fit" and res["schema_version"] == 2
    assert set(res["parameters"]) >= {"eta1", "kd1", "gamma_s1", "gamma_v1", "area1", "scale",
                                      "log_noise"}
    q = res["quality"]
    assert q == e["quality"] and q["albedo_delta_e2000"] == e["albedo_delta_e2000"]
    # CUReT is grey: no colour difference, and the reason says so
    assert e["albedo_delta_e2000"] is None and "grey" in q["albedo_delta_e2000_reason"]
    assert res["adequate"] in (True, False) and isinstance(res["warnings"], list)
    # the fitted noise explains the residuals: normalized rms near 1, raw rms near exp(noise)
    assert 0.7 < q["rms_normalized"] < 1.3
    assert q["rms_residual"] == pytest.approx(np.exp(res["parameters"]["log_noise"]["median"]), rel=0.3)
    for name in ("lobes", "residuals", "corner", "traces", "adequacy"):
        assert (out / "curet_44_linen" / f"{name}.png").stat().st_size > 1000


def test_report_page_of_measured_fits(fitted, tmp_path):
    from reports.report import build_report
    out, _ = fitted
    index = build_report(["velvet"], tmp_path / "rep", sections=["parameters"], progress=False,
                         quality="fast", measured=out)
    root = index.parent
    page = (root / "measured.html").read_text()
    assert '<section id="curet_44_linen"' in page and "NOT converged" in page
    imgs = re.findall(r'<img src="([^"]+)"', page)
    assert len(imgs) == 5 and all((root / i).stat().st_size > 1000 for i in imgs)
    res = json.loads((out / "curet_44_linen" / "results.json").read_text())
    verdict = {True: "<b>adequate</b>", False: "<b>NOT adequate</b>"}[res["adequate"]]
    assert verdict in page
    for w in res["warnings"]:
        assert html.escape(w["message"]) in page
    assert "measured.html" in index.read_text()
    summary = json.loads((root / "summary.json").read_text())
    assert summary["measured"]["curet_44_linen"]["converged"] is False
    with pytest.raises(ValueError, match="measured.json: not found"):
        build_report(["velvet"], tmp_path / "rep2", sections=["parameters"], progress=False,
                     quality="fast", measured=tmp_path)


def test_concurrent_runs_keep_each_others_summary(tmp_path, shared_data, monkeypatch):
    """Two fit-measured runs into one folder: the one that finishes last must not drop the
    entry the other wrote while it was fitting."""
    import analysis.measured
    from analysis.measured import fit_measured
    real = analysis.measured.run_batch

    def batch_and_other_run_finishing(*a, **kw):
        out = real(*a, **kw)
        (tmp_path / "measured.json").write_text(json.dumps(
            {"datasets": {"curet_07_velvet": {"converged": True, "steps": 1}}}))
        return out

    monkeypatch.setattr(analysis.measured, "run_batch", batch_and_other_run_finishing)
    doc = fit_measured(["curet_44_linen"], tmp_path, data_dir=shared_data, max_steps=20,
                       plots=None, progress=False, workers=1)
    on_disk = json.loads((tmp_path / "measured.json").read_text())
    assert set(on_disk["datasets"]) == set(doc["datasets"]) == {"curet_07_velvet",
                                                               "curet_44_linen"}
