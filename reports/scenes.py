"""Scene description for the cloth renderer: primitives, cameras, lights and named scenes.

Every primitive answers two vectorized questions: where does a batch of rays first hit it
(:meth:`intersect`), and what is the shading frame at given points on it (:meth:`frame`).
The frame is the surface normal ``n`` and the warp tangent; the renderer completes it with
``y = n x warp`` so that local coordinates are (x = warp, y = n x warp, z = n), the frame of
:meth:`brdf.Fabric.eval`.

World axes: +y is up.  Lengths are in arbitrary scene units (metres, say); point-light
intensities in W/sr (any consistent radiometric unit), so that radiance comes out in
W / (m^2 sr).

Named scenes (:data:`SCENES`, built by :func:`make_scene`):

``curtain``
    A drape hung vertically: the surface ``z = a(y) sin(k x)`` over a rectangle of the
    x-y plane, the fold depth ``a(y)`` growing from top to bottom.  Warp tangent: the
    horizontal direction of the cloth, ``dP/dx`` normalized (it follows the width, across
    the folds); ``n x warp`` then points up the cloth, so the weft runs vertically.
    A grey floor and back wall give context.
``cylinder``
    An upright cylinder (axis +y) covered in fabric, standing on a grey floor.  Side: warp
    around the cylinder (the azimuthal direction), so ``n x warp`` runs along the axis.
    Caps: warp tangential (around the axis, concentric circles), so ``n x warp`` is radial
    (inward on the top cap); at the exact centre the warp falls back to +x.
``sphere``
    The lit sphere of Disney's BRDF Explorer: a unit sphere on black, lit by one point
    light from the upper left front.  Warp along the lines of latitude (east, about the
    vertical +y axis); ``n x warp`` points north along the meridians.  At the poles the warp
    falls back to +x.
``patch``
    A flat square of cloth in the x-y plane (n = +z, warp = +x), filling the view of an
    orthographic camera, under a directional light: every pixel shows the same
    ``f_r(wi, wo) E cos(theta_i)``.  The test scene; its normal, warp, view and light
    directions can be changed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Rectangle", "Sphere", "Cylinder", "Curtain", "Plane",
    "PinholeCamera", "OrthographicCamera", "PointLight", "DirectionalLight",
    "Scene", "SCENES", "make_scene",
]

_INF = np.inf


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


# --------------------------------------------------------------------------- primitives
@dataclass(frozen=True)
class Rectangle:
    """A flat rectangle with centre ``center``, normal ``normal`` and warp axis ``warp``.

    Parameters
    ----------
    center : (3,) array_like
        Centre, scene units.
    normal : (3,) array_like
        Surface normal (need not be unit).
    warp : (3,) array_like
        In-plane warp direction (made orthogonal to ``normal``).
    half_size : (float, float)
        Half extents along warp and along ``normal x warp``, scene units.
    material : str
        ``"cloth"`` (shaded with the fabric) or ``"diffuse"``.
    albedo : float
        Lambertian albedo when ``material == "diffuse"``.
    """

    center: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)
    warp: tuple = (1.0, 0.0, 0.0)
    half_size: tuple = (1.0, 1.0)
    material: str = "cloth"
    albedo: float = 0.5

    def _axes(self):
        n = _unit(self.normal)
        u = np.asarray(self.warp, float)
        u = _unit(u - _dot(u, n) * n)
        return np.asarray(self.center, float), n, u, np.cross(n, u)

    def intersect(self, o, d, tmin):
        """Ray parameter of the first hit (inf on a miss) and part index (always 0)."""
        c, n, u, v = self._axes()
        dn = d @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((c - o) @ n) / dn
        p = o + t[:, None] * d
        q = p - c
        ok = (np.isfinite(t) & (t > tmin) & (np.abs(q @ u) <= self.half_size[0])
              & (np.abs(q @ v) <= self.half_size[1]))
        return np.where(ok, t, _INF), np.zeros(len(t), np.int8)

    def frame(self, p, part):
        """Normal and warp, each (m, 3), at hit points ``p``."""
        _, n, u, _ = self._axes()
        m = len(p)
        return np.broadcast_to(n, (m, 3)).copy(), np.broadcast_to(u, (m, 3)).copy()


@dataclass(frozen=True)
class Plane:
    """An infinite plane ``x[axis] = offset`` with normal along +axis (a floor or wall).

    ``axis`` is 0, 1 or 2; ``sign`` (+1 or -1) picks which way the normal faces.
    """

    axis: int = 1
    offset: float = 0.0
    sign: float = 1.0
    material: str = "diffuse"
    albedo: float = 0.5

    def intersect(self, o, d, tmin):
        """Ray parameter of the first hit (inf on a miss) and part index (always 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self.offset - o[:, self.axis]) / d[:, self.axis]
        ok = np.isfinite(t) & (t > tmin)
        return np.where(ok, t, _INF), np.zeros(len(t), np.int8)

    def frame(self, p, part):
        """Normal and warp, each (m, 3)."""
        n = np.zeros(3)
        n[self.axis] = self.sign
        u = np.zeros(3)
        u[(self.axis + 1) % 3] = 1.0
        m = len(p)
        return np.broadcast_to(n, (m, 3)).copy(), np.broadcast_to(u, (m, 3)).copy()


