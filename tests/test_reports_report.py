"""Tests of reports.report: the HTML report, its links, its providers and its failures."""

import json
from html.parser import HTMLParser
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from analysis import EnergyReport  # noqa: E402
from analysis.sanity import edge_pairs  # noqa: E402
from reports import report as rep  # noqa: E402
from reports.report import sec_energy, sec_renders  # noqa: E402
from reports.report.page import Page  # noqa: E402
from reports_standin import Lambert, Phongish  # noqa: E402

FABRICS = ["velvet", "silk_crepe_de_chine"]


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.sections, self.cards = [], [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img" and a.get("src"):
            self.links.append(a["src"])
        if tag == "a" and a.get("href") and not a["href"].startswith("#"):
            self.links.append(a["href"].split("#")[0])
        if tag == "section":
            self.sections.append((a.get("id"), a.get("class"), a.get("data-fabric")))
        if tag == "article":
            self.cards.append(a.get("id"))


def parse(path: Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


def fake_energy_report(calls):
    """energy_report with the curves 0.5 cos(theta) (1, 0.8, 0.6), error 1e-3."""
    def energy_report(presets, variants, *, theta_deg, phi_deg, **kw):
        calls.append("albedo")
        t = np.radians(np.asarray(theta_deg))[:, None, None]
        value = np.broadcast_to(0.5 * np.cos(t) * np.array([1.0, 0.8, 0.6]),
                                (len(theta_deg), len(phi_deg), 3)).copy()
        curves = [{"preset": presets[0], "variant": variants[0], "mode": m,
                   "value": value.tolist(), "error": np.full_like(value, 1e-3).tolist()}
                  for m in kw.get("modes", ("furnace",))]
        return EnergyReport(settings={}, curves=curves, hemispherical=[], furnace=[],
                            seconds=0.0)
    return energy_report


def fake_providers(monkeypatch, calls):
    def render(scene, fab, width, height, spp, progress, **_):
        calls.append(("render", scene, getattr(fab, "options", {}).get("masking")))
        return np.full((height, width, 3), 0.25, dtype=np.float32)

    def render_mitsuba(scene, fab, width, height, spp, variant, progress):
        calls.append(("render", scene, getattr(fab, "options", {}).get("masking")))
        return np.full((height, width, 3), 0.25, dtype=np.float32)

    monkeypatch.setattr(sec_energy, "energy_report", fake_energy_report(calls))
    monkeypatch.setattr(sec_renders, "render", render)
    monkeypatch.setattr(sec_renders, "render_mitsuba", render_mitsuba)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    calls = []
    fake_providers(mp, calls)
    out = tmp_path_factory.mktemp("r") / "report"
    try:
        index = rep.build_report(FABRICS, out, quality="fast", progress=False)
    finally:
        mp.undo()
    return out, index, calls


def test_report_has_a_section_per_preset_and_every_link_exists(built):
    out, index, calls = built
    assert index == out / "index.html"
    idx = parse(index)
    assert idx.cards == [f"fabric-{n}" for n in FABRICS]      # one card per fabric
    pages = [index] + [out / f"{n}.html" for n in FABRICS]
    n_images = 0
    for page in pages:
        links = parse(page).links
        for link in links:
            assert not link.startswith(("/", "http")), link       # relative, self-contained
            assert (out / link).is_file(), f"{page.name} links missing {link}"
        n_images += sum(l.endswith(".png") for l in links)
    assert n_images >= 15
    for name in FABRICS:
        secs = parse(out / f"{name}.html").sections
        assert [s[0] for s in secs] == list(rep.SECTIONS)
        assert all(s[2] == name for s in secs)
    # providers were called: energy per fabric, three renders per fabric (one without masking)
    assert calls.count("albedo") == 2
    assert ("render", "cylinder", False) in calls and ("render", "curtain", True) in calls


def test_report_data_and_no_leftovers(built):
    out, _, _ = built
    summary = json.loads((out / "summary.json").read_text())
    assert list(summary["fabrics"]) == FABRICS
    v = summary["fabrics"]["velvet"]
    assert v["sections"]["energy"]["status"] == "ok"
    assert v["energy"]["max"] == pytest.approx(0.5)
    assert v["parameters"]["threads"][0]["offsets"] == [-90.0, -50.0]
    assert v["sections"]["fit"]["status"].startswith("not available")
    lobes = np.genfromtxt(out / "velvet" / "lobes.csv", delimiter=",", names=True)
    assert lobes.dtype.names[0] == "theta_o_deg"
    leftovers = [p for p in out.parent.rglob("*") if p.name.endswith(".part")
                 or p.name.startswith(".microcyl-") and p.name != ".microcyl-report"]
    assert leftovers == []


def test_sanity_section_shows_the_scan_per_fabric(built):
    out, _, _ = built
    summary = json.loads((out / "summary.json").read_text())
    directions = list(edge_pairs())
    for name in FABRICS:
        page = parse(out / f"{name}.html")
        assert ("sanity", "report-section", name) in page.sections
        text = (out / f"{name}.html").read_text()
        sec = text[text.index('<section id="sanity"'):]
        sec = sec[:sec.index("</section>")]
        head = sec[sec.index("<thead>"):sec.index("</thead>")]
        assert all(f"<th>{d}</th>" in head for d in directions)
        rows = sec[sec.index("<tbody>"):sec.index("</tbody>")].split("<tr>")[1:]
        cells = [r.split("<td>")[1:] for r in rows]
        assert cells[0][0].startswith("as_given")
        assert all(len(c) == 1 + len(directions) for c in cells)
        checks = json.loads((out / name / "sanity.json").read_text())["checks"]
        assert len(checks) == len(rows) * len(directions)
        s = summary["fabrics"][name]["sanity"]
        assert s["n_checks"] == len(checks) and s["ok"] == all(
            c[1:] == ["ok</td>"] * (len(c) - 2) + ["ok</td></tr>"] for c in cells)
        assert s["ok"]                                   # the presets pass (microcyl sanity)
    assert "Sanity compared" in (out / "index.html").read_text()


def test_a_brdf_that_is_no_preset_gets_its_albedo_and_says_what_is_not_available(tmp_path):
    index = rep.build_report({"standin": Lambert()}, tmp_path / "rep", quality="fast",
                             progress=False,
                             sections=["energy", "renders", "parameters", "masking", "fit"])
    page = (tmp_path / "rep" / "standin.html").read_text()
    assert page.count("Not available") == 2          # masking (no replace) and fit
    assert "replace(masking" in page and "results.json" in page
    assert "Albedos compared" in index.read_text()
    assert (tmp_path / "rep" / "standin" / "parameters.json").is_file()
    energy = json.loads((tmp_path / "rep" / "summary.json").read_text())[
        "fabrics"]["standin"]["energy"]
    # a Lambertian surface of albedo A reflects exactly A in every direction
    assert energy["max"] == pytest.approx(0.5, abs=1e-3)
    assert np.asarray(energy["value"]) == pytest.approx(
        np.broadcast_to([0.5, 0.4, 0.3], (4, 2, 3)), abs=1e-3)


def test_rerun_replaces_a_report_but_never_another_folder(tmp_path, monkeypatch):
    kw = dict(quality="fast", progress=False, sections=["parameters"])
    out = tmp_path / "rep"
    rep.build_report({"a": Phongish()}, out, **kw)
    rep.build_report({"b": Phongish()}, out, **kw)
    assert (out / "b.html").is_file() and not (out / "a.html").exists()
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("precious")
    with pytest.raises(ValueError, match="not a microcyl report"):
        rep.build_report({"a": Phongish()}, other, **kw)
    assert [p.name for p in other.iterdir()] == ["thesis.tex"]


def test_interrupted_report_leaves_nothing(tmp_path, monkeypatch):
    def boom(page):
        raise KeyboardInterrupt

    monkeypatch.setitem(rep.BUILDERS, "reciprocity", boom)
    with pytest.raises(KeyboardInterrupt):
        rep.build_report({"a": Phongish(), "b": Phongish()}, tmp_path / "rep", quality="fast",
                         progress=False, sections=["parameters", "reciprocity"])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(fabrics=["velvet", "tweed"]), ValueError, "unknown fabric 'tweed'; valid presets are linen_plain"),
    (dict(fabrics=[]), ValueError, "fabrics is empty"),
    (dict(fabrics=["velvet"], sections=["lobes", "poetry"]), ValueError, "unknown section"),
    (dict(fabrics=["velvet"], quality="ultra"), ValueError, "quality"),
])
def test_bad_input_fails_before_work(tmp_path, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        rep.build_report(out_dir=tmp_path / "rep", progress=False, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OSError, match="cannot create output folder"):
        rep.build_report(["velvet"], blocker / "sub" / "rep", progress=False)
    with pytest.raises(OSError, match="is a file"):
        rep.build_report(["velvet"], blocker, progress=False)


@pytest.mark.parametrize("quality, size", [("default", (448, 252)), ("high", (1280, 720))])
def test_renders_size_per_quality(tmp_path, monkeypatch, quality, size):
    """Renders are 448 x 252 by default and 1280 x 720 at --quality high, 16 spp or more;
    each links to itself at full size."""
    sizes = []

    def render(scene, fab, width, height, spp, progress, **_):
        assert spp >= 16
        sizes.append((width, height))
        return np.full((height, width, 3), 0.25)

    monkeypatch.setattr(sec_renders, "render", render)
    page = Page(tmp_path, "standin", Lambert(), rep.QUALITIES[quality])
    sec = sec_renders.section_renders(page)
    assert sizes and set(sizes) == {size}
    for stem in ("curtain", "cylinder"):
        src = f"standin/render_{stem}.png"
        assert f'<a href="{src}"' in sec.html and f'<img src="{src}"' in sec.html
    assert (tmp_path / "standin" / "render_curtain.png").stat().st_size > 0


@pytest.mark.parametrize("usable", [True, False])
def test_renders_engine_is_mitsuba_where_it_runs(tmp_path, monkeypatch, usable):
    """A preset is rendered by Mitsuba where llvm_ad_rgb runs (at the quality's
    render_mitsuba size), by the built-in renderer otherwise; the caption and the summary
    name the engine; any BRDF other than a brdf.Fabric goes to the built-in renderer."""
    import brdf
    from reports.mitsuba import render as mitsuba_render
    calls = []
    monkeypatch.setattr(mitsuba_render, "have_mitsuba", lambda: usable)
    monkeypatch.setattr(mitsuba_render, "variant_works", lambda v: (usable, ""))
    monkeypatch.setattr(sec_renders, "render", lambda scene, fab, width, height, spp, progress,
                        **_: calls.append(("builtin", width, height, spp))
                        or np.full((height, width, 3), 0.25))
    monkeypatch.setattr(sec_renders, "render_mitsuba",
                        lambda scene, fab, width, height, spp, variant, progress:
                        calls.append(("mitsuba", width, height, spp))
                        or np.full((height, width, 3), 0.25))
    q = rep.QUALITIES["default"]
    sec = sec_renders.section_renders(Page(tmp_path, "velvet", brdf.fabric("velvet"), q))
    engine = "mitsuba" if usable else "builtin"
    size = q["render_mitsuba" if usable else "render"]
    assert set(calls) == {(engine, *size)} and len(calls) == 3
    assert sec_renders.ENGINES[engine] in sec.html
    assert {r["engine"] for r in sec.data.summary()["renders"].values()
            if isinstance(r, dict)} == {engine}
    calls.clear()
    sec_renders.section_renders(Page(tmp_path, "standin", Lambert(), q))
    assert {c[0] for c in calls} == {"builtin"}
    calls.clear()
    fast = dict(rep.QUALITIES["fast"], render_engine="auto")   # no compile for previews
    sec_renders.section_renders(Page(tmp_path, "velvet", brdf.fabric("velvet"), fast))
    assert {c[0] for c in calls} == {"builtin"}
    if not usable:
        with pytest.raises(ValueError, match="needs mitsuba"):
            sec_renders.render_engine(brdf.fabric("velvet"), "mitsuba")


def test_page_is_a_grid_of_clickable_figures(built):
    """Every figure's image sits in a link to the same file; the sections lay figures out in
    a responsive grid (CSS grid, columns of at least 560 px or the page width)."""
    out, index, calls = built
    page = (out / f"{FABRICS[0]}.html").read_text(encoding="utf-8")
    figures = page.split("<figure")[1:]
    assert len(figures) > 5
    for fig in figures:
        src = fig.split('<img src="', 1)[1].split('"', 1)[0]
        assert f'<a href="{src}"' in fig.split("<img", 1)[0]
    assert '<link rel="stylesheet" href="report.css">' in page
    css = (out / "report.css").read_text(encoding="utf-8")
    assert "display:grid" in css and "minmax(min(100%,560px),1fr)" in css
