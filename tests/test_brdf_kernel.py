"""Each block of brdf.kernel against its twin: the same equation of MODEL.md written from the
angles (atan2, asin) with brdf.terms, as a reader of the spec would write it."""

import numpy as np
import pytest

import brdf
from brdf import kernel, shading, terms

C, S = 400, 5


def wrap(a):
    """Into (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


@pytest.fixture(scope="module")
def case():
    rng = np.random.default_rng(7)

    def hemi(n):
        z = rng.uniform(0.02, 1.0, n)
        p = rng.uniform(-np.pi, np.pi, n)
        r = np.sqrt(1.0 - z * z)
        return np.stack([r * np.cos(p), r * np.sin(p), z], -1)

    wi, wo = hemi(C), hemi(C)
    alpha = np.radians(rng.uniform(-60.0, 60.0, S))
    weight = rng.uniform(0.5, 1.0, S)
    weight /= weight.sum()
    # Thread along +x: t0 = x, b = n x t0 = y, n = z.
    side = (wi[:, 0:1], wi[:, 1:2], wi[:, 2:3], wo[:, 0:1], wo[:, 1:2], wo[:, 2:3])
    # The spec's frame per (pair, sample): t = cos a t0 + sin a n, n_t = cos a n - sin a t0.
    t = np.stack([np.cos(alpha), np.zeros(S), np.sin(alpha)], -1)        # (S, 3)
    nt = np.stack([-np.sin(alpha), np.zeros(S), np.cos(alpha)], -1)
    b = np.array([0.0, 1.0, 0.0])
    ang = {}
    for tag, w in (("i", wi), ("r", wo)):
        wt, wn, wb = w @ t.T, w @ nt.T, (w @ b)[:, None]
        ang["theta" + tag] = np.arcsin(np.clip(wt, -1, 1))
        ang["phi" + tag] = np.arctan2(np.broadcast_to(wb, wn.shape), wn)
        ang["psi" + tag] = np.arctan2(wt, wn)
    ang["theta_h"] = (ang["thetai"] + ang["thetar"]) / 2
    ang["theta_d"] = (ang["thetai"] - ang["thetar"]) / 2
    ang["phi_d"] = wrap(ang["phii"] - ang["phir"])
    ang["psi_d"] = wrap(ang["psii"] - ang["psir"])
    return side, np.cos(alpha), np.sin(alpha), weight, ang


def test_longitudinal(case):
    side, ca, sa, _, ang = case
    sd = kernel.longitudinal(*side, ca, sa)
    np.testing.assert_allclose(sd.si, np.sin(ang["thetai"]), atol=1e-14)
    np.testing.assert_allclose(sd.ci, np.cos(ang["thetai"]), atol=1e-12)
    np.testing.assert_allclose(sd.cr, np.cos(ang["thetar"]), atol=1e-12)


def test_half_difference(case):
    side, ca, sa, _, ang = case
    th2, c2d, _, _ = kernel.half_difference(kernel.longitudinal(*side, ca, sa))
    np.testing.assert_allclose(th2, 4 * ang["theta_h"] ** 2, atol=1e-10)
    np.testing.assert_allclose(c2d, 2 * np.cos(ang["theta_d"]) ** 2, atol=1e-12)


def test_azimuth(case):
    side, ca, sa, _, ang = case
    sd = kernel.longitudinal(*side, ca, sa)
    _, _, cc, _ = kernel.half_difference(sd)
    cphi, _ = kernel.azimuth(sd, side[1], side[4], cc, degenerate=False)
    np.testing.assert_allclose(cphi, np.cos(ang["phi_d"]), atol=1e-12)


def test_masking_is_pair_weight_of_visibility(case):
    side, ca, sa, _, ang = case
    sd = kernel.longitudinal(*side, ca, sa)
    _, _, cc, _ = kernel.half_difference(sd)
    cphi, frame = kernel.azimuth(sd, side[1], side[4], cc, degenerate=False)
    k = np.ones((C, S))
    m = kernel.masking(frame, cphi, k)
    twin = terms.pair_weight(terms.visibility(np.cos(ang["phii"])),
                             terms.visibility(np.cos(ang["phir"])), ang["phi_d"])
    np.testing.assert_allclose(m, twin, atol=1e-12)
    np.testing.assert_allclose(k, twin, atol=1e-12)


def test_reweighting_is_pair_weight_of_visibility(case):
    side, ca, sa, weight, ang = case
    sd = kernel.longitudinal(*side, ca, sa)
    _, _, _, ss = kernel.half_difference(sd)
    k = np.ones((C, S))
    ti, _, zi, to, _, zo = side
    pmean = kernel.reweighting(sd, ti, zi, to, zo, ss, k, weight)
    twin = terms.pair_weight(terms.visibility(np.cos(ang["psii"])),
                             terms.visibility(np.cos(ang["psir"])), ang["psi_d"])
    np.testing.assert_allclose(k, twin, atol=1e-12)
    np.testing.assert_allclose(pmean, twin @ weight, atol=1e-12)


def test_fresnel2_into_is_twice_fresnel():
    c = np.linspace(0.0, 1.0, 101)
    bufs = [np.empty(101) for _ in range(4)]
    f2 = shading.fresnel2_into(1.46**2, c, c * c, *bufs)
    np.testing.assert_allclose(f2, 2 * terms.fresnel(1.46, c), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("transmission", ["half_angle", "longitudinal"])
@pytest.mark.parametrize("gammas", [(7.0, 14.0), (5.0, 19.0)])   # once, and two lobes
def test_surface_and_volume_terms(case, transmission, gammas):
    side, ca, sa, weight, ang = case
    eta, kd = 1.46, 0.3
    gs, gv = np.radians(gammas)
    geom = kernel.thread_geometry(*side, ca, sa, weight, keep_cos=True)
    surf, vol = shading.thread_shade(geom, weight, eta, kd, gs, gv, transmission)
    mp = (terms.pair_weight(terms.visibility(np.cos(ang["phii"])),
                            terms.visibility(np.cos(ang["phir"])), ang["phi_d"])
          * terms.pair_weight(terms.visibility(np.cos(ang["psii"])),
                              terms.visibility(np.cos(ang["psir"])), ang["psi_d"]))
    ci, cr = np.cos(ang["thetai"]), np.cos(ang["thetar"])
    cos2d = np.cos(ang["theta_d"]) ** 2
    cos_g = np.cos(ang["theta_d"]) * np.cos(ang["phi_d"] / 2)
    f_rs = (terms.fresnel(eta, cos_g) * np.cos(ang["phi_d"] / 2)
            * terms.gaussian(gs, ang["theta_h"]))
    f_rv = (terms.transmission(eta, cos_g, ci, cr, transmission)
            * ((1 - kd) * terms.gaussian(gv, ang["theta_h"]) + kd) / (ci + cr))
    np.testing.assert_allclose(surf, (f_rs / cos2d * mp * ci) @ weight, rtol=1e-9)
    np.testing.assert_allclose(vol, (f_rv / cos2d * mp * ci) @ weight, rtol=1e-9)


# -- each of MODEL.md's names (brdf/__init__'s table) against its transliteration ------------

def test_u_of_cos_is_u():
    delta = np.linspace(0.0, np.pi, 97)
    np.testing.assert_allclose(kernel.u_of_cos(np.cos(delta)), terms.u(delta), rtol=1e-12,
                               atol=1e-300)


def test_gaussian_is_g():
    gamma = np.radians([2.5, 12.0, 60.0])[:, None]
    theta_h = np.linspace(-1.5, 1.5, 41)
    out = np.empty((3, 41))
    g = shading.gaussian_into(4 * theta_h**2, shading.gaussian_exponent(gamma), out)
    g *= shading.gaussian_norm(gamma)
    np.testing.assert_allclose(g, terms.gaussian(gamma, theta_h), rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize("transmission", list(brdf.Transmission))
def test_transmission_into_is_f_t(case, transmission):
    side, ca, sa, weight, ang = case
    eta = 1.46
    geom = kernel.thread_geometry(*side, ca, sa, weight, keep_cos=True)
    f2 = shading.fresnel2_into(eta**2, geom.cg, geom.cg2, *(np.empty(geom.cg.shape)
                                                             for _ in range(4)))
    ft, scale = shading.transmission_into(f2, geom, eta**2, transmission)
    cos_g = np.cos(ang["theta_d"]) * np.cos(ang["phi_d"] / 2)
    twin = terms.transmission(eta, cos_g, np.cos(ang["thetai"]), np.cos(ang["thetar"]),
                              transmission.value)
    np.testing.assert_allclose(ft * scale, twin, rtol=1e-12, atol=1e-15)


def test_f_rs_and_f_rv_geometry(case):
    side, ca, sa, weight, ang = case
    k = np.random.default_rng(5).random((C, S))
    ci, cr = np.cos(ang["thetai"]), np.cos(ang["thetar"])
    kv = kernel.f_rv_geometry(ci, cr, k)
    np.testing.assert_allclose(kv, k / (ci + cr), rtol=1e-15)
    ks = kernel.f_rs_geometry(1.0 + np.cos(ang["phi_d"]), k)
    # (1 + cos phi_d loses digits near phi_d = pi, in the twin's argument as in the kernel's)
    np.testing.assert_allclose(ks, k * np.cos(ang["phi_d"] / 2), rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("transmission", list(brdf.Transmission))
def test_f_rv_is_the_volume_term(case, transmission):
    """f_rv's factors, put together as the shading does, give MODEL.md's f_rv / A summed with
    the weights (k = 1: no masking, reweighting or cos^2 theta_d)."""
    side, ca, sa, weight, ang = case
    eta, kd, gv = 1.46, np.array([[0.3], [0.0], [1.0]]), np.radians(24.0)
    ci, cr = np.cos(ang["thetai"]), np.cos(ang["thetar"])
    cos_g = np.cos(ang["theta_d"]) * np.cos(ang["phi_d"] / 2)
    ft_twin = terms.transmission(eta, cos_g, ci, cr, transmission.value)
    f2 = np.broadcast_to(2 * terms.fresnel(eta, cos_g), (3, C, S)).copy()
    geom = kernel.ThreadGeometry(None, None, None, None, None, ci, cr, None)
    ft, scale = shading.transmission_into(f2, geom, eta**2, transmission)
    ft = ft * kernel.f_rv_geometry(ci, cr, np.ones((C, S)))
    ev = shading.gaussian_into(4 * ang["theta_h"] ** 2, shading.gaussian_exponent(gv),
                               np.empty((3, C, S)))
    out = np.empty((3, C))
    shading.f_rv(np.broadcast_to(ft, (3, C, S)).copy(), ev, weight,
                 shading.f_rv_coefficients(kd, gv), kd, scale, out)
    f_rv = ft_twin * ((1 - kd[:, :, None]) * terms.gaussian(gv, ang["theta_h"])
                      + kd[:, :, None]) / (ci + cr)
    np.testing.assert_allclose(out, f_rv @ weight, rtol=1e-11)


@pytest.mark.parametrize("gap", list(brdf.Gap))
def test_q_is_the_normalization(gap):
    """The plan's Q against MODEL.md's equation written from psi (terms.pair_weight of the
    visibilities) for each thread's samples."""
    fab = brdf.fabric("silk_shot", gap=gap)
    rng = np.random.default_rng(11)
    wi = brdf.directions.from_angles(rng.uniform(0.1, 1.4, 50), rng.uniform(-3, 3, 50))
    wo = brdf.directions.from_angles(rng.uniform(0.1, 1.4, 50), rng.uniform(-3, 3, 50))
    geoms = fab.plan.geometry(wi, wo)
    a = [t.area for t in fab.threads]
    q = fab.plan.q([g.pmean for g in geoms], a[0], a[1], wi[:, 2], wo[:, 2])
    want = (1 - a[0] - a[1]) * (wi[:, 2] if gap is brdf.Gap.INCIDENT else wo[:, 2])
    for j, (tp, t0) in enumerate(zip(fab.plan.threads, ([1, 0, 0], [0, 1, 0]))):
        t0 = np.asarray(t0, float)
        t = tp.ca[:, None] * t0 + tp.sa[:, None] * [0, 0, 1]          # (S, 3)
        nt = tp.ca[:, None] * [0, 0, 1] - tp.sa[:, None] * t0
        psi = [np.arctan2(w @ t.T, w @ nt.T) for w in (wi, wo)]
        p = terms.pair_weight(terms.visibility(np.cos(psi[0])), terms.visibility(np.cos(psi[1])),
                              wrap(psi[0] - psi[1]))
        want = want + a[j] * (p @ tp.weight)
    np.testing.assert_allclose(q, want, rtol=1e-12)
    assert fab.replace(reweighting=False).plan.q([None, None], *a, wi[:, 2], wo[:, 2]) == 1.0
