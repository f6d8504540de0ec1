"""Lobe views: the curves are the fabric at directions written out here, each evaluated once,
and a selection or another quantity of a view evaluates nothing again."""

import numpy as np
import pytest

import brdf
from analysis.views import LobeView, compute_lobes, compute_masking_lobes

W = np.array([0.2126, 0.7152, 0.0722])


def sph(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    t, p = np.broadcast_arrays(t, p)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


class Counting:
    """A BRDF that counts the pairs it evaluates: f = (1 + wo_x) (0.1, 0.2, 0.3) above."""

    def __init__(self):
        self.pairs = 0

    def eval(self, wi, wo):
        self.pairs += wi.shape[0]
        up = (wi[:, 2] > 0) & (wo[:, 2] > 0)
        return np.where(up[:, None], (1.0 + wo[:, :1]) * [0.1, 0.2, 0.3], 0.0)


def test_curves_are_the_fabric_in_the_plane():
    fab = brdf.fabric("velvet")
    view = compute_lobes(fab, (10.0, 50.0), (0.0, 45.0, 90.0), resolution=13)
    s = np.linspace(-90.0, 90.0, 13)
    for phi in (0.0, 45.0, 90.0):
        wo = np.where((s >= 0)[:, None], sph(np.abs(s), phi), sph(np.abs(s), phi + 180.0))
        for ti in (10.0, 50.0):
            f = fab.eval(np.broadcast_to(sph(ti, phi + 180.0), wo.shape), wo)
            assert np.allclose(view.curve(phi, ti, "rgb"), f, rtol=1e-12, atol=1e-15)
            assert np.allclose(view.curve(phi, ti), f @ W, rtol=1e-4)
            assert np.array_equal(view.curve(phi, ti, "b"), view.curve(phi, ti, "rgb")[:, 2])


def test_each_curve_evaluated_once_and_selections_evaluate_nothing():
    b = Counting()
    view = compute_lobes(b, (0.0, 30.0, 60.0), (0.0, 90.0), resolution=11)
    assert b.pairs == 6 * 11
    sub = view.select(theta_i_deg=(60.0,), planes_deg=90.0)
    assert sub.rgb.shape == (1, 1, 11, 3) and sub.theta_i_deg == (60.0,)
    assert np.array_equal(sub.curve(90.0, 60.0, "rgb"), view.curve(90.0, 60.0, "rgb"))
    header, table = view.columns()
    view.peak("rgb"), view.peak("luminance"), view.curves(0.0, "g")
    assert b.pairs == 6 * 11                                # nothing evaluated again
    assert header[0] == "theta_o_deg" and len(header) == 1 + 6 * 4 and table.shape == (11, 25)
    # f = (1 + wo_x) 0.3 in blue: largest where wo leans toward +x, in the warp plane
    assert view.peak("b") == pytest.approx(0.3 * (1 + 1.0), rel=1e-12)
    assert np.allclose(table[:, header.index("f_g_phi90_ti30")], 0.2 * (1 + 0 * table[:, 0]))


def test_cosine_multiplies_after_the_quantity():
    view = compute_lobes(Counting(), 30.0, 0.0, resolution=7, cosine=True)
    s = np.linspace(-90, 90, 7)
    plain = LobeView(view.theta_o_deg, view.theta_i_deg, view.planes_deg, view.rgb)
    assert view.label == "f_r cos θo" and plain.label == "f_r"
    assert np.allclose(view.curve(0.0, 30.0, "r"), plain.curve(0.0, 30.0, "r") *
                       np.cos(np.radians(s)))


def test_bad_input_before_work():
    b = Counting()
    for kw, match in ((dict(theta_i_deg=95.0), "theta_i_deg"),
                      (dict(planes_deg=400.0), "planes_deg"),
                      (dict(resolution=2), "resolution")):
        with pytest.raises(ValueError, match=match):
            compute_lobes(b, **kw)
    assert b.pairs == 0
    view = compute_lobes(b, 30.0, 0.0, resolution=3)
    with pytest.raises(ValueError, match="phi_deg must be one of the view's"):
        view.curve(45.0, 30.0)
    with pytest.raises(ValueError, match="quantity"):
        view.peak("hsv")
    with pytest.raises(ValueError, match="replace"):
        compute_masking_lobes(b)


def test_masking_view_is_the_fabric_with_masking_on_and_off():
    fab = brdf.fabric("velvet")
    view = compute_masking_lobes(fab, (60.0,), (45.0,), resolution=9)
    s = np.linspace(-90, 90, 9)
    wo = np.where((s >= 0)[:, None], sph(np.abs(s), 45.0), sph(np.abs(s), 225.0))
    wi = np.broadcast_to(sph(60.0, 225.0), wo.shape)
    curves = view.curves(45.0, 60.0)
    assert np.allclose(curves["masking on"], fab.replace(masking=True).eval(wi, wo) @ W,
                       rtol=1e-4)
    assert np.allclose(curves["masking off"], fab.replace(masking=False).eval(wi, wo) @ W,
                       rtol=1e-4)
    assert not np.allclose(curves["masking on"], curves["masking off"])
