"""Tests of analysis.likelihood against scipy.stats transliterations."""

import numpy as np
import pytest
from scipy import stats

from analysis.likelihood import Likelihood, is_relative
from gonio.table import Table


def _table(sigma=True, meta=None):
    rng = np.random.default_rng(3)
    n = 40
    ct = rng.uniform(0.2, 1, (2, n))
    ph = rng.uniform(-np.pi, np.pi, (2, n))
    w = np.stack([np.sqrt(1 - ct**2) * np.cos(ph), np.sqrt(1 - ct**2) * np.sin(ph), ct], -1)
    f = rng.uniform(0.05, 2.0, (n, 3))
    sig = 0.1 * f if sigma else None
    return Table(w[0], w[1], f, sigma=sig, meta=meta or {})


def test_gaussian_matches_delta_method_by_hand():
    t = _table()
    lik = Likelihood(t)
    m = t.values * 1.1
    c = t.wi[:, 2:3]
    y, mu = np.log(1 + t.values * c), np.log(1 + m * c)
    s = c * t.sigma / (1 + t.values * c)
    expect = stats.norm.logpdf(y, mu, s).sum()
    assert lik(m[None])[0] == pytest.approx(expect, rel=1e-12)
    # scale multiplies the model
    assert lik(t.values[None], scale=np.array([1.1]))[0] == pytest.approx(expect, rel=1e-12)


def test_delta_method_sigma_matches_monte_carlo():
    t = _table()
    lik = Likelihood(t)
    rng = np.random.default_rng(0)
    small = t.replace(sigma=0.01 * t.values)
    lik = Likelihood(small)
    draws = small.values + small.sigma * rng.normal(size=(20000,) + small.values.shape)
    sd = np.log1p(draws * small.wi[:, 2:3]).std(axis=0)
    np.testing.assert_allclose(np.sqrt(lik.sigma_y2), sd[lik.pt, lik.ch], rtol=0.03)


def test_student_t_and_relative():
    t = _table()
    m = t.values * 0.8
    c = t.wi[:, 2:3]
    r = np.log(1 + t.values * c) - np.log(1 + m * c)
    s = c * t.sigma / (1 + t.values * c)
    expect = (stats.t.logpdf(r / s, 3.0) - np.log(s)).sum()
    assert Likelihood(t, "student-t", nu=3.0)(m[None])[0] == pytest.approx(expect, rel=1e-12)
    expect_rel = stats.norm.logpdf(np.log(t.values), np.log(m), t.sigma / t.values).sum()
    assert Likelihood(t, "relative")(m[None])[0] == pytest.approx(expect_rel, rel=1e-12)


def test_log_noise_without_sigma():
    t = _table(sigma=False)
    lik = Likelihood(t)
    assert not lik.has_sigma
    m = t.values * 1.2
    c = t.wi[:, 2:3]
    r = np.log(1 + t.values * c) - np.log(1 + m * c)
    expect = stats.norm.logpdf(r, 0, np.exp(-2.0)).sum()
    got = lik(np.stack([m, m]), log_noise=np.array([-2.0, -1.0]))
    assert got.shape == (2,) and got[0] == pytest.approx(expect, rel=1e-12)
    with pytest.raises(ValueError, match="log_noise"):
        lik(m[None])


def test_masks_are_counted():
    t = _table()
    v = t.values.copy()
    s = t.sigma.copy()
    v[0, 0] = np.nan
    v[1, :] = -1.0
    s[2, 1] = 0.0
    wi = t.wi.copy()
    wi[3] = [1.0, 0.0, 0.0]                 # grazing: at the horizon
    lik = Likelihood(Table(wi, t.wo, v, sigma=s))
    c = lik.counts
    assert c["invalid_value"] == 4 and c["bad_sigma"] == 1 and c["below_horizon"] == 3
    assert c["used"] == 120 - 8 == lik.n_used
    assert np.isfinite(lik(v[None])[0])      # masked entries are never read


