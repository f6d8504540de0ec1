"""Fabric.eval: hand-computed values, the spec transliteration, and physical properties."""

import itertools
import math
import re

import numpy as np
import pytest

import brdf
from brdf import Fabric, Thread
from spec_reference import random_pairs, reference_eval, thread_sample

VARIANTS = [
    {},
    {"masking": False},
    {"reweighting": False},
    {"masking": False, "reweighting": False},
    {"transmission": "longitudinal"},
    {"gap": "outgoing"},
    {"tangent_sampling": "control_points"},
    {"tangent_samples": 5},
    {"rotation": 0.7},
]
CASES = list(itertools.product(brdf.PRESETS, VARIANTS))
IDS = [f"{p}-{'-'.join(f'{k}={v}' for k, v in o.items()) or 'default'}" for p, o in CASES]


@pytest.fixture(scope="module")
def pairs():
    return random_pairs(300, np.random.default_rng(7))


# -- one thread, one tangent sample, worked by hand -------------------------------------------
def one_thread_fabric(**options):
    t1 = Thread(1.46, (0.5, 0.3, 0.1), 0.3, 12, 24, 0.7, (0, 0), (1,))
    t2 = Thread(1.5, (1, 1, 1), 0.5, 10, 20, 0.0, (0, 0), (1,))  # area 0: contributes nothing
    return Fabric((t1, t2), tangent_samples=1, **options)


def fresnel_snell(eta, c):
    ti = math.acos(c)
    tt = math.asin(math.sin(ti) / eta)
    return 0.5 * ((math.sin(ti - tt) / math.sin(ti + tt)) ** 2
                  + (math.tan(ti - tt) / math.tan(ti + tt)) ** 2)


def test_hand_values_one_thread_one_sample():
    # Thread along x, offset 0: t = x, b = y, n_t = z.
    wi = np.array([0.48, 0.36, 0.8])
    wo = np.array([-0.6, 0.0, 0.8])
    th_i, th_r = math.asin(0.48), math.asin(-0.6)
    phi_i, phi_r = math.atan2(0.36, 0.8), 0.0
    psi_i, psi_r = math.atan2(0.48, 0.8), math.atan2(-0.6, 0.8)
    th_h, th_d = (th_i + th_r) / 2, (th_i - th_r) / 2
    phi_d, psi_d = phi_i - phi_r, psi_i - psi_r
    # each term
    cos_g = math.cos(th_d) * math.cos(phi_d / 2)
    F = fresnel_snell(1.46, cos_g)
    assert brdf.terms.fresnel(1.46, cos_g) == pytest.approx(F, rel=1e-13)
    g_s = math.exp(-th_h**2 / (2 * math.radians(12) ** 2)) / (math.radians(12) * math.sqrt(2 * math.pi))
    g_v = math.exp(-th_h**2 / (2 * math.radians(24) ** 2)) / (math.radians(24) * math.sqrt(2 * math.pi))
    assert brdf.terms.gaussian(math.radians(12), th_h) == pytest.approx(g_s, rel=1e-14)
    u = lambda x: math.exp(-x * x / (2 * math.radians(20) ** 2))  # noqa: E731
    M = (1 - u(phi_d)) * math.cos(phi_i) * 1.0 + u(phi_d) * min(math.cos(phi_i), 1.0)
    P = (1 - u(psi_d)) * math.cos(psi_i) * math.cos(psi_r) + u(psi_d) * min(math.cos(psi_i), math.cos(psi_r))
    assert brdf.terms.pair_weight(math.cos(phi_i), 1.0, phi_d) == pytest.approx(M, rel=1e-14)
    f_rs = F * math.cos(phi_d / 2) * g_s
    ci, cr = math.cos(th_i), math.cos(th_r)
    A = np.array([0.5, 0.3, 0.1])
    f_rv = (1 - F) ** 2 * ((1 - 0.3) * g_v + 0.3) / (ci + cr) * A
    f_s = (f_rs + f_rv) / math.cos(th_d) ** 2
    S = f_s * M * P * ci
    Q = 0.7 * P + (1 - 0.7) * 0.8
    expect = 0.7 * S / (Q * 0.8)
    np.testing.assert_allclose(one_thread_fabric().eval(wi, wo), expect, rtol=1e-13)
    # the terms of the "outgoing" gap and longitudinal transmission change just what they should
    Qo = 0.7 * P + 0.3 * 0.8      # n.wo = 0.8 too: the same Q here
    np.testing.assert_allclose(one_thread_fabric(gap="outgoing").eval(wi, wo),
                               0.7 * S / (Qo * 0.8), rtol=1e-13)
    ft_long = (1 - fresnel_snell(1.46, ci)) * (1 - fresnel_snell(1.46, cr))
    S_long = (f_rs + ft_long / (1 - F) ** 2 * f_rv) / math.cos(th_d) ** 2 * M * P * ci
    np.testing.assert_allclose(one_thread_fabric(transmission="longitudinal").eval(wi, wo),
                               0.7 * S_long / (Q * 0.8), rtol=1e-13)
    # masking and reweighting off: M = P = Q = 1
    np.testing.assert_allclose(
        one_thread_fabric(masking=False, reweighting=False).eval(wi, wo),
        0.7 * f_s * ci / 0.8, rtol=1e-13)


