r"""Microcyl's scenes as Mitsuba 3 scenes: the same camera, geometry, lights and sky.

:func:`scene_dict` turns a :class:`reports.render.scenes.Scene` and a :class:`brdf.Fabric` into the
dictionary of ``mi.load_dict``. Curved primitives become triangle meshes (:func:`meshes`
builds their arrays with NumPy) with vertex normals and texture coordinates chosen so that
Mitsuba's first tangent ``dp_du``, which the ``microcylinder`` BSDF takes as the warp
(:mod:`reports.mitsuba.plugin`), runs along the warp of :meth:`frame` in the built-in renderer:

- cylinder side, sphere: ``u`` the azimuth about +y, position
  ``(r sin(2 pi u), y, r cos(2 pi u))``, so ``dp_du`` is along ``(z, 0, -x)``;
- cylinder caps: ``u`` affine in the coordinate along the caps' constant warp
  (:meth:`reports.render.primitives.Cylinder.cap_direction`), so ``dp_du`` is that warp;
- curtain: ``u`` along x over the height field, ``dp_du`` along ``(1, 0, z_x)``;
- rectangle: Mitsuba's ``rectangle`` turned so that its local +x (its ``dp_du``) is the warp.

Planes become rectangles 100 scene scales across, or as far as the camera sees them (up to 5000
units). Cloth is the ``microcylinder`` BSDF, wrapped in ``twosided`` on open surfaces (curtain,
rectangle: the built-in renderer's cloth is two-sided) and one-sided on closed ones (cylinder,
sphere), whose inside no ray sees: Mitsuba's ``twosided`` calls its BSDF once per side, which
doubles the kernel that LLVM compiles. (On a back face ``twosided`` mirrors the frame to (s, t,
-n) where the built-in renderer turns it to (warp, -t, -n); the two agree for fabrics symmetric
under y -> -y, every preset among them.)
Diffuse surfaces are a two-sided ``diffuse``. Lights: a point light of the same intensity
(W/sr), a disc light as a ``disk`` area emitter of radiance ``I / (pi r^2)`` facing its
target, a ``directional`` emitter of the same irradiance. The sky
(:class:`reports.render.envlight.EnvironmentLight`) is an ``envmap`` whose rows hold its radiance:
Mitsuba's row ``i`` of ``n`` looks along ``w_y = cos(pi i / (n - 1))``.
Rays that escape show black (``hide_emitters``), as in the built-in renderer.

Imports Mitsuba at its top: import it after ``mitsuba.set_variant``
(:func:`reports.mitsuba.render.render_mitsuba` does).
"""

from __future__ import annotations

import numpy as np

# optional dependency: this module is imported only by reports.mitsuba.render on use
import mitsuba as mi

from analysis.fabricfile import plugin_dict
from reports.render.cameras import OrthographicCamera, PinholeCamera
from reports.render.lights import DirectionalLight, PointLight
from reports.render.primitives import Curtain, Cylinder, Plane, Rectangle, Sphere
from reports.render.vec3 import unit

__all__ = ["scene_dict", "meshes", "ENV_ROWS", "SEGMENTS", "LIGHT_SETS"]

#: Rows of the sky's bitmap (its radiance depends on the height of the direction alone).
ENV_ROWS = 512
#: Segments of a mesh around the vertical axis (cylinder, sphere) and across the curtain.
SEGMENTS = 512


def _orient(faces, pos, normals):
    """``faces`` (k, 3) with each triangle wound so that its geometric normal faces its
    vertex normals; triangles of zero area dropped."""
    a, b, c = (pos[faces[:, i]] for i in range(3))
    g = np.cross(b - a, c - a)
    keep = np.linalg.norm(g, axis=1) > 1e-14
    faces, g = faces[keep], g[keep]
    flip = np.einsum("ij,ij->i", g, normals[faces].sum(axis=1)) < 0
    faces[flip] = faces[flip][:, [0, 2, 1]]
    return faces


def _grid_faces(rows, cols):
    """Two triangles per cell of a (rows + 1) x (cols + 1) vertex grid, row-major."""
    i, j = np.mgrid[0:rows, 0:cols]
    v0 = (i * (cols + 1) + j).ravel()
    v1, v2, v3 = v0 + 1, v0 + cols + 1, v0 + cols + 2
    return np.concatenate([np.stack([v0, v1, v3], 1), np.stack([v0, v3, v2], 1)])


def _around(r, phi, y):
    """Points (..., 3) at radius r, azimuth phi about +y, height y: (r sin, y, r cos)."""
    return np.stack(np.broadcast_arrays(r * np.sin(phi), y, r * np.cos(phi)), axis=-1)


