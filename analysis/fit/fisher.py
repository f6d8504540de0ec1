r"""Which parameters a table can tell, before sampling: the Fisher information at the start.

For the likelihood of :mod:`analysis.likelihood` (the residual space y = log(1 + f cos
theta_i), or log f for relative data, with variance s^2 per used value) the expected
information about the candidate parameters u, in their fitting transform (the internal logit
coordinates of :mod:`analysis.params`), is

.. math::

    I_{ab} = c_\mu \sum_k \frac{\partial_a \mu_k \, \partial_b \mu_k}{s_k^2}
           + \frac{c_s}{2} \sum_k \frac{\partial_a s_k^2 \, \partial_b s_k^2}{s_k^4}

with :math:`\mu_k` the model's prediction in the residual space (``scale`` included),
:math:`s_k^2` the table's variance plus :math:`e^{2\,\mathrm{log\_noise}}`, and
:math:`c_\mu = c_s = 1` for the Gaussian likelihoods, :math:`c_\mu = (\nu + 1)/(\nu + 3)`,
:math:`c_s = \nu/(\nu + 3)` for the Student-t. The derivatives are central finite differences
in u (one batched evaluation of the model). The flat prior within the bounds is a standard
logistic distribution in u: standard deviation :math:`\pi/\sqrt 3` and information 1/3 per
parameter. The Cramér–Rao standard deviation reported is
:math:`\sqrt{[(I + I_\mathrm{prior})^{-1}]_{aa}}` (the Bayesian bound: finite, near the prior's,
for a parameter without effect), and correlations come from the same inverse.

A parameter is *informed* when that sd is below ``informed_ratio`` (0.5) times the prior's, and
two are *confounded* when their correlation exceeds ``confounded`` (0.95) in magnitude. The
suggested free set is chosen forward: the candidates in order of their own information, each
taken when, freed together with those taken before (the others fixed), all of them stay
informed and no two of them are confounded; so of a confounded pair (which the marginal sds
show both not informed) one is kept.

One rule overrides the information: on an RGB table whose mean (albedo) colour the start
contradicts (CIEDE2000 above :data:`analysis.fit.trust.COLOUR_DE_MAX` between the table's
colour and the start's, the start's scaled to the table's luminance so that only hue and
chroma count), every candidate colour channel is suggested. The information at a start of
the wrong colour is no guide there: a colour the data contradict, held fixed, pulls every
other parameter to make up for it
(:func:`analysis.fit.quality.start_colour_difference`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

import gonio
from analysis.families import family_of
from analysis.fit.driver import with_nuisance
from analysis.fit.posterior import LogPosterior, forward_model
from analysis.fit.quality import start_colour_difference
from analysis.fit.trust import COLOUR_DE_MAX
from analysis.fit.workflow import fit_spec
from analysis.likelihood import Likelihood, is_grey
from analysis.params import ParamSpec

__all__ = ["FisherReport", "fisher_information", "table_information", "suggest_free",
           "suggest_for_file",
           "candidate_spec", "PRIOR_SD", "INFORMED_RATIO", "CONFOUNDED"]

#: Standard deviation of the flat prior in the internal (logit) coordinates: the standard
#: logistic distribution's.
PRIOR_SD = math.pi / math.sqrt(3.0)
#: Fisher information of the standard logistic prior about its location.
PRIOR_INFORMATION = 1.0 / 3.0
#: A parameter is informed when its Cramér–Rao sd is below this fraction of the prior's.
INFORMED_RATIO = 0.5
#: Two parameters are confounded when the magnitude of their correlation exceeds this.
CONFOUNDED = 0.95
#: Finite-difference step in the internal coordinates (whose typical scale is 4).
STEP = 1e-3


@dataclasses.dataclass
class FisherReport:
    """What a table tells of each candidate parameter at the start point.

    Attributes
    ----------
    names : tuple of str
        The candidate parameters (free parameters of the spec, nuisance ones included).
    start : dict
        Their natural values at the point of evaluation.
    information : ndarray (ndim, ndim)
        The table's Fisher information in the internal coordinates (prior excluded).
    cr_sd, prior_sd : ndarray (ndim,)
        Cramér–Rao standard deviation (prior information included) and the prior's, both in
        the internal coordinates.
    natural_sd : ndarray (ndim,)
        ``cr_sd`` in the parameter's own unit at the start (times the slope of the natural
        value in the internal coordinate there).
    correlation : ndarray (ndim, ndim)
        From the inverse of the information plus the prior's.
    confounded : list of (str, str, float)
        Pairs whose correlation exceeds :data:`CONFOUNDED` in magnitude, strongest first.
    suggested : tuple of str
        The suggested free set (see the module notes), in the candidates' order.
    n_used : int
        Values of the table that enter the likelihood.
    units : dict
        Each candidate's unit.
    """

    names: tuple
    start: dict
    information: np.ndarray
    cr_sd: np.ndarray
    prior_sd: np.ndarray
    natural_sd: np.ndarray
    correlation: np.ndarray
    confounded: list
    suggested: tuple
    n_used: int
    units: dict = dataclasses.field(default_factory=dict)
    informed_ratio: float = INFORMED_RATIO

    @property
    def ratio(self) -> np.ndarray:
        """Cramér–Rao sd over the prior's, per parameter."""
        return self.cr_sd / self.prior_sd

    def verdict(self, name: str) -> str:
        """"well informed" (ratio below a fifth of the threshold), "informed" or
        "not informed"."""
        r = float(self.ratio[self.names.index(name)])
        if r < 0.2 * self.informed_ratio:
            return "well informed"
        return "informed" if r < self.informed_ratio else "not informed"

    def summary(self) -> dict:
        """JSON-ready: per parameter its start, CR sd, prior sd, ratio and verdict; the
        confounded pairs; the suggested free set."""
        return {"parameters": {n: {"start": float(self.start[n]), "cr_sd": float(s),
                                   "prior_sd": float(p), "ratio": float(s / p),
                                   "natural_sd": float(x), "verdict": self.verdict(n)}
                               for n, s, p, x in zip(self.names, self.cr_sd, self.prior_sd,
                                                     self.natural_sd)},
                "confounded": [{"parameters": [a, b], "correlation": c}
                               for a, b, c in self.confounded],
                "suggested": list(self.suggested), "n_used": self.n_used,
                "informed_ratio": self.informed_ratio, "confounded_above": CONFOUNDED}


