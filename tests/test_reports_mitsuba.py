"""reports.mitsuba.plugin: the Mitsuba 3 BSDF 'microcylinder' against brdf.Fabric (eval in float32,
sample and pdf), Mitsuba's own chi-square test of its sampler, the warp along dp_du, and
``microcyl export`` run as a user runs it.

Tests that need Mitsuba skip when it is not installed; those of the JIT variant skip when no
usable LLVM is found (Dr.Jit needs a shared libLLVM; on Debian LLVM 14 and 15 fail with
"Cannot select fmaximum", libllvm19 works with DRJIT_LIBLLVM_PATH set to its libLLVM-19.so;
.ci/run sets it).
"""

import importlib.util
import json
import math
import os
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import brdf
from reports.mitsuba.plugin import fabric_from_dict, plugin_dict

REPO = Path(__file__).resolve().parents[1]
HAVE_MITSUBA = importlib.util.find_spec("mitsuba") is not None
needs_mitsuba = pytest.mark.skipif(not HAVE_MITSUBA, reason="mitsuba is not installed "
                                   "(pip install mitsuba; it is in pyproject's dependencies)")

#: Variants by the plugin's keys (rotation in degrees).
VARIANTS = [{}, {"masking": False}, {"reweighting": False},
            {"tangent_sampling": "control_points"}, {"tangent_samples": 5},
            {"transmission": "longitudinal"}, {"gap": "outgoing"}, {"rotation": 40.0},
            {"masking": False, "reweighting": False}]
#: Tolerance of eval against Fabric.eval: relative to the pair's largest channel.
RTOL = 1e-5


def _id(v):
    return "-".join(f"{k}={x}" for k, x in v.items()) or "default"


def _hemi(rng, n):
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2])
    return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)


def _reference(name, variant, light, view):
    """f_r cos(theta_i) of brdf.Fabric in float64 at the float32 directions."""
    fab = brdf.fabric(name, **{k: (math.radians(v) if k == "rotation" else v)
                               for k, v in variant.items()})
    light, view = light.astype(np.float64), view.astype(np.float64)
    return fab.eval(light, view) * light[:, 2:3]


def _worst(out, ref):
    """Largest |out - ref| relative to the pair's largest channel (inf where ref is 0 and out
    is not)."""
    err, scale = np.abs(out - ref), ref.max(axis=1, keepdims=True)
    rel = np.divide(err, scale, out=np.where(err > 0, np.inf, 0.0), where=scale > 0)
    return float(rel.max())


# -- without Mitsuba ---------------------------------------------------------------------
@pytest.mark.parametrize("name", brdf.PRESETS)
def test_plugin_dict_round_trip(name):
    fab = brdf.fabric(name, masking=False, tangent_samples=7, rotation=0.3, gap="outgoing")
    d = json.loads(json.dumps(plugin_dict(fab)))
    back = fabric_from_dict(d)
    assert back.threads == fab.threads
    assert back.options == pytest.approx(fab.options)
    assert d["rotation"] == pytest.approx(math.degrees(0.3))


def test_fabric_from_dict_keys_and_errors():
    fab = fabric_from_dict({"type": "microcylinder", "fabric": "velvet", "albedo2": 0.4,
                            "offsets1": "-80, -40", "kd2": 0.25})
    assert fab.threads[1].albedo == (0.4, 0.4, 0.4) and fab.threads[1].kd == 0.25
    assert fab.threads[0].offsets == (-80.0, -40.0) and fab.threads[0].eta == 1.46
    with pytest.raises(ValueError, match="unknown microcylinder parameter.*'eta3'"):
        fabric_from_dict({"fabric": "velvet", "eta3": 1.5})
    with pytest.raises(ValueError, match="unknown fabric 'denim'"):
        fabric_from_dict({"fabric": "denim"})
    with pytest.raises(ValueError, match="offsets1 must be numbers"):
        fabric_from_dict({"offsets1": "a, b"})


# -- scalar_rgb --------------------------------------------------------------------------
@pytest.fixture
def scalar():
    mi = pytest.importorskip("mitsuba", reason="mitsuba is not installed")
    mi.set_variant("scalar_rgb")
    from reports.mitsuba import plugin
    plugin.register()
    return mi