def _cylinder(prim: Cylinder, n: int):
    """Side and caps of a closed cylinder: positions, normals, uv, faces."""
    c = np.asarray(prim.center, float)
    u = np.linspace(0.0, 1.0, n + 1)
    phi = 2.0 * np.pi * u
    parts = []
    h = np.array([0.0, prim.height])[:, None]
    side = _around(prim.radius, phi[None, :], h)                       # (2, n + 1, 3)
    nrm = _around(1.0, phi[None, :], np.zeros((2, 1)))
    uv = np.stack(np.broadcast_arrays(u[None, :], np.array([0.0, 1.0])[:, None]), axis=-1)
    parts.append((side.reshape(-1, 3), nrm.reshape(-1, 3), uv.reshape(-1, 2),
                  _grid_faces(1, n)))
    rings = 8
    rad = np.linspace(0.0, 1.0, rings + 1)[:, None]
    axis = prim.cap_direction()
    for y, ny in ((prim.height, 1.0), (0.0, -1.0)):
        cap = _around(prim.radius * rad, phi[None, :], y)
        nrm = np.broadcast_to([0.0, ny, 0.0], cap.shape)
        # u affine in the coordinate along the cap's warp, v across it: dp_du is the
        # constant warp of the built-in cap (Cylinder.frame), no singular centre
        along = cap[..., 0] * axis[0] + cap[..., 2] * axis[2]
        across = cap[..., 2] * axis[0] - cap[..., 0] * axis[2]
        uv = 0.5 + 0.5 / prim.radius * np.stack([along, across], axis=-1)
        parts.append((cap.reshape(-1, 3), nrm.reshape(-1, 3), uv.reshape(-1, 2),
                      _grid_faces(rings, n)))
    return _join(parts, c)


