"""Tangent curves: the midpoint rule of MODEL.md, control points, and bad input."""

import numpy as np
import pytest

from brdf.curve import TangentCurve


def test_linear_segment_midpoints():
    alpha, w = TangentCurve((-25, 25), (1,)).samples(32)
    expect = -25 + 50 * (np.arange(32) + 0.5) / 32
    np.testing.assert_allclose(alpha, expect, rtol=0, atol=1e-12)
    np.testing.assert_allclose(w, 1 / 32)


def test_flat_segments_merge_with_weights():
    # silk crepe warp: flat at -35 for a third, ramp, flat at +35 for a third.
    alpha, w = TangentCurve((-35, -35, 35, 35), (1, 1, 1)).samples(32)
    # midpoints s = (m + 1/2) 3 / 32 < 1 for m <= 10: eleven samples at -35, likewise at +35.
    assert alpha[0] == -35 and alpha[-1] == 35
    assert w[0] == pytest.approx(11 / 32) and w[-1] == pytest.approx(11 / 32)
    assert alpha.size == 12 and w.sum() == pytest.approx(1.0)
    ramp = alpha[1:-1]
    s = (np.arange(11, 21) + 0.5) * 3 / 32
    np.testing.assert_allclose(ramp, -35 + 70 * (s - 1), atol=1e-12)


def test_jump_segment():
    # velvet weft: -90..-55 over half, jump, 55..90 over half.
    alpha, w = TangentCurve((-90, -55, 55, 90), (0.5, 0, 0.5)).samples(4)
    np.testing.assert_allclose(alpha, [-81.25, -63.75, 63.75, 81.25])


def test_control_points_equally_weighted():
    alpha, w = TangentCurve((-32, -32, -18, 0, 0, 18, 32, 32),
                            (1.33, 0.66, 2, 2, 2, 0.66, 1.33)).samples(32, "control_points")
    np.testing.assert_array_equal(alpha, [-32, -18, 0, 18, 32])
    np.testing.assert_allclose(w, [2 / 8, 1 / 8, 2 / 8, 1 / 8, 2 / 8])


@pytest.mark.parametrize("offsets, lengths, match", [
    ((-95, 0), (1,), r"offsets must lie in \[-90, 90\]"),
    ((0, 91), (1,), r"offsets must lie in \[-90, 90\]"),
    ((0, 10), (-1,), "lengths must be finite and >= 0"),
    ((0, 10), (0,), "lengths must sum to more than 0"),
    ((0, 10, 20), (1,), "one more entry than lengths"),
    ((0, float("nan")), (1,), r"offsets must lie in \[-90, 90\]"),
])
def test_bad_curves(offsets, lengths, match):
    with pytest.raises(ValueError, match=match):
        TangentCurve(offsets, lengths)


def test_bad_sampling():
    c = TangentCurve((0, 0), (1,))
    with pytest.raises(ValueError, match="tangent_sampling must be one of"):
        c.samples(8, "random")
    with pytest.raises(ValueError, match="tangent_samples must be an integer in 1..4096"):
        c.samples(0)
