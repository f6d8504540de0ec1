"""brdf.baselines: each sheen model against a transliteration of its published formulas (typed
here from the source, scalar math), reciprocity, energy by quadrature (and the tabulated or
fitted albedos against it), the samplers by chi-square, the weights, batched shading, and bad
parameters."""

import math
import zlib

import numpy as np
import pytest

from _chi2 import cell_integrals, chi2_pvalue, histogram, sidak
from brdf import MODELS
from brdf.baselines import Ashikhmin, BaselineModel, Charlie, Lambert, Zeltner, charlietable
from brdf.baselines.charlie import sheen_albedo
from brdf.baselines.sheen import hemisphere_rule, lobe_albedo
from brdf.baselines.zeltner import dir_albedo

SHEENS = [Charlie, Ashikhmin, Zeltner]


def _seed(*parts):
    return zlib.crc32(repr(parts).encode())


def _pairs(n, seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(2, n, 3))
    w[..., 2] = np.abs(w[..., 2]) + 0.02
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    return w[0], w[1]


def _params(rng, cls):
    lo = cls.ROUGHNESS.lo
    return dict(base=tuple(rng.random(3)), sheen=tuple(rng.random(3)),
                roughness=float(lo + (1.0 - lo) * rng.random()))


# -- transliterations, typed from the sources --------------------------------------------------
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cos_h(wi, wo):
    h = [wi[k] + wo[k] for k in range(3)]
    return h[2] / math.sqrt(_dot(h, h))


def _mix(x, y, t):
    return x * (1.0 - t) + y * t


def gltf_l(x, alpha_g):
    # KHR_materials_sheen README, "Sheen visibility"
    one_minus_alpha_sq = (1.0 - alpha_g) * (1.0 - alpha_g)
    a = _mix(21.5473, 25.3245, one_minus_alpha_sq)
    b = _mix(3.82987, 3.32435, one_minus_alpha_sq)
    c = _mix(0.19823, 0.16801, one_minus_alpha_sq)
    d = _mix(-1.97760, -1.27393, one_minus_alpha_sq)
    e = _mix(-4.32054, -4.85967, one_minus_alpha_sq)
    return a / (1.0 + b * x ** c) + d * x + e


def gltf_lambda(cos_theta, alpha_g):
    if abs(cos_theta) < 0.5:
        return math.exp(gltf_l(cos_theta, alpha_g))
    return math.exp(2.0 * gltf_l(0.5, alpha_g) - gltf_l(1.0 - cos_theta, alpha_g))


def gltf_distribution(ndoth, sheen_roughness):
    # "Sheen distribution"
    alpha_g = sheen_roughness * sheen_roughness
    inv_r = 1 / alpha_g
    cos2h = ndoth * ndoth
    sin2h = 1 - cos2h
    return (2 + inv_r) * sin2h ** (inv_r * 0.5) / (2 * math.pi)


def _clamp(x, lo, hi):
    return min(max(x, lo), hi)


def sv_v_sheen(ndotl, ndotv, sheen_roughness):
    # glTF-Sample-Viewer source/Renderer/shaders/brdf.glsl at 00536c7d (and d0b428c8), V_Sheen:
    # the spec's "Sheen visibility" clamped to [0, 1]
    sheen_roughness = max(sheen_roughness, 0.000001)  # clamp (0,1]
    alpha_g = sheen_roughness * sheen_roughness
    return _clamp(1.0 / ((1.0 + gltf_lambda(ndotv, alpha_g) + gltf_lambda(ndotl, alpha_g))
                         * (4.0 * ndotv * ndotl)), 0.0, 1.0)


def gltf_sheen(ndotl, ndotv, ndoth, sheen_roughness):
    # "Sheen distribution" times the Sample Viewer's V_Sheen, colour 1 (its BRDF_specularSheen)
    return gltf_distribution(ndoth, sheen_roughness) * sv_v_sheen(ndotl, ndotv, sheen_roughness)


def ref_charlie(wi, wo, base, sheen, roughness):
    s = gltf_sheen(wi[2], wo[2], _cos_h(wi, wo), roughness)
    m = max(sheen)
    # "Albedo-scaling technique"; E from the checked table, clamped to 1 (our reading)
    e_v = min(float(sheen_albedo(wo[2], roughness)), 1.0)
    e_l = min(float(sheen_albedo(wi[2], roughness)), 1.0)
    scale = min(1.0 - m * e_v, 1.0 - m * e_l)
    return [sheen[k] * s + scale * base[k] / math.pi for k in range(3)]