def fisher_information(logpost: LogPosterior, theta, step: float = STEP) -> np.ndarray:
    """The expected information of ``logpost``'s likelihood about its free parameters at
    internal ``theta`` (ndim,), in the internal coordinates (see the module notes).

    Returns
    -------
    ndarray (ndim, ndim)
    """
    theta = np.asarray(theta, dtype=np.float64)
    d = theta.size
    lik, spec = logpost.lik, logpost.spec
    pts = np.repeat(theta[None], 2 * d + 1, axis=0)
    pts[1:d + 1] += step * np.eye(d)
    pts[d + 1:] -= step * np.eye(d)
    with np.errstate(all="ignore"):
        mu = lik.transform(logpost.predict(pts))                  # (2d + 1, n_used)
    s2 = _variance(lik, spec.values(pts), logpost.use_noise, mu.shape[-1])
    dmu = (mu[1:d + 1] - mu[d + 1:]) / (2 * step)                # (d, n_used)
    ds2 = (s2[1:d + 1] - s2[d + 1:]) / (2 * step)
    c_mu, c_s = _factors(lik)
    w = 1.0 / s2[0]
    info = c_mu * (dmu * w) @ dmu.T + 0.5 * c_s * (ds2 * w * w) @ ds2.T
    if not np.all(np.isfinite(info)):
        raise ValueError("the model's prediction is not finite near the start point: its "
                         "information cannot be computed; check that the fabric matches the "
                         "table")
    return 0.5 * (info + info.T)


def _variance(lik: Likelihood, values, use_noise: bool, n: int) -> np.ndarray:
    """s^2 (B, n_used) of each value in the residual space at parameter values ``values``."""
    b = values["log_noise"].shape[0]
    s2 = np.zeros((b, n)) if lik.sigma_y2 is None else np.repeat(lik.sigma_y2[None], b, 0)
    if use_noise:
        s2 = s2 + np.exp(2.0 * values["log_noise"])[:, None]
    return s2


