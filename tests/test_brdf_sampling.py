"""brdf.sampling: sample against pdf (chi-square, as pbrt-v4 and Mitsuba check theirs), the
pdf's normalization on the sphere, the weights, and a Monte Carlo albedo against
analysis.albedo."""

import math
import zlib

import numpy as np
import pytest
from scipy import optimize, stats

import analysis
import brdf
from _chi2 import cell_integrals, chi2_pvalue, histogram, sidak
from spec_reference import curve_samples, random_pairs

#: Variants that change what the sampler draws (masking shapes the azimuth; the tangent
#: rule and the rotation move the lobes).
DRAW_VARIANTS = [{}, {"masking": False}, {"tangent_sampling": "control_points"},
                 {"tangent_samples": 5}, {"rotation": 0.7}]
#: Variants that change f_r only: the sampler is that of the base variant (second item).
F_ONLY_VARIANTS = [({"reweighting": False}, {}), ({"transmission": "longitudinal"}, {}),
                   ({"gap": "outgoing"}, {}),
                   ({"masking": False, "reweighting": False}, {"masking": False})]
ALL_VARIANTS = DRAW_VARIANTS + [v for v, _ in F_ONLY_VARIANTS]
#: Viewer directions (theta_o, phi_o) in degrees: normal, oblique, grazing along -warp.
WOS = [(0.0, 0.0), (50.0, 20.0), (85.0, 180.0)]
CHI2_CASES = [(p, v, wo) for p in brdf.PRESETS for v in DRAW_VARIANTS for wo in WOS]
CHI2_CASES += [(p, {}, (85.0, 45.0)) for p in brdf.PRESETS]
#: grazing viewers, where the truncated lobes' windows are narrowest
CHI2_CASES += [(p, v, (89.0, 100.0)) for p in brdf.PRESETS for v in ({}, {"masking": False})]
ALPHA = 0.01                                       # family-wise significance
N_CHI2 = 40_000


def _id(v):
    return "-".join(f"{k}={x}" for k, x in v.items()) or "default"


def _wo(theta_deg, phi_deg):
    return brdf.directions.from_angles(math.radians(theta_deg), math.radians(phi_deg))


def _seed(*parts):
    return zlib.crc32(repr(parts).encode())


# -- chi-square goodness of fit -----------------------------------------------------------
@pytest.mark.parametrize("name,variant,wo", CHI2_CASES,
                         ids=[f"{p}-{_id(v)}-{wo[0]:g},{wo[1]:g}" for p, v, wo in CHI2_CASES])
def test_chi2_sample_matches_pdf(name, variant, wo):
    fab = brdf.fabric(name, **variant)
    w = _wo(*wo)
    u = np.random.default_rng(_seed(name, variant, wo)).random((N_CHI2, 2))
    wi, _, _ = fab.sample(w, u)
    expected = N_CHI2 * cell_integrals(lambda d: fab.pdf(w, d), tol=1e-6)
    assert expected.sum() == pytest.approx(N_CHI2, rel=2e-3)
    stat, dof, p = chi2_pvalue(histogram(wi), expected)
    level = sidak(ALPHA, len(CHI2_CASES))
    assert p > level, f"chi2 = {stat:.1f} on {dof} dof, p = {p:.3g} < {level:.3g}"


@pytest.mark.parametrize("variant,base", F_ONLY_VARIANTS, ids=[_id(v) for v, _ in F_ONLY_VARIANTS])
def test_f_only_variants_draw_as_their_base(variant, base):
    # these variants change f_r, not the sampler: same directions, same pdf as the base
    # (whose draws the chi-square tests check), so only the weights differ.
    u = np.random.default_rng(3).random((500, 2))
    for name in brdf.PRESETS:
        w = _wo(85.0, 180.0)
        a = brdf.fabric(name, **variant).sample(w, u)
        b = brdf.fabric(name, **base).sample(w, u)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[2], b[2])


def test_chi2_detects_a_wrong_pdf():
    # the test has power: samples against the pdf of a viewer 8 degrees off, or against the
    # pdf without masking's cos-shaped azimuth, fail it.
    fab = brdf.fabric("silk_shot")
    w = _wo(50.0, 20.0)
    wi, _, _ = fab.sample(w, np.random.default_rng(0).random((N_CHI2, 2)))
    for other, w2 in ((fab, _wo(58.0, 20.0)), (fab.replace(masking=False), w)):
        expected = N_CHI2 * cell_integrals(lambda d: other.pdf(w2, d), tol=1e-6)
        assert chi2_pvalue(histogram(wi), expected)[2] < 1e-6


