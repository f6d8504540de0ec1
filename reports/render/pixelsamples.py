"""Where a pixel's samples go: the camera jitter, the sky's uniform numbers, and the cloth's
coverage of the pixels (camera rays and first hits alone), for :mod:`reports.render.engine`.

The coverage counts the *metered* cloth (:func:`metered`): the hits on cloth that set the
automatic exposure, on every part of a primitive except where it names its
``metered_parts`` (the cylinder: its side, not its caps)."""

from __future__ import annotations

import numpy as np

from reports.render.tracing import intersect

__all__ = ["sample_offsets", "lhs", "sky_plan", "metered", "coverage"]


def sample_offsets(rng, npix, spp):
    """Stratified (n-rooks) offsets in [0, 1)^2, shape (npix, spp) each."""
    k = np.broadcast_to(np.arange(spp), (npix, spp))
    jx = (k + rng.random((npix, spp))) / spp
    jy = (rng.permuted(k, axis=1) + rng.random((npix, spp))) / spp
    return jx, jy


def lhs(rng, npix, n, dims=4):
    """Uniform numbers (npix, n, dims) stratified over each pixel's ``n`` samples in every
    dimension (Latin hypercube)."""
    strata = np.broadcast_to(np.arange(n), (npix, n))
    return np.stack([(rng.permuted(strata, axis=1) + rng.random((npix, n))) / n
                     for _ in range(dims)], axis=-1)


def sky_plan(rng, npix, spp, sky_spp):
    """How each of a pixel's ``spp`` samples samples the sky: on diffuse surfaces every
    sample (a cosine direction costs one shadow ray), numbers stratified over the pixel's
    samples; on cloth ``sky_spp`` samples spread over the pixel's x strata, weighted
    ``spp / sky_spp``, numbers stratified over them.  Returns the cloth weights (npix * spp,)
    and the numbers (npix * spp, 4) of diffuse and of cloth hits."""
    k = (np.arange(sky_spp) * spp) // sky_spp
    weight = np.zeros((npix, spp))
    weight[:, k] = spp / sky_spp
    u_cloth = np.zeros((npix, spp, 4))
    u_cloth[:, k] = lhs(rng, npix, sky_spp)
    return weight.ravel(), lhs(rng, npix, spp, 2).reshape(-1, 2), u_cloth.reshape(-1, 4)


def metered(prims, pid, part) -> np.ndarray:
    """Whether each hit (primitive ``pid``, part ``part``; ``pid < 0``: none) is metered
    cloth: cloth, on a part in its primitive's ``metered_parts`` (every part where it has
    none).

    Examples
    --------
    >>> from reports.render.scenes import make_scene
    >>> prims = make_scene("cylinder").primitives      # cylinder (side, top, bottom), floor
    >>> metered(prims, np.array([0, 0, 1, -1]), np.array([0, 1, 0, 0])).tolist()
    [True, False, False, False]
    """
    pid, part = np.asarray(pid), np.asarray(part)
    out = np.zeros(pid.shape, bool)
    for k, prim in enumerate(prims):
        if prim.material != "cloth":
            continue
        sel = pid == k
        parts = getattr(prim, "metered_parts", None)
        out |= sel if parts is None else sel & np.isin(part, parts)
    return out


def coverage(scene, width, height, spp, seed, chunk, metered_only=True):
    """The fraction of each pixel's ``spp`` samples whose first hit is metered cloth
    (:func:`metered`; any cloth with ``metered_only=False``), (height, width) float32:
    :func:`reports.render.engine.cloth_coverage` (which checks its arguments)."""
    rng = np.random.default_rng(seed)
    cloth = np.array([pr.material == "cloth" for pr in scene.primitives])
    ys, xs = np.mgrid[0:height, 0:width]
    jx, jy = sample_offsets(rng, ys.size, spp)
    sx = (xs.reshape(-1, 1) + jx).ravel()
    sy = (ys.reshape(-1, 1) + jy).ravel()
    hits = np.zeros(sx.size)
    for s in range(0, sx.size, chunk):
        o, d = scene.camera.rays(sx[s:s + chunk], sy[s:s + chunk], width, height)
        t, pid, part = intersect(scene.primitives, np.ascontiguousarray(o),
                                 np.ascontiguousarray(d), 1e-6 * scene.scale)
        pid = np.where(np.isfinite(t), pid, -1)
        hits[s:s + chunk] = metered(scene.primitives, pid, part) if metered_only else \
            cloth[np.maximum(pid, 0)] & (pid >= 0)
    return hits.reshape(height, width, spp).mean(axis=2).astype(np.float32)
