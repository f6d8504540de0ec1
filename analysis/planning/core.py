r"""``analysis.plan``: which (wi, wo) pairs to measure, chosen for the free parameters.

The plan maximises the Bayesian D-optimality criterion of :mod:`analysis.planning.select`
(the expected log determinant of the posterior precision, in the Laplace approximation,
over draws of the parameters: :mod:`analysis.planning.draws`) with the information of
:mod:`analysis.planning.information`. It reports the expected posterior covariance of its
design and of uniform designs of N and 3N pairs
(:func:`analysis.planning.candidates.uniform_pairs`), each the mean over the draws of :math:`(A_0 + I)^{-1}`.

What the numbers are: the curvature of the log-likelihood linearised at each draw (Fisher
information) with the fit's prior added; a posterior far from Gaussian in the internal
coordinates (a parameter piled against a bound, a ridge between two confounded ones) has
sds the Laplace approximation misses, and a draw far from the truth gives the design a
different emphasis. They rank designs well; the fit's intervals are the final word.
"""

from __future__ import annotations

import dataclasses

import numpy as np

import brdf
from analysis.fit.fisher import PRIOR_INFORMATION, STEP
from analysis.fit.workflow import fit_spec
from analysis.planning.candidates import Candidates, candidates as make_candidates, \
    reachable, uniform_pairs
from analysis.planning.draws import (check_draws, fit_folder_spec, posterior_draws,
                                     prior_draws)
from analysis.planning.information import information, whitened_jacobians
from analysis.planning.select import (exchange, expected_covariance, expected_log_det,
                                      greedy)
from analysis.sources import Source, resolve
from brdf.frames import to_angles
from gonio.memory import check_memory
from gonio.pairsfile import order_for_travel
from gonio.progress import progress_bar

__all__ = ["Plan", "plan", "MAX_BUDGET", "DEFAULT_DRAWS"]

#: The most pairs one plan may choose.
MAX_BUDGET = 100_000
#: Draws the criterion averages over by default.
DEFAULT_DRAWS = 8


@dataclasses.dataclass(frozen=True)
class Plan:
    """A measurement plan and what it is expected to tell.

    Attributes
    ----------
    fabric : str
        The label of the fabric or fit planned for.
    free, units : tuple of str
        The free parameters and their units.
    wi, wo : ndarray (N, 3)
        The chosen pairs in measurement order (:func:`gonio.pairsfile.order_for_travel`).
    angles : ndarray (N, 4)
        theta_i, phi_i, theta_o, phi_o of the pairs in degrees (phi in [0, 360)).
    rank : ndarray (N,) of int
        Each pair's place in the selection (1 the most informative given the start): an
        operator cut short measures by rank.
    covariance : ndarray (d, d)
        The expected posterior covariance of the free parameters, internal coordinates.
    sd, uniform_sd, uniform3_sd : ndarray (d,)
        Expected posterior sd (internal coordinates) of the plan, of a uniform design of
        N pairs and of one of 3N.
    natural_sd, uniform_natural_sd, uniform3_natural_sd : ndarray (d,)
        The same in each parameter's own unit (the delta method at each draw, root mean
        square over the draws).
    uniform_wi, uniform_wo : ndarray (N, 3)
        The uniform design of N pairs (for the figure).
    criterion : dict
        Expected log det of the posterior precision: ``start`` (prior and ``measured``),
        ``plan``, ``uniform`` and ``uniform3``.
    draws, seed : int
    source : str
        ``prior`` (local prior about the fabric) or ``posterior`` (a fit's samples).
    candidates : str
        The candidate geometry's spec; ``n_candidates`` how many the instrument reaches.
    n_candidates, n_measured : int
    instrument : dict
        :meth:`gonio.Instrument.describe`.
    grey : bool
        Whether the instrument reads one grey value a pair (else R, G and B).
    """

    fabric: str
    free: tuple
    units: tuple
    wi: np.ndarray
    wo: np.ndarray
    angles: np.ndarray
    rank: np.ndarray
    covariance: np.ndarray
    sd: np.ndarray
    natural_sd: np.ndarray
    uniform_sd: np.ndarray
    uniform_natural_sd: np.ndarray
    uniform3_sd: np.ndarray
    uniform3_natural_sd: np.ndarray
    uniform_wi: np.ndarray
    uniform_wo: np.ndarray
    criterion: dict
    draws: int
    seed: int
    source: str
    candidates: str
    n_candidates: int
    n_measured: int
    instrument: dict
    grey: bool = False

    @property
    def budget(self) -> int:
        """Pairs in the plan."""
        return int(self.wi.shape[0])

    def table(self) -> list[dict]:
        """Per free parameter: name, unit and the expected natural sds of the plan and of
        the uniform designs of N and 3N (what ``microcyl plan`` prints)."""
        return [{"parameter": n, "unit": u, "plan": float(a), "uniform": float(b),
                 "uniform3": float(c)}
                for n, u, a, b, c in zip(self.free, self.units, self.natural_sd,
                                         self.uniform_natural_sd, self.uniform3_natural_sd)]


