"""Reciprocity: how far f_r(wi, wo) is from f_r(wo, wi).

For each direction pair the relative asymmetry is

    r(wi, wo) = |f(wi, wo) - f(wo, wi)| / max(f(wi, wo), f(wo, wi)),

between 0 (reciprocal) and 1 (one of the two is 0), computed on the luminance
Y = 0.2126 R + 0.7152 G + 0.0722 B of the RGB f_r (:func:`analysis.colour.luminance`) unless a
channel is asked for. Pairs where both values are 0 are excluded and counted; so are pairs where
either value is not finite. :func:`reciprocity_report` gathers the statistics of the presets,
their variants and measured felts as a :class:`ReciprocityReport`; its plain-language findings
are written by :func:`reports.prose.reciprocity_statements`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from analysis.colour import luminance
from analysis.variants import VARIANTS, applies, check_names, fabric_of, label_of
from brdf import validate
from brdf.frames import to_angles
from brdf.protocols import BRDF
from gonio.geometry import Geometry
from gonio.rgl import load_rgl
from gonio.table import Table

__all__ = ["ReciprocityResult", "ReciprocityReport", "reciprocity", "reciprocity_report",
           "random_pairs", "relative_asymmetry"]



def relative_asymmetry(a, b) -> np.ndarray:
    """The reciprocity error of microcyl, r = |a - b| / max(|a|, |b|), elementwise.

    ``a`` = f(wi, wo) and ``b`` = f(wo, wi) in any one unit (1/sr); r is unitless, in [0, 1]
    for non-negative values (1 where one of the two is 0). NaN where both are 0 or either is
    not finite: such pairs say nothing about reciprocity. The report's maps and the pair
    statistics of :func:`reciprocity` both use this definition.

    Examples
    --------
    >>> relative_asymmetry([1.0, 0.0, 2.0, 0.0], [0.5, 0.0, 2.0, 3.0]).tolist()
    [0.5, nan, 0.0, 1.0]
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    big = np.maximum(np.abs(a), np.abs(b))
    ok = np.isfinite(a) & np.isfinite(b) & (big > 0)
    return np.divide(np.abs(a - b), big, out=np.full(np.shape(big), np.nan), where=ok)


_CHANNELS = {"luminance": None, "r": 0, "g": 1, "b": 2, 0: 0, 1: 1, 2: 2}


