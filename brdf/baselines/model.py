r"""What every baseline cloth model shares: validated parameters, ``eval``, a batched
``prepare(wi, wo).eval(**params)`` for fitting, and importance sampling.

A baseline model is a frozen set of parameters (its class's :attr:`BaselineModel.PARAMS`, rows
of :class:`brdf.schema.ParamInfo`: names, units, validated and typical ranges) and two class
methods that define it: :meth:`BaselineModel.geometry` (the direction-dependent quantities of
n pairs, computed once) and :meth:`BaselineModel.shade` (RGB f_r from that geometry for a batch
of parameter sets). ``eval``, ``prepare``, ``sample`` and ``pdf`` are written once, here, for
every model; a model may refine the sampler (:meth:`BaselineModel.sample_directions`).

Conventions are :class:`brdf.Fabric`'s: directions (..., 3) in the local frame (z the normal),
``wi`` toward the light and ``wo`` toward the viewer; f_r in 1/sr without the cosine, RGB on the
last axis; 0 where either direction is at or below the horizon, NaN for a zero or non-finite
direction.

Sampling: a mixture of the cosine-weighted hemisphere (the Lambertian base's shape) with
probability ``p`` and the uniform hemisphere (the broad sheen lobes) with ``1 - p``,
p = Y(base) / (Y(base) + Y(sheen)) clipped to [0.1, 0.9] (Y the luminance; 1 for a model with
no sheen). Its density is exact: p cos(theta_i) / pi + (1 - p) / (2 pi).
"""

from __future__ import annotations

import math
from typing import ClassVar, Mapping

import numpy as np

from brdf.forward import Forward
from brdf.frames import flat_pairs, normalize
from brdf.paramschema import ParamSchema
from brdf.schema import ParamInfo

__all__ = ["BaselineModel", "PreparedBaseline", "LUMINANCE"]

#: Rec. 709 / sRGB luminance weights (colour-science's, the project's one luminance).
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def _rgb(info: ParamInfo, value) -> tuple[float, float, float]:
    arr = np.broadcast_to(np.asarray(value, dtype=np.float64), (3,)) \
        if np.ndim(value) == 0 or np.shape(value) == (3,) else None
    if arr is None:
        raise ValueError(f"{info.name} must be one number or three (R, G, B); got shape "
                         f"{np.shape(value)}")
    return tuple(info.check(float(v)) for v in arr)


