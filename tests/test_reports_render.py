"""Tests of reports.render.engine, reports.render.scenes and reports.render.imageio (tiny images, fast)."""

import numpy as np
import pytest
from PIL import Image

from reports.render import imageio
from reports.render.engine import render
from reports.render.scenes import (Curtain, Cylinder, DirectionalLight, OrthographicCamera,
                            PointLight, Rectangle, Scene, Sphere, make_scene)


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


class Aniso:
    """An analytic anisotropic BRDF (Ward + coloured diffuse); different in x and y."""

    def __init__(self, ax=0.15, ay=0.45, kd=(0.3, 0.05, 0.1), ks=0.4):
        self.ax, self.ay, self.kd, self.ks = ax, ay, np.array(kd), ks

    def eval(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        ci, co = wi[..., 2], wo[..., 2]
        ok = (ci > 0) & (co > 0)
        with np.errstate(all="ignore"):
            e = -((h[..., 0] / self.ax) ** 2 + (h[..., 1] / self.ay) ** 2) / h[..., 2] ** 2
            s = self.ks * np.exp(e) / (4 * np.pi * self.ax * self.ay * np.sqrt(ci * co))
        s = np.where(ok, s, 0.0)
        return np.where(ok[..., None], self.kd / np.pi + s[..., None], 0.0)


class Lambert:
    def eval(self, wi, wo):
        wi, wo = np.broadcast_arrays(np.asarray(wi, float), np.asarray(wo, float))
        ok = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(ok[..., None], np.array([0.2, 0.4, 0.6]) / np.pi, 0.0)


def srgb_encode(x):
    """IEC 61966-2-1 sRGB encoding, written out by hand."""
    x = np.asarray(x, float)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def srgb_decode(c):
    c = np.asarray(c, float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# --------------------------------------------------------------------------- shading
@pytest.mark.parametrize("normal, warp, view, light", [
    ((0, 0, 1), (1, 0, 0), (0, 0, 1), (0.3, 0.2, 1.0)),
    ((0.2, -0.3, 1.0), (1.0, 0.4, 0.0), (0.5, 0.1, 1.0), (-0.4, 0.6, 0.8)),
    ((0.0, 1.0, 0.3), (0.3, 0.0, 1.0), (0.4, 1.0, -0.2), (-0.5, 0.7, 0.6)),
])
def test_patch_equals_brdf_times_irradiance_times_cosine(normal, warp, view, light):
    """Every pixel = f_r(wi_local, wo_local) * E * (n . wi), E the light's irradiance."""
    E = np.array([1.0, 0.5, 2.0])
    fab = Aniso()
    scene = make_scene("patch", normal=normal, warp=warp, view=view, light=light,
                       irradiance=E)
    img = render(scene, fab, width=12, height=7, spp=3, progress=False, seed=1)
    # independent frame: x = warp made orthogonal to n, y = n x x, z = n
    n = unit(normal)
    n = n if np.dot(n, view) > 0 else -n  # the patch faces the viewer
    x = unit(np.asarray(warp, float) - np.dot(warp, n) * n)
    y = np.cross(n, x)
    wi, wo = unit(light), unit(view)
    wi_l = np.array([wi @ x, wi @ y, wi @ n])
    wo_l = np.array([wo @ x, wo @ y, wo @ n])
    expected = fab.eval(wi_l, wo_l) * E * max(wi @ n, 0.0)
    assert expected.max() > 0.05
    np.testing.assert_allclose(img, np.broadcast_to(expected, img.shape), rtol=2e-6, atol=0)


def test_patch_lit_from_behind_is_black():
    img = render(make_scene("patch", light=(0.2, 0.1, -1.0)), Lambert(), width=5, height=4,
                 spp=1, progress=False)
    assert np.all(img == 0)


def test_patch_with_real_fabric_equals_its_eval():
    brdf = pytest.importorskip("brdf")
    if not hasattr(brdf, "fabric"):
        pytest.skip("brdf.fabric not available yet")
    fab = brdf.fabric("silk_shot", tangent_samples=8)
    view, light = unit((0.3, 0.2, 1.0)), unit((-0.5, 0.1, 0.8))
    img = render(make_scene("patch", view=view, light=light), fab, width=6, height=4, spp=2,
                 progress=False)
    expected = fab.eval(light, view) * light[2]
    np.testing.assert_allclose(img, np.broadcast_to(expected, img.shape), rtol=1e-5)


def test_point_light_irradiance_is_intensity_over_r_squared():
    light = PointLight(position=(1.0, 2.0, 2.0), intensity=(3.0, 6.0, 9.0))
    p = np.array([[1.0, 2.0, 0.0], [1.0, 0.0, 2.0]])
    wi, dist, E = light.sample(p, np.random.default_rng(0))
    np.testing.assert_allclose(dist, [2.0, 2.0])
    np.testing.assert_allclose(wi, [[0, 0, 1], [0, 1, 0]], atol=1e-15)
    np.testing.assert_allclose(E, np.array([[3.0, 6.0, 9.0]] * 2) / 4.0)


def test_shadowed_points_get_zero():
    """Patch at z = 0, opaque sphere above it at height 1, light at 45 degrees in x-z."""
    h, r = 1.0, 0.3
    L = unit((1.0, 0.0, 1.0))
    scene = Scene(
        primitives=(Rectangle(half_size=(10, 10)), Sphere(center=(0, 0, h), radius=r)),
        camera=OrthographicCamera(position=(0, 0, 5), target=(0, 0, 0), extent=2.0),
        light=DirectionalLight(direction=L, irradiance=1.0), name="shadow")
    W = H = 40
    img = render(scene, Lambert(), width=W, height=H, spp=4, progress=False)
    # pixel centres in the world (orthographic, extent 2 -> [-1, 1]^2, +y up)
    xs = (np.arange(W) + 0.5) / W * 2 - 1
    ys = 1 - (np.arange(H) + 0.5) / H * 2
    X, Y = np.meshgrid(xs, ys)
    # a point (x, y, 0) is in shadow iff its ray toward L meets the sphere (by hand):
    # distance from the sphere centre to the line p + s L
    P = np.stack([X, Y, np.zeros_like(X)], -1)
    c = np.array([0, 0, h])
    s = (c - P) @ L
    dist = np.linalg.norm(P + s[..., None] * L - c, axis=-1)
    half_pixel = 2 / W * 0.75
    on_patch = np.hypot(X, Y) > r + half_pixel          # the sphere itself is not in view
    deep_shadow = (dist < r - half_pixel) & on_patch
    fully_lit = (dist > r + half_pixel) & on_patch
    assert deep_shadow.sum() > 20 and fully_lit.sum() > 200
    assert np.all(img[deep_shadow] == 0)
    lit_value = np.array([0.2, 0.4, 0.6]) / np.pi * L[2]
    np.testing.assert_allclose(img[fully_lit], np.broadcast_to(lit_value, img[fully_lit].shape),
                               rtol=1e-6)


# --------------------------------------------------------------------------- geometry
def test_cylinder_frames():
    cyl = Cylinder(center=(0.0, 0.0, 0.0), radius=0.5, height=1.0)
    p = np.array([[0.5, 0.5, 0.0], [0.0, 0.3, 0.5], [0.2, 1.0, 0.0], [0.0, 0.0, -0.2]])
    n, u = cyl.frame(p, np.array([0, 0, 1, 2]))
    np.testing.assert_allclose(n, [[1, 0, 0], [0, 0, 1], [0, 1, 0], [0, -1, 0]], atol=1e-15)
    # warp runs around the +y axis on the side, (z, 0, -x) normalized; +x on both caps
    np.testing.assert_allclose(u, [[0, 0, -1], [1, 0, 0], [1, 0, 0], [1, 0, 0]], atol=1e-15)
    # camera rays along -z hit the side (part 0) and from above the top cap (part 1)
    o = np.array([[0.0, 0.5, 5.0], [0.1, 3.0, 0.1]])
    d = np.array([[0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])
    t, part = cyl.intersect(o, d, 1e-9)
    np.testing.assert_allclose(t, [4.5, 2.0])
    assert list(part) == [0, 1]


def test_cylinder_cap_warp_is_continuous():
    """No wedges: on a fine polar grid of the top cap, neighbouring points' warps differ by
    less than 1 degree everywhere, the centre included (a tangential warp turns by 90
    degrees between neighbours there and by about 360/segments on every ring)."""
    cyl = Cylinder(radius=0.5, height=1.0, cap_warp=(1.0, 0.0, 2.0))
    r = np.linspace(0.0, 0.5, 60)[:, None]
    phi = np.linspace(0.0, 2 * np.pi, 180)[None, :]
    p = np.stack(np.broadcast_arrays(r * np.cos(phi), 1.0, r * np.sin(phi)), axis=-1)
    n, u = cyl.frame(p.reshape(-1, 3), np.ones(p[..., 0].size, np.int8))
    u = u.reshape(p.shape)
    for axis in (0, 1):
        cos = np.sum(np.take(u, range(1, u.shape[axis]), axis) *
                     np.take(u, range(u.shape[axis] - 1), axis), axis=-1)
        assert np.degrees(np.arccos(np.clip(cos.min(), -1, 1))) < 1.0
    np.testing.assert_allclose(np.einsum("ij,ij->i", n, u.reshape(-1, 3)), 0.0, atol=1e-12)
    np.testing.assert_allclose(u[0, 0], np.array([1.0, 0.0, 2.0]) / np.sqrt(5.0), atol=1e-12)
    with pytest.raises(ValueError, match="cap_warp"):
        Cylinder(cap_warp=(0.0, 1.0, 0.0)).cap_direction()


def test_sphere_frame_follows_latitude():
    sph = Sphere(radius=2.0)
    p = np.array([[2.0, 0, 0], [0, 0, 2.0], [0, 2.0, 0]])
    n, u = sph.frame(p, np.zeros(3, np.int8))
    np.testing.assert_allclose(n, [[1, 0, 0], [0, 0, 1], [0, 1, 0]], atol=1e-15)
    np.testing.assert_allclose(u, [[0, 0, -1], [1, 0, 0], [1, 0, 0]], atol=1e-15)
    # n x warp points north (+y) on the equator
    np.testing.assert_allclose(np.cross(n[:2], u[:2]), [[0, 1, 0], [0, 1, 0]], atol=1e-15)


def test_curtain_hits_lie_on_the_surface_and_are_the_first_crossing():
    cur = Curtain()
    rng = np.random.default_rng(5)
    o = np.column_stack([rng.uniform(-3, 3, 300), rng.uniform(0, 2.5, 300), np.full(300, 4.0)])
    tgt = np.column_stack([rng.uniform(-1, 1, 300), rng.uniform(0.2, 2.2, 300),
                           rng.uniform(-0.2, 0.2, 300)])
    d = (tgt - o) / np.linalg.norm(tgt - o, axis=1, keepdims=True)
    t, _ = cur.intersect(o, d, 1e-9)
    hit = np.isfinite(t)
    assert hit.sum() > 100
    p = o[hit] + t[hit, None] * d[hit]
    np.testing.assert_allclose(p[:, 2], cur._height(p[:, 0], p[:, 1]), atol=1e-9)
    # no crossing before t: dense sampling of z - h along each ray from the camera side
    for k in np.nonzero(hit)[0][:40]:
        ts = np.linspace(0, t[k] * (1 - 1e-6), 4000)
        q = o[k] + ts[:, None] * d[k]
        inside = (np.abs(q[:, 0]) <= cur.width / 2) & (q[:, 1] >= cur.y0) & (q[:, 1] <= cur.y1)
        g = q[:, 2] - cur._height(q[:, 0], q[:, 1])
        assert np.all(g[inside] > 0)
    # frame: the normal is orthogonal to finite-difference tangents; warp is horizontal-ish
    n, u = cur.frame(p, np.zeros(len(p), np.int8))
    e = 1e-6
    tx = np.column_stack([np.full(len(p), 2 * e), np.zeros(len(p)),
                          cur._height(p[:, 0] + e, p[:, 1]) - cur._height(p[:, 0] - e, p[:, 1])])
    ty = np.column_stack([np.zeros(len(p)), np.full(len(p), 2 * e),
                          cur._height(p[:, 0], p[:, 1] + e) - cur._height(p[:, 0], p[:, 1] - e)])
    tx /= np.linalg.norm(tx, axis=1, keepdims=True)
    ty /= np.linalg.norm(ty, axis=1, keepdims=True)
    assert np.abs(np.einsum("ij,ij->i", n, tx)).max() < 1e-6
    assert np.abs(np.einsum("ij,ij->i", n, ty)).max() < 1e-6
    np.testing.assert_allclose(u, tx, atol=1e-6)
    assert np.all(n[:, 2] > 0)


# --------------------------------------------------------------------------- files
def test_png_decodes_to_exr_through_srgb_curve(tmp_path):
    img = render("cylinder", Aniso(), width=24, height=14, spp=2, progress=False)
    assert img.max() > 0
    exposure = 1.5
    imageio.write_exr(tmp_path / "c.exr", img)
    imageio.write_png(tmp_path / "c.png", img, exposure=exposure)
    lin = imageio.read_exr(tmp_path / "c.exr")
    assert lin.dtype == np.float32 and np.array_equal(lin, img)
    code = np.asarray(Image.open(tmp_path / "c.png").convert("RGB"), float) / 255
    target = np.clip(lin.astype(float) * 2 ** exposure, 0, 1)
    # within 8-bit quantization in the encoded domain ...
    assert np.abs(code - srgb_encode(target)).max() <= 0.5 / 255 + 1e-9
    # ... and so, decoded, within the curve's slope times half a code value
    slope = np.maximum(1 / 12.92, 2.4 / 1.055 * ((code + 0.055) / 1.055) ** 1.4)
    assert np.all(np.abs(srgb_decode(code) - target) <= slope * 0.51 / 255 + 1e-9)


def test_same_seed_same_bytes_and_workers_do_not_matter(tmp_path):
    kw = dict(width=20, height=12, spp=2, progress=False, tile=8)
    a = render("sphere", Aniso(), seed=3, workers=1, **kw)
    b = render("sphere", Aniso(), seed=3, workers=2, **kw)
    c = render("sphere", Aniso(), seed=4, workers=1, **kw)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    imageio.write_exr(tmp_path / "a.exr", a)
    imageio.write_exr(tmp_path / "b.exr", b)
    imageio.write_png(tmp_path / "a.png", a)
    imageio.write_png(tmp_path / "b.png", b)
    assert (tmp_path / "a.exr").read_bytes() == (tmp_path / "b.exr").read_bytes()
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    def boom(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(Image.Image, "save", boom)
    with pytest.raises(KeyboardInterrupt):
        imageio.write_png(tmp_path / "x.png", np.zeros((2, 2, 3)))
    assert list(tmp_path.iterdir()) == []


def test_area_light_softens_but_keeps_the_lit_level():
    scene = make_scene("cylinder")
    kw = dict(width=32, height=18, spp=4, progress=False)
    hard = render(scene, Lambert(), **kw)
    soft = render(scene.replace(light=PointLight(position=scene.light.position,
                                                 intensity=scene.light.intensity,
                                                 radius=0.3, target=scene.light.target)),
                  Lambert(), **kw)
    assert soft.max() > 0 and not np.array_equal(hard, soft)
    # a disc light is Lambertian: on axis it matches the point light (one sample estimate)
    assert 0.5 < soft.mean() / hard.mean() < 1.2


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, match", [
    (dict(width=1281), "width=1281 is beyond the limit"),
    (dict(height=721), "height=721 is beyond the limit"),
    (dict(width=0), "width=0 must be at least 1"),
    (dict(width=10.5), "width=10.5 must be an integer"),
    (dict(spp=0), "spp=0 must be an integer from 1"),
    (dict(scene="teapot"), "scene 'teapot' is unknown"),
    (dict(fabric=object()), "must be a preset name or have an eval"),
    (dict(fabric="tweed"), "unknown fabric 'tweed'"),
    (dict(workers=0), "workers=0"),
])
def test_bad_input_fails_at_once(kwargs, match):
    args = dict(scene="cylinder", fabric=Lambert(), width=8, height=8, spp=1, progress=False)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        render(**args)


def test_unwritable_folder_fails(tmp_path):
    with pytest.raises(OSError, match="does not exist"):
        imageio.write_exr(tmp_path / "nope" / "x.exr", np.zeros((1, 1, 3)))
    with pytest.raises(ValueError, match="must be \\(height, width, 3\\)"):
        imageio.write_png(tmp_path / "x.png", np.zeros((3, 3)))


def _sphere_view_cosines(scene, width, height):
    """n . v at each pixel centre's hit on the sphere scene's sphere (nan on a miss), from the
    ray-sphere quadratic solved here."""
    ys, xs = np.mgrid[0:height, 0:width]
    o, d = scene.camera.rays(xs.ravel() + 0.5, ys.ravel() + 0.5, width, height)
    sph = scene.primitives[0]
    oc = o - np.asarray(sph.center)
    b = np.einsum("ij,ij->i", oc, d)
    disc = b * b - (np.einsum("ij,ij->i", oc, oc) - sph.radius ** 2)
    t = -b - np.sqrt(np.where(disc > 0, disc, np.nan))
    n = (oc + t[:, None] * d) / sph.radius
    return (-np.einsum("ij,ij->i", n, d)).reshape(height, width)


@pytest.mark.parametrize("name, rim_brighter", [("velvet", True), ("linen_plain", False)])
def test_velvet_has_a_bright_rim(name, rim_brighter):
    """Velvet reads as velvet: on the lit sphere its grazing rim (n . v < 0.35, theta_o > 70
    deg) is on average at least 3 times as bright as its centre (n . v > 0.9); linen, nearly
    Lambertian, is the other way round."""
    from reports.colour import luminance
    scene = make_scene("sphere")
    img = render(scene, name, width=96, height=96, spp=4, progress=False, workers=1)
    cos = _sphere_view_cosines(scene, 96, 96)
    y = luminance(img)
    rim, centre = y[cos < 0.35].mean(), y[cos > 0.9].mean()
    assert (cos < 0.35).sum() > 100 and (cos > 0.9).sum() > 100
    assert (rim > 3 * centre) if rim_brighter else (centre > rim)


def test_fewer_sky_samples_on_cloth_keep_the_mean():
    """The sky on 2 of 16 samples a pixel on cloth (weighted 8) estimates the same image as on
    every sample: the cloth's mean luminance within a tenth of the sky's share of it (linen on
    the cylinder scene, the sky at least a tenth of its light), and sky_spp out of range is
    refused."""
    from reports.colour import luminance
    scene = make_scene("cylinder")
    full, cloth = render(scene, "linen_plain", 48, 27, spp=16, progress=False, workers=1,
                         mask=True)
    few = render(scene, "linen_plain", 48, 27, spp=16, progress=False, workers=1,
                 sky_spp=2, seed=1)
    unlit = render(scene.replace(environment=None), "linen_plain", 48, 27, spp=16,
                   progress=False, workers=1)
    c = cloth == 1
    sky = luminance(full)[c].mean() - luminance(unlit)[c].mean()
    assert sky > 0.1 * luminance(full)[c].mean()       # the sky matters on this cloth
    assert luminance(few)[c].mean() == pytest.approx(luminance(full)[c].mean(), abs=0.1 * sky)
    with pytest.raises(ValueError, match="sky_spp"):
        render("cylinder", "linen_plain", 8, 8, spp=4, sky_spp=5, progress=False)
