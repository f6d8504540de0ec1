"""The directional albedo of any BRDF at fixed directions, refined until its error is small.

The gauss rules of :mod:`analysis.albedo.quadrature` are evaluated at two resolutions, the
finer having twice as many panels along each angle, and refined per direction until the
error estimate ``2 |fine - coarse| + rel_floor |fine| + abs_floor`` (factor 3 when the coarse
level is -1) is below the tolerance: the factors and the floors cover the pre-asymptotic cases
where two levels agree by chance (seen on the cloth presets at the 1e-5 level, from the kinks
of M and P and the boundary layers of 1/Q at the horizon).
"""

from __future__ import annotations

import numpy as np

from analysis.albedo.quadrature import gauss_level, rqmc, thread_axes
from analysis.albedo.results import AlbedoResult
from brdf.protocols import BRDF

__all__ = ["albedo"]

#: Factor on |fine - coarse| in the gauss error estimate.
_SAFETY = 2.0
#: The same factor when the coarse level is -1 (further from the asymptotic regime).
_SAFETY_M1 = 3.0
_METHODS = ("auto", "threads", "sphere", "rqmc")


def _check_dirs(name, w) -> np.ndarray:
    """Unit directions from ``w`` (..., 3); ValueError naming ``name`` otherwise."""
    arr = np.asarray(w, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3); got {arr.shape}")
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    if not np.all(np.isfinite(norm) & (norm > 0)):
        raise ValueError(f"{name} must be finite non-zero vectors")
    return arr / norm


def _check_options(brdf, method, tol, rtol, min_level, max_level):
    """ValueError for a bad method, tolerance, level range or a BRDF without ``eval``."""
    if method not in _METHODS:
        raise ValueError(f"method must be 'auto', 'threads', 'sphere' or 'rqmc'; got {method!r}")
    if not (tol > 0):
        raise ValueError(f"tol must be > 0; got {tol}")
    if not (-1 <= min_level <= max_level):
        raise ValueError(f"need -1 <= min_level <= max_level; got {min_level}, {max_level}")
    if not (rtol >= 0):
        raise ValueError(f"rtol must be >= 0; got {rtol}")
    if not isinstance(brdf, BRDF):
        raise ValueError(f"brdf must have an eval(wi, wo) method; got {type(brdf).__name__}")


def _refine(brdf, flat, swap, rule, axes, scale, tol, rtol, min_level, max_level, rel_floor,
            abs_floor):
    """Gauss albedo of the directions ``flat`` (K, 3), each refined until its error is below
    max(tol, rtol |value|): values (K, 3), errors (K, 3), finest levels (K,), pair count."""
    K = flat.shape[0]
    v = np.zeros((K, 3))
    e = np.full((K, 3), np.inf)
    lev = np.zeros(K, dtype=int)
    prev, n = gauss_level(brdf, flat, swap, rule, min_level, axes, scale)
    todo = np.arange(K)
    for level in range(min_level + 1, max_level + 1):
        cur, n_ = gauss_level(brdf, flat[todo], swap, rule, level, axes, scale)
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
    return v, e, lev, n


def albedo(brdf, wo, *, swap: bool = False, method: str = "auto", tol: float = 5e-4,
           rtol: float = 1e-3, min_level: int = 0, max_level: int = 3, scale=(1, 1), n_scrambles: int = 8,
           m: int = 12, seed=0, rel_floor: float = 1e-4,
           abs_floor: float = 2e-5) -> AlbedoResult:
    """Directional albedo of a BRDF at one or more fixed directions (see :mod:`analysis.albedo`).

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
        Relative and absolute floors added to the gauss error estimate (module notes).

    Returns
    -------
    AlbedoResult
        ``value`` (dimensionless) and ``error`` of shape (..., 3).

    Raises
    ------
    ValueError
        For a bad method, direction array or tolerance.

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
    _check_options(brdf, method, tol, rtol, min_level, max_level)
    fixed = _check_dirs("wo" if not swap else "wi", wo)
    shape, flat = fixed.shape[:-1], fixed.reshape(-1, 3)
    axes = thread_axes(brdf)
    rule = "threads" if axes is not None else "sphere"
    if method == "threads" and axes is None:
        raise ValueError("method='threads' needs a BRDF with eval_threads")
    if method == "rqmc":
        v, e, n = rqmc(brdf, flat, swap, axes, rule, m, n_scrambles, seed)
        lev, name = np.full(flat.shape[0], -1), f"rqmc-{rule}"
    else:
        name = rule if method == "auto" else method
        v, e, lev, n = _refine(brdf, flat, swap, name, axes, scale, tol, rtol, min_level,
                               max_level, rel_floor, abs_floor)
    return AlbedoResult(value=v.reshape(shape + (3,)), error=e.reshape(shape + (3,)),
                        direction=fixed, swap=bool(swap), method=name, evals=int(n),
                        level=lev.reshape(shape))
