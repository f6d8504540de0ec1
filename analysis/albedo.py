"""Directional and hemispherical albedo of any BRDF, with an honest error estimate.

The directional albedo for a fixed viewing direction wo is

    rho(wo) = integral over the upper hemisphere of f_r(wi, wo) cos(theta_i) dwi,

the radiance seen from wo when the surface sits in a uniform white environment of unit
radiance (the *white furnace*). With the roles swapped (``swap=True``) it is

    rho'(wi) = integral of f_r(wi, wo) cos(theta_o) dwo,

the fraction of the energy arriving from wi that leaves the surface: energy conservation in
the strict sense is rho'(wi) <= 1. For a reciprocal BRDF the two are equal.

Two quadratures are used.

* ``"threads"`` (used when the BRDF has ``eval_threads``, e.g. a microcylinder fabric):
  each thread's share of f_r is integrated separately in that thread's own coordinates. For
  a thread with in-plane tangent t0 and b = n x t0, a direction is written
  w = cos(beta) b + sin(beta) (cos(chi) n + sin(chi) t0), beta in [0, pi] the angle from
  b, chi in [-pi/2, pi/2] the angle about b measured from n toward t0; the upper hemisphere is
  exactly that rectangle and dw = sin(beta) dbeta dchi. Every tangent sample of the thread
  lies in the (t0, n) plane, so its azimuth psi equals chi + alpha, its masking and
  reweighting kinks sit on lines of constant chi, and its specular cone runs along lines of
  nearly constant chi: a product rule (composite Gauss-Legendre in both angles) resolves
  the narrow lobes (gamma_s = 2.5 degrees) with a few thousand points. Summing the thread
  integrals is exact, since the integral of a sum is the sum of the integrals.
* ``"sphere"`` (any BRDF): composite Gauss-Legendre in mu = cos(theta) on [0, 1] times the
  trapezoid rule in phi (periodic, hence spectrally accurate for smooth integrands). It is
  exact for a Lambertian BRDF at every resolution.

Error estimate: the rule is evaluated at two resolutions, the finer having twice as many
panels along each angle; ``value`` is the finer result and ``error`` the absolute
difference |fine - coarse|, which for a convergent rule bounds the error of the finer one
(the coarse error is larger by a factor of 4 or more for the kinks of the masking terms,
much more on smooth parts). Resolution doubles until ``error <= tol`` or ``max_level``.
Alternatively ``method="rqmc"`` averages independent Owen-scrambled Sobol estimates
(scipy.stats.qmc) over the same parametrisations and reports the half-width of a 99 %
Student-t interval.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import math
import os
import pickle
from typing import Any

import numpy as np

from brdf.protocols import BRDF, ThreadedBRDF
from scipy import stats
from scipy.stats import qmc

__all__ = [
    "AlbedoResult",
    "AlbedoCurve",
    "HemisphericalAlbedo",
    "albedo",
    "albedo_curve",
    "albedo_hemispherical",
    "thread_axes",
    "run_tasks",
]

#: Gauss-Legendre points per panel of the composite rules.
_GL_ORDER = 4
#: Most (wi, wo) pairs passed to one ``eval`` call (bounds the memory of the model).
_CHUNK_PAIRS = 1 << 15
#: Factor on |fine - coarse| in the gauss error estimate.
_SAFETY = 2.0
#: The same factor when the coarse level is -1 (further from the asymptotic regime).
_SAFETY_M1 = 3.0
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


# --------------------------------------------------------------------------- results
@dataclasses.dataclass(frozen=True, eq=False)
class AlbedoResult:
    """Directional albedo at one or more fixed directions.

    Attributes
    ----------
    value : ndarray, shape (..., 3)
        Albedo per RGB channel (dimensionless).
    error : ndarray, shape (..., 3)
        Estimated absolute error bound of ``value`` (see the module notes).
    direction : ndarray, shape (..., 3)
        The fixed direction: wo when ``swap`` is False, wi when True.
    swap : bool
        False: integral over wi of f_r cos(theta_i); True: integral over wo of f_r cos(theta_o).
    method : str
        ``"threads"``, ``"sphere"`` or ``"rqmc"`` (with the rule it scrambled).
    evals : int
        Number of (wi, wo) pairs at which the BRDF was evaluated.
    level : ndarray of int, shape (...)
        Finest level used per direction (gauss methods; -1 for rqmc).
    """

    value: np.ndarray
    error: np.ndarray
    direction: np.ndarray
    swap: bool
    method: str
    evals: int
    level: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {
            "value": self.value.tolist(), "error": self.error.tolist(),
            "direction": self.direction.tolist(), "swap": self.swap,
            "method": self.method, "evals": int(self.evals), "level": self.level.tolist(),
        }


@dataclasses.dataclass(frozen=True, eq=False)
class AlbedoCurve:
    """Albedo over a (theta, phi) sweep of the fixed direction.

    Attributes
    ----------
    theta_deg, phi_deg : ndarray, shapes (T,), (P,)
        Polar angle from the normal and azimuth from the warp (+x), degrees.
    value, error : ndarray, shape (T, P, 3)
        Albedo and its error bound per RGB channel.
    swap : bool
        As in :class:`AlbedoResult`.
    method : str
        Quadrature used.
    evals : int
        BRDF evaluations in total.
    seconds : float
        Wall time of the computation.
    """

    theta_deg: np.ndarray
    phi_deg: np.ndarray
    value: np.ndarray
    error: np.ndarray
    swap: bool
    method: str
    evals: int
    seconds: float

    def max(self) -> dict[str, Any]:
        """The largest albedo over the sweep and channels, where it occurs, and its error.

        Returns
        -------
        dict
            ``value``, ``error``, ``theta_deg``, ``phi_deg``, ``channel`` (0, 1, 2 = R, G, B).
        """
        idx = np.unravel_index(int(np.argmax(self.value)), self.value.shape)
        return {
            "value": float(self.value[idx]), "error": float(self.error[idx]),
            "theta_deg": float(self.theta_deg[idx[0]]), "phi_deg": float(self.phi_deg[idx[1]]),
            "channel": int(idx[2]),
        }

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {
            "theta_deg": self.theta_deg.tolist(), "phi_deg": self.phi_deg.tolist(),
            "value": self.value.tolist(), "error": self.error.tolist(), "swap": self.swap,
            "method": self.method, "evals": int(self.evals), "seconds": float(self.seconds),
            "max": self.max(),
        }


@dataclasses.dataclass(frozen=True, eq=False)
class HemisphericalAlbedo:
    """Hemispherical-hemispherical albedo (1/pi) integral of rho(w) cos(theta) dw.

    Attributes
    ----------
    value, error : ndarray, shape (3,)
        Per RGB channel; ``error`` adds the inner albedo errors (weighted) and the outer
        quadrature's two-resolution difference.
    evals : int
        BRDF evaluations in total.
    """

    value: np.ndarray
    error: np.ndarray
    evals: int

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {"value": self.value.tolist(), "error": self.error.tolist(),
                "evals": int(self.evals)}


# --------------------------------------------------------------------------- rules
def _gl_composite(a: float, b: float, panels: int, order: int = _GL_ORDER,
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


def _thread_dirs(axis: float, beta: np.ndarray, chi: np.ndarray):
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


def _threads_rule(axis: float, level: int, scale=(1, 1)):
    pb, pc = _THREADS_PANELS if level >= 0 else _THREADS_PANELS_M1
    f = 2 ** max(level, 0)
    beta, wb = _gl_composite(0.0, math.pi, pb * f * scale[0])
    chi, wc = _gl_composite(-math.pi / 2, math.pi / 2, pc * f * scale[1],
                            grade=(True, True))
    B, C = np.meshgrid(beta, chi, indexing="ij")
    W = np.outer(wb, wc).ravel()
    w, jac = _thread_dirs(axis, B.ravel(), C.ravel())
    return w, W * jac


def _sphere_rule(level: int, scale=(1, 1)):
    pm, nphi = _SPHERE_PANELS
    f = 2.0 ** level
    mu, wm = _gl_composite(0.0, 1.0, int(pm * f * scale[0]), grade=(True, False))
    n_phi = int(nphi * f * scale[1])
    phi = (np.arange(n_phi) + 0.5) * (2 * math.pi / n_phi)
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(np.clip(1.0 - M * M, 0.0, None))
    w = np.stack([s * np.cos(P), s * np.sin(P), M], axis=-1).reshape(-1, 3)
    # dw = dmu dphi ; cosine factor mu
    W = (np.outer(wm, np.full(n_phi, 2 * math.pi / n_phi)) * M).ravel()
    return w, W


# --------------------------------------------------------------------------- evaluation
def _eval_weighted(fn, fixed: np.ndarray, pts: np.ndarray, wts: np.ndarray, swap: bool,
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


def _gauss_level(brdf, fixed, swap, method, level, axes, scale):
    """Albedo at one resolution level; returns (K, 3) values and the pair count."""
    if method == "threads":
        total = np.zeros((fixed.shape[0], 3))
        n = 0
        for j, ax in enumerate(axes):
            pts, wts = _threads_rule(ax, level, scale)
            total += _eval_weighted(brdf.eval_threads, fixed, pts, wts, swap, j)
            n += pts.shape[0] * fixed.shape[0]
        return total, n
    pts, wts = _sphere_rule(level, scale)
    return _eval_weighted(brdf.eval, fixed, pts, wts, swap, None), pts.shape[0] * fixed.shape[0]


def _rqmc(brdf, fixed, swap, axes, rule, m, n_scrambles, seed):
    rng = np.random.default_rng(seed)
    ests = np.zeros((n_scrambles, fixed.shape[0], 3))
    n = 0
    for s in range(n_scrambles):
        if rule == "threads":
            for j, ax in enumerate(axes):
                u = qmc.Sobol(2, scramble=True, seed=rng).random_base2(m)
                beta, chi = math.pi * u[:, 0], math.pi * (u[:, 1] - 0.5)
                w, jac = _thread_dirs(ax, beta, chi)
                wts = jac * (math.pi * math.pi / u.shape[0])
                ests[s] += _eval_weighted(brdf.eval_threads, fixed, w, wts, swap, j)
                n += u.shape[0] * fixed.shape[0]
        else:
            u = qmc.Sobol(2, scramble=True, seed=rng).random_base2(m)
            mu, phi = u[:, 0], 2 * math.pi * u[:, 1]
            s_ = np.sqrt(np.clip(1 - mu * mu, 0, None))
            w = np.stack([s_ * np.cos(phi), s_ * np.sin(phi), mu], axis=-1)
            wts = mu * (2 * math.pi / u.shape[0])
            ests[s] += _eval_weighted(brdf.eval, fixed, w, wts, swap, None)
            n += u.shape[0] * fixed.shape[0]
    mean = ests.mean(axis=0)
    se = ests.std(axis=0, ddof=1) / math.sqrt(n_scrambles)
    return mean, stats.t.ppf(0.995, n_scrambles - 1) * se, n


def _check_dirs(name, w) -> np.ndarray:
    arr = np.asarray(w, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3); got {arr.shape}")
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    if not np.all(np.isfinite(norm) & (norm > 0)):
        raise ValueError(f"{name} must be finite non-zero vectors")
    return arr / norm


def albedo(brdf, wo, *, swap: bool = False, method: str = "auto", tol: float = 5e-4,
           rtol: float = 1e-3, min_level: int = 0, max_level: int = 3, scale=(1, 1), n_scrambles: int = 8,
           m: int = 12, seed=0, rel_floor: float = 1e-4,
           abs_floor: float = 2e-5) -> AlbedoResult:
    """Directional albedo of a BRDF at one or more fixed directions.

    Parameters
    ----------
    brdf : object
        Anything with ``eval(wi, wo) -> (..., 3)`` in 1/sr; a fabric's ``eval_threads``
        is used when present.
    wo : array_like, shape (..., 3)
        Fixed unit direction(s) in the local frame (n = +z): the viewer when ``swap`` is
        False, the light when True. Directions with z <= 0 give 0.
    swap : bool, default False
        False: rho(wo) = integral f_r(wi, wo) cos(theta_i) dwi (white furnace).
        True: rho'(wi) = integral f_r(wi, wo) cos(theta_o) dwo (energy leaving for light
        from wi), with ``wo`` holding wi.
    method : {"auto", "threads", "sphere", "rqmc"}, default "auto"
        Quadrature: "auto" is "threads" for BRDFs with ``eval_threads``, else "sphere".
        "rqmc" scrambles whichever of the two "auto" would pick.
    tol, rtol : float, default 5e-4, 1e-3
        Target error for the gauss rules: the resolution doubles until every channel's error
        is below max(tol, rtol |value|) or ``max_level`` is reached.
    min_level, max_level : int, default 0, 3
        Range of refinement levels (level L has 2**L times the level-0 panels per angle,
        L >= -1; the reported value is the finer of levels L-1 and L, so at least level
        min_level + 1 is used). Level 0 against level -1 is about 3 times cheaper than
        level 1 against level 0, for quick scans.
    scale : tuple of int, default (1, 1)
        Extra panel multipliers along (beta or mu, chi or phi).
    n_scrambles, m : int
        For "rqmc": independent scrambles, and 2**m Sobol points per scramble (per thread).
    seed : int or numpy.random.Generator
        Seeds the scrambles ("rqmc" only).
    rel_floor, abs_floor : float, default 1e-4, 2e-5
        Relative and absolute floors added to the gauss error estimate (see Notes).

    Returns
    -------
    AlbedoResult
        ``value`` and ``error`` of shape (..., 3).

    Raises
    ------
    ValueError
        For a bad method, direction array or tolerance.

    Notes
    -----
    See the module docstring for the two rules. The gauss error estimate is
    ``2 |fine - coarse| + rel_floor |fine| + abs_floor`` (factor 3 when the coarse level is
    -1): the factors and the floors cover the
    pre-asymptotic cases where two levels agree by chance (seen on the cloth presets at the
    1e-5 level, from the kinks of M and P and the boundary layers of 1/Q at the horizon).

    Examples
    --------
    >>> import numpy as np
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    ...         return np.where(up[..., None], np.array([0.2, 0.5, 0.8]) / np.pi, 0.0)
    >>> r = albedo(Lambert(), [0.0, 0.6, 0.8])
    >>> np.round(r.value, 12).tolist(), bool(np.all(r.error < 1e-3))
    ([0.2, 0.5, 0.8], True)
    """
    if method not in ("auto", "threads", "sphere", "rqmc"):
        raise ValueError(f"method must be 'auto', 'threads', 'sphere' or 'rqmc'; got {method!r}")
    if not (tol > 0):
        raise ValueError(f"tol must be > 0; got {tol}")
    if not (-1 <= min_level <= max_level):
        raise ValueError(f"need -1 <= min_level <= max_level; got {min_level}, {max_level}")
    if not (rtol >= 0):
        raise ValueError(f"rtol must be >= 0; got {rtol}")
    if not isinstance(brdf, BRDF):
        raise ValueError(f"brdf must have an eval(wi, wo) method; got {type(brdf).__name__}")
    fixed = _check_dirs("wo" if not swap else "wi", wo)
    shape = fixed.shape[:-1]
    flat = fixed.reshape(-1, 3)
    axes = thread_axes(brdf)
    rule = "threads" if axes is not None else "sphere"
    if method == "threads" and axes is None:
        raise ValueError("method='threads' needs a BRDF with eval_threads")
    if method == "rqmc":
        v, e, n = _rqmc(brdf, flat, swap, axes, rule, m, n_scrambles, seed)
        lev = np.full(flat.shape[0], -1)
        name = f"rqmc-{rule}"
    else:
        rule = rule if method == "auto" else method
        name = rule
        K = flat.shape[0]
        v = np.zeros((K, 3))
        e = np.full((K, 3), np.inf)
        lev = np.zeros(K, dtype=int)
        n = 0
        prev, n_ = _gauss_level(brdf, flat, swap, rule, min_level, axes, scale)
        n += n_
        todo = np.arange(K)
        for level in range(min_level + 1, max_level + 1):
            cur, n_ = _gauss_level(brdf, flat[todo], swap, rule, level, axes, scale)
            n += n_
            safety = _SAFETY if level > 0 else _SAFETY_M1
            err = safety * np.abs(cur - prev) + rel_floor * np.abs(cur) + abs_floor
            v[todo], e[todo], lev[todo] = cur, err, level
            keep = np.any(err > np.maximum(tol, rtol * np.abs(cur)), axis=-1)
            todo, prev = todo[keep], cur[keep]
            if todo.size == 0:
                break
        if max_level == min_level:  # single level: no error estimate possible
            v[:] = prev
            lev[:] = min_level
    return AlbedoResult(value=v.reshape(shape + (3,)), error=e.reshape(shape + (3,)),
                        direction=fixed, swap=bool(swap), method=name, evals=int(n),
                        level=lev.reshape(shape))


def _albedo_chunk(brdf, dirs, kwargs):
    r = albedo(brdf, dirs, **kwargs)
    return r.value, r.error, r.evals


def _default_workers() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def run_tasks(tasks, workers: int | None = None, *, chunk: int = 8, progress=None):
    """Run many albedo computations, in parallel processes when possible.

    Parameters
    ----------
    tasks : sequence of (brdf, dirs, kwargs)
        ``dirs`` of shape (N, 3); ``kwargs`` passed to :func:`albedo`.
    workers : int, optional
        Processes (default: up to 2, the cores of the target machine). Tasks whose BRDF cannot
        be pickled run in this process.
    chunk : int, default 8
        Directions per job (jobs interleave directions so grazing and normal ones mix).
    progress : callable, optional
        Called with the number of directions finished after each job.

    Returns
    -------
    list of (value, error, evals)
        value and error of shape (N, 3) per task, in task order.
    """
    workers = _default_workers() if workers is None else int(workers)
    results = [[np.zeros((np.asarray(d).shape[0], 3)), np.zeros((np.asarray(d).shape[0], 3)), 0]
               for _, d, _ in tasks]
    jobs, local = [], []
    for t, (brdf, dirs, kwargs) in enumerate(tasks):
        dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
        N = dirs.shape[0]
        n_jobs = max(1, math.ceil(N / chunk))
        ok = workers > 1
        if ok:
            try:
                pickle.dumps(brdf)
            except Exception:  # noqa: BLE001 - unpicklable BRDFs run here
                ok = False
        for i in range(n_jobs):
            idx = np.arange(i, N, n_jobs)
            (jobs if ok else local).append((t, idx, brdf, dirs[idx], kwargs))

    def store(job, res):
        t, idx = job[0], job[1]
        results[t][0][idx], results[t][1][idx] = res[0], res[1]
        results[t][2] += res[2]
        if progress is not None:
            progress(len(idx))

    for job in local:
        store(job, _albedo_chunk(*job[2:]))
    if jobs:
        # the dearest jobs first (more directions first), for a balanced finish
        with concurrent.futures.ProcessPoolExecutor(max_workers=workers) as ex:
            futs = {ex.submit(_albedo_chunk, *job[2:]): job for job in jobs}
            try:
                for fut in concurrent.futures.as_completed(futs):
                    store(futs[fut], fut.result())
            except BaseException:
                for f in futs:
                    f.cancel()
                raise
    return [tuple(r) for r in results]


def _map_chunks(brdf, dirs: np.ndarray, kwargs: dict, workers: int | None):
    """Albedo over the rows of dirs (N, 3), in parallel processes when possible."""
    return run_tasks([(brdf, dirs, kwargs)], workers)[0]


def albedo_curve(brdf, theta_deg, phi_deg=0.0, *, swap: bool = False, workers: int | None = None,
                 **kwargs) -> AlbedoCurve:
    """Albedo over a sweep of polar angle and azimuth of the fixed direction.

    Parameters
    ----------
    brdf : object
        Any BRDF (see :func:`albedo`).
    theta_deg : array_like, shape (T,)
        Polar angles from the normal, degrees, in [0, 90].
    phi_deg : float or array_like, shape (P,), default 0
        Azimuths from the warp (+x) toward +y, degrees.
    swap : bool, default False
        As in :func:`albedo`.
    workers : int, optional
        Processes to use (default: up to 2). BRDFs that cannot be pickled run serially.
    **kwargs
        Passed to :func:`albedo` (method, tol, max_level, ...).

    Returns
    -------
    AlbedoCurve
        ``value`` and ``error`` of shape (T, P, 3).

    Examples
    --------
    >>> import numpy as np
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(np.broadcast(wi, wo).shape, 0.5 / np.pi)
    >>> c = albedo_curve(Lambert(), [0, 45, 89], [0, 90], workers=1)
    >>> c.value.shape, bool(np.allclose(c.value, 0.5))
    ((3, 2, 3), True)
    """
    import time

    t0 = time.perf_counter()
    th = np.atleast_1d(np.asarray(theta_deg, dtype=np.float64))
    ph = np.atleast_1d(np.asarray(phi_deg, dtype=np.float64))
    if th.ndim != 1 or ph.ndim != 1:
        raise ValueError("theta_deg and phi_deg must be scalars or 1-D")
    if np.any((th < 0) | (th > 90)) or not np.all(np.isfinite(th)):
        raise ValueError(f"theta_deg must lie in [0, 90] degrees; got {th.tolist()}")
    T, P = np.meshgrid(np.radians(th), np.radians(ph), indexing="ij")
    s = np.sin(T)
    dirs = np.stack([s * np.cos(P), s * np.sin(P), np.cos(T)], axis=-1).reshape(-1, 3)
    v, e, n = _map_chunks(brdf, dirs, dict(kwargs, swap=swap), workers)
    method = kwargs.get("method", "auto")
    if method == "auto":
        method = "threads" if thread_axes(brdf) is not None else "sphere"
    return AlbedoCurve(theta_deg=th, phi_deg=ph, value=v.reshape(th.size, ph.size, 3),
                       error=e.reshape(th.size, ph.size, 3), swap=bool(swap), method=method,
                       evals=int(n), seconds=time.perf_counter() - t0)


def albedo_hemispherical(brdf, *, n_theta: int = 8, n_phi: int = 8, swap: bool = False,
                         workers: int | None = None, **kwargs) -> HemisphericalAlbedo:
    """Hemispherical-hemispherical albedo (1/pi) integral of rho(w) cos(theta) dw.

    Parameters
    ----------
    brdf : object
        Any BRDF (see :func:`albedo`).
    n_theta, n_phi : int, default 8, 8
        Outer rule: Gauss-Legendre in s = sin^2(theta) on [0, 1] (n_theta nodes; the
        Jacobian makes (1/pi) cos(theta) dw = ds dphi / (2 pi)) times the trapezoid rule in
        phi (n_phi nodes). A rule with half the nodes gives the outer error estimate.
    swap : bool, default False
        Which directional albedo is averaged (the two averages agree in exact arithmetic).
    workers : int, optional
        Processes to use.
    **kwargs
        Passed to :func:`albedo`.

    Returns
    -------
    HemisphericalAlbedo

    Examples
    --------
    >>> import numpy as np
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(np.broadcast(wi, wo).shape, 0.3 / np.pi)
    >>> h = albedo_hemispherical(Lambert(), workers=1)
    >>> np.round(h.value, 10)
    array([0.3, 0.3, 0.3])
    """
    if n_theta < 2 or n_phi < 2:
        raise ValueError(f"n_theta and n_phi must be >= 2; got {n_theta}, {n_phi}")

    def rule(nt, nph):
        x, w = np.polynomial.legendre.leggauss(nt)
        s, ws = 0.5 * (x + 1), 0.5 * w
        phi = (np.arange(nph) + 0.5) * (2 * math.pi / nph)
        S, P = np.meshgrid(s, phi, indexing="ij")
        st = np.sqrt(S)
        d = np.stack([st * np.cos(P), st * np.sin(P), np.sqrt(1 - S)], axis=-1).reshape(-1, 3)
        W = np.outer(ws, np.full(nph, 1.0 / nph)).ravel()
        return d, W

    d1, w1 = rule(n_theta, n_phi)
    d2, w2 = rule(max(2, n_theta // 2), max(2, n_phi // 2))
    dirs = np.concatenate([d1, d2])
    v, e, n = _map_chunks(brdf, dirs, dict(kwargs, swap=swap), workers)
    k = d1.shape[0]
    fine = w1 @ v[:k]
    coarse = w2 @ v[k:]
    err = w1 @ e[:k] + np.abs(fine - coarse)
    return HemisphericalAlbedo(value=fine, error=err, evals=int(n))