def test_simplified_equation_against_direct_evaluation(pairs):
    """Masking and reweighting off: f_r = sum_j a_j (1/N) sum_t f_s cos(theta_i) / (n . wi)."""
    wi, wo = pairs
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, masking=False, reweighting=False, tangent_samples=16)
        direct = np.zeros((len(wi), 3))
        for j, th in enumerate(fab.threads):
            t0 = np.array([1.0, 0.0, 0.0]) if j == 0 else np.array([0.0, 1.0, 0.0])
            s = np.zeros((len(wi), 3))
            total = sum(th.lengths)
            for m in range(16):
                a = math.radians(float(th.curve.offset_at((m + 0.5) / 16 * total)))
                fs_cos, _ = thread_sample(wi, wo, t0, a, th, False, False, "half_angle")
                s += fs_cos / 16
            direct += th.area * s
        direct /= wi[:, 2:3]
        np.testing.assert_allclose(fab.eval(wi, wo), direct, rtol=1e-11, atol=0)


@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_matches_spec_transliteration(pairs, preset, options):
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    np.testing.assert_allclose(fab.eval(wi, wo), reference_eval(fab, wi, wo), rtol=1e-11,
                               atol=1e-13)


# -- properties ------------------------------------------------------------------------------
@pytest.mark.parametrize("preset, options", CASES, ids=IDS)
def test_finite_nonnegative_and_broadcasting(pairs, preset, options):
    wi, wo = pairs
    fab = brdf.fabric(preset, **options)
    f = fab.eval(wi, wo)
    assert f.shape == (len(wi), 3)
    assert np.all(np.isfinite(f)) and np.all(f >= 0)
    assert np.any(f > 0)
    six = fab.eval(wi[:6], wo[:6])
    np.testing.assert_array_equal(fab.eval(wi[:6].reshape(2, 3, 3), wo[:6].reshape(2, 3, 3)),
                                  six.reshape(2, 3, 3))
    # one wi against many wo
    np.testing.assert_allclose(fab.eval(wi[0], wo[:5]), fab.eval(np.tile(wi[0], (5, 1)), wo[:5]),
                               rtol=1e-15)


def rotate_z(w, angle):
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return w @ R.T


@pytest.mark.parametrize("preset", brdf.PRESETS)
def test_rotating_fabric_and_directions_together_changes_nothing(pairs, preset):
    wi, wo = pairs
    for rho in (0.3, 2.0, -1.2):
        fab = brdf.fabric(preset)
        rot = brdf.fabric(preset, rotation=rho)
        np.testing.assert_allclose(rot.eval(rotate_z(wi, rho), rotate_z(wo, rho)),
                                   fab.eval(wi, wo), rtol=1e-10, atol=1e-13)


