"""Tests of analysis.measured, ``microcyl fit-measured`` and the report's measured-fits page."""

import json
import re

import markupsafe
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
    for name in ("lobes", "residuals", "corner", "traces", "adequacy", "pit"):
        assert (out / "curet_44_linen" / f"{name}.png").stat().st_size > 1000
    assert e["loo"] == res["loo"] and np.isfinite(res["loo"]["elpd"]) and res["loo"]["se"] > 0


def test_report_page_of_measured_fits(fitted, tmp_path):
    from reports.report import build_report
    out, _ = fitted
    index = build_report(["velvet"], tmp_path / "rep", sections=["parameters"], progress=False,
                         quality="fast", measured=out)
    root = index.parent
    page = (root / "measured.html").read_text()
    assert '<section id="curet_44_linen"' in page and "NOT converged" in page
    imgs = re.findall(r'<img src="([^"]+)"', page)
    assert len(imgs) == 6 and all((root / i).stat().st_size > 1000 for i in imgs)
    res = json.loads((out / "curet_44_linen" / "results.json").read_text())
    loo = res["loo"]
    assert f"PSIS-LOO elpd {loo['elpd']:.1f} ± {loo['se']:.1f}" in page
    verdict = {True: "<b>adequate</b>", False: "<b>NOT adequate</b>"}[res["adequate"]]
    assert verdict in page
    for w in res["warnings"]:
        assert str(markupsafe.escape(w["message"])) in page
    assert "measured.html" in index.read_text()
    summary = json.loads((root / "summary.json").read_text())
    assert summary["measured"]["curet_44_linen"]["converged"] is False
    assert summary["measured"]["curet_44_linen"]["loo"] == loo
    with pytest.raises(ValueError, match="measured.json: not found"):
        build_report(["velvet"], tmp_path / "rep2", sections=["parameters"], progress=False,
                     quality="fast", measured=tmp_path)


def test_concurrent_runs_keep_each_others_summary(tmp_path, shared_data, monkeypatch):
    """Two fit-measured runs into one folder: the one that finishes last must not drop the
    entry the other wrote while it was fitting."""
    import analysis.batch
    from analysis.measured import fit_measured
    real = analysis.batch.run_batch

    def batch_and_other_run_finishing(*a, **kw):
        out = real(*a, **kw)
        (tmp_path / "measured.json").write_text(json.dumps(
            {"datasets": {"curet_07_velvet": {"converged": True, "steps": 1}}}))
        return out

    monkeypatch.setattr(analysis.batch, "run_batch", batch_and_other_run_finishing)
    doc = fit_measured(["curet_44_linen"], tmp_path, data_dir=shared_data, max_steps=20,
                       plots=None, progress=False, workers=1)
    on_disk = json.loads((tmp_path / "measured.json").read_text())
    assert set(on_disk["datasets"]) == set(doc["datasets"]) == {"curet_07_velvet",
                                                               "curet_44_linen"}


# ------------------------------------------------------------- hostile measured.json
def _fake_fit(folder, plots=None, extra_files=()):
    """A fit folder as fit-measured writes one: results.json, results.csv and plot files."""
    folder.mkdir(parents=True, exist_ok=True)
    plots = plots if plots is not None else {"lobes": "lobes.png"}
    (folder / "results.json").write_text(json.dumps(
        {"schema": "microcyl-fit", "schema_version": 2, "converged": True, "reason": "ok",
         "parameters": {"kd1": {"median": 0.2, "lo68": 0.1, "hi68": 0.3, "lo95": 0.05,
                                "hi95": 0.4, "tau": 10.0, "rhat": 1.0, "ess": 900.0,
                                "unit": ""}},
         "fit": {}, "quality": {}, "plots": plots}))
    (folder / "results.csv").write_text("parameter,median\nkd1,0.2\n")
    for name in list(plots.values()) + list(extra_files):
        (folder / name).write_bytes(b"\x89PNG planted " + name.encode())


def _measured_dir(root, datasets):
    """DIR/measured.json naming ``datasets`` (name -> entry overrides), every fit in DIR/good."""
    root.mkdir(parents=True, exist_ok=True)
    doc = {"datasets": {n: dict({"title": "t", "preset": "linen_plain", "source": "x",
                                 "pairs": 3, "free": ["kd1"], "ties": [], "converged": True,
                                 "reason": "ok", "steps": 10, "wall_s": 1.0,
                                 "results": "good/results.json", "values_used": 3,
                                 "quality": {}, "albedo_delta_e2000": None}, **e)
                        for n, e in datasets.items()}}
    (root / "measured.json").write_text(json.dumps(doc))
    return root


