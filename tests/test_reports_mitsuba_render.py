"""Tests of reports.mitsuba.render: the Mitsuba engine agrees with the built-in renderer.

Both renderers estimate the same integral when Mitsuba's paths stop after the first bounce
(``max_depth=2``): the key light and the sky (the built-in by MIS of Fabric.sample and cosine
directions, Mitsuba by MIS of the envmap's and the BSDF's draws). Their images' mean
luminances then differ by Monte Carlo noise alone, plus the tessellation of the meshes and
float32: the test allows 4 standard errors of the mean of the per-pixel difference (pixels
are independent; the scene's structure cancels in the difference, so its spread is noise)
plus 1 % of the mean. The JIT tests run in llvm_ad_rgb and cuda_ad_rgb and skip where the
variant does not run (no usable LLVM, no GPU);
scalar_rgb runs wherever Mitsuba is installed.
"""

import numpy as np
import pytest

import brdf
from reports.mitsuba import render as mitsuba_render
from reports.colour import luminance
from reports.render.engine import cloth_coverage, render
from reports.render.scenes import make_scene
from reports.render.tracing import intersect, occluded

pytestmark = pytest.mark.skipif(not mitsuba_render.have_mitsuba(),
                                reason="mitsuba is not installed")

W, H, SPP = 64, 36, 4


@pytest.fixture(scope="module", params=["llvm_ad_rgb", "cuda_ad_rgb"])
def jit(request):
    """A JIT variant that runs here (llvm_ad_rgb: a usable LLVM; cuda_ad_rgb: a GPU)."""
    ok, why = mitsuba_render.variant_works(request.param)
    if not ok:
        need = ("install libllvm19 and set DRJIT_LIBLLVM_PATH to its libLLVM-19.so"
                if request.param == "llvm_ad_rgb" else "it needs an NVIDIA GPU")
        pytest.skip(f"{request.param} does not run here ({why}): {need}")
    return request.param


def shadow_mask(scene, width, height):
    """Pixels whose camera ray (through the pixel centre) hits a diffuse surface that the key
    light does not see: traced with the built-in renderer's geometry."""
    ys, xs = np.mgrid[0:height, 0:width]
    o, d = scene.camera.rays(xs.ravel() + 0.5, ys.ravel() + 0.5, width, height)
    o = np.ascontiguousarray(o)
    t, pid, part = intersect(scene.primitives, o, d, 1e-6)
    hit = np.isfinite(t)
    diffuse = hit & np.array([scene.primitives[k].material != "cloth" if h else False
                              for k, h in zip(pid, hit)])
    p = o + np.where(hit, t, 0.0)[:, None] * d
    wi, dist, _ = scene.light.sample(p, None)
    mask = np.zeros(len(p), bool)
    k = np.nonzero(diffuse)[0]
    mask[k] = occluded(scene.primitives, p[k] + 1e-4 * wi[k], wi[k], dist[k], 1e-6)
    return mask.reshape(height, width)


def agree(a, b, extra=0.01):
    """|mean(L_a) - mean(L_b)| within 4 standard errors of the mean per-pixel difference plus
    ``extra`` of mean(L_b); returns the relative difference."""
    la, lb = luminance(a), luminance(b)
    diff = la - lb
    se = diff.std(ddof=1) / np.sqrt(diff.size)
    assert abs(diff.mean()) <= 4 * se + extra * lb.mean(), (la.mean(), lb.mean(), se)
    return diff.mean() / lb.mean()


def test_direct_light_agrees_with_the_builtin_renderer(jit):
    fab = brdf.fabric("velvet")
    a = mitsuba_render.render_mitsuba("cylinder", fab, W, H, SPP, max_depth=2, variant=jit,
                                      progress=False)
    b = render("cylinder", fab, W, H, SPP, progress=False, workers=1)
    assert a.shape == (H, W, 3) and a.dtype == np.float32 and np.all(np.isfinite(a))
    agree(a, b)
    shadow = shadow_mask(make_scene("cylinder"), W, H)
    assert shadow.sum() >= 20
    assert luminance(a)[shadow].mean() > 0.5 * luminance(b)[shadow].mean() > 0


def test_scalar_variant_renders_without_llvm():
    """scalar_rgb needs no LLVM: a tiny image, finite and lit."""
    fab = brdf.fabric("velvet", tangent_samples=4)
    img = mitsuba_render.render_mitsuba("cylinder", fab, 16, 9, 1, variant="scalar_rgb",
                                        progress=False)
    assert img.shape == (9, 16, 3) and np.all(np.isfinite(img)) and img.max() > 0


def test_passes_split_large_sample_counts(monkeypatch):
    """More samples than one pass holds are rendered in passes that add up to spp."""
    monkeypatch.setattr(mitsuba_render, "PASS_SAMPLES", 16 * 9 * 2)
    fab = brdf.fabric("velvet", tangent_samples=4)
    img = mitsuba_render.render_mitsuba("sphere", fab, 16, 9, 5, variant="scalar_rgb",
                                        progress=False)
    assert np.all(np.isfinite(img)) and img.max() > 0