def _scalar_eval(mi, bsdf, light, view, dp_du=None):
    ctx = mi.BSDFContext()
    out = np.empty((light.shape[0], 3))
    for k, (l, v) in enumerate(zip(light, view)):
        si = mi.SurfaceInteraction3f()
        si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
        if dp_du is not None:
            si.dp_du = mi.Vector3f(*dp_du)
        si.wi = mi.Vector3f(*map(float, v))
        out[k] = np.array(bsdf.eval(ctx, si, mi.Vector3f(*map(float, l))))
    return out


CASES = [(p, v) for p in brdf.PRESETS for v in VARIANTS]


@needs_mitsuba
@pytest.mark.parametrize("name,variant", CASES, ids=[f"{p}-{_id(v)}" for p, v in CASES])
def test_scalar_eval_matches_fabric(scalar, name, variant):
    mi = scalar
    rng = np.random.default_rng(zlib.crc32(f"{name}{variant}".encode()))
    n = 200 if not variant else 60
    light, view = _hemi(rng, n), _hemi(rng, n)
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": name, **variant})
    out = _scalar_eval(mi, bsdf, light, view)
    ref = _reference(name, variant, light, view)
    assert _worst(out, ref) < RTOL


@needs_mitsuba
def test_warp_follows_dp_du(scalar):
    """dp_du along local +y turns the warp by 90 degrees; below the horizon eval is 0."""
    mi = scalar
    rng = np.random.default_rng(5)
    light, view = _hemi(rng, 40), _hemi(rng, 40)
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": "silk_shot", "rotation": 10.0})
    out = _scalar_eval(mi, bsdf, light, view, dp_du=(0.0, 2.0, 0.3))
    ref = _reference("silk_shot", {"rotation": 100.0}, light, view)
    assert _worst(out, ref) < RTOL
    below = light * np.array([1, 1, -1], dtype=np.float32)
    assert np.all(_scalar_eval(mi, bsdf, below, view) == 0)


@needs_mitsuba
@pytest.mark.parametrize("name", brdf.PRESETS)
def test_scalar_sample_weight_and_pdf(scalar, name):
    """sample's weight is f_r cos / pdf, its pdf brdf.sampling.pdf where f_r cos > 0 and 0
    elsewhere (below the horizon; where the model's f_r vanishes above it)."""
    mi = scalar
    fab = brdf.fabric(name)
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": name})
    ctx = mi.BSDFContext()
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    view = _hemi(rng, 1)[0]
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(*map(float, view))
    got = []
    for u in rng.random((150, 3)):
        bs, w = bsdf.sample(ctx, si, float(u[0]), mi.Point2f(float(u[1]), float(u[2])))
        got.append((np.array(bs.wo), bs.pdf, np.array(w), bsdf.pdf(ctx, si, bs.wo)))
    wo = np.array([g[0] for g in got], dtype=np.float64)
    f = fab.eval(wo, view.astype(np.float64)) * np.maximum(wo[:, 2:3], 0.0)
    up = f.max(axis=1) > 0
    assert np.all(wo[:, 2] > 0)     # the lobes are truncated to the upper hemisphere
    assert up.mean() > 0.9          # (velvet lost over half of its draws below it before)
    pdf_ref = fab.pdf(view.astype(np.float64), wo)
    np.testing.assert_allclose([g[1] for g in got], np.where(up, pdf_ref, 0.0), rtol=1e-5)
    np.testing.assert_allclose([g[3] for g in got], np.where(up, pdf_ref, 0.0), rtol=1e-5)
    w_ref = np.where(up[:, None], f / pdf_ref[:, None], 0.0)
    np.testing.assert_allclose([g[2] for g in got], w_ref, rtol=1e-4, atol=1e-9)