def ref_ashikhmin(wi, wo, base, sheen, roughness):
    # Filament docs "Cloth model": D_velvet (Neubelt's normalization), f_r = D / (4 (NoL +
    # NoV - NoL NoV)); Filament's roughness is alpha = perceptual^2; color = Fd + Fr
    a = roughness * roughness
    ch = _cos_h(wi, wo)
    sin2 = 1.0 - ch * ch
    cot2 = ch * ch / sin2
    d = 1.0 / (math.pi * (1.0 + 4.0 * a * a)) * (1.0 + 4.0 * math.exp(-cot2 / (a * a))
                                                 / (sin2 * sin2))
    v = 1.0 / (4.0 * (wi[2] + wo[2] - wi[2] * wo[2]))
    return [sheen[k] * d * v + base[k] / math.pi for k in range(3)]


def mx_dir_albedo(x, y):
    # mx_microfacet_sheen.glsl, mx_zeltner_sheen_dir_albedo
    s = y * (0.0206607 + 1.58491 * y) / (0.0379424 + y * (1.32227 + y))
    m = y * (-0.193854 + y * (-1.14885 + y * (1.7932 - 0.95943 * y * y))) / (0.046391 + y)
    o = y * (0.000654023 + (-0.0207818 + 0.119681 * y) * y) / (1.26264 + y * (-1.92021 + y))
    return math.exp(-0.5 * ((x - m) / s) ** 2) / (s * math.sqrt(2.0 * math.pi)) + o


def mx_ltc_ainv(x, y):
    # mx_zeltner_sheen_ltc_aInv
    return (2.58126 * x + 0.813703 * y) * y / (1.0 + 0.310327 * x * x + 2.60994 * x * y)


def mx_ltc_binv(x, y):
    # mx_zeltner_sheen_ltc_bInv
    return (math.sqrt(1.0 - x) * (y - 1.0) * y * y * y
            / (0.0000254053 + 1.71228 * x - 1.71506 * x * y + 1.34174 * y * y))


def mx_brdf(L, V, NdotV, roughness):
    # mx_zeltner_sheen_brdf with N = +z
    X = [V[0], V[1], V[2] - NdotV]
    len_sqr = _dot(X, X)
    if len_sqr > 0.0:
        X = [c / math.sqrt(len_sqr) for c in X]
    else:
        X = [1.0, 0.0, 0.0]
    Y = [-X[1], X[0], 0.0]                                   # cross(N, X)
    w = [_dot(L, X), _dot(L, Y), L[2]]
    a_inv, b_inv = mx_ltc_ainv(NdotV, roughness), mx_ltc_binv(NdotV, roughness)
    wo = [a_inv * w[0] + b_inv * w[2], a_inv * w[1], w[2]]
    len_sqr = _dot(wo, wo)
    return max(wo[2], 0.0) / math.pi * (a_inv / len_sqr) ** 2


def ref_zeltner(wi, wo, base, sheen, roughness):
    # mx_sheen_bsdf, mode zeltner: response = dirAlbedo * color * D (carries NdotL),
    # throughput = 1 - dirAlbedo
    ndotv = min(max(wo[2], 1e-8), 1.0)
    r = min(max(roughness, 0.01), 1.0)
    alb = max(mx_dir_albedo(ndotv, r), 0.0)           # our reading: R clamped at 0
    d = mx_brdf(wi, wo, ndotv, r)
    return [alb * sheen[k] * d / wi[2] + (1.0 - alb) * base[k] / math.pi for k in range(3)]


REFERENCES = {Charlie: ref_charlie, Ashikhmin: ref_ashikhmin, Zeltner: ref_zeltner}


@pytest.mark.parametrize("cls", SHEENS, ids=lambda c: c.name)
def test_eval_matches_transliteration(cls):
    rng = np.random.default_rng(_seed("translit", cls.name))
    wi, wo = _pairs(60, _seed("pairs", cls.name))
    for k in range(0, 60, 6):
        p = _params(rng, cls)
        got = cls(**p).eval(wi[k:k + 6], wo[k:k + 6])
        want = [REFERENCES[cls](list(a), list(b), p["base"], p["sheen"], p["roughness"])
                for a, b in zip(wi[k:k + 6], wo[k:k + 6])]
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-14)


def test_zeltner_never_negative():
    # MaterialX's R dips below 0 at roughness 0.04 to 0.13; clamped, f_r stays >= 0
    wi, wo = _pairs(20000, _seed("negative"))
    f = Zeltner(base=0.0, sheen=1.0).prepare(wi, wo).eval(roughness=np.linspace(0.04, 0.14, 11))
    assert f.min() >= 0.0