def test_chi2_pooling_by_hand():
    obs = [3, 2, 10, 20]
    exp = [1.0, 4.5, 9.5, 20.0]
    # 1.0 + 4.5 pooled (5.5), then 9.5, 20: three cells, two dof
    stat, dof, p = chi2_pvalue(obs, exp)
    want = (5 - 5.5) ** 2 / 5.5 + (10 - 9.5) ** 2 / 9.5 + 0.0
    assert dof == 2 and stat == pytest.approx(want)
    assert p == pytest.approx(stats.chi2.sf(want, 2))


# -- the pdf integrates to 1 over the upper hemisphere; no draw lands below it -----------
PDF_CASES = [(p, v, wo) for p in brdf.PRESETS for v in ({}, {"masking": False})
             for wo in ((0.0, 0.0), (85.0, 180.0))]


@pytest.mark.parametrize("name,variant,wo", PDF_CASES,
                         ids=[f"{p}-{_id(v)}-{wo[0]:g}" for p, v, wo in PDF_CASES])
def test_pdf_integrates_to_one(name, variant, wo):
    fab = brdf.fabric(name, **variant)
    w = _wo(*wo)
    cells = cell_integrals(lambda d: fab.pdf(w, d), tol=2e-7)
    total = cells.sum()
    below = cells[: cells.shape[0] // 2]             # cos(theta) < 0
    # the adaptive rule converges from below at the integrable 1/cos(theta) peaks at the
    # tangents and the closing azimuth windows at the horizon
    assert total == pytest.approx(1.0, abs=3e-4)
    assert np.all(below == 0.0)                       # the lobes are truncated to z > 0
    down = brdf.directions.from_angles(np.linspace(1.6, np.pi, 7), np.linspace(-3, 3, 7))
    assert np.all(fab.pdf(w, down) == 0.0)


#: Incidences and azimuths of the honest count of draws below the horizon (issue 36).
SWEEP_THETA = np.arange(0.0, 90.0, 7.5).tolist() + [89.0, 89.9]
SWEEP_PHI = [0.0, 45.0, 90.0, 160.0, 250.0]
#: Most of a sampler's draws allowed at or below the horizon, at any incidence.
MAX_BELOW = 0.05


@pytest.mark.parametrize("variant", [{}, {"masking": False}, {"rotation": 0.7}], ids=_id)
@pytest.mark.parametrize("name", brdf.PRESETS)
def test_draws_stay_above_the_horizon(name, variant, record_property):
    # counted, not integrated: the share of draws with wi_z <= 0 for each viewer of the
    # sweep (the untruncated lobes lost up to 71% for velvet, 12% for crepe de chine)
    fab = brdf.fabric(name, **variant)
    th, ph = np.meshgrid(np.radians(SWEEP_THETA), np.radians(SWEEP_PHI), indexing="ij")
    wo = brdf.directions.from_angles(th.ravel(), ph.ravel())            # (V, 3)
    # 500 draws a viewer measure a share near the 5% bound to +-1% (binomial sd); the
    # truncated lobes lose none (0 of 3,000 at every viewer of every case, 2026-12-07)
    u = np.random.default_rng(_seed("below", name, variant)).random((500, wo.shape[0], 2))
    wi, weight, p = fab.sample(wo, u)
    below = np.mean(wi[..., 2] <= 0.0, axis=0)
    record_property("worst_below", float(below.max()))
    worst = int(np.argmax(below))
    assert below.max() <= MAX_BELOW, (
        f"{below.max():.1%} of draws below the horizon at theta_o = "
        f"{np.degrees(th.ravel()[worst]):g}, phi_o = {np.degrees(ph.ravel()[worst]):g}")
    assert np.all(p > 0) and np.all(np.isfinite(weight))


# -- an independent transliteration of the pdf -------------------------------------------
def _azimuth_mass(theta, alpha, masking):
    """Mass of the azimuth density where the direction (theta, phi) about the tangent tilted
    by alpha is above the horizon: the window's edge found by brentq on its height."""
    def height(phi):
        return (math.cos(theta) * math.cos(phi) * math.cos(alpha)
                + math.sin(theta) * math.sin(alpha))
    end = math.pi / 2 if masking else math.pi
    if height(0.0) <= 0:
        return 0.0
    m = end if height(end) > 0 else optimize.brentq(height, 0.0, end, xtol=1e-15)
    return math.sin(m) if masking else m / math.pi


def reference_pdf(fabric, wo, wi):
    """The mixture density of one pair, written from MODEL.md's angles and scipy.stats: the
    lobes truncated to the directions above the horizon (brdf.horizon)."""
    share, lobe = brdf.sampling.lobe_probabilities(fabric)
    opts = fabric.options
    total = brdf.sampling.COSINE_SHARE * max(wi[2], 0.0) / math.pi
    if wi[2] <= 0:
        return total
    rot = opts["rotation"]
    n = np.array([0.0, 0.0, 1.0])
    for j, th in enumerate(fabric.threads):
        ang = rot + j * math.pi / 2
        t0 = np.array([math.cos(ang), math.sin(ang), 0.0])
        b = np.cross(n, t0)
        alphas = curve_samples(th.offsets, th.lengths, opts["tangent_samples"],
                               opts["tangent_sampling"])
        for a in alphas:
            t = math.cos(a) * t0 + math.sin(a) * n
            nt = math.cos(a) * n - math.sin(a) * t0
            theta_i = math.asin(np.clip(wi @ t, -1, 1))
            theta_r = math.asin(np.clip(wo @ t, -1, 1))
            phi = math.atan2(wi @ b, wi @ nt)
            p_phi = max(math.cos(phi), 0.0) / 2 if opts["masking"] else 1 / (2 * math.pi)
            p_phi /= _azimuth_mass(theta_i, a, opts["masking"])
            lo, hi = max(-math.pi / 2, a - math.pi / 2), min(math.pi / 2, a + math.pi / 2)
            dens = lobe[j, 2] / (math.sin(hi) - math.sin(lo))
            for k, gamma in enumerate((th.gamma_s, th.gamma_v)):
                sd = 2 * math.radians(gamma)
                g = stats.truncnorm.pdf(theta_i, (lo + theta_r) / sd, (hi + theta_r) / sd,
                                        loc=-theta_r, scale=sd)
                dens += lobe[j, k] * g / math.cos(theta_i)
            total += share[j] * dens * p_phi / len(alphas)
    return total


@pytest.mark.parametrize("variant", ALL_VARIANTS, ids=[_id(v) for v in ALL_VARIANTS])
def test_pdf_matches_reference(variant):
    rng = np.random.default_rng(11)
    wi, wo = random_pairs(12, rng)
    wi = wi * np.where(rng.random(12) < 0.3, -1.0, 1.0)[:, None]   # some below the horizon
    wi[:3, 2] = [1e-3, 1e-6, 0.02]                        # near it: narrow azimuth windows
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, **variant)
        got = fab.pdf(wo, wi)
        want = [reference_pdf(fab, b, a) for a, b in zip(wi, wo)]
        np.testing.assert_allclose(got, want, rtol=1e-9)


