"""The six presets carry MODEL.md's Table II exactly."""

import numpy as np
import pytest

import brdf

# Table II of MODEL.md, typed in again: (eta, scale, rgb, kd, gamma_s, gamma_v, area, offsets, lengths)
TABLE = {
    "linen_plain": [(1.46, 0.3, (0.2, 0.8, 1.0), 0.3, 12, 24, 0.33, (-25, 25), (1,))] * 2,
    "silk_crepe_de_chine": [
        (1.345, 0.12, (1.0, 0.95, 0.05), 0.2, 5, 10, 0.75, (-35, -35, 35, 35), (1, 1, 1)),
        (1.345, 0.16, (1.0, 0.95, 0.05), 0.3, 18, 32, 0.25, (0, 0), (1,))],
    "polyester_satin_charmeuse": [
        (1.539, 0.035, (1.0, 0.37, 0.3), 0.1, 2.5, 5, 0.9, (-32, -32, -18, 0, 0, 18, 32, 32),
         (1.33, 0.66, 2, 2, 2, 0.66, 1.33)),
        (1.539, 0.2, (1.0, 0.37, 0.3), 0.7, 30, 60, 0.1, (0, 0), (1,))],
    "polyester_satin_charmeuse_back": [
        (1.539, 0.035, (1.0, 0.37, 0.3), 0.1, 2.5, 5, 0.67, (-30, -30, 30, 30, -5, -5, 5, 5),
         (1.33, 1.33, 1.33, 0, 0.67, 0.67, 0.67)),
        (1.539, 0.2, (1.0, 0.37, 0.3), 0.7, 30, 60, 0.33, (0, 0), (1,))],
    "silk_shot": [
        (1.345, 0.2, (0.1, 1.0, 0.4), 0.1, 4, 8, 0.86, (-25, -25, 25, 25), (1.33, 2.67, 1.33)),
        (1.345, 0.6, (1.0, 0.0, 0.1), 0.1, 5, 10, 0.14, (0, 0), (1,))],
    "velvet": [
        (1.46, 0.3, (0.05, 0.02, 0.0), 0.1, 6, 12, 0.5, (-90, -50), (1,)),
        (1.46, 0.3, (0.05, 0.02, 0.0), 0.1, 6, 12, 0.5, (-90, -55, 55, 90), (0.5, 0, 0.5))],
}


def test_preset_names():
    assert brdf.PRESETS == tuple(TABLE)


@pytest.mark.parametrize("name", list(TABLE))
def test_preset_parameters(name):
    fab = brdf.fabric(name)
    assert fab.name == name
    for th, row in zip(fab.threads, TABLE[name]):
        eta, scale, rgb, kd, gs, gv, area, offsets, lengths = row
        assert th.eta == eta and th.kd == kd and th.gamma_s == gs and th.gamma_v == gv
        assert th.area == area
        np.testing.assert_allclose(th.albedo, scale * np.array(rgb), rtol=1e-15)
        assert th.offsets == tuple(float(o) for o in offsets)
        assert th.lengths == tuple(float(x) for x in lengths)


def test_unknown_preset_lists_valid_ones():
    with pytest.raises(ValueError, match="unknown fabric 'denim'; valid presets are linen_plain, "
                                         "silk_crepe_de_chine, .*velvet"):
        brdf.fabric("denim")
