"""Tests of analysis.reciprocity."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import brdf  # noqa: E402
import gonio  # noqa: E402
from _analytic_brdfs import BlinnPhong, Lambert, ViewCosine  # noqa: E402

from analysis import reciprocity, reciprocity_report  # noqa: E402
from analysis.reciprocity import random_pairs  # noqa: E402


def test_lambert_and_blinn_phong_are_reciprocal_to_round_off():
    assert reciprocity(Lambert(), n=2000).max == 0.0
    r = reciprocity(BlinnPhong(), n=5000, seed=3)
    assert r.max < 1e-12
    assert r.n_included + r.n_zero == 5000


def test_view_cosine_closed_form():
    wi, wo = random_pairs(1000, seed=7)
    r = reciprocity(ViewCosine(), (wi, wo), n_worst=3)
    ci, co = wi[:, 2], wo[:, 2]
    exact = np.abs(co - ci) / np.maximum(co, ci)
    assert r.median == pytest.approx(np.median(exact), rel=1e-12)
    assert r.p95 == pytest.approx(np.percentile(exact, 95), rel=1e-12)
    assert r.max == pytest.approx(exact.max(), rel=1e-12)
    # the worst pair's angles (degrees) reproduce its values
    w = r.worst[0]
    assert w["r"] == pytest.approx(exact.max())
    assert np.cos(np.radians(w["theta_o"])) * 0.3 == pytest.approx(w["f_io"], rel=1e-9)


def test_both_zero_pairs_are_excluded_and_counted():
    class HalfZero:
        def eval(self, wi, wo):
            wi, wo = np.asarray(wi), np.asarray(wo)
            on = (wi[..., 0] > 0) | (wo[..., 0] > 0)
            return np.where(on, 0.1, 0.0)[..., None] * np.ones(3)

    wi, wo = random_pairs(4000, seed=1)
    r = reciprocity(HalfZero(), (wi, wo))
    both_off = np.sum((wi[:, 0] <= 0) & (wo[:, 0] <= 0))
    assert r.n_zero == both_off
    assert r.n_included == 4000 - both_off
    assert r.max == 0.0


def test_same_seed_same_result_and_json():
    fab = brdf.fabric("silk_shot")
    a = reciprocity(fab, n=3000, seed=11).to_dict()
    b = reciprocity(fab, n=3000, seed=11).to_dict()
    c = reciprocity(fab, n=3000, seed=12).to_dict()
    assert json.dumps(a) == json.dumps(b)
    assert a != c


def test_cloth_presets_are_not_reciprocal():
    """MODEL.md: cos(theta_i)/(n . wi) is not symmetric, so f(wi,wo) != f(wo,wi) in general."""
    wi, wo = random_pairs(2000, seed=2)
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        r = reciprocity(fab, (wi, wo))
        assert r.median > 0.05, name
        # independent check on one pair: f(wi, wo) (n.wi) vs f(wo, wi) (n.wo) differ little,
        # f itself differs by about the ratio of the cosines
        assert r.n_nonfinite == 0


def test_gonio_geometry_pairs_and_channels():
    g = gonio.full_grid(30)
    r = reciprocity(BlinnPhong(), g, channel="g")
    assert r.channel == "g" and r.n_pairs == len(g.wi) and r.max < 1e-12
    with pytest.raises(ValueError, match="channel"):
        reciprocity(BlinnPhong(), g, channel="y")
    with pytest.raises(ValueError, match="same shape"):
        reciprocity(BlinnPhong(), (np.zeros((3, 3)), np.zeros((2, 3))))


def test_report_variants_and_felts(shared_data):
    felt = shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf"
    rep = reciprocity_report(["linen_plain"], ["default", "gap_outgoing"], n=500,
                             felts=[felt] if felt.is_file() else [])
    json.dumps(rep.to_dict())
    names = [(r["name"], r["variant"]) for r in rep.rows]
    assert ("linen_plain", "default") in names and ("linen_plain", "gap_outgoing") in names
    d = {r["variant"]: r["random"] for r in rep.rows if r["source"] == "model"}
    # the gap term changes linen's asymmetry (a1 + a2 = 0.66 < 1)
    assert d["default"]["median"] != d["gap_outgoing"]["median"]
    if felt.is_file():
        m = [r for r in rep.rows if r["source"] == "measured"][0]
        assert m["random"]["median"] < d["default"]["median"]


@pytest.mark.parametrize("n", [2.5, 0, True, "3", None])
def test_a_pair_count_that_is_no_integer_is_refused_by_name(n):
    with pytest.raises(ValueError, match="n must be an integer >= 1"):
        reciprocity(Lambert(), n=n)
    with pytest.raises(ValueError, match="n_worst must be an integer >= 0"):
        reciprocity(Lambert(), n=10, n_worst=1.5)
    assert reciprocity(Lambert(), n=np.int64(3)).n_included == 3