@pytest.mark.parametrize("kwargs, match", [
    (dict(width=2000), "width=2000"), (dict(spp=0), "spp=0"), (dict(seed=-1), "seed=-1"),
    (dict(max_depth=0), "max_depth=0"), (dict(variant="gpu_rgb"), "'gpu_rgb' is unknown"),
    (dict(fabric="tweed"), "unknown fabric 'tweed'"), (dict(scene="teapot"), "teapot"),
])
def test_bad_input_is_refused_before_rendering(kwargs, match):
    args = dict(scene="cylinder", fabric="velvet", width=8, height=8, spp=1, progress=False)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        mitsuba_render.render_mitsuba(**args)


def test_an_eval_only_brdf_is_refused():
    class Lambert:
        def eval(self, wi, wo):
            return np.full(np.broadcast_shapes(np.shape(wi), np.shape(wo)), 0.1)

    with pytest.raises(ValueError, match="brdf.Fabric"):
        mitsuba_render.render_mitsuba("cylinder", Lambert(), 8, 8, 1, progress=False)


def test_missing_mitsuba_is_one_clear_error(monkeypatch):
    monkeypatch.setattr(mitsuba_render, "have_mitsuba", lambda: False)
    with pytest.raises(ImportError, match=r"needs mitsuba \(pip install mitsuba\)"):
        mitsuba_render.pick_variant()


def test_floor_noise_falls_when_each_path_samples_both_lights(jit):
    """Mitsuba's path integrator sends each shadow ray to one emitter picked at random: a lit
    floor in one scene of key light and sky flickers between twice the key light and the sky.
    render_mitsuba renders a scene per light and sums them; at equal spp the noise of the lit
    floor (the spread of the difference of two seeds, over a floor patch) is at least 4 times
    lower, and the mean agrees within that noise."""
    import mitsuba as mi
    mi.set_variant(jit)
    from reports.mitsuba import plugin
    from reports.mitsuba import scene as mitsuba_scene
    plugin.register()
    scene, fab, spp = make_scene("cylinder"), brdf.fabric("velvet"), 8
    lit = ~shadow_mask(scene, W, H)
    lit[: int(0.7 * H)] = False                     # the floor below the cylinder, lit
    lit &= cloth_coverage(scene, W, H, metered=False) == 0
    assert lit.sum() > 100
    one = mi.load_dict(mitsuba_scene.scene_dict(scene, fab, W, H, spp, lights="both"))
    old = [np.asarray(mi.render(one, seed=s, spp=spp))[..., :3] for s in (1, 2)]
    new = [mitsuba_render.render_mitsuba(scene, fab, W, H, spp, seed=s, variant=jit,
                                         progress=False) for s in (1, 2)]

    def noise(pair):
        return float(np.std(luminance(pair[0])[lit] - luminance(pair[1])[lit]) / np.sqrt(2))

    assert noise(new) < noise(old) / 4, (noise(new), noise(old))
    diff = luminance(sum(new) / 2)[lit].mean() - luminance(sum(old) / 2)[lit].mean()
    assert abs(diff) < 4 * noise(old) / np.sqrt(lit.sum()) + 0.01 * luminance(old[0])[lit].mean()


def test_a_first_pass_that_compiles_writes_heartbeat_lines_on_a_pipe(monkeypatch):
    """The first pass of a scene compiles the kernel and updates nothing for minutes: on a
    pipe a line still comes every PIPE_INTERVAL (here 0.05 s), saying what runs; the later
    passes write none."""
    import io
    import time as _time

    import gonio.progress as gp
    from reports.mitsuba import render as mr

    out = io.StringIO()
    monkeypatch.setattr(gp.sys, "stderr", out)
    monkeypatch.setattr(gp, "PIPE_INTERVAL", 0.05)

    class FakeMi:
        calls = 0

        def render(self, scene, seed, spp):
            FakeMi.calls += 1
            _time.sleep(0.3 if FakeMi.calls == 1 else 0.0)
            return np.ones((2, 3, 3))

    img = mr._render_passes(FakeMi(), ["scene"], [1, 1, 1], 0, (2, 3), True, desc="demo")
    assert img.shape == (2, 3, 3)
    lines = out.getvalue().splitlines()
    beats = [s for s in lines if "compiles the kernel" in s]
    assert len(beats) >= 3 and all(s.startswith("demo:") for s in beats)
    assert "compiles the kernel" not in lines[-1] and "3/3" in lines[-1]


def test_the_top_row_of_a_cylinder_render_is_not_black(jit):
    """The cylinder's camera sees the floor up to 140 units away in its top row, past the
    100-scale rectangle that stood for the infinite floor: that row was black at 640 x 360
    (all of it; half at 320 x 180). Now it is lit as the rows below it are, as the built-in
    renderer's infinite plane is."""
    lum = luminance(mitsuba_render.render_mitsuba("cylinder", "velvet", 640, 360, 1,
                                                  variant=jit, progress=False))
    assert np.all(lum[0] > 0)
    assert lum[0].mean() > 0.9 * lum[2].mean()