@pytest.mark.parametrize("preset", brdf.PRESETS)
def test_rotation_by_90_degrees_equals_swapping_threads(pairs, preset):
    # Turned by 90 degrees the weft runs along -x: the same thread as along +x with its tangent
    # offsets negated. Every preset's weft curve is symmetric under that, so this is a swap.
    wi, wo = pairs
    fab = brdf.fabric(preset)
    t1, t2 = fab.threads
    swapped = Fabric((t2, t1))
    np.testing.assert_allclose(fab.replace(rotation=math.pi / 2).eval(wi, wo),
                               swapped.eval(wi, wo), rtol=1e-10, atol=1e-13)


def test_rotation_by_90_degrees_with_asymmetric_weft(pairs):
    wi, wo = pairs
    t1 = Thread(1.46, 0.2, 0.3, 8, 16, 0.4, (-10, 40), (1,))
    t2 = Thread(1.5, 0.3, 0.2, 6, 12, 0.5, (-60, -20), (1,))
    mirrored = t2.replace(offsets=(60, 20))
    turned = Fabric((t1, t2), rotation=math.pi / 2)
    assert not np.allclose(turned.eval(wi, wo), Fabric((t2, t1)).eval(wi, wo))
    np.testing.assert_allclose(turned.eval(wi, wo), Fabric((mirrored, t1)).eval(wi, wo),
                               rtol=1e-10, atol=1e-13)