@needs_mitsuba
def test_horizon_twin_matches_brdf_horizon(scalar):
    """brdf.jit.horizon against brdf.horizon (scipy's log_ndtr and ndtri_exp), in
    scalar_rgb's doubles: log Phi to 3e-7 relative out to 40 standard deviations, its
    inverse, the truncated normal's draws and mass, the azimuth window."""
    from scipy.special import log_ndtr
    from brdf.jit import horizon as twin
    for z in (-40.0, -12.0, -7.5, -3.0, -0.5, 0.0, 0.7, 4.0):
        assert twin.log_ndtr(z) == pytest.approx(float(log_ndtr(z)), rel=3e-7, abs=1e-9)
        assert twin.ndtri_exp(float(log_ndtr(z))) == pytest.approx(z, abs=2e-5)
    rng = np.random.default_rng(8)
    for _ in range(200):
        mu, sig = rng.uniform(-1.6, 1.6), rng.uniform(0.02, 0.6)
        alpha = rng.uniform(-math.pi / 2, math.pi / 2)
        lo, hi = brdf.horizon.theta_range(math.cos(alpha), math.sin(alpha))
        lo2, hi2 = twin.theta_range(math.cos(alpha), math.sin(alpha))
        assert (lo2, hi2) == pytest.approx((float(lo), float(hi)), abs=1e-15)
        want = float(brdf.horizon.truncnorm_logmass(mu, sig, lo, hi))
        assert twin.truncnorm_logmass(mu, 1.0 / sig, lo2, hi2) == pytest.approx(
            want, rel=1e-6, abs=1e-6)
        z = (rng.uniform(float(lo), float(hi)) - mu) / sig
        assert twin.truncnorm_density(z, (lo2 - mu) / sig, (hi2 - mu) / sig) == pytest.approx(
            math.exp(-0.5 * z * z - want), rel=1e-6)
        v = rng.random()
        assert twin.truncnorm_draw(mu, sig, lo2, hi2, v) == pytest.approx(
            float(brdf.horizon.truncnorm_draw(mu, sig, lo, hi, v)), abs=1e-5)
        th = rng.uniform(float(lo), float(hi))
        for masking in (True, False):
            got = twin.azimuth_window(math.sin(th), math.cos(th), math.cos(alpha),
                                      math.sin(alpha), masking)
            ref = brdf.horizon.azimuth_window(math.sin(th), math.cos(th), math.cos(alpha),
                                              math.sin(alpha), masking)
            assert got == pytest.approx(tuple(map(float, ref)), abs=1e-12)


@needs_mitsuba
def test_register_needs_an_rgb_variant():
    import mitsuba as mi
    from reports.mitsuba import plugin
    mi.set_variant("scalar_spectral")
    try:
        with pytest.raises(ValueError, match="needs an RGB variant"):
            plugin.register()
    finally:
        mi.set_variant("scalar_rgb")


# -- the JIT variants: llvm_ad_rgb, and cuda_ad_rgb where a GPU is -------------------------
#: Why a JIT variant cannot run, by variant: what to install.
JIT_NEEDS = {"llvm_ad_rgb": "install libllvm19 and set DRJIT_LIBLLVM_PATH to its libLLVM-19.so "
                            "(LLVM 14 and 15 fail)",
             "cuda_ad_rgb": "it needs an NVIDIA GPU and its driver"}


@pytest.fixture(scope="module", params=list(JIT_NEEDS))
def jit(request):
    """mitsuba in a JIT variant (llvm_ad_rgb, cuda_ad_rgb), after reports.mitsuba.render's
    probe in a subprocess (an unusable LLVM aborts the process that tries it); skips with the
    probe's reason where the variant does not run."""
    if not HAVE_MITSUBA:
        pytest.skip("mitsuba is not installed")
    from reports.mitsuba.render import variant_works
    ok, why = variant_works(request.param)
    if not ok:
        pytest.skip(f"{request.param} does not run here ({why}): {JIT_NEEDS[request.param]}")
    import mitsuba as mi
    mi.set_variant(request.param)
    from reports.mitsuba import plugin
    plugin.register()
    yield mi
    mi.set_variant("scalar_rgb")


#: Every preset under every variant: one kernel serves every fabric of a variant
#: (test_one_kernel_serves_every_fabric), so this costs one compilation per variant.
JIT_CASES = CASES


@needs_mitsuba
@pytest.mark.parametrize("name,variant", JIT_CASES,
                         ids=[f"{p}-{_id(v)}" for p, v in JIT_CASES])
def test_jit_eval_matches_fabric_float32(jit, name, variant):
    mi, dr = jit, pytest.importorskip("drjit")
    rng = np.random.default_rng(zlib.crc32(f"llvm{name}{variant}".encode()))
    n = 10_000
    light, view = _hemi(rng, n), _hemi(rng, n)
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": name, **variant})
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(view[:, 0], view[:, 1], view[:, 2])
    out = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(light[:, 0], light[:, 1], light[:, 2]))
    out = np.asarray(out.numpy(), dtype=np.float64).T
    assert dr.is_jit_v(mi.Float) and dr.type_v(mi.Float) == dr.VarType.Float32
    assert _worst(out, _reference(name, variant, light, view)) < RTOL


