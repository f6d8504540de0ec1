r"""What a fit's answer cannot be trusted for: the ``warnings`` of ``results.json``.

Each warning is ``{"kind", "parameters", "message"}``, computed from the posterior draws:

- ``at_bound``: the 95% interval reaches into the outer 1% of the prior range (measured
  where the prior is flat: in the value, or in its logarithm for a log-uniform prior). The
  bound then shapes the answer, not the data. Not for a circular parameter
  (:meth:`analysis.params.ParamSpec.period`: a symmetric fabric's ``rotation`` on [-90, 90]
  degrees), whose ends are one point: its draws are unwrapped (:mod:`analysis.fit.circular`)
  before this and every other check.
- ``not_informed``: the posterior sd is above half the prior sd, both where the prior is flat;
  the prior sd is that of the fit's actual prior (:meth:`analysis.params.ParamSpec.log_prior`,
  its ties and the area constraint included), from :data:`PRIOR_DRAWS` draws of it.
- ``correlated``: two free parameters with |corr| > 0.95 (Pearson, where each prior is flat):
  the data fix a combination of the two, along a ridge the message describes.
- ``implausible``: a posterior median outside the range real cloth takes: brdf.schema's
  :attr:`~brdf.schema.ParamInfo.plausible` range where it gives one (eta: 1.3 to 1.8, textile
  fibres), else its :attr:`~brdf.schema.ParamInfo.typical` range (the fit's default bounds,
  so only a fit whose bounds were widened can leave it).
- ``misfit``: the model does not describe the data (:func:`analysis.fit.adequacy.adequacy`).
- ``colour_fixed``: the CIEDE2000 difference between the table's mean (albedo) colour and the
  fit's exceeds :data:`COLOUR_DE_MAX` while a colour's channels are held fixed: the fixed
  colour, not the data, decides the fit's colour, and the other parameters are pulled to
  make up for it. The warning names the channels to free. It needs the fit's quality
  figures (:func:`analysis.fit.quality.fit_quality`), so :func:`colour_warnings` is run after
  them (:func:`analysis.fit.workflow.fit_fabric`), not among :data:`CHECKS`.

:data:`CHECKS` lists the checks, each ``check(result) -> list of warnings``;
:func:`fit_warnings` runs them in order, so another kind is one more function appended there.
:func:`assess` fills a result's ``adequacy`` and ``warnings``.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.special

from analysis.fit.adequacy import adequacy
from analysis.families import family
from analysis.params import INTERNAL_LIMIT

__all__ = ["warning", "fit_warnings", "assess", "CHECKS", "prior_sd", "flat_values",
           "colour_warnings", "fixed_colour_channels", "COLOUR_DE_MAX", "BOUND_ZONE",
           "SD_RATIO", "CORR_MAX", "PRIOR_DRAWS"]

#: colour_fixed: the CIEDE2000 difference of mean colours above which a fit with a colour
#: held fixed is warned (about 1 is just noticeable; 5 is plainly another colour).
COLOUR_DE_MAX = 5.0
#: at_bound: the 95% interval reaches into this share of the prior range at either end.
BOUND_ZONE = 0.01
#: not_informed: posterior sd above this share of the prior sd.
SD_RATIO = 0.5
#: correlated: |corr| above this.
CORR_MAX = 0.95
#: Draws of the prior for its sd.
PRIOR_DRAWS = 20000


def warning(kind: str, parameters, message: str) -> dict:
    """One warning: ``{"kind", "parameters", "message"}`` (parameters a list of names)."""
    return {"kind": kind, "parameters": list(parameters), "message": message}


def flat_values(param, x) -> np.ndarray:
    """Values ``x`` where ``param``'s prior is flat: x, or log x for a log-uniform prior."""
    x = np.asarray(x, dtype=np.float64)
    return np.log(x) if param.is_log else x


def _unit(unit: str) -> str:
    """`` deg`` after a number; nothing for a dimensionless ``"1"``."""
    return "" if unit in ("1", "") else f" {unit}"


def _from_flat(param, g: float) -> float:
    return float(np.exp(g) if param.is_log else g)