def _report(tmp_path, measured):
    from reports.report import build_report
    return build_report(["velvet"], tmp_path / "site" / "rep", sections=["parameters"],
                        progress=False, quality="fast", measured=measured)


def _files_under(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("hostile", ["../../escape_target", "../escape_target", "/ABS",
                                     ".hidden", "a/b", "..", "x\ny"])
def test_a_hostile_dataset_name_is_refused_and_nothing_written_outside(tmp_path, hostile):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "authorized_keys").write_text("ssh-ed25519 AAAA the owner's key\n")
    name = str(victim) if hostile == "/ABS" else hostile
    mdir = _measured_dir(tmp_path / "m", {name: {}})
    _fake_fit(mdir / "good", plots={"lobes": "authorized_keys"})
    before = _files_under(tmp_path)
    with pytest.raises(ValueError) as err:
        _report(tmp_path, mdir)
    msg = str(err.value)
    assert "\n" not in msg.replace(repr(name)[1:-1], "")     # one line (the name as repr)
    assert str(mdir / "measured.json") in msg and "datasets" in msg and "refused" in msg
    assert _files_under(tmp_path) == before                  # not one file written anywhere
    assert (victim / "authorized_keys").read_text() == "ssh-ed25519 AAAA the owner's key\n"


@pytest.mark.parametrize("entry", [{"results": "/etc/results.json"},
                                   {"results": "../outside/results.json"},
                                   {"results": ["good", "results.json"]}])
def test_a_results_path_outside_the_folder_is_refused(tmp_path, entry):
    (tmp_path / "outside").mkdir()
    _fake_fit(tmp_path / "outside")
    mdir = _measured_dir(tmp_path / "m", {"felt": entry})
    with pytest.raises(ValueError, match=r"measured\.json: datasets\.felt\.results"):
        _report(tmp_path, mdir)


def test_a_planted_link_is_not_followed_out_of_the_folder(tmp_path):
    """A plot (and a dataset folder) that is a symbolic link to a file outside the measured
    folder is refused: the report never copies a stranger's file into itself."""
    secret = tmp_path / "secret.txt"
    secret.write_text("private")
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json"}})
    _fake_fit(mdir / "felt", plots={"lobes": "lobes.png"})
    (mdir / "felt" / "lobes.png").unlink()
    (mdir / "felt" / "lobes.png").symlink_to(secret)
    with pytest.raises(ValueError, match=r"felt.*outside.*refused"):
        _report(tmp_path, mdir)
    assert not (tmp_path / "site" / "rep").exists()
    elsewhere = tmp_path / "elsewhere"
    _fake_fit(elsewhere)
    mdir2 = _measured_dir(tmp_path / "m2", {"felt": {"results": "felt/results.json"}})
    (mdir2 / "felt").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(ValueError, match=r"datasets\.felt\.results.*outside"):
        _report(tmp_path, mdir2)


def test_a_plot_swapped_for_a_link_after_the_checks_is_refused_not_copied(tmp_path):
    """The checks of read_measured pass; then, before the copy, the plot becomes a link to a
    secret (what a colleague with write access to the shared folder can do while a report
    runs): the copy refuses it by name and nothing of the secret reaches the report."""
    from reports.report_measured import measured_page, read_measured
    secret = tmp_path / "secret.txt"
    secret.write_text("private key material")
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json"}})
    _fake_fit(mdir / "felt", plots={"lobes": "lobes.png"})
    measured = read_measured(mdir)                      # every check passes here
    plot = mdir / "felt" / "lobes.png"
    plot.unlink()
    plot.symlink_to(secret)
    root = tmp_path / "rep"
    root.mkdir()
    with pytest.raises(ValueError) as err:
        measured_page(root, measured)
    msg = str(err.value)
    assert str(plot) in msg and "symbolic link" in msg and "\n" not in msg, msg
    copied = [p for p in root.rglob("*") if p.is_file()]
    assert all(b"private" not in p.read_bytes() for p in copied), copied
    assert not any(p.name.startswith(".microcyl-") for p in root.rglob("*"))


def test_a_sparse_2gb_plot_is_refused_fast_and_nothing_large_is_written(tmp_path):
    """A "PNG" of 2 GB that takes no disk (a sparse file) is refused by its size before a
    byte is copied: the report stops in one line naming it and writes nothing large."""
    import os
    import time
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json"}})
    _fake_fit(mdir / "felt", plots={"lobes": "lobes.png"})
    plot = mdir / "felt" / "lobes.png"
    os.truncate(plot, 2 << 30)
    t0 = time.monotonic()
    with pytest.raises(ValueError) as err:
        _report(tmp_path, mdir)
    assert time.monotonic() - t0 < 60
    msg = str(err.value)
    assert str(plot) in msg and "2048 MiB" in msg and "\n" not in msg, msg
    site = tmp_path / "site"
    sizes = [p.stat().st_size for p in site.rglob("*") if p.is_file()] if site.exists() else []
    assert sum(sizes) < 16 << 20, sizes