def test_zeltner_at_normal_view_and_grazing():
    # wo = n: MaterialX's fallback frame (bInv = 0 there); wo at the clamp of NdotV
    p = dict(base=(0.2, 0.4, 0.6), sheen=(0.9, 0.5, 0.1), roughness=0.45)
    wi, _ = _pairs(20, _seed("normal view"))
    for wo in ([0.0, 0.0, 1.0], [1.0, 0.0, 1e-9]):
        got = Zeltner(**p).eval(wi, np.array(wo) / np.linalg.norm(wo))
        want = [ref_zeltner(list(a), list(np.array(wo) / np.linalg.norm(wo)), p["base"],
                            p["sheen"], p["roughness"]) for a in wi]
        np.testing.assert_allclose(got, want, rtol=1e-9)


def test_registry_and_sheen_param():
    # each baseline is registered under its own name (the registry's other entries are
    # checked by tests/test_brdf_models_conformance.py)
    for cls in (Lambert, *SHEENS):
        assert MODELS[cls.name] is cls
    for cls in SHEENS:
        assert [p.name for p in cls.PARAMS] == ["base", "sheen", "roughness"]
        assert cls.SHEEN_PARAM == "sheen"
    assert (Charlie.reciprocal, Ashikhmin.reciprocal, Zeltner.reciprocal) == (True, True, False)


def test_below_horizon_and_bad_directions():
    for cls in SHEENS:
        f = cls().eval([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]],
                       [[0.3, 0.0, -0.9], [0.3, 0.0, 0.9], [0.0, 0.0, 1.0]])
        assert np.all(f[0] == 0.0) and np.all(f[1] > 0.0) and np.all(np.isnan(f[2]))


# -- grazing directions ----------------------------------------------------------------------
#: theta = 90 deg exactly (cos 6e-17: above the horizon, so shaded) and 89.999 deg, as
#: `microcyl plot lobes` samples them, and cos theta = 1e-12.
GRAZING_COS = [math.cos(math.pi / 2), math.cos(math.radians(89.999)), 1e-12]


def _ring(cos_values, phis_deg):
    """Unit directions at the given cos theta and azimuths (degrees): (n, 3)."""
    c, p = np.meshgrid(np.asarray(cos_values, dtype=np.float64), np.radians(phis_deg),
                       indexing="ij")
    s = np.sqrt(1.0 - c * c)
    return np.stack([s * np.cos(p), s * np.sin(p), c], axis=-1).reshape(-1, 3)


def test_charlie_at_grazing_matches_the_sample_viewer():
    # with theta_i or theta_o at 90 deg the spec's V is about 1e8 and f_r grew like 1 / cos;
    # the Sample Viewer's clamp holds V at 1, so f_sheen <= D
    graze = _ring(GRAZING_COS, [0.0, 90.0, 180.0])
    other = _ring([1.0, 0.8, 0.3, 0.05] + GRAZING_COS, [0.0, 135.0, 180.0])
    p = dict(base=(0.2, 0.4, 0.6), sheen=(0.9, 0.5, 0.1))
    for r in (0.045, 0.3, 1.0):
        m = Charlie(roughness=r, **p)
        for wi, wo in [(graze[:, None], other[None, :]), (other[:, None], graze[None, :])]:
            wi, wo = np.broadcast_arrays(wi, wo)
            wi, wo = wi.reshape(-1, 3), wo.reshape(-1, 3)
            want = [ref_charlie(list(a), list(b), p["base"], p["sheen"], r)
                    for a, b in zip(wi, wo)]
            np.testing.assert_allclose(m.eval(wi, wo), want, rtol=1e-10, atol=0.0)


