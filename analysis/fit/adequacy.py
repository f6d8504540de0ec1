r"""Does the model describe the data? Posterior predictive checks with calibrated statistics.

``converged`` says the sampler explored the posterior; this module says whether the model,
at that posterior, explains the table to within its noise. Each test compares the residuals
with the distribution the likelihood (:mod:`analysis.likelihood`) assumes for them:

- **Normal scores.** The residual r = y - mu in the likelihood's space (log(1 + f_r
  cos theta_i), or log f_r for "relative"), over its scale s (s^2 = sigma_y^2, plus
  exp(2 log_noise) when the noise is fitted), is z ~ N(0, 1) (Student-t with nu degrees of
  freedom for "student-t"); its normal score n = Phi^-1(F(z)), F the likelihood's standardized
  CDF, is N(0, 1) for every kind, and independent between values.
- ``distribution``: Kolmogorov-Smirnov test of the normal scores at the posterior median
  against N(0, 1) (scipy.stats.kstest). The parameters were fitted to these data, which
  makes the p-value conservative (too large, as Lilliefors showed for a fitted normal).
- ``chi_square``: a posterior predictive p-value of T = sum n^2 (Gelman, Meng & Stern 1996):
  for each of a few dozen posterior draws, T of the data, against T of replicated data,
  which is chi-square with (values) degrees of freedom exactly; the p-value P(T_rep >= T) is
  averaged over the draws (upper tail: residuals larger than the noise). It uses the
  table's own sigma alone, so a fitted ``log_noise`` cannot absorb the misfit; without a
  table sigma the residual scale is fitted and the test does not apply.
- ``regions``: residual structure. The normal scores are averaged per point over its channels
  (times sqrt(channels): N(0, 1) per point under the model; one value a point, so that a
  correlation between a point's channels, which real data may have, scales both sides alike
  and does not multiply the evidence) and two regions of each split are compared by a two-sided
  Mann-Whitney U test (scipy.stats.mannwhitneyu, distribution-free): forward against back
  scatter (cos(phi_o - phi_i) < 0 or > 0, both directions at least 5 degrees off the normal),
  warp plane against weft plane (the half vector h nearer the x-z or the y-z plane), grazing
  against near-normal (theta_i or theta_o >= 60 degrees, or both below), left against right
  (h_x < 0 or > 0), light against view more oblique (theta_i > theta_o + 2 degrees, or
  theta_o > theta_i + 2 degrees: a model that is not reciprocal, as the microcylinder is
  not, fitted to reciprocal data misses the two sides in opposite senses; in CUReT's
  geometry this split and the left/right one are the same pairs). The warp/weft split leaves
  out pairs whose h is within 5 degrees of the normal, the left/right split those within 5
  degrees of the y-z plane. A split with fewer
  than :data:`MIN_REGION` points on a side is skipped.
- ``noise``: where the noise is fitted, its level exp(log_noise) (median, 95% interval)
  against the table's own sigma in the same space (the median of sigma_y), as their ratio.

Values the likelihood masks do not enter. Where a table's noise makes small values negative
(an instrument floor), dropping them leaves the rest biased upward there, and the tests see
it even at the true parameters: the reason then says how many were masked.

The verdict ``adequate`` is false when any test's p-value, Holm-corrected over the tests that
ran, is below :data:`ALPHA`; true when none is; None when no test could run (too few values,
or a result without its posterior). With thousands of values the tests detect small
systematic departures: "false" means the misfit is larger than the noise can explain, not
that it is large; the region means say where and how much.
"""

from __future__ import annotations

import numpy as np

from analysis.lazy import stats

__all__ = ["adequacy", "normal_scores", "point_scores", "regions", "ALPHA", "MIN_REGION",
           "N_DRAWS"]

#: Family-wise level of the tests (Holm-corrected): below it a test says "misfit".
ALPHA = 0.01
#: Fewest points on each side of a region split for its test to run.
MIN_REGION = 8
#: Posterior draws of the predictive chi-square (fewer for a very large table).
N_DRAWS = 32
#: Fewest used values for any test.
MIN_VALUES = 20
#: A direction this close to the normal (degrees) has no azimuth: no forward/back side.
POLE_DEG = 5.0
#: Grazing: theta_i or theta_o at least this (degrees).
GRAZING_DEG = 60.0
#: Light or view "more oblique": theta_i and theta_o at least this far apart (degrees).
OBLIQUE_DEG = 2.0