# -- weights -------------------------------------------------------------------------------
@pytest.mark.parametrize("variant", ALL_VARIANTS, ids=[_id(v) for v in ALL_VARIANTS])
def test_weight_is_fr_cos_over_pdf(variant, record_property):
    u = np.random.default_rng(2).random((3000, 2))
    largest = 0.0
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, **variant)
        for wo in ((0.0, 0.0), (30.0, 100.0), (85.0, 180.0), (89.0, 45.0)):
            w = _wo(*wo)
            wi, weight, p = fab.sample(w, u)
            np.testing.assert_allclose(np.linalg.norm(wi, axis=-1), 1.0, rtol=1e-12)
            np.testing.assert_allclose(p, fab.pdf(w, wi), rtol=1e-12)
            f = fab.eval(wi, w)
            want = f * np.maximum(wi[:, 2], 0.0)[:, None] / p[:, None]
            np.testing.assert_allclose(weight, want, rtol=1e-12, atol=0)
            assert np.all(p > 0) and np.all(np.isfinite(weight)) and np.all(weight >= 0)
            assert np.all(p[f.max(axis=-1) > 0] > 0)
            largest = max(largest, float(weight.max()))
    record_property("largest_weight", largest)
    # largest seen: 3.8 with masking, 5.7 without (f_r cos(theta_i) peaks where Q vanishes at
    # the horizon, near the mirror direction of a grazing viewer; 6.5 and 14.7 before the
    # lobes were truncated to the upper hemisphere)
    assert largest < (5.0 if fab.options["masking"] else 8.0)