class BaselineModel:
    """Base class of the baseline cloth models (see the module notes).

    Subclasses set :attr:`name`, :attr:`PARAMS`, :attr:`reciprocal` and implement
    :meth:`geometry` and :meth:`shade`. Instances are immutable; parameters are attributes
    (RGB ones as 3-tuples) and keyword arguments of the constructor (an RGB one may be one
    number, used for the three channels); missing ones take their ParamInfo's
    ``typical_value``.
    """

    #: The model's name (``microcyl fit --model NAME``).
    name: ClassVar[str] = ""
    #: Its parameters, in order.
    PARAMS: ClassVar[tuple[ParamInfo, ...]] = ()
    #: Whether f_r(wi, wo) = f_r(wo, wi) for every pair.
    reciprocal: ClassVar[bool] = True
    #: The parameters whose luminance weights the sampler's cosine / uniform mixture.
    BASE_PARAM: ClassVar[str | None] = "base"
    SHEEN_PARAM: ClassVar[str | None] = None
    #: A fit's default free set: None, every parameter (with the fit's identifiability
    #: choices for the table); no ties.
    DEFAULT_FREE: ClassVar[tuple[str, ...] | None] = None
    DEFAULT_TIES: ClassVar[tuple[str, ...]] = ()
    #: No presets: a baseline starts from its parameters' typical values.
    PRESETS: ClassVar[tuple[str, ...]] = ()
    #: No parameters constrained together (:meth:`admissible`).
    CONSTRAINED: ClassVar[tuple[str, ...]] = ()

    def __init__(self, **values):
        known = {p.name: p for p in self.PARAMS}
        extra = sorted(set(values) - set(known))
        if extra:
            raise ValueError(f"{self.name}: unknown parameter(s) {', '.join(extra)}; "
                             f"parameters: {', '.join(known)}")
        for p in self.PARAMS:
            v = values.get(p.name, p.typical_value)
            v = _rgb(p, v) if p.kind == "rgb" else p.check(v)
            object.__setattr__(self, p.name, v)

    def __setattr__(self, key, value):
        raise AttributeError(f"{type(self).__name__} is immutable; use replace()")

    # -- parameters ------------------------------------------------------------------------
    def params(self) -> dict[str, float | tuple[float, float, float]]:
        """The parameters by name (natural units; RGB ones as 3-tuples)."""
        return {p.name: getattr(self, p.name) for p in self.PARAMS}

    def replace(self, **values) -> "BaselineModel":
        """A copy with some parameters changed (validated)."""
        return type(self)(**{**self.params(), **values})

    # -- the model protocol (brdf.Model): the flat parameters a fit samples -----------------
    @classmethod
    def param_schema(cls) -> ParamSchema:
        """The flat parameters: a scalar row by its name, an RGB one per channel
        (``base_r``, ``base_g``, ``base_b``; the alias ``base``)."""
        return ParamSchema.from_rows(cls.PARAMS)

    @classmethod
    def admissible(cls, values) -> np.ndarray:
        """Every set of values in range is a model: True for each (B...)."""
        return np.ones(np.broadcast(*values.values()).shape if values else (), dtype=bool)

    @classmethod
    def start(cls, preset: str | None = None, options=None) -> "BaselineModel":
        """The model at its parameters' typical values (no preset, no option)."""
        if preset is not None:
            raise ValueError(f"model {cls.name} has no preset ({preset!r})")
        if options:
            raise ValueError(f"model {cls.name} takes no fabric option "
                             f"({', '.join(sorted(options))})")
        return cls()

    def values(self) -> dict[str, float]:
        """Every flat parameter by name (natural units)."""
        out = {}
        for q, v in self.params().items():
            if np.ndim(v):
                out.update({f"{q}_{c}": float(x) for c, x in zip("rgb", v)})
            else:
                out[q] = float(v)
        return out

    def with_values(self, values) -> "BaselineModel":
        """A copy with some flat parameters changed (validated; the rest, a colour's other
        channels included, kept)."""
        schema = self.param_schema()
        unknown = sorted(set(values) - set(schema.names))
        if unknown:
            raise ValueError(f"{self.name}: unknown parameter(s) {', '.join(unknown)}; "
                             f"parameters: {', '.join(schema.names)}")
        grouped = schema.grouped({**self.values(), **values},
                                 lambda xs: tuple(float(x) for x in xs))
        return self.replace(**{q: v if isinstance(v, tuple) else float(v)
                               for q, v in grouped.items()})

    @classmethod
    def batch_kwargs(cls, values) -> dict[str, np.ndarray]:
        """:meth:`PreparedBaseline.eval`'s keyword arguments from every flat parameter's
        values (B...): each scalar (B...), each RGB one (B..., 3)."""
        return cls.param_schema().grouped(values)

    def forward(self, wi, wo) -> Forward:
        """The forward model at the pairs (wi, wo): :class:`brdf.forward.Forward` (float64
        only, so no ``with_dtype``)."""
        return Forward(self, wi, wo)

    def __eq__(self, other):
        return type(other) is type(self) and other.params() == self.params()

    def __hash__(self):
        return hash((type(self).__name__, tuple(self.params().items())))

    def __repr__(self) -> str:
        items = ", ".join(f"{p.name}={p.text(getattr(self, p.name))}" if p.kind == "scalar"
                          else f"{p.name}=({p.text(getattr(self, p.name))})"
                          for p in self.PARAMS)
        return f"{type(self).__name__}({items})"

    # -- the model: subclasses define these two ---------------------------------------------
    @classmethod
    def geometry(cls, wi: np.ndarray, wo: np.ndarray) -> Mapping[str, np.ndarray]:
        """Direction-dependent quantities of n pairs (unit vectors (n, 3), both above the
        horizon), each of shape (n,): computed once by :meth:`prepare`."""
        raise NotImplementedError

    @classmethod
    def shade(cls, geom: Mapping[str, np.ndarray], **params) -> np.ndarray:
        """RGB f_r (B..., n, 3) in 1/sr from :meth:`geometry`'s arrays and a batch of
        parameters: scalars (B...), RGB ones (B..., 3)."""
        raise NotImplementedError

    # -- evaluation -------------------------------------------------------------------------
    def prepare(self, wi, wo) -> "PreparedBaseline":
        """Precompute the geometry of fixed pairs for repeated shading (fits); see
        :class:`PreparedBaseline`."""
        return PreparedBaseline(self, wi, wo)

    def eval(self, wi, wo) -> np.ndarray:
        """RGB f_r (..., 3) in 1/sr (no cosine) of direction pairs (..., 3), broadcasting."""
        prep = self.prepare(wi, wo)
        return prep.eval().reshape(prep.shape + (3,))

    # -- importance sampling ----------------------------------------------------------------
    def cosine_share(self) -> float:
        """Probability that :meth:`sample` draws from the cosine-weighted hemisphere."""
        if self.SHEEN_PARAM is None:
            return 1.0
        yb = float(LUMINANCE @ np.asarray(getattr(self, self.BASE_PARAM)))
        ys = float(LUMINANCE @ np.asarray(getattr(self, self.SHEEN_PARAM)))
        return float(np.clip(yb / (yb + ys), 0.1, 0.9)) if yb + ys > 0 else 0.5

    def sample_directions(self, wo: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Directions wi (n, 3) for viewers wo (n, 3) and uniforms u (n, 2) in [0, 1): the
        cosine / uniform hemisphere mixture (u[:, 0] chooses and is reused)."""
        p = self.cosine_share()
        u0, u1 = u[:, 0], u[:, 1]
        cos_pick = u0 < p
        v = np.where(cos_pick, u0 / p, (u0 - p) / max(1.0 - p, 1e-300))
        v = np.clip(v, 0.0, 1.0 - 1e-16)
        z = np.where(cos_pick, np.sqrt(1.0 - v), 1.0 - v)
        r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        ph = 2.0 * np.pi * u1
        return np.stack([r * np.cos(ph), r * np.sin(ph), z], axis=-1)

    def pdf(self, wo, wi) -> np.ndarray:
        """Density (1/sr) of :meth:`sample`'s directions ``wi`` for the viewer ``wo``;
        0 below the horizon."""
        wi, wo, shape, bad, below = flat_pairs(wi, wo, names=("wi", "wo"))
        p = self.cosine_share()
        out = p * np.maximum(wi[:, 2], 0.0) / math.pi + (1.0 - p) / (2.0 * math.pi)
        out = np.where(below | (wi[:, 2] <= 0), 0.0, out)
        return np.where(bad, np.nan, out).reshape(shape)

    def sample(self, wo, u):
        """Draw directions toward the light: ``(wi, weight, pdf)``.

        Parameters
        ----------
        wo : array_like, shape (..., 3)
            Directions toward the viewer (normalized here).
        u : array_like, shape (..., 2)
            Uniform numbers in [0, 1).

        Returns
        -------
        wi : ndarray (..., 3)
        weight : ndarray (..., 3)
            f_r cos(theta_i) / pdf (RGB); 0 for a viewer below the horizon.
        pdf : ndarray (...)
            Density of wi in 1/sr.
        """
        wo = np.asarray(wo, dtype=np.float64)
        u = np.asarray(u, dtype=np.float64)
        if u.ndim == 0 or u.shape[-1] != 2:
            raise ValueError(f"u must have shape (..., 2); got shape {u.shape}")
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        wo_f, _ = normalize(np.broadcast_to(wo, shape + (3,)).reshape(-1, 3))
        u_f = np.broadcast_to(u, shape + (2,)).reshape(-1, 2)
        wi = self.sample_directions(wo_f, u_f)
        pdf = self.pdf(wo_f, wi)
        f = self.eval(wi, wo_f)
        with np.errstate(divide="ignore", invalid="ignore"):
            weight = np.where((pdf > 0)[:, None], f * wi[:, 2:3] / pdf[:, None], 0.0)
        return wi.reshape(shape + (3,)), weight.reshape(shape + (3,)), pdf.reshape(shape)


class PreparedBaseline:
    """A baseline model's geometry of n fixed pairs, shaded for batches of parameters.

    ``eval(**params)``: each scalar parameter (B...), each RGB one (B..., 3) (or (3,) / one
    number); omitted ones take the model's own values. Returns f_r (B..., n, 3) in 1/sr,
    float64: 0 where a direction is at or below the horizon, NaN for a bad direction.

    Parameters
    ----------
    model : BaselineModel
    wi, wo : array_like, shape (..., 3)
        Direction pairs (broadcast, flattened to n, normalized).

    Examples
    --------
    >>> from brdf.baselines import Lambert
    >>> wi = np.array([[0.0, 0.0, 1.0], [0.0, 0.6, -0.8]])       # the second below the horizon
    >>> prep = PreparedBaseline(Lambert(base=0.5), wi, [0.0, 0.0, 1.0])
    >>> f = prep.eval(base=np.array([[0.1, 0.2, 0.3], [np.pi, 0, 0]]) / np.pi)
    >>> f.shape, np.round(f[:, 0] * np.pi**2, 12).tolist(), float(f[:, 1].max())
    ((2, 2, 3), [[0.1, 0.2, 0.3], [3.14159265359, 0.0, 0.0]], 0.0)
    """

    def __init__(self, model: BaselineModel, wi, wo):
        self.model = model
        wi, wo, self.shape, self.bad, self.below = flat_pairs(wi, wo)
        self.n = wi.shape[0]
        self.keep = ~(self.bad | self.below)
        self.geom = type(model).geometry(wi[self.keep], wo[self.keep])
        self.wi, self.wo = wi, wo

    def eval(self, dtype=None, **params) -> np.ndarray:
        """RGB f_r (B..., n, 3) in 1/sr for a batch of parameter sets (see the class).
        ``dtype`` is accepted for the fit's protocol; baselines shade in float64."""
        own = self.model.params()
        unknown = sorted(set(params) - set(own))
        if unknown:
            raise ValueError(f"{self.model.name}: unknown parameter(s) {', '.join(unknown)}; "
                             f"parameters: {', '.join(own)}")
        kw, batch = {}, ()
        for p in type(self.model).PARAMS:
            v = np.asarray(params.get(p.name, own[p.name]), dtype=np.float64)
            if p.kind == "rgb":
                v = np.broadcast_to(v[..., None], v.shape + (3,)) if v.ndim == 0 else v
                if v.shape[-1] != 3:
                    raise ValueError(f"{p.name} must have shape (B..., 3); got {v.shape}")
                batch = np.broadcast_shapes(batch, v.shape[:-1])
            else:
                batch = np.broadcast_shapes(batch, v.shape)
            kw[p.name] = v
        out = np.zeros(batch + (self.n, 3))
        if self.keep.any():
            out[..., self.keep, :] = type(self.model).shade(self.geom, **kw)
        out[..., self.bad, :] = np.nan
        return out