def normal_scores(result, theta, table_sigma_only: bool = False) -> np.ndarray:
    """Normal scores of the used values at internal parameter sets ``theta`` (B, ndim).

    Parameters
    ----------
    result : analysis.fit.FitResult
        With its ``logpost`` (likelihood and model).
    theta : ndarray (B, ndim)
        Internal coordinates.
    table_sigma_only : bool
        Scale the residuals by the table's sigma alone, without the fitted ``log_noise``.

    Returns
    -------
    ndarray (B, n_used)
        Phi^-1(F(r / s)): N(0, 1) under the model (see the module notes).
    """
    lik = result.logpost.lik
    theta = np.atleast_2d(theta)
    with np.errstate(all="ignore"):
        r = lik.y - lik.transform(result.logpost.predict(theta))
    s2 = np.zeros((1, r.shape[-1])) if lik.sigma_y2 is None else lik.sigma_y2[None]
    if "log_noise" in result.names and not table_sigma_only:
        ln = result.spec.to_natural(theta)[:, result.names.index("log_noise")]
        s2 = s2 + np.exp(2.0 * ln)[:, None]
    z = r / np.sqrt(s2)
    if lik.kind != "student-t":
        return z
    nu = lik.nu
    return np.where(z > 0, stats.norm.isf(stats.t.sf(z, nu)), stats.norm.ppf(stats.t.cdf(z, nu)))


def point_scores(lik, scores) -> tuple[np.ndarray, np.ndarray]:
    """Per table point: the channel mean of the normal scores ``scores`` (n_used,) times
    sqrt(channels), N(0, 1) under the model; returns (points with a value, their scores)."""
    n = int(lik.mask.shape[0])
    cnt = np.bincount(lik.pt, minlength=n)
    tot = np.bincount(lik.pt, weights=scores, minlength=n)
    keep = np.nonzero(cnt > 0)[0]
    return keep, tot[keep] / np.sqrt(cnt[keep])


def regions(wi, wo) -> dict[str, tuple[str, str, np.ndarray, np.ndarray]]:
    """The region splits of the table's points: name -> (label a, label b, mask a, mask b).

    Parameters
    ----------
    wi, wo : ndarray (n, 3)
        Unit directions (z up, x the warp).

    Examples
    --------
    >>> wi = np.array([[0.5, 0, 0.866], [0.5, 0, 0.866]])
    >>> wo = np.array([[-0.5, 0, 0.866], [0.5, 0, 0.866]])
    >>> fwd, back = regions(wi, wo)["forward_back"][2:]
    >>> fwd.tolist(), back.tolist()
    ([True, False], [False, True])
    """
    wi, wo = np.asarray(wi, float), np.asarray(wo, float)
    sin_pole = np.sin(np.radians(POLE_DEG))
    off_pole = ((np.hypot(wi[:, 0], wi[:, 1]) >= sin_pole)
                & (np.hypot(wo[:, 0], wo[:, 1]) >= sin_pole))
    dot = wi[:, 0] * wo[:, 0] + wi[:, 1] * wo[:, 1]
    h = wi + wo
    h = h / np.linalg.norm(h, axis=1, keepdims=True)
    h_off = np.hypot(h[:, 0], h[:, 1]) >= sin_pole      # a half vector with an azimuth
    hx, hy = np.abs(h[:, 0]), np.abs(h[:, 1])
    cos_graze = np.cos(np.radians(GRAZING_DEG))
    ti, to = (np.arccos(np.clip(w[:, 2], -1.0, 1.0)) for w in (wi, wo))
    tilt = np.radians(OBLIQUE_DEG)
    grazing = (wi[:, 2] <= cos_graze) | (wo[:, 2] <= cos_graze)
    return {
        "forward_back": ("forward scatter", "back scatter", off_pole & (dot < 0),
                         off_pole & (dot > 0)),
        "warp_weft": ("warp plane", "weft plane", h_off & (hy < hx), h_off & (hy > hx)),
        "grazing_normal": ("grazing", "near-normal", grazing, ~grazing),
        "left_right": ("left (h_x < 0)", "right (h_x > 0)", h[:, 0] <= -sin_pole,
                       h[:, 0] >= sin_pole),
        "light_view": ("light more oblique", "view more oblique", ti > to + tilt,
                       to > ti + tilt),
    }


