r"""A source BRDF projected onto a renderer's sheen model: least squares over the stated grid.

The target is one of microcyl's own models of what renderers evaluate (``charlie``: glTF's
KHR_materials_sheen; ``zeltner``: MaterialX's ``sheen_bsdf`` mode zeltner, OpenPBR's fuzz,
Cycles' microfiber sheen), each a sheen over a Lambertian base with parameters
``base`` (RGB), ``sheen`` (RGB) and ``roughness``. The projection minimises

    sum over pairs and channels of  w (f_t(wi, wo; x) - f_s(wi, wo))^2 c(wi, wo)^2

over x = (base, sheen, roughness) within the model's ranges (scipy.optimize.least_squares,
trust-region reflective, bounded), w the grid's solid-angle weights
(:class:`~analysis.export.grid.HemisphereGrid`) and c the objective's cosine factor
(:data:`OBJECTIVES`): ``cos_cos`` (the default) fits f_r cos(theta_i) cos(theta_o), the
quantity whose relative L2 error the fidelity reports; ``cos_o`` fits f_r cos(theta_o). On
velvet (6 x 8 grid) ``cos_o`` leaves a relative L2 error of f_r cos cos of 1.14 (Zeltner), worse
than no sheen at all, where ``cos_cos`` leaves 0.84: f_r cos(theta_o) weights grazing
incidence, where velvet's lobe is tallest, far above what any view of it shows. Three starts (roughness 0.3, 0.6, 0.9) guard against a local minimum; the best is
kept. The Jacobian is taken by forward differences, all seven columns in one batched call of
the model's ``prepare(wi, wo).eval``.

For a fit, :func:`project_draws` projects a subsample of the posterior draws (each from the
medians' projection) and reports each target parameter's median and 95% interval.

Examples
--------
>>> from brdf.baselines import Zeltner
>>> from analysis.export.grid import HemisphereGrid
>>> truth = Zeltner(base=(0.2, 0.3, 0.4), sheen=(0.9, 0.5, 0.1), roughness=0.4)
>>> p = project(truth, "zeltner", HemisphereGrid(5, 8))      # a model projects onto itself
>>> [round(v, 3) for v in p.values["sheen"]], round(p.values["roughness"], 3)
([0.9, 0.5, 0.1], 0.4)
"""

from __future__ import annotations

import dataclasses

import numpy as np

from analysis.export.grid import DEFAULT_GRID, HemisphereGrid
from analysis.lazy import optimize
from brdf import model_class

__all__ = ["Projection", "project", "project_draws", "target_model", "TARGET_MODELS",
           "OBJECTIVES"]

#: The cosine factor c(cos_i, cos_o) of each objective (module notes).
OBJECTIVES = {"cos_cos": lambda ci, co: ci * co, "cos_o": lambda ci, co: co}
#: The models a projection may target.
TARGET_MODELS = ("zeltner", "charlie")
_STARTS = (0.3, 0.6, 0.9)
_STEP = 1e-6


@dataclasses.dataclass(frozen=True)
class Projection:
    """A target model's parameters projected from a source.

    Attributes
    ----------
    model : str
        ``zeltner`` or ``charlie``.
    values : dict
        ``base`` and ``sheen`` (3 floats each, linear RGB in [0, 1]) and ``roughness``
        (dimensionless): the projection of the source (for a fit: the medians over the
        projected draws).
    intervals : dict
        For a fit, each parameter's 95% interval over the projected draws (``base`` and
        ``sheen``: [[lo, hi]] a channel; ``roughness``: [lo, hi]); empty otherwise.
    draws : int
        Posterior draws projected (0 for a fixed source).
    residual : float
        Relative root weighted squared residual of the objective at ``values`` (unitless).
    objective : str
        The key of :data:`OBJECTIVES` fitted.
    grid : HemisphereGrid
    """

    model: str
    values: dict
    intervals: dict = dataclasses.field(default_factory=dict)
    draws: int = 0
    residual: float = float("nan")
    grid: HemisphereGrid = DEFAULT_GRID
    objective: str = "cos_cos"

    def brdf(self):
        """The target as a microcyl model (:mod:`brdf.baselines`) at :attr:`values`."""
        return target_model(self.model, self.values)

    def as_dict(self) -> dict:
        """Plain data (for the fidelity file)."""
        return {"model": self.model, "values": self.values, "intervals_95": self.intervals,
                "draws": self.draws, "relative_residual": self.residual,
                "objective": self.objective}


def target_model(model: str, values: dict):
    """The microcyl model ``model`` (``zeltner`` or ``charlie``) at ``values``."""
    if model not in TARGET_MODELS:
        raise ValueError(f"target model {model!r}: must be one of {', '.join(TARGET_MODELS)}")
    return model_class(model)(base=tuple(values["base"]), sheen=tuple(values["sheen"]),
                              roughness=float(values["roughness"]))


def _bounds(model: str):
    lo_r = model_class(model).ROUGHNESS.lo
    return np.array([0.0] * 6 + [lo_r]), np.ones(7)


def _unpack(x) -> dict:
    return {"base": x[..., 0:3], "sheen": x[..., 3:6], "roughness": x[..., 6]}


