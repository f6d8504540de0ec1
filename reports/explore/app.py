"""The BRDF Explorer as a Bokeh document: the controls, the views, and the one state they
share (:class:`reports.explore.engine.State`).

:func:`app` returns the function that builds a document, for the local server
(:func:`reports.explore.server.serve`, ``microcyl explore``) and for Jupyter
(:func:`reports.explore.notebook.explore`: ``explore(brdf.fabric("velvet"))``).

Every control is named ``param-NAME`` (a model parameter's name, e.g. ``param-gamma_s1``,
or ``param-theta_i``, ``param-plane``, ``param-channel``, ``param-scale``,
``param-light_theta``, ``param-light_phi``, ``param-model``, ``param-source``,
``param-preset``, ``param-compare``, ``param-reset``, ``param-rotation`` and each
variant's, ``param-masking``...), every view ``view-NAME`` (:data:`reports.explore.figures.VIEWS`).

Examples
--------
>>> from bokeh.document import Document
>>> doc = Document()
>>> app("velvet")(doc)
>>> sorted(m.name for m in doc.select({"type": Slider}))[:3]
['param-albedo1_b', 'param-albedo1_g', 'param-albedo1_r']
"""

from __future__ import annotations

import math
import time

from bokeh.layouts import column, row
from bokeh.models import Button, Paragraph, Select, Slider

from brdf.fabric import Fabric
from reports.explore.data import Inputs, load_inputs
from reports.explore.engine import Explorer
from reports.explore.figures import SCALED, VIEWS, make_figures, update_figures
from reports.explore.models import explore_model, model_names
from reports.explore.page import page_script

__all__ = ["app", "Controller", "CHANNELS"]

#: What the lobe, the hemisphere and the slice show: luminance or one channel.
CHANNELS = ("luminance", "r", "g", "b")

#: Milliseconds with no control moved before the pairs shaded without being prepared are
#: prepared (:meth:`Controller._prepare_later`).
PREPARE_AFTER_MS = 300.0

_VIEW = {"theta_i": ("incidence θi (deg)", 0.0, 85.0, 1.0),
         "plane": ("plane of incidence φ (deg)", 0.0, 180.0, 5.0),
         "light_theta": ("sphere: light θ (deg)", 0.0, 89.0, 1.0),
         "light_phi": ("sphere: light φ (deg)", 0.0, 360.0, 5.0)}


def _name(widget, name):
    widget.name = f"param-{name}"
    widget.css_classes = [f"param-{name}"]
    return widget


