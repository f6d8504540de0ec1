"""``gonio.measure``: evaluate any BRDF on a geometry through an instrument, into a Table."""

from __future__ import annotations

import sys
from importlib.metadata import PackageNotFoundError, version
from typing import Any

import numpy as np

from gonio.geometry import Geometry, rotate_z
from gonio.geomspec import from_spec
from gonio.instrument import Instrument, cone_directions
from gonio.jsonplain import plain
from gonio.progress import progress_bar
from gonio.terminal import shown
from gonio.table import Table

__all__ = ["measure", "toolkit_version", "describe_brdf"]

#: Default number of BRDF evaluations per chunk (pairs x cone points). A fabric with 32
#: tangent samples per thread keeps well under 1 GiB of temporaries at this size.
CHUNK_EVALUATIONS = 1 << 15

#: Show a progress bar only from this many BRDF evaluations on (and only on a terminal).
PROGRESS_MIN_EVALUATIONS = 1 << 19


def toolkit_version() -> str:
    """The installed microcyl version, or "unknown" when it is not installed.

    Examples
    --------
    >>> isinstance(toolkit_version(), str)
    True
    """
    try:
        return version("microcyl")
    except PackageNotFoundError:
        return "unknown"
    except Exception:  # pragma: no cover - broken metadata
        return "unknown"


def describe_brdf(brdf) -> dict[str, Any]:
    """What is being measured, as a JSON-serializable dict.

    Records the class, and ``name``, ``options`` and ``threads`` (each thread's parameters)
    when the object has them, as ``brdf.Fabric`` does.

    Examples
    --------
    >>> class Lambert:
    ...     name = "white"
    ...     def eval(self, wi, wo):
    ...         return np.full(np.shape(wi)[:-1] + (3,), 1 / np.pi)
    >>> describe_brdf(Lambert())
    {'type': 'Lambert', 'name': 'white'}
    """
    d: dict[str, Any] = {"type": type(brdf).__name__}
    for attr in ("name", "preset", "options", "threads", "params"):
        v = getattr(brdf, attr, None)
        if v is not None and not callable(v):
            d[attr] = plain(v, nonfinite="repr")
    return d