def test_bad_options_and_relative_meta():
    with pytest.raises(ValueError, match="likelihood must be one of"):
        Likelihood(_table(), "cauchy")
    with pytest.raises(ValueError, match="nu"):
        Likelihood(_table(), "student-t", nu=0)
    assert is_relative({"units": "relative"}) and Likelihood(
        _table(meta={"units": "relative"})).relative_data


def test_grey_table_enters_once_per_point_against_the_channel_mean():
    t = _table()
    grey = t.values[:, :1] * np.ones(3)
    g = t.replace(values=grey, sigma=0.1 * grey)
    lik = Likelihood(g)
    assert lik.grey and lik.counts["used"] == len(t) and lik.counts["total"] == len(t)
    m = t.values * 1.3                                  # a coloured model
    c = t.wi[:, 2]
    y = np.log1p(grey[:, 0] * c)
    mu = np.log1p(m.mean(axis=1) * c)
    s = c * 0.1 * grey[:, 0] / (1 + grey[:, 0] * c)
    expect = stats.norm.logpdf(y, mu, s).sum()
    assert lik(m[None])[0] == pytest.approx(expect, rel=1e-12)
    # one channel different at one point: an RGB table, every channel counted
    v = grey.copy()
    v[0, 2] *= 1.01
    assert Likelihood(t.replace(values=v, sigma=0.1 * v)).counts["used"] == 3 * len(t)


@pytest.mark.parametrize("kind", ["gaussian", "relative", "student-t"])
@pytest.mark.parametrize("sigma,noise", [(True, None), (True, -3.0), (False, -2.0)])
def test_pointwise_terms_sum_to_the_likelihood(kind, sigma, noise):
    t = _table(sigma=sigma)
    lik = Likelihood(t, kind, nu=5.0)
    m = np.stack([t.values * 0.9, t.values * 1.2])
    ln = None if noise is None else np.array([noise, noise + 0.5])
    ll, cdf = lik.pointwise(m, scale=np.array([1.0, 0.95]), log_noise=ln, cdf=True)
    assert ll.shape == cdf.shape == (2, lik.n_used)
    np.testing.assert_allclose(ll.sum(axis=1), lik(m, scale=np.array([1.0, 0.95]),
                                                    log_noise=ln), rtol=1e-12)
    # the CDF by hand: the residual over its scale, through scipy's distribution
    c = t.wi[:, 2:3]
    y, mu = ((np.log(t.values), np.log(m[0])) if kind == "relative"
             else (np.log1p(t.values * c), np.log1p(m[0] * c)))
    s2 = np.zeros_like(y) if not sigma else (
        (t.sigma / t.values) ** 2 if kind == "relative" else (c * t.sigma / (1 + t.values * c)) ** 2)
    if noise is not None:
        s2 = s2 + np.exp(2 * noise)
    z = ((y - mu) / np.sqrt(s2)).ravel()
    ref = stats.t.cdf(z, 5.0) if kind == "student-t" else stats.norm.cdf(z)
    np.testing.assert_allclose(cdf[0], ref, rtol=1e-10)


def test_log_jacobian_is_the_derivative_of_the_residual_space():
    t = _table()
    for kind, space in (("gaussian", lambda f, c: np.log1p(f * c)),
                        ("relative", lambda f, c: np.log(f))):
        lik = Likelihood(t, kind)
        f, c = t.values.ravel(), np.repeat(t.wi[:, 2], 3)
        h = 1e-6 * f
        dy = (space(f + h, c) - space(f - h, c)) / (2 * h)
        np.testing.assert_allclose(lik.log_jacobian, np.log(dy), atol=1e-7)


def test_pointwise_of_a_grey_table_is_one_term_a_point():
    t = _table()
    grey = t.values[:, :1] * np.ones(3)
    lik = Likelihood(t.replace(values=grey, sigma=0.1 * grey))
    m = (t.values * 1.3)[None]
    ll = lik.pointwise(m)
    assert ll.shape == (1, len(t)) and ll.sum() == pytest.approx(lik(m)[0], rel=1e-12)