class Controller:
    """One document's controls, views and state; every control's change goes through
    :meth:`set` and redraws every view on the next tick (moves in between coalesce)."""

    def __init__(self, doc, explorer: Explorer):
        self.doc, self.ex = doc, explorer
        self.state = explorer.initial_state()
        self.figs, self.src = make_figures()
        self.status = Paragraph(text="", name="status")   # plain text, never HTML
        self._pending = self._quiet = False
        self._drawn = None                                 # (frame, log) drawn last
        self._preparing = False                            # a prepare step scheduled
        self._moved_at = time.monotonic()                  # the last control's move
        self.sliders: dict = {}
        self.slider_box = row()
        self.variant_box = column()
        self.widgets = self._view_widgets()
        self._rebuild_model_controls()

    # -- controls ------------------------------------------------------------------------
    def _select(self, name, title, value, options, on):
        w = _name(Select(title=title, value=value, options=list(options), width=200), name)
        w.on_change("value", lambda _a, _o, new: self._user(on, new))
        return w

    def _view_widgets(self) -> list:
        out = []
        for key, (title, lo, hi, st) in _VIEW.items():
            w = _name(Slider(title=title, start=lo, end=hi, step=st,
                             value=getattr(self.state, key), width=200), key)
            w.on_change("value", lambda _a, _o, new, key=key: self._user(
                lambda v: self.set(**{key: float(v)}), new))
            out.append(w)
        labels = self.ex.labels()
        out += [self._select("channel", "channel", self.state.channel, CHANNELS,
                             lambda v: self.set(channel=v)),
                self._select("scale", "scale", "linear", ("linear", "log"),
                             lambda v: self.set(log=v == "log")),
                self._select("model", "model", self.state.model, model_names(),
                             self._switch_model),
                self._select("source", "loaded", self.state.source, labels or [""],
                             self._switch_source),
                self._select("compare", "compare with", "", [""] + self.ex.compare_choices(),
                             lambda v: self.set(compare=v))]
        self.preset = self._select("preset", "preset", "", [""] + list(explore_model().presets),
                                   self._pick_preset)
        reset = _name(Button(label="reset (a fit: its medians)", width=200),
                      "reset")
        reset.on_click(lambda: self._switch_source(self.state.source))
        return out + [self.preset, reset]

    def _rebuild_model_controls(self) -> None:
        model = explore_model(self.state.model)
        self.sliders = {}
        for s in model.sliders:
            w = _name(Slider(title=f"{s.name} ({s.unit})", start=s.lo, end=s.hi, step=s.step,
                             value=self.state.values[s.name], width=200), s.name)
            w.on_change("value", lambda _a, _o, new, n=s.name: self._user(
                lambda v: self._set_value(n, v), new))
            self.sliders[s.name] = w
        ws = list(self.sliders.values())
        self.slider_box.children = [column(ws[k:k + 8]) for k in range(0, len(ws), 8)]
        self.variant_box.children = [
            self._select(k, k, str(self.state.options.get(k, v[0])), [str(c) for c in v],
                         lambda val, k=k: self._set_option(k, val))
            for k, v in model.variants.items()] + self._rotation(model)
        self.preset.disabled = not model.is_microcylinder

    def _rotation(self, model) -> list:
        """The fabric's rotation about n (schema.FABRIC's ``rotation``, shown in degrees;
        each move prepares new pairs, like a variant)."""
        if not model.is_microcylinder:
            return []
        deg = math.degrees(self.state.options.get("rotation", 0.0)) % 180.0
        w = _name(Slider(title="rotation (deg)", start=0.0, end=180.0, step=5.0,
                         value=round(deg / 5.0) * 5.0, width=200), "rotation")
        w.on_change("value", lambda _a, _o, new: self._user(
            lambda v: self.set(options=dict(self.state.options, rotation=math.radians(v))),
            new))
        return [w]

    def _user(self, fn, value) -> None:
        if not self._quiet:
            fn(value)

    def _show_values(self) -> None:
        self._quiet = True
        try:
            for n, w in self.sliders.items():
                w.value = self.state.values[n]
        finally:
            self._quiet = False

    # -- state changes -------------------------------------------------------------------
    def set(self, **changes) -> None:
        """Change the state and schedule a redraw."""
        self.state = self.state.replace(**changes)
        self._moved_at = time.monotonic()
        if not self._pending:
            self._pending = True
            self.doc.add_next_tick_callback(self.redraw)

    def _set_value(self, name, value) -> None:
        model = explore_model(self.state.model)
        s = {x.name: x for x in model.sliders}[name]
        values = dict(self.state.values, **{name: s.clip(value)})
        if model.is_microcylinder and name in ("area1", "area2"):
            other = "area2" if name == "area1" else "area1"
            if values[name] + values[other] > 1.0:
                values[other] = 1.0 - values[name]
                self.state = self.state.replace(values=values)
                self._show_values()
        self.set(values=values)

    def _set_option(self, key, text) -> None:
        choices = explore_model(self.state.model).variants[key]
        value = {str(c): c for c in choices}[text]
        self.set(options=dict(self.state.options, **{key: value}))

    def _switch_model(self, name) -> None:
        model = explore_model(name)
        src = self.ex.sources.get(self.state.source)
        obj = src.brdf if src is not None and src.model == name else model.start()
        opts = ({k: obj.options[k] for k in (*model.variants, "rotation")}
                if isinstance(obj, Fabric) else {})
        self.state = self.state.replace(model=name, values=model.values_of(obj), options=opts)
        self._rebuild_model_controls()
        self.set()

    def _switch_source(self, label) -> None:
        st = self.ex.initial_state(label)
        self.state = self.state.replace(model=st.model, values=st.values,
                                        options=st.options, source=label)
        self._rebuild_model_controls()
        self.set()

    def _pick_preset(self, name) -> None:
        if not name:
            return
        model = explore_model(self.state.model)
        self.set(values=model.values_of(model.start(name)))
        self._show_values()

    def redraw(self) -> None:
        """Compute the frame of the state and put it into the views."""
        self._pending = False
        try:
            frame = self.ex.frame(self.state)
        except ValueError as exc:
            self.status.text = f"not drawn: {exc}"[:300]
            return
        self.status.text = ""
        before, self._drawn = self._drawn, (frame, self.state.log)
        views = frame.changed(before[0] if before else None)
        if before and before[1] != self.state.log:
            views = tuple(dict.fromkeys(views + SCALED))
        update_figures(self.figs, self.src, frame, self.state.log, views)
        self._prepare_later()

    def _prepare_later(self, delay_ms: float = PREPARE_AFTER_MS) -> None:
        """Prepare the pairs the last frames shaded without (:mod:`reports.explore.fast`)
        once no control has moved for :data:`PREPARE_AFTER_MS` (not during a drag, whose
        next move would find other pairs), one pair set a callback: a move is served
        first."""
        if self.ex.cache.pending and not self._preparing:
            self._preparing = True
            self.doc.add_timeout_callback(self._prepare_step, max(delay_ms, 1.0))

    def _prepare_step(self) -> None:
        self._preparing = False
        if self._pending:               # a move waits: draw it first, prepare after
            return
        idle_ms = 1e3 * (time.monotonic() - self._moved_at)
        if idle_ms < PREPARE_AFTER_MS:
            self._prepare_later(PREPARE_AFTER_MS - idle_ms)
        elif self.ex.cache.prepare_pending():
            self._prepare_later(1.0)

    def layout(self, per_row: int = 4):
        """The document's one root: the view controls beside the views (``per_row`` a
        row), then the variants and the parameters in columns of eight."""
        views = [self.figs[v] for v in VIEWS]
        grid = column(*(row(views[k:k + per_row]) for k in range(0, len(views), per_row)),
                      self.status)
        self.param_box = row(self.variant_box, self.slider_box)
        return column(row(column(*self.widgets), grid), self.param_box)


def app(*texts, inputs: Inputs | None = None, per_row: int = 4):
    """The function that builds an explorer document of the FABRIC / TABLE / FITDIR
    arguments or model objects ``texts`` (default the ``linen_plain`` preset), ``per_row``
    views a row: for :func:`reports.explore.server.serve`, or Jupyter
    (:func:`reports.explore.notebook.explore`)."""
    inputs = inputs if inputs is not None else load_inputs(list(texts) or ["linen_plain"])
    if not inputs.sources:
        inputs.sources.extend(load_inputs(["linen_plain"]).sources)

    explorer = Explorer(inputs)      # one cache of prepared pairs for every session

    def build(doc) -> None:
        ctl = Controller(doc, explorer)
        doc.add_root(ctl.layout(per_row))
        doc.title = "microcyl explore"
        doc.js_on_event("document_ready", page_script())
        ctl.redraw()
    return build