def _evaluate(brdf, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """f_r of flat (m, 3) pairs as (m, 3), checking what the BRDF returns."""
    f = np.asarray(brdf.eval(wi, wo), dtype=float)
    m = wi.shape[0]
    if f.shape == (m,):
        f = np.repeat(f[:, None], 3, axis=1)
    if f.shape != (m, 3):
        raise ValueError(f"{type(brdf).__name__}.eval returned shape {f.shape} for {m} "
                         f"direction pairs; expected ({m}, 3)")
    return f


def measure(brdf, geometry, instrument: Instrument | None = None, seed=None, *,
            chunk: int | None = None, progress: bool | None = None) -> Table:
    """Measure a BRDF on a geometry through an instrument.

    Parameters
    ----------
    brdf : object with ``eval(wi, wo) -> (..., 3)``
        Any BRDF: a ``brdf.Fabric``, a loaded measurement, an analytic model. It is called
        with flat (m, 3) arrays of directions in the sample frame and must return f_r in 1/sr
        (shape (m, 3), or (m,) for grey).
    geometry : Geometry or str
        The (wi, wo) pairs, or a spec string for :func:`gonio.from_spec`. Its rotation
        turns the sample: directions reach the BRDF turned by -rotation about n.
    instrument : Instrument, optional
        Cones and noise; a noiseless point instrument when None.
    seed : int, numpy.random.Generator or None
        Seed of the noise. The same integer seed (and the same ``chunk``) gives the same
        bytes. The noise is drawn once over the whole table in a fixed order and the cone
        averages are explicitly ordered sums, so another ``chunk`` changes at most the last
        bit of a value (where NumPy's or the BRDF's rounding depends on the batch).
    chunk : int, optional
        BRDF evaluations per chunk (pairs x cone points); default ``CHUNK_EVALUATIONS``.
        Bounds the memory of each ``eval`` call.
    progress : bool, optional
        Show a tqdm bar on stderr. By default shown only when stderr is a terminal and the
        work is at least ``PROGRESS_MIN_EVALUATIONS`` evaluations.

    Returns
    -------
    Table
        ``wi``, ``wo``: the geometry's directions in the sample frame (n = +z, warp = +x);
        ``values``: the (noisy) cone averages of f_r in 1/sr; ``sigma``: the noise model's
        standard deviation at the noiseless value (None for a noiseless instrument);
        ``meta``: a JSON-serializable dict with ``source`` (:func:`describe_brdf`),
        ``geometry`` (:meth:`Geometry.describe`: kind, spec, params, rotation, names of the
        coordinates), ``instrument`` (:meth:`Instrument.describe`), ``seed``,
        ``units`` ("1/sr"), ``quantity`` ("f_r"), ``software`` and ``version``.
        The geometry's coordinate arrays are not copied into ``meta`` (they would bloat file
        headers); :meth:`Geometry.from_table` rebuilds them from the table's directions.

    Raises
    ------
    ValueError
        If ``brdf`` has no ``eval`` method, the geometry spec is bad, a pair is out of the
        instrument's reach (:meth:`Instrument.check_reachable`, before any evaluation), or
        ``eval`` returns a wrong shape.

    Notes
    -----
    For a pair (wi, wo) with source points s_k (weights a_k) and detector points d_l
    (weights b_l) placed about wi and wo in the lab frame (see
    :func:`gonio.instrument.cap_quadrature`), the noiseless value is
    v = sum_k sum_l a_k b_l f_r(R(-rho) s_k, R(-rho) d_l), with rho the geometry's rotation.
    Noise then follows the instrument's model.

    Examples
    --------
    >>> from gonio.layouts import plane
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    ...         return np.where(up, 0.5 / np.pi, 0.0)[..., None] * np.ones(3)
    >>> t = measure(Lambert(), plane("warp", 30, theta_i=[30]), seed=1)
    >>> len(t), bool(np.allclose(t.values, 0.5 / np.pi)), t.meta["units"]
    (5, True, '1/sr')
    >>> t = measure(Lambert(), "plane:warp:30:30", Instrument(snr=100), seed=1)
    >>> float(t.sigma[0, 0] * np.pi)
    0.005
    """
    if not callable(getattr(brdf, "eval", None)):
        raise ValueError(f"brdf must have an eval(wi, wo) method; got {type(brdf).__name__}")
    geometry, instrument = _geometry_of(geometry), _instrument_of(instrument)
    _check_reach(geometry, instrument)
    rng, seed_meta = _rng_of(seed)
    values = _cone_averages(brdf, geometry, instrument, _chunk_of(chunk), progress)
    sigma = instrument.sigma(values)
    noisy = instrument.add_noise(values, rng)
    meta = _meta(brdf, geometry, instrument, seed_meta)
    # copies: Table normalizes its direction arrays in place
    return Table(np.array(geometry.wi), np.array(geometry.wo), noisy, sigma, meta)


def _meta(brdf, geometry: Geometry, instrument: Instrument, seed_meta) -> dict[str, Any]:
    """The table's ``meta``: what was measured, on what, through what, with which seed."""
    return {
        "quantity": "f_r",
        "units": "1/sr",
        "source": describe_brdf(brdf),
        "geometry": geometry.describe(),
        "instrument": instrument.describe(),
        "seed": seed_meta,
        "software": "microcyl gonio.measure",
        "version": toolkit_version(),
    }


def _geometry_of(geometry) -> Geometry:
    """A Geometry, or one built from a spec string; ValueError otherwise."""
    if isinstance(geometry, str):
        geometry = from_spec(geometry)
    if not isinstance(geometry, Geometry):
        raise ValueError(f"geometry must be a gonio.Geometry or a spec string; "
                         f"got {type(geometry).__name__}")
    return geometry


def _instrument_of(instrument) -> Instrument:
    """The instrument, a noiseless point instrument for None; ValueError otherwise."""
    if instrument is None:
        return Instrument()
    if not isinstance(instrument, Instrument):
        raise ValueError(f"instrument must be a gonio.Instrument or None; "
                         f"got {type(instrument).__name__}")
    return instrument


def _check_reach(geometry: Geometry, instrument: Instrument) -> None:
    """Refuse, before any work, a geometry with pairs out of the instrument's reach."""
    if instrument.has_limits:
        instrument.check_reachable(geometry.wi, geometry.wo,
                                   f"geometry {shown(geometry.spec or geometry.kind)}")


def _chunk_of(chunk) -> int:
    """BRDF evaluations per chunk: ``CHUNK_EVALUATIONS`` for None; ValueError unless >= 1."""
    if chunk is None:
        return CHUNK_EVALUATIONS
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ValueError(f"chunk must be a positive integer; got {chunk!r}")
    return int(chunk)


def _rng_of(seed) -> tuple[np.random.Generator, Any]:
    """The noise generator of ``seed`` and what ``meta["seed"]`` records of it."""
    if isinstance(seed, np.random.Generator):
        return seed, "numpy.random.Generator (state not recorded)"
    if seed is None or (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)
                        and seed >= 0):
        return np.random.default_rng(seed), None if seed is None else int(seed)
    raise ValueError(f"seed must be a non-negative integer, a numpy Generator or None; "
                     f"got {seed!r}")