def _sphere(prim: Sphere, n: int):
    """A latitude-longitude sphere: u the azimuth about +y, v from the north pole."""
    u = np.linspace(0.0, 1.0, n + 1)
    v = np.linspace(0.0, 1.0, n // 2 + 1)
    theta = np.pi * v[:, None]
    nrm = _around(np.sin(theta), 2.0 * np.pi * u[None, :], np.cos(theta))
    uv = np.stack(np.broadcast_arrays(u[None, :], v[:, None]), axis=-1)
    return _join([(prim.radius * nrm.reshape(-1, 3), nrm.reshape(-1, 3), uv.reshape(-1, 2),
                   _grid_faces(n // 2, n))], np.asarray(prim.center, float))


def _curtain(prim: Curtain, n: int):
    """The curtain's height field on an n x n/4 grid, normals from its exact gradient."""
    u = np.linspace(0.0, 1.0, n + 1)
    v = np.linspace(0.0, 1.0, n // 4 + 1)
    x = (u - 0.5)[None, :] * prim.width + 0.0 * v[:, None]
    y = prim.y0 + v[:, None] * (prim.y1 - prim.y0) + 0.0 * u[None, :]
    z, zx, zy = prim._height_grad(x, y)
    pos = np.stack([x, y, z], axis=-1)
    nrm = unit(np.stack([-zx, -zy, np.ones_like(zx)], axis=-1))
    uv = np.stack(np.broadcast_arrays(u[None, :], v[:, None]), axis=-1)
    return _join([(pos.reshape(-1, 3), nrm.reshape(-1, 3), uv.reshape(-1, 2),
                   _grid_faces(n // 4, n))], np.zeros(3))


def _join(parts, offset):
    """Concatenate mesh parts into one (positions + offset, normals, uv, oriented faces)."""
    pos, nrm, uv, faces, base = [], [], [], [], 0
    for p, nr, t, f in parts:
        pos.append(p)
        nrm.append(nr)
        uv.append(t)
        faces.append(f + base)
        base += len(p)
    pos, nrm = np.concatenate(pos) + offset, np.concatenate(nrm)
    return pos, nrm, np.concatenate(uv), _orient(np.concatenate(faces), pos, nrm)


def meshes(prim, segments: int = SEGMENTS):
    """The triangle mesh of a curved primitive, or None for the flat ones.

    Parameters
    ----------
    prim : Cylinder, Sphere, Curtain, Rectangle or Plane
    segments : int
        Segments around the vertical axis (across the curtain).

    Returns
    -------
    tuple or None
        ``(positions (m, 3), normals (m, 3), uv (m, 2), faces (k, 3))``: scene units, unit
        normals, ``u`` along the warp (module notes), faces wound to face their normals.
    """
    if isinstance(prim, Cylinder):
        return _cylinder(prim, segments)
    if isinstance(prim, Sphere):
        return _sphere(prim, segments)
    if isinstance(prim, Curtain):
        return _curtain(prim, segments)
    return None


def _mesh(name, arrays, bsdf):
    """A ``mi.Mesh`` of ``arrays`` (see :func:`meshes`) with the BSDF object ``bsdf``."""
    pos, nrm, uv, faces = arrays
    props = mi.Properties()
    props["bsdf"] = bsdf
    mesh = mi.Mesh(name, len(pos), len(faces), has_vertex_normals=True,
                   has_vertex_texcoords=True, props=props)
    params = mi.traverse(mesh)
    for key, a, dtype in (("vertex_positions", pos, np.float32),
                          ("vertex_normals", nrm, np.float32),
                          ("vertex_texcoords", uv, np.float32), ("faces", faces, np.uint32)):
        params[key] = type(params[key])(np.ascontiguousarray(a, dtype).ravel())
    params.update()
    return mesh


def _frame_transform(center, x, y, z):
    """The 4x4 transform taking local x, y, z (scaled) to ``x``, ``y``, ``z`` at ``center``."""
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, center
    return mi.ScalarTransform4f(m.tolist())


#: The farthest a plane's rectangle reaches (scene units): half the sensor's far clip.
PLANE_REACH = 5e3


def _plane_half(prim, camera, width, height, scale) -> float:
    """Half the side of the rectangle that stands for an infinite Plane: 100 scene scales, or
    beyond, up to :data:`PLANE_REACH`, far enough to hold every point of the plane the
    camera sees through the edges of its image (a pinhole looking down at a floor sees it
    up to near the horizon: the cylinder scene's top row meets it 140 units away, past 100
    scales, and showed the black beyond its edge)."""
    half = 100.0 * scale
    if not isinstance(camera, PinholeCamera):
        return half
    k = np.linspace(0.0, 1.0, 65)
    sx = np.concatenate([k * width, k * width, np.zeros_like(k), np.full_like(k, width)])
    sy = np.concatenate([np.zeros_like(k), np.full_like(k, height), k * height, k * height])
    o, d = camera.rays(sx, sy, width, height)
    dn = d[:, prim.axis]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (prim.offset - o[:, prim.axis]) / dn
    hit = np.isfinite(t) & (t > 0)
    if hit.any():
        p = o[hit] + t[hit, None] * d[hit]
        p[:, prim.axis] = 0.0
        half = max(half, 1.05 * float(np.abs(p).max()))
    return min(half, PLANE_REACH)


def _flat(prim, scale, half=None):
    """A Mitsuba ``rectangle`` dictionary for a Rectangle or a Plane (``half`` the half side
    of its square, default 100 scales: :func:`_plane_half`)."""
    if isinstance(prim, Plane):
        n = np.zeros(3)
        n[prim.axis] = prim.sign
        u = np.zeros(3)
        u[(prim.axis + 1) % 3] = 1.0
        c = np.zeros(3)
        c[prim.axis] = prim.offset
        hx = hy = 100.0 * scale if half is None else float(half)
    else:
        c, n, u, _ = prim._axes()
        hx, hy = prim.half_size
    return {"type": "rectangle",
            "to_world": _frame_transform(c, hx * u, hy * np.cross(n, u), n)}


def _bsdf(prim, fabric):
    """The BSDF dictionary of a primitive: the fabric (two-sided unless the primitive is
    closed) or a two-sided diffuse grey."""
    if prim.material == "cloth":
        if isinstance(prim, (Cylinder, Sphere)):
            return plugin_dict(fabric)
        return {"type": "twosided", "bsdf": plugin_dict(fabric)}
    a = float(prim.albedo)
    return {"type": "twosided",
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [a, a, a]}}}


def _rgb(value):
    v = np.broadcast_to(np.asarray(value, float), (3,))
    return {"type": "rgb", "value": [float(x) for x in v]}


def _light(light, scale):
    """The emitter (or emitting shape) dictionary of a PointLight or DirectionalLight."""
    if isinstance(light, DirectionalLight):
        return {"type": "directional", "direction": (-unit(light.direction)).tolist(),
                "irradiance": _rgb(light.irradiance)}
    if not isinstance(light, PointLight):
        raise ValueError(f"light {light!r}: the Mitsuba engine takes a PointLight or a "
                         f"DirectionalLight")
    if light.radius <= 0:
        return {"type": "point", "position": [float(x) for x in light.position],
                "intensity": _rgb(light.intensity)}
    look = mi.ScalarTransform4f().look_at(origin=list(map(float, light.position)),
                                          target=list(map(float, light.target)),
                                          up=_up_for(np.subtract(light.target, light.position)))
    radiance = np.asarray(light.intensity, float) / (np.pi * light.radius ** 2)
    return {"type": "disk", "to_world": look @ mi.ScalarTransform4f().scale(light.radius),
            "emitter": {"type": "area", "radiance": _rgb(radiance)},
            "bsdf": {"type": "diffuse", "reflectance": _rgb(0.0)}}


def _up_for(forward):
    """An up vector not parallel to ``forward``."""
    f = unit(forward)
    return [0.0, 1.0, 0.0] if abs(f[1]) < 0.99 else [0.0, 0.0, 1.0]


def _sensor(camera, width, height, spp, seed):
    """The sensor dictionary of a PinholeCamera or OrthographicCamera (box pixel filter)."""
    if not isinstance(camera, (PinholeCamera, OrthographicCamera)):
        raise ValueError(f"camera {camera!r}: the Mitsuba engine takes a PinholeCamera or an "
                         f"OrthographicCamera")
    look = mi.ScalarTransform4f().look_at(origin=list(map(float, camera.position)),
                                          target=list(map(float, camera.target)),
                                          up=list(map(float, camera.up)))
    film = {"type": "hdrfilm", "width": int(width), "height": int(height),
            "pixel_format": "rgb", "rfilter": {"type": "box"}}
    sampler = {"type": "independent", "sample_count": int(spp), "seed": int(seed)}
    if isinstance(camera, PinholeCamera):
        return {"type": "perspective", "fov": float(camera.fov), "fov_axis": "y",
                "near_clip": 1e-3, "far_clip": 1e4, "to_world": look, "film": film,
                "sampler": sampler}
    # Mitsuba's orthographic view is 2 wide and 2 / aspect high before to_world's scale
    s = 0.5 * camera.extent * width / height
    return {"type": "orthographic", "near_clip": 1e-3, "far_clip": 1e4,
            "to_world": look @ mi.ScalarTransform4f().scale([s, s, 1.0]),
            "film": film, "sampler": sampler}


def sky_bitmap(env, rows: int = ENV_ROWS) -> np.ndarray:
    """The sky as an ``envmap`` bitmap (rows, 4, 3) float32: row ``i`` holds the radiance
    (W / (m^2 sr)) along ``w_y = cos(pi i / (rows - 1))``, where Mitsuba's ``envmap`` puts
    that row (its rows are the samples at the poles and between, interpolated linearly).

    Examples
    --------
    >>> from reports.render.envlight import EnvironmentLight
    >>> b = sky_bitmap(EnvironmentLight(zenith=(1, 1, 1), horizon=(0, 0, 0)), rows=4)
    >>> np.round(b[:, 0, 0], 3).tolist()
    [1.0, 0.5, 0.0, 0.0]
    """
    v = np.arange(rows) / (rows - 1.0)
    w = np.zeros((rows, 3))
    w[:, 1] = np.cos(np.pi * v)
    rad = env.radiance(w)
    return np.ascontiguousarray(np.broadcast_to(rad[:, None, :], (rows, 4, 3)), np.float32)


#: The lights a scene dictionary may hold: the key light, the sky, or both.
LIGHT_SETS = ("both", "key", "sky")


def scene_dict(scene, fabric, width, height, spp, *, seed=0, max_depth=8,
               lights="both") -> dict:
    """The ``mi.load_dict`` dictionary of a microcyl scene with cloth of ``fabric``.

    Parameters
    ----------
    scene : reports.render.scenes.Scene
    fabric : brdf.Fabric
    width, height : int
        Pixels.
    spp : int
        Samples per pixel.
    seed : int
        The sampler's seed.
    max_depth : int
        The path integrator's longest path (2: direct light only, as the built-in renderer;
        -1: unbounded).
    lights : {"both", "key", "sky"}
        The emitters: the key light and the sky, or one of them (a scene of each, rendered
        and summed, has every path sample both: :func:`reports.mitsuba.render.render_mitsuba`).

    Returns
    -------
    dict
        Scene dictionary; the meshes in it are Mitsuba objects of the variant that is set.
    """
    if lights not in LIGHT_SETS:
        raise ValueError(f"lights={lights!r} must be one of {', '.join(LIGHT_SETS)}")
    out = {"type": "scene",
           "integrator": {"type": "path", "max_depth": int(max_depth), "hide_emitters": True},
           "sensor": _sensor(scene.camera, width, height, spp, seed)}
    if lights != "sky":
        out["light"] = _light(scene.light, scene.scale)
    for k, prim in enumerate(scene.primitives):
        if not isinstance(prim, (Cylinder, Sphere, Curtain, Rectangle, Plane)):
            raise ValueError(f"primitive {prim!r}: the Mitsuba engine has no mesh for it")
        bsdf = _bsdf(prim, fabric)
        arrays = meshes(prim)
        if arrays is None:
            half = (_plane_half(prim, scene.camera, width, height, scene.scale)
                    if isinstance(prim, Plane) else None)
            out[f"shape{k}"] = {**_flat(prim, scene.scale, half), "bsdf": bsdf}
        else:
            out[f"shape{k}"] = _mesh(f"shape{k}", arrays, mi.load_dict(bsdf))
    if scene.environment is not None and lights != "key":
        out["sky"] = {"type": "envmap", "bitmap": mi.Bitmap(sky_bitmap(scene.environment))}
    return out