def test_no_thread_area_samples_the_cosine_part_only():
    t = brdf.preset_threads("linen_plain")[0].replace(area=0.0)
    fab = brdf.Fabric((t, t))
    wo = _wo(40.0, 10.0)
    wi, weight, p = fab.sample(wo, np.random.default_rng(0).random((200, 2)))
    np.testing.assert_allclose(p, wi[:, 2] / np.pi, rtol=1e-12)
    assert np.all(wi[:, 2] > 0) and np.all(weight == 0)      # f_r = 0 without threads


def test_pdf_positive_where_fr_positive():
    wi, wo = random_pairs(4000, np.random.default_rng(4))
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        pos = fab.eval(wi, wo).max(axis=-1) > 0
        assert np.all(fab.pdf(wo, wi)[pos] > 0)


# -- Monte Carlo albedo ---------------------------------------------------------------------
MC_CASES = [(p, {}, wo) for p in brdf.PRESETS for wo in ((0.0, 0.0), (60.0, 30.0), (85.0, 180.0))]
MC_CASES += [(p, v, (85.0, 45.0)) for p in brdf.PRESETS for v in ALL_VARIANTS[1:]]
N_MC = 40_000


@pytest.mark.parametrize("name,variant,wo", MC_CASES,
                         ids=[f"{p}-{_id(v)}-{wo[0]:g}" for p, v, wo in MC_CASES])
def test_mc_albedo_matches_analysis(name, variant, wo):
    fab = brdf.fabric(name, **variant)
    w = _wo(*wo)
    u = np.random.default_rng(_seed("mc", name, variant, wo)).random((N_MC, 2))
    _, weight, _ = fab.sample(w, u)
    mean = weight.mean(axis=0)
    se = weight.std(axis=0, ddof=1) / math.sqrt(N_MC)
    ref = analysis.albedo(fab, w)
    z = stats.norm.isf(0.5 * sidak(ALPHA, 3 * len(MC_CASES)))
    np.testing.assert_array_less(np.abs(mean - ref.value), z * se + ref.error + 1e-12)


# -- interface -------------------------------------------------------------------------------
def test_shapes_broadcasting_and_determinism():
    fab = brdf.fabric("velvet")
    wo = brdf.directions.from_angles(np.radians([10.0, 70.0]), 0.0)       # (2, 3)
    u = np.random.default_rng(0).random((5, 1, 2))
    wi, weight, p = fab.sample(wo, u)
    assert wi.shape == (5, 2, 3) and weight.shape == (5, 2, 3) and p.shape == (5, 2)
    again = fab.sample(wo, u)
    for a, b in zip((wi, weight, p), again):
        assert a.tobytes() == b.tobytes()
    assert fab.pdf(wo, wi).shape == (5, 2)
    wi0, w0, p0 = fab.sample([0.0, 0.0, 0.0], [0.5, 0.5])
    assert np.isnan(wi0).all() and np.isnan(w0).all() and np.isnan(p0)
    wib, wb, pb = fab.sample([0.0, 0.6, -0.8], np.random.default_rng(1).random((50, 2)))
    assert np.all(wb == 0) and np.all(pb > 0)            # viewer below: f_r = 0


@pytest.mark.parametrize("u,match", [
    (np.zeros((4, 3)), r"u must have shape \(\.\.\., 2\)"),
    ([0.5, 1.0], r"u must lie in \[0, 1\)"),
    ([-0.1, 0.5], r"u must lie in \[0, 1\)"),
    ([np.nan, 0.5], r"u must lie in \[0, 1\)"),
    (np.zeros((3, 2)), "does not broadcast"),
    ("ab", "u must be a numeric array"),
])
def test_bad_u(u, match):
    wo = np.tile([0.0, 0.0, 1.0], (2, 1))
    with pytest.raises(ValueError, match=match):
        brdf.fabric("linen_plain").sample(wo, u)


def test_bad_directions():
    fab = brdf.fabric("linen_plain")
    with pytest.raises(ValueError, match="wo must have shape"):
        fab.sample([0.0, 1.0], [0.5, 0.5])
    with pytest.raises(ValueError, match="wi must have shape"):
        fab.pdf([0.0, 0.0, 1.0], [0.0, 1.0])
