"""A small NumPy ray tracer for cloth shaded with the microcylinder BRDF.

:func:`render` traces one camera ray per sample (stratified jitter, seeded), finds the first
hit among the scene's primitives, samples the light directly with a shadow ray, and shades
cloth with ``fabric.eval(wi_local, wo_local)`` and everything else as Lambertian.  Only
samples that hit lit cloth reach the BRDF, in batches of one image tile at a time, and tiles
are spread over the processor cores.  :func:`write_exr` and :func:`write_png` (from
:mod:`reports.render.imageio`) save the result.  ``render(..., mask=True)`` also returns the cloth's
coverage (the fraction of each pixel's samples whose first hit is metered cloth: the
cylinder's side, not its caps), and
:func:`cloth_coverage` traces it alone, for :func:`reports.render.exposure.auto_exposure`.

Shading (direct light only: one key-light sample per camera sample, plus the sky when the
scene has an environment light, :mod:`reports.render.envlight`, no bounces):

    L_o = f_r(wi, wo) * E * cos(theta_i) * V  [+ the sky's, by MIS of a table of the
                                                fabric's f_r cos and cosine directions]

the sky on every sample of a diffuse surface and on ``sky_spp`` samples a pixel of cloth
(weighted ``spp / sky_spp``), its uniform numbers stratified over the pixel's samples;
with ``E`` the light's irradiance normal to ``wi`` (point light: ``I / r^2``; disc light:
``I cos(theta_l) / r^2``; directional light: its irradiance), ``cos(theta_i) = n . wi``,
and ``V`` the visibility (0 or 1) from the shadow ray.  Diffuse surfaces use
``f_r = albedo / pi``.  Cloth is two-sided: the normal is turned toward the viewer, keeping
the warp, and ``wi``, ``wo`` are expressed in (x = warp, y = n x warp, z = n).  A pixel is
the mean of its samples; rays that hit nothing give 0.
"""

from __future__ import annotations

import functools
import multiprocessing
import os
import signal
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np

from gonio.progress import progress_bar
from reports.render import pixelsamples
from reports.render.checks import (MAX_HEIGHT, MAX_SPP, MAX_WIDTH, check_size,  # noqa: F401
                                   check_workers, probe, resolve_fabric, scene_of)
from reports.render.brdftable import BRDFTable
from reports.render.envlight import environment_radiance
from reports.render.imageio import write_exr, write_png
from reports.render.scenes import SCENES
from reports.render.tracing import intersect, occluded
from reports.render.workerexit import exit_with_parent

__all__ = ["render", "cloth_coverage", "write_exr", "write_png", "MAX_WIDTH", "MAX_HEIGHT",
           "SCENES", "resolve_fabric", "check_size"]

#: Largest number of (wi, wo) pairs passed to one ``fabric.eval`` call.
BRDF_BATCH = 131072


# --------------------------------------------------------------------------- shading
def _hits(scene, o, d):
    """The rays' first hits: indices of the rays that hit, points, normals turned toward
    the viewer, warps, directions to the viewer, primitive indices and parts."""
    prims = scene.primitives
    t, pid, part = intersect(prims, o, d, 1e-6 * scene.scale)
    hit = np.nonzero(np.isfinite(t))[0]
    p = o[hit] + t[hit, None] * d[hit]
    wo = -d[hit]
    n = np.empty((hit.size, 3))
    warp = np.empty((hit.size, 3))
    pid_h = pid[hit]
    for k, prim in enumerate(prims):
        sel = pid_h == k
        if sel.any():
            n[sel], warp[sel] = prim.frame(p[sel], part[hit][sel])
    flip = np.einsum("ij,ij->i", n, wo) < 0          # two-sided: face the viewer
    n[flip] *= -1
    return hit, p, n, warp, wo, pid_h, part[hit]


def _local(n, warp):
    """World -> local frames (m, 3, 3): rows warp, n x warp, n."""
    return np.stack([warp, np.cross(n, warp), n], axis=1)