def _lobe_bound(cls, roughness, cos_i, cos_o):
    """The largest colourless sheen lobe the model's equations allow (1/sr), from the
    transliterations: Charlie D's maximum (D at theta_h = 90 deg) times V <= 1 (the Sample
    Viewer's clamp); the velvet D's maximum times Neubelt's V <= 1 / (4 max(cos_i, cos_o));
    MaterialX's R+ times the LTC's largest D / cos_i, a^2 / (pi lambda_min^2) with
    lambda_min the least eigenvalue of M^T M, M = [[a, 0, b], [0, a, 0], [0, 0, 1]]."""
    if cls is Lambert:
        return np.zeros_like(cos_i)
    if cls is Charlie:
        return np.full_like(cos_i, gltf_distribution(0.0, roughness))
    if cls is Ashikhmin:
        dmax = max(filament_d_ashikhmin(roughness ** 2, math.cos(t))
                   for t in np.linspace(1e-3, math.pi / 2, 20001))
        return dmax / (4.0 * np.maximum(cos_i, cos_o))
    out = []
    for x in np.clip(cos_o, 1e-8, 1.0):
        a, b = mx_ltc_ainv(x, roughness), mx_ltc_binv(x, roughness)
        mat = np.array([[a, 0.0, b], [0.0, a, 0.0], [0.0, 0.0, 1.0]])
        lam = np.linalg.eigvalsh(mat.T @ mat)[0]
        out.append(max(mx_dir_albedo(x, roughness), 0.0) * a * a / (math.pi * lam * lam))
    return np.array(out)


@pytest.mark.parametrize("cls", [c for c in MODELS.values() if issubclass(c, BaselineModel)],
                         ids=lambda c: c.name)
def test_grazing_directions_finite_and_bounded(cls):
    # one direction at theta 90 deg exactly, 89.999 deg or cos 1e-12, the other from the
    # normal to 85 deg or also grazing: f_r finite, >= 0 and at most the lobe's bound plus
    # the base (white). Neubelt's V alone is unbounded when both graze (1 / (cos_i + cos_o),
    # 3e15 1/sr at 90 and 90 deg): there its bound asserts little beyond finiteness.
    graze = _ring(GRAZING_COS, np.arange(0.0, 360.0, 45.0))
    inner = _ring(np.cos(np.radians([0.0, 30.0, 60.0, 80.0, 85.0])), np.arange(0.0, 360.0, 45.0))
    for r in ([None] if cls is Lambert else [cls.ROUGHNESS.lo, 0.1, 0.3, 0.6, 1.0]):
        m = cls(base=1.0) if cls is Lambert else cls(base=1.0, sheen=1.0, roughness=r)
        for wi, wo in [(graze[:, None], inner[None, :]), (inner[:, None], graze[None, :]),
                       (graze[:, None], graze[None, :])]:
            wi, wo = np.broadcast_arrays(wi, wo)
            wi, wo = wi.reshape(-1, 3), wo.reshape(-1, 3)
            with np.errstate(over="raise", divide="raise", invalid="raise"):
                f = m.eval(wi, wo)
            assert np.all(np.isfinite(f)) and f.min() >= 0.0
            bound = _lobe_bound(cls, r, wi[:, 2], wo[:, 2]) + 1.0 / math.pi
            assert np.all(f[:, 0] <= bound * (1.0 + 1e-9))


# -- reciprocity ---------------------------------------------------------------------------
@pytest.mark.parametrize("cls", [Charlie, Ashikhmin], ids=lambda c: c.name)
def test_reciprocal(cls):
    wi, wo = _pairs(500, _seed("recip", cls.name))
    m = cls(base=(0.3, 0.5, 0.7), sheen=(0.9, 0.4, 0.2), roughness=0.35)
    np.testing.assert_allclose(m.eval(wi, wo), m.eval(wo, wi), rtol=1e-12)


def test_zeltner_not_reciprocal():
    wi, wo = _pairs(500, _seed("recip", "zeltner"))
    m = Zeltner(base=0.0, sheen=1.0, roughness=0.5)
    a, b = m.eval(wi, wo)[:, 0], m.eval(wo, wi)[:, 0]
    assert np.max(np.abs(a - b) / np.maximum(a, b)) > 0.5


# -- energy ----------------------------------------------------------------------------------
COS_O = [0.001, 0.01, 0.05, 0.1, 0.3, 0.6, 1.0]


def _albedo_grid(cls, roughness, base=1.0, sheen=1.0, n=96):
    """Directional albedo (red channel) by quadrature: (len(COS_O), len(roughness))."""
    out = []
    for c in COS_O:
        wi, w = hemisphere_rule(c, n, n)
        wo = np.array([math.sqrt(1.0 - c * c), 0.0, c])
        f = cls(base=base, sheen=sheen).prepare(wi, wo).eval(roughness=np.array(roughness))
        out.append((f[..., 0] * wi[:, 2]) @ w)
    return np.array(out)


def filament_d_ashikhmin(roughness, noh):
    # Filament docs, listing clothBRDF (D_Ashikhmin) without its fp16 clamp of sin2h
    a2 = roughness * roughness
    cos2h = noh * noh
    sin2h = 1.0 - cos2h
    sin4h = sin2h * sin2h
    cot2 = -cos2h / (a2 * sin2h)
    return 1.0 / (math.pi * (4.0 * a2 + 1.0) * sin4h) * (4.0 * math.exp(cot2) + sin4h)


