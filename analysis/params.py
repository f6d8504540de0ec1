"""Parameter specification for fitting a model: bounds, priors, ties.

The names, their bounds, units and priors come from the model's family
(:mod:`analysis.families`: the registered model's flat parameters, :class:`brdf.ParamSchema`);
the parsing of ``--free``/``--tie`` strings is in :mod:`analysis.paramnames`; this module
re-exports the microcylinder's names.

Each parameter is free (sampled), fixed (at its default, normally the preset's value) or tied to
another one (``eta2=eta1``: eta2 takes eta1's value; ``area2=1-area1``: the complement).

The sampler works in unbounded *internal* coordinates: with g the identity for a uniform prior
and the natural log for a log-uniform one, p = (g(x) - g(lo)) / (g(hi) - g(lo)) is the position
of x within its bounds and u = logit(p) = log(p / (1 - p)). The prior, flat in g(x), has the
density p (1 - p) in u (the Jacobian), so the log-prior is sum of log p + log(1 - p) over the
free parameters (minus infinity where area1 + area2 > 1 or a tied value leaves its bounds).
A posterior piled against a bound (an albedo near 1, a k_d near 0) is then a smooth bump in u
rather than a wall, which the samplers and the Laplace approximation handle far better.
Internal values are limited to +-:data:`INTERNAL_LIMIT` (p within 4e-18 of a bound). A
circular parameter (a fabric's ``rotation``, :meth:`ParamSpec.period`) has no bound to pile
against, only a wrap: its internal coordinate is linear instead, its prior flat in it
(:meth:`ParamSpec.to_natural`).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from analysis.families import ModelFamily, family
from analysis.lazy import special
from analysis.param import INTERNAL_LIMIT, INTERNAL_WIDTH, Param
from analysis.paramnames import (BASE_PARAMS, DEFAULT_FREE, DEFAULT_TIES, MODEL_PARAM_NAMES,
                                 PARAM_NAMES, checked_bounds, checked_defaults,
                                 checked_priors, checked_ties, checked_toml,
                                 defaults_from_fabric, parse_free, parse_ties,
                                 resolve_ties, unknown)
from gonio.statefields import load_toml

__all__ = ["Param", "ParamSpec", "INTERNAL_LIMIT", "BASE_PARAMS", "PARAM_NAMES", "MODEL_PARAM_NAMES",
           "DEFAULT_FREE", "DEFAULT_TIES", "defaults_from_fabric", "parse_free", "parse_ties"]


class ParamSpec:
    """Which parameters are free, fixed or tied, and their bounds, priors and defaults.

    Parameters
    ----------
    free : str or sequence of str
        Free parameter names (aliases ``albedo1``/``albedo2`` expand to the three channels).
    defaults : mapping, optional
        Natural-unit defaults (e.g. :func:`defaults_from_fabric`); missing ones use the
        built-in fallbacks. Free parameters start here; fixed ones stay here.
    ties : str, sequence or mapping, optional
        ``"eta2=eta1"`` (equal) or ``"area2=1-area1"`` (complement); exactly one side of
        each tie is free (when it is the target, the two are swapped).
    bounds : mapping name -> (lo, hi), optional
        Override bounds (natural units).
    priors : mapping name -> "uniform" | "log-uniform", optional
        Override priors.
    family : ModelFamily or str, optional
        The model (:func:`analysis.families.family`): its parameter names, bounds, priors
        and forward-model arguments. Default the microcylinder.
    notes : sequence of str, optional
        Sentences on the choices made for identifiability (written to ``results.json``).
    periods : mapping name -> float, optional
        Angles whose model repeats every ``period`` (natural units), from the model object
        (:meth:`analysis.families.ModelFamily.periods`: a fabric's ``rotation``, 180 or 360
        degrees); a parameter whose range holds a whole period is circular (:meth:`period`).
    folds : mapping name -> float, optional
        Parameters whose upper bound (the value) is a fold of a symmetry of the model, not a
        limit (:func:`analysis.fit.swap.fold_thread_swap`: a value above it describes the same
        model as one below): an interval reaching it is no ``at_bound``.

    Raises
    ------
    ValueError
        Unknown names (listing the valid ones), a tie with both sides free or neither, a
        parameter tied twice, a free parameter whose default lies outside its bounds, bad
        bounds, priors or start values (not numbers, not finite).

    Examples
    --------
    >>> spec = ParamSpec("eta1,gamma_s1", defaults={"eta1": 1.5, "gamma_s1": 5.0},
    ...                  ties="eta2=eta1")
    >>> spec.free, spec.ndim
    (('eta1', 'gamma_s1'), 2)
    >>> v = spec.values(spec.to_internal(np.array([[1.6, 4.0]])))
    >>> round(float(v["eta2"][0]), 12), round(float(v["gamma_s1"][0]), 12)
    (1.6, 4.0)
    >>> ParamSpec("base", family="lambert").free
    ('base_r', 'base_g', 'base_b')
    """

    def __init__(self, free, defaults: Mapping[str, float] | None = None, ties=None,
                 bounds: Mapping[str, Sequence[float]] | None = None,
                 priors: Mapping[str, str] | None = None,
                 family: ModelFamily | str | None = None, notes: Sequence[str] = (),
                 periods: Mapping[str, float] | None = None,
                 folds: Mapping[str, float] | None = None):
        fam = _family(family)
        self.family = fam
        self.notes = tuple(notes)
        self.periods = {str(k): float(v) for k, v in (periods or {}).items()}
        self.folds = {str(k): float(v) for k, v in (folds or {}).items()}
        defaults = checked_defaults(defaults, fam)
        bounds, priors = checked_bounds(bounds, fam), checked_priors(priors, fam)
        free = list(parse_free(free, fam))
        self.ties = resolve_ties(free, checked_ties(ties, fam))
        free = [f for f in free if f not in self.ties]
        self.params: dict[str, Param] = {}
        for name in fam.names:
            lo, hi, prior, unit, fallback = fam.entry(name)
            lo, hi = bounds.get(name, (lo, hi))
            prior = priors.get(name, prior)
            self.params[name] = Param(name, float(lo), float(hi), prior, unit,
                                      float(defaults.get(name, fallback)))
        for name, per in self.periods.items():  # a repeating angle spans one whole period
            p = self.params.get(name)
            if p is not None and name not in bounds and not p.is_log and p.hi - p.lo < per:
                self.params[name] = dataclasses.replace(p, lo=-per / 2.0, hi=per / 2.0)
        self.free: tuple[str, ...] = tuple(free)
        if not self.free:
            raise ValueError("no free parameter left after applying ties")
        for name in self.free:
            p = self.params[name]
            if not (p.lo <= p.default <= p.hi) or (p.is_log and p.default <= 0):
                raise ValueError(f"start value of {name} = {p.default:g} {p.unit} lies outside "
                                 f"its bounds [{p.lo:g}, {p.hi:g}]; widen the bounds or set a "
                                 f"start inside them")
        self._index = {n: i for i, n in enumerate(self.free)}
        self.lower = np.array([self.params[n].internal_bounds[0] for n in self.free])
        self.upper = np.array([self.params[n].internal_bounds[1] for n in self.free])
        #: A typical scale of each internal coordinate (for step sizes and starting balls).
        self.width = np.full(len(self.free), INTERNAL_WIDTH)
        # (lo, centre, period) of each circular free parameter: fixed with the bounds and
        # periods, asked on every evaluation of the prior and every transform
        self._circles = {n: (self.params[n].lo, 0.5 * (self.params[n].lo + self.params[n].hi),
                             self.period(n)) for n in self.free if self.period(n) is not None}
        self._circular = np.array([n in self._circles for n in self.free], dtype=bool)
        # each free parameter's map to its natural value as arrays, so that to_natural (in
        # every evaluation of a fit) runs once over the columns, not a call a parameter
        free_params = [self.params[n] for n in self.free]
        scale = np.array([p.scale_bounds for p in free_params])
        self._g0, self._span = scale[:, 0], scale[:, 1] - scale[:, 0]
        self._log = np.array([p.is_log for p in free_params], dtype=bool)
        self._lo = np.array([p.lo for p in free_params])
        self._hi = np.array([p.hi for p in free_params])

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_toml(cls, path, defaults: Mapping[str, float] | None = None,
                  free=None, ties=None, family: ModelFamily | str | None = None
                  ) -> "ParamSpec":
        """Read a spec from a TOML file.

        Keys: ``free`` (list), ``tie`` (list of ``"a=b"``), tables ``[bounds]``
        (name = [lo, hi]), ``[prior]`` (name = "uniform" | "log-uniform") and ``[start]``
        (name = value, overriding the defaults). ``free``/``ties`` given here are added.

        Raises
        ------
        ValueError
            The file is not valid TOML, holds unknown keys, a key of the wrong type (``tie =
            [1]``, a table where a number belongs) or a contradiction (a tie with both sides
            free): the message names the file and the key. The whole spec is checked here,
            once, before any work.
        """
        path = Path(path)
        fam = _family(family)
        doc = load_toml(path, "fit spec")     # unreadable, invalid or nested: one line
        try:
            doc = checked_toml(doc, fam)
            d = checked_defaults(defaults, fam)
            d.update(doc.get("start", {}))
            fr = doc.get("free", [])
            if free:
                fr += [f for f in parse_free(free, fam) if f not in fr]
            if isinstance(ties, str):
                ties = ties.split(",")
            tie_list = doc.get("tie", []) + list(ties or [])
            return cls(fr, defaults=d, ties=tie_list, bounds=doc.get("bounds"),
                       priors=doc.get("prior"), family=fam)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None

    # ------------------------------------------------------------------ accessors
    @property
    def ndim(self) -> int:
        return len(self.free)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(self.params[n].unit for n in self.free)

    def start(self) -> np.ndarray:
        """Internal coordinates of the free parameters' defaults, shape (ndim,); a default on
        a bound starts just inside it (internal values are clipped to +-10: p = 4.5e-5)."""
        u = self.to_internal(np.array([self.params[n].default for n in self.free]))
        return np.clip(u, -10.0, 10.0)

    def with_defaults(self, **values: float) -> "ParamSpec":
        """A copy whose defaults (start values) are changed."""
        new = object.__new__(ParamSpec)
        new.__dict__.update(self.__dict__)
        new.params = dict(self.params)
        for k, v in values.items():
            if k not in new.params:
                raise unknown(k, cat=self.family)
            new.params[k] = dataclasses.replace(new.params[k], default=float(v))
        return new

    def with_free(self, names) -> "ParamSpec":
        """A copy with ``names`` freed as well: bounds, priors, defaults, ties, notes and
        periods kept."""
        ps = self.params.values()
        return ParamSpec(list(self.free) + list(names), defaults={p.name: p.default for p in ps},
                         bounds={p.name: (p.lo, p.hi) for p in ps},
                         priors={p.name: p.prior for p in ps}, ties=self.ties,
                         family=self.family, notes=self.notes, periods=self.periods,
                         folds=self.folds)

    def with_periods(self, periods: Mapping[str, float]) -> "ParamSpec":
        """A copy with the periods ``periods`` (name -> period, natural units) added; a
        periodic parameter left at its family's bounds spans one whole period, centred on 0
        (a fabric's ``rotation``: [-90, 90] degrees for 180, [-180, 180] for 360)."""
        ps = self.params.values()
        own = {p.name: (p.lo, p.hi) for p in ps if (p.lo, p.hi) != self.family.entry(p.name)[:2]}
        return ParamSpec(list(self.free), defaults={p.name: p.default for p in ps}, bounds=own,
                         priors={p.name: p.prior for p in ps}, ties=self.ties,
                         family=self.family, notes=self.notes,
                         periods={**self.periods, **periods}, folds=self.folds)

    def period(self, name: str) -> float | None:
        """The period of a circular parameter: its model repeats every ``periods[name]`` and
        its range [lo, hi] holds at least one whole period (a fabric's ``rotation`` on [-90,
        90] degrees, symmetric under a half turn); None otherwise, and for a log prior.

        Examples
        --------
        >>> spec = ParamSpec("rotation", periods={"rotation": 180.0})
        >>> spec.period("rotation"), spec.with_periods({"rotation": 360.0}).period("rotation")
        (180.0, 360.0)
        >>> spec.with_periods({"rotation": 360.0}).params["rotation"].hi
        180.0
        """
        period = self.periods.get(name)
        p = self.params.get(name)
        if period is None or p is None or p.is_log or not period > 0:
            return None
        return period if p.hi - p.lo >= period * (1.0 - 1e-9) else None

    def to_natural(self, theta) -> np.ndarray:
        """Internal (..., ndim) -> natural values of the free parameters (..., ndim).

        A circular parameter (:meth:`period`) has a linear internal coordinate, u = (x -
        centre) * INTERNAL_WIDTH / period, its natural value wrapped into [lo, lo + period):
        the sampler and the optimizer move across the wrap as anywhere else on the circle,
        where a logit would make it a wall at each end.

        Examples
        --------
        >>> spec = ParamSpec("rotation", periods={"rotation": 180.0})
        >>> spec.to_natural(spec.to_internal(np.array([[85.0]])) + 0.25).round(9).tolist()
        [[-83.75]]
        """
        theta = np.asarray(theta, dtype=np.float64)
        v = self._g0 + special.expit(theta) * self._span    # Param.to_natural, all columns
        if self._log.any():
            v[..., self._log] = np.exp(v[..., self._log])
        out = np.clip(v, self._lo, self._hi)
        for n, (lo, mid, per) in self._circles.items():
            i = self._index[n]
            out[..., i] = lo + np.mod(mid - lo + theta[..., i] * per / INTERNAL_WIDTH, per)
        return out

    def to_internal(self, x) -> np.ndarray:
        """Natural (..., ndim) -> internal coordinates (NaN outside the bounds)."""
        x = np.asarray(x, dtype=np.float64)
        out = np.empty_like(x)
        for i, n in enumerate(self.free):
            circle, p = self._circles.get(n), self.params[n]
            if circle is None:
                out[..., i] = p.to_internal(x[..., i])
            else:
                inside = (x[..., i] >= p.lo) & (x[..., i] <= p.hi)
                u = (x[..., i] - circle[1]) * INTERNAL_WIDTH / circle[2]
                out[..., i] = np.where(inside, u, np.nan)
        return out

    @property
    def circular(self) -> np.ndarray:
        """Per free parameter, whether it is circular (bool (ndim,)): its internal coordinate
        is linear and its prior flat in it (:meth:`to_natural`)."""
        return self._circular.copy()

    def values(self, theta) -> dict[str, np.ndarray]:
        """Every parameter's natural value for internal coordinates ``theta`` (B..., ndim).

        Returns a dict name -> array of shape B... (fixed ones broadcast).
        """
        theta = np.asarray(theta, dtype=np.float64)
        batch = theta.shape[:-1]
        nat = self.to_natural(theta)
        out: dict[str, np.ndarray] = {}
        for name, p in self.params.items():
            if name in self._index:
                out[name] = nat[..., self._index[name]]
            else:
                out[name] = np.full(batch, p.default)
        for target, (source, kind) in self.ties.items():
            out[target] = out[source] if kind == "equal" else 1.0 - out[source]
        return out

    def log_prior(self, theta) -> np.ndarray:
        """Log prior (up to a constant) for internal ``theta`` (B..., ndim) -> (B...,).

        Flat in each natural value (or its log) within the bounds: in the internal logit
        coordinates the sum of log p + log(1 - p); -inf beyond +-INTERNAL_LIMIT, where the
        model refuses the values together (its ``admissible``: a fabric's area1 + area2 > 1)
        or a tied value leaves its own bounds.
        """
        theta = np.asarray(theta, dtype=np.float64)
        ok = np.all((theta >= self.lower) & (theta <= self.upper) & np.isfinite(theta), axis=-1)
        with np.errstate(invalid="ignore"):    # a circle's coordinate is linear: no Jacobian
            jac = -np.where(self._circular, 0.0, np.logaddexp(0.0, theta)
                            + np.logaddexp(0.0, -theta)).sum(axis=-1)
        cls = self.family.cls
        joint = bool(set(cls.CONSTRAINED) & set(self.free))
        if self.ties or joint:
            v = self.values(theta)
            if cls.CONSTRAINED:
                ok &= cls.admissible(v)
            for target in self.ties:
                p = self.params[target]
                ok &= (v[target] >= p.lo) & (v[target] <= p.hi)
        return np.where(ok, jac, -np.inf)

    def model_kwargs(self, values: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Keyword arguments of the model's forward model (its class's ``batch_kwargs``,
        :meth:`analysis.families.ModelFamily.model_kwargs`): for the microcylinder each
        (B..., 2), albedo (B..., 2, 3) and ``tangent_scale``; for a baseline each scalar
        (B...), RGB (B..., 3)."""
        return self.family.model_kwargs(values)

    @property
    def model(self) -> str:
        """The name of the model fitted (``microcylinder`` or a baseline's)."""
        return self.family.name

    def describe(self) -> dict:
        """A JSON-ready description (for checkpoints and reports); the model is the
        configuration's ``model`` (:meth:`analysis.fit.FitOptions.config`)."""
        return {
            "free": list(self.free),
            "ties": {k: list(v) for k, v in self.ties.items()},
            "params": {n: {"lo": p.lo, "hi": p.hi, "prior": p.prior, "unit": p.unit,
                           "default": p.default} for n, p in self.params.items()},
            **({"periods": dict(self.periods)} if self.periods else {}),
            **({"folds": dict(self.folds)} if self.folds else {}),
        }

    def __repr__(self) -> str:
        model = "" if self.family.is_default else f", model={self.model!r}"
        return f"ParamSpec(free={list(self.free)}, ties={self.ties}{model})"


def _family(value) -> ModelFamily:
    """A family from a family or a model's name (None: the microcylinder)."""
    return value if isinstance(value, ModelFamily) else family(value)