def _key_light(scene, fabric, p, n, warp, wo, cloth, albedo, rng):
    """Radiance (m, 3) from the scene's light: f_r E cos(theta_i) V (one shadow ray)."""
    out = np.zeros((len(p), 3))
    wi, dist, E = scene.light.sample(p, rng)
    cos_i = np.einsum("ij,ij->i", n, wi)
    idx = np.nonzero((cos_i > 0) & (np.einsum("ij,ij->i", n, wo) > 0)
                     & np.any(E > 0, axis=1))[0]
    if idx.size == 0:
        return out
    off = 1e-4 * scene.scale
    blocked = occluded(scene.primitives, p[idx] + off * n[idx], wi[idx], dist[idx] - 2 * off,
                       1e-6 * scene.scale)
    idx = idx[~blocked]
    c, di = idx[cloth[idx]], idx[~cloth[idx]]
    if c.size:
        frame = _local(n[c], warp[c])
        wi_l = np.einsum("mij,mj->mi", frame, wi[c])
        wo_l = np.einsum("mij,mj->mi", frame, wo[c])
        f = np.empty((c.size, 3))
        for s in range(0, c.size, BRDF_BATCH):
            f[s:s + BRDF_BATCH] = fabric.eval(wi_l[s:s + BRDF_BATCH], wo_l[s:s + BRDF_BATCH])
        out[c] = f * (E[c] * cos_i[c, None])
    out[di] = (albedo[di] / np.pi * cos_i[di])[:, None] * E[di]     # diffuse: albedo / pi
    return out


def _shade(scene, fabric, o, d, rng, sky=None, table=None):
    """Radiance (m, 3) of the rays ``(o, d)``: the key light, plus the sky when the scene has
    an environment light (:mod:`reports.render.envlight`), on the rays of nonzero weight in ``sky =
    (weights (m,), uniform numbers (m, 4))`` (None: every ray, weight 1); and whether each
    ray's first hit is metered cloth (m,) (:func:`reports.render.pixelsamples.metered`:
    the cylinder's side, not its caps), as a fourth column. ``table``: the fabric's
    :class:`reports.render.brdftable.BRDFTable` for the sky (None: cosine directions alone)."""
    out = np.zeros((len(o), 4))
    hit, p, n, warp, wo, pid_h, part_h = _hits(scene, o, d)
    if hit.size == 0:
        return out
    prims = scene.primitives
    cloth = np.array([pr.material == "cloth" for pr in prims])[pid_h]
    out[hit, 3] = pixelsamples.metered(prims, pid_h, part_h)
    albedo = np.array([0.0 if pr.material == "cloth" else pr.albedo for pr in prims])[pid_h]
    rad = _key_light(scene, fabric, p, n, warp, wo, cloth, albedo, rng)
    if scene.environment is not None:
        if sky is None:
            k, w, u = np.arange(hit.size), 1.0, None
        else:
            weight, u_diffuse, u_cloth = (a[hit] for a in sky)
            k = np.nonzero(~cloth | (weight > 0))[0]
            w = np.where(cloth[k], weight[k], 1.0)[:, None]
            u = np.where(cloth[k, None], u_cloth[k],
                         np.concatenate([u_diffuse[k], u_cloth[k, 2:]], axis=1))
        frame = _local(n[k], warp[k])
        rad[k] += w * environment_radiance(
            scene.environment, prims, fabric, p[k], n[k], frame,
            np.einsum("mij,mj->mi", frame, wo[k]), cloth[k], albedo[k], rng,
            off=1e-4 * scene.scale, eps=1e-6 * scene.scale, batch=BRDF_BATCH, u=u,
            table=table)
    out[hit, :3] = rad
    return out


def cloth_coverage(scene, width, height, spp=4, seed=0, chunk=65536, metered=True):
    """The fraction of each pixel's samples (stratified jitter) whose first hit is metered
    cloth (:func:`reports.render.pixelsamples.metered`: the cylinder's side, not its caps).

    The mask of :func:`reports.render.exposure.auto_exposure` for an image rendered elsewhere
    (Mitsuba's): camera rays and the first hit alone, no shading.

    Parameters
    ----------
    scene : str or Scene
    width, height, spp : int
        Image size and samples per pixel.
    seed : int
        Seed of the jitter.
    chunk : int
        Rays traced at once.
    metered : bool
        Count the metered cloth alone (the exposure's mask); False: any cloth (the
        cylinder's caps too).

    Returns
    -------
    (height, width) float32 ndarray

    Examples
    --------
    >>> m = cloth_coverage("patch", 4, 3, spp=1)
    >>> m.shape, float(m.min())
    ((3, 4), 1.0)
    """
    check_size(width, height, spp)
    return pixelsamples.coverage(scene_of(scene, None, None), width, height, spp, seed, chunk,
                                 metered)


