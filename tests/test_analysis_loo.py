"""Tests of analysis.fit.loo: PSIS-LOO against exact leave-one-out, against arviz.loo, and on
a real fit (against WAIC from the same draws, and p_loo against the number of parameters)."""

import dataclasses
import json
import os
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy import stats
from scipy.special import logsumexp

from analysis.fit.loo import (HIGH_K, LOO_FILE, Loo, import_arviz, k_threshold, load_loo,
                              psis_loo, psis_pointwise, thin_draws)


def _normal_mean_problem(n=20, draws=4000, seed=1):
    """y_i ~ N(mu, 1), flat prior: the posterior of mu is N(mean y, 1/n), drawn exactly; the
    exact leave-one-out predictive of y_i is N(mean of the others, 1 + 1/(n-1))."""
    rng = np.random.default_rng(seed)
    y = rng.normal(0.3, 1.0, n)
    mu = rng.normal(y.mean(), 1 / np.sqrt(n), draws)
    ll = stats.norm.logpdf(y[None], mu[:, None], 1.0)
    cdf = stats.norm.cdf(y[None], mu[:, None], 1.0)
    others = (y.sum() - y) / (n - 1)
    sd = np.sqrt(1 + 1 / (n - 1))
    return ll, cdf, stats.norm.logpdf(y, others, sd), stats.norm.cdf(y, others, sd)


def test_psis_matches_exact_leave_one_out_of_a_normal_mean():
    ll, cdf, exact_elpd, exact_pit = _normal_mean_problem()
    out = psis_pointwise(ll, cdf)
    # Monte Carlo error of 4000 exact draws: a few 1e-3 per value
    np.testing.assert_allclose(out["elpd_i"], exact_elpd, atol=0.01)
    assert out["elpd_i"].sum() == pytest.approx(exact_elpd.sum(), abs=0.05)
    np.testing.assert_allclose(out["pit"], exact_pit, atol=0.01)
    assert np.all(out["pareto_k"] < 0.5)


def test_psis_pointwise_is_arviz_loo():
    ll, _, _, _ = _normal_mean_problem(n=30, draws=500, seed=4)
    az = import_arviz()
    ref = az.loo(az.from_dict(log_likelihood={"y": ll[None]}), pointwise=True, reff=0.8)
    out = psis_pointwise(ll, reff=0.8)
    np.testing.assert_allclose(out["elpd_i"], ref["loo_i"].values, rtol=1e-12)
    np.testing.assert_allclose(out["pareto_k"], np.asarray(ref["pareto_k"]), rtol=1e-12)
    p_loo = np.sum(out["lppd_i"] - out["elpd_i"])
    assert p_loo == pytest.approx(float(ref["p_loo"]), rel=1e-10)
    loo = Loo(out["elpd_i"], out["pareto_k"], out["pit"], np.arange(30), np.zeros(30, int),
              p_loo, 500, 0.8)
    assert loo.elpd == pytest.approx(float(ref["elpd_loo"]), rel=1e-12)
    assert loo.se == pytest.approx(float(ref["se"]), rel=1e-10)


def test_a_value_no_draw_changes_has_an_exact_elpd_and_k_zero():
    rng = np.random.default_rng(0)
    ll = np.column_stack([rng.normal(-1, 0.1, 200), np.full(200, -2.5)])
    out = psis_pointwise(ll)
    assert out["elpd_i"][1] == pytest.approx(-2.5, abs=1e-12) and out["pareto_k"][1] == 0.0


@pytest.mark.parametrize("draws", [60, 200, 400, 4000])
def test_the_k_threshold_is_arviz_loos_own(draws):
    """arviz.loo judges k against good_k, its sample-size threshold; ours is the same."""
    az = import_arviz()
    rng = np.random.default_rng(draws)
    mu = rng.normal(size=(1, draws))
    y = rng.normal(size=5)
    idata = az.from_dict(posterior={"mu": mu},
                         log_likelihood={"y": -0.5 * (y[None, None, :] - mu[..., None]) ** 2})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        good_k = az.loo(idata).good_k
    assert k_threshold(draws) == pytest.approx(good_k, abs=1e-12)