@dataclass(frozen=True)
class Sphere:
    """A sphere; warp along the lines of latitude about the +y axis (east).

    Parameters
    ----------
    center : (3,) array_like
        Centre, scene units.
    radius : float
        Radius, scene units.
    material, albedo : see :class:`Rectangle`.
    """

    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 1.0
    material: str = "cloth"
    albedo: float = 0.5

    def intersect(self, o, d, tmin):
        """Ray parameter of the first hit (inf on a miss) and part index (always 0)."""
        oc = o - np.asarray(self.center, float)
        b = _dot(oc, d)
        c = _dot(oc, oc) - self.radius ** 2
        disc = b * b - c
        s = np.sqrt(np.maximum(disc, 0.0))
        t0, t1 = -b - s, -b + s
        t = np.where(t0 > tmin, t0, np.where(t1 > tmin, t1, _INF))
        return np.where(disc >= 0, t, _INF), np.zeros(len(t), np.int8)

    def frame(self, p, part):
        """Outward normal and the east tangent ``(z, 0, -x)`` normalized (+x at the poles)."""
        n = _unit(p - np.asarray(self.center, float))
        east = np.stack([n[:, 2], np.zeros(len(n)), -n[:, 0]], axis=-1)
        return n, _safe_tangent(east, n)


@dataclass(frozen=True)
class Cylinder:
    """An upright (axis +y) closed cylinder: side (part 0), top cap (1), bottom cap (2).

    Warp on the side: around the axis; on the caps: tangential (concentric circles).

    Parameters
    ----------
    center : (3,) array_like
        Centre of the bottom cap, scene units.
    radius, height : float
        Scene units.
    material, albedo : see :class:`Rectangle`.
    """

    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.5
    height: float = 1.0
    material: str = "cloth"
    albedo: float = 0.5

    def intersect(self, o, d, tmin):
        """Ray parameter of the first hit (inf on a miss) and the part hit."""
        c = np.asarray(self.center, float)
        oc = o - c
        y0, y1 = 0.0, self.height
        # side: quadratic in the x-z plane
        a = d[:, 0] ** 2 + d[:, 2] ** 2
        b = oc[:, 0] * d[:, 0] + oc[:, 2] * d[:, 2]
        cc = oc[:, 0] ** 2 + oc[:, 2] ** 2 - self.radius ** 2
        disc = b * b - a * cc
        s = np.sqrt(np.maximum(disc, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            ts = []
            for t in ((-b - s) / a, (-b + s) / a):
                y = oc[:, 1] + t * d[:, 1]
                ok = (disc >= 0) & (a > 0) & (t > tmin) & (y >= y0) & (y <= y1)
                ts.append(np.where(ok, t, _INF))
            t_side = np.minimum(ts[0], ts[1])
            caps = []
            for yc in (y1, y0):
                t = (yc - oc[:, 1]) / d[:, 1]
                px = oc[:, 0] + t * d[:, 0]
                pz = oc[:, 2] + t * d[:, 2]
                ok = np.isfinite(t) & (t > tmin) & (px * px + pz * pz <= self.radius ** 2)
                caps.append(np.where(ok, t, _INF))
        allt = np.stack([t_side, caps[0], caps[1]])
        part = np.argmin(allt, axis=0).astype(np.int8)
        return np.min(allt, axis=0), part

    def frame(self, p, part):
        """Outward normal and warp (around the axis) at points ``p`` on parts ``part``."""
        q = p - np.asarray(self.center, float)
        m = len(p)
        around = np.stack([q[:, 2], np.zeros(m), -q[:, 0]], axis=-1)  # (z, 0, -x): about +y
        n = np.zeros((m, 3))
        side = part == 0
        radial = q.copy()
        radial[:, 1] = 0.0
        n[side] = _unit(radial[side]) if side.any() else n[side]
        n[part == 1, 1] = 1.0
        n[part == 2, 1] = -1.0
        return n, _safe_tangent(around, n)


@dataclass(frozen=True)
class Curtain:
    """A drape hung vertically over ``|x| <= width/2``, ``y0 <= y <= y1``:

        z = z0 + a(y) (sin(k x) + 0.4 sin(1.9 k x + 0.8 + 1.5 s)),   s = (y1 - y) / (y1 - y0)

    with ``k = 2 pi folds / width`` and ``a(y) = depth (top + (1 - top) s)``: the folds
    deepen from ``top * depth`` at the top edge to ``depth`` at the bottom, and the second
    harmonic drifts with height so they are not all alike.  Warp: ``dP/dx``
    normalized (horizontal, across the folds).

    Parameters
    ----------
    width : float
        Width, scene units.
    y0, y1 : float
        Bottom and top edges, scene units.
    depth : float
        Fold amplitude at the bottom, scene units.
    folds : float
        Number of fold periods across the width.
    top : float
        Fold amplitude at the top as a fraction of ``depth``.
    z : float
        Mean depth of the drape.
    """

    width: float = 2.4
    y0: float = 0.05
    y1: float = 2.4
    depth: float = 0.08
    folds: float = 6.0
    top: float = 0.4
    z: float = 0.0
    material: str = "cloth"
    albedo: float = 0.5

    @property
    def _k(self):
        return 2 * np.pi * self.folds / self.width

    def _height(self, x, y):
        k = self._k
        s = (self.y1 - y) * (1.0 / (self.y1 - self.y0))
        a = self.depth * (self.top + (1 - self.top) * s)
        return self.z + a * (np.sin(k * x) + 0.4 * np.sin(1.9 * k * x + 0.8 + 1.5 * s))

    def _height_grad(self, x, y):
        """Height z(x, y) and its partial derivatives z_x, z_y."""
        k, H = self._k, self.y1 - self.y0
        s = (self.y1 - y) / H
        a = self.depth * (self.top + (1 - self.top) * s)
        da = -self.depth * (1 - self.top) / H
        p2 = 1.9 * k * x + 0.8 + 1.5 * s
        shape = np.sin(k * x) + 0.4 * np.sin(p2)
        z = self.z + a * shape
        zx = a * (k * np.cos(k * x) + 0.4 * 1.9 * k * np.cos(p2))
        zy = da * shape + a * 0.4 * np.cos(p2) * (-1.5 / H)
        return z, zx, zy

    def _g(self, o, d, t):
        p = o + t[:, None] * d
        return p[:, 2] - self._height(p[:, 0], p[:, 1])

    def intersect(self, o, d, tmin):
        """First crossing of the height field inside its bounding box.

        March in steps fine enough to see every fold (12 per period of the shortest
        harmonic, measured along x), then refine the first sign change by bisection.
        """
        n = len(o)
        lo = np.array([-self.width / 2, self.y0, self.z - 1.4 * self.depth])
        hi = np.array([self.width / 2, self.y1, self.z + 1.4 * self.depth])
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / d
            ta = (lo - o) * inv
            tb = (hi - o) * inv
        ta = np.where(np.isnan(ta), -_INF, ta)
        tb = np.where(np.isnan(tb), _INF, tb)
        tnear = np.max(np.minimum(ta, tb), axis=1)
        tfar = np.min(np.maximum(ta, tb), axis=1)
        tnear = np.maximum(tnear, tmin)
        result = np.full(n, _INF)
        idx = np.nonzero(tfar > tnear)[0]
        if idx.size == 0:
            return result, np.zeros(n, np.int8)
        o2, d2, a, b = o[idx], d[idx], tnear[idx], tfar[idx]
        # march: steps enough to resolve the shortest fold (12 per period) along x
        period = self.width / (self.folds * 1.9)
        need = 4 + np.ceil(12 * np.abs(d2[:, 0]) * (b - a) / period)
        bucket = np.clip(np.ceil(np.log2(need)), 2, 9).astype(int)   # 4 .. 512 steps
        for e in np.unique(bucket):
            sel = np.nonzero(bucket == e)[0]
            t_hit = self._march(o2[sel], d2[sel], a[sel], b[sel], 2 ** e)
            result[idx[sel]] = t_hit
        return result, np.zeros(n, np.int8)

    def _march(self, o, d, a, b, steps):
        """First root of g in [a, b] (inf if none): sign change over ``steps`` steps, then
        24 bisections and one secant step."""
        out = np.full(len(o), _INF)
        fr = np.linspace(0.0, 1.0, steps + 1)
        ts = a[:, None] + (b - a)[:, None] * fr[None, :]          # (m, steps+1)
        x = o[:, None, 0] + ts * d[:, None, 0]
        y = o[:, None, 1] + ts * d[:, None, 1]
        g = o[:, None, 2] + ts * d[:, None, 2] - self._height(x, y)
        change = np.signbit(g[:, :-1]) != np.signbit(g[:, 1:])
        rows = np.nonzero(change.any(axis=1))[0]
        if rows.size == 0:
            return out
        first = np.argmax(change[rows], axis=1)
        t_lo, t_hi = ts[rows, first], ts[rows, first + 1]
        g_lo, g_hi = g[rows, first], g[rows, first + 1]
        oo, dd = o[rows], d[rows]
        for _ in range(24):
            tm = 0.5 * (t_lo + t_hi)
            gm = self._g(oo, dd, tm)
            same = np.signbit(gm) == np.signbit(g_lo)
            t_lo, g_lo = np.where(same, tm, t_lo), np.where(same, gm, g_lo)
            t_hi, g_hi = np.where(same, t_hi, tm), np.where(same, g_hi, gm)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = t_lo - g_lo * (t_hi - t_lo) / (g_hi - g_lo)
        bad = ~((t >= t_lo) & (t <= t_hi))
        t[bad] = 0.5 * (t_lo[bad] + t_hi[bad])
        out[rows] = t
        return out

    def frame(self, p, part):
        """Normal ``(-z_x, -z_y, 1)`` normalized and warp ``(1, 0, z_x)`` normalized."""
        _, zx, zy = self._height_grad(p[:, 0], p[:, 1])
        one, zero = np.ones_like(zx), np.zeros_like(zx)
        n = _unit(np.stack([-zx, -zy, one], axis=-1))
        warp = _unit(np.stack([one, zero, zx], axis=-1))
        return n, _safe_tangent(warp, n)


def _safe_tangent(t, n):
    """``t`` made orthogonal to ``n`` and unit; +x (or +z) where ``t`` degenerates."""
    t = t - _dot(t, n)[:, None] * n
    norm = np.linalg.norm(t, axis=1)
    bad = norm < 1e-9
    if bad.any():
        fb = np.zeros((int(bad.sum()), 3))
        fb[:, 0] = 1.0
        nb = n[bad]
        fb = fb - _dot(fb, nb)[:, None] * nb
        fnorm = np.linalg.norm(fb, axis=1)
        alt = fnorm < 1e-6
        fb[alt] = np.array([0.0, 0.0, 1.0]) - nb[alt][:, 2:3] * nb[alt]
        t = t.copy()
        t[bad] = fb
        norm = np.linalg.norm(t, axis=1)
    return t / norm[:, None]


# --------------------------------------------------------------------------- cameras
@dataclass(frozen=True)
class PinholeCamera:
    """A pinhole camera at ``position`` looking at ``target``; ``fov`` vertical, degrees."""

    position: tuple = (0.0, 0.0, 4.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    fov: float = 40.0

    def rays(self, sx, sy, width, height):
        """Origins and unit directions, each (m, 3), through image points ``(sx, sy)``.

        ``sx`` in [0, width) from the left, ``sy`` in [0, height) from the top, in pixels.
        """
        f, r, u = _basis(self.position, self.target, self.up)
        th = np.tan(np.radians(self.fov) / 2)
        px = (2 * sx / width - 1) * th * width / height
        py = (1 - 2 * sy / height) * th
        d = _unit(f + px[:, None] * r + py[:, None] * u)
        return np.broadcast_to(np.asarray(self.position, float), d.shape), d


@dataclass(frozen=True)
class OrthographicCamera:
    """An orthographic camera looking along ``target - position``; ``extent`` is the
    height of the view in scene units (the width follows the image aspect)."""

    position: tuple = (0.0, 0.0, 4.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    extent: float = 2.0

    def rays(self, sx, sy, width, height):
        """Origins on the image plane and the common direction, each (m, 3)."""
        f, r, u = _basis(self.position, self.target, self.up)
        px = (sx / width - 0.5) * self.extent * width / height
        py = (0.5 - sy / height) * self.extent
        o = np.asarray(self.position, float) + px[:, None] * r + py[:, None] * u
        return o, np.broadcast_to(f, o.shape)


def _basis(position, target, up):
    f = _unit(np.asarray(target, float) - np.asarray(position, float))
    r = np.cross(f, np.asarray(up, float))
    if np.linalg.norm(r) < 1e-9:
        r = np.cross(f, np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0, 0]))
    r = _unit(r)
    return f, r, np.cross(r, f)


# --------------------------------------------------------------------------- lights
@dataclass(frozen=True)
class PointLight:
    """A point light, or a small one-sided Lambertian disc when ``radius > 0``.

    Parameters
    ----------
    position : (3,) array_like
        Position (disc centre), scene units.
    intensity : float or (3,) array_like
        Radiant intensity, W/sr (RGB); for a disc, the intensity along its axis (the disc's
        radiance is ``intensity / (pi radius^2)``).
    radius : float
        Disc radius, scene units; 0 for a point light.
    target : (3,) array_like
        The disc faces this point.

    Notes
    -----
    Irradiance at distance r, normal to the direction to the light: point light
    ``E = I / r^2``; disc, sampled uniformly by area with one sample per camera sample,
    ``E = I cos(theta_l) / r^2`` (theta_l between the disc axis and the direction to the
    shaded point), an unbiased estimate of the disc's irradiance.
    """

    position: tuple = (-2.0, 3.0, 3.0)
    intensity: object = 20.0
    radius: float = 0.0
    target: tuple = (0.0, 0.0, 0.0)

    def sample(self, p, rng):
        """Unit direction to the light, distance, and irradiance (m, 3) at points ``p``."""
        m = len(p)
        pos = np.broadcast_to(np.asarray(self.position, float), (m, 3))
        axis = _unit(np.asarray(self.target, float) - np.asarray(self.position, float))
        if self.radius > 0:
            r = self.radius * np.sqrt(rng.random(m))
            a = 2 * np.pi * rng.random(m)
            _, e1, e2 = _basis((0.0, 0.0, 0.0), axis, (0.0, 1.0, 0.0))
            pos = pos + (r * np.cos(a))[:, None] * e1 + (r * np.sin(a))[:, None] * e2
        v = pos - p
        dist = np.linalg.norm(v, axis=1)
        wi = v / dist[:, None]
        scale = 1.0 / dist ** 2
        if self.radius > 0:
            scale = scale * np.maximum(-(wi @ axis), 0.0)
        E = scale[:, None] * np.broadcast_to(np.asarray(self.intensity, float), (3,))
        return wi, dist, E


@dataclass(frozen=True)
class DirectionalLight:
    """A distant light: every point receives irradiance ``irradiance`` (W/m^2, RGB) on a
    plane normal to ``direction``, the unit vector pointing TOWARD the light."""

    direction: tuple = (0.0, 0.0, 1.0)
    irradiance: object = 1.0

    def sample(self, p, rng):
        """Unit direction to the light, distance (inf) and irradiance (m, 3)."""
        m = len(p)
        wi = np.broadcast_to(_unit(self.direction), (m, 3))
        E = np.broadcast_to(np.asarray(self.irradiance, float), (3,))
        return wi, np.full(m, _INF), np.broadcast_to(E, (m, 3))


# --------------------------------------------------------------------------- scenes
@dataclass(frozen=True)
class Scene:
    """Primitives, a camera and a light."""

    primitives: tuple
    camera: object
    light: object
    name: str = ""
    scale: float = 1.0  # typical size, sets ray epsilons

    def replace(self, **changes):
        """A copy with some fields changed."""
        from dataclasses import replace
        return replace(self, **changes)


def _curtain():
    return Scene(
        primitives=(Curtain(), Plane(axis=1, offset=0.0, albedo=0.4),
                    Plane(axis=2, offset=-0.8, albedo=0.4)),
        camera=PinholeCamera(position=(0.6, 1.4, 4.2), target=(0.0, 1.15, 0.0), fov=38.0),
        light=PointLight(position=(-1.8, 3.0, 2.6), intensity=24.0, target=(0.0, 1.0, 0.0)),
        name="curtain", scale=2.4)


def _cylinder():
    return Scene(
        primitives=(Cylinder(center=(0.0, 0.0, 0.0), radius=0.55, height=1.2),
                    Plane(axis=1, offset=0.0, albedo=0.4)),
        camera=PinholeCamera(position=(0.0, 1.7, 3.4), target=(0.0, 0.55, 0.0), fov=36.0),
        light=PointLight(position=(-1.6, 2.8, 2.2), intensity=14.0, target=(0.0, 0.6, 0.0)),
        name="cylinder", scale=1.2)


def _sphere():
    return Scene(
        primitives=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0),),
        camera=PinholeCamera(position=(0.0, 0.0, 4.5), target=(0.0, 0.0, 0.0), fov=30.0),
        light=PointLight(position=(-2.0, 2.0, 5.0), intensity=30.0),
        name="sphere", scale=1.0)