@pytest.mark.parametrize("preset", ["linen_plain", "velvet", "polyester_satin_charmeuse"])
def test_converges_as_tangent_samples_grow(pairs, preset):
    wi, wo = pairs
    ref = brdf.fabric(preset, tangent_samples=2048).eval(wi, wo)
    errs = [np.max(np.abs(brdf.fabric(preset, tangent_samples=n).eval(wi, wo) - ref))
            for n in (8, 32, 128)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 0.05 * errs[0]


def test_zero_below_horizon_and_nan_for_bad_vectors():
    fab = brdf.fabric("silk_shot")
    up = np.array([0.3, 0.2, 0.9])
    wi = np.array([up, [0.3, 0.2, -0.1], [1.0, 0.0, 0.0], [0, 0, 0], [np.nan, 0, 1], up])
    wo = np.array([up, up, up, up, up, [0.1, 0.0, -1.0]])
    f = fab.eval(wi, wo)
    assert np.all(f[0] > 0)
    np.testing.assert_array_equal(f[[1, 2, 5]], 0.0)
    assert np.all(np.isnan(f[[3, 4]]))
    # NaN stays in its own entries
    np.testing.assert_array_equal(f[0], fab.eval(up, up))


def test_non_unit_vectors_are_normalized(pairs):
    wi, wo = pairs
    fab = brdf.fabric("velvet")
    np.testing.assert_allclose(fab.eval(3.0 * wi, 1e-3 * wo), fab.eval(wi, wo), rtol=1e-13)
    np.testing.assert_allclose(fab.eval(1e200 * wi[:3], wo[:3]), fab.eval(wi[:3], wo[:3]),
                               rtol=1e-13)


def test_eval_threads_sum_to_eval(pairs):
    wi, wo = pairs
    fab = brdf.fabric("silk_crepe_de_chine")
    parts = fab.eval_threads(wi, wo)
    assert parts.shape == (len(wi), 2, 3)
    np.testing.assert_allclose(parts.sum(axis=-2), fab.eval(wi, wo), rtol=1e-14)


def test_prepare_matches_eval_for_other_parameters(pairs):
    wi, wo = pairs
    fab = brdf.fabric("velvet")
    prep = fab.prepare(wi, wo)
    changed = [t.replace(eta=1.6, kd=0.5, gamma_s=9, gamma_v=11, area=0.3 + 0.1 * j,
                         albedo=(0.2, 0.4, 0.6)) for j, t in enumerate(fab.threads)]
    direct = fab.replace(threads=changed).eval(wi, wo)
    batch = prep.eval(eta=[[1.46, 1.46], [1.6, 1.6]], kd=[[0.1, 0.1], [0.5, 0.5]],
                      gamma_s=[[6, 6], [9, 9]], gamma_v=[[12, 12], [11, 11]],
                      area=[[0.5, 0.5], [0.3, 0.4]],
                      albedo=[[fab.threads[0].albedo, fab.threads[1].albedo],
                              [[0.2, 0.4, 0.6]] * 2])
    assert batch.shape == (2, len(wi), 3)
    np.testing.assert_allclose(batch[0], fab.eval(wi, wo), rtol=1e-12)
    np.testing.assert_allclose(batch[1], direct, rtol=1e-12)
    with pytest.raises(ValueError, match=r"eta must have shape \(\.\.\., 2\)"):
        prep.eval(eta=[1.4, 1.4, 1.4])


def test_blocked_batch_matches_per_set_evaluation():
    # A batch of 7 random parameter sets shaded in many small blocks (over pairs and sets)
    # against each set evaluated on its own by Fabric.eval of a fabric with those threads.
    wi, wo = random_pairs(2000, np.random.default_rng(11))
    wi[:3, 2] = -0.2                     # below the horizon: 0
    wo[3] = 0.0                          # a bad vector: NaN
    rng = np.random.default_rng(5)
    b = 7
    gs = rng.uniform(3.0, 20.0, (b, 2))
    gv = np.where(rng.random((b, 2)) < 0.5, 2.0 * gs, rng.uniform(5.0, 40.0, (b, 2)))
    kw = dict(eta=rng.uniform(1.2, 1.8, (b, 2)), kd=rng.uniform(0.0, 1.0, (b, 2)),
              gamma_s=gs, gamma_v=gv, area=rng.uniform(0.05, 0.5, (b, 2)),
              albedo=rng.uniform(0.0, 1.0, (b, 2, 3)))
    for preset, options in [("linen_plain", {}), ("silk_crepe_de_chine", {}),
                            ("velvet", {"transmission": "longitudinal"}),
                            ("silk_shot", {"reweighting": False})]:
        fab = brdf.fabric(preset).replace(**options)
        prep = fab.prepare(wi, wo)
        prep.block_elements = 3000       # 93 pairs of linen by 1 set: over 150 blocks
        batch = prep.eval(**kw)
        assert batch.shape == (b, len(wi), 3)
        for i in range(b):
            threads = [t.replace(**{k: v[i, j] for k, v in kw.items()})
                       for j, t in enumerate(fab.threads)]
            single = fab.replace(threads=threads).eval(wi, wo)
            np.testing.assert_allclose(batch[i], single, rtol=1e-13, atol=0)
        assert np.isnan(batch[:, 3]).all() and (batch[:, :3] == 0.0).all()


# -- bad input -------------------------------------------------------------------------------
GOOD = dict(eta=1.46, albedo=(0.1, 0.2, 0.3), kd=0.3, gamma_s=12, gamma_v=24, area=0.33,
            offsets=(-25, 25), lengths=(1,))


@pytest.mark.parametrize("field, value, match", [
    ("eta", 1.0, r"eta must be a finite number with 1.0 < eta; got 1.0"),
    ("eta", 0.5, "eta must be"),
    ("kd", 1.2, r"kd must be a finite number with 0.0 <= kd <= 1.0; got 1.2"),
    ("kd", -0.1, "kd must be"),
    ("gamma_s", 0.0, r"gamma_s must be a finite angle > 0 degrees; got 0.0"),
    ("gamma_v", -3, "gamma_v must be a finite angle > 0 degrees"),
    ("area", -0.1, "area must be"),
    ("albedo", (0.1, -0.2, 0.3), "albedo must be one or three finite numbers >= 0"),
    ("albedo", (0.1, 0.2), "albedo must be one or three"),
    ("offsets", (-25, 95), r"offsets must lie in \[-90, 90\] degrees; got 95.0"),
    ("lengths", (-1,), "lengths must be finite and >= 0"),
    ("lengths", (0,), "lengths must sum to more than 0"),
    ("offsets", (-25, 0, 25), "offsets must have exactly one more entry than lengths"),
    ("eta", "glass", "eta must be a real number; got 'glass'"),
])
def test_bad_thread_parameters(field, value, match):
    with pytest.raises(ValueError, match=match):
        Thread(**dict(GOOD, **{field: value}))


def test_bad_fabric_input():
    t = Thread(**GOOD)
    with pytest.raises(ValueError, match=r"areas must sum to at most 1; got 0.6 \+ 0.6"):
        Fabric((t.replace(area=0.6), t.replace(area=0.6)))
    with pytest.raises(ValueError, match="threads must be two brdf.Thread"):
        Fabric((t,))
    for opt, val, match in [
        ("transmission", "fresnel", "transmission must be one of 'half_angle', 'longitudinal'"),
        ("gap", "none", "gap must be one of 'incident', 'outgoing'"),
        ("tangent_sampling", "random", "tangent_sampling must be one of"),
        ("tangent_samples", 0, "tangent_samples must be an integer in 1..4096; got 0"),
        ("tangent_samples", 2.5, "tangent_samples must be an integer"),
        ("masking", "maybe", "masking must be True or False"),
        ("rotation", float("inf"), "rotation must be a finite angle in radians"),
        ("colour", 1, "unknown option\\(s\\) 'colour'; valid options are masking"),
    ]:
        with pytest.raises(ValueError, match=match):
            brdf.fabric("linen_plain", **{opt: val})


def test_bad_directions():
    fab = brdf.fabric("linen_plain")
    with pytest.raises(ValueError, match=r"wi must have shape \(\.\.\., 3\).*got shape \(4, 2\)"):
        fab.eval(np.ones((4, 2)), np.ones((4, 3)))
    with pytest.raises(ValueError, match=r"wi and wo must broadcast; got shapes \(4, 3\) and \(5, 3\)"):
        fab.eval(np.ones((4, 3)), np.ones((5, 3)))
    with pytest.raises(ValueError, match="wo must"):
        fab.eval(np.ones(3), 1.0)


@pytest.mark.parametrize("options", [{}, {"masking": False}, {"reweighting": False},
                                     {"masking": False, "reweighting": False}])
def test_grazing_pairs_finite_without_warnings(options):
    """Near the horizon, incl. opposite grazing pairs where cos^2(theta_d) rounds to 0."""
    z = np.array([6e-17, 1e-12, 1e-6])
    phi = np.radians(np.arange(0, 360, 7.5))
    P, Z = np.meshgrid(phi, z)
    r = np.sqrt(1 - Z**2)
    w = np.stack([r * np.cos(P), r * np.sin(P), Z], -1).reshape(-1, 3)
    wi, wo = w[:, None, :], w[None, :, :]
    opposite = w * [-1, -1, 1]
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, **options)
        with np.errstate(divide="raise", invalid="raise", over="raise", under="ignore"):
            f = fab.eval(wi, wo)
            g = fab.eval(w, opposite)
        assert np.all(np.isfinite(f)) and np.all(f >= 0)
        assert np.all(np.isfinite(g)) and np.all(g >= 0)


