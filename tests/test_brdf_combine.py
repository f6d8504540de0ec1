"""brdf.combine: Q, the denominator Q (n . wi) and the RGB sum over the threads, by hand."""

import numpy as np
import pytest

from brdf import combine


def test_combine_rgb_by_hand():
    rng = np.random.default_rng(3)
    s, v = rng.random((2, 2, 4, 6))                 # (thread, set, pair)
    area, albedo, inv = rng.random((4, 2)), rng.random((4, 2, 3)), rng.random((4, 6))
    out = combine.combine_rgb(s, v, area, albedo, inv, np.empty((4, 6, 3)))
    b, c, ch = 2, 5, 1
    want = sum(area[b, j] * (s[j, b, c] + albedo[b, j, ch] * v[j, b, c]) for j in range(2))
    assert out[b, c, ch] == pytest.approx(want * inv[b, c], rel=1e-14)


def test_normalization_q_by_hand():
    # a_1 P_1 + a_2 P_2 + (1 - a_1 - a_2) c_gap with a = (0.5, 0.25): 0.5 * 0.8 + 0.25 * 0.4
    # + 0.25 * 0.6 = 0.65
    assert combine.normalization_q(0.8, 0.4, 0.5, 0.25, 0.6) == pytest.approx(0.65, rel=1e-15)


def test_inverse_denominator_zero_where_not_positive_and_saturated():
    q = np.array([2.0, 0.0, -1.0, 1.0, 1e-200])
    zi = np.array([0.25, 0.5, 0.5, 0.0, 1e-200])
    inv = combine.inverse_denominator(q, zi)
    assert inv.tolist()[:4] == [2.0, 0.0, 0.0, 0.0]
    assert inv[4] == 1.0 / combine.DENOM_MIN and np.isfinite(inv[4])
