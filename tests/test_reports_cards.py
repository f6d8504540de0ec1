"""The overview's cards (reports.report.cards): one exposure for every card's render, what
the reciprocity number is, and which sections could not be built (the fit's only when a fit
was asked for)."""

import numpy as np
from PIL import Image

import brdf
from reports.report import cards as cards_module
from reports.report.sec_fit import NO_FIT
from reports.report.sec_reciprocity import ReciprocityData
from reports.report.sec_renders import RendersData
from reports.report.sections import FabricReport, SectionRun
from reports.report.settings import Section


def _renders(level, stops):
    img = np.full((6, 8, 3), level, np.float32)
    return SectionRun("renders", "ok", 0.0, Section(
        "", RendersData(1.0, {"curtain": {"exposure": stops}}, img)))


def _fit_missing(reason=NO_FIT):
    return SectionRun("fit", f"not available: {reason}", 0.0, Section(""))


def test_every_card_shows_its_render_at_one_exposure_the_lowest(tmp_path):
    """A dark fabric (own exposure +3 stops) and a bright one (+1): both cards at +1, so the
    dark one stays darker (at its own +3 its card would match the bright one's)."""
    dark = FabricReport("dark", brdf.fabric("velvet"), [_renders(0.05, 3.0), _fit_missing()])
    bright = FabricReport("bright", brdf.fabric("velvet"), [_renders(0.2, 1.0)])
    assert cards_module.card_exposure([dark, bright]) == 1.0
    page = str(cards_module.cards(tmp_path, [dark, bright], {"dark": "#000000", "bright": "#ffffff"}))
    assert "one exposure, +1.0 stops" in page
    means = {}
    for name in ("dark", "bright"):
        png = tmp_path / "overview" / f"card_{name}.png"
        assert f'src="overview/card_{name}.png"' in page
        means[name] = np.asarray(Image.open(png).convert("L"), float).mean()
    assert 0 < means["dark"] < means["bright"] < 255


def test_a_card_says_what_the_reciprocity_number_is_and_drops_an_unasked_fit(tmp_path):
    rec = SectionRun("reciprocity", "ok", 0.0, Section("", ReciprocityData.__new__(
        ReciprocityData)))
    object.__setattr__(rec.section.data, "stats", {"median": 0.567})
    r = FabricReport("velvet", brdf.fabric("velvet"), [rec, _fit_missing()])
    text = str(cards_module.card(tmp_path, r, "#000000"))
    assert "median 0.567" in text and "relative difference" in text
    assert "not reciprocal by design" in text
    assert "not built" not in text and "Fitting results" not in text
    r = FabricReport("velvet", brdf.fabric("velvet"),
                     [_fit_missing("results.json: field 'fit' missing")])
    text = str(cards_module.card(tmp_path, r, "#000000"))
    assert "Fitting results section" in text and "not built: results.json: field" in text