def _patch(normal=(0.0, 0.0, 1.0), warp=(1.0, 0.0, 0.0), view=(0.0, 0.0, 1.0),
           light=(0.0, 0.0, 1.0), irradiance=1.0, half_size=50.0):
    """The flat-patch scene: a large cloth square, orthographic camera along ``-view``."""
    view = _unit(view)
    up = (0.0, 1.0, 0.0) if abs(view[1]) < 0.9 else (0.0, 0.0, 1.0)
    return Scene(
        primitives=(Rectangle(normal=normal, warp=warp, half_size=(half_size, half_size)),),
        camera=OrthographicCamera(position=tuple(3.0 * view), target=(0.0, 0.0, 0.0),
                                  up=up, extent=2.0),
        light=DirectionalLight(direction=light, irradiance=irradiance),
        name="patch", scale=1.0)


#: Scene name -> builder (no arguments).
SCENES = {"curtain": _curtain, "cylinder": _cylinder, "sphere": _sphere, "patch": _patch}


def make_scene(name: str, **kwargs) -> Scene:
    """Build a named scene.

    Parameters
    ----------
    name : str
        One of :data:`SCENES`: ``curtain``, ``cylinder``, ``sphere``, ``patch``.
    **kwargs
        Passed to the builder (only ``patch`` takes any: ``normal``, ``warp``, ``view``,
        ``light`` (toward the light), ``irradiance`` (W/m^2), ``half_size``).

    Raises
    ------
    ValueError
        For an unknown name.

    Examples
    --------
    >>> make_scene("cylinder").primitives[0].radius
    0.55
    >>> make_scene("teapot")
    Traceback (most recent call last):
    ...
    ValueError: scene 'teapot' is unknown; choose one of curtain, cylinder, sphere, patch
    """
    if name not in SCENES:
        raise ValueError(f"scene {name!r} is unknown; choose one of {', '.join(SCENES)}")
    return SCENES[name](**kwargs)