@pytest.mark.parametrize("r", [0.045, 0.2, 0.6, 1.0])
def test_distributions_are_normalized(r):
    # the integral of D(h) cos(theta_h) over the hemisphere of h is 1 (analytic for both)
    x, w = np.polynomial.legendre.leggauss(400)
    th = 0.25 * math.pi * (x + 1.0)                          # theta_h in [0, pi/2]
    jac = 2.0 * math.pi * np.sin(th) * np.cos(th) * 0.25 * math.pi * w
    a = r * r
    charlie = [gltf_distribution(math.cos(t), r) for t in th]
    velvet = [filament_d_ashikhmin(a, math.cos(t)) for t in th]
    assert float(np.dot(charlie, jac)) == pytest.approx(1.0, abs=2e-3)
    assert float(np.dot(velvet, jac)) == pytest.approx(1.0, abs=2e-3)
    # and the models' lobes at normal incidence (theta_h = 0) and at a grazing pair
    for wi, wo in [([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]), ([0.9, 0.1, 0.3], [-0.8, 0.2, 0.4])]:
        wi, wo = np.array(wi) / np.linalg.norm(wi), np.array(wo) / np.linalg.norm(wo)
        ch = _cos_h(wi, wo)
        v = 1.0 / (4.0 * (wi[2] + wo[2] - wi[2] * wo[2]))
        if ch < 1.0:
            got = Ashikhmin(base=0.0, sheen=1.0, roughness=r).eval(wi, wo)[0]
            assert got == pytest.approx(filament_d_ashikhmin(a, ch) * v, rel=1e-10)


def test_quadrature_rule_against_an_independent_one():
    # the package's rule (t^2 in cos, half azimuth) against a plain midpoint rule over the
    # whole hemisphere in (cos theta_i, phi), on the Charlie lobe typed from the spec
    n = 400
    mu = (np.arange(n) + 0.5) / n
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * math.pi
    for cos_o, r in [(0.3, 0.5), (0.8, 0.9), (0.1, 0.25)]:
        wo = [math.sqrt(1 - cos_o ** 2), 0.0, cos_o]
        total = 0.0
        for m in mu[::1]:
            s = math.sqrt(1 - m * m)
            for p in ph[::4]:
                wi = [s * math.cos(p), s * math.sin(p), m]
                total += gltf_sheen(m, cos_o, _cos_h(wi, wo), r) * m
        want = total / n * (2 * math.pi / (2 * n / 4))
        got = float(lobe_albedo(Charlie, cos_o, r)[0, 0])
        assert got == pytest.approx(want, rel=2e-3, abs=2e-4)


def test_zeltner_energy_and_its_albedo_fit():
    r = [0.01, 0.1, 0.3, 0.6, 1.0]
    total = _albedo_grid(Zeltner, r)
    assert np.all(np.abs(total - 1.0) < 1e-6)               # R + (1 - R) with D normalized
    lobe = _albedo_grid(Zeltner, r, base=0.0)
    want = dir_albedo(np.clip(np.array(COS_O), 1e-8, 1)[:, None], np.array(r)[None, :])
    np.testing.assert_allclose(lobe, np.maximum(want, 0.0), atol=2e-5)   # f_r = R D / cos:
    # its albedo is R (clamped at 0)
    # MaterialX's Gaussian fit of R itself dips below 0 (documented in docs/guide/baselines.rst)
    x, y = np.meshgrid(np.linspace(0, 1, 201), np.linspace(0.01, 1, 199), indexing="ij")
    fit = dir_albedo(x, y)
    assert -3e-5 < fit.min() < 0.0 and 0.74 < fit.max() < 0.75


#: Zeltner et al.'s reference albedo of the volumetric sheen the LTC approximates, typed from
#: tizian/ltc-sheen fitting/python/data/ltc_table_sheen_volume.cpp at 344d95b8 (third
#: component R of _ltcParamTableVolume[j][i], roughness max(0.01, j / 31), cos max(0.01, i / 31))
LTC_SHEEN_VOLUME_R = {
    4: {0: 0.63273, 1: 0.42999, 4: 0.05910, 10: 0.00062, 31: 0.00001},
    8: {0: 0.69794, 1: 0.60100, 4: 0.31773, 10: 0.05252, 31: 0.00030},
    22: {0: 0.70253, 1: 0.67808, 4: 0.59306, 10: 0.44072, 31: 0.11016},
    31: {0: 0.74973, 1: 0.73527, 4: 0.68291, 10: 0.58226, 31: 0.34187},
}