def _jit(mi, dr, *columns):
    """Float arrays that Dr.Jit allocated (numpy's memory, mapped, can be unaligned, and the
    kernel's loads say so)."""
    out = [mi.Float(np.ascontiguousarray(c, dtype=np.float32)) + 0.0 for c in columns]
    dr.eval(*out)
    return out


def _kernel_hashes(mi, dr, props, light, view, u):
    """Hashes of the JIT kernels that eval, pdf and sample of the plugin ``props`` (a dict,
    or a loaded BSDF) launch."""
    bsdf = mi.load_dict({"type": "microcylinder", **props}) if isinstance(props, dict) else props
    si = dr.zeros(mi.SurfaceInteraction3f, dr.width(view))
    si.wi = view
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.dp_du = mi.Vector3f(1.0, 0.2, 0.0)
    ctx = mi.BSDFContext()
    dr.kernel_history()                                  # clears it
    f, p = bsdf.eval_pdf(ctx, si, light)
    bs, w = bsdf.sample(ctx, si, u[0], mi.Point2f(u[1], u[2]))
    dr.eval(f, p, bs.wo, bs.pdf, w)
    return [e["hash"] for e in dr.kernel_history() if e["type"] == dr.KernelType.JIT]


@needs_mitsuba
def test_one_kernel_serves_every_fabric(jit):
    """The fabric's numbers are kernel parameters, not code: every preset, and a fitted-like
    fabric of other tangent offsets, launch the same kernels; another option does not."""
    mi, dr = jit, pytest.importorskip("drjit")
    rng = np.random.default_rng(11)
    light, view = (mi.Vector3f(*_jit(mi, dr, *_hemi(rng, 512).T)) for _ in range(2))
    args = (light, view, _jit(mi, dr, *rng.random((3, 512))))
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        seen = {name: _kernel_hashes(mi, dr, {"fabric": name}, *args) for name in brdf.PRESETS}
        other = _kernel_hashes(mi, dr, {"fabric": "velvet", "offsets1": "-30, 10, 45",
                                        "lengths1": "1, 0.5", "eta2": 1.6, "gamma_s1": 9.0},
                               *args)
        unmasked = _kernel_hashes(mi, dr, {"fabric": "velvet", "masking": False}, *args)
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    first = seen["linen_plain"]
    assert first and all(h == first for h in seen.values()), seen
    assert other == first
    assert unmasked != first


def _edited(name, **changes):
    """brdf.fabric(name) with thread values changed ({key}{j}, as the plugin names them) and
    a rotation in degrees: what an edit through mi.traverse should give."""
    fab = brdf.fabric(name, rotation=math.radians(changes.pop("rotation", 0.0)))
    threads = [t.replace(**{k[:-1]: v for k, v in changes.items() if k.endswith(str(j))})
               for j, t in enumerate(fab.threads, start=1)]
    return fab.replace(threads=threads)


