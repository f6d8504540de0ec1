"""Quadrature rules of the albedo integrals, and the weighted sums of f_r over them.

``threads``: per thread, composite Gauss-Legendre in the thread's own (beta, chi) angles;
``sphere``: Gauss-Legendre in mu = cos(theta) times the trapezoid rule in phi; ``rqmc``:
Owen-scrambled Sobol points over either parametrisation (see :mod:`analysis.albedo`).
"""

from __future__ import annotations

import math

import numpy as np

from analysis.lazy import qmc, stats
from brdf.protocols import ThreadedBRDF

__all__ = ["thread_axes", "gl_composite", "thread_dirs", "threads_rule", "sphere_rule",
           "eval_weighted", "gauss_level", "rqmc"]

#: Gauss-Legendre points per panel of the composite rules.
_GL_ORDER = 4
#: Most (wi, wo) pairs passed to one ``eval`` call (bounds the memory of the model).
_CHUNK_PAIRS = 1 << 15
#: Geometric grading of the panels next to the horizon: levels and ratio.
_GRADE_LEVELS = 5
_GRADE_RATIO = 0.15
#: Panels along (beta, chi) at level 0 of the ``threads`` rule; each level doubles both.
#: Level -1 (a cheap first estimate) keeps a panel edge at beta = 90 degrees, where the
#: thread's horizon layer vanishes.
_THREADS_PANELS = (6, 12)
_THREADS_PANELS_M1 = (4, 6)
#: Panels along mu and points along phi at level 0 of the ``sphere`` rule.
_SPHERE_PANELS = (4, 16)


def gl_composite(a: float, b: float, panels: int, order: int = _GL_ORDER,
                  grade: tuple[bool, bool] = (False, False)):
    """Nodes and weights of composite Gauss-Legendre on [a, b].

    ``grade`` refines the first and/or last panel geometrically (widths h r^k, ..., h r,
    ratio r = _GRADE_RATIO, _GRADE_LEVELS levels) to resolve boundary layers at the horizon.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(a, b, panels + 1)
    h = (b - a) / panels
    geo = h * _GRADE_RATIO ** np.arange(_GRADE_LEVELS, 0, -1)
    if grade[0]:
        edges = np.concatenate([[a], a + geo, edges[1:]])
    if grade[1]:
        edges = np.concatenate([edges[:-1], (b - geo)[::-1], [b]])
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    nodes = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    weights = (half[:, None] * w[None, :]).ravel()
    return nodes, weights


def thread_axes(brdf) -> tuple[float, ...] | None:
    """In-plane azimuths (radians, from +x toward +y) of a fabric's thread tangents.

    Thread 1 (the warp) runs along +x turned by the fabric rotation, thread 2 along +y
    turned by it (MODEL.md, Frame). Returns None for a BRDF without ``eval_threads``.

    Parameters
    ----------
    brdf : object
        Any BRDF; a fabric exposes ``eval_threads`` and ``options['rotation']``.

    Returns
    -------
    tuple of float or None
        One azimuth per thread, radians.

    Examples
    --------
    >>> thread_axes(object()) is None
    True
    """
    if not isinstance(brdf, ThreadedBRDF):
        return None
    opts = getattr(brdf, "options", None) or {}
    rot = float(opts.get("rotation", 0.0))
    n = len(getattr(brdf, "threads", (None, None)))
    return tuple(rot + j * math.pi / 2 for j in range(n))


def thread_dirs(axis: float, beta: np.ndarray, chi: np.ndarray):
    """Directions and solid-angle x cosine weights on a thread's (beta, chi) grid points."""
    t0 = np.array([math.cos(axis), math.sin(axis), 0.0])
    nz = np.array([0.0, 0.0, 1.0])
    b = np.cross(nz, t0)
    sb, cb = np.sin(beta), np.cos(beta)
    w = (cb[:, None] * b + (sb * np.cos(chi))[:, None] * nz + (sb * np.sin(chi))[:, None] * t0)
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    # dw = sin(beta) dbeta dchi ; cosine factor n.w = sin(beta) cos(chi)
    jac = sb * sb * np.cos(chi)
    return w, jac


def threads_rule(axis: float, level: int, scale=(1, 1)):
    """Directions (M, 3) and weights (M,) of the ``threads`` rule of one thread at a level."""
    pb, pc = _THREADS_PANELS if level >= 0 else _THREADS_PANELS_M1
    f = 2 ** max(level, 0)
    beta, wb = gl_composite(0.0, math.pi, pb * f * scale[0])
    chi, wc = gl_composite(-math.pi / 2, math.pi / 2, pc * f * scale[1],
                            grade=(True, True))
    B, C = np.meshgrid(beta, chi, indexing="ij")
    W = np.outer(wb, wc).ravel()
    w, jac = thread_dirs(axis, B.ravel(), C.ravel())
    return w, W * jac