def prior_sd(spec, n: int = PRIOR_DRAWS, seed: int = 0) -> np.ndarray:
    """The prior sd of each free parameter where its prior is flat (:func:`flat_values`),
    from ``n`` draws of the spec's prior: uniform positions within the bounds, those the
    prior refuses (area1 + area2 > 1, a tied value out of its bounds) dropped."""
    p = np.random.default_rng(seed).uniform(size=(n, spec.ndim))
    u = np.clip(scipy.special.logit(p), -INTERNAL_LIMIT, INTERNAL_LIMIT)
    u = u[np.isfinite(spec.log_prior(u))]
    x = spec.to_natural(u)
    return np.array([np.std(flat_values(spec.params[name], x[:, i]))
                     for i, name in enumerate(spec.free)])


def _flat_samples(result) -> np.ndarray:
    x = result.samples()
    return np.stack([flat_values(result.spec.params[n], x[:, i])
                     for i, n in enumerate(result.names)], -1)


def at_bound(result) -> list[dict]:
    """``at_bound`` warnings (see the module notes)."""
    out = []
    g = _flat_samples(result)
    for i, name in enumerate(result.names):
        p = result.spec.params[name]
        if result.spec.period(name) is not None:     # a circle has no bound, only a wrap
            continue
        g0, g1 = flat_values(p, p.lo), flat_values(p, p.hi)
        lo, hi = np.percentile(g[:, i], [2.5, 97.5])
        for side, edge, q, zone in (("lower", p.lo, (lo - g0) / (g1 - g0),
                                     _from_flat(p, g0 + BOUND_ZONE * (g1 - g0))),
                                    ("upper", p.hi, (g1 - hi) / (g1 - g0),
                                     _from_flat(p, g1 - BOUND_ZONE * (g1 - g0)))):
            if q < BOUND_ZONE and not (side == "upper" and name in result.spec.folds):
                a, b = _from_flat(p, lo), _from_flat(p, hi)   # a fold is no bound
                meaning = ("the data need no noise beyond the table's sigma"
                           if name == "log_noise" and side == "lower"
                           else "the bound, not the data, sets this value")
                out.append(warning("at_bound", [name], (
                    f"{name}: 95% interval [{a:.4g}, {b:.4g}]{_unit(p.unit)} reaches the {side} "
                    f"bound {edge:.4g} (within the outer {100 * BOUND_ZONE:g}% of the prior "
                    f"range [{p.lo:.4g}, {p.hi:.4g}], beyond {zone:.4g}): {meaning}")))
    return out


def not_informed(result) -> list[dict]:
    """``not_informed`` warnings (see the module notes)."""
    post = np.std(_flat_samples(result), axis=0)
    prior = prior_sd(result.spec)
    out = []
    for i, name in enumerate(result.names):
        ratio = post[i] / prior[i] if prior[i] > 0 else np.nan
        if ratio > SD_RATIO:
            where = " of its logarithm" if result.spec.params[name].is_log else ""
            out.append(warning("not_informed", [name], (
                f"{name}: posterior sd{where} {post[i]:.3g} is {ratio:.2f} x the prior's "
                f"{prior[i]:.3g} (above {SD_RATIO:g}): the table hardly informs it; its "
                f"interval mostly restates the prior range")))
    return out


