"""Tests of reports.colour: sRGB encoding and Rec. 709 luminance."""

import colour
import numpy as np
import pytest

from reports.colour import display_colour, fabric_colour, line_colour, luminance, to_srgb


def test_luminance_is_the_y_row_of_srgb():
    rgb = np.random.default_rng(0).uniform(0, 2, (5, 3))
    cs = colour.RGB_COLOURSPACES["sRGB"]
    expected = colour.RGB_luminance(rgb, cs.primaries, cs.whitepoint)
    assert np.allclose(luminance(rgb), expected, atol=1e-4)
    assert luminance([1.0, 0.0, 0.0]) == pytest.approx(0.2126)
    assert luminance([0.0, 0.0, 1.0]) == pytest.approx(0.0722)


def test_to_srgb_is_the_srgb_curve():
    x = np.array([0.0, 0.001, 0.0031308, 0.2, 0.5, 1.0, 3.0])
    by_hand = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.minimum(x, 1) ** (1 / 2.4) - 0.055)
    out = to_srgb(np.stack([x, x, x], -1))
    assert np.allclose(out[:, 1], by_hand, atol=1e-6)
    assert out[-1, 0] == pytest.approx(1.0)  # clipped
    assert np.allclose(to_srgb([0.25, 0.25, 0.25], exposure=1.0), to_srgb([0.5, 0.5, 0.5]))


def test_colours_of_fabrics():
    assert display_colour([0.0, 0.0, 0.3]) == pytest.approx((0.0, 0.0, 1.0))

    class T:
        def __init__(self, albedo, area):
            self.albedo, self.area = albedo, area

    class F:
        threads = (T((0.4, 0.0, 0.0), 0.5), T((0.0, 0.0, 0.4), 0.5))

    r, g, b = fabric_colour(F())
    assert r == pytest.approx(1.0) and b == pytest.approx(1.0) and g == 0.0
    lc = np.array(line_colour(F()))
    lin = colour.cctf_decoding(lc, function="sRGB")
    assert luminance(lin) == pytest.approx(0.2, rel=1e-6)


@pytest.mark.parametrize("bad", [[1.0, 2.0], 3.0, [[1.0, 2.0, 3.0, 4.0]]])
def test_bad_shapes(bad):
    with pytest.raises(ValueError, match="rgb"):
        luminance(bad)
    with pytest.raises(ValueError, match="rgb"):
        to_srgb(bad)