# -- grazing incidence: n . wi far below sqrt(float64's smallest normal) ------------------------
GRAZING = [(1.0, 0.0), (0.0, 1.0), (0.6, 0.8), (0.3, -0.95), (-0.8, 0.6)]


@pytest.mark.parametrize("options", [{}, {"reweighting": False}, {"masking": False},
                                     {"rotation": 0.7}, {"gap": "outgoing"}],
                         ids=lambda o: "-".join(f"{k}={v}" for k, v in o.items()) or "default")
@pytest.mark.parametrize("name", brdf.PRESETS)
def test_tiny_normal_component_matches_the_limit(name, options):
    """f_r at n.wi = 1e-200 and 1e-160 is finite and equals MODEL.md's value. Near the horizon
    f_r = A / (n.wi) + B + O(n.wi): the cosine-weighted f_r (n.wi) = (a_1 S_1 + a_2 S_2) / Q
    has a limit A (S_j carries the thread-frame cos(theta_i), not n.wi), so f_r grows like
    1/(n.wi) where A > 0. A and B come from the spec transliteration at n.wi = 1e-5, 2e-5
    and 3e-5 (a quadratic in n.wi through f_r (n.wi)); closer to the horizon its asin loses
    the digits of cos(theta) of directions along a thread. With wi and wo exchanged f_r tends
    to a finite value."""
    fab = brdf.fabric(name).replace(**options)
    wo = brdf.directions.from_angles(np.radians([30.0, 60.0]), np.array([[2.9], [0.4]]))
    wo = wo.reshape(-1, 3)
    xy = np.array(GRAZING)

    def directions(z):
        w = np.concatenate([xy, np.full((len(xy), 1), z)], axis=1)
        return w / np.linalg.norm(w, axis=1, keepdims=True)

    zs = np.array([1e-5, 2e-5, 3e-5])
    lagrange0 = np.array([3.0, -3.0, 1.0])            # the quadratic through 3 points, at 0
    lagrange1 = np.array([-2.5, 4.0, -1.5]) / zs[0]   # its slope at 0
    idx = np.array(list(itertools.product(range(len(xy)), range(len(wo)))))
    g = np.array([reference_eval(fab, directions(z)[idx[:, 0]], wo[idx[:, 1]]) * z
                  for z in zs])
    big, rest = np.tensordot(lagrange0, g, 1), np.tensordot(lagrange1, g, 1)
    h = np.array([reference_eval(fab, wo[idx[:, 1]], directions(z)[idx[:, 0]]) for z in zs])
    grows = np.abs(big) > 1e-6 * np.abs(g[0])        # else A is rounding noise
    for z in (1e-200, 1e-160):
        got = fab.eval(directions(z)[idx[:, 0]], wo[idx[:, 1]])
        assert np.all(np.isfinite(got))
        np.testing.assert_allclose((got * z)[grows], big[grows], rtol=1e-6)
        np.testing.assert_allclose(got[~grows], rest[~grows], rtol=1e-5, atol=1e-12)
        back = fab.eval(wo[idx[:, 1]], directions(z)[idx[:, 0]])
        np.testing.assert_allclose(back, np.tensordot(lagrange0, h, 1), rtol=1e-6, atol=1e-12)