TRAVERSED = sorted(f"{k}{j}" for j in (1, 2)
                   for k in ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area")) + ["rotation"]


@needs_mitsuba
def test_traverse_edits_the_fabric(scalar):
    """mi.traverse exposes every thread's numbers and the rotation; an edit, once updated,
    gives the fabric with those values (Mitsuba holds them as float32); an out-of-range one
    is refused with the thread named and changes nothing."""
    mi = scalar
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": "silk_shot"})
    params = mi.traverse(bsdf)
    assert sorted(params.keys()) == TRAVERSED
    params["eta1"] = 1.7
    params["albedo2"] = mi.Color3f(0.1, 0.2, 0.3)
    params["gamma_s2"] = 9.0
    params["rotation"] = 30.0
    params.update()
    f32 = lambda x: float(np.float32(x))  # noqa: E731
    want = _edited("silk_shot", eta1=f32(1.7), albedo2=tuple(map(f32, (0.1, 0.2, 0.3))),
                   gamma_s2=9.0, rotation=30.0)
    rng = np.random.default_rng(21)
    light, view = _hemi(rng, 60), _hemi(rng, 60)
    got = _scalar_eval(mi, bsdf, light, view)
    ref = want.eval(light.astype(float), view.astype(float)) * light[:, 2:3]
    assert _worst(got, ref) < RTOL
    assert _worst(got, _reference("silk_shot", {}, light, view)) > 1e-2     # it did change
    params["kd1"] = 1.5
    with pytest.raises(ValueError, match="thread 1: kd"):
        params.update()
    assert float(np.ravel(params["kd1"])[0]) == f32(want.threads[0].kd)     # put back
    np.testing.assert_array_equal(_scalar_eval(mi, bsdf, light, view), got)


@needs_mitsuba
def test_traverse_edit_reuses_the_kernel(jit):
    """In a JIT variant an edit changes the kernel's parameters, not its code: the same
    kernels run, and they compute the edited fabric (float32, 1e-5)."""
    mi, dr = jit, pytest.importorskip("drjit")
    rng = np.random.default_rng(12)
    light_np, view_np = _hemi(rng, 2000), _hemi(rng, 2000)
    light, view = (mi.Vector3f(*_jit(mi, dr, *x.T)) for x in (light_np, view_np))
    args = (light, view, _jit(mi, dr, *rng.random((3, 2000))))
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": "velvet"})
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        before = _kernel_hashes(mi, dr, bsdf, *args)
        params = mi.traverse(bsdf)
        params["kd2"] = 0.6
        params["gamma_v1"] = 20.0
        params["area1"] = 0.4
        params.update()
        after = _kernel_hashes(mi, dr, bsdf, *args)
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    assert before and after == before
    si = dr.zeros(mi.SurfaceInteraction3f, 2000)
    si.wi = view
    out = np.asarray(bsdf.eval(mi.BSDFContext(), si, light).numpy(), dtype=np.float64).T
    want = _edited("velvet", kd2=float(np.float32(0.6)), gamma_v1=20.0,
                   area1=float(np.float32(0.4)))
    ref = want.eval(light_np.astype(float), view_np.astype(float)) * light_np[:, 2:3]
    assert _worst(out, ref) < RTOL


@needs_mitsuba
def test_albedo_texture_varies_over_the_surface(jit):
    """albedo1 given as a Mitsuba texture (a checkerboard of two RGB values): eval at each hit
    is brdf.Fabric's with thread 1's albedo the texture's value there (Mitsuba's own
    checkerboard, evaluated apart); a texture for another key is refused by name."""
    mi, dr = jit, pytest.importorskip("drjit")
    a, b = (0.1, 0.4, 0.2), (0.6, 0.1, 0.05)
    checker = {"type": "checkerboard", "color0": {"type": "rgb", "value": list(a)},
               "color1": {"type": "rgb", "value": list(b)}}
    bsdf = mi.load_dict({"type": "microcylinder", "fabric": "linen_plain", "albedo1": checker})
    rng = np.random.default_rng(31)
    n = 4000
    light, view, uv = _hemi(rng, n), _hemi(rng, n), rng.random((n, 2)).astype(np.float32)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(*view.T)
    si.uv = mi.Point2f(*uv.T)
    out = np.asarray(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(*light.T)).numpy(),
                     dtype=np.float64).T
    tex = np.asarray(mi.load_dict(checker).eval(si).numpy()).T          # (n, 3)
    first = np.all(np.isclose(tex, np.float32(a)), axis=1)
    assert 0.3 < first.mean() < 0.7 and np.all(first | np.all(np.isclose(tex, b), axis=1))
    ref = np.empty_like(out)
    for mask, rgb in ((first, a), (~first, b)):
        t1, t2 = brdf.fabric("linen_plain").threads
        fab = brdf.fabric("linen_plain").replace(
            threads=[t1.replace(albedo=tuple(float(np.float32(x)) for x in rgb)), t2])
        li, vi = light[mask].astype(float), view[mask].astype(float)
        ref[mask] = fab.eval(li, vi) * li[:, 2:3]
    assert _worst(out, ref) < RTOL
    image = np.asarray(mi.render(_two_cloths(mi, {"fabric": "linen_plain"},
                                             {"fabric": "linen_plain", "albedo1": checker})))
    assert np.isfinite(image).all() and image[:, 32:].std() > 0     # it renders, and varies
    with pytest.raises(RuntimeError, match="'eta1' cannot be a texture"):
        mi.load_dict({"type": "microcylinder", "eta1": checker})


