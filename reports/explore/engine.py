"""The explorer's one state and the numbers of every view for it.

:class:`State` is what the controls set (the model and its slider values, the variants, the
incidence, the plane, the channel, the light of the sphere, the model compared with);
:class:`Explorer` turns a state into a :class:`Frame`, the numbers every view draws, through
the views of :mod:`analysis.views` evaluated on a :class:`reports.explore.fast.FastBRDF`
(prepared pairs shaded again for each slider move).

Examples
--------
>>> from reports.explore.data import load_inputs
>>> ex = Explorer(load_inputs(["velvet"]))
>>> st = ex.initial_state()
>>> fr = ex.frame(st)
>>> fr.lobe_f.shape, fr.hemisphere.shape, fr.slice.shape, fr.sphere.shape
((181,), (48, 48), (48, 48), (64, 64, 3))
>>> bool(fr.albedo.max() < 1.0), fr.compare_f is None
(True, True)
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from analysis.views.common import reduce_quantity
from analysis.views.explore import compute_albedo_curve, compute_sphere
from analysis.views.hemisphere import compute_hemisphere
from analysis.views.lobes import compute_lobes
from analysis.views.masking import masking_terms
from analysis.views.slices import compute_slice_image
from brdf import PRESETS
from brdf.fabric import Fabric
from brdf.presets import fabric as preset_fabric
from reports.explore.data import Band, Inputs, Points, lobe_band, lobe_points
from reports.explore.fast import FastBRDF, PreparedCache
from reports.explore.models import explore_model

__all__ = ["State", "Frame", "Explorer", "RESOLUTION", "PARTS", "VIEW_PARTS", "views_moved_by",
           "part_key"]

#: Default resolution of each view: samples of the lobe, pixels a side of the hemisphere,
#: the slice and the sphere, pixels a side of the albedo's quadrature.
RESOLUTION = {"lobe": 181, "hemisphere": 48, "slice": 48, "sphere": 64, "albedo": 24}
#: Incidences of the albedo curve, degrees.
ALBEDO_THETAS = tuple(float(t) for t in range(0, 90, 10))


@dataclasses.dataclass(frozen=True)
class State:
    """Everything the controls set. Angles in degrees; ``values`` every slider of
    ``model`` (natural units); ``options`` the microcylinder's variants; ``source`` the
    label of the loaded model the sliders started from (its tangent curves); ``compare``
    the label of a loaded model overlaid, or ``""``."""

    model: str
    values: dict
    options: dict
    source: str
    theta_i: float = 30.0
    plane: float = 0.0
    channel: str = "luminance"
    log: bool = False
    light_theta: float = 45.0
    light_phi: float = 180.0
    compare: str = ""

    def replace(self, **changes) -> "State":
        return dataclasses.replace(self, **changes)


#: The State's fields a model's numbers depend on.
_MODEL = ("model", "values", "options", "source")
#: What each part of a :class:`Frame` is computed from: the :class:`State`'s fields. A move
#: of any other field leaves the part as it was (neither computed nor sent again): the
#: incidence moves the lobe and the hemisphere, not the slice, the sphere or the albedo.
PARTS = {"lobe": _MODEL + ("theta_i", "plane", "channel"),
         "compare": ("compare", "theta_i", "plane", "channel"),
         "band": ("compare", "source", "theta_i", "plane", "channel"),
         "points": ("theta_i", "plane", "channel"),
         "hemisphere": _MODEL + ("theta_i", "plane", "channel"),
         "slice": _MODEL,
         "sphere": _MODEL + ("light_theta", "light_phi"),
         "albedo": _MODEL + ("plane",),
         "tangents": ("model", "options", "source")}
#: The parts each view draws (:data:`reports.explore.figures.VIEWS`).
VIEW_PARTS = {"lobe": ("lobe", "compare", "band", "points"), "hemisphere": ("hemisphere",),
              "slice": ("slice",), "sphere": ("sphere",), "albedo": ("albedo",),
              "masking": (), "tangent": ("tangents",)}


def views_moved_by(field: str) -> tuple:
    """The views whose numbers a change of the :class:`State`'s ``field`` changes.

    >>> views_moved_by("theta_i"), views_moved_by("light_phi")
    (('lobe', 'hemisphere'), ('sphere',))
    """
    if field not in State.__dataclass_fields__:
        raise ValueError(f"no field {field!r} in the explorer's state")
    return tuple(v for v, parts in VIEW_PARTS.items()
                 if any(field in PARTS[p] for p in parts))


def _hashable(value):
    return tuple(sorted(value.items())) if isinstance(value, dict) else value


def part_key(state: State, part: str) -> tuple:
    """The key of ``part`` (:data:`PARTS`) in ``state``: equal keys, equal numbers."""
    return (part,) + tuple(_hashable(getattr(state, f)) for f in PARTS[part])


@dataclasses.dataclass(frozen=True, eq=False)
class Frame:
    """The numbers of every view for one state (f_r in 1/sr; angles in degrees).

    ``lobe_theta``/``lobe_f`` the lobe in the plane (``compare_f`` the compared model's, or
    None), ``band`` a fit's 95% band (or None), ``points`` the tables' points near the plane;
    ``hemisphere`` f_r over the equal-area disc (NaN outside), ``slice`` f_r on theta_h
    (columns) x theta_d (rows), ``sphere`` the lit sphere's RGB radiance, ``albedo_theta``
    and ``albedo`` (m, 3) the directional albedo, ``masking`` M, u and the pair weight
    against ``masking_angle``, ``tangents`` each thread's (arc length, offset in degrees);
    ``keys`` each part's :func:`part_key` (a view whose parts' keys are those of the frame
    drawn before needs no redraw: :meth:`changed`).
    """

    lobe_theta: np.ndarray
    lobe_f: np.ndarray
    compare_f: np.ndarray | None
    band: Band | None
    points: list
    hemisphere: np.ndarray
    slice: np.ndarray
    sphere: np.ndarray
    albedo_theta: np.ndarray
    albedo: np.ndarray
    masking_angle: np.ndarray
    masking: dict
    tangents: list
    keys: dict = dataclasses.field(default_factory=dict)

    def changed(self, before: "Frame | None") -> tuple:
        """The views whose numbers differ from those of the frame ``before`` (every view
        when there is none)."""
        if before is None or not self.keys or not before.keys:
            return tuple(VIEW_PARTS)
        return tuple(v for v, parts in VIEW_PARTS.items()
                     if any(self.keys[p] != before.keys[p] for p in parts))


def _tangents(base) -> list:
    if not isinstance(base, Fabric):
        return []
    out = []
    for th in base.threads:
        s = np.concatenate([[0.0], np.cumsum(th.lengths)])
        s = s / s[-1] if s[-1] > 0 else s
        out.append((np.linspace(0.0, 1.0, len(th.offsets)) if len(s) != len(th.offsets)
                    else s, np.asarray(th.offsets, float)))
    return out


class Explorer:
    """The views' numbers for the loaded ``inputs``, at ``resolution``.

    ``inputs`` come from :func:`reports.explore.data.load_inputs`; ``resolution`` overrides
    some of :data:`RESOLUTION`'s entries."""

    def __init__(self, inputs: Inputs, resolution: dict | None = None):
        self.inputs = inputs
        self.resolution = dict(RESOLUTION, **(resolution or {}))
        self.cache = PreparedCache(24)
        self.memo = PreparedCache(64)        # each part's numbers by its key (small arrays)
        self.sources = {s.label: s for s in inputs.sources}
        self._angle = np.linspace(-90.0, 90.0, 181)
        self._masking = masking_terms(self._angle)

    def labels(self) -> list:
        """The loaded models' labels, in the command line's order."""
        return list(self.sources)

    def base(self, state: State):
        """The model object the sliders act on: the source's own (its tangent curves),
        with the state's variants; a preset's fabric for another model."""
        src = self.sources.get(state.source)
        model = explore_model(state.model)
        obj = src.brdf if src is not None and model.name == src.model else model.start()
        return obj.replace(**state.options) if isinstance(obj, Fabric) else obj

    def initial_state(self, label: str | None = None) -> State:
        """The state of a loaded model (the first by default) at its own values."""
        label = label or (self.labels()[0] if self.sources else "")
        src = self.sources.get(label)
        model = explore_model(src.model if src is not None else "microcylinder")
        obj = src.brdf if src is not None else model.start("linen_plain")
        opts = ({k: obj.options[k] for k in (*model.variants, "rotation")}
                if isinstance(obj, Fabric) else {})
        return State(model.name, model.values_of(obj), opts, label)

    def fast(self, state: State, values=None, base=None) -> FastBRDF:
        model = explore_model(state.model)
        return FastBRDF(model, state.values if values is None else values,
                        self.base(state) if base is None else base, self.cache)

    def compare_choices(self) -> list:
        """What the lobe may be compared with: the loaded models, then the presets."""
        return self.labels() + [p for p in PRESETS if p not in self.sources]

    def _compare(self, state: State, theta):
        src = self.sources.get(state.compare)
        obj = src.brdf if src is not None else (
            preset_fabric(state.compare) if state.compare in PRESETS else None)
        if obj is None:
            return None
        v = compute_lobes(obj, state.theta_i, state.plane, resolution=theta.size)
        return reduce_quantity(v.rgb[0, 0], state.channel)

    def _band(self, state: State, theta) -> Band | None:
        label = state.compare if state.compare in self.inputs.draws else state.source
        draws, src = self.inputs.draws.get(label), self.sources.get(label)
        if draws is None or src is None:
            return None
        model = explore_model(src.model)
        fast = FastBRDF(model, draws, src.brdf, self.cache)
        return lobe_band(fast, theta, state.theta_i, state.plane, state.channel)

    def points(self, state: State) -> list:
        """Each table's :class:`Points` near the plane and incidence."""
        out = []
        for label, table in self.inputs.tables:
            p: Points = lobe_points(table, state.theta_i, state.plane, state.channel)
            out.append((label, p))
        return out

    def _part(self, state: State, part: str, make):
        """``make()`` of ``part``, or the numbers of the same key made before."""
        return self.memo.get(part_key(state, part), make)

    def _lobe(self, state: State, fast):
        lobe = compute_lobes(fast, state.theta_i, state.plane,
                             resolution=self.resolution["lobe"])
        return lobe.theta_o_deg, reduce_quantity(lobe.rgb[0, 0], state.channel)

    def _hemisphere(self, state: State, fast):
        hemi = compute_hemisphere(fast, state.theta_i, state.plane + 180.0,
                                  resolution=self.resolution["hemisphere"])
        return reduce_quantity(hemi.rgb, state.channel)

    def frame(self, state: State) -> Frame:
        """Every view's numbers for ``state``: each part (:data:`PARTS`) computed again
        only where its fields differ from a state computed before (one evaluation of the
        part's pairs, prepared once)."""
        res, part = self.resolution, lambda name, make: self._part(state, name, make)
        fast = functools.cache(lambda: self.fast(state))   # one for the parts made anew
        theta, lobe_f = part("lobe", lambda: self._lobe(state, fast()))
        alb = part("albedo", lambda: compute_albedo_curve(
            fast(), ALBEDO_THETAS, state.plane + 180.0, resolution=res["albedo"]))
        return Frame(
            theta, lobe_f, part("compare", lambda: self._compare(state, theta)),
            part("band", lambda: self._band(state, theta)),
            part("points", lambda: self.points(state)),
            part("hemisphere", lambda: self._hemisphere(state, fast())),
            part("slice", lambda: compute_slice_image(fast(), resolution=res["slice"]).image),
            part("sphere", lambda: compute_sphere(fast(), state.light_theta,
                                                  state.light_phi,
                                                  resolution=res["sphere"]).radiance),
            alb.theta_i_deg, alb.albedo, self._angle, self._masking,
            part("tangents", lambda: _tangents(self.base(state))),
            {p: part_key(state, p) for p in PARTS})