def _tiles(width, height, tile):
    out = []
    for y0 in range(0, height, tile):
        for x0 in range(0, width, tile):
            out.append((len(out), y0, min(y0 + tile, height), x0, min(x0 + tile, width)))
    return out


_CTX = {}


def _init_worker(ctx, parent=None):
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # the parent handles Ctrl-C
    parent = os.getppid() if parent is None else parent
    exit_with_parent(parent)
    _CTX.clear()
    _CTX.update(ctx, parent=parent)


def _render_tile(tile, ctx=None):
    if ctx is None:
        ctx = _CTX
        if os.getppid() != ctx["parent"]:   # the parent was killed: stop, do not linger
            os._exit(1)
    index, y0, y1, x0, x1 = tile
    width, height, spp = ctx["width"], ctx["height"], ctx["spp"]
    rng = np.random.default_rng([ctx["seed"], index])
    ys, xs = np.mgrid[y0:y1, x0:x1]
    npix = ys.size
    jx, jy = pixelsamples.sample_offsets(rng, npix, spp)
    sx = (xs.reshape(-1, 1) + jx).ravel()
    sy = (ys.reshape(-1, 1) + jy).ravel()
    scene = ctx["scene"]
    o, d = scene.camera.rays(sx, sy, width, height)
    sky = pixelsamples.sky_plan(rng, npix, spp, ctx["sky_spp"])
    rad = _shade(scene, ctx["fabric"], np.ascontiguousarray(o), np.ascontiguousarray(d), rng,
                 sky, ctx["table"])
    img = rad.reshape(npix, spp, 4).mean(axis=1)
    return tile, img.reshape(y1 - y0, x1 - x0, 4).astype(np.float32)


def render(scene, fabric, width=MAX_WIDTH, height=MAX_HEIGHT, spp=16, light=None,
           camera=None, seed=0, progress=True, workers=None, tile=64, mask=False,
           sky_spp=None):
    """Render a scene with cloth shaded by ``fabric``.

    Parameters
    ----------
    scene : str or Scene
        A name in :data:`reports.render.scenes.SCENES` (``curtain``, ``cylinder``, ``sphere``,
        ``patch``) or a :class:`reports.render.scenes.Scene`.
    fabric : str or object
        A preset name (``brdf.fabric(name)`` with default options) or any object with
        ``eval(wi, wo) -> (..., 3)`` f_r in 1/sr (e.g. ``brdf.fabric("velvet",
        masking=False)``).
    width, height : int
        Image size in pixels, at most 1280 x 720.
    spp : int
        Samples per pixel (stratified jitter), 1 to 4096.
    light : PointLight or DirectionalLight, optional
        Replaces the scene's light.
    camera : PinholeCamera or OrthographicCamera, optional
        Replaces the scene's camera.
    seed : int
        Seed of the jitter and light samples; the same seed gives the same image, whatever
        the number of workers.
    progress : bool
        Show a tqdm bar over the tiles.
    workers : int, optional
        Processes; default the usable cores.  1 renders in this process.
    tile : int
        Tile edge, pixels.
    sky_spp : int, optional
        Samples of the sky per pixel on cloth, 1 to ``spp`` (default ``spp``): on that many
        of a pixel's samples, spread over its area and weighted ``spp / sky_spp``, each with
        one cosine direction and one from a table of the fabric's ``f_r cos``
        (:mod:`reports.render.brdftable`, built once per render), numbers stratified over the
        pixel.  Diffuse surfaces sample the sky on every sample (one cosine direction).
        Fewer sky samples make a render of cloth faster: its two shadow rays and two
        ``fabric.eval`` calls cost most of a sample.
    mask : bool
        Also return the coverage of the metered cloth (for
        :func:`reports.render.exposure.auto_exposure`;
        :func:`reports.render.pixelsamples.metered`).

    Returns
    -------
    (height, width, 3) float32 ndarray
        Linear RGB radiance (W / (m^2 sr) for intensities in W/sr).
    (height, width) float32 ndarray
        With ``mask=True``: the fraction of each pixel's samples that hit metered cloth.

    Raises
    ------
    ValueError
        For an unknown scene or fabric, a size beyond 1280 x 720, or a bad ``spp``,
        ``tile`` or ``workers``, before any rendering.

    Notes
    -----
    Each sample's radiance is ``f_r(wi, wo) * E * cos(theta_i) * V`` (see the module
    docstring); ``wi`` and ``wo`` go to ``fabric.eval`` in the local frame (x = warp,
    y = n x warp, z = n), all lit cloth samples of a tile in one call (at most
    131072 pairs each).  Tiles run in ``workers`` processes (fork where available).

    Examples
    --------
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(np.broadcast_shapes(wi.shape, wo.shape), 0.5 / np.pi)
    >>> img = render("patch", Lambert(), width=4, height=3, spp=1, progress=False)
    >>> img.shape, img.dtype
    ((3, 4, 3), dtype('float32'))
    >>> bool(np.allclose(img, 0.5 / np.pi))   # f_r * E * cos(theta_i), E = 1, theta_i = 0
    True
    """
    ctx, workers = _checked_context(scene, fabric, width, height, spp, light, camera, seed,
                                    tile, workers, sky_spp)
    image = _render_tiles(ctx, tile, workers, progress)
    rgb = np.ascontiguousarray(image[..., :3])
    return (rgb, np.ascontiguousarray(image[..., 3])) if mask else rgb