def test_high_k_is_warned_and_the_file_round_trips(tmp_path):
    # 0.65 is above the threshold of 400 draws (1 - 1/log10 400 = 0.616), not above 0.7
    k = np.array([0.1, 0.65, 0.9, 0.2])
    loo = Loo(np.array([-1.0, -2.0, -3.0, -1.5]), k, np.array([0.1, 0.5, 0.9, 0.3]),
              np.arange(4), np.zeros(4, int), 1.2, 400, 1.0, "abcd")
    assert loo.summary() == {"elpd": -7.5, "se": pytest.approx(np.sqrt(4 * np.var(
        [-1.0, -2.0, -3.0, -1.5]))), "p_loo": 1.2, "pareto_k_max": 0.9, "n_high_k": 2,
        "k_threshold": pytest.approx(0.6156891), "draws": 400}
    (w,) = loo.warnings()
    assert w["kind"] == "pareto_k" and w["parameters"] == [] and "2 of 4 values" in w["message"]
    assert "Pareto k > 0.62 (the threshold of 400 draws" in w["message"]
    # with 10**5 draws the threshold is capped at 0.7: only 0.9 is high
    assert dataclasses.replace(loo, draws=10**5).n_high_k == 1
    loo.save(tmp_path)
    back = load_loo(tmp_path)
    assert back.table == "abcd" and back.draws == 400 and np.array_equal(back.pareto_k, k)
    (tmp_path / LOO_FILE).write_bytes(b"not a zip file")
    with pytest.raises(ValueError, match="loo.npz: not a (readable|fit.s) LOO file"):
        load_loo(tmp_path)


def test_thinning_keeps_first_and_last_draw():
    class R:
        names = ("a",)
        chains_internal = np.arange(2 * 50 * 4, dtype=float).reshape(2, 50, 4, 1)
    th = thin_draws(R, 100)
    assert th.shape == (100, 1) and th[0, 0] == 0 and th[-1, 0] == 399
    assert len(np.unique(th)) == 100


@pytest.fixture(scope="module")
def silk_fit(tmp_path_factory):
    """A short fit of gamma_s1 and kd1 to a silk table whose sigma is its noise's."""
    from analysis.fit import fit_fabric, fit_spec
    from _fitmodels import fabric_table
    table, fab = fabric_table("silk_crepe_de_chine", n=150, seed=9)
    out = tmp_path_factory.mktemp("loo") / "fit"
    res = fit_fabric(table, fab, fit_spec(fab, "gamma_s1,kd1", ["none"], None), out,
                     max_steps=60, check_every=30, progress=False)
    return out, res


def test_a_fit_has_its_loo_close_to_waic_and_p_loo_near_its_parameters(silk_fit):
    out, res = silk_fit
    doc = json.loads((out / "results.json").read_text())
    loo = doc["loo"]
    assert set(loo) == {"elpd", "se", "p_loo", "pareto_k_max", "n_high_k", "k_threshold",
                        "draws"}
    assert loo["k_threshold"] == pytest.approx(min(1 - 1 / np.log10(loo["draws"]), HIGH_K))
    assert loo["n_high_k"] == 0 and loo["pareto_k_max"] < loo["k_threshold"]
    assert not [w for w in doc["warnings"] if w["kind"] == "pareto_k"]
    # two free parameters and a noise model that is right: p_loo near 2
    assert 1.3 < loo["p_loo"] < 3.0
    stored = load_loo(out)
    assert stored.elpd == pytest.approx(loo["elpd"]) and stored.elpd_i.size == res.counts["used"]
    # WAIC from the same draws, computed here: lppd - sum of the pointwise variances
    theta = thin_draws(res, stored.draws)
    ll = res.logpost.pointwise(theta) + res.logpost.lik.log_jacobian
    lppd = logsumexp(ll, axis=0) - np.log(ll.shape[0])
    waic = float(np.sum(lppd - ll.var(axis=0, ddof=1)))
    assert loo["elpd"] == pytest.approx(waic, abs=0.5)
    assert loo["elpd"] < float(np.sum(lppd))
    pit = doc["quality"]["loo_pit"]
    assert pit["values"] == res.counts["used"] == stored.pit.size
    # the fabric that made the table, with its noise: about 5% outside the central 95%
    assert 0.02 < pit["outside_95"] < 0.09 and abs(np.mean(stored.pit) - 0.5) < 0.05


def test_a_sigma_above_the_noise_gives_a_pit_hump(fit_folder):
    """conftest's velvet table: noise 5% of f_r, sigma 5% + 1e-5 (1/sr), far above the noise
    where f_r is small: too few values in the tails of their predictive distributions."""
    out, res = fit_folder
    pit = json.loads((out / "results.json").read_text())["quality"]["loo_pit"]
    assert pit["outside_95"] < 0.03 and pit["ks_pvalue"] < 1e-3