def _angles(wi, wo) -> np.ndarray:
    """(N, 4) theta_i, phi_i, theta_o, phi_o in degrees, phi in [0, 360), rounded to 1e-9."""
    ti, pi_ = to_angles(wi)
    to, po = to_angles(wo)
    a = np.degrees(np.stack([ti, pi_, to, po], axis=-1))
    a[:, [1, 3]] = np.mod(a[:, [1, 3]], 360.0)
    a = np.round(a, 9)
    a[:, [1, 3]] = np.where(a[:, [1, 3]] >= 360.0, 0.0, a[:, [1, 3]])
    return a + 0.0


def _check_budget(budget) -> int:
    if isinstance(budget, bool) or not isinstance(budget, (int, np.integer)) or not (
            1 <= budget <= MAX_BUDGET):
        raise ValueError(f"budget must be a whole number of pairs in 1..{MAX_BUDGET}; got "
                         f"{budget!r}")
    return int(budget)


def _source(fabric_or_source) -> Source:
    if isinstance(fabric_or_source, Source):
        return fabric_or_source
    if isinstance(fabric_or_source, brdf.Fabric):
        return Source("fabric", fabric_or_source.name or "fabric", fabric_or_source)
    return resolve(fabric_or_source, what="fabric")


def _spec(src: Source, free, ties):
    """The plan's ParamSpec: ``free`` and ``ties`` as ``microcyl fit`` takes them; neither
    given, a fit folder's own."""
    if free is None and ties is None and src.kind == "fit":
        fitted, ties = fit_folder_spec(src.path)
        free = list(fitted.free)
    return fit_spec(src.fabric, free, ties)


def _measured_pairs(measured):
    """(wi, wo) of the pairs already measured: a table (rows with a missing value or a
    direction below the horizon dropped, as the likelihood drops them) or a (wi, wo) tuple.
    They count whatever instrument took them (its limits are not this one's business)."""
    if measured is None:
        return np.zeros((0, 3)), np.zeros((0, 3))
    if hasattr(measured, "values"):
        keep = np.all(np.isfinite(np.asarray(measured.values, dtype=np.float64)), axis=-1)
        wi, wo = np.asarray(measured.wi)[keep], np.asarray(measured.wo)[keep]
    else:
        wi, wo = (np.asarray(a, dtype=np.float64).reshape(-1, 3) for a in measured)
    keep = reachable(None, wi, wo)
    return wi[keep], wo[keep]


def _uniform(n: int, instrument, cands: Candidates, seed: int):
    """A uniform design of ``n`` pairs (:func:`~analysis.planning.candidates.uniform_pairs`);
    for an instrument that reaches too little of the hemisphere to draw them (in-plane
    only), ``n`` of the candidates drawn at random (seeded)."""
    try:
        return uniform_pairs(n, instrument, max_theta=cands.max_theta, seed=seed)
    except ValueError:
        rng = np.random.default_rng([seed, 1])
        pick = rng.choice(len(cands), size=n, replace=n > len(cands))
        return cands.wi[pick], cands.wo[pick]