@dataclasses.dataclass(frozen=True, eq=False)
class ReciprocityResult:
    """Distribution of the relative reciprocity error over direction pairs.

    Attributes
    ----------
    median, p95, max, mean : float
        Statistics of r over the included pairs (dimensionless, in [0, 1]); NaN if none.
    n_pairs : int
        Pairs examined.
    n_included : int
        Pairs with at least one non-zero, finite value.
    n_zero : int
        Pairs excluded because f(wi, wo) = f(wo, wi) = 0.
    n_nonfinite : int
        Pairs excluded because a value was NaN or infinite.
    channel : str
        ``"luminance"`` or ``"r"``, ``"g"``, ``"b"``.
    worst : list of dict
        The worst pairs: ``theta_i, phi_i, theta_o, phi_o`` in degrees, ``f_io`` = f(wi, wo),
        ``f_oi`` = f(wo, wi) (1/sr, on the chosen channel) and ``r``.
    """

    median: float
    p95: float
    max: float
    mean: float
    n_pairs: int
    n_included: int
    n_zero: int
    n_nonfinite: int
    channel: str
    worst: list

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data (NaN becomes None)."""
        d = dataclasses.asdict(self)
        for k in ("median", "p95", "max", "mean"):
            d[k] = None if not math.isfinite(d[k]) else float(d[k])
        return d


@dataclasses.dataclass(frozen=True, eq=False)
class ReciprocityReport:
    """Everything :func:`reciprocity_report` measured, as plain data.

    Attributes
    ----------
    settings : dict
        ``n``, ``seed``, ``channel``, ``presets``, ``variants`` (name -> options),
        ``geometry`` (its kind or None), ``felts`` (paths) and ``metric`` (the definition).
    rows : list of dict
        One per BRDF: ``source`` ("model" or "measured"), ``name``, ``variant`` (None for a
        measured one), ``random``, ``random_cos_i`` (the ``weight="cos_i"`` diagnostic) and
        optionally ``geometry``, each :meth:`ReciprocityResult.to_dict`.
    seconds : float
        Wall time.
    """

    settings: dict
    rows: list
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return dataclasses.asdict(self)


def random_pairs(n: int, seed=0) -> tuple[np.ndarray, np.ndarray]:
    """n direction pairs drawn uniformly (in solid angle) on the upper hemisphere.

    Parameters
    ----------
    n : int
        Number of pairs.
    seed : int or numpy.random.Generator
        The same seed gives the same pairs.

    Returns
    -------
    wi, wo : ndarray, shape (n, 3)

    Examples
    --------
    >>> wi, wo = random_pairs(4, seed=1)
    >>> wi.shape, bool(np.all(wi[:, 2] > 0))
    ((4, 3), True)
    """
    n = validate.integer("n", n, lo=1)
    rng = np.random.default_rng(seed)
    u = rng.random((2, int(n), 2))
    z = 1.0 - u[..., 0]                      # uniform in (0, 1]: uniform in solid angle
    phi = 2 * np.pi * u[..., 1]
    s = np.sqrt(1.0 - z * z)
    w = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1)
    return w[0], w[1]


def _angles_deg(w):
    """theta in [0, 180] and phi in [0, 360) degrees (the worst pairs' report)."""
    theta, phi = to_angles(w)
    return np.degrees(theta), np.degrees(phi) % 360.0



def _as_pairs(pairs, n: int, seed) -> tuple[np.ndarray, np.ndarray]:
    """(wi, wo), each (m, 3): ``n`` random pairs when ``pairs`` is None, else those given."""
    if pairs is None:
        return random_pairs(n, seed)
    wi, wo = (pairs.wi, pairs.wo) if isinstance(pairs, (Geometry, Table)) else pairs
    wi = np.asarray(wi, dtype=np.float64).reshape(-1, 3)
    wo = np.asarray(wo, dtype=np.float64).reshape(-1, 3)
    if wi.shape != wo.shape:
        raise ValueError(f"pairs: wi and wo must have the same shape; got {wi.shape}, "
                         f"{wo.shape}")
    return wi, wo


def _both_ways(brdf, wi, wo, channel, weight) -> tuple[np.ndarray, np.ndarray, str]:
    """f(wi, wo) and f(wo, wi) on the chosen channel (1/sr), and the channel's name."""
    with np.errstate(all="ignore"):
        f_io = np.asarray(brdf.eval(wi, wo), dtype=np.float64)
        f_oi = np.asarray(brdf.eval(wo, wi), dtype=np.float64)
        if weight == "cos_i":
            f_io = f_io * np.clip(wi[..., 2:3], 0, None)
            f_oi = f_oi * np.clip(wo[..., 2:3], 0, None)
    ch = _CHANNELS[channel]
    if ch is None:
        return luminance(f_io), luminance(f_oi), "luminance"
    return f_io[..., ch], f_oi[..., ch], "rgb"[ch]


def _worst_pairs(wi, wo, a, b, r, inc, n_worst: int) -> list[dict]:
    """The ``n_worst`` included pairs of largest r: angles in degrees, both values, r."""
    ri = r[inc]
    if not ri.size or n_worst <= 0:
        return []
    idx = np.flatnonzero(inc)
    order = idx[np.argsort(-ri, kind="stable")[:n_worst]]
    ti, pi_ = _angles_deg(wi[order])
    to, po = _angles_deg(wo[order])
    return [{"theta_i": float(ti[k]), "phi_i": float(pi_[k]), "theta_o": float(to[k]),
             "phi_o": float(po[k]), "f_io": float(a[j]), "f_oi": float(b[j]), "r": float(r[j])}
            for k, j in enumerate(order)]


def _statistics(a, b, name, wi, wo, n_worst: int) -> ReciprocityResult:
    """The :class:`ReciprocityResult` of the values a = f(wi, wo) and b = f(wo, wi)."""
    finite = np.isfinite(a) & np.isfinite(b)
    zero = finite & (a == 0) & (b == 0)
    inc = finite & ~zero
    r = relative_asymmetry(a, b)
    ri = r[inc]
    if ri.size:
        med, p95, mx, mean = (float(np.median(ri)), float(np.percentile(ri, 95)),
                              float(ri.max()), float(ri.mean()))
    else:
        med = p95 = mx = mean = float("nan")
    return ReciprocityResult(median=med, p95=p95, max=mx, mean=mean, n_pairs=int(a.size),
                             n_included=int(inc.sum()), n_zero=int(zero.sum()),
                             n_nonfinite=int((~finite).sum()), channel=name,
                             worst=_worst_pairs(wi, wo, a, b, r, inc, n_worst))


def reciprocity(brdf, pairs=None, *, n: int = 20000, seed=0, channel="luminance",
                n_worst: int = 5, weight: str = "none") -> ReciprocityResult:
    """Relative reciprocity error of a BRDF over random or given direction pairs.

    Parameters
    ----------
    brdf : object
        Anything with ``eval(wi, wo) -> (..., 3)`` in 1/sr.
    pairs : tuple (wi, wo) of arrays (n, 3), or a gonio Geometry or Table, optional
        The pairs to test. Default: ``n`` random pairs, uniform on the hemisphere, from
        ``seed``.
    n : int, default 20000
        Number of random pairs when ``pairs`` is None.
    seed : int or numpy.random.Generator, default 0
        Seed of the random pairs.
    channel : {"luminance", "r", "g", "b"}, default "luminance"
        What the error is computed on.
    n_worst : int, default 5
        How many of the worst pairs to return.
    weight : {"none", "cos_i"}, default "none"
        "cos_i" compares f(wi, wo) cos(theta_i) with f(wo, wi) cos(theta_o) instead: a
        diagnostic that removes the 1/(n . wi) of the microcylinder model's f_r, to show how
        much of the asymmetry is left in S_j / Q.

    Returns
    -------
    ReciprocityResult

    Raises
    ------
    ValueError
        For a bad channel, pair arrays of different shapes, or a BRDF without ``eval``.

    Notes
    -----
    r = |f(wi, wo) - f(wo, wi)| / max(f(wi, wo), f(wo, wi)); pairs with both values 0
    (or a non-finite value) are excluded and counted.

    Examples
    --------
    >>> import numpy as np
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(np.broadcast(wi, wo).shape, 0.5 / np.pi)
    >>> r = reciprocity(Lambert(), n=100, seed=0)
    >>> r.max, r.n_included, r.n_zero
    (0.0, 100, 0)
    """
    if channel not in _CHANNELS:
        raise ValueError(f"channel must be 'luminance', 'r', 'g' or 'b'; got {channel!r}")
    if not isinstance(brdf, BRDF):
        raise ValueError(f"brdf must have an eval(wi, wo) method; got {type(brdf).__name__}")
    if weight not in ("none", "cos_i"):
        raise ValueError(f"weight must be 'none' or 'cos_i'; got {weight!r}")
    n = validate.integer("n", n, lo=1)
    n_worst = validate.integer("n_worst", n_worst, lo=0)
    wi, wo = _as_pairs(pairs, n, seed)
    a, b, name = _both_ways(brdf, wi, wo, channel, weight)
    return _statistics(a, b, name, wi, wo, n_worst)


def _report_row(name, variant, source, b, pairs, geometry, channel, n_worst) -> dict[str, Any]:
    """One row of :class:`ReciprocityReport`: random pairs, the cos_i diagnostic, the grid."""
    row = {"source": source, "name": name, "variant": variant,
           "random": reciprocity(b, pairs, channel=channel, n_worst=n_worst).to_dict(),
           "random_cos_i": reciprocity(b, pairs, channel=channel, n_worst=n_worst,
                                       weight="cos_i").to_dict()}
    if geometry is not None:
        row["geometry"] = reciprocity(b, geometry, channel=channel, n_worst=n_worst).to_dict()
    return row


def _measured(felt) -> tuple[str, object]:
    """A measured contrast's name and BRDF: an RGL file (named by its stem) or a
    (name, BRDF) pair."""
    if isinstance(felt, tuple):
        return str(felt[0]), felt[1]
    return Path(felt).stem, load_rgl(felt)


def reciprocity_report(presets=None, variants=None, *, n: int = 20000, seed=0,
                       geometry=None, felts=(), channel="luminance",
                       n_worst: int = 5) -> ReciprocityReport:
    """Reciprocity statistics per preset and variant, and for measured BRDFs as a contrast.

    Parameters
    ----------
    presets : sequence of str or brdf.Fabric, optional
        Preset names (default: all of ``brdf.PRESETS``), or fabrics named by their ``name``
        (a fit's, a file's: :func:`analysis.variants.label_of`).
    variants : sequence of str, optional
        Keys of :data:`analysis.variants.VARIANTS` (default: all), so the report shows which
        term (gap, transmission, masking, reweighting) changes the asymmetry.
    n : int, default 20000
        Random pairs (uniform on the hemisphere) per BRDF.
    seed : int, default 0
        Seed of the random pairs (the same pairs for every BRDF).
    geometry : gonio.Geometry, optional
        A gonio geometry examined as well (e.g. ``gonio.full_grid(10)``).
    felts : sequence of str, os.PathLike or (name, BRDF) pairs, optional
        RGL tensor files (``gonio.load_rgl``) or measured BRDFs (a MERL table's
        ``gonio.load_merl``), reported as measured contrasts.
    channel : str, default "luminance"
        See :func:`reciprocity`.
    n_worst : int, default 5
        Worst pairs kept per entry.

    Returns
    -------
    ReciprocityReport
        Its findings in words: :func:`reports.prose.reciprocity_statements`.

    Raises
    ------
    ValueError
        Unknown preset or variant.
    """
    t0 = time.perf_counter()
    presets, variants = check_names(presets, variants)
    pairs = random_pairs(n, seed)
    rows = [_report_row(label_of(p), v, "model", fabric_of(p, v), pairs, geometry,
                        channel, n_worst) for p in presets for v in variants if applies(p, v)]
    measured = [_measured(felt) for felt in felts]
    rows += [_report_row(name, None, "measured", b, pairs, geometry, channel, n_worst)
             for name, b in measured]
    settings = {"n": int(n), "seed": seed if isinstance(seed, int) else None,
                "channel": channel, "presets": [label_of(p) for p in presets],
                "variants": {v: VARIANTS[v] for v in variants},
                "geometry": geometry.kind if isinstance(geometry, Geometry) else None,
                "felts": [f[0] if isinstance(f, tuple) else str(f) for f in felts],
                "metric": "|f(wi,wo) - f(wo,wi)| / max(f(wi,wo), f(wo,wi)); pairs with "
                          "both 0 excluded and counted (n_zero)"}
    return ReciprocityReport(settings=settings, rows=rows, seconds=time.perf_counter() - t0)