@pytest.mark.parametrize("plot", ["../../x.png", "/tmp/x.png", ".x.png", "a/b.png"])
def test_a_hostile_plot_name_in_results_json_is_refused(tmp_path, plot):
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json"}})
    _fake_fit(mdir / "felt", plots={"lobes": "lobes.png"})
    doc = json.loads((mdir / "felt" / "results.json").read_text())
    doc["plots"]["corner"] = plot
    (mdir / "felt" / "results.json").write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"results\.json: plots\.corner: name .* refused"):
        _report(tmp_path, mdir)


def test_safe_names_still_make_the_page(tmp_path):
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json"}})
    _fake_fit(mdir / "felt", plots={"lobes": "lobes.png", "corner": "corner.png"})
    index = _report(tmp_path, mdir)
    root = index.parent
    assert (root / "measured" / "felt" / "lobes.png").read_bytes().startswith(b"\x89PNG")
    assert (root / "measured" / "felt" / "results.json").is_file()
    page = (root / "measured.html").read_text()
    assert 'src="measured/felt/lobes.png"' in page and 'src="measured/felt/corner.png"' in page


def test_the_report_cli_refuses_a_climbing_name_in_one_line(tmp_path):
    import os
    import subprocess
    import sys
    from pathlib import Path
    mdir = _measured_dir(tmp_path / "m", {"../../escape_target": {}})
    _fake_fit(mdir / "good")
    root = Path(__file__).resolve().parents[1]
    r = subprocess.run([sys.executable, "-m", "reports", "report", "--fabric", "velvet",
                        "--quality", "fast", "--measured", str(mdir), "-o",
                        str(tmp_path / "site" / "rep")], capture_output=True, text=True,
                       env=dict(os.environ, PYTHONPATH=str(root)), timeout=300)
    assert r.returncode != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "measured.json: datasets" in lines[0] \
        and "escape_target" in lines[0] and "Traceback" not in r.stderr
    assert not (tmp_path / "escape_target").exists() and not (tmp_path / "site").exists()


@pytest.mark.parametrize("field, value, named", [
    ("values_used", "<script>alert(1)</script>", "datasets.felt.values_used"),
    ("pairs", 3.5, "datasets.felt.pairs"),
    ("steps", -1, "datasets.felt.steps"),
    ("converged", "yes", "datasets.felt.converged"),
    ("quality", {"rms_residual": [1, 2]}, "datasets.felt.quality.rms_residual"),
    ("quality", {"rms_normalized": float("nan")}, "datasets.felt.quality.rms_normalized"),
    ("quality", "good", "datasets.felt.quality"),
    ("albedo_delta_e2000", float("inf"), "datasets.felt.albedo_delta_e2000"),
    ("albedo_delta_e2000", "<b>2</b>", "datasets.felt.albedo_delta_e2000"),
    ("ties", "eta2=eta1", "datasets.felt.ties"),
    ("title", 7, "datasets.felt.title"),
])
def test_a_field_of_measured_json_out_of_its_schema_is_one_line(tmp_path, field, value,
                                                                named):
    mdir = _measured_dir(tmp_path / "m", {"felt": {"results": "felt/results.json",
                                                   field: value}})
    _fake_fit(mdir / "felt")
    with pytest.raises(ValueError) as err:
        _report(tmp_path, mdir)
    msg = str(err.value)
    assert msg.startswith(f"{mdir / 'measured.json'}: {named} must be") and "\n" not in msg
    assert not (tmp_path / "site" / "rep").exists()


@pytest.mark.parametrize("doc", [[1, 2], {"datasets": [1]}, {"datasets": {"x": 3}},
                                 {"datasets": {"../x": {}}}])
def test_fit_measured_refuses_a_damaged_summary_before_any_fit(tmp_path, shared_data, doc,
                                                              monkeypatch):
    import analysis.batch
    from analysis.measured import fit_measured

    def no_batch(*a, **kw):
        raise AssertionError("a fit started")

    monkeypatch.setattr(analysis.batch, "run_batch", no_batch)
    (tmp_path / "measured.json").write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"measured\.json: "):
        fit_measured(["curet_44_linen"], tmp_path, data_dir=shared_data, plots=None,
                     progress=False, workers=1)


def test_dataset_names_differing_only_in_case_are_refused():
    from analysis.measuredjson import check_measured_doc
    with pytest.raises(ValueError, match="m.json: datasets: 'Felt' and 'felt' differ only in"):
        check_measured_doc({"datasets": {"felt": {}, "Felt": {}}}, "m.json")