def test_zeltner_albedo_fit_against_the_published_table():
    # MaterialX's Gaussian fit of R against the table it fits: within 0.01 at most points,
    # 0.084 at most (near grazing, cos 0.01, roughness 4/31); documented in the guide
    err = np.array([dir_albedo(max(0.01, i / 31), max(0.01, j / 31)) - r
                    for j, row in LTC_SHEEN_VOLUME_R.items() for i, r in row.items()])
    assert np.median(np.abs(err)) < 0.006
    assert 0.08 < np.abs(err).max() < 0.085


def test_ashikhmin_energy_documented_excess():
    r = [0.045, 0.2, 0.5, 1.0]
    lobe = _albedo_grid(Ashikhmin, r, base=0.0)
    assert np.all(lobe <= 1.0) and lobe.max() > 0.8           # the velvet lobe alone: <= 0.856
    total = _albedo_grid(Ashikhmin, r)
    # Filament's plain sum: a white base under a white sheen reflects 1 + E > 1 everywhere
    np.testing.assert_allclose(total, 1.0 + lobe, rtol=1e-12)
    assert total.min() > 1.1 and total.max() == pytest.approx(1.839, abs=2e-3)


def _velvet_albedo(cos_o, roughness, n=200):
    """E_velvet(cos_o) of the documented equations (docs/guide/baselines.rst), written here
    apart from brdf.baselines: Gauss-Legendre in cos_i on (0, 1) and in phi_i on (0, pi)
    (doubled: the lobe is symmetric about the plane of wo), D V cos_i summed."""
    a2 = roughness ** 4
    x, w = np.polynomial.legendre.leggauss(n)
    mu, wmu = 0.5 * (x + 1.0), 0.5 * w
    ph, wph = 0.5 * math.pi * (x + 1.0), 0.5 * math.pi * w
    m, p = np.meshgrid(mu, ph, indexing="ij")
    s = np.sqrt(1.0 - m * m)
    so = math.sqrt(1.0 - cos_o * cos_o)
    hx, hy, hz = s * np.cos(p) + so, s * np.sin(p), m + cos_o
    c2 = hz * hz / (hx * hx + hy * hy + hz * hz)
    d = (1.0 + 4.0 * np.exp(-c2 / (a2 * (1.0 - c2))) / (1.0 - c2) ** 2) / (math.pi * (1 + 4 * a2))
    v = 1.0 / (4.0 * (m + cos_o - m * cos_o))
    return 2.0 * float(np.sum(d * v * m * wmu[:, None] * wph[None, :]))


def test_ashikhmin_albedo_figures_of_the_guide():
    """docs/guide/baselines.rst: E_velvet at most 0.856 (grazing view, roughness near
    0.575), least 0.099 at normal view near roughness 0.85 (0.25 at small roughness, 0.128
    at 0.7, 0.132 at 1); a white base under a white sheen reflects 1.10 to 1.86."""
    rough = np.round(np.arange(0.045, 1.0001, 0.005), 3)
    grazing = np.array([_velvet_albedo(0.001, r, 120) for r in rough])
    normal = np.array([_velvet_albedo(1.0, r, 120) for r in rough])
    # the figures as the guide prints them (0.8565 is 0.856 to three places)
    assert f"{grazing.max():.3f}" == "0.856"
    assert rough[grazing.argmax()] == pytest.approx(0.575, abs=0.01)
    assert f"{normal.min():.3f}" == "0.099"
    assert rough[normal.argmin()] == pytest.approx(0.85, abs=0.01)
    assert f"{normal[0]:.2f}" == "0.25"
    assert f"{normal[rough == 0.7][0]:.3f}" == "0.128" and f"{normal[-1]:.3f}" == "0.132"
    # nowhere between lower than at normal view, nor higher than at grazing
    mid = [_velvet_albedo(c, r, 80) for c in (0.01, 0.1, 0.5, 0.9) for r in (0.2, 0.575, 0.85)]
    assert normal.min() < min(mid) and max(mid) < grazing.max()
    # the code's albedo is this quadrature's, and a white base adds 1: rho spans 1.10-1.86
    r = [0.575, 0.85]
    code = _albedo_grid(Ashikhmin, r, base=0.0, n=128)
    want = [[_velvet_albedo(c, x) for x in r] for c in COS_O]
    np.testing.assert_allclose(code, want, rtol=2e-4)
    total = _albedo_grid(Ashikhmin, r, n=128)
    assert f"{total.min():.2f}-{total.max():.2f}" == "1.10-1.86"


