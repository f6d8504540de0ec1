"""Tests of reports.report: the HTML report, its links, its providers and its failures."""

import json
from html.parser import HTMLParser
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from reports import report as rep  # noqa: E402
from reports_standin import Phongish  # noqa: E402

FABRICS = ["velvet", "silk_crepe_de_chine"]


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.sections = [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img" and a.get("src"):
            self.links.append(a["src"])
        if tag == "a" and a.get("href") and not a["href"].startswith("#"):
            self.links.append(a["href"].split("#")[0])
        if tag == "section":
            self.sections.append((a.get("id"), a.get("class"), a.get("data-fabric")))


def parse(path: Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


class FakeCurve:
    def __init__(self, theta, phi):
        t = np.radians(np.asarray(theta))[:, None, None]
        self.value = np.broadcast_to(0.5 * np.cos(t) * np.array([1.0, 0.8, 0.6]),
                                     (len(theta), len(phi), 3)).copy()
        self.error = np.full_like(self.value, 1e-3)


def fake_providers(monkeypatch, calls):
    def albedo_curve(fab, theta, phi):
        calls.append("albedo")
        return FakeCurve(theta, phi)

    def render(scene, fab, width, height, spp, progress):
        calls.append(("render", scene, getattr(fab, "options", {}).get("masking")))
        return np.full((height, width, 3), 0.25, dtype=np.float32)

    table = {("analysis", "albedo_curve"): albedo_curve, ("reports.render", "render"): render}
    monkeypatch.setattr(rep, "_optional", lambda m, a: table.get((m, a)))


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
    fabric_sections = [s for s in idx.sections if s[1] == "fabric"]
    assert [s[0] for s in fabric_sections] == [f"fabric-{n}" for n in FABRICS]
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
                 or ".tmp-" in p.name or ".old-" in p.name]
    assert leftovers == []


def test_absent_providers_say_not_available(tmp_path, monkeypatch):
    monkeypatch.setattr(rep, "_optional", lambda m, a: None)
    fab = Phongish()
    index = rep.build_report({"standin": fab}, tmp_path / "rep", quality="fast", progress=False,
                             sections=["energy", "renders", "parameters"])
    page = (tmp_path / "rep" / "standin.html").read_text()
    assert page.count("Not available") == 2
    assert "albedo" in page and "reports.render" in page
    assert "Albedo compared" in index.read_text()
    assert (tmp_path / "rep" / "standin" / "parameters.json").is_file()


def test_rerun_replaces_a_report_but_never_another_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(rep, "_optional", lambda m, a: None)
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
    monkeypatch.setattr(rep, "_optional", lambda m, a: None)

    def boom(page):
        raise KeyboardInterrupt

    monkeypatch.setitem(rep._BUILDERS, "reciprocity", boom)
    with pytest.raises(KeyboardInterrupt):
        rep.build_report({"a": Phongish(), "b": Phongish()}, tmp_path / "rep", quality="fast",
                         progress=False, sections=["parameters", "reciprocity"])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(fabrics=["velvet", "tweed"]), ValueError, "unknown fabric 'tweed'; valid: linen_plain"),
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