def _two_cloths(mi, left, right):
    """A scene of two rectangles side by side, with the plugin dictionaries left and right."""
    T = mi.ScalarTransform4f()
    return mi.load_dict({
        "type": "scene", "integrator": {"type": "path", "max_depth": 4},
        "sensor": {"type": "perspective", "fov": 60,
                   "to_world": T.look_at(origin=[0, -2.5, 2], target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 64, "height": 32},
                   "sampler": {"type": "independent", "sample_count": 8}},
        "a": {"type": "rectangle", "to_world": T.translate([-1.1, 0, 0]),
              "bsdf": {"type": "microcylinder", **left}},
        "b": {"type": "rectangle", "to_world": T.translate([1.1, 0, 0]),
              "bsdf": {"type": "microcylinder", **right}},
        "lamp": {"type": "point", "position": [0, -1, 3],
                 "intensity": {"type": "rgb", "value": [20, 20, 20]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.2, 0.2, 0.2]}}})


@needs_mitsuba
def test_two_fabrics_in_one_scene_keep_their_own_numbers(jit):
    """Two instances of the plugin share one kernel but not their numbers: each half of a
    scene with velvet on the left and linen on the right is the half of the scene with that
    fabric on both sides (same seed, same paths)."""
    mi = jit
    velvet, linen = {"fabric": "velvet"}, {"fabric": "linen_plain"}
    both = np.asarray(mi.render(_two_cloths(mi, velvet, linen), seed=3))
    left = np.asarray(mi.render(_two_cloths(mi, velvet, velvet), seed=3))
    right = np.asarray(mi.render(_two_cloths(mi, linen, linen), seed=3))
    assert both[:, :32].mean() > 0 and both[:, 32:].mean() > 1.5 * both[:, :32].mean()
    np.testing.assert_allclose(both[:, :32], left[:, :32], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(both[:, 32:], right[:, 32:], rtol=1e-5, atol=1e-7)


CHI2_CASES = [(p, th) for p in brdf.PRESETS for th in (30.0, 75.0)]


@needs_mitsuba
@pytest.mark.slow
@pytest.mark.parametrize("name,theta", CHI2_CASES, ids=[f"{p}-{t:g}" for p, t in CHI2_CASES])
def test_mitsuba_chi2(jit, name, theta, tmp_path, monkeypatch):
    """Mitsuba's own chi-square test of sample against pdf through BSDFAdapter. The pdf
    grows like 1/cos(theta) toward each tangent sample (brdf.sampling), so the cells are
    integrated with ires=16 (the default 4 overestimates them by ~1%)."""
    mi = jit
    monkeypatch.chdir(tmp_path)                 # a failed test writes chi2_data.py here
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain
    t = math.radians(theta)
    dr = pytest.importorskip("drjit")
    # opaque: one kernel for both incidences (a literal viewer would compile one each)
    wi = dr.opaque(mi.Vector3f, [math.sin(t) * math.cos(0.4), math.sin(t) * math.sin(0.4),
                                 math.cos(t)])
    sample, pdf = BSDFAdapter("microcylinder", {"type": "microcylinder", "fabric": name},
                              wi=wi)
    test = ChiSquareTest(SphericalDomain(), sample, pdf, sample_dim=3, sample_count=200_000,
                         res=51, ires=16, seed=zlib.crc32(name.encode()) % 1000)
    assert test.run(0.01, test_count=len(CHI2_CASES), quiet=True), test.messages


# -- microcyl export ----------------------------------------------------------------------
def _export(folder, target):
    """`microcyl export FOLDER -o TARGET` run as a user runs it, in TARGET's folder."""
    return subprocess.run([sys.executable, "-m", "reports", "export", str(folder), "-o",
                           str(target)], cwd=target.parent, capture_output=True, text=True,
                          timeout=120, env=dict(os.environ, PYTHONPATH=str(REPO)))


def test_export_cli_writes_the_medians(fit_folder, tmp_path):
    out, res = fit_folder
    target = tmp_path / "fabric.json"
    p = _export(out, target)
    assert p.returncode == 0, p.stderr
    assert f"wrote {target}" in p.stderr and "velvet: medians of gamma_s1, kd1" in p.stdout
    doc = json.loads(target.read_text())
    assert doc["type"] == "microcylinder" and doc["fabric"] == "velvet"
    assert doc["gamma_s1"] == pytest.approx(res.summary["gamma_s1"]["median"])
    assert doc["kd1"] == doc["kd2"] == pytest.approx(res.summary["kd1"]["median"])
    assert doc["gamma_v1"] == 12.0 and doc["masking"] is False
    assert doc["rotation"] == pytest.approx(math.degrees(0.25))
    assert [f.name for f in tmp_path.iterdir() if f.name.startswith(".")] == []
    bad = _export(tmp_path, target)
    assert bad.returncode == 1 and "results.json" in bad.stderr
    assert "Traceback" not in bad.stderr


def test_export_dict_loads_in_mitsuba(fit_folder, scalar):
    mi = scalar
    out, _ = fit_folder
    from analysis.fit import median_fabric
    med = median_fabric(out)
    bsdf = mi.load_dict(json.loads(json.dumps(plugin_dict(med.fabric))))
    rng = np.random.default_rng(9)
    light, view = _hemi(rng, 20), _hemi(rng, 20)
    got = _scalar_eval(mi, bsdf, light, view)
    ref = med.fabric.eval(light.astype(float), view.astype(float)) * light[:, 2:3]
    assert _worst(got, ref) < RTOL


@needs_mitsuba
def test_export_xml_loads_in_a_scene_file(fit_folder, scalar, tmp_path):
    """`microcyl export FIT -o fabric.xml` writes a <bsdf> element that a Mitsuba scene file
    takes as it is (pasted in, referred to by id) and that evaluates the median fabric."""
    mi = scalar
    out, _ = fit_folder
    target = tmp_path / "fabric.xml"
    p = _export(out, target)
    assert p.returncode == 0, p.stderr
    element = target.read_text()
    assert element.startswith('<bsdf type="microcylinder" id="fabric">')
    scene = mi.load_string('<scene version="3.0.0">\n' + element
                           + '<shape type="rectangle"><ref id="fabric"/></shape>\n</scene>')
    bsdf = scene.shapes()[0].bsdf()
    from analysis.fit import median_fabric
    med = median_fabric(out)
    rng = np.random.default_rng(19)
    light, view = _hemi(rng, 30), _hemi(rng, 30)
    got = _scalar_eval(mi, bsdf, light, view)
    ref = med.fabric.eval(light.astype(float), view.astype(float)) * light[:, 2:3]
    assert _worst(got, ref) < RTOL
    assert not med.fabric.options["masking"]        # the fit's variant came through


@needs_mitsuba
def test_kernel_on_its_consts_matches_fabric_without_the_plugin(scalar):
    """brdf.jit.sampler.eval_cos on brdf.jit.consts.consts in the variant's types, called directly (no
    BSDF object): f_r cos(theta_i) of brdf.Fabric in float64 at random pairs; the constants
    carry the fabric's options and gap area, the sampler's cdf ends at 1; and
    reports.mitsuba.bsdf.bsdf_class() is one mi.BSDF subclass per variant."""
    mi = scalar
    from brdf.jit import consts as mconsts, sampler as mkernel
    from reports.mitsuba import bsdf as mbsdf
    fab = brdf.fabric("silk_shot", masking=False, gap="outgoing")
    k = mconsts.consts(fab.plan, mbsdf.variant_types(), brdf.sampling.lobe_probabilities(fab))
    assert k.masking is False and k.reweighting is True and str(k.gap) == "outgoing"
    assert k.gap_area == pytest.approx(1 - fab.threads[0].area - fab.threads[1].area)
    assert k.comp_cdf[-1] == 1.0 and len(k.comp_cdf) == k.comp_size
    rng = np.random.default_rng(7)
    light, view = _hemi(rng, 40), _hemi(rng, 40)
    out = np.array([mkernel.eval_cos(k, mi.Vector3f(*map(float, l)), mi.Vector3f(*map(float, v)),
                                     1.0, 0.0) for l, v in zip(light, view)], dtype=np.float64)
    ref = fab.eval(light.astype(np.float64), view.astype(np.float64)) * light[:, 2:3]
    assert _worst(out, ref) < RTOL
    cls = mbsdf.bsdf_class()
    assert cls is mbsdf.bsdf_class() and issubclass(cls, mi.BSDF)