def sphere_rule(level: int, scale=(1, 1)):
    """Directions (M, 3) and weights (M,) of the ``sphere`` rule at a level."""
    pm, nphi = _SPHERE_PANELS
    f = 2.0 ** level
    mu, wm = gl_composite(0.0, 1.0, int(pm * f * scale[0]), grade=(True, False))
    n_phi = int(nphi * f * scale[1])
    phi = (np.arange(n_phi) + 0.5) * (2 * math.pi / n_phi)
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(np.clip(1.0 - M * M, 0.0, None))
    w = np.stack([s * np.cos(P), s * np.sin(P), M], axis=-1).reshape(-1, 3)
    # dw = dmu dphi ; cosine factor mu
    W = (np.outer(wm, np.full(n_phi, 2 * math.pi / n_phi)) * M).ravel()
    return w, W


# --------------------------------------------------------------------------- evaluation
def eval_weighted(fn, fixed: np.ndarray, pts: np.ndarray, wts: np.ndarray, swap: bool,
                   thread: int | None) -> np.ndarray:
    """sum_m wts[m] f(pts[m], fixed[k]) (or swapped) for each fixed direction: (K, 3)."""
    K, M = fixed.shape[0], pts.shape[0]
    out = np.zeros((K, 3))
    per = max(1, _CHUNK_PAIRS // max(M, 1))
    mchunk = min(M, _CHUNK_PAIRS)
    for k0 in range(0, K, per):
        kk = fixed[k0:k0 + per]
        for m0 in range(0, M, mchunk):
            p = pts[m0:m0 + mchunk]
            a = np.broadcast_to(p[None, :, :], (kk.shape[0],) + p.shape)
            c = np.broadcast_to(kk[:, None, :], a.shape)
            wi, wo = (c, a) if swap else (a, c)
            wi = np.ascontiguousarray(wi).reshape(-1, 3)
            wo = np.ascontiguousarray(wo).reshape(-1, 3)
            if thread is None:
                f = np.asarray(fn(wi, wo), dtype=np.float64)
            else:
                f = np.asarray(fn(wi, wo), dtype=np.float64)[..., thread, :]
            f = f.reshape(kk.shape[0], p.shape[0], 3)
            out[k0:k0 + per] += np.einsum("kmc,m->kc", f, wts[m0:m0 + mchunk])
    return out


def gauss_level(brdf, fixed, swap, method, level, axes, scale):
    """Albedo at one resolution level; returns (K, 3) values and the pair count."""
    if method == "threads":
        total = np.zeros((fixed.shape[0], 3))
        n = 0
        for j, ax in enumerate(axes):
            pts, wts = threads_rule(ax, level, scale)
            total += eval_weighted(brdf.eval_threads, fixed, pts, wts, swap, j)
            n += pts.shape[0] * fixed.shape[0]
        return total, n
    pts, wts = sphere_rule(level, scale)
    return eval_weighted(brdf.eval, fixed, pts, wts, swap, None), pts.shape[0] * fixed.shape[0]


def rqmc(brdf, fixed, swap, axes, rule, m, n_scrambles, seed):
    """Mean of ``n_scrambles`` scrambled-Sobol albedo estimates (K, 3), the half-width of
    their 99 % Student-t interval (K, 3), and the pair count."""
    rng = np.random.default_rng(seed)
    ests = np.zeros((n_scrambles, fixed.shape[0], 3))
    n = 0
    for s in range(n_scrambles):
        if rule == "threads":
            for j, ax in enumerate(axes):
                u = qmc.Sobol(2, scramble=True, seed=rng).random_base2(m)
                beta, chi = math.pi * u[:, 0], math.pi * (u[:, 1] - 0.5)
                w, jac = thread_dirs(ax, beta, chi)
                wts = jac * (math.pi * math.pi / u.shape[0])
                ests[s] += eval_weighted(brdf.eval_threads, fixed, w, wts, swap, j)
                n += u.shape[0] * fixed.shape[0]
        else:
            u = qmc.Sobol(2, scramble=True, seed=rng).random_base2(m)
            mu, phi = u[:, 0], 2 * math.pi * u[:, 1]
            s_ = np.sqrt(np.clip(1 - mu * mu, 0, None))
            w = np.stack([s_ * np.cos(phi), s_ * np.sin(phi), mu], axis=-1)
            wts = mu * (2 * math.pi / u.shape[0])
            ests[s] += eval_weighted(brdf.eval, fixed, w, wts, swap, None)
            n += u.shape[0] * fixed.shape[0]
    mean = ests.mean(axis=0)
    se = ests.std(axis=0, ddof=1) / math.sqrt(n_scrambles)
    return mean, stats.t.ppf(0.995, n_scrambles - 1) * se, n