def _natural_sd(spec, thetas, a0, jac_design) -> np.ndarray:
    """RMS over draws of (slope of the natural value) x (sd in the internal coordinate)."""
    a = a0 + information(jac_design)
    var = np.diagonal(np.linalg.inv(a), axis1=-2, axis2=-1)          # (K, d)
    h = STEP * np.eye(spec.ndim)
    slope = np.stack([np.diag(spec.to_natural(t + h) - spec.to_natural(t - h)) / (2 * STEP)
                      for t in thetas])
    return np.sqrt(np.mean(slope ** 2 * var, axis=0))


def plan(fabric_or_source, free=None, budget: int = 60, *, instrument, candidates=None,
         measured=None, draws: int = DEFAULT_DRAWS, seed: int = 0, ties=None,
         grey: bool = False, exchange_pass: bool = True, progress: bool = False) -> Plan:
    """Choose ``budget`` pairs that maximise the expected information about ``free``.

    Parameters
    ----------
    fabric_or_source : brdf.Fabric, str, path or analysis.sources.Source
        A fabric, a preset's name, or a ``microcyl fit`` folder (plans over its posterior).
    free : str or sequence of str, optional
        Free parameters (names of :mod:`analysis.paramnames`); default a fit folder's own
        free parameters and ties, else :data:`analysis.params.DEFAULT_FREE` with
        :data:`~analysis.params.DEFAULT_TIES`.
    budget : int
        Pairs to choose.
    instrument : gonio.Instrument
        Its noise model gives each reading's sigma (it must be noisy); its limits the
        reachable pairs.
    candidates : str, gonio.Geometry or Candidates, optional
        Where to choose from; default :data:`analysis.planning.DEFAULT_CANDIDATES`.
    measured : gonio.Table or (wi, wo), optional
        Pairs already measured: their information is the start; the plan is the next N.
    draws, seed : int
        Draws of the parameters the criterion averages over; the seed of the draws and of
        the uniform designs (same seed, same plan).
    ties : sequence of str, optional
        ``"a=b"`` / ``"a=1-b"``, as ``microcyl fit --tie``.
    grey : bool
        A grey (luminance) instrument: one reading a pair, not three.
    exchange_pass : bool
        Follow the greedy choice by one exchange pass.
    progress : bool
        Show a progress bar.

    Returns
    -------
    Plan

    Raises
    ------
    ValueError
        A bad budget or draw count, unknown free parameters, a noiseless instrument, a budget
        above the reachable candidates; before any work.

    Examples
    --------
    >>> from gonio import Instrument
    >>> p = plan("silk_crepe_de_chine", "kd1,gamma_s1", 4, instrument=Instrument(snr=20),
    ...          candidates="full:30:60", draws=2)
    >>> p.budget, bool(np.all(p.sd < p.uniform_sd * 1.0001))
    (4, True)
    """
    budget, draws = _check_budget(budget), check_draws(draws)
    if not instrument.is_noisy:
        raise ValueError("the instrument is noiseless: a plan needs its noise (give snr or "
                         "floor, --snr or --floor)")
    src = _source(fabric_or_source)
    fab = src.fabric
    spec = _spec(src, free, ties)
    cands = candidates if isinstance(candidates, Candidates) else make_candidates(
        candidates, instrument)
    if budget > len(cands):
        raise ValueError(f"budget {budget} exceeds the {len(cands)} candidate pairs the "
                         f"instrument reaches on {cands.spec}; give a finer --candidates "
                         f"grid or a smaller budget")
    mwi, mwo = _measured_pairs(measured)
    check_memory(f"a plan over {len(cands)} candidates x {draws} draws x {spec.ndim} free "
                 f"parameters", 3 * draws * len(cands) * 3 * spec.ndim * 8.0,
                 "give coarser --candidates or fewer --draws")
    rng = np.random.default_rng(seed)
    thetas = (posterior_draws(src.path, spec, draws, rng) if src.kind == "fit"
              else prior_draws(spec, draws, rng))
    uwi, uwo = _uniform(3 * budget, instrument, cands, seed)
    chosen, a0, j_cand, j_uni = _choose(fab, spec, thetas, cands, (mwi, mwo), (uwi, uwo),
                                        instrument, budget, grey, exchange_pass, progress)
    return _assemble(src, spec, cands, chosen, thetas, a0, j_cand, j_uni, (uwi, uwo),
                     dict(draws=draws, seed=seed, source="posterior" if src.kind == "fit"
                          else "prior", n_measured=len(mwi),
                          instrument=instrument.describe(), grey=bool(grey)))


