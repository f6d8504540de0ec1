"""Tests of analysis.colour: luminance weights, albedo colours of a table, CIEDE2000."""

import numpy as np
import pytest

from analysis.colour import LUMINANCE_WEIGHTS, albedo_colours, albedo_delta_e, luminance
from gonio.table import Table


def test_weights_are_the_rec709_luma_coefficients():
    # ITU-R BT.709-6, item 3.2: E'Y = 0.2126 E'R + 0.7152 E'G + 0.0722 E'B
    assert LUMINANCE_WEIGHTS.tolist() == [0.2126, 0.7152, 0.0722]
    assert luminance(np.eye(3)).tolist() == [0.2126, 0.7152, 0.0722]
    assert luminance([[2.0, 2.0, 2.0]]) == pytest.approx([2.0])
    with pytest.raises(ValueError):
        LUMINANCE_WEIGHTS[0] = 1.0          # the one definition cannot be changed in place


def test_weights_are_colour_sciences_srgb_y_row():
    """The constants written in analysis.colour are colour-science's sRGB matrix row."""
    import colour
    row = colour.RGB_COLOURSPACES["sRGB"].matrix_RGB_to_XYZ[1]
    assert LUMINANCE_WEIGHTS.tolist() == np.asarray(row, dtype=np.float64).tolist()


def _lambert_table(rho, n=40000, seed=3):
    """A table of the Lambertian f_r = rho / pi at pairs uniform in solid angle."""
    rng = np.random.default_rng(seed)
    z = 1.0 - rng.random((2, n))
    p = 2 * np.pi * rng.random((2, n))
    s = np.sqrt(1 - z * z)
    w = np.stack([s * np.cos(p), s * np.sin(p), z], axis=-1)
    return Table(w[0], w[1], np.broadcast_to(np.asarray(rho) / np.pi, (n, 3)).copy())


def test_albedo_colours_of_a_lambertian_table():
    """2 pi mean(f_r cos theta_o) estimates rho: mean(cos) = 1/2 for uniform directions."""
    rho = np.array([0.2, 0.5, 0.8])
    table = _lambert_table(rho)
    meas, pred = albedo_colours(table, 0.5 * table.values)
    assert meas == pytest.approx(rho, rel=0.02)
    np.testing.assert_allclose(pred, 0.5 * meas, rtol=1e-12)


def test_grey_table_is_compared_with_the_grey_of_the_prediction():
    table = _lambert_table([0.4, 0.4, 0.4], n=2000)
    colourful = np.broadcast_to(np.array([0.1, 0.4, 0.7]) / np.pi, (2000, 3))
    meas, pred = albedo_colours(table, colourful)
    assert pred[0] == pred[1] == pred[2]
    assert pred[0] == pytest.approx(meas[0])   # the channel mean is the table's grey


def test_delta_e_black_against_white_is_100():
    """L* 0 against 100, a* = b* = 0: CIEDE2000 has S_L = 1 at mean L* 50, so dE = dL* = 100."""
    assert albedo_delta_e([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]) == pytest.approx(100.0, abs=1e-3)
    assert albedo_delta_e([0.3, 0.2, 0.1], [0.3, 0.2, 0.1]) == 0.0
