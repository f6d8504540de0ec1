"""Primitives of the renderer's scenes: rectangle, plane, sphere, cylinder and curtain.

Every primitive answers two vectorized questions: where does a batch of rays first hit it
(:meth:`intersect`), and what is the shading frame at given points on it (:meth:`frame`):
the surface normal ``n`` and the warp tangent (see :mod:`reports.render.scenes`). Lengths in scene
units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reports.render.vec3 import INF as _INF
from reports.render.vec3 import dot as _dot
from reports.render.vec3 import unit as _unit

__all__ = ["Rectangle", "Plane", "Sphere", "Cylinder", "Curtain"]


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

    Warp on the side: around the axis; on the caps: the constant direction ``cap_warp``
    projected onto the cap's plane, a warp field without a singular point (a tangential warp
    would turn once around the centre, and an anisotropic fabric would show pie-shaped
    wedges there).

    Parameters
    ----------
    center : (3,) array_like
        Centre of the bottom cap, scene units.
    radius, height : float
        Scene units.
    material, albedo : see :class:`Rectangle`.
    cap_warp : (3,) array_like
        The caps' warp before its projection onto their plane (not along +y).
    metered_parts : tuple of int
        The parts whose pixels set the automatic exposure (:mod:`reports.render.exposure`):
        the side; the top cap, seen nearly edge-on, glows with a fabric's grazing sheen.
    """

    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.5
    height: float = 1.0
    material: str = "cloth"
    albedo: float = 0.5
    cap_warp: tuple = (1.0, 0.0, 0.0)
    metered_parts: tuple = (0,)

    def cap_direction(self):
        """The caps' warp: ``cap_warp`` with its y component removed, unit (3,).

        Examples
        --------
        >>> Cylinder(cap_warp=(1.0, 5.0, 1.0)).cap_direction().round(4).tolist()
        [0.7071, 0.0, 0.7071]
        """
        w = np.array(self.cap_warp, float)
        w[1] = 0.0
        norm = np.linalg.norm(w)
        if not norm > 1e-9:
            raise ValueError(f"cap_warp={self.cap_warp!r} must not be along the axis (+y)")
        return w / norm

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
        """Outward normal and warp (around the axis on the side, :meth:`cap_direction` on the
        caps) at points ``p`` on parts ``part``."""
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
        around[~side] = self.cap_direction()
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