def _factors(lik: Likelihood) -> tuple[float, float]:
    """(c_mu, c_s) of the likelihood's kind (module notes)."""
    if lik.kind == "student-t":
        return (lik.nu + 1.0) / (lik.nu + 3.0), lik.nu / (lik.nu + 3.0)
    return 1.0, 1.0


def _suggest(names, info, informed_ratio) -> tuple:
    """Forward selection: the candidates in order of their own information, each taken when,
    with those taken before, every one of them stays informed and no two confounded (the sds
    and correlations of the sub-matrix of the information, the prior's added)."""
    taken = []
    for i in np.argsort(-np.diag(info), kind="stable"):
        trial = taken + [int(i)]
        cov = np.linalg.inv(info[np.ix_(trial, trial)] + PRIOR_INFORMATION * np.eye(len(trial)))
        sd = np.sqrt(np.diag(cov))
        corr = cov / np.outer(sd, sd) - np.eye(len(trial))
        if np.all(sd < informed_ratio * PRIOR_SD) and np.all(np.abs(corr) <= CONFOUNDED):
            taken = trial
    return tuple(names[i] for i in sorted(taken))


def table_information(table, spec: ParamSpec, model, *, likelihood: str = "gaussian",
                      nu: float = 4.0, theta=None,
                      informed_ratio: float = INFORMED_RATIO) -> FisherReport:
    """Which of ``spec``'s free parameters ``table`` can tell, from the Fisher information
    at the start point (module notes).

    Parameters
    ----------
    table : gonio.Table
    spec : ParamSpec
        The candidates are its free parameters, plus ``log_noise`` when the table has no
        sigma and ``scale`` for relative data (as the fit adds them).
    model : callable
        The forward model (:class:`~analysis.fit.posterior.FabricModel` at the table's pairs).
    likelihood, nu
        As :func:`analysis.fit.fit`.
    theta : array_like (ndim,), optional
        Internal coordinates of the point; default the spec's start. Without sigma in the
        table, ``log_noise`` starts at the log of the rms residual there (unless ``theta``
        is given).
    informed_ratio : float
        The threshold of CR sd / prior sd below which a parameter counts as informed.

    Returns
    -------
    FisherReport

    Examples
    --------
    >>> import brdf
    >>> from analysis.fit import FabricModel
    >>> from analysis.params import defaults_from_fabric
    >>> from gonio import measure, Instrument
    >>> fab = brdf.fabric("silk_crepe_de_chine")
    >>> t = measure(fab, "full:30:60", Instrument(snr=20), seed=1, progress=False)
    >>> spec = ParamSpec("kd1,tangent_scale2", defaults=defaults_from_fabric(fab))
    >>> r = table_information(t, spec, FabricModel(fab, t.wi, t.wo))
    >>> r.verdict("kd1") != "not informed"
    True
    """
    lik = Likelihood(table, kind=likelihood, nu=nu)
    spec = with_nuisance(spec, lik)
    logpost = LogPosterior(spec, lik, model)
    if theta is None:
        if not lik.has_sigma:
            spec = _noise_at_start(spec, lik, logpost)
            logpost = LogPosterior(spec, lik, model)
        theta = spec.start()
    theta = np.asarray(theta, dtype=np.float64)
    info = fisher_information(logpost, theta)
    cov = np.linalg.inv(info + PRIOR_INFORMATION * np.eye(spec.ndim))
    sd = np.sqrt(np.diag(cov))
    corr = cov / np.outer(sd, sd)
    names = spec.free
    pairs = sorted(((names[i], names[j], float(corr[i, j]))
                    for i in range(len(names)) for j in range(i + 1, len(names))
                    if abs(corr[i, j]) > CONFOUNDED), key=lambda p: -abs(p[2]))
    prior = np.full(len(names), PRIOR_SD)
    h = STEP * np.eye(spec.ndim)
    slope = np.diag(spec.to_natural(theta + h) - spec.to_natural(theta - h)) / (2 * STEP)
    return FisherReport(names=names, start=dict(zip(names, spec.to_natural(theta).tolist())),
                        information=info, cr_sd=sd, prior_sd=prior,
                        natural_sd=sd * np.abs(slope), correlation=corr,
                        confounded=pairs,
                        suggested=_suggest(names, info, informed_ratio),
                        n_used=lik.n_used, units=dict(zip(names, spec.units)),
                        informed_ratio=informed_ratio)