def _as_values(x) -> dict:
    return {"base": [float(v) for v in x[0:3]], "sheen": [float(v) for v in x[3:6]],
            "roughness": float(x[6])}


class _Problem:
    """The least-squares problem of one source on one grid (module notes)."""

    def __init__(self, model: str, f_source: np.ndarray, grid: HemisphereGrid,
                 objective: str = "cos_cos"):
        wi, wo = grid.wi, grid.wo
        self.prep = target_model(model, {"base": (0.5,) * 3, "sheen": (0.5,) * 3,
                                         "roughness": 0.5}).prepare(wi, wo)
        if objective not in OBJECTIVES:
            raise ValueError(f"objective {objective!r}: must be one of "
                             f"{', '.join(OBJECTIVES)}")
        self.scale = (np.sqrt(grid.weights) * OBJECTIVES[objective](wi[:, 2], wo[:, 2]))[:, None]
        self.target = f_source * self.scale
        self.norm = float(np.sqrt(np.sum(self.target ** 2))) or 1.0
        self.lo, self.hi = _bounds(model)

    def _eval(self, xs):
        f = self.prep.eval(**_unpack(np.asarray(xs)))
        return (f * self.scale - self.target) / self.norm

    def fun(self, x):
        return self._eval(x[None])[0].ravel()

    def jac(self, x):
        steps = np.where(x + _STEP <= self.hi, _STEP, -_STEP)
        xs = np.vstack([x[None], x[None] + np.diag(steps)])
        r = self._eval(xs).reshape(len(xs), -1)
        return ((r[1:] - r[0]) / steps[:, None]).T

    def solve(self, starts) -> tuple[np.ndarray, float]:
        best = None
        for x0 in starts:
            res = optimize.least_squares(self.fun, np.clip(x0, self.lo, self.hi),
                                         jac=self.jac, bounds=(self.lo, self.hi),
                                         method="trf", x_scale=1.0, max_nfev=200)
            if best is None or res.cost < best.cost:
                best = res
        return best.x, float(np.sqrt(2.0 * best.cost))


def _source_values(source, grid: HemisphereGrid) -> np.ndarray:
    f = np.asarray(source.eval(grid.wi, grid.wo), dtype=np.float64)
    if f.shape != (len(grid.weights), 3) or not np.all(np.isfinite(f)):
        raise ValueError("the source's f_r is not finite over the export grid")
    return f


def project(source, model: str, grid: HemisphereGrid = DEFAULT_GRID,
            start: dict | None = None, objective: str = "cos_cos") -> Projection:
    """Project ``source`` (anything with ``eval(wi, wo)`` -> RGB f_r in 1/sr) onto the
    target model ``model`` over ``grid`` (module notes).

    Parameters
    ----------
    source : brdf.Fabric or brdf.baselines.BaselineModel or similar
    model : str
        ``zeltner`` or ``charlie``.
    grid : HemisphereGrid
    start : dict, optional
        A starting point (a previous projection's values) instead of the three starts.
    objective : str
        A key of :data:`OBJECTIVES`.

    Returns
    -------
    Projection
    """
    target_model(model, {"base": (0.5,) * 3, "sheen": (0.5,) * 3, "roughness": 0.5})
    prob = _Problem(model, _source_values(source, grid), grid, objective)
    if start is not None:
        starts = [np.array(list(start["base"]) + list(start["sheen"]) + [start["roughness"]])]
    else:
        starts = [np.array([0.3] * 6 + [r]) for r in _STARTS]
    x, resid = prob.solve(starts)
    return Projection(model, _as_values(x), residual=resid, grid=grid, objective=objective)


def project_draws(median_source, draw_sources, model: str,
                  grid: HemisphereGrid = DEFAULT_GRID, objective: str = "cos_cos") -> Projection:
    """Project a fit's median source and each of ``draw_sources`` (its posterior draws);
    the values are the medians of the draws' projections, with 95% intervals (2.5 and
    97.5 percentiles) a parameter.

    Returns
    -------
    Projection
        With ``draws`` = len(draw_sources); the medians' own projection when there are no
        draws.
    """
    med = project(median_source, model, grid, objective=objective)
    if not draw_sources:
        return med
    xs = []
    for src in draw_sources:
        p = project(src, model, grid, start=med.values, objective=objective)
        v = p.values
        xs.append(list(v["base"]) + list(v["sheen"]) + [v["roughness"]])
    xs = np.array(xs)
    mid = np.median(xs, axis=0)
    lo, hi = np.percentile(xs, [2.5, 97.5], axis=0)
    intervals = {"base": [[float(lo[k]), float(hi[k])] for k in range(3)],
                 "sheen": [[float(lo[k]), float(hi[k])] for k in range(3, 6)],
                 "roughness": [float(lo[6]), float(hi[6])]}
    prob = _Problem(model, _source_values(median_source, grid), grid, objective)
    resid = float(np.sqrt(np.sum(prob.fun(mid) ** 2)))
    return Projection(model, _as_values(mid), intervals, len(draw_sources), resid, grid,
                      objective)
