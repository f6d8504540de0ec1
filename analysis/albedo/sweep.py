"""Albedo over many directions: sweeps of the fixed direction and the hemispherical average,
run in parallel processes when the BRDF can be pickled."""

from __future__ import annotations

import concurrent.futures
import math
import os
import pickle
import time

import numpy as np

from analysis.albedo.directional import albedo
from analysis.albedo.quadrature import thread_axes
from analysis.albedo.results import AlbedoCurve, HemisphericalAlbedo

__all__ = ["run_tasks", "albedo_curve", "albedo_hemispherical"]


def _albedo_chunk(brdf, dirs, kwargs):
    """One job of :func:`run_tasks`: albedo values, errors and evaluations of ``dirs``."""
    r = albedo(brdf, dirs, **kwargs)
    return r.value, r.error, r.evals


def _default_workers() -> int:
    """Up to 2 processes (the cores of the target machine)."""
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


def _outer_rule(nt: int, nph: int):
    """Directions (nt nph, 3) and weights of the hemispherical average: Gauss-Legendre in
    s = sin^2(theta) times the trapezoid rule in phi; the weights sum to 1."""
    x, w = np.polynomial.legendre.leggauss(nt)
    s, ws = 0.5 * (x + 1), 0.5 * w
    phi = (np.arange(nph) + 0.5) * (2 * math.pi / nph)
    S, P = np.meshgrid(s, phi, indexing="ij")
    st = np.sqrt(S)
    d = np.stack([st * np.cos(P), st * np.sin(P), np.sqrt(1 - S)], axis=-1).reshape(-1, 3)
    W = np.outer(ws, np.full(nph, 1.0 / nph)).ravel()
    return d, W


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

    d1, w1 = _outer_rule(n_theta, n_phi)
    d2, w2 = _outer_rule(max(2, n_theta // 2), max(2, n_phi // 2))
    dirs = np.concatenate([d1, d2])
    v, e, n = _map_chunks(brdf, dirs, dict(kwargs, swap=swap), workers)
    k = d1.shape[0]
    fine = w1 @ v[:k]
    coarse = w2 @ v[k:]
    err = w1 @ e[:k] + np.abs(fine - coarse)
    return HemisphericalAlbedo(value=fine, error=err, evals=int(n))