def _region_tests(lik, scores, wi, wo) -> dict:
    """Mann-Whitney U of the per-point scores between the two sides of each split."""
    points, zp = point_scores(lik, scores)
    out = {}
    for name, (la, lb, ma, mb) in regions(wi[points], wo[points]).items():
        a, b = zp[ma], zp[mb]
        entry = {"a": la, "b": lb, "n_a": int(a.size), "n_b": int(b.size),
                 "mean_a": float(a.mean()) if a.size else None,
                 "mean_b": float(b.mean()) if b.size else None, "p": None}
        if min(a.size, b.size) >= MIN_REGION:
            entry["p"] = float(stats.mannwhitneyu(a, b, alternative="two-sided").pvalue)
        else:
            entry["skipped"] = f"fewer than {MIN_REGION} points on a side"
        out[name] = entry
    return out


def _draws(result, n_used: int) -> np.ndarray:
    """Up to :data:`N_DRAWS` posterior draws (internal), fewer for a large table."""
    flat = result.chains_internal.reshape(-1, len(result.names))
    k = int(max(4, min(N_DRAWS, 4_000_000 // max(n_used, 1), flat.shape[0])))
    k = min(k, flat.shape[0])
    return flat[np.random.default_rng(0).choice(flat.shape[0], k, replace=False)]


def _chi_square(result, lik) -> dict:
    """The posterior predictive chi-square p-value with the table's sigma alone."""
    if lik.sigma_y2 is None:
        return {"p": None, "skipped": "the table gives no sigma: the residual scale is fitted "
                                      "(log_noise), so its size says nothing of the fit"}
    scores = normal_scores(result, _draws(result, lik.n_used), table_sigma_only=True)
    t = np.sum(scores * scores, axis=1)
    n = scores.shape[1]
    p = stats.chi2.sf(t, n)
    return {"p": float(np.mean(np.where(np.isfinite(p), p, 0.0))), "draws": int(t.size),
            "dof": n, "t_over_dof": float(np.median(t) / n)}


def _noise(result, lik) -> dict | None:
    """The fitted noise level against the table's sigma (None when the noise is not fitted)."""
    if "log_noise" not in result.names:
        return None
    ln = result.samples()[:, result.names.index("log_noise")]
    lo, med, hi = np.exp(np.percentile(ln, [2.5, 50, 97.5]))
    out = {"fitted": float(med), "fitted_lo95": float(lo), "fitted_hi95": float(hi),
           "table_sigma": None, "ratio": None}
    if lik.sigma_y2 is not None:
        ts = float(np.median(np.sqrt(lik.sigma_y2)))
        out.update(table_sigma=ts, ratio=float(med / ts))
    return out


def _holm(pvalues: dict) -> dict:
    """Holm-adjusted p-values of {name: p}."""
    names = sorted(pvalues, key=pvalues.get)
    m, run, out = len(names), 0.0, {}
    for k, n in enumerate(names):
        run = max(run, min(1.0, (m - k) * pvalues[n]))
        out[n] = run
    return out


def adequacy(result, wi=None, wo=None) -> dict:
    """The adequacy checks of a fit (JSON-ready; see the module notes).

    Parameters
    ----------
    result : analysis.fit.FitResult
        With its ``logpost``.
    wi, wo : ndarray (n, 3), optional
        The table's directions (for the region tests; taken from the model when it has them).

    Returns
    -------
    dict
        ``adequate`` (bool or None), ``reason`` (str), ``alpha``, ``values``, ``tests``
        {name: {"p", "p_holm", ...}} for ``distribution``, ``chi_square`` and
        ``region_<split>``, ``regions`` (each split's sides, counts, mean scores, p),
        ``noise`` (or None), ``rms_normal_score``.
    """
    if result.logpost is None:
        return {"adequate": None, "reason": "no posterior to check (a result read from disk)"}
    lik = result.logpost.lik
    if wi is None and hasattr(result.logpost.model, "wi"):
        wi, wo = result.logpost.model.wi, result.logpost.model.wo
    if lik.n_used < MIN_VALUES:
        return {"adequate": None, "values": lik.n_used,
                "reason": f"too few values ({lik.n_used} < {MIN_VALUES}) to test the fit"}
    scores = normal_scores(result, result.median_internal()[None])[0]
    ok = np.isfinite(scores)
    good = scores[ok]
    if good.size < MIN_VALUES:
        return {"adequate": None, "values": lik.n_used,
                "reason": f"only {good.size} finite residuals at the posterior median"}
    tests = {"distribution": {"p": float(stats.kstest(good, "norm").pvalue),
                              "statistic": "Kolmogorov-Smirnov, normal scores at the median",
                              "mean": float(good.mean()), "sd": float(good.std()),
                              "skewness": float(stats.skew(good)),
                              "excess_kurtosis": float(stats.kurtosis(good))},
             "chi_square": _chi_square(result, lik)}
    reg = None
    if wi is not None:
        reg = _region_tests(lik, np.where(ok, scores, 0.0), np.asarray(wi), np.asarray(wo))
        for name, e in reg.items():
            tests[f"region_{name}"] = {"p": e["p"], "statistic": f"Mann-Whitney U, {e['a']} "
                                       f"against {e['b']}"}
    ps = {k: v["p"] for k, v in tests.items() if v.get("p") is not None}
    for k, p in _holm(ps).items():
        tests[k]["p_holm"] = p
    out = {"alpha": ALPHA, "values": int(lik.n_used), "tests": tests, "regions": reg,
           "noise": _noise(result, lik),
           "rms_normal_score": float(np.sqrt(np.mean(good ** 2)))}
    out.update(_verdict(tests, reg))
    masked = lik.counts["invalid_value"]
    if out["adequate"] is False and masked > 0.01 * lik.counts["total"]:
        out["reason"] += (f"; note: {masked} values were masked as NaN or negative, and "
                          f"dropping negative values near the noise floor biases the rest "
                          f"upward (a matter of the likelihood, not of the model)")
    return out


def _verdict(tests: dict, reg: dict | None) -> dict:
    ran = {k: v for k, v in tests.items() if "p_holm" in v}
    if not ran:
        return {"adequate": None, "reason": "no test could run"}
    failed = sorted((k for k, v in ran.items() if v["p_holm"] < ALPHA),
                    key=lambda k: ran[k]["p_holm"])
    if not failed:
        return {"adequate": True,
                "reason": f"no test rejects the model at {ALPHA:g} (Holm over {len(ran)} tests; "
                          f"smallest corrected p {min(v['p_holm'] for v in ran.values()):.3g})"}
    parts = []
    for k in failed:
        p = ran[k]["p_holm"]
        if k.startswith("region_") and reg is not None:
            e = reg[k[len("region_"):]]
            parts.append(f"residuals differ between {e['a']} (mean score {e['mean_a']:+.2f}) "
                         f"and {e['b']} ({e['mean_b']:+.2f}), p = {p:.2g}")
        elif k == "chi_square":
            parts.append(f"residuals exceed the table's sigma (sum of squares "
                         f"{tests[k]['t_over_dof']:.2f} x its expectation), p = {p:.2g}")
        else:
            d = tests[k]
            parts.append(f"standardized residuals are not distributed as the likelihood "
                         f"assumes (mean {d['mean']:+.2f}, sd {d['sd']:.2f}, skewness "
                         f"{d['skewness']:+.2f}, excess kurtosis {d['excess_kurtosis']:+.2f}; "
                         f"0, 1, 0, 0 for N(0, 1)), p = {p:.2g}")
    return {"adequate": False, "reason": "; ".join(parts) + f" (Holm-corrected, level {ALPHA:g})"}
