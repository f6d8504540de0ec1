"""The sky of the built-in renderer: under a uniform sky, a flat patch reflects L times the
integral of f_r cos(theta_i) over the hemisphere, computed here by quadrature; for a fabric
(MIS of its sampler and cosine directions) and for an eval-only Lambertian BRDF."""

import numpy as np
import pytest

import brdf
from reports.render.envlight import EnvironmentLight
from reports.render.engine import render
from reports.render.scenes import DirectionalLight, make_scene

L = 0.7


def hemisphere_integral(fab, wo, n_theta=300, n_phi=600):
    """Midpoint quadrature of f_r(wi, wo) cos(theta_i) over the hemisphere (RGB)."""
    th = (np.arange(n_theta) + 0.5) * (np.pi / 2) / n_theta
    ph = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(th, ph, indexing="ij")
    wi = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    f = fab.eval(wi, np.broadcast_to(wo, wi.shape))
    w = (np.cos(t) * np.sin(t)).ravel() * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)
    return w @ f


def sky_patch(view):
    scene = make_scene("patch", view=view, light=(0.0, 0.0, 1.0), irradiance=0.0)
    return scene.replace(environment=EnvironmentLight(zenith=(L, L, L), horizon=(L, L, L)))


def mean_and_error(img):
    px = img.reshape(-1, 3).astype(np.float64)
    return px.mean(axis=0), px.std(axis=0) / np.sqrt(len(px))


@pytest.mark.parametrize("name", ["silk_crepe_de_chine", "velvet", "linen_plain"])
def test_a_fabric_under_a_uniform_sky(name):
    view = (np.sin(np.radians(40)), 0.0, np.cos(np.radians(40)))
    fab = brdf.fabric(name)
    img = render(sky_patch(view), fab, width=48, height=48, spp=16, progress=False,
                 workers=1)
    got, err = mean_and_error(img)
    want = L * hemisphere_integral(fab, np.array(view))
    assert np.all(np.abs(got - want) <= 4 * err + 2e-3 * want), (got, want, err)


def test_an_eval_only_brdf_uses_cosine_directions():
    class Lambert:
        def eval(self, wi, wo):
            return np.full(np.broadcast_shapes(wi.shape, wo.shape), 0.6 / np.pi)

    img = render(sky_patch((0.0, 0.0, 1.0)), Lambert(), width=16, height=16, spp=4,
                 progress=False, workers=1)
    np.testing.assert_allclose(img, 0.6 * L, rtol=1e-6)   # f pi L: exact for Lambert


def test_the_sky_lights_the_curtains_shadow():
    scene = make_scene("curtain")
    dark = render(scene.replace(environment=None), "velvet", 64, 36, spp=16, progress=False)
    lit = render(scene, "velvet", 64, 36, spp=16, progress=False)
    black = np.all(dark == 0, axis=-1)           # in the key light's shadow (or the sky)
    assert black.mean() > 0.05
    # the grey backdrop (albedo 0.18) under a whole sky of about 0.06 would show 0.18 * 0.06
    # = 0.011; in the curtain's shadow it sees a part of the sky
    assert np.mean(lit[black].sum(axis=-1) > 0) > 0.9 and lit[black].mean() > 0.002


def test_the_sky_blends_horizon_to_zenith():
    env = EnvironmentLight(zenith=(0.0, 0.0, 1.0), horizon=(1.0, 0.0, 0.0))
    w = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, np.sqrt(0.5), np.sqrt(0.5)],
                  [0.0, -1.0, 0.0]])
    np.testing.assert_allclose(env.radiance(w), [[1, 0, 0], [0, 0, 1],
                                                 [1 - np.sqrt(0.5), 0, np.sqrt(0.5)],
                                                 [1, 0, 0]])