def _cone_averages(brdf, geometry: Geometry, instrument: Instrument, chunk: int,
                   progress: bool | None) -> np.ndarray:
    """Noiseless cone averages of f_r, (n, 3), chunk by chunk with an optional progress bar."""
    n = len(geometry)
    per_pair = instrument.n_source * instrument.n_detector
    step = max(1, chunk // per_pair)
    if progress is None:
        progress = n * per_pair >= PROGRESS_MIN_EVALUATIONS and sys.stderr.isatty()
    values = np.empty((n, 3))
    bar = progress_bar(n, desc="measure", unit="pair", enabled=bool(progress and n))
    try:
        for a in range(0, n, step):
            b = min(n, a + step)
            values[a:b] = _chunk_average(brdf, geometry.wi_lab[a:b], geometry.wo_lab[a:b],
                                         geometry.rotation, instrument)
            if bar is not None:
                bar.update(b - a)
    finally:
        if bar is not None:
            bar.close()
    return values


def _chunk_average(brdf, wi_lab: np.ndarray, wo_lab: np.ndarray, rot: float,
                   instrument: Instrument) -> np.ndarray:
    """Cone averages of f_r for c pairs of lab directions (c, 3) -> (c, 3).

    Each source point (ks of them about wi) is paired with each detector point (kd about wo),
    turned into the sample frame by -rot about n, evaluated, and summed with the weights
    a_k b_l in a fixed order.
    """
    ps, ws = instrument.source_rule
    pd, wd = instrument.detector_rule
    ks, kd, c = len(ws), len(wd), wi_lab.shape[0]
    si = wi_lab[:, None, :] if ks == 1 else cone_directions(wi_lab, ps)   # (c, ks, 3)
    so = wo_lab[:, None, :] if kd == 1 else cone_directions(wo_lab, pd)   # (c, kd, 3)
    if rot:
        si = rotate_z(si, -rot)
        so = rotate_z(so, -rot)
    wi_all = np.broadcast_to(si[:, :, None, :], (c, ks, kd, 3)).reshape(-1, 3)
    wo_all = np.broadcast_to(so[:, None, :, :], (c, ks, kd, 3)).reshape(-1, 3)
    f = _evaluate(brdf, wi_all, wo_all).reshape(c, ks * kd, 3)
    if ks * kd == 1:
        return f[:, 0]
    # an explicitly ordered sum (numpy's reductions pick pairwise or sequential order by
    # memory layout)
    wgt = (ws[:, None] * wd[None, :]).reshape(-1)
    acc = f[:, 0] * wgt[0]
    for q in range(1, ks * kd):
        acc += f[:, q] * wgt[q]
    return acc