def test_tiny_components_everywhere_stay_finite():
    """Directions whose components underflow when squared, subnormal ones included, give
    finite f_r from eval, eval_threads and prepare(...).eval, never NaN (wi = wo along a
    thread, along the other in-plane axis, subnormal n . wi)."""
    fab = brdf.fabric("polyester_satin_charmeuse").replace(reweighting=False)
    tiny = [1e-200, 1e-310, 5e-324, 1e-160]
    ws = [np.array(v, float) for z in tiny for v in ([1.0, 0.0, z], [0.0, 1.0, z],
                                                     [z, 0.0, 1.0], [1.0, z, z])]
    wi = np.array([a for a in ws for _ in ws])
    wo = np.array([b for _ in ws for b in ws])
    for f in (fab, brdf.fabric("velvet"), brdf.fabric("linen_plain")):
        for got in (f.eval(wi, wo), f.eval_threads(wi, wo).sum(axis=-2),
                    f.prepare(wi, wo).eval()):
            assert np.all(np.isfinite(got)) and np.all(got >= 0)


@pytest.mark.parametrize("kwargs, words", [
    ({"area": [-1.0, 0.3]}, "area must be a finite number with 0.0 <= area <= 1.0; got -1.0"),
    ({"eta": [np.nan, 1.4]}, "eta must be a finite number with 1.0 < eta; got nan"),
    ({"kd": [[0.3, 0.3], [5.0, 0.1]]}, "kd must be a finite number with 0.0 <= kd <= 1.0; "
                                       "got 5.0 (at index (1, 0))"),
    ({"area": [0.6, 0.6]}, "areas must sum to at most 1"),
    ({"gamma_v": [0.0, 3.0]}, "gamma_v must be a finite angle > 0 degrees"),
    ({"albedo": [[1, 1, -1], [1, 1, 1]]}, "albedo must be one or three finite numbers >= 0"),
    ({"gamma_s": "wide"}, "gamma_s must be a numeric array; got 'wide'"),
])
def test_prepared_eval_refuses_parameters_outside_their_ranges(kwargs, words):
    prep = brdf.fabric("linen_plain").prepare([0.0, 0.0, 1.0], [0.0, 0.6, 0.8])
    with pytest.raises(ValueError, match=re.escape(words)):
        prep.eval(**kwargs)
