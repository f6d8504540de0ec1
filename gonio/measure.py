"""``gonio.measure``: evaluate any BRDF on a geometry through an instrument, into a Table."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from gonio.geometry import Geometry, rotate_z
from gonio.geomspec import from_spec
from gonio.instrument import Instrument, cone_directions
from gonio.jsonplain import plain
from gonio.progress import progress_bar
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
        from importlib.metadata import PackageNotFoundError, version
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
        The (wi, wo) pairs, or a spec string for :meth:`Geometry.from_spec`. Its rotation
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
        If ``brdf`` has no ``eval`` method, the geometry spec is bad, or ``eval`` returns a
        wrong shape.

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
    if isinstance(geometry, str):
        geometry = from_spec(geometry)
    if not isinstance(geometry, Geometry):
        raise ValueError(f"geometry must be a gonio.Geometry or a spec string; "
                         f"got {type(geometry).__name__}")
    if instrument is None:
        instrument = Instrument()
    if not isinstance(instrument, Instrument):
        raise ValueError(f"instrument must be a gonio.Instrument or None; "
                         f"got {type(instrument).__name__}")
    if chunk is None:
        chunk = CHUNK_EVALUATIONS
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ValueError(f"chunk must be a positive integer; got {chunk!r}")
    if isinstance(seed, np.random.Generator):
        rng, seed_meta = seed, "numpy.random.Generator (state not recorded)"
    elif seed is None or (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)
                          and seed >= 0):
        rng = np.random.default_rng(seed)
        seed_meta = None if seed is None else int(seed)
    else:
        raise ValueError(f"seed must be a non-negative integer, a numpy Generator or None; "
                         f"got {seed!r}")

    n = len(geometry)
    ps, ws = instrument.source_rule
    pd, wd = instrument.detector_rule
    ks, kd = len(ws), len(wd)
    per_pair = ks * kd
    step = max(1, int(chunk) // per_pair)
    total = n * per_pair
    if progress is None:
        progress = total >= PROGRESS_MIN_EVALUATIONS and sys.stderr.isatty()

    values = np.empty((n, 3))
    wgt = (ws[:, None] * wd[None, :]).reshape(-1)
    rot = geometry.rotation
    bar = progress_bar(n, desc="measure", unit="pair", enabled=bool(progress and n))
    try:
        for a in range(0, n, step):
            b = min(n, a + step)
            wi_lab = geometry.wi_lab[a:b]
            wo_lab = geometry.wo_lab[a:b]
            si = wi_lab[:, None, :] if ks == 1 else cone_directions(wi_lab, ps)   # (c, ks, 3)
            so = wo_lab[:, None, :] if kd == 1 else cone_directions(wo_lab, pd)   # (c, kd, 3)
            if rot:
                si = rotate_z(si, -rot)
                so = rotate_z(so, -rot)
            c = b - a
            wi_all = np.broadcast_to(si[:, :, None, :], (c, ks, kd, 3)).reshape(-1, 3)
            wo_all = np.broadcast_to(so[:, None, :, :], (c, ks, kd, 3)).reshape(-1, 3)
            f = _evaluate(brdf, wi_all, wo_all).reshape(c, ks, kd, 3)
            if per_pair == 1:
                values[a:b] = f[:, 0, 0]
            else:
                # an explicitly ordered sum (numpy's reductions pick pairwise or sequential
                # order by memory layout)
                f = f.reshape(c, per_pair, 3)
                acc = f[:, 0] * wgt[0]
                for q in range(1, per_pair):
                    acc += f[:, q] * wgt[q]
                values[a:b] = acc
            if bar is not None:
                bar.update(c)
    finally:
        if bar is not None:
            bar.close()

    sigma = instrument.sigma(values)
    noisy = instrument.add_noise(values, rng)
    meta = {
        "quantity": "f_r",
        "units": "1/sr",
        "source": describe_brdf(brdf),
        "geometry": geometry.describe(),
        "instrument": instrument.describe(),
        "seed": seed_meta,
        "software": "microcyl gonio.measure",
        "version": toolkit_version(),
    }
    # copies: Table normalizes its direction arrays in place
    return Table(np.array(geometry.wi), np.array(geometry.wo), noisy, sigma, meta)