def _checked_context(scene, fabric, width, height, spp, light, camera, seed, tile, workers,
                     sky_spp) -> tuple[dict, int]:
    """Check :func:`render`'s arguments, in its order, before any work; return the tiles'
    shared context (scene, fabric, size, samples, seed) and the number of workers."""
    check_size(width, height, spp)
    scene = scene_of(scene, light, camera)
    fabric = resolve_fabric(fabric)
    workers = check_workers(tile, workers)
    probe(fabric)
    sky_spp = spp if sky_spp is None else sky_spp
    if isinstance(sky_spp, bool) or not isinstance(sky_spp, (int, np.integer)) \
            or not 1 <= sky_spp <= spp:
        raise ValueError(f"sky_spp={sky_spp!r} must be an integer from 1 to spp={spp}")
    # the sky's sampler, tabulated once here (the workers share it by fork)
    table = BRDFTable(fabric, batch=BRDF_BATCH) if scene.environment is not None else None
    ctx = {"scene": scene, "fabric": fabric, "width": int(width), "height": int(height),
           "spp": int(spp), "seed": int(seed), "sky_spp": int(sky_spp), "table": table}
    return ctx, workers


def _render_tiles(ctx, tile, workers, progress) -> np.ndarray:
    """The (height, width, 4) image of ``ctx``'s scene: RGB and cloth coverage, tile by tile,
    in this process (``workers == 1``) or in a pool."""
    width, height = ctx["width"], ctx["height"]
    tiles = _tiles(width, height, tile)
    image = np.zeros((height, width, 4), np.float32)
    workers = min(workers, len(tiles))
    new_bar = functools.partial(progress_bar, len(tiles),
                                desc=f"render {ctx['scene'].name or 'scene'}",
                                unit="tile", enabled=progress)
    if workers == 1:
        with new_bar() as bar:
            for t in tiles:
                _paste(image, _render_tile(t, ctx))
                bar.update()
    else:
        _render_pool(image, tiles, ctx, workers, new_bar)
    return image


def _paste(image, done) -> None:
    """Put a rendered tile ``((index, y0, y1, x0, x1), pixels)`` into ``image``."""
    (_, y0, y1, x0, x1), img = done
    image[y0:y1, x0:x1] = img


def _render_pool(image, tiles, ctx, workers, new_bar) -> None:
    """Render ``tiles`` in ``workers`` processes into ``image``; ``new_bar()`` makes the
    progress bar, once the workers are started."""
    # fork (where available) shares the scene and fabric without pickling; the workers are
    # started by the first submit, before this process starts any thread of its own (tqdm)
    methods = multiprocessing.get_all_start_methods()
    mp = multiprocessing.get_context("fork" if "fork" in methods else None)
    pool = ProcessPoolExecutor(workers, mp_context=mp, initializer=_init_worker,
                               initargs=(ctx, os.getpid()))
    try:
        futures = [pool.submit(_render_tile, t) for t in tiles]
        with new_bar() as bar:
            for fut in as_completed(futures):
                _paste(image, fut.result())
                bar.update()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
