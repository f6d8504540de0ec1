"""Parts of the HTML report checked alone: the report folder's life (built aside, marked,
swapped in whole, refused when it holds what a report did not write) and the parameters,
reciprocity and sanity sections against answers known beforehand (a preset's own numbers, a
Lambertian BRDF's exact reciprocity)."""

import json

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import brdf  # noqa: E402
from reports.report import folder, sec_parameters, sec_reciprocity, sec_sanity  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports.report.settings import QUALITIES  # noqa: E402
from reports_standin import Lambert  # noqa: E402


def _build(out, files):
    tmp = folder.make_build_folder(out)
    for name, data in files.items():
        (tmp / name).parent.mkdir(parents=True, exist_ok=True)
        folder.write_file(tmp / name, data)
    folder.write_marker(tmp)
    folder.swap_into_place(tmp, out)


def test_report_folder_built_aside_marked_swapped_whole_and_refused_when_touched(tmp_path):
    out = folder.check_output_dir(tmp_path / "rep")       # missing: accepted, not created
    assert out == (tmp_path / "rep").resolve() and not out.exists()
    _build(out, {"index.html": "<p>one</p>", "img/a.png": b"\x89PNG"})
    marker = json.loads((out / folder.MARKER).read_text())
    assert marker["files"] == ["img/a.png", "index.html"]
    folder.check_report_folder(out)                       # an earlier report: replaceable
    _build(out, {"index.html": "two"})
    assert (out / "index.html").read_text() == "two" and not (out / "img").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]      # no temporary left beside
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match=r"holds files a report did not write \(notes.txt\)"):
        folder.check_output_dir(out)
    fit = tmp_path / "fit"
    fit.mkdir()
    (fit / "results.json").write_text("{}")
    with pytest.raises(ValueError, match=r"holds a fit \(results.json\), not a microcyl"):
        folder.check_report_folder(fit)


def test_parameters_section_shows_the_presets_own_numbers(tmp_path):
    fab = brdf.fabric("velvet")
    params = sec_parameters.parameters_of(fab)
    threads = brdf.preset_threads("velvet")
    assert len(params["threads"]) == len(threads) == 2
    assert [t["eta"] for t in params["threads"]] == [float(t.eta) for t in threads]
    assert params["options"]["masking"] is True
    assert sec_parameters.parameters_of(object()) == {"threads": [], "options": {}}
    page = Page(tmp_path, "velvet", fab, QUALITIES["fast"], "velvet")
    sec = sec_parameters.section_parameters(page)
    assert "T2" in str(sec.html) and "specular 30 warp" in str(sec.html)
    saved = json.loads((tmp_path / "velvet" / "parameters.json").read_text())
    assert saved["threads"][1]["eta"] == float(threads[1].eta)
    assert set(sec.data.summary()) == {"parameters", "standard_geometries"}


def test_reciprocity_section_of_a_lambertian_brdf_is_exactly_zero(tmp_path):
    sec = sec_reciprocity.section_reciprocity(
        Page(tmp_path, "lambert", Lambert(), QUALITIES["fast"]))
    summary = sec.data.summary()
    assert set(summary["reciprocity_maps"]) == {"warp", "weft"}
    assert all(v == {"median": 0.0, "max": 0.0} for v in summary["reciprocity_maps"].values())
    assert summary["reciprocity"]["max"] == 0.0
    assert (tmp_path / "lambert" / "reciprocity.png").is_file()


def test_sanity_check_passes_only_when_nothing_was_found():
    ok = {"n_nonfinite": 0, "n_negative": 0, "warnings": []}
    assert sec_sanity.check_passes(ok)
    assert sec_sanity.check_passes({**ok, "n_nonzero_below_horizon": 0})
    assert not sec_sanity.check_passes({**ok, "n_negative": 2})
    assert not sec_sanity.check_passes({**ok, "n_nonfinite": 1})
    assert not sec_sanity.check_passes({**ok, "warnings": ["overflow"]})
    assert not sec_sanity.check_passes({**ok, "n_nonzero_below_horizon": 3})