def test_charlie_energy_documented_excess():
    r = [0.045, 0.1, 0.2, 0.3, 0.5, 1.0]
    total = _albedo_grid(Charlie, r)
    lobe = _albedo_grid(Charlie, r, base=0.0)
    # V <= 1 bounds the lobe, yet at grazing and small roughness its albedo still exceeds 1
    # (4.41 here without the Sample Viewer's clamp); where E > 1, S = 0 and rho = E
    assert lobe[0, 0] == pytest.approx(1.865, abs=2e-3)
    assert total.max() == pytest.approx(1.865, abs=2e-3) and total.argmax() == 0
    assert lobe[COS_O.index(0.05)].max() < 1.0 and np.all(lobe[:, 3:] < 1.0)
    # at roughness >= 0.3 the albedo scaling keeps the sum at 1 (within the table's error)
    assert np.all(total[:, 3:] <= 1.0 + 3e-3)
    assert np.all(total[COS_O.index(0.1):] <= 1.0)           # above 5.7 degrees: <= 1


@pytest.mark.parametrize("r", [0.045, 0.285, 1.0])
def test_charlie_albedo_at_the_horizon(r):
    # at theta_o = 90 deg exactly the clamp holds V at 1 for every wi, so f_sheen = D and the
    # lobe's albedo is the integral of D(h) cos_i over the hemisphere: a plain midpoint rule
    n, n_phi = 2000, 800
    mu = (np.arange(n) + 0.5) / n
    ph = (np.arange(n_phi) + 0.5) / n_phi * 2.0 * math.pi
    m, p = np.meshgrid(mu, ph, indexing="ij")
    s = np.sqrt(1.0 - m * m)
    wi = np.stack([s * np.cos(p), s * np.sin(p), m], axis=-1)
    cos_o = math.cos(math.pi / 2)
    wo = np.array([math.sqrt(1.0 - cos_o * cos_o), 0.0, cos_o])
    h = wi + wo
    d = gltf_distribution(h[..., 2] / np.linalg.norm(h, axis=-1), r)
    want = float(np.sum(d * m)) / n * (2.0 * math.pi / n_phi)
    lobe = float(lobe_albedo(Charlie, cos_o, r)[0, 0])
    assert lobe == pytest.approx(want, rel=2e-4)
    assert 1.19 < lobe < 2.0                               # E > 1 at every roughness there
    # the white model: below the table's first node E is held at cos 1/4096, so S does not
    # fall with E; its largest albedo, 2.056, is here at roughness 0.285
    wi_q, w = hemisphere_rule(cos_o, 128, 128)
    total = float((Charlie(base=1.0, sheen=1.0, roughness=r).eval(wi_q, wo)[:, 0]
                   * wi_q[:, 2]) @ w)
    assert total >= lobe - 1e-9
    if r == 0.285:
        assert total == pytest.approx(2.056, abs=1e-3)


def test_charlie_table_against_quadrature():
    u = 0.5 * (charlietable.U[:-1] + charlietable.U[1:])      # between the nodes
    v = 0.5 * (np.sqrt(charlietable.R[:-1]) + np.sqrt(charlietable.R[1:]))
    cos, r = u[::4] ** 2, v[::4] ** 2
    want = lobe_albedo(Charlie, cos, r, 96, 96)
    got = sheen_albedo(cos[:, None], r[None, :])
    err = np.abs(got - want)
    assert err[want <= 1.0].max() < 8e-3                      # where S uses it unclamped
    assert err.max() < 0.01
    # and at the nodes the table is the quadrature
    k, j = 9, 5
    node = lobe_albedo(Charlie, charlietable.U[k] ** 2, charlietable.R[j], 160, 160)[0, 0]
    assert charlietable.table()[k, j] == pytest.approx(node, rel=1e-7)


# -- sampling --------------------------------------------------------------------------------
# charlie and ashikhmin share the cosine / uniform mixture (its roughness plays no part);
# zeltner's LTC lobe follows wo and the roughness, down to MaterialX's 0.01
CHI2_CASES = ([(cls, 0.5, th) for cls in (Charlie, Ashikhmin) for th in (10.0, 75.0)]
              + [(Zeltner, r, th) for r in (0.01, 0.1, 0.3, 0.6, 0.9) for th in (0.0, 45.0, 85.0)])
N_CHI2 = 40_000


