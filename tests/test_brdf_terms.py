"""The named terms of brdf.terms, against values worked out by hand."""

import math

import numpy as np
import pytest
from scipy import integrate

from brdf import terms


def snell_fresnel(eta, theta_i):
    """Fresnel from Snell's law and the s/p amplitude coefficients (a different route)."""
    theta_t = math.asin(math.sin(theta_i) / eta)
    rs = math.sin(theta_i - theta_t) / math.sin(theta_i + theta_t)
    rp = math.tan(theta_i - theta_t) / math.tan(theta_i + theta_t)
    return 0.5 * (rs * rs + rp * rp)


@pytest.mark.parametrize("eta", [1.345, 1.46, 1.539])
@pytest.mark.parametrize("deg", [10.0, 35.0, 60.0, 85.0])
def test_fresnel_matches_snell(eta, deg):
    assert terms.fresnel(eta, math.cos(math.radians(deg))) == pytest.approx(
        snell_fresnel(eta, math.radians(deg)), rel=1e-12)


def test_fresnel_normal_and_grazing():
    assert terms.fresnel(1.5, 1.0) == pytest.approx(0.04, rel=1e-14)
    assert terms.fresnel(1.46, 0.0) == pytest.approx(1.0, abs=1e-15)
    out = terms.fresnel(np.array([1.3, 1.5])[:, None], np.array([1.0, 0.5, 0.0]))
    assert out.shape == (2, 3)


def test_gaussian_unit_area_and_peak():
    gamma = math.radians(12.0)
    area, _ = integrate.quad(lambda x: terms.gaussian(gamma, x), -np.inf, np.inf)
    assert area == pytest.approx(1.0, abs=1e-9)
    assert terms.gaussian(gamma, 0.0) == pytest.approx(1 / (gamma * math.sqrt(2 * math.pi)))
    assert terms.gaussian(gamma, gamma) == pytest.approx(
        math.exp(-0.5) / (gamma * math.sqrt(2 * math.pi)))


def test_u_unit_height_20_degrees():
    assert terms.SIGMA_U == pytest.approx(math.pi / 9)
    assert terms.u(0.0) == 1.0
    assert terms.u(math.radians(40.0)) == pytest.approx(math.exp(-2.0))


def test_visibility_and_pair_weight():
    np.testing.assert_array_equal(terms.visibility([-1.0, 0.0, 0.3]), [0.0, 0.0, 0.3])
    d = math.radians(20.0)
    expect = (1 - math.exp(-0.5)) * 0.3 * 0.9 + math.exp(-0.5) * 0.3
    assert terms.pair_weight(0.3, 0.9, d) == pytest.approx(expect, rel=1e-14)
    assert terms.pair_weight(0.9, 0.3, -d) == pytest.approx(expect, rel=1e-14)


def test_transmission_variants():
    eta, cg, ci, cr = 1.46, 0.7, 0.9, 0.6
    assert terms.transmission(eta, cg, ci, cr) == pytest.approx(
        (1 - snell_fresnel(eta, math.acos(cg))) ** 2)
    assert terms.transmission(eta, cg, ci, cr, "longitudinal") == pytest.approx(
        (1 - snell_fresnel(eta, math.acos(ci))) * (1 - snell_fresnel(eta, math.acos(cr))))
    with pytest.raises(ValueError, match="transmission must be one of"):
        terms.transmission(eta, cg, ci, cr, "fresnel")