def correlated(result) -> list[dict]:
    """``correlated`` warnings: pairs with |corr| > :data:`CORR_MAX` and their ridge."""
    if len(result.names) < 2:
        return []
    g = _flat_samples(result)
    sd = np.std(g, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.corrcoef(g, rowvar=False)
    out = []
    for i in range(len(result.names)):
        for j in range(i + 1, len(result.names)):
            if not abs(c[i, j]) > CORR_MAX:
                continue
            a, b = result.names[i], result.names[j]
            pa, pb = result.spec.params[a], result.spec.params[b]
            da = f"{'log ' if pa.is_log else ''}{a}"
            db = f"{'log ' if pb.is_log else ''}{b}"
            out.append(warning("correlated", [a, b], (
                f"{a} and {b}: correlation {c[i, j]:+.3f}; the posterior is a ridge along "
                f"which {db} changes by {c[i, j] * sd[j]:+.3g} when {da} changes by "
                f"{sd[i]:+.3g} (one posterior sd): the table fixes a combination of the two, "
                f"not each")))
    return out


def _typical(name: str, spec=None):
    """The plausible range of a fit parameter (the model's flat parameter's,
    :attr:`brdf.FlatParam.plausible`: for a microcylinder thread parameter brdf.schema's
    plausible range, its typical range where it gives none); None for the fit's own
    parameters (scale, noise) and where the model gives none (tangent scales). The model is
    ``spec.family``'s (no spec: the default model)."""
    return (family() if spec is None else spec.family).plausible(name)


def implausible(result) -> list[dict]:
    """``implausible`` warnings: medians outside brdf.schema's plausible (or typical) range."""
    out = []
    for name in result.names:
        typical = _typical(name, result.spec)
        if typical is None:
            continue
        s = result.summary[name]
        if not typical[0] <= s["median"] <= typical[1]:
            out.append(warning("implausible", [name], (
                f"{name}: median {s['median']:.4g}{_unit(s['unit'])} (95% [{s['lo95']:.4g}, "
                f"{s['hi95']:.4g}]) lies outside the range real cloth takes, "
                f"[{typical[0]:g}, {typical[1]:g}]")))
    return out


def misfit(result) -> list[dict]:
    """A ``misfit`` warning when the adequacy verdict is false."""
    a = result.adequacy or {}
    if a.get("adequate") is not False:
        return []
    return [warning("misfit", [], "the model does not describe the data: " + a["reason"])]


def fixed_colour_channels(spec) -> tuple[str, ...]:
    """The channels of ``spec``'s colours that are neither free nor tied to a free one."""
    moving = set(spec.free) | {t for t, (src, _) in spec.ties.items() if src in spec.free}
    return tuple(n for names in spec.family.aliases.values() for n in names
                 if n not in moving)


def colour_warnings(result, max_delta_e: float = COLOUR_DE_MAX) -> list[dict]:
    """A ``colour_fixed`` warning when ``result.quality``'s ``albedo_delta_e2000`` exceeds
    ``max_delta_e`` (CIEDE2000, unitless) and some colour channel is fixed (see the module
    notes); none for a grey table (no colour difference) or with every colour free.

    Examples
    --------
    >>> import types, brdf
    >>> from analysis.params import ParamSpec, defaults_from_fabric
    >>> spec = ParamSpec("kd1", defaults=defaults_from_fabric(brdf.fabric("linen_plain")))
    >>> r = types.SimpleNamespace(spec=spec, quality={"albedo_delta_e2000": 16.5})
    >>> [w["parameters"][:3] for w in colour_warnings(r)]
    [['albedo1_r', 'albedo1_g', 'albedo1_b']]
    >>> r.quality["albedo_delta_e2000"] = 0.7
    >>> colour_warnings(r)
    []
    """
    de = (getattr(result, "quality", None) or {}).get("albedo_delta_e2000")
    fixed = fixed_colour_channels(result.spec)
    if de is None or not np.isfinite(de) or de <= max_delta_e or not fixed:
        return []
    groups = [g for g, names in result.spec.family.aliases.items()
              if any(n in fixed for n in names)]
    return [warning("colour_fixed", list(fixed), (
        f"the fitted mean colour differs from the table's by CIEDE2000 {de:.1f} (above "
        f"{max_delta_e:g}) while {', '.join(groups)} are held fixed: the fixed colour, not "
        f"the data, sets the fit's colour and the other parameters are pulled to make up "
        f"for it; free {', '.join(fixed)} (--free ...,{','.join(groups)})"))]


#: The checks :func:`fit_warnings` runs, in order: ``check(result) -> list of warnings``.
CHECKS: list[Callable] = [at_bound, not_informed, correlated, implausible, misfit]


def fit_warnings(result, checks=None) -> list[dict]:
    """Every warning of ``result`` (a :class:`~analysis.fit.FitResult` with its spec and
    chains, and its ``adequacy`` for ``misfit``), from ``checks`` (default :data:`CHECKS`)."""
    out = []
    for check in CHECKS if checks is None else checks:
        out.extend(check(result))
    return out


def assess(result, table=None):
    """Fill ``result.adequacy`` (:func:`~analysis.fit.adequacy.adequacy`, the region tests
    at ``table``'s directions) and ``result.warnings``; returns ``result``."""
    wi = None if table is None else np.asarray(table.wi)
    wo = None if table is None else np.asarray(table.wo)
    result.adequacy = adequacy(result, wi, wo)
    result.warnings = fit_warnings(result)
    return result