def _noise_at_start(spec: ParamSpec, lik: Likelihood, logpost: LogPosterior) -> ParamSpec:
    """``spec`` with ``log_noise`` starting at the log of the rms residual at the start."""
    with np.errstate(all="ignore"):
        r = lik.y - lik.transform(logpost.predict(spec.start()[None]))[0]
    rms = float(np.sqrt(np.mean(r * r)))
    p = spec.params["log_noise"]
    if not (np.isfinite(rms) and rms > 0):
        return spec
    return spec.with_defaults(log_noise=float(np.clip(np.log(rms), p.lo + 1e-6, p.hi - 1e-6)))


def candidate_spec(table, fabric, free=None, ties=None, toml=None) -> ParamSpec:
    """The candidates of :func:`suggest_free`: ``free`` / ``ties`` / ``toml`` as
    :func:`analysis.fit.fit_spec` takes them when given; otherwise for a model with a default
    free set of its own (``DEFAULT_FREE``: the microcylinder's) that set and its ties plus its
    colours for an RGB table (a grey table cannot tell the channels apart: the
    microcylinder's two albedos) and its ``rotation`` (degrees; where the table cannot tell
    it, the Fisher test leaves it out), for any other model its default free set for the table
    (every parameter, with :meth:`analysis.families.ModelFamily.default_free`'s
    identifiability choices)."""
    fam = family_of(fabric)
    if fam.cls.DEFAULT_FREE is None:
        return fit_spec(fabric, free, ties, toml, table=table)
    if free is None and toml is None:
        free, default_ties, _ = fam.default_free()
        free = list(free)
        ties = list(default_ties) if ties is None else ties
        if not is_grey(np.asarray(table.values, dtype=np.float64)):
            free += list(fam.schema.colours)
        free += [n for n in ("rotation",) if n in fam.schema]
    return fit_spec(fabric, free, ties, toml)


def suggest_free(table, fabric, model, free=None, ties=None, toml=None, *,
                 likelihood: str = "gaussian", nu: float = 4.0) -> tuple[FisherReport, dict]:
    """:func:`table_information` of the candidates of :func:`candidate_spec`, and the ties
    of the suggested free set (``{target: "source"}`` or ``"1-source"``, only those whose
    source is suggested).

    Returns
    -------
    (FisherReport, dict)
    """
    spec = candidate_spec(table, fabric, free, ties, toml)
    report = table_information(table, spec, model, likelihood=likelihood, nu=nu)
    colours = [n for names in spec.family.aliases.values() for n in names if n in spec.free]
    if colours and start_colour_difference(table, spec, model) > COLOUR_DE_MAX:
        keep = set(report.suggested) | set(colours)
        report = dataclasses.replace(report, suggested=tuple(n for n in report.names
                                                             if n in keep))
    kept = {t: (src if kind == "equal" else f"1-{src}")
            for t, (src, kind) in spec.ties.items() if src in report.suggested}
    return report, kept


def suggest_for_file(path, fabric, free=None, ties=None, toml=None, *, read_options=None,
                     likelihood: str = "gaussian", nu: float = 4.0) -> tuple[FisherReport, dict]:
    """What ``microcyl fit --suggest`` does: the free set given (``free``, ``ties``, ``toml``
    as :func:`analysis.fit.fit_spec` takes them) checked before the table is read, the table
    ``path`` read (``gonio.read(path, **read_options)``), then :func:`suggest_free` with
    ``fabric``'s model at the table's pairs. Nothing is written.

    Returns
    -------
    (FisherReport, dict)
        As :func:`suggest_free`.
    """
    if free is not None or toml is not None:
        fit_spec(fabric, free, ties, toml)      # a bad free set, tie or spec: before reading
    table = gonio.read(path, **dict(read_options or {}))
    return suggest_free(table, fabric, forward_model(fabric, table.wi, table.wo), free, ties,
                        toml, likelihood=likelihood, nu=nu)
