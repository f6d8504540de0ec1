"""Tests of reports.mitsuba.scene: Mitsuba's copies of the built-in scenes hit the same points
with the same normals and warps, and their sky has the built-in sky's radiance.

The reference is the built-in renderer's own geometry (reports.render.tracing and each primitive's
frame), traced independently of Mitsuba. Skips where Mitsuba is not installed; everything
runs in scalar_rgb (no LLVM needed).
"""

import numpy as np
import pytest

import brdf
from reports.render.envlight import EnvironmentLight
from reports.render.scenes import make_scene
from reports.render.tracing import intersect

mi = pytest.importorskip("mitsuba", reason="mitsuba is not installed")


@pytest.fixture(scope="module")
def scalar():
    mi.set_variant("scalar_rgb")
    from reports.mitsuba import plugin
    plugin.register()
    from reports.mitsuba import scene as mitsuba_scene
    return mitsuba_scene


def _camera_rays(scene, nx=16, ny=9, width=64, height=36):
    xs, ys = np.meshgrid((np.arange(nx) + 0.5) * width / nx, (np.arange(ny) + 0.5) * height / ny)
    o, d = scene.camera.rays(xs.ravel(), ys.ravel(), width, height)
    return np.ascontiguousarray(o), np.ascontiguousarray(d)


@pytest.mark.parametrize("name", ["cylinder", "sphere", "curtain", "patch"])
def test_hits_normals_and_warps_match_the_builtin_scene(scalar, name):
    """Where a camera ray hits cloth in the built-in scene, Mitsuba's scene is hit at the same
    point, with the same shading normal, and dp_du (the plugin's warp) along the same warp."""
    scene = make_scene(name)
    mscene = mi.load_dict(scalar.scene_dict(scene, brdf.fabric("velvet"), 64, 36, 1))
    o, d = _camera_rays(scene)
    t, pid, part = intersect(scene.primitives, o, d, 1e-6)
    checked = 0
    for k in np.nonzero(np.isfinite(t))[0]:
        prim = scene.primitives[pid[k]]
        if prim.material != "cloth":
            continue
        p = o[k] + t[k] * d[k]
        n, warp = (a[0] for a in prim.frame(p[None], part[k:k + 1]))
        si = mscene.ray_intersect(mi.Ray3f(mi.Point3f(*o[k]), mi.Vector3f(*d[k])))
        assert si.is_valid()
        assert np.linalg.norm(np.array(si.p) - p) < 2e-3 * scene.scale, (k, si.p, p)
        n_mi = np.array(si.sh_frame.n)
        assert n_mi @ n > 0.999, (k, n_mi, n)
        du = np.array(si.dp_du)
        du = du - (du @ n_mi) * n_mi
        assert (du / np.linalg.norm(du)) @ warp > 0.995, (k, du, warp)
        checked += 1
    assert checked >= 10


def test_sky_radiance_matches_the_environment_light(scalar):
    """The envmap's radiance along random directions is EnvironmentLight.radiance's."""
    env = EnvironmentLight(zenith=(1.0, 0.5, 0.2), horizon=(0.1, 0.2, 0.3))
    emitter = mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(scalar.sky_bitmap(env))})
    rng = np.random.default_rng(5)
    w = rng.normal(size=(40, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    ref = env.radiance(w)
    for wk, rk in zip(w, ref):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*(-wk))                    # the ray travels along wk, into the sky
        got = np.array(emitter.eval(si))
        assert np.allclose(got, rk, rtol=1e-4, atol=1e-6), (wk, got, rk)


@pytest.mark.parametrize("name", ["cylinder", "sphere", "curtain"])
def test_meshes_are_closed_where_the_primitive_is_and_face_their_normals(scalar, name):
    prim = make_scene(name).primitives[0]
    pos, nrm, uv, faces = scalar.meshes(prim, segments=32)
    a, b, c = (pos[faces[:, i]] for i in range(3))
    g = np.cross(b - a, c - a)
    assert np.all(np.einsum("ij,ij->i", g, nrm[faces].sum(axis=1)) > 0)
    assert np.allclose(np.linalg.norm(nrm, axis=1), 1.0)
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    area = 0.5 * np.linalg.norm(g, axis=1).sum()
    if name == "cylinder":
        exact = 2 * np.pi * prim.radius * (prim.radius + prim.height)
        assert area == pytest.approx(exact, rel=0.01)
    elif name == "sphere":
        assert area == pytest.approx(4 * np.pi * prim.radius ** 2, rel=0.01)


def test_unknown_light_or_camera_is_refused(scalar):
    scene = make_scene("sphere")
    fab = brdf.fabric("velvet")
    with pytest.raises(ValueError, match="light"):
        scalar.scene_dict(scene.replace(light="lamp"), fab, 8, 8, 1)
    with pytest.raises(ValueError, match="camera"):
        scalar.scene_dict(scene.replace(camera="eye"), fab, 8, 8, 1)


@pytest.mark.parametrize("name", ["cylinder", "curtain", "patch"])
def test_sensor_rays_are_the_builtin_camera_rays(scalar, name):
    """Mitsuba's sensor sends the ray of the built-in camera through each film position
    (perspective: same origin and direction; orthographic: same origin plane and extent)."""
    scene = make_scene(name)
    width, height = 64, 36
    mscene = mi.load_dict(scalar.scene_dict(scene, brdf.fabric("velvet"), width, height, 1))
    sensor = mscene.sensors()[0]
    rng = np.random.default_rng(2)
    for u, v in rng.random((12, 2)):
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(u, v), mi.Point2f(0.5, 0.5))
        o, d = scene.camera.rays(np.array([u * width]), np.array([v * height]), width, height)
        d_mi, o_mi = np.array(ray.d), np.array(ray.o)
        assert d_mi @ d[0] > 1 - 1e-6, (u, v, d_mi, d[0])
        # Mitsuba starts the ray at the near clip plane: the origin is on the built-in ray
        off = o_mi - o[0]
        assert np.linalg.norm(off - (off @ d[0]) * d[0]) < 1e-4 * scene.scale, (u, v)


@pytest.mark.parametrize("width, height", [(640, 360), (1280, 720), (64, 36)])
def test_a_floor_reaches_every_point_the_camera_sees_of_it(scalar, width, height):
    """The rectangle standing for the cylinder scene's infinite floor holds every point the
    camera's rays through the image's edges hit (the top row's, 140 units away, were past
    its 100-scale edge: black)."""
    from reports.render.primitives import Plane
    scene = make_scene("cylinder")
    floor = next(p for p in scene.primitives if isinstance(p, Plane))
    half = scalar._plane_half(floor, scene.camera, width, height, scene.scale)
    k = np.linspace(0.0, 1.0, 33)
    o, d = scene.camera.rays(k * width, np.zeros_like(k), width, height)   # the top edge
    t = (floor.offset - o[:, floor.axis]) / d[:, floor.axis]
    p = o + t[:, None] * d
    assert np.all(t > 0) and np.abs(p[:, [0, 2]]).max() > 100 * scene.scale
    assert np.abs(p[:, [0, 2]]).max() <= half <= scalar.PLANE_REACH