def _choose(fab, spec, thetas, cands, measured, uniform, instrument, budget, grey,
            exchange_pass, progress):
    """The information of the candidates, of the measured pairs (the start) and of the
    uniform design; the choice. Returns (chosen, a0, j_cand, j_uni)."""
    draws = thetas.shape[0]
    total = 3 * draws + budget * (2 if exchange_pass else 1)
    with progress_bar(total, desc="plan", unit="step", enabled=progress) as bar:
        def jac(wi, wo, update=bar.update):
            return whitened_jacobians(fab, spec, thetas, wi, wo, instrument, grey=grey,
                                      progress=update)
        j_cand = jac(cands.wi, cands.wo)
        a0 = PRIOR_INFORMATION * np.eye(spec.ndim) + information(jac(*measured, None))
        j_uni = jac(*uniform)
        chosen = greedy(j_cand, a0, budget, progress=bar.update)
        if exchange_pass:
            chosen = exchange(j_cand, a0, chosen, progress=bar.update)
        bar.update(draws)
    return chosen, a0, j_cand, j_uni


def _assemble(src, spec, cands, chosen, thetas, a0, j_cand, j_uni, uniform, extra) -> Plan:
    """The Plan of the chosen candidates, in measurement order."""
    n = len(chosen)
    order = travel_order(_angles(cands.wi[chosen], cands.wo[chosen]))
    chosen = np.asarray(chosen)
    rank = order + 1                  # chosen[i] was the (i + 1)-th choice
    picked = chosen[order]
    j_plan = j_cand[:, picked]
    crit = {"start": expected_log_det(a0, j_plan[:, :0]),
            "plan": expected_log_det(a0, j_plan),
            "uniform": expected_log_det(a0, j_uni[:, :n]),
            "uniform3": expected_log_det(a0, j_uni)}
    cov = expected_covariance(a0, j_plan)
    sd_of = (lambda j: np.sqrt(np.diag(expected_covariance(a0, j))))
    wi, wo = cands.wi[picked], cands.wo[picked]
    return Plan(fabric=src.label, free=spec.free, units=spec.units, wi=wi, wo=wo,
                angles=_angles(wi, wo), rank=rank, covariance=cov, sd=np.sqrt(np.diag(cov)),
                natural_sd=_natural_sd(spec, thetas, a0, j_plan),
                uniform_sd=sd_of(j_uni[:, :n]),
                uniform_natural_sd=_natural_sd(spec, thetas, a0, j_uni[:, :n]),
                uniform3_sd=sd_of(j_uni),
                uniform3_natural_sd=_natural_sd(spec, thetas, a0, j_uni),
                uniform_wi=uniform[0][:n], uniform_wo=uniform[1][:n], criterion=crit,
                candidates=cands.spec, n_candidates=len(cands), **extra)


def travel_order(angles_deg) -> np.ndarray:
    """The measurement order of pairs (N, 4 angles in degrees) that limits arm travel:
    :func:`gonio.pairsfile.order_for_travel`."""
    return np.asarray(order_for_travel(np.asarray(angles_deg, dtype=np.float64)), int)