@pytest.mark.parametrize("cls,r,theta", CHI2_CASES,
                         ids=[f"{c.name}-r{r}-{t:g}" for c, r, t in CHI2_CASES])
def test_chi2_sample_matches_pdf(cls, r, theta):
    m = cls(base=(0.2, 0.3, 0.4), sheen=(0.8, 0.7, 0.6), roughness=r)
    t = math.radians(theta)
    w = np.array([math.sin(t) * math.cos(0.4), math.sin(t) * math.sin(0.4), math.cos(t)])
    u = np.random.default_rng(_seed(cls.name, r, theta)).random((N_CHI2, 2))
    wi, _, _ = m.sample(w, u)
    expected = N_CHI2 * cell_integrals(lambda d: m.pdf(w, d), tol=1e-6)
    assert expected.sum() == pytest.approx(N_CHI2, rel=2e-3)
    stat, dof, p = chi2_pvalue(histogram(wi), expected)
    level = sidak(0.01, len(CHI2_CASES))
    assert p > level, f"chi2 = {stat:.1f} on {dof} dof, p = {p:.3g} < {level:.3g}"


@pytest.mark.parametrize("cls", SHEENS + [Lambert], ids=lambda c: c.name)
def test_weight_is_fr_cos_over_pdf(cls):
    m = cls(base=(0.2, 0.3, 0.4)) if cls is Lambert else \
        cls(base=(0.2, 0.3, 0.4), sheen=(0.8, 0.7, 0.6), roughness=0.5)
    _, wo = _pairs(2000, _seed("weights", cls.name))
    u = np.random.default_rng(_seed("u", cls.name)).random((2000, 2))
    wi, weight, pdf = m.sample(wo, u)
    assert np.all(pdf > 0) and np.all(wi[:, 2] > 0)
    np.testing.assert_allclose(pdf, m.pdf(wo, wi), rtol=1e-12)
    want = m.eval(wi, wo) * wi[:, 2:3] / pdf[:, None]
    np.testing.assert_allclose(weight, want, rtol=1e-10, atol=1e-14)


def test_zeltner_samples_the_ltc_lobe():
    # with no base the sampler still mixes (p >= 0.1), but the LTC branch carries the lobe:
    # the weights' mean is the lobe's albedo R (Monte Carlo, 200k samples)
    m = Zeltner(base=0.0, sheen=1.0, roughness=0.4)
    wo = np.array([0.6, 0.0, 0.8])
    u = np.random.default_rng(7).random((200_000, 2))
    _, weight, _ = m.sample(wo, u)
    assert weight[:, 0].mean() == pytest.approx(dir_albedo(0.8, 0.4), rel=2e-3)
    assert weight[:, 0].std() / weight[:, 0].mean() < 0.6    # close to proportional to f cos


# -- batched shading and parameters ----------------------------------------------------------
@pytest.mark.parametrize("cls", SHEENS, ids=lambda c: c.name)
def test_prepared_batch_equals_eval(cls):
    rng = np.random.default_rng(_seed("batch", cls.name))
    wi, wo = _pairs(40, _seed("bpairs", cls.name))
    sets = [_params(rng, cls) for _ in range(6)]
    batch = {k: np.array([s[k] for s in sets]).reshape((2, 3) + np.shape(sets[0][k]))
             for k in sets[0]}
    got = cls().prepare(wi, wo).eval(**batch)
    assert got.shape == (2, 3, 40, 3)
    for b, s in enumerate(sets):
        np.testing.assert_allclose(got.reshape(6, 40, 3)[b], cls(**s).eval(wi, wo),
                                   rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("cls,kw,match", [
    (Charlie, {"roughness": 0.01}, r"^roughness must .*got 0\.01$"),
    (Ashikhmin, {"roughness": 1.5}, r"^roughness must .*got 1\.5$"),
    (Zeltner, {"roughness": 0.0}, r"^roughness must .*got 0\.0$"),
    (Zeltner, {"sheen": (0.2, 1.2, 0.0)}, r"^sheen must .*got 1\.2$"),
    (Charlie, {"base": -0.1}, r"^base must .*got -0\.1$"),
    (Ashikhmin, {"sheen": (0.1, 0.2)}, r"^sheen must be one number or three"),
    (Zeltner, {"fuzz": 1.0}, r"^zeltner: unknown parameter\(s\) fuzz"),
])
def test_bad_parameters_one_line(cls, kw, match):
    with pytest.raises(ValueError, match=match) as err:
        cls(**kw)
    assert "\n" not in str(err.value)
