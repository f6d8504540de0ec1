"""The report's renders (reports.report.sec_renders) are exposed for the cloth, one exposure
per scene, and say so in their captions and summary."""

import html

import numpy as np
import pytest

import brdf
from reports import report as rep
from reports.render.engine import cloth_coverage
from reports.report import sec_renders
from reports.report.page import Page


def test_each_scene_is_exposed_for_its_cloth(tmp_path, monkeypatch):
    """A stand-in render whose cloth is 0.1 (curtain) or 0.3 (cylinder) and whose backdrop is
    5.0: each scene's exposure shows its cloth at 0.9, the backdrop is ignored, and the
    cylinder without masking takes the masked cylinder's exposure."""
    q = dict(rep.QUALITIES["fast"], render=(48, 27, 16), render_engine="builtin")
    value = {"curtain": 0.1, "cylinder": 0.3}

    def render(scene, fab, width, height, spp, progress, sky_spp=None):
        assert sky_spp == sec_renders.SKY_SPP
        cloth = cloth_coverage(scene, width, height) >= 0.5
        scale = 2.0 if fab.options.get("masking") is False else 1.0
        img = np.where(cloth[..., None], value[scene] * scale, 5.0)
        return np.broadcast_to(img, (height, width, 3)).copy()

    monkeypatch.setattr(sec_renders, "render", render)
    sec = sec_renders.section_renders(Page(tmp_path, "velvet", brdf.fabric("velvet"), q))
    renders = sec.data.summary()["renders"]
    assert renders["curtain"]["exposure"] == pytest.approx(np.log2(0.9 / 0.1))
    assert renders["cylinder"]["exposure"] == pytest.approx(np.log2(0.9 / 0.3))
    assert renders["cylinder_nomask"]["exposure"] == renders["cylinder"]["exposure"]
    assert renders["cylinder"]["spp"] == 16 and renders["cylinder"]["sky_spp"] == 4
    captions = html.unescape(str(sec.html))
    assert captions.count("16 spp (sky: 4 on cloth)") >= 3
    curtain = captions.count("automatic: the 99th percentile of the cloth shown at 0.9")
    assert curtain >= 1 and captions.count(   # each caption is the figure's title too
        "automatic: the 99th percentile of the cylinder's side (not its cap, seen edge-on) "
        "shown at 0.9") == 2 * curtain


def test_the_cylinder_is_exposed_for_its_side_not_its_cap(tmp_path, monkeypatch):
    """A stand-in render whose cylinder side is 0.3 and its caps 3.0 (velvet's cap, seen
    edge-on, is the brightest cloth): the exposure shows the side at 0.9 and lets the cap clip;
    the curtain, all cloth metered, is exposed for its brightest cloth."""
    q = dict(rep.QUALITIES["fast"], render=(48, 27, 16), render_engine="builtin")

    def render(scene, fab, width, height, spp, progress, sky_spp=None):
        side = cloth_coverage(scene, width, height) >= 0.5
        cloth = cloth_coverage(scene, width, height, metered=False) >= 0.5
        img = np.where(side, 0.3, np.where(cloth, 3.0, 5.0))
        return np.broadcast_to(img[..., None], (height, width, 3)).copy()

    monkeypatch.setattr(sec_renders, "render", render)
    sec = sec_renders.section_renders(Page(tmp_path, "velvet", brdf.fabric("velvet"), q))
    renders = sec.data.summary()["renders"]
    cyl = cloth_coverage("cylinder", 48, 27, metered=False) >= 0.5
    assert (cyl & (cloth_coverage("cylinder", 48, 27) < 0.5)).sum() > 20     # the cap
    assert renders["cylinder"]["exposure"] == pytest.approx(np.log2(0.9 / 0.3))
    assert renders["curtain"]["exposure"] == pytest.approx(np.log2(0.9 / 0.3))