def test_a_one_parameter_fit_matches_brute_force_leave_one_out(tmp_path):
    """A table of 12 pairs (36 values), kd1 free: each p(y_i | y_-i) integrated on a grid of
    the posterior without y_i (the fit's own log-prior and pointwise terms), against PSIS."""
    from analysis.fit import fit_fabric, fit_spec
    from _fitmodels import fabric_table
    table, fab = fabric_table("silk_crepe_de_chine", n=12, rel=0.1, seed=5)
    res = fit_fabric(table, fab, fit_spec(fab, "kd1", ["none"], None), tmp_path / "fit",
                     max_steps=1000, check_every=100, progress=False)
    lp = res.logpost
    u = res.chains_internal.reshape(-1)
    grid = np.linspace(u.min() - 1.0, u.max() + 1.0, 3001)[:, None]
    ll = lp.pointwise(grid) + lp.lik.log_jacobian                     # (grid, values)
    log_post_all = lp.spec.log_prior(grid) + ll.sum(axis=1)
    exact = np.empty(ll.shape[1])
    for i in range(ll.shape[1]):
        w = log_post_all - ll[:, i]                                   # posterior without y_i
        w = w - logsumexp(w)
        exact[i] = logsumexp(w + ll[:, i])
    # the fit's own 400 draws, and 4000 (Monte Carlo error about 3 times smaller)
    np.testing.assert_allclose(res.loo.elpd_i, exact, atol=0.05)
    assert res.loo.elpd == pytest.approx(exact.sum(), abs=0.15)
    many = psis_loo(res, max_draws=4000)
    np.testing.assert_allclose(many.elpd_i, exact, atol=0.015)
    assert many.elpd == pytest.approx(exact.sum(), abs=0.05)


def _loo_of(elpd_i):
    n = len(elpd_i)
    return Loo(np.asarray(elpd_i, float), np.zeros(n), np.full(n, 0.5), np.arange(n),
               np.zeros(n, int), 1.0, 400, 1.0, "t")


@pytest.mark.parametrize("rho", [0.0, 0.6, 0.8])
def test_the_block_se_of_a_difference_allows_for_streaks(rho):
    """Pointwise differences that follow an AR(1) along the table, of lag-1 correlation rho:
    the variance of their sum is n var (1 + rho) / (1 - rho) for large n, so the block se
    should be the naive se times sqrt((1 + rho) / (1 - rho)); the lag-1 estimate near rho."""
    from analysis.fit.compare import paired_structure
    rng = np.random.default_rng(1)
    n, reps = 3000, 60
    ratios, lags = [], []
    for _ in range(reps):
        e = rng.normal(size=n)
        d = np.empty(n)
        d[0] = e[0] / np.sqrt(1 - rho ** 2)
        for i in range(1, n):
            d[i] = rho * d[i - 1] + e[i]
        block, lag1 = paired_structure(_loo_of(d), _loo_of(np.zeros(n)))
        ratios.append(block / np.sqrt(n * np.var(d)))
        lags.append(lag1)
    assert np.mean(lags) == pytest.approx(rho, abs=0.02)
    want = np.sqrt((1 + rho) / (1 - rho))
    # batch means with blocks of sqrt(n) = 55 values: a small bias (b / (b + 2 rho/(1-rho)))
    assert np.mean(ratios) == pytest.approx(want, rel=0.08)


def test_arviz_is_imported_without_bokeh_and_bokeh_still_imports_after():
    """import_arviz skips the Bokeh modules arviz imports for two docstrings (0.65 s of CPU
    a fit), leaves arviz whole (psislw, compare), and a later ``import bokeh.plotting``
    (the explorer's) loads Bokeh as usual. In a new interpreter: this one may hold both."""
    import subprocess
    import sys
    code = ("import sys; from analysis.fit.loo import import_arviz; az = import_arviz(); "
            "print('bokeh.plotting' in sys.modules, 'bokeh.models' in sys.modules, "
            "callable(az.psislw), callable(az.compare)); import bokeh.plotting as b; "
            "print(callable(b.figure))")
    root = str(Path(__file__).resolve().parents[1])
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=root, timeout=120, env=dict(os.environ, PYTHONPATH=root))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "False", "True", "True", "True"]
